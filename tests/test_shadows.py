"""Shadows (``render(..., shadows=...)``, ``render.shadows.fractions``): shadow maps and shadow rays against Embree.

Oracle: Embree through ``embreex`` (ORACLES.md): from each drawn pixel's ``Frame.position``, moved off the surface
along ``Frame.normals``, a ray toward the light; the pixel is in shadow where Embree finds a hit nearer than the
light. Shadow maps agree on >= 99 % of the drawn pixels (the rest within 2 pixels of an edge of the oracle's
shadow), shadow rays on >= 99.9 %.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy import ndimage

import frustum as fr
from frustum.geometry.primitives import box, plane, uv_sphere
from frustum.geometry.teapot import teapot as teapot_patches
from frustum.transforms import rotate_x, translate

embree_scene = pytest.importorskip("embreex.rtcore_scene")
mesh_construction = pytest.importorskip("embreex.mesh_construction")

GROUND = fr.Material(color=(0.8, 0.8, 0.8))
OFFSET = 1e-4
"""Oracle rays start this far along the normal: far above the float32 round-off of Frame.position (~5e-7 here),
far below a pixel (~0.03); ORACLES.md's 2e-3 shifts shadow edges by a visible fraction of a pixel at grazing rays."""


def _ground(scene: fr.Scene, size: float = 10.0) -> None:
    scene.add(plane((size, size), divisions=(4, 4)), GROUND, transform=rotate_x(-math.pi / 2))


def _sphere_and_box(light) -> fr.Scene:
    scene = fr.Scene(lights=[fr.AmbientLight(intensity=0.2), light])
    _ground(scene)
    scene.add(box((1, 1, 1), center=(0, 0.5, 0)), fr.Material(color=(0.9, 0.3, 0.2)))
    scene.add(uv_sphere(0.6, segments=48, rings=24), fr.Material(color=(0.2, 0.5, 0.9)),
              transform=translate(1.8, 0.6, 0.5))  # fmt: skip
    return scene


def _teapot_on_plane(light) -> fr.Scene:
    scene = fr.Scene(lights=[fr.AmbientLight(intensity=0.2), light])
    _ground(scene)
    teapot = teapot_patches().tessellate(8)
    scene.add(teapot, fr.Material(color=(0.9, 0.8, 0.3)), transform=rotate_x(-math.pi / 2) @ np.diag([0.6] * 3 + [1]))
    return scene


def _grille(light) -> fr.Scene:
    """Six slats 0.2 wide, 0.3 apart, 2 units above the ground, under a spot light."""
    scene = fr.Scene(lights=[fr.AmbientLight(intensity=0.2), light])
    _ground(scene)
    for k in range(6):
        scene.add(box((0.2, 0.05, 3.0), center=(-1.25 + 0.5 * k, 2.0, 0.0)), fr.Material(color=(0.4, 0.4, 0.4)))
    return scene


CAMERA = fr.Camera.look_at((4.0, 5.0, 7.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), width=320, height=240)
LIGHTS = {
    "directional": fr.DirectionalLight((1.0, -0.8, -0.3)),
    "point": fr.PointLight((-3.0, 3.0, 1.5)),
    "spot": fr.SpotLight((-3.0, 4.0, 0.0), (0.6, -1.0, 0.0), inner_angle=0.4, outer_angle=0.6),
}


def _world_triangles(scene: fr.Scene) -> np.ndarray:
    triangles = []
    for item in scene.items:
        m = np.asarray(item.world_from_model)
        world = item.mesh.vertices @ m[:3, :3].T + m[:3, 3]
        triangles.append(world[item.mesh.faces])
    return np.concatenate(triangles).astype(np.float32)


def embree_lit(scene: fr.Scene, frame: fr.Frame, light) -> np.ndarray:
    """(H, W) bool: True where Embree finds no surface between the drawn point and the light (NaN background:
    False, masked out by the callers)."""
    drawn = np.isfinite(frame.position[..., 0])
    points = frame.position[drawn].astype(np.float64)
    normals = frame.normals[drawn].astype(np.float64)
    if isinstance(light, fr.DirectionalLight):
        direction = np.broadcast_to(-np.asarray(light.direction), points.shape)
        distance = np.full(points.shape[0], np.inf)
    else:
        offset = np.asarray(light.position) - points
        distance = np.linalg.norm(offset, axis=1)
        direction = offset / distance[:, None]
    origins = points + OFFSET * normals
    rtc = embree_scene.EmbreeScene()
    mesh_construction.TriangleMesh(rtc, _world_triangles(scene))
    result = rtc.run(origins.astype(np.float32), np.ascontiguousarray(direction, dtype=np.float32), output=1)
    blocked = (result["primID"] >= 0) & (result["tfar"] < distance - OFFSET)
    lit = np.zeros(drawn.shape, dtype=bool)
    lit[drawn] = ~blocked
    return lit


def _agreement(frame: fr.Frame, oracle: np.ndarray, light=None) -> tuple[float, np.ndarray]:
    """Fraction of drawn pixels (inside a spot light's cone, for a spot) where the frame's lit/shadowed decision
    (fraction >= 0.5) equals the oracle's, and the mask of disagreeing pixels."""
    drawn = np.isfinite(frame.shadow[..., 0])
    if isinstance(light, fr.SpotLight):
        to_point = frame.position.astype(np.float64) - np.asarray(light.position)
        cos = (to_point @ np.asarray(light.direction)) / np.linalg.norm(to_point, axis=2)
        drawn &= cos > math.cos(light.outer_angle)
    ours = frame.shadow[..., 0] >= 0.5
    wrong = drawn & (ours != oracle)
    return 1.0 - wrong.sum() / drawn.sum(), wrong


def _near_oracle_edge(oracle: np.ndarray, drawn: np.ndarray, pixels: int = 2) -> np.ndarray:
    """Pixels within `pixels` of a change in the oracle's lit mask (over the drawn pixels)."""
    structure = np.ones((2 * pixels + 1, 2 * pixels + 1), dtype=bool)
    lit = oracle & drawn
    shadowed = ~oracle & drawn
    return ndimage.binary_dilation(lit, structure) & ndimage.binary_dilation(shadowed, structure)


SCENES = [("sphere_and_box", name) for name in LIGHTS] + [("teapot", "directional"), ("teapot", "point"),
                                                           ("grille", "spot")]  # fmt: skip


def _build(kind: str, light) -> fr.Scene:
    return {"sphere_and_box": _sphere_and_box, "teapot": _teapot_on_plane, "grille": _grille}[kind](light)


@pytest.mark.parametrize(("kind", "light_name"), SCENES)
def test_shadow_maps_agree_with_embree(kind, light_name):
    light = LIGHTS[light_name]
    scene = _build(kind, light)
    frame = fr.render(scene, CAMERA, shadows=True, buffers=("position", "normals", "shadow"),
                      cull_back_faces=kind != "teapot")  # fmt: skip
    oracle = embree_lit(scene, frame, light)
    agreement, wrong = _agreement(frame, oracle, light)
    shadowed = (frame.shadow[..., 0] < 0.5).sum()
    print(f"{kind}/{light_name}: shadow maps agree with Embree on {agreement:.4%}, {shadowed} shadowed pixels")
    assert shadowed > 100  # the scene does cast shadows into the picture
    assert agreement >= 0.99
    near_edge = _near_oracle_edge(oracle, np.isfinite(frame.shadow[..., 0]))
    assert not (wrong & ~near_edge).any(), np.argwhere(wrong & ~near_edge)[:10]


@pytest.mark.parametrize(("kind", "light_name"), SCENES)
def test_shadow_rays_agree_with_embree(kind, light_name):
    light = LIGHTS[light_name]
    scene = _build(kind, light)
    frame = fr.render(scene, CAMERA, shadows="ray", buffers=("position", "normals", "shadow"),
                      cull_back_faces=kind != "teapot")  # fmt: skip
    oracle = embree_lit(scene, frame, light)
    agreement, _ = _agreement(frame, oracle, light)
    print(f"{kind}/{light_name}: shadow rays agree with Embree on {agreement:.5%}")
    assert agreement >= 0.999


def _slats_and_items(light) -> fr.Scene:
    """Several items (issue 50): five thin slats 2 units above a ground plane, a box and a sphere on the ground."""
    scene = fr.Scene(lights=[fr.AmbientLight(intensity=0.2), light])
    _ground(scene)
    for k in range(5):
        scene.add(box((0.2, 0.05, 3.0), center=(-1.0 + 0.5 * k, 2.0, 0.0)), fr.Material(color=(0.4, 0.4, 0.4)))
    scene.add(box((1, 1, 1), center=(1.5, 0.5, 1.5)), fr.Material(color=(0.9, 0.3, 0.2)))
    scene.add(uv_sphere(0.6, segments=48, rings=24), fr.Material(color=(0.2, 0.5, 0.9)),
              transform=translate(-1.8, 0.6, 1.2))  # fmt: skip
    return scene


SLAT_LIGHTS = {
    "directional": fr.DirectionalLight((0.3, -1.0, -0.2)),
    "point": fr.PointLight((0.3, 5.0, 0.5)),
    "point_close": fr.PointLight((0.3, 2.6, 0.5)),
    "spot": fr.SpotLight((0.0, 5.0, 0.5), (0.0, -1.0, -0.1), inner_angle=0.5, outer_angle=0.7),
    "spot_close": fr.SpotLight((0.3, 2.8, 0.5), (0.1, -1.0, 0.0), inner_angle=0.9, outer_angle=1.1),
}


def _issue_mask(frame: fr.Frame, light) -> np.ndarray:
    """The pixels issue 50 compares: drawn, not grazing (|n·l| >= 0.1), inside a spot light's inner cone."""
    points = frame.position.astype(np.float64)
    drawn = np.isfinite(points[..., 0])
    if isinstance(light, fr.DirectionalLight):
        to_light = np.broadcast_to(-np.asarray(light.direction) / np.linalg.norm(light.direction), points.shape)
    else:
        to_light = np.asarray(light.position) - points
        to_light = to_light / np.linalg.norm(to_light, axis=2, keepdims=True)
    with np.errstate(invalid="ignore"):
        mask = drawn & (np.abs((frame.normals * to_light).sum(axis=2)) >= 0.1)
        if isinstance(light, fr.SpotLight):
            axis = np.asarray(light.direction) / np.linalg.norm(light.direction)
            mask &= -(to_light @ axis) > math.cos(light.inner_angle)
    return mask


@pytest.mark.parametrize("light_name", SLAT_LIGHTS)
def test_maps_and_rays_hold_every_caster_of_a_scene_of_several_items(light_name):
    """Shadow maps hold every caster that can shade a point in the light's reach: a spot map's (and a cube face's)
    near plane lies before every caster in its pyramid, not only before the nearest one on the axis (the far half
    of each slat's shadow was missing: 89 % agreement for "spot", 91 % for "spot_close")."""
    light = SLAT_LIGHTS[light_name]
    scene = _slats_and_items(light)
    for method, needed in ((True, 0.99), ("ray", 0.999)):
        frame = fr.render(scene, CAMERA, shadows=method, buffers=("position", "normals", "shadow"))
        oracle = embree_lit(scene, frame, light)
        mask = _issue_mask(frame, light)
        agreement = 1.0 - (mask & ((frame.shadow[..., 0] >= 0.5) != oracle)).sum() / mask.sum()
        print(f"{light_name} shadows={method}: {agreement:.4%} of {mask.sum()} pixels")
        assert (mask & ~oracle).sum() > 300  # shadows fall inside the compared pixels
        assert agreement >= needed, (method, agreement)


def test_no_acne_on_a_plane_lit_at_80_degrees():
    """A lit plane facing the light at 80° from its normal has no shadowed pixel (slope-scaled bias)."""
    for light in (
        fr.DirectionalLight((math.sin(math.radians(80.0)), -math.cos(math.radians(80.0)), 0.0)),
        fr.SpotLight((-11.0, 2.0, 0.0), (math.sin(math.radians(80.0)), -math.cos(math.radians(80.0)), 0.0),
                     inner_angle=0.5, outer_angle=0.6),
    ):  # fmt: skip
        scene = fr.Scene(lights=[light])
        _ground(scene)
        for softness in (0.0, 1.0, 3.0):
            frame = fr.render(scene, CAMERA, shadows=True, shadow_softness=softness, buffers=("shadow",))
            values = frame.shadow[..., 0][np.isfinite(frame.shadow[..., 0])]
            assert values.size > 10000
            assert (values == 1.0).all(), (type(light).__name__, softness, (values < 1.0).sum())


def test_box_on_plane_shadow_touches_its_base():
    """Contact: no gap between a box resting on the plane and its shadow (no peter-panning): every ground pixel
    that the exact shadow rays put in shadow and that the map calls lit lies within one pixel of the box's base
    (or within 2 pixels of the shadow's edges on the ground, where the filter blurs)."""
    light = fr.DirectionalLight((1.0, -0.6, 0.4))
    scene = fr.Scene(lights=[light])
    _ground(scene)
    scene.add(box((1, 1, 1), center=(0, 0.5, 0)), fr.Material())
    camera = fr.Camera.look_at((3.0, 2.5, 4.0), (0.5, 0.0, 0.0), (0.0, 1.0, 0.0), width=400, height=300)
    exact = fr.render(scene, camera, shadows="ray", buffers=("shadow", "position"))
    mapped = fr.render(scene, camera, shadows=True, buffers=("shadow",))
    ground = np.abs(exact.position[..., 1]) < 1e-6
    exact_lit = exact.shadow[..., 0] >= 0.5
    # where the map calls lit what the rays shadow, away from the shadow's edges on the ground (filtered there)
    gap = ground & ~exact_lit & (mapped.shadow[..., 0] >= 0.5) & ~_near_oracle_edge(exact_lit, ground)
    # image distance of each gap pixel to the box's base square (its four edges projected)
    corners = np.array([[-0.5, 0, -0.5], [0.5, 0, -0.5], [0.5, 0, 0.5], [-0.5, 0, 0.5]])
    window = camera.project(corners)[:, :2]
    rows, cols = np.nonzero(gap)
    centres = np.stack([cols + 0.5, camera.height - 1 - rows + 0.5], axis=1)
    distance = np.full(centres.shape[0], np.inf)
    for k in range(4):
        a, b = window[k], window[(k + 1) % 4]
        t = np.clip(((centres - a) @ (b - a)) / ((b - a) @ (b - a)), 0.0, 1.0)
        distance = np.minimum(distance, np.linalg.norm(centres - (a + t[:, None] * (b - a)), axis=1))
    shadowed = (ground & (exact.shadow[..., 0] < 0.5)).sum()
    assert shadowed > 1000
    assert (distance <= 1.0 + 0.5 * math.sqrt(2)).all(), np.sort(distance)[-5:]  # within one pixel (centre to edge)


def test_shadows_off_changes_no_byte():
    scene = _sphere_and_box(LIGHTS["directional"])
    plain = fr.render(scene, CAMERA)
    for shadows in (None, False):
        frame = fr.render(scene, CAMERA, shadows=shadows, shadow_map_size=256, shadow_softness=3.0)
        assert np.array_equal(frame.color, plain.color) and np.array_equal(frame.depth, plain.depth)
        assert frame.shadow is None and frame.position is None


@pytest.mark.parametrize("light_name", list(LIGHTS))
def test_lights_that_cast_no_shadow_give_the_unshadowed_bytes(light_name):
    """Phong with every light's cast_shadows False: the shadowed shading kernel gives the plain picture's bytes."""
    light = dataclasses.replace(LIGHTS[light_name], cast_shadows=False)
    scene = _sphere_and_box(light)
    plain = fr.render(scene, CAMERA)
    for shadows in (True, "ray"):
        frame = fr.render(scene, CAMERA, shadows=shadows, buffers=("shadow",))
        assert frame.shadow.shape == (*plain.depth.shape, 0)
        assert np.array_equal(frame.color, plain.color)


@pytest.mark.parametrize("shading", ["phong", "gouraud", "flat"])
def test_shadowed_ground_is_darker_in_every_shading_mode(shading):
    scene = _sphere_and_box(LIGHTS["directional"])
    lit = fr.render(scene, CAMERA, shading=shading, buffers=("object_id",))
    frame = fr.render(scene, CAMERA, shading=shading, shadows=True, buffers=("shadow", "object_id"))
    ground = frame.object_id == 0
    shadowed = ground & (frame.shadow[..., 0] == 0.0)
    sunny = ground & (frame.shadow[..., 0] == 1.0)
    assert shadowed.sum() > 300
    # in shadow only the ambient term is left; in the sun the picture equals the unshadowed one within a level
    assert (frame.color[shadowed][:, :3].astype(int) < lit.color[shadowed][:, :3].astype(int) - 40).all()
    assert np.abs(frame.color[sunny].astype(int) - lit.color[sunny].astype(int)).max() <= 1


def test_position_buffer_is_the_unprojected_depth():
    scene = _sphere_and_box(LIGHTS["point"])
    frame = fr.render(scene, CAMERA, buffers=("position",))
    drawn = frame.depth < 1.0
    assert np.isnan(frame.position[~drawn]).all() and np.isfinite(frame.position[drawn]).all()
    rows, cols = np.nonzero(drawn)
    window = np.stack([cols + 0.5, CAMERA.height - 1 - rows + 0.5, frame.depth[drawn]], axis=1)
    expected = CAMERA.unproject(window)
    # float32 window depth: its round-off (~6e-8) times dz/d(depth) of a perspective camera at ~8 units
    assert np.abs(frame.position[drawn] - expected).max() < 2e-3
    assert frame.position.dtype == np.float32 and not frame.position.flags.writeable


def test_shadows_with_other_methods_and_supersampling():
    scene = _sphere_and_box(LIGHTS["directional"])
    reference = fr.render(scene, CAMERA, shadows="ray", buffers=("shadow",))
    for method in ("scan-line", "ray-casting"):
        frame = fr.render(scene, CAMERA, method=method, shadows=True, buffers=("shadow",))
        both = np.isfinite(frame.shadow) & np.isfinite(reference.shadow)
        assert ((frame.shadow[both] >= 0.5) == (reference.shadow[both] >= 0.5)).mean() > 0.995
    big = fr.render(scene, CAMERA, shadows=True, samples=4, buffers=("shadow", "position"))
    assert big.shadow.shape == (CAMERA.height, CAMERA.width, 1)
    assert big.position.shape == (CAMERA.height, CAMERA.width, 3)


def test_light_order_of_the_shadow_buffer():
    """Channels follow Scene.world_lights: the root's lights first, then lights riding nodes; lights with
    cast_shadows=False and ambient lights have none."""
    left = fr.DirectionalLight((1.0, -0.8, -0.3))
    unshadowing = fr.DirectionalLight((0.0, -1.0, 0.0), cast_shadows=False)
    scene = _sphere_and_box(left)
    scene.root.lights.append(unshadowing)
    rider = fr.Node("lamp", translate(0.0, 0.0, 0.0))
    rider.add_light(fr.PointLight((3.0, 3.0, -2.0)))
    scene.add(rider)
    frame = fr.render(scene, CAMERA, shadows="ray", buffers=("shadow",))
    assert frame.shadow.shape[2] == 2
    alone = fr.render(_sphere_and_box(left), CAMERA, shadows="ray", buffers=("shadow",))
    assert np.array_equal(frame.shadow[..., 0], alone.shadow[..., 0], equal_nan=True)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"shadows": True, "shadow_map_size": 100}, r"shadow_map_size = 100 is not a power of two in \[64, 16384\]"),
        ({"shadows": True, "shadow_map_size": 32}, r"shadow_map_size = 32 is not a power of two"),
        ({"shadows": True, "shadow_map_size": 32768}, r"shadow_map_size = 32768 is not a power of two"),
        ({"shadows": True, "shadow_map_size": 2048.0}, r"shadow_map_size = 2048.0 is not an integer"),
        ({"shadows": True, "shadow_softness": -1}, r"shadow_softness = -1 is not a number in \[0, 16\]"),
        ({"shadows": True, "shadow_softness": "soft"}, r"shadow_softness = 'soft' is not a number"),
        ({"shadows": "maps"}, r"shadows = 'maps' is unknown; expected None"),
        ({"shadows": True, "mode": "wireframe"}, r"shadows = True with mode = 'wireframe'"),
        ({"shadows": True, "mode": "hidden-line"}, r"mode = 'hidden-line'"),
        ({"shadows": True, "method": "a-buffer"}, r"not available with method = 'a-buffer'"),
        ({"buffers": ("shadow",)}, r"asks for 'shadow' with shadows = None; give shadows=True or 'ray'"),
        ({"buffers": ("position",), "mode": "points"}, r"asks for 'position' with mode = 'points'"),
    ],
)
def test_bad_shadow_arguments(options, message):
    scene = _sphere_and_box(LIGHTS["point"])
    with pytest.raises(fr.FrustumError, match=message):
        fr.render(scene, CAMERA, **options)


def test_cube_maps_over_the_memory_budget():
    scene = _sphere_and_box(LIGHTS["point"])
    with fr.budget(bytes=2**30), pytest.raises(fr.FrustumError, match=r"shadow_map_size = 8192 .* point light.*budget"):
        fr.render(scene, CAMERA, shadows=True, shadow_map_size=8192)


def test_cast_shadows_must_be_a_bool():
    with pytest.raises(fr.FrustumError, match=r"PointLight: cast_shadows = 'yes' is not a bool"):
        fr.PointLight((0, 1, 0), cast_shadows="yes")
    with pytest.raises(fr.FrustumError, match=r"SpotLight: cast_shadows = 1 is not a bool"):
        fr.SpotLight((0, 1, 0), (0, -1, 0), cast_shadows=1)
    assert fr.DirectionalLight((0, -1, 0)).cast_shadows is True


# --- scene files and the CLI ------------------------------------------------------------------------------

SCENE_TOML = """
[render]
size = [96, 72]
{render}

[camera]
eye = [4.0, 5.0, 7.0]
target = [0.0, 0.0, 0.0]

[[lights]]
type = "directional"
direction = [1.0, -0.8, -0.3]
{light}

[[nodes]]
geometry = {{ type = "plane", size = [10.0, 10.0] }}
transform = [{{ rotate_x_deg = -90 }}]

[[nodes]]
geometry = {{ type = "box", center = [0.0, 0.5, 0.0] }}
"""


def _scene_file(tmp_path, render="", light=""):
    path = tmp_path / "shadows.toml"
    path.write_text(SCENE_TOML.format(render=render, light=light))
    return path


@pytest.mark.parametrize("value", ["true", '"ray"'])
def test_scene_file_shadows(tmp_path, value):
    from frustum.scenefile import load_scene_file, render_scene_file

    loaded = load_scene_file(_scene_file(tmp_path, f"shadows = {value}\nshadow_map_size = 512\nshadow_softness = 0"))
    assert loaded.options["shadows"] == (True if value == "true" else "ray")
    assert loaded.options["shadow_map_size"] == 512 and loaded.options["shadow_softness"] == 0
    shadowed = fr.render(loaded.scene, loaded.camera, **loaded.options)
    plain = fr.render(loaded.scene, loaded.camera, **{**loaded.options, "shadows": False})
    assert (shadowed.color[..., :3].astype(int).sum(axis=2) < plain.color[..., :3].astype(int).sum(axis=2)).sum() > 50
    written = render_scene_file(_scene_file(tmp_path, f"shadows = {value}"), tmp_path / "out.png")
    assert written.is_file()


def test_scene_file_light_without_shadows(tmp_path):
    from frustum.scenefile import load_scene_file

    loaded = load_scene_file(_scene_file(tmp_path, "shadows = true", "cast_shadows = false"))
    assert [light.cast_shadows for light in loaded.scene.world_lights()] == [False]
    frame = fr.render(loaded.scene, loaded.camera, **loaded.options)
    plain = fr.render(loaded.scene, loaded.camera, **{**loaded.options, "shadows": False})
    assert np.array_equal(frame.color, plain.color)


@pytest.mark.parametrize(
    ("render", "light", "message"),
    [
        ('shadows = "maps"', "", r"shadows.* is not a shadow method"),
        ("shadow_map_size = 32", "", r"shadow_map_size"),
        ("", 'cast_shadows = "yes"', r"cast_shadows"),
    ],
)
def test_scene_file_bad_shadows(tmp_path, render, light, message):
    from frustum.scenefile import load_scene_file

    with pytest.raises(fr.FrustumError, match=message):
        load_scene_file(_scene_file(tmp_path, render, light))


def test_cli_shadows_option(tmp_path):
    import subprocess
    import sys

    path = _scene_file(tmp_path)
    command = [sys.executable, "-m", "frustum", "render", str(path), "-o"]
    plain = subprocess.run([*command, str(tmp_path / "plain.png")], capture_output=True, text=True, timeout=600)
    shadowed = subprocess.run([*command, str(tmp_path / "ray.png"), "--shadows", "ray"], capture_output=True, text=True,
                              timeout=600)  # fmt: skip
    assert plain.returncode == 0 and shadowed.returncode == 0, shadowed.stderr
    from PIL import Image

    a = np.asarray(Image.open(tmp_path / "plain.png")).astype(int)
    b = np.asarray(Image.open(tmp_path / "ray.png")).astype(int)
    assert (b[..., :3].sum(axis=2) < a[..., :3].sum(axis=2)).sum() > 50
    bad = subprocess.run([*command, str(tmp_path / "x.png"), "--shadows", "maybe"], capture_output=True, text=True,
                         timeout=600)  # fmt: skip
    assert bad.returncode != 0 and "--shadows 'maybe' is unknown; expected on, off or ray" in bad.stderr
    assert len(bad.stderr.strip().splitlines()) == 1


# --- exact shadow polygons in vector drawings -------------------------------------------------------------

shapely = pytest.importorskip("shapely")


def _box_on_plane(light) -> fr.Scene:
    scene = fr.Scene(lights=[light])
    scene.add(plane((10, 10)), fr.Material(), transform=rotate_x(-math.pi / 2))
    scene.add(box((1, 1, 1), center=(0, 0.5, 0)), fr.Material())
    return scene


SVG_LIGHTS = {"directional": fr.DirectionalLight((1.0, -1.0, -0.5)), "point": fr.PointLight((-2.0, 3.0, 1.5))}


def _analytic_ground_shadow(light):
    """The box's shadow on the ground, (x, z): hull of its corners projected from the light, and its base."""
    corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (0.0, 1.0) for z in (-0.5, 0.5)])
    if isinstance(light, fr.DirectionalLight):
        d = np.asarray(light.direction)
        projected = corners - (corners[:, 1] / d[1])[:, None] * d
    else:
        p = np.asarray(light.position)
        projected = p + (p[1] / (p[1] - corners[:, 1]))[:, None] * (corners - p)
    hull = shapely.MultiPoint([tuple(q) for q in projected[:, [0, 2]]]).convex_hull
    base = shapely.Polygon([(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)])
    return hull, base


@pytest.mark.parametrize("light_name", list(SVG_LIGHTS))
def test_shadow_polygon_vertices_are_the_projected_silhouette(light_name):
    """Seen from above (orthographic), the ground's shadow polygon is the projection of the box's silhouette from
    the light less the base the box stands on: the same vertices to 1e-9."""
    light = SVG_LIGHTS[light_name]
    scene = _box_on_plane(light)
    camera = fr.Camera(fr.ViewFrame((0.0, 10.0, 0.0), target=(0.0, 0.0, 0.0), up=(0.0, 0.0, -1.0)),
                       fr.Orthographic(8.0, 0.1, 20.0), 400, 400)  # fmt: skip
    polygons = [p for p in fr.shadow_polygons(scene, camera) if p.item == 0]
    assert len(polygons) == 1 and polygons[0].kind == "cast" and len(polygons[0].loops) == 1
    loop = polygons[0].loops[0]
    hull, base = _analytic_ground_shadow(light)
    expected_xz = np.array(hull.difference(base).exterior.coords)[:-1]
    expected = camera.project(np.column_stack([expected_xz[:, 0], np.zeros(len(expected_xz)), expected_xz[:, 1]]))
    expected = expected[:, :2]
    assert loop.shape == expected.shape, (loop, expected)
    distances = np.linalg.norm(loop[:, None, :] - expected[None, :, :], axis=2)
    assert distances.min(axis=1).max() < 1e-9 and distances.min(axis=0).max() < 1e-9
    assert polygons[0].area == pytest.approx(hull.difference(base).area * (400 / 8.0) ** 2, rel=1e-9)


@pytest.mark.parametrize("light_name", list(SVG_LIGHTS))
def test_shadow_polygon_area_equals_the_rasterized_shadow(light_name):
    """Perspective view (the box hides part of its shadow): the polygons' area equals the area of the exact
    shadow rays' Frame.shadow, 16x supersampled, within 1 %."""
    light = SVG_LIGHTS[light_name]
    scene = _box_on_plane(light)
    eye, target = (3.0, 6.0, 5.0), (0.5, 0.0, 0.0)
    camera = fr.Camera.look_at(eye, target, (0.0, 1.0, 0.0), width=300, height=225)
    area = sum(p.area for p in fr.shadow_polygons(scene, camera))
    fine = fr.Camera.look_at(eye, target, (0.0, 1.0, 0.0), width=1200, height=900)
    frame = fr.render(scene, fine, shadows="ray", buffers=("shadow",))
    raster = float((frame.shadow[..., 0] < 0.5).sum()) / 16.0
    print(f"{light_name}: polygons {area:.2f} px², rasterized {raster:.2f} px²")
    assert raster > 300
    assert area == pytest.approx(raster, rel=0.01)


def test_render_svg_and_drawing_sheet_draw_the_shadows():
    scene = _box_on_plane(fr.sun_45())
    assert np.allclose(fr.sun_45().direction, np.array([1.0, -1.0, -1.0]) / math.sqrt(3.0))
    camera = fr.Camera.look_at((3.0, 6.0, 5.0), (0.5, 0.0, 0.0), (0.0, 1.0, 0.0), width=300, height=225)
    plain = fr.render_svg(scene, camera)
    assert 'id="shadows"' not in plain
    filled = fr.render_svg(scene, camera, fill=True, shadows=True)
    hatched = fr.render_svg(scene, camera, shadows=True)
    assert '<g id="shadows" fill="#000000" fill-opacity="0.35"' in filled
    assert 'fill="url(#shadow-hatch)"' in hatched and '<pattern id="shadow-hatch"' in hatched
    assert hatched.count('class="cast"') >= 1 and hatched.count('class="attached"') >= 1
    # the shadows lie under the lines: their group comes before the edges
    assert hatched.index('id="shadows"') < hatched.index('id="visible"')
    sheet = fr.drawing_sheet(scene, ("front", "top"), shadows=True)
    assert 'id="top-shadows"' in sheet and 'id="front-shadows"' in sheet
    with pytest.raises(fr.FrustumError, match=r"shadows = 'yes' is not a bool"):
        fr.render_svg(scene, camera, shadows="yes")


# --- the polygon operations of the vector shadows (properties) --------------------------------------------

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from frustum.output import svg_shadows  # noqa: E402

_coordinates = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)
_point_sets = st.lists(st.tuples(_coordinates, _coordinates), min_size=3, max_size=8)


def _convex(points):
    from scipy.spatial import ConvexHull, QhullError

    array = np.array(points, dtype=np.float64)
    try:
        hull = ConvexHull(array)
    except (QhullError, ValueError):
        return None
    polygon = array[hull.vertices]
    return polygon if hull.volume > 1e-3 else None  # counter-clockwise (Qhull's 2-D order)


@settings(max_examples=60, deadline=None)
@given(_point_sets, _point_sets)
def test_convex_difference_and_intersection_partition_the_polygon(a_points, b_points):
    a, b = _convex(a_points), _convex(b_points)
    if a is None or b is None:
        return
    tiny = 1e-18
    inside = svg_shadows._intersect(a, b)
    outside = svg_shadows._subtract(a, b, tiny)
    area = lambda p: abs(svg_shadows._signed_area(p)) if p.shape[0] >= 3 else 0.0  # noqa: E731
    # round-off of a few clipped corners of coordinates up to 10: 1e-9 of the area scale
    assert area(inside) + sum(area(p) for p in outside) == pytest.approx(area(a), abs=1e-9 * max(1.0, area(a)))
    for piece in outside:  # disjoint from B
        assert area(svg_shadows._intersect(svg_shadows._ccw(piece), b)) < 1e-9 * max(1.0, area(a))


@settings(max_examples=40, deadline=None)
@given(st.lists(_point_sets, min_size=1, max_size=4))
def test_outline_of_the_union_has_the_union_area(point_sets):
    polygons = [p for p in (_convex(points) for points in point_sets) if p is not None]
    if not polygons:
        return
    pieces = svg_shadows._disjoint_union(polygons, 1e-18)
    loops = svg_shadows._outline(pieces, 20.0)
    union = shapely.union_all([shapely.Polygon(p) for p in polygons])
    assert sum(svg_shadows._signed_area(loop) for loop in loops) == pytest.approx(union.area, abs=1e-6)


@pytest.mark.parametrize("format", ["nerf", "webdataset"])
def test_dataset_writes_position_and_shadow_for_a_scene_with_shadows(tmp_path, format):
    from frustum.batch import render_dataset

    path = _scene_file(tmp_path, "shadows = true")
    result = render_dataset(path, tmp_path / "out", views=2, format=format, executor="serial", progress=False)
    assert result.ok and len(result.rendered) == 2
    if format == "nerf":
        positions = sorted((tmp_path / "out" / "position").glob("*.npy"))
        shadows = sorted((tmp_path / "out" / "shadow").glob("*.npy"))
        assert len(positions) == 2 and len(shadows) == 2
        position, shadow = np.load(positions[0]), np.load(shadows[0])
        assert position.shape == (72, 96, 3) and shadow.shape == (72, 96, 1)
        assert np.array_equal(np.isnan(position[..., 0]), np.isnan(shadow[..., 0]))
        assert (shadow[np.isfinite(shadow)] == 0.0).any()
    plain = _scene_file(tmp_path, "")
    render_dataset(plain, tmp_path / "plain", views=1, format="nerf", executor="serial", progress=False)
    assert not (tmp_path / "plain" / "shadow").exists()


# --- one mesh: the tile pipeline with shadows (raster.shadow_tiled) -----------------------------------------------


def _one_mesh(scene: fr.Scene) -> fr.Scene:
    """`scene`'s items merged into one mesh in world space (one material): a frame the one-mesh tile pipeline
    draws."""
    vertices, normals, faces, base = [], [], [], 0
    for item in scene.items:
        m = np.asarray(item.world_from_model, dtype=np.float64)
        vertices.append(item.mesh.vertices @ m[:3, :3].T + m[:3, 3])
        turned = item.mesh.vertex_normals @ np.linalg.inv(m[:3, :3])
        normals.append(turned / np.linalg.norm(turned, axis=1, keepdims=True))
        faces.append(np.asarray(item.mesh.faces) + base)
        base += item.mesh.vertex_count
    merged = fr.Scene(lights=list(scene.lights))
    merged.add(fr.Mesh(np.concatenate(vertices), np.concatenate(faces), vertex_normals=np.concatenate(normals)),
               fr.Material(color=(0.9, 0.8, 0.3)))  # fmt: skip
    return merged


def _spy(monkeypatch, module, name: str, argument: int) -> list:
    """Record the shape of argument `argument` of each call of the kernel `module.name` (and call it)."""
    calls = []
    kernel = getattr(module, name)

    def spy(*args):
        calls.append(args[argument].shape)
        return kernel(*args)

    monkeypatch.setattr(module, name, spy)
    return calls


def _spy_tiled(monkeypatch) -> list:
    """Record each call of the shadowed tile kernel (so a test knows the one-mesh path drew its frame)."""
    from frustum.raster import shadow_tiled

    return _spy(monkeypatch, shadow_tiled, "draw_tiles_shadowed", 17)


def _fraction_from_colors(scene: fr.Scene, camera: fr.Camera, light, **options) -> tuple[np.ndarray, np.ndarray]:
    """The light's fraction at each pixel read back from the colors of a shadowed frame (a frame without
    buffers: the one-mesh tile pipeline), between the unshadowed frame (1) and the frame without that light (0);
    and where that is well defined (the light adds at least 24 levels)."""
    on = fr.render(scene, camera, shadows=True, **options).color[..., :3].astype(float)
    full = fr.render(scene, camera).color[..., :3].astype(float)
    without = fr.Scene(lights=[dataclasses.replace(x, intensity=0.0) if x is light else x for x in scene.lights])
    for item in scene.items:
        without.add(item.mesh, item.material, transform=item.world_from_model)
    none = fr.render(without, camera).color[..., :3].astype(float)
    span = full - none
    channel = np.argmax(span, axis=2)[..., None]
    top = np.take_along_axis(span, channel, axis=2)[..., 0]
    fraction = (np.take_along_axis(on - none, channel, axis=2)[..., 0]) / np.maximum(top, 1.0)
    return fraction, top >= 24.0


def test_one_mesh_tile_pipeline_shadows_agree_with_embree(monkeypatch):
    """The teapot and its ground as one mesh: the frame goes tile by tile with the map lookups in the shading
    (map fitted before drawing); its shadows, read back from the colors, agree with Embree's rays as the
    stage-by-stage path's must (>= 99 %, the rest within 2 pixels of an edge)."""
    light = LIGHTS["directional"]
    scene = _one_mesh(_teapot_on_plane(light))
    calls = _spy_tiled(monkeypatch)
    fraction, defined = _fraction_from_colors(scene, CAMERA, light, cull_back_faces=False)
    assert calls, "the one-mesh tile pipeline did not draw the frame"
    buffers = fr.render(scene, CAMERA, buffers=("position", "normals"), cull_back_faces=False)
    oracle = embree_lit(scene, buffers, light)
    drawn = np.isfinite(buffers.position[..., 0]) & defined
    wrong = drawn & ((fraction >= 0.5) != oracle)
    agreement = 1.0 - wrong.sum() / drawn.sum()
    shadowed = (drawn & (fraction < 0.5)).sum()
    print(f"one mesh: shadow maps agree with Embree on {agreement:.4%} of {drawn.sum()}, {shadowed} shadowed")
    assert shadowed > 500 and drawn.sum() > 20000
    assert agreement >= 0.99
    near_edge = _near_oracle_edge(oracle, np.isfinite(buffers.position[..., 0]))
    assert not (wrong & ~near_edge).any(), np.argwhere(wrong & ~near_edge)[:10]


def test_one_mesh_tile_pipeline_no_acne_and_no_shadow_without_casting_lights(monkeypatch):
    """A plane lit at 80° from its normal (one mesh, the tile pipeline with shadows) has the unshadowed frame's
    bytes at every softness (no pixel darkened: no acne); so does a frame whose light casts no shadow."""
    calls = _spy_tiled(monkeypatch)
    light = fr.DirectionalLight((math.sin(math.radians(80.0)), -math.cos(math.radians(80.0)), 0.0))
    scene = fr.Scene(lights=[light])
    _ground(scene)
    plain = fr.render(scene, CAMERA)
    for softness in (0.0, 0.5, 1.0, 3.0):
        frame = fr.render(scene, CAMERA, shadows=True, shadow_softness=softness)
        assert np.array_equal(frame.color, plain.color), softness
        assert np.array_equal(frame.depth, plain.depth)
    assert len(calls) == 4
    scene = _one_mesh(_teapot_on_plane(dataclasses.replace(LIGHTS["directional"], cast_shadows=False)))
    frame = fr.render(scene, CAMERA, shadows=True, cull_back_faces=False)
    assert len(calls) == 5
    assert np.array_equal(frame.color, fr.render(scene, CAMERA, cull_back_faces=False).color)


def test_one_mesh_tile_pipeline_matches_the_stage_by_stage_shading():
    """Where the one-mesh pipeline and the stage-by-stage path (forced by asking for a buffer) find the same
    fraction, they give the same bytes: the shading with shadows is the same in both (their maps are fitted
    differently, so fractions may differ near shadow edges)."""
    light = LIGHTS["directional"]
    scene = _one_mesh(_teapot_on_plane(light))
    tiled = fr.render(scene, CAMERA, shadows=True, cull_back_faces=False)
    staged = fr.render(scene, CAMERA, shadows=True, cull_back_faces=False, buffers=("shadow",))
    whole = np.isfinite(staged.shadow[..., 0]) & ((staged.shadow[..., 0] == 0.0) | (staged.shadow[..., 0] == 1.0))
    same = np.all(tiled.color == staged.color, axis=2)
    assert whole.sum() > 20000
    assert same[whole].mean() >= 0.99, same[whole].mean()
    assert np.array_equal(tiled.depth, staged.depth)


# --- receivers with bump or normal maps, or an environment to reflect -----------------------------------------------


def _box_on_ground(ground: fr.Material, environment=None) -> fr.Scene:
    scene = fr.Scene(lights=[fr.AmbientLight(intensity=0.2), LIGHTS["directional"]], environment=environment)
    scene.add(plane((10.0, 10.0), divisions=(4, 4)), ground, transform=rotate_x(-math.pi / 2))
    scene.add(box((1, 1, 1), center=(0, 0.5, 0)), fr.Material(color=(0.9, 0.3, 0.2)))
    return scene


def test_items_with_normal_or_bump_maps_receive_shadows():
    """A ground with a flat normal map (every texel the unperturbed normal) receives the same shadow as a plain
    ground (within a level); with a real bump map it is still darkened where the map puts the pixel in shadow."""
    flat_map = np.zeros((16, 16, 3), dtype=np.uint8)
    flat_map[:] = (128, 128, 255)
    plain = fr.render(_box_on_ground(GROUND), CAMERA, shadows=True, buffers=("shadow",))
    shadowed = plain.shadow[..., 0] == 0.0
    mapped = fr.render(_box_on_ground(dataclasses.replace(GROUND, normal_map=flat_map)), CAMERA, shadows=True)
    assert np.abs(mapped.color.astype(int) - plain.color.astype(int)).max() <= 1
    rng = np.random.default_rng(3)
    bumpy = dataclasses.replace(GROUND, bump=ndimage.gaussian_filter(rng.random((64, 64)), 2.0), bump_scale=0.3)
    lit = fr.render(_box_on_ground(bumpy), CAMERA)
    frame = fr.render(_box_on_ground(bumpy), CAMERA, shadows=True, buffers=("shadow", "object_id"))
    assert np.abs(lit.color.astype(int) - plain.color.astype(int))[~shadowed].max() > 3  # the bumps show
    assert np.array_equal(frame.shadow[..., 0] == 0.0, shadowed)
    dark = shadowed & (frame.object_id == 0)  # on the bumpy ground
    assert dark.sum() > 300
    # in shadow only the ambient term is left: clearly darker than the lit bumpy ground there
    assert (frame.color[dark][:, :3].astype(int) < lit.color[dark][:, :3].astype(int) - 20).mean() > 0.99
    sunny = frame.shadow[..., 0] == 1.0
    assert np.abs(frame.color[sunny].astype(int) - lit.color[sunny].astype(int)).max() <= 1


def test_reflective_items_receive_shadows():
    """A half-mirror ground under an environment: its shadowed pixels keep the reflection and lose the light
    (darker than without shadows by about (1 − reflectivity) of the light's share); its sunny pixels keep the
    unshadowed bytes."""
    env = np.zeros((16, 32, 3))
    env[:8] = (0.3, 0.5, 0.9)
    env[8:] = (0.4, 0.3, 0.2)
    ground = dataclasses.replace(GROUND, reflectivity=0.5)
    scene = _box_on_ground(ground, environment=fr.EnvironmentMap(env))
    lit = fr.render(scene, CAMERA)
    frame = fr.render(scene, CAMERA, shadows=True, buffers=("shadow", "object_id"))
    flat = fr.render(_box_on_ground(GROUND), CAMERA, shadows=True, buffers=("shadow",))
    assert np.array_equal(frame.shadow[..., 0] == 0.0, flat.shadow[..., 0] == 0.0)
    dark = (frame.shadow[..., 0] == 0.0) & (frame.object_id == 0)  # on the mirror ground
    assert dark.sum() > 300
    drop = lit.color[dark][:, :3].astype(int) - frame.color[dark][:, :3].astype(int)
    unreflected = fr.render(_box_on_ground(GROUND), CAMERA).color[dark][:, :3].astype(int) - flat.color[dark][:, :3]
    assert (np.abs(drop - 0.5 * unreflected) <= 1.5).all(), np.abs(drop - 0.5 * unreflected).max()
    assert drop.min() > 10
    sunny = frame.shadow[..., 0] == 1.0
    assert np.array_equal(frame.color[sunny], lit.color[sunny])


@pytest.mark.parametrize("closed", [True, False])
def test_depth_only_map_fill_equals_the_tile_rasterizer(closed):
    """``raster.shadow.fill_depth_tiles`` (depth alone, 64-pixel tiles, branch-free rows) writes the same map as
    ``raster.triangles.rasterize_tiles`` for the same items (a second item drawn over the first: fresh=False)."""
    from frustum.raster import shadow, triangles
    from frustum.render.shadows import fractions as render_shadows
    from frustum.render.stages import TILE_SIZE, bin_item

    scene = _sphere_and_box(LIGHTS["directional"])
    teapot = _teapot_on_plane(LIGHTS["directional"]).items[1]
    scene.add(teapot.mesh, teapot.material, transform=teapot.world_from_model)
    assert sum(bool(item.mesh.is_watertight) for item in scene.items) == 2  # the box and the sphere: culled
    light_camera = fr.Camera.look_at((3.0, 5.0, 2.0), (0.0, 0.5, 0.0), (0.0, 1.0, 0.0),
                                     projection=fr.Orthographic(6.0, 0.5, 12.0), width=512, height=384)  # fmt: skip
    ours = np.empty((384, 512), dtype=np.float32)
    theirs = np.ones((384, 512), dtype=np.float32)
    codes = np.zeros((384, 512), dtype=np.int64)
    bary = np.zeros((384, 512, 2), dtype=np.float32)
    for number, item in enumerate(reversed(scene.items)):
        render_shadows.draw_depth(item, light_camera, ours, number == 0) if closed else shadow.fill_depth_tiles(
            *_binned_fill_arguments(item, light_camera, ours), number == 0)  # fmt: skip
        binned = bin_item(item, light_camera, closed and bool(item.mesh.is_watertight))
        tiling = np.array([TILE_SIZE, binned.tiles_x, 0, 512, 384], dtype=np.int64)
        triangles.rasterize_tiles(binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float,
                                  binned.tri_weights, binned.tile_starts, binned.tile_entries, tiling, theirs, codes,
                                  bary)  # fmt: skip
    assert (theirs < 1.0).sum() > 20000
    assert np.array_equal(ours, theirs)



@pytest.mark.parametrize("light_name", ["directional", "point_close", "spot"])
def test_one_pass_fill_of_all_casters_equals_the_item_by_item_fill(light_name):
    """The casters of a scene of several items filled into each map in one pass per culling
    (``fractions.caster_groups``: the closed items merged, back faces skipped; the open ones merged, both sides)
    write the same maps as the items filled one after another."""
    from frustum.render.shadows import fractions

    light = SLAT_LIGHTS[light_name]
    items = list(_slats_and_items(light).items)
    scene_box = fractions._scene_box(items)
    cameras = fractions._light_cameras(light, np.array([[0.0, 0.0, 0.0], [1.0, 0.5, 1.0]]), scene_box, 512, 1.0)
    keys = [fractions.casters_key(item, bool(item.mesh.is_watertight)) for item in items]
    groups = fractions.caster_groups(items, keys)
    assert len(groups) == 2 and [cull for _, cull in groups] == [True, False]
    for light_camera, _ in cameras:
        one_by_one = np.empty((512, 512), dtype=np.float32)
        in_one_pass = np.empty((512, 512), dtype=np.float32)
        for number, item in enumerate(items):
            fractions.draw_depth(item, light_camera, one_by_one, number == 0)
        for number, (item, cull) in enumerate(groups):
            fractions.draw_depth(item, light_camera, in_one_pass, number == 0, cull)
        assert np.array_equal(one_by_one, in_one_pass)
    assert (one_by_one < 1.0).sum() > 1000


def test_several_items_go_through_the_tile_pipeline_with_shadows(monkeypatch):
    """A frame of several opaque items (each its own material) with a directional light's map is drawn tile by
    tile (``raster.shadow_tiled``, the items merged into one mesh, each face shaded with its item's parameters):
    the stage-by-stage path's depth, its bytes wherever both find a whole fraction (their maps are fitted
    differently), and shadows that agree with Embree's rays, read back from the colors."""
    light = SLAT_LIGHTS["directional"]
    scene = _slats_and_items(light)
    calls = _spy_tiled(monkeypatch)
    tiled = fr.render(scene, CAMERA, shadows=True)
    assert len(calls) == 1
    staged = fr.render(scene, CAMERA, shadows=True, buffers=("shadow", "position", "normals"))
    assert len(calls) == 1
    assert np.array_equal(tiled.depth, staged.depth)
    whole = np.isfinite(staged.shadow[..., 0]) & ((staged.shadow[..., 0] == 0.0) | (staged.shadow[..., 0] == 1.0))
    same = np.all(tiled.color == staged.color, axis=2)
    assert whole.sum() > 20000
    assert same[whole].mean() >= 0.99, same[whole].mean()
    fraction, defined = _fraction_from_colors(scene, CAMERA, light)
    oracle = embree_lit(scene, staged, light)
    drawn = _issue_mask(staged, light) & defined
    wrong = drawn & ((fraction >= 0.5) != oracle)
    agreement = 1.0 - wrong.sum() / drawn.sum()
    print(f"several items, tile pipeline: shadow maps agree with Embree on {agreement:.4%} of {drawn.sum()}")
    assert (drawn & ~oracle).sum() > 300
    assert agreement >= 0.99

def _binned_fill_arguments(item, camera, depth):
    from frustum.render.stages import TILED_BITS, bin_item

    binned = bin_item(item, camera, False, tile_bits=TILED_BITS)
    tiling = np.array([1 << TILED_BITS, binned.tiles_x, 0, depth.shape[1], depth.shape[0]], dtype=np.int64)
    return (binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tile_starts,
            binned.tile_entries, tiling, depth)  # fmt: skip


# --- shadow maps reused across frames (shadow_pass.kept_maps) -------------------------------------------------------


def _spy_fills(monkeypatch) -> list:
    """Record each depth-only map fill (a shadow map drawn, not reused)."""
    from frustum.raster import shadow

    return _spy(monkeypatch, shadow, "fill_depth_tiles", 8)


def _checked_frame(fills: list, scene: fr.Scene, camera: fr.Camera, **options) -> tuple[fr.Frame, int]:
    """A shadowed frame (kept maps reused where they still hold) and how many maps it drew (`fills` from
    ``_spy_fills``); its bytes are those of the same frame with every map drawn for it."""
    count = len(fills)
    frame = fr.render(scene, camera, shadows=True, **options)
    drawn = len(fills) - count
    assert np.array_equal(frame.color, _redrawn(scene, camera, **options).color)
    return frame, drawn


def _redrawn(scene: fr.Scene, camera: fr.Camera, **options) -> fr.Frame:
    """The frame with every shadow map drawn for it (reuse off)."""
    from frustum.render.shadows import fractions as shadow_pass

    previous = shadow_pass.set_map_reuse(False)
    try:
        return fr.render(scene, camera, shadows=True, **options)
    finally:
        shadow_pass.set_map_reuse(previous)


def _orbit(angle: float) -> fr.Camera:
    return fr.Camera.look_at((8.0 * math.cos(angle), 5.0, 8.0 * math.sin(angle)), (0.0, 0.5, 0.0), (0.0, 1.0, 0.0),
                             width=200, height=160)  # fmt: skip


def _small_teapot_on_plane(light) -> fr.Scene:
    """The teapot on a 3 × 3 ground, as one mesh: ``_orbit``'s cameras see all of it."""
    scene = fr.Scene(lights=[fr.AmbientLight(intensity=0.2), light])
    _ground(scene, 3.0)
    teapot = _teapot_on_plane(light).items[1]
    scene.add(teapot.mesh, teapot.material, transform=teapot.world_from_model)
    return _one_mesh(scene)


def test_a_reused_shadow_map_gives_the_bytes_of_a_redrawn_one(monkeypatch):
    """A turntable (the camera orbits a model it sees whole, the light fixed): the one-mesh tile pipeline draws the
    map once and reuses it for every view (the map is fitted to what the camera sees, here all of the model);
    every frame has the bytes of the same frame with its map drawn for it."""
    from frustum.render.shadows import fractions as shadow_pass

    shadow_pass.release_memory()
    scene = _small_teapot_on_plane(LIGHTS["directional"])
    fills = _spy_fills(monkeypatch)
    calls = _spy_tiled(monkeypatch)
    drawn = []
    for angle in np.linspace(0.0, 2.0 * math.pi, 5, endpoint=False):
        frame, count = _checked_frame(fills, scene, _orbit(angle), cull_back_faces=False)
        drawn.append(count)
    assert drawn == [1, 0, 0, 0, 0]  # drawn for the first view only
    assert len(fills) == 6 and len(calls) == 10  # the five reference frames drew their own maps
    plain = fr.render(scene, _orbit(0.0), cull_back_faces=False).color
    assert not np.array_equal(frame.color, plain)  # there are shadows to get right


def test_a_changed_mesh_light_or_map_size_draws_the_map_again(monkeypatch):
    """The kept map is not reused once anything it depends on changes: the vertices changed in place (a mesh made
    with copy=False shares the caller's array), the faces, the light's direction, the map's size or softness (its
    fitted margin), the modeling transform; each frame equals the frame drawn without reuse."""
    from frustum.render.shadows import fractions as shadow_pass

    shadow_pass.release_memory()
    merged = _small_teapot_on_plane(LIGHTS["directional"]).items[0].mesh
    vertices = np.array(merged.vertices)
    faces = np.array(merged.faces, dtype=np.int32)
    mesh = fr.Mesh(vertices, faces, vertex_normals=merged.vertex_normals, copy=False)
    light = LIGHTS["directional"]

    def scene_of(mesh, light, transform=None):
        scene = fr.Scene(lights=[fr.AmbientLight(intensity=0.2), light])
        scene.add(mesh, fr.Material(color=(0.9, 0.8, 0.3)), transform=transform)
        return scene

    fills = _spy_fills(monkeypatch)
    camera = _orbit(0.7)
    steps = []

    def frame(scene, **options):
        picture, count = _checked_frame(fills, scene, camera, cull_back_faces=False, **options)
        steps.append(count)
        return picture

    first = frame(scene_of(mesh, light))
    frame(scene_of(mesh, light))  # the same: reused
    lifted = vertices[:, 1] > 1.0  # the teapot's upper part moves: its shadow moves
    vertices[lifted, 0] += 0.4
    moved = frame(scene_of(mesh, light))
    assert not np.array_equal(moved.color, first.color)
    frame(scene_of(mesh, light))  # reused again
    faces[:, [1, 2]] = faces[:, [2, 1]]  # the faces turned over (in place)
    frame(scene_of(mesh, light))
    faces[:, [1, 2]] = faces[:, [2, 1]]
    frame(scene_of(mesh, dataclasses.replace(light, direction=(1.0, -0.9, -0.3))))
    frame(scene_of(mesh, light), shadow_map_size=1024)
    frame(scene_of(mesh, light), shadow_softness=3.0)
    frame(scene_of(mesh, light, transform=translate(0.0, 1e-3, 0.0)))
    assert steps == [1, 0, 1, 0, 1, 1, 1, 1, 1], steps


def test_map_reuse_can_be_turned_off_and_memory_released(monkeypatch):
    """``set_map_reuse(False)`` draws every frame's map; ``release_memory`` frees the kept ones (the next frame
    draws its map again)."""
    from frustum.render.shadows import fractions as shadow_pass

    scene = _one_mesh(_teapot_on_plane(LIGHTS["directional"]))
    fills = _spy_fills(monkeypatch)
    fr.render(scene, CAMERA, shadows=True)
    fr.render(scene, CAMERA, shadows=True)
    drawn = len(fills)
    assert drawn <= 1
    assert fr.release_memory() >= 2048 * 2048 * 4
    fr.render(scene, CAMERA, shadows=True)
    assert len(fills) == drawn + 1
    assert shadow_pass.set_map_reuse(False) is True
    try:
        fr.render(scene, CAMERA, shadows=True)
        fr.render(scene, CAMERA, shadows=True)
        assert len(fills) == drawn + 3
    finally:
        assert shadow_pass.set_map_reuse(True) is False


def test_a_kept_map_set_is_held_by_one_frame_at_a_time():
    """``kept_maps`` hands a kept set to one caller until ``keep_maps`` takes it back (a frame drawing on another
    thread meanwhile draws its own, so a set in use never goes back to the work-array pool); past ``KEPT_MAPS``
    sets the least recently used one goes to the pool."""
    from frustum.render.shadows import fractions as shadow_pass

    shadow_pass.release_memory()
    shape = (1, 64, 64)
    first, second, third = (np.full(shape, value, dtype=np.float32) for value in (0.25, 0.5, 0.75))
    shadow_pass.keep_maps(("a",), first)
    held = shadow_pass.kept_maps(("a",), shape)
    assert held is first
    assert shadow_pass.kept_maps(("a",), shape) is None  # in use
    assert shadow_pass.kept_maps(("a",), (1, 32, 32)) is None
    shadow_pass.keep_maps(("a",), held)
    shadow_pass.keep_maps(("b",), second)
    shadow_pass.keep_maps(("c",), third)  # "a" is the least recently used of three: back to the pool
    assert shadow_pass.kept_maps(("a",), shape) is None
    assert shadow_pass.take_array(shape, np.float32) is first
    assert shadow_pass.kept_maps(("b",), shape) is second
    assert shadow_pass.set_map_reuse(True) is True
    assert shadow_pass.map_key(None, [], np.zeros((1, 1))) is None
    shadow_pass.release_memory()


def _sphere_items_scene(subdivisions: int) -> fr.Scene:
    """Issue 50's scene for vector shadows: a ground plane, five slats, a box and an icosphere of 20·4^k faces."""
    scene = fr.Scene(lights=[fr.AmbientLight(intensity=0.2), fr.DirectionalLight((0.3, -1.0, -0.2)),
                             fr.PointLight((0.3, 5.0, 0.5))])  # fmt: skip
    _ground(scene)
    for k in range(5):
        scene.add(box((0.2, 0.05, 3.0), center=(-1.0 + 0.5 * k, 2.0, 0.0)), fr.Material(color=(0.4, 0.4, 0.4)))
    scene.add(box((1, 1, 1), center=(1.5, 0.5, 1.5)), fr.Material(color=(0.9, 0.3, 0.2)))
    scene.add(fr.icosphere(0.6, subdivisions), fr.Material(color=(0.2, 0.5, 0.9)), transform=translate(-1.8, 0.6, 1.2))
    return scene


def _same_polygons(ours: list, reference: list) -> None:
    """Same regions: per (light, item, kind), the same area (to 1e-9 relative) and the same outline corners (each
    corner of one within 1e-6 pixel of a corner of the other)."""

    def by_key(polygons):
        grouped: dict[tuple, list] = {}
        for p in polygons:
            grouped.setdefault((p.light, p.item, p.kind), []).append(p)
        return grouped

    mine, theirs = by_key(ours), by_key(reference)
    assert mine.keys() == theirs.keys()
    for key in mine:
        area = sum(p.area for p in mine[key])
        assert area == pytest.approx(sum(p.area for p in theirs[key]), rel=1e-9, abs=1e-9), key
        a = np.concatenate([loop for p in mine[key] for loop in p.loops])
        b = np.concatenate([loop for p in theirs[key] for loop in p.loops])
        distance = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2)
        assert distance.min(axis=1).max() <= 1e-6 and distance.min(axis=0).max() <= 1e-6, key


def test_shadow_polygons_through_the_grids_equal_all_pairs_on_a_5120_face_sphere_scene(monkeypatch):
    """The candidate search (grids of boxes in the light's projection and the window) and the faces skipped on
    closed items change no polygon: on a subset of receiving faces (ground faces in the sphere's and the slats'
    shadows, sphere and box faces, slats), the polygons equal those of every face tried against every face."""
    from frustum.output import svg_shadows

    scene = _sphere_items_scene(4)
    faces = svg_shadows._scene_faces(scene, CAMERA)
    assert faces.corners.shape[0] > 5120
    rng = np.random.default_rng(50)
    subset = np.zeros(faces.corners.shape[0], dtype=bool)
    for item in np.unique(faces.item)[1:]:
        mine = np.flatnonzero(faces.item == item)
        subset[rng.choice(mine, size=min(mine.size, 2), replace=False)] = True
    ground = np.flatnonzero(faces.item == 0)
    middle = np.linalg.norm(faces.corners[ground].mean(axis=1) - [-0.5, 0.0, 0.5], axis=1)
    subset[ground[np.argsort(middle)[:4]]] = True  # the ground faces under the slats and the sphere
    fast = svg_shadows._shadow_polygons(scene, CAMERA, subset)
    assert len(fast) >= 8

    class AllPairs(svg_shadows._Grid):
        def query(self, box):
            return np.arange(self.boxes.shape[0])

    monkeypatch.setattr(svg_shadows, "_Grid", AllPairs)
    monkeypatch.setattr(svg_shadows, "_turned_away", lambda faces, *_: np.zeros(faces.corners.shape[0], bool))
    _same_polygons(fast, svg_shadows._shadow_polygons(scene, CAMERA, subset))


@pytest.mark.parametrize("light_name", ["point", "spot"])
def test_maps_of_a_scene_of_several_items_are_reused_across_views(monkeypatch, light_name):
    """A scene of several items (the stage-by-stage path) under a point light (a cube of six maps) or a spot light:
    the maps follow the light and the casters' box, not the view, so a turntable draws them once; every frame has
    the bytes of the same frame with its maps drawn for it; another item in the scene draws them again."""
    from frustum.render.shadows import fractions as shadow_pass

    shadow_pass.release_memory()
    light = SLAT_LIGHTS[light_name]
    scene = _slats_and_items(light)
    fills = _spy_fills(monkeypatch)
    drawn = []
    for angle in np.linspace(0.0, 2.0 * math.pi, 4, endpoint=False):
        frame, count = _checked_frame(fills, scene, _orbit(angle))
        drawn.append(count)
    per_set = (6 if light_name == "point" else 1) * 2  # each map filled in one pass per culling: closed, open
    assert drawn == [per_set, 0, 0, 0]
    assert not np.array_equal(frame.color, fr.render(scene, _orbit(0.0)).color)  # there are shadows
    moved = _slats_and_items(light)
    moved.add(box((0.3, 0.3, 0.3), center=(0.0, 0.15, 0.0)), fr.Material())
    count = len(fills)
    fr.render(moved, _orbit(0.0), shadows=True)
    assert len(fills) - count == per_set
