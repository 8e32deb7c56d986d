"""One light model (docs/architecture.md): the same lit scene through the depth buffer (the shading kernels,
``raster.light``), ray casting (the same kernels on the hits of a BVH) and Whitted ray tracing without mirrors or
shadows (``shading.light`` in NumPy) gives the same colours, within one level, with a directional, a point and a
spot light, with and without attenuation. A fix to attenuation or the spot cone made in one place and not the
other fails here.

Oracle: the three methods against each other (two code paths of the light model, two ways of finding the surface).
Pixels on an item's outline are left out: there the rasterizer's coverage (pixel centres) and a ray's hit may
pick different items; everywhere else the surface point is the same up to float32 barycentrics (~1e-7)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from frustum import Camera, Perspective
from frustum.geometry import plane, uv_sphere
from frustum.render import render
from frustum.scene import Scene
from frustum.shading import AmbientLight, DirectionalLight, Material, PointLight, SpotLight
from frustum.transforms import compose, rotate_x, scale, translate

ATTENUATION = {"no attenuation": (1.0, 0.0, 0.0), "attenuation": (1.0, 0.09, 0.032)}


def lit_scene(attenuation: tuple[float, float, float]) -> tuple[Scene, Camera]:
    """A floor and two spheres under a directional, a point and a spot light (the spot's cone edge on the floor)."""
    lights = [
        AmbientLight(intensity=0.1),
        DirectionalLight(direction=(-0.3, -1.0, -0.4), intensity=0.35),
        PointLight(position=(-1.5, 1.8, 1.5), color=(1.0, 0.8, 0.6), intensity=0.8, attenuation=attenuation),
        SpotLight(position=(1.2, 3.0, 0.5), direction=(-0.3, -1.0, -0.2), color=(0.6, 0.8, 1.0), intensity=0.9,
                  inner_angle=math.radians(15.0), outer_angle=math.radians(28.0), attenuation=attenuation),
    ]  # fmt: skip
    scene = Scene(lights=lights)
    floor = compose(scale(6.0, 6.0, 1.0), rotate_x(-math.pi / 2))
    scene.add(plane(divisions=(8, 8)), Material(color=(0.8, 0.8, 0.75), specular=0.2, shininess=16.0), floor)
    scene.add(uv_sphere(0.8, 96, 48), Material(color=(0.9, 0.3, 0.2), specular=0.6, shininess=40.0),
              translate(-0.6, 0.8, 0.0))  # fmt: skip
    scene.add(uv_sphere(0.5, 96, 48), Material(color=(0.2, 0.5, 0.9), specular=0.5, shininess=7.5),
              translate(1.1, 0.5, 0.6))  # fmt: skip
    camera = Camera.look_at((0.5, 3.0, 5.5), (0.2, 0.4, 0.0), projection=Perspective(math.radians(40), 0.1, 50.0),
                            width=160, height=120)  # fmt: skip
    return scene, camera


def _interior(object_id: np.ndarray) -> np.ndarray:
    """Pixels whose 3 × 3 neighbourhood shows one item: away from outlines and from the background."""
    padded = np.pad(object_id, 1, constant_values=-1)
    same = np.ones(object_id.shape, dtype=bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            shifted = padded[1 + dy : 1 + dy + object_id.shape[0], 1 + dx : 1 + dx + object_id.shape[1]]
            same &= shifted == object_id
    return same & (object_id >= 0)


@pytest.mark.parametrize("shading_specular", ["blinn-phong", "phong"])
@pytest.mark.parametrize("name", list(ATTENUATION))
def test_one_lit_scene_has_the_same_colours_by_every_method(name, shading_specular):
    scene, camera = lit_scene(ATTENUATION[name])
    frames = {
        method: render(scene, camera, method=method, specular=shading_specular, shadows=False, buffers=("object_id",))
        for method in ("depth-buffer", "ray-casting", "ray-tracing")
    }
    reference = frames["depth-buffer"]
    inside = _interior(reference.object_id)
    assert inside.mean() > 0.5  # the scene fills the picture: the comparison covers most of it
    lit = reference.color[inside, :3].astype(int)
    assert lit.max() > 200 and len(np.unique(lit // 16, axis=0)) > 20  # highlights and a range of shades
    for method in ("ray-casting", "ray-tracing"):
        frame = frames[method]
        same = inside & (frame.object_id == reference.object_id)
        assert same.sum() >= 0.999 * inside.sum(), method
        difference = np.abs(frame.color[same].astype(int) - reference.color[same].astype(int)).max(axis=1)
        assert difference.max() <= 1, (method, name, int(difference.max()), int((difference > 1).sum()))


def test_the_attenuation_and_the_spot_light_show_in_the_picture():
    # the comparison above is not vacuous: attenuation darkens the picture, and the spot light lights a part of it
    scene, camera = lit_scene(ATTENUATION["no attenuation"])
    plain = render(scene, camera, method="ray-tracing", shadows=False)
    faded = render(*lit_scene(ATTENUATION["attenuation"]), method="ray-tracing", shadows=False)
    assert faded.color[..., :3].astype(int).sum() < plain.color[..., :3].astype(int).sum()
    assert (np.abs(faded.color.astype(int) - plain.color.astype(int)).max(axis=2) > 8).mean() > 0.2
    no_spot = Scene(lights=[light for light in scene.lights if not isinstance(light, SpotLight)])
    for item in scene.items:
        no_spot.add(item.mesh, item.material, item.world_from_model)
    unlit = render(no_spot, camera, method="ray-tracing", shadows=False)
    brighter = (plain.color[..., :3].astype(int) - unlit.color[..., :3].astype(int)).max(axis=2) > 8
    assert 0.02 < brighter.mean() < 0.5  # the cone's spot on the floor and the spheres, not the whole picture
