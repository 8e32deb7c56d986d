"""Radiosity: hemicube form factors against closed forms, progressive refinement against the radiosity equation's
closed-box solution and against Mitsuba 3's path tracer (the Cornell box), direct light, the lit scene, bad input.

Tolerances: the hemicube samples each face's solid angle on a pixel grid, so form factors carry an aliasing error
that falls with the resolution (≈ 0.3 % at 256 for the shapes below); the issue allows 2 %. Mitsuba's per-wall
means carry a Monte Carlo error of ≈ 0.5 % at 64 samples per pixel on 64² pixels; the issue allows 5 %.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import frustum as fr
from cornell import WALLS, camera, cornell_box, quad
from frustum.errors import ShadingError
from frustum.render.radiosity import (
    RadiosityError,
    _Rasterizer,
    form_factors,
    hemicube_delta_form_factors,
    hemicube_form_factors,
    patches_of,
    radiosity,
)


def _area_form_factor(scene: fr.Scene, source_item: int, target_item: int, patch_size: float, hemicube: int) -> float:
    """F from item `source_item` to item `target_item`: the area-weighted mean over the source's patches of the
    point form factors (each patch's hemicube) summed over the target's patches."""
    patches = patches_of(scene, patch_size)
    raster = _Rasterizer(patches)
    sources = np.flatnonzero(patches.item == source_item)
    targets = patches.item == target_item
    total = sum(patches.area[i] * form_factors(patches, int(i), hemicube=hemicube, rasterizer=raster)[targets].sum()
                for i in sources)  # fmt: skip
    return float(total / patches.area[sources].sum())


def parallel_squares(side: float, distance: float) -> float:
    """Closed form: two coaxial parallel squares of `side` at `distance` (Howell's catalogue, C-11)."""
    x = y = side / distance
    return 2.0 / (math.pi * x * y) * (
        math.log(math.sqrt((1 + x * x) * (1 + y * y) / (1 + x * x + y * y)))
        + x * math.sqrt(1 + y * y) * math.atan(x / math.sqrt(1 + y * y))
        + y * math.sqrt(1 + x * x) * math.atan(y / math.sqrt(1 + x * x))
        - x * math.atan(x) - y * math.atan(y)
    )  # fmt: skip


def perpendicular_rectangles(width: float, height: float, edge: float) -> float:
    """Closed form: from a rectangle (width × edge) to a perpendicular one (height × edge) sharing the edge (C-14)."""
    w, h = width / edge, height / edge
    a = (1 + w * w) * (1 + h * h) / (1 + w * w + h * h)
    b = (w * w * (1 + w * w + h * h) / ((1 + w * w) * (w * w + h * h))) ** (w * w)
    c = (h * h * (1 + h * h + w * w) / ((1 + h * h) * (h * h + w * w))) ** (h * h)
    root = math.sqrt(h * h + w * w)
    return (w * math.atan(1 / w) + h * math.atan(1 / h) - root * math.atan(1 / root)
            + 0.25 * math.log(a * b * c)) / (math.pi * w)  # fmt: skip


def test_delta_form_factors_of_a_whole_hemicube_sum_to_one():
    for resolution in (64, 128, 256):
        top, side = hemicube_delta_form_factors(resolution)
        assert top.shape == (resolution, resolution) and side.shape == (resolution // 2, resolution)
        assert top.sum() + 4 * side.sum() == pytest.approx(1.0, abs=2e-3)
        assert side[0].sum() < side[-1].sum() or side[0].mean() > 0  # rows are top first: z = 1 on row 0
        assert side[:, resolution // 2].argmax() < resolution // 4  # the largest side factors lie near z = 1/√3


def test_parallel_squares_match_the_closed_form_and_converge():
    scene = fr.Scene()
    scene.add(quad((0, 0, 0), (1, 0, 0), (0, 1, 0)))  # facing +z
    scene.add(quad((0, 0, 1), (0, 1, 0), (1, 0, 0)))  # facing −z, one unit above
    exact = parallel_squares(1.0, 1.0)
    errors = [abs(_area_form_factor(scene, 0, 1, 0.25, n) - exact) / exact for n in (32, 256)]
    assert errors[1] < 0.02
    assert errors[1] < errors[0]


def test_perpendicular_rectangles_sharing_an_edge_match_the_closed_form():
    scene = fr.Scene()
    scene.add(quad((0, 0, 0), (2, 0, 0), (0, 1, 0)))  # floor 2 wide (x) × 1 along the edge (y), facing +z
    scene.add(quad((0, 0, 0), (0, 1, 0), (0, 0, 1.5)))  # wall 1.5 high, facing +x, sharing the edge x = 0, z = 0
    exact = perpendicular_rectangles(2.0, 1.5, 1.0)
    assert _area_form_factor(scene, 0, 1, 0.125, 256) == pytest.approx(exact, rel=0.02)


def test_differential_area_to_a_coaxial_disk():
    radius, height = 0.7, 1.3
    angles = np.linspace(0.0, 2.0 * np.pi, 257)[:-1]
    rim = np.c_[radius * np.cos(angles), radius * np.sin(angles), np.full(256, height)]
    vertices = np.vstack([[0.0, 0.0, height], rim])
    faces = np.c_[np.zeros(256, int), 1 + (np.arange(256) + 1) % 256, 1 + np.arange(256)]  # facing −z
    scene = fr.Scene()
    scene.add(fr.Mesh(vertices, faces))
    scene.add(quad((-2, -2, 0), (4, 0, 0), (0, 4, 0)))  # a floor below, so the scene's size is the usual one
    patches = patches_of(scene, 10.0)
    factors = hemicube_form_factors(patches, np.zeros(3), np.array([0.0, 0.0, 1.0]), 256, _Rasterizer(patches))
    polygon_area = 0.5 * 256 * radius * radius * math.sin(2 * math.pi / 256)
    exact = radius**2 / (radius**2 + height**2) * polygon_area / (math.pi * radius**2)
    assert factors[patches.item == 0].sum() == pytest.approx(exact, rel=0.02)


def test_reciprocity():
    scene = fr.Scene()
    scene.add(quad((0, 0, 0), (1, 0, 0), (0, 1, 0)))  # 1 × 1 facing +z
    scene.add(quad((0.5, -1.0, 1.5), (0, 2.5, 0), (1.2, 0, 0)))  # 2.5 × 1.2 facing −z, offset
    f01 = _area_form_factor(scene, 0, 1, 0.25, 256)
    f10 = _area_form_factor(scene, 1, 0, 0.25, 256)
    assert 1.0 * f01 == pytest.approx(2.5 * 1.2 * f10, rel=0.02)


def closed_box(material: fr.Material) -> fr.Scene:
    """The unit cube's six faces, facing in."""
    scene = fr.Scene()
    for corner, u, v in [((0, 0, 0), (0, 0, 1), (1, 0, 0)), ((0, 1, 0), (1, 0, 0), (0, 0, 1)),
                         ((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 1), (0, 1, 0), (1, 0, 0)),
                         ((0, 0, 0), (0, 1, 0), (0, 0, 1)), ((1, 0, 0), (0, 0, 1), (0, 1, 0))]:  # fmt: skip
        scene.add(quad(corner, u, v), material)
    return scene


def test_form_factors_from_a_patch_in_a_closed_box_sum_to_one():
    patches = patches_of(closed_box(fr.Material()), 0.3)
    raster = _Rasterizer(patches)
    for source in (0, patches.count // 3, patches.count - 1):
        assert form_factors(patches, source, hemicube=128, rasterizer=raster).sum() == pytest.approx(1.0, abs=0.01)


def test_a_closed_white_box_with_uniform_emission_converges_to_e_over_one_minus_rho():
    emitting = fr.Material(color=(1.0, 1.0, 1.0), diffuse=0.5, emissive=(1.0, 1.0, 1.0), emission=0.4)
    result = radiosity(closed_box(emitting), patch_size=0.25, hemicube=128, tolerance=1e-4, shooter=1.0)
    assert result.residual <= 1e-4
    exact = 0.4 / (1 - 0.5)
    patches = result.patch_mesh
    for wall in range(6):  # energy is conserved: every wall's mean is exact
        mine = patches.item == wall
        assert (result.radiosity[mine, 0] * patches.area[mine]).sum() / patches.area[mine].sum() == pytest.approx(
            exact, rel=0.01
        )
    # point-to-area form factors (from each patch's centre) break reciprocity a little between neighbours at the
    # box's edges, the hemicube's classic error: single patches stay within 10 %
    np.testing.assert_allclose(result.radiosity, exact, rtol=0.1)


def _mitsuba_wall_means(scene: fr.Scene, spp: int = 64, size: int = 64) -> np.ndarray:
    """(5, 3) mean radiance of the Cornell box's walls by Mitsuba 3's path tracer: an orthographic sensor just in
    front of each wall, looking at it face-on and covering it exactly, so the image mean is the area mean."""
    return _mitsuba_wall_means_and_errors(scene, spp, size)[0]


def _mitsuba_wall_means_and_errors(scene: fr.Scene, spp: int = 64, size: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """``_mitsuba_wall_means`` and the standard error of each mean (pixel standard deviation / √pixels)."""
    import mitsuba as mi  # a test dependency (the oracle): missing, the test fails
    mi.set_variant("scalar_rgb")
    transform = mi.ScalarTransform4f

    def frame(mesh: fr.Mesh) -> tuple[np.ndarray, ...]:
        v = mesh.vertices
        u, w = v[1] - v[0], v[3] - v[0]
        n = np.cross(u, w)
        return v.mean(axis=0), u, w, n / np.linalg.norm(n)

    shapes = {}
    for name, item in zip(WALLS, scene.items, strict=True):
        centre, u, w, n = frame(item.mesh)
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, w / 2, n, centre  # the rectangle [-1, 1]² facing +z
        material = item.material
        reflectance = (np.asarray(material.color) * material.diffuse).tolist()
        shape = {"type": "rectangle", "to_world": transform(m.tolist()),
                 "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": reflectance}}}  # fmt: skip
        radiance = np.asarray(material.emissive) * material.emission
        if radiance.max() > 0:
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": radiance.tolist()}}
        shapes[name] = shape
    means, errors = [], []
    for item in scene.items[:5]:
        centre, u, w, n = frame(item.mesh)
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = -u / 2, w / 2, -n, centre + n * 4e-4
        sensor = {"type": "orthographic", "to_world": transform(m.tolist()), "near_clip": 1e-5, "far_clip": 10.0,
                  "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"},
                           "pixel_format": "rgb"},
                  "sampler": {"type": "independent", "sample_count": spp}}  # fmt: skip
        mitsuba_scene = mi.load_dict({"type": "scene", "integrator": {"type": "path", "max_depth": 64},
                                      "sensor": sensor, **shapes})  # fmt: skip
        pixels = np.asarray(mi.render(mitsuba_scene, spp=spp)).reshape(-1, 3)
        means.append(pixels.mean(axis=0))
        errors.append(pixels.std(axis=0) / np.sqrt(pixels.shape[0]))
    return np.array(means), np.array(errors)


def test_cornell_box_wall_means_agree_with_mitsuba():
    scene = cornell_box()
    result = radiosity(scene, patch_size=0.05)
    assert result.residual <= 1e-3
    patches = result.patch_mesh
    ours = np.array([(result.radiosity[patches.item == i] * patches.area[patches.item == i, None]).sum(axis=0)
                     / patches.area[patches.item == i].sum() for i in range(5)])  # fmt: skip
    theirs = _mitsuba_wall_means(scene)
    # same units (module docstring): no scale. Colour bleeding shows: the floor's red is above its green near the
    # red wall in both.
    np.testing.assert_allclose(ours, theirs, rtol=0.05)


def test_direct_light_is_the_depth_buffers_diffuse_term_and_blocked_light_casts_a_shadow():
    scene = fr.Scene([fr.DirectionalLight((0.0, -1.0, -1.0), intensity=0.8)])
    floor = fr.Material(color=(0.5, 0.5, 0.5), diffuse=0.8)
    scene.add(quad((-2, 0, -2), (0, 0, 4), (4, 0, 0)), floor)  # the floor y = 0, facing +y
    scene.add(fr.box((0.5, 0.5, 0.5)), fr.Material(color=(0, 0, 0), diffuse=0.0), fr.translate(0, 0.3, 0))
    result = radiosity(scene, patch_size=0.2, max_iterations=0)
    patches = result.patch_mesh
    on_floor = patches.item == 0
    lit = 0.5 * 0.8 * 0.8 * math.cos(math.pi / 4)
    b = result.radiosity[on_floor, 0]
    centre = patches.centre[on_floor]
    far_away = np.linalg.norm(centre[:, [0, 2]] - [0.0, -0.3], axis=1) > 1.0
    np.testing.assert_allclose(b[far_away], lit, rtol=1e-9)
    # the box [−0.25, 0.25]³ + (0, 0.3, 0) shades the floor along (0, −1, −1): its shadow lies around z ≈ −0.3
    shadowed = (np.abs(centre[:, 0]) < 0.1) & (np.abs(centre[:, 2] + 0.35) < 0.1)
    assert shadowed.any() and (b[shadowed] < 0.5 * lit).all()


def test_the_lit_scene_renders_the_interpolated_radiosity():
    scene = fr.Scene([fr.DirectionalLight((0.0, -1.0, 0.0), intensity=0.6)])
    scene.add(quad((-1, 0, -1), (0, 0, 2), (2, 0, 0)), fr.Material(color=(1.0, 1.0, 1.0), diffuse=1.0))
    result = radiosity(scene, patch_size=0.5)  # a plane sees nothing: converged once every group has shot
    assert result.residual == 0.0
    view = fr.Camera.look_at((0, 3, 0.01), (0, 0, 0), (0, 0, -1), fr.Perspective(0.5, 0.1, 10.0), 32, 32)
    frame = fr.render(result.scene, view, shading="none")
    drawn = frame.depth < 1.0
    assert drawn.mean() > 0.9
    np.testing.assert_allclose(frame.color[drawn][:, :3], round(0.6 * 255), atol=1)
    assert result.patches == result.radiosity.shape[0] == result.patch_mesh.count


def test_cornell_box_picture_shows_colour_bleeding():
    result = radiosity(cornell_box(), patch_size=0.1)
    frame = fr.render(result.scene, camera(64), shading="none")
    floor_left = frame.color[58, 12, :3].astype(int)  # floor next to the red wall
    floor_right = frame.color[58, 51, :3].astype(int)  # floor next to the green wall
    assert floor_left[0] - floor_left[1] > floor_right[0] - floor_right[1]


def test_bad_input():
    with pytest.raises(ShadingError, match="emission"):
        fr.Material(emission=-1.0)
    scene = cornell_box()
    with pytest.raises(RadiosityError, match=r"patches.*over the (memory|work) budget"):
        radiosity(scene, patch_size=1e-4)
    with pytest.raises(RadiosityError, match="hemicube"):
        radiosity(scene, hemicube=33)
    with pytest.raises(RadiosityError, match="tolerance"):
        radiosity(scene, tolerance=0.0)
    with pytest.raises(RadiosityError, match="patch_size"):
        radiosity(scene, patch_size=-1.0)
    dark = fr.Scene()
    dark.add(quad((0, 0, 0), (1, 0, 0), (0, 1, 0)))
    with pytest.raises(RadiosityError, match="nothing emits light"):
        radiosity(dark)
    with pytest.raises(RadiosityError, match="no surfaces"):
        radiosity(fr.Scene([fr.DirectionalLight((0, -1, 0))]))
