"""frustum.interop.pyrender.OffscreenRenderer against pyrender itself (0.1.45 on Mesa llvmpipe through EGL).

pyrender draws into a 4× multisampled framebuffer: its colour is the mean of 4 samples (silhouette and crease
pixels blend), and it blits the depth with GL_NEAREST, which keeps sample 0, the point (0.375, 0.875) of each
pixel (u right, v down; measured here on a tilted plane), not the centre. frustum samples pixel centres once.
The comparisons therefore run pyrender with multisampling switched off (``single_sample``: ``glEnable
(GL_MULTISAMPLE)`` becomes ``glDisable``, as pyrender itself does for ``SEG``), where both draw the pixel centres;
``test_multisampled_pyrender_depth_is_its_sample_zero`` checks the multisampled depth with frustum's principal
point moved onto sample 0, and bounds the share of blended colour pixels.
"""

from __future__ import annotations

import math
import os
import sys

os.environ.setdefault("PYOPENGL_PLATFORM", "egl")  # before PyOpenGL is first imported: no display needed

import numpy as np
import pytest
from scipy import ndimage

pyrender = pytest.importorskip("pyrender")
trimesh = pytest.importorskip("trimesh")

from frustum import FrustumError, look_at  # noqa: E402
from frustum.interop.pyrender import OffscreenRenderer, RenderFlags  # noqa: E402

tf = trimesh.transformations
SAMPLE_SHIFT = (0.5 - 0.375, 0.5 - 0.875)  # pyrender's depth sample 0 relative to the pixel centre (u, v down)
W, H = 320, 240


@pytest.fixture(scope="module")
def egl() -> None:
    try:
        renderer = pyrender.OffscreenRenderer(8, 8)
        renderer.delete()
    except Exception as error:  # no EGL / llvmpipe on this machine
        pytest.skip(f"pyrender cannot start an EGL context here: {error!r}")


@pytest.fixture
def single_sample(egl, monkeypatch) -> None:
    """pyrender without multisampling: every sample of a pixel gets the pixel centre's coverage and depth."""
    import pyrender.renderer as module
    from OpenGL.GL import GL_MULTISAMPLE

    enable = module.glEnable
    monkeypatch.setattr(module, "glEnable", lambda cap: module.glDisable(cap) if cap == GL_MULTISAMPLE else enable(cap))


def _pyrender(scene, flags=pyrender.RenderFlags.NONE, seg_node_map=None, size=(W, H)):
    renderer = pyrender.OffscreenRenderer(*size)
    try:
        return renderer.render(scene, flags, seg_node_map=seg_node_map)
    finally:
        renderer.delete()


def _frustum(scene, flags=RenderFlags.NONE, seg_node_map=None, size=(W, H)):
    renderer = OffscreenRenderer(*size)
    try:
        return renderer.render(scene, flags, seg_node_map=seg_node_map)
    finally:
        renderer.delete()


def _bunny() -> trimesh.Trimesh:
    path = os.path.join(os.path.dirname(__file__), "data", "bunny", "bun_zipper_res3.ply")
    mesh = trimesh.load(path, process=False)
    # the file holds faces twice with opposite windings: their vertices' normals cancel to zero (pyrender would
    # divide by zero there, frustum's adapter refuses them); keep one of each
    mesh.update_faces(mesh.unique_faces())
    mesh.remove_unreferenced_vertices()
    assert (mesh.vertex_normals != 0.0).any(axis=1).all()
    mesh.apply_translation(-mesh.bounds.mean(axis=0))
    mesh.apply_scale(1.2 / mesh.extents.max())
    return mesh


def _material(rgb, metallic=0.0, roughness=0.6):
    return pyrender.MetallicRoughnessMaterial(baseColorFactor=[*rgb, 1.0], metallicFactor=metallic,
                                              roughnessFactor=roughness)  # fmt: skip


def _objects(scene, *, smooth: bool = False) -> dict:
    """Two boxes (flat-shaded), a sphere, the bunny and an instanced row of boxes; returns their nodes."""
    nodes = {}
    box = trimesh.creation.box((1.0, 0.8, 0.9))
    box_pose = tf.translation_matrix([-1.0, 0.1, 0]) @ tf.rotation_matrix(0.5, [1, 1, 0])
    box_mesh = pyrender.Mesh.from_trimesh(box, material=_material((0.8, 0.3, 0.2)), smooth=False)
    nodes["box"] = scene.add(box_mesh, pose=box_pose)
    slab = trimesh.creation.box((3.6, 0.2, 2.4))
    slab_mesh = pyrender.Mesh.from_trimesh(slab, material=_material((0.6, 0.6, 0.5), 0.0, 0.9), smooth=False)
    nodes["slab"] = scene.add(slab_mesh, pose=tf.translation_matrix([0, -0.75, 0]))
    # flat-shaded facets a few pixels wide blend under pyrender's multisampling: the sphere is faceted only
    # where asked (`smooth=False`) and then coarse
    sphere = trimesh.creation.icosphere(1 if not smooth else 3, 0.55)
    nodes["sphere"] = scene.add(
        pyrender.Mesh.from_trimesh(sphere, material=_material((0.2, 0.5, 0.8), 0.3, 0.4), smooth=smooth),
        pose=tf.translation_matrix([1.0, 0.0, -0.3]),
    )
    # the bunny's faces are a pixel or two wide: always smooth
    nodes["bunny"] = scene.add(pyrender.Mesh.from_trimesh(_bunny(), material=_material((0.7, 0.7, 0.6))),
                               pose=tf.translation_matrix([0.1, -0.05, 0.6]))  # fmt: skip
    small = trimesh.creation.box((0.3, 0.3, 0.3))
    poses = np.array([tf.translation_matrix([-1.3 + 0.55 * i, -0.5, 1.0]) @ tf.rotation_matrix(0.3 * i, [0, 1, 0])
                      for i in range(5)])  # fmt: skip
    nodes["row"] = scene.add(pyrender.Mesh.from_trimesh(small, material=_material((0.3, 0.8, 0.3)), poses=poses,
                                                        smooth=False))  # fmt: skip
    return nodes


def _lit_scene(camera, camera_pose, *, smooth=False, lights=("directional",)):
    scene = pyrender.Scene(ambient_light=[0.08, 0.08, 0.1], bg_color=[0.2, 0.25, 0.3, 1.0])
    nodes = _objects(scene, smooth=smooth)
    if "directional" in lights:
        scene.add(pyrender.DirectionalLight(color=[1.0, 0.95, 0.9], intensity=3.0),
                  pose=tf.rotation_matrix(-0.7, [1, 0.4, 0]))  # fmt: skip
    if "point" in lights:
        scene.add(pyrender.PointLight(color=[0.9, 0.9, 1.0], intensity=12.0), pose=tf.translation_matrix([1, 2, 2.5]))
    if "spot" in lights:
        aim = tf.rotation_matrix(-0.5, [1, 0, 0]) @ tf.rotation_matrix(0.2, [0, 1, 0])
        scene.add(pyrender.SpotLight(color=[1, 1, 1], intensity=25.0, innerConeAngle=0.2, outerConeAngle=0.5),
                  pose=tf.translation_matrix([0.0, 1.5, 3.0]) @ aim)  # fmt: skip
    node = scene.add(camera, pose=camera_pose)
    return scene, nodes, node


CAMERA_POSE = np.linalg.inv(look_at((0.4, 1.6, 3.6), (0.0, -0.2, 0.0)))  # camera-to-world, OpenGL axes


def _intrinsics(shift=(0.0, 0.0)):
    # an off-centre principal point, fx != fy
    return pyrender.IntrinsicsCamera(fx=330.0, fy=310.0, cx=151.3 + shift[0], cy=128.6 + shift[1], znear=0.5, zfar=30)


def _coverage_and_depth(reference, ours, *, coverage=0.999):
    """Depth coverage equal on >= `coverage` of the pixels; depth within 1e-4 relative on every pixel both drew.

    Grazing pixels included: frustum's depth is the plane through the triangle's corners before their window
    positions snap to 1/256 pixel (``raster.triangles.depth_plane``); the plane through the snapped corners was
    off by up to 2.7e-4 on 5 of the 44,096 pixels of the intrinsics scene, where pyrender's depth and a float64
    ray cast agree within 2e-6.
    """
    agree = (reference > 0) == (ours > 0)
    assert agree.mean() >= coverage, f"coverage equal on {agree.mean():.5f} of the pixels"
    both = (reference > 0) & (ours > 0)
    assert both.sum() > 5000
    relative = np.abs(ours[both].astype(np.float64) / reference[both] - 1.0)
    assert relative.max() <= 1e-4, f"{(relative > 1e-4).sum()} of {both.sum()} pixels beyond 1e-4 relative"


def _colors_close(reference, ours, covered, *, share=0.99, tolerance=3):
    difference = np.abs(reference.astype(int) - ours.astype(int)).max(axis=2)
    close = (difference[covered] <= tolerance).mean()
    assert close >= share, f"colour within {tolerance}/255 on {close:.4f} of the covered pixels"


def test_intrinsics_camera_depth_coverage_and_flat_shaded_colour_match_pyrender(single_sample) -> None:
    """Off-centre principal point, fx ≠ fy; flat-shaded boxes and sphere, a directional light."""
    scene, _, _ = _lit_scene(_intrinsics(), CAMERA_POSE)
    color_ref, depth_ref = _pyrender(scene)
    color, depth = _frustum(scene)
    assert color.shape == (H, W, 3) and color.dtype == np.uint8
    assert depth.shape == (H, W) and depth.dtype == np.float32
    _coverage_and_depth(depth_ref, depth)
    _colors_close(color_ref, color, depth_ref > 0)


def test_perspective_camera_matches_pyrender_and_its_intrinsics_equivalent(single_sample) -> None:
    yfov = 0.8
    scene, _, camera_node = _lit_scene(pyrender.PerspectiveCamera(yfov=yfov, znear=0.3, zfar=40.0), CAMERA_POSE,
                                       smooth=True)  # fmt: skip
    color_ref, depth_ref = _pyrender(scene)
    color, depth = _frustum(scene)
    _coverage_and_depth(depth_ref, depth)
    _colors_close(color_ref, color, depth_ref > 0)
    f = H / (2.0 * math.tan(yfov / 2.0))
    camera_node.camera = pyrender.IntrinsicsCamera(f, f, W / 2, H / 2, znear=0.3, zfar=40.0)
    color_k, depth_k = _frustum(scene)
    np.testing.assert_allclose(depth_k, depth, rtol=1e-6)
    assert np.abs(color_k.astype(int) - color.astype(int)).max() <= 1


def test_perspective_camera_without_far_plane(single_sample) -> None:
    scene, _, _ = _lit_scene(pyrender.PerspectiveCamera(yfov=0.8, znear=0.3), CAMERA_POSE)
    _, depth_ref = _pyrender(scene)
    _, depth = _frustum(scene)
    _coverage_and_depth(depth_ref, depth)


def test_instanced_poses_draw_every_instance(single_sample) -> None:
    scene, nodes, _ = _lit_scene(_intrinsics(), CAMERA_POSE)
    seg = {nodes["row"]: (0, 255, 0)}
    color_ref, depth_ref = _pyrender(scene, pyrender.RenderFlags.SEG, seg)
    color, depth = _frustum(scene, RenderFlags.SEG, seg)
    mask = color[:, :, 1] == 255
    _, count = ndimage.label(mask)
    assert count == 5  # five instances, apart on the image
    assert (mask == (color_ref[:, :, 1] == 255)).mean() >= 0.999
    _coverage_and_depth(depth_ref, depth)


def test_orthographic_camera_coverage_matches_and_depth_is_the_plane_distance(single_sample) -> None:
    """pyrender linearizes an orthographic depth buffer as if it were perspective: compare coverage, and check
    frustum's depth analytically on a plane facing the camera."""
    camera = pyrender.OrthographicCamera(xmag=1.6, ymag=1.6, znear=0.5, zfar=20.0)
    scene, _, _ = _lit_scene(camera, CAMERA_POSE)
    color_ref, depth_ref = _pyrender(scene)
    color, depth = _frustum(scene)
    assert ((depth_ref > 0) == (depth > 0)).mean() >= 0.999
    _colors_close(color_ref, color, depth_ref > 0)
    # a box face at z = −1.95 seen by an orthographic camera at z = 3 is 4.95 away everywhere
    plain = pyrender.Scene()
    plain.add(pyrender.Mesh.from_trimesh(trimesh.creation.box((8.0, 8.0, 0.1))), pose=tf.translation_matrix([0, 0, -2]))
    plain.add(camera, pose=tf.translation_matrix([0.2, 0.1, 3.0]))
    depth_plane = _frustum(plain, RenderFlags.DEPTH_ONLY)
    np.testing.assert_allclose(depth_plane, 4.95, rtol=2e-6)


def test_multisampled_pyrender_depth_is_its_sample_zero(egl) -> None:
    """pyrender as it ships (4× MSAA): its depth equals frustum's with the principal point moved by
    (+0.125, −0.375) pixel, onto sample 0; colours differ only on the pixels multisampling blends."""
    scene, _, camera_node = _lit_scene(_intrinsics(), CAMERA_POSE)
    color_ref, depth_ref = _pyrender(scene)
    color, _ = _frustum(scene)
    _colors_close(color_ref, color, depth_ref > 0, share=0.9)  # measured 0.95: silhouettes and creases blend
    camera_node.camera = _intrinsics(SAMPLE_SHIFT)
    _, depth_at_samples = _frustum(scene)
    _coverage_and_depth(depth_ref, depth_at_samples)


def test_point_and_spot_lights_match_pyrender(single_sample) -> None:
    scene, _, _ = _lit_scene(_intrinsics(), CAMERA_POSE, smooth=True, lights=("point", "spot"))
    color_ref, depth_ref = _pyrender(scene)
    color, _ = _frustum(scene)
    _colors_close(color_ref, color, depth_ref > 0)


def test_seg_masks_equal_pyrender(single_sample) -> None:
    scene, nodes, _ = _lit_scene(_intrinsics(), CAMERA_POSE)
    seg_node_map = {nodes["box"]: (255, 0, 0), nodes["sphere"]: 7, nodes["row"]: (10, 200, 30)}  # bunny left out
    color_ref, depth_ref = _pyrender(scene, pyrender.RenderFlags.SEG, seg_node_map)
    color, depth = _frustum(scene, RenderFlags.SEG, seg_node_map)
    assert color.shape == (H, W, 3)
    _coverage_and_depth(depth_ref, depth)  # only the mapped nodes are drawn: the bunny hides nothing
    # SEG draws without multisampling: masks at the pixel centres, as frustum's
    assert (np.all(color_ref == color, axis=2)).mean() >= 0.999
    assert set(map(tuple, color.reshape(-1, 3))) == {(0, 0, 0), (255, 0, 0), (7, 7, 7), (10, 200, 30)}


def test_flat_rgba_and_depth_only(single_sample) -> None:
    scene, _, _ = _lit_scene(_intrinsics(), CAMERA_POSE)
    flags = RenderFlags.FLAT | RenderFlags.RGBA
    color_ref, depth_ref = _pyrender(scene, flags)
    color, _ = _frustum(scene, flags)
    assert color.shape == (H, W, 4)
    _colors_close(color_ref, color, depth_ref > 0, tolerance=1)
    assert (color[depth_ref == 0][:, 3] == color_ref[depth_ref == 0][:, 3]).mean() > 0.99
    depth = _frustum(scene, RenderFlags.DEPTH_ONLY)
    assert isinstance(depth, np.ndarray) and depth.shape == (H, W)


def test_textured_and_vertex_coloured_meshes_match_pyrender(single_sample) -> None:
    rng = np.random.default_rng(4)
    image = (rng.uniform(0, 255, (8, 8, 3))).astype(np.uint8)
    quad = trimesh.Trimesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]], process=False)
    texture = pyrender.Texture(source=image, source_channels="RGB")
    material = pyrender.MetallicRoughnessMaterial(baseColorTexture=texture, metallicFactor=0.0, roughnessFactor=0.9)
    primitive = pyrender.Primitive(positions=quad.vertices, indices=quad.faces, normals=np.tile([0, 0, 1.0], (4, 1)),
                                   texcoord_0=[[0, 0], [1, 0], [1, 1], [0, 1]], material=material)  # fmt: skip
    ball = trimesh.creation.icosphere(2, 0.4)
    ball.visual.vertex_colors = rng.integers(0, 256, (len(ball.vertices), 4)).astype(np.uint8) | np.uint8(0)
    ball.visual.vertex_colors[:, 3] = 255
    scene = pyrender.Scene(ambient_light=[0.1, 0.1, 0.1])
    scene.add(pyrender.Mesh([primitive]), pose=tf.rotation_matrix(-0.3, [1, 0, 0]))
    scene.add(pyrender.Mesh.from_trimesh(ball), pose=tf.translation_matrix([0.6, 0.5, 0.5]))
    scene.add(pyrender.DirectionalLight(intensity=2.5), pose=tf.rotation_matrix(-0.4, [1, 0, 0]))
    scene.add(_intrinsics(), pose=tf.translation_matrix([0, 0, 3.2]))
    for flags in (RenderFlags.NONE, RenderFlags.FLAT):
        color_ref, depth_ref = _pyrender(scene, flags)
        color, _ = _frustum(scene, flags)
        _colors_close(color_ref, color, depth_ref > 0, share=0.98)


@pytest.mark.parametrize("kind", ["directional", "spot"])
def test_shadows_fall_where_rays_to_the_light_are_blocked(kind: str) -> None:
    """Shadow flags: frustum's shadow maps darken the floor where a ray from the floor toward the light meets the
    box (trimesh's ray casting is the oracle; pyrender 0.1.45 cannot draw shadows under NumPy 2: np.infty)."""
    scene = pyrender.Scene(ambient_light=[0.05, 0.05, 0.05])
    floor = trimesh.creation.box((6, 0.1, 6))
    floor.apply_translation([0, -1.05, 0])
    blocker = trimesh.creation.box((0.8, 0.8, 0.8))
    floor_node = scene.add(pyrender.Mesh.from_trimesh(floor, material=_material((0.8, 0.8, 0.8))))
    scene.add(pyrender.Mesh.from_trimesh(blocker, material=_material((0.8, 0.2, 0.2))))
    if kind == "directional":
        light_pose, flags = tf.rotation_matrix(-1.1, [1, 0, 0.3]), RenderFlags.SHADOWS_DIRECTIONAL
        scene.add(pyrender.DirectionalLight(intensity=3.0), pose=light_pose)
    else:
        light_pose = np.linalg.inv(look_at((1.0, 2.5, 1.5), (0.0, -1.0, 0.0), (0.0, 1.0, 0.0)))
        flags = RenderFlags.SHADOWS_SPOT
        scene.add(pyrender.SpotLight(intensity=30.0, innerConeAngle=0.6, outerConeAngle=1.0), pose=light_pose)
    camera_pose = np.linalg.inv(look_at((0.5, 2.5, 4.5), (0.0, -0.8, 0.0)))
    scene.add(_intrinsics(), pose=camera_pose)
    color, depth = _frustum(scene, flags)
    unshadowed, _ = _frustum(scene)
    on_floor = _frustum(scene, RenderFlags.SEG, {floor_node: 255})[0][:, :, 0] == 255
    darker = color.astype(int).sum(axis=2) < unshadowed.astype(int).sum(axis=2) - 6
    # the oracle: floor points from the depth and the camera, a ray toward the light
    rows, columns = np.nonzero(on_floor)
    k = _intrinsics()
    z = depth[rows, columns].astype(np.float64)
    camera_points = np.column_stack([(columns + 0.5 - k.cx) / k.fx * z, -(rows + 0.5 - k.cy) / k.fy * z, -z])
    points = camera_points @ camera_pose[:3, :3].T + camera_pose[:3, 3]
    if kind == "directional":
        toward = np.broadcast_to(light_pose[:3, 2], points.shape)
    else:
        toward = light_pose[:3, 3] - points
        toward = toward / np.linalg.norm(toward, axis=1)[:, None]
    blocked = blocker.ray.intersects_any(points + 1e-3 * toward, toward)
    assert blocked.sum() > 300
    # shadow-map texels and filtering move the shadow's edge by a pixel or so
    agree = (darker[rows, columns] == blocked).mean()
    assert agree >= 0.98, f"shadow agrees with the rays on {agree:.4f} of the floor"


def test_skip_cull_faces_draws_back_faces_as_pyrender_does(single_sample) -> None:
    """A quad turned away from the camera: culled by default, drawn with SKIP_CULL_FACES (coverage and depth as
    pyrender's; its back is lit differently: frustum turns the normal toward the viewer)."""
    quad = trimesh.Trimesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 2, 1], [0, 3, 2]], process=False)
    scene = pyrender.Scene()
    node = scene.add(pyrender.Mesh.from_trimesh(quad, material=_material((0.8, 0.8, 0.8))))
    scene.add(_intrinsics(), pose=tf.translation_matrix([0.1, 0.0, 3.0]))
    _, culled = _frustum(scene)
    _, culled_ref = _pyrender(scene)
    assert not (culled > 0).any() and not (culled_ref > 0).any()
    _, both_sides = _frustum(scene, RenderFlags.SKIP_CULL_FACES)
    _, both_sides_ref = _pyrender(scene, pyrender.RenderFlags.SKIP_CULL_FACES)
    _coverage_and_depth(both_sides_ref, both_sides)
    scene.add(pyrender.Mesh.from_trimesh(trimesh.creation.box(), material=pyrender.MetallicRoughnessMaterial(
        doubleSided=True)), pose=tf.translation_matrix([0, 0, -2]))  # fmt: skip
    with pytest.raises(FrustumError, match=r"some primitives are doubleSided and others are not"):
        _frustum(scene)
    node.mesh.primitives[0].material.doubleSided = True
    _, double_sided = _frustum(scene)
    assert (double_sided > 0).sum() > (both_sides > 0).sum() * 0.5


def test_renderer_matches_pyrender_signature_and_deletes() -> None:
    renderer = OffscreenRenderer(32, 24, point_size=2.0)
    assert (renderer.viewport_width, renderer.viewport_height, renderer.point_size) == (32, 24, 2.0)
    renderer.delete()
    scene = pyrender.Scene()
    with pytest.raises(FrustumError, match=r"the renderer was deleted"):
        renderer.render(scene)
    with pytest.raises(FrustumError, match=r"viewport_width = 0 is not a positive integer"):
        OffscreenRenderer(0, 10)


def _small_scene(material=None, wireframe=False, **primitive):
    box = trimesh.creation.box()
    scene = pyrender.Scene()
    if primitive:
        scene.add(pyrender.Mesh([pyrender.Primitive(positions=box.vertices, indices=box.faces, material=material,
                                                    **primitive)]))  # fmt: skip
    else:
        scene.add(pyrender.Mesh.from_trimesh(box, material=material, wireframe=wireframe))
    scene.add(pyrender.PerspectiveCamera(yfov=1.0), pose=tf.translation_matrix([0, 0, 3]))
    return scene


@pytest.mark.parametrize(
    ("material", "match"),
    [
        (
            dict(normalTexture=pyrender.Texture(source=np.zeros((2, 2, 3), np.uint8), source_channels="RGB")),
            r"normalTexture is not drawn",
        ),
        (
            dict(occlusionTexture=pyrender.Texture(source=np.zeros((2, 2, 3), np.uint8), source_channels="RGB")),
            r"occlusionTexture is not drawn",
        ),
        (dict(alphaMode="MASK"), r"alphaMode 'MASK'"),
        (dict(alphaMode="BLEND", baseColorFactor=[1, 1, 1, 0.5]), r"alphaMode 'BLEND' with baseColorFactor alpha 0.5"),
        (dict(wireframe=True), r"wireframe=True"),
    ],
)
def test_unsupported_material_features_are_named(material: dict, match: str) -> None:
    wireframe = material.pop("wireframe", False)
    scene = _small_scene(pyrender.MetallicRoughnessMaterial(**material), wireframe=wireframe)
    with pytest.raises(FrustumError, match=match):
        _frustum(scene)


def test_unsupported_primitives_flags_and_scenes_are_named() -> None:
    scene = _small_scene(pyrender.MetallicRoughnessMaterial(), mode=0)
    with pytest.raises(FrustumError, match=r"mode POINTS; frustum's OffscreenRenderer draws TRIANGLES only"):
        _frustum(scene)
    glossy = _small_scene(pyrender.material.SpecularGlossinessMaterial())
    with pytest.raises(FrustumError, match=r"SpecularGlossinessMaterial is not drawn"):
        _frustum(glossy)
    plain = _small_scene()
    with pytest.raises(FrustumError, match=r"RenderFlags.ALL_WIREFRAME \(wireframes\) is not drawn"):
        _frustum(plain, RenderFlags.ALL_WIREFRAME)
    with pytest.raises(FrustumError, match=r"VERTEX_NORMALS"):
        _frustum(plain, RenderFlags.VERTEX_NORMALS)
    no_camera = pyrender.Scene()
    no_camera.add(pyrender.Mesh.from_trimesh(trimesh.creation.box()))
    with pytest.raises(FrustumError, match=r"the scene has no camera"):
        _frustum(no_camera)
    with pytest.raises(FrustumError, match=r"is not a pyrender.Scene"):
        _frustum(trimesh.Scene())


def test_missing_pyrender_names_the_extra(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "pyrender", None)
    with pytest.raises(FrustumError, match=r"pip install 'frustum\[pyrender\]'"):
        OffscreenRenderer(8, 8).render(object())
