"""Scene.from_trimesh and render_trimesh: a trimesh scene graph, its visuals and its camera, drawn by frustum.

The oracle for placement is a hand-built frustum scene of the same meshes at the transforms the test gave trimesh
(not read back from trimesh's graph): both must draw the same ``object_id`` silhouettes. Colours are checked with
shading "none" (the base colour alone) against the colours the test set.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import frustum
from frustum import Camera, FrustumError, Material, Mesh, Scene, render

tf = trimesh.transformations

# transforms given to trimesh's graph; node names sort in this order, the order Scene.from_trimesh places parts
PLACEMENTS = {
    "a_box": tf.translation_matrix([-1.2, 0.0, 0.0]) @ tf.rotation_matrix(0.6, [0, 1, 0]),
    "b_ball": tf.translation_matrix([0.9, 0.3, -0.4]) @ tf.scale_matrix(1.3),
    "c_cone": tf.translation_matrix([0.0, -0.6, 0.8]) @ tf.rotation_matrix(-1.2, [1, 0, 0]),
}
FACE_RGB = np.array([200, 40, 30, 255], dtype=np.uint8)


def _meshes() -> dict[str, trimesh.Trimesh]:
    box = trimesh.creation.box((1.0, 0.8, 0.9))
    box.visual.face_colors = np.tile(FACE_RGB, (len(box.faces), 1))
    box.visual.face_colors[0] = (20, 220, 40, 255)  # one face of another colour
    ball = trimesh.creation.icosphere(2, 0.5)
    ball.visual.vertex_colors = np.column_stack([np.linspace(0, 255, len(ball.vertices)).astype(np.uint8),
                                                 np.full(len(ball.vertices), 128, np.uint8),
                                                 np.full(len(ball.vertices), 64, np.uint8),
                                                 np.full(len(ball.vertices), 255, np.uint8)])  # fmt: skip
    cone = trimesh.creation.cone(0.5, 1.0, sections=24)
    material = trimesh.visual.material.PBRMaterial(baseColorFactor=[0.1, 0.3, 0.9, 1.0])
    cone.visual = trimesh.visual.TextureVisuals(material=material)
    return {"a_box": box, "b_ball": ball, "c_cone": cone}


def _trimesh_scene(camera: bool = True) -> trimesh.Scene:
    scene = trimesh.Scene()
    for name, mesh in _meshes().items():
        scene.add_geometry(mesh, node_name=name, geom_name=name, transform=PLACEMENTS[name])
    if camera:
        scene.set_camera(angles=(0.4, 0.3, 0.0), distance=7.0, center=(0, 0, 0), resolution=(160, 120), fov=(60, 47))
    return scene


def test_three_transformed_coloured_meshes_draw_the_same_silhouettes_as_the_hand_built_scene() -> None:
    source = _trimesh_scene()
    scene, camera = Scene.from_trimesh(source)
    assert (camera.width, camera.height) == (160, 120)
    hand = Scene()
    for name, mesh in _meshes().items():
        hand.add(Mesh(mesh.vertices, mesh.faces), Material(), PLACEMENTS[name], name=name)
    ours = render(scene, camera, buffers=("object_id",))
    expected = render(hand, camera, buffers=("object_id",))
    assert set(np.unique(expected.object_id)) == {-1, 0, 1, 2}  # every mesh is in view
    # the face-coloured box is split per face (same geometry, its own vertices): ties on its edges may differ
    assert (ours.object_id == expected.object_id).mean() >= 0.999


def test_camera_is_trimesh_camera_intrinsics_and_pose() -> None:
    source = _trimesh_scene()
    _, camera = Scene.from_trimesh(source)
    np.testing.assert_allclose(camera.intrinsics(), source.camera.K, rtol=1e-12)
    np.testing.assert_allclose(camera.world_to_camera("opengl"), np.linalg.inv(source.camera_transform), atol=1e-12)
    _, bigger = Scene.from_trimesh(source, resolution=(320, 240))
    np.testing.assert_allclose(bigger.intrinsics(), source.camera.K * [[2], [2], [1]], rtol=1e-12)


def test_face_vertex_and_pbr_colours_reach_the_materials() -> None:
    source = _trimesh_scene()
    scene, camera = Scene.from_trimesh(source)
    frame = render(scene, camera, shading="none", buffers=("object_id",))
    box_pixels = frame.color[frame.object_id == 0][:, :3]
    colors = {tuple(c) for c in box_pixels.tolist()}
    assert tuple(FACE_RGB[:3]) in colors and colors <= {tuple(FACE_RGB[:3]), (20, 220, 40)}
    cone_pixels = frame.color[frame.object_id == 2][:, :3]
    stored = np.asarray(source.geometry["c_cone"].visual.material.baseColorFactor)  # trimesh keeps it as bytes
    assert stored.dtype == np.uint8
    assert {tuple(c) for c in cone_pixels.tolist()} == {tuple(stored[:3].tolist())}
    ball_pixels = frame.color[frame.object_id == 1][:, :3]
    assert (ball_pixels[:, 1] == 128).all() and (ball_pixels[:, 2] == 64).all() and np.ptp(ball_pixels[:, 0]) > 50


def test_render_trimesh_of_a_bare_mesh_frames_it() -> None:
    mesh = trimesh.creation.torus(1.0, 0.3)
    frame = frustum.render_trimesh(mesh, resolution=(96, 64))
    assert frame.color.shape == (64, 96, 4)
    covered = frame.depth < 1.0
    assert covered.mean() > 0.2
    rows, columns = np.nonzero(covered)  # Camera.fit leaves a margin on every side
    assert rows.min() > 0 and columns.min() > 0 and rows.max() < 63 and columns.max() < 95
    scene, camera = Scene.from_trimesh(mesh)
    assert isinstance(camera, Camera) and (camera.width, camera.height) == (640, 480) and len(scene.items) == 1


def test_from_trimesh_rejects_what_is_not_a_trimesh_scene() -> None:
    with pytest.raises(FrustumError, match=r"is not a trimesh.Scene or Trimesh"):
        Scene.from_trimesh([[0, 0, 0]])
    with pytest.raises(FrustumError, match=r"holds no triangle mesh"):
        Scene.from_trimesh(trimesh.Scene())
    with pytest.raises(FrustumError, match=r"resolution = .* is not \(width, height\)"):
        Scene.from_trimesh(trimesh.creation.box(), resolution=(0, 10))
