"""Shadows (``render(..., shadows=...)``, ``frustum.shadow_pass``): shadow maps and shadow rays against Embree.

Oracle: Embree through ``embreex`` (ORACLES.md): from each drawn pixel's ``Frame.position``, moved off the surface
along ``Frame.normals``, a ray toward the light; the pixel is in shadow where Embree finds a hit nearer than the
light. Shadow maps agree on >= 99 % of the drawn pixels (the rest within 2 pixels of an edge of the oracle's
shadow), shadow rays on >= 99.9 %.
"""

from __future__ import annotations

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
