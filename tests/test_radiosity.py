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
from hypothesis import given, settings
from hypothesis import strategies as st

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


def closed_box(material: fr.Material, sides: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> fr.Scene:
    """The box [0, a] × [0, b] × [0, c]'s six faces, facing in (the unit cube by default)."""
    scene = fr.Scene()
    for corner, u, v in [((0, 0, 0), (0, 0, 1), (1, 0, 0)), ((0, 1, 0), (1, 0, 0), (0, 0, 1)),
                         ((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 1), (0, 1, 0), (1, 0, 0)),
                         ((0, 0, 0), (0, 1, 0), (0, 0, 1)), ((1, 0, 0), (0, 0, 1), (0, 1, 0))]:  # fmt: skip
        scene.add(quad(*(np.multiply(p, sides) for p in (corner, u, v))), material)
    return scene


def test_form_factors_from_a_patch_in_a_closed_box_sum_to_one():
    patches = patches_of(closed_box(fr.Material()), 0.3)
    raster = _Rasterizer(patches)
    for source in (0, patches.count // 3, patches.count - 1):
        assert form_factors(patches, source, hemicube=128, rasterizer=raster).sum() == pytest.approx(1.0, abs=0.01)


def test_hemicube_form_factors_in_a_closed_white_box_are_right_on_average_and_blotchy_per_patch():
    emitting = fr.Material(color=(1.0, 1.0, 1.0), diffuse=0.5, emissive=(1.0, 1.0, 1.0), emission=0.4)
    result = radiosity(closed_box(emitting), patch_size=0.25, hemicube=128, tolerance=1e-4, shooter=1.0,
                       form_factors="hemicube")  # fmt: skip
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


@settings(max_examples=12, deadline=None)
@given(
    sides=st.tuples(*[st.floats(0.3, 3.0)] * 3),
    rho=st.floats(0.05, 0.9),
    emission=st.floats(0.05, 2.0),
    cells=st.integers(2, 6),
    shooter=st.sampled_from([1.0, 4.0]),
)
def test_every_patch_of_a_closed_box_is_e_over_one_minus_rho(sides, rho, emission, cells, shooter):
    """Any box proportions and tessellation: the ray form factors at each patch centre sum to one over the box, so
    every patch (not only each wall's mean) converges to the radiosity equation's solution E / (1 − ρ)."""
    emitting = fr.Material(color=(1.0, 1.0, 1.0), diffuse=rho, emissive=(1.0, 1.0, 1.0), emission=emission)
    scene = closed_box(emitting, sides)
    result = radiosity(scene, patch_size=max(sides) / cells, shooter=shooter)
    assert result.residual <= 1e-3 or result.iterations >= 50 * result.patches
    np.testing.assert_allclose(result.radiosity, emission / (1.0 - rho), rtol=0.02)


def test_point_form_factors_match_closed_forms_and_boundary_sums_match_triangle_sums():
    from frustum.raster.form_factors import point_group_factors, point_triangle_factors

    # a point under the centre of a square of half side a at height h: 4 × the corner rectangle's factor
    a, h = 0.7, 1.3
    square = np.array([[-a, -a, h], [a, -a, h], [a, a, h], [-a, a, h]])
    triangles = np.ascontiguousarray(np.stack([square[[0, 2, 1]], square[[0, 3, 2]]]))  # facing −z
    out = np.zeros((1, 1))
    point_triangle_factors(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), triangles, np.zeros(2, np.int64), out)
    x = a / h
    corner = 2 * x / math.sqrt(1 + x * x) * math.atan(x / math.sqrt(1 + x * x)) / (2 * math.pi)
    assert out[0, 0] == pytest.approx(4 * corner, rel=1e-12)
    # tilted receivers (the square straddles their tangent plane, so it is clipped) against quadrature
    rng = np.random.default_rng(5)
    normals = rng.normal(size=(6, 3))
    normals[:, 2] = np.abs(normals[:, 2])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    points = rng.uniform(-0.5, 0.5, size=(6, 3)) * [1, 1, 0]
    out = np.zeros((6, 1))
    point_triangle_factors(points, normals, triangles, np.zeros(2, np.int64), out)
    g = (np.arange(400) + 0.5) / 400 * 2 * a - a
    gx, gy = np.meshgrid(g, g)
    samples = np.c_[gx.ravel(), gy.ravel(), np.full(gx.size, h)]
    for k in range(6):
        d = samples - points[k]
        r2 = (d * d).sum(axis=1)
        kernel = np.maximum(d @ normals[k], 0.0) * d[:, 2] / (math.pi * r2 * r2)
        assert out[k, 0] == pytest.approx(kernel.mean() * (2 * a) ** 2, rel=2e-3)
    # a group of patches: the boundary-edge sum equals the sum over its triangles, flat or not
    scene = fr.Scene()
    scene.add(fr.icosphere(subdivisions=1, radius=0.5), transform=fr.translate(0, 0, 3))
    patches = patches_of(scene, 0.3)
    triangles = np.ascontiguousarray(patches.vertices[patches.faces])
    facing = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    below = np.flatnonzero(patches.normal[:, 2] < -0.5)  # the cap facing the receivers: one piece, not flat
    receivers = np.c_[rng.uniform(-1, 1, size=(20, 2)), np.zeros(20)]
    up = np.tile([0.0, 0.0, 1.0], (20, 1))
    from frustum.render.radiosity import _boundaries

    edges, edge_first = _boundaries(patches.faces[below], np.zeros(below.size, np.int64), 1)
    whole = np.zeros((20, 1))
    point_group_factors(receivers, up, np.ascontiguousarray(triangles[below]), np.ascontiguousarray(facing[below]),
                        np.array([0, below.size]), np.ascontiguousarray(patches.vertices[edges]), edge_first,
                        np.full((1, 4), np.nan), whole)  # fmt: skip
    each = np.zeros((20, 1))
    point_triangle_factors(receivers, up, np.ascontiguousarray(triangles[below]), np.zeros(below.size, np.int64), each)
    np.testing.assert_allclose(whole, each, rtol=1e-12)
    assert each.min() > 0.0


def test_ray_form_factors_see_occluders():
    """A ceiling emitter over a floor with an opaque plate between: the floor under the plate gets no light from the
    emitter (shadow rays), the floor outside it gets the exact point-to-area factor times E ρ."""
    scene = fr.Scene()
    floor = fr.Material(color=(1.0, 1.0, 1.0), diffuse=0.5)
    dark = fr.Material(color=(0.0, 0.0, 0.0), diffuse=0.0)
    lamp = fr.Material(color=(0.0, 0.0, 0.0), diffuse=0.0, emissive=(1.0, 1.0, 1.0), emission=1.0)
    scene.add(quad((-2, 0, -2), (0, 0, 4), (4, 0, 0)), floor)  # y = 0 facing +y
    scene.add(quad((-0.5, 1.0, -0.5), (1, 0, 0), (0, 0, 1)), dark)  # plate y = 1 facing −y, 1 × 1
    scene.add(quad((-0.1, 2.0, -0.1), (0.2, 0, 0), (0, 0, 0.2)), lamp)  # emitter y = 2 facing −y, 0.2 × 0.2
    result = radiosity(scene, patch_size=0.25)  # the floor sees only black backs: direct light alone
    patches = result.patch_mesh
    on_floor = np.flatnonzero(patches.item == 0)
    centre = patches.centre[on_floor]
    b = result.radiosity[on_floor, 0]
    under = np.abs(centre[:, [0, 2]]).max(axis=1) < 0.3
    assert under.any() and (b[under] == 0.0).all()
    # far out, the small emitter is seen whole: E ρ F with F ≈ A cos θ cos θ' / (π r²)
    far = np.abs(centre[:, [0, 2]]).max(axis=1) > 1.5
    r2 = (centre[far] ** 2).sum(axis=1) - centre[far, 1] ** 2 + 4.0
    approx = 0.5 * 0.04 * 4.0 / (math.pi * r2 * r2)
    np.testing.assert_allclose(b[far], approx, rtol=0.02)


def _display_radiance(result, camera: fr.Camera) -> tuple[np.ndarray, np.ndarray]:
    """The Gouraud-interpolated display radiosity under each pixel centre (float, not 8-bit) and the wall it
    shows (−1 for none): the frame's position buffer, then a ray from the eye to that point through the lit
    scene's triangles, whose vertex colors are interpolated at the hit."""
    from frustum.raster import rays

    frame = fr.render(result.scene, camera, shading="none", buffers=("position",))
    triangles, colors, owner = [], [], []
    for k, item in enumerate(result.scene.items):
        faces = item.mesh.faces
        triangles.append(item.mesh.vertices[faces])
        colors.append(np.asarray(item.mesh.vertex_colors)[faces][..., :3])
        owner.append(np.full(faces.shape[0], k))  # one lit item per scene item, in order
    triangles, colors, owner = np.concatenate(triangles), np.concatenate(colors), np.concatenate(owner)
    drawn = frame.depth < 1.0
    eye = np.asarray(camera.frame.eye, dtype=np.float64)
    to_point = frame.position[drawn].astype(np.float64) - eye
    hits = rays.closest_hits(rays.build(triangles), np.broadcast_to(eye, to_point.shape), to_point, 0.0, 1.01)
    u, v = hits.uv[:, :1], hits.uv[:, 1:]
    face = np.maximum(hits.face, 0)
    image = np.zeros((*drawn.shape, 3))
    image[drawn] = colors[face, 0] * (1 - u - v) + colors[face, 1] * u + colors[face, 2] * v
    wall = np.full(drawn.shape, -1)
    wall[drawn] = np.where(hits.face >= 0, owner[face], -1)
    return image, wall


def test_cornell_box_per_pixel_agrees_with_mitsuba():
    """Per pixel, not wall means: Mitsuba 3's path tracer (1024 low-discrepancy samples per pixel) against the
    displayed radiosity (Gouraud over the patches' vertex values) in the same camera; walls' pixels 2 pixels
    from their edges left out. Within 5 % on at least 90 % of the walls' pixels (all three channels)."""
    import mitsuba as mi
    from scipy.ndimage import binary_erosion

    scene = cornell_box()
    result = radiosity(scene, patch_size=0.05)
    size = 64
    view = camera(size)
    image, wall = _display_radiance(result, view)
    shapes = _mitsuba_shapes(scene)  # sets the scalar_rgb variant
    sensor = {"type": "perspective", "fov_axis": "y", "fov": 39.0, "near_clip": 0.1, "far_clip": 10.0,
              "to_world": mi.ScalarTransform4f().look_at(origin=[0.5, 0.5, 2.4], target=[0.5, 0.5, 0.0], up=[0, 1, 0]),
              "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"},
                       "pixel_format": "rgb"},
              "sampler": {"type": "ldsampler", "sample_count": 1024}}  # fmt: skip
    mitsuba_scene = mi.load_dict({"type": "scene", "integrator": {"type": "path", "max_depth": 64}, "sensor": sensor,
                                  **shapes})  # fmt: skip
    reference = np.asarray(mi.render(mitsuba_scene, spp=1024))
    within = []
    for k in range(5):
        mask = binary_erosion(wall == k, iterations=2)
        assert mask.sum() > 100
        close = (np.abs(image[mask] / reference[mask] - 1.0) <= 0.05).all(axis=1)
        within.append(close)
        if WALLS[k] != "ceiling":  # lit only indirectly: Mitsuba's own noise is a few % per pixel there
            assert close.mean() >= 0.9, (WALLS[k], close.mean())
    assert np.concatenate(within).mean() >= 0.9


def _mitsuba_wall_means(scene: fr.Scene, spp: int = 64, size: int = 64) -> np.ndarray:
    """(5, 3) mean radiance of the Cornell box's walls by Mitsuba 3's path tracer: an orthographic sensor just in
    front of each wall, looking at it face-on and covering it exactly, so the image mean is the area mean."""
    return _mitsuba_wall_means_and_errors(scene, spp, size)[0]


def _wall_frame(mesh: fr.Mesh) -> tuple[np.ndarray, ...]:
    v = mesh.vertices
    u, w = v[1] - v[0], v[3] - v[0]
    n = np.cross(u, w)
    return v.mean(axis=0), u, w, n / np.linalg.norm(n)


def _mitsuba_shapes(scene: fr.Scene) -> dict:
    """The Cornell box's walls as Mitsuba 3 rectangles (diffuse ρ = diffuse · color; the light an area emitter)."""
    import mitsuba as mi  # a test dependency (the oracle): missing, the test fails

    mi.set_variant("scalar_rgb")
    shapes = {}
    for name, item in zip(WALLS, scene.items, strict=True):
        centre, u, w, n = _wall_frame(item.mesh)
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, w / 2, n, centre  # the rectangle [-1, 1]² facing +z
        material = item.material
        reflectance = (np.asarray(material.color) * material.diffuse).tolist()
        shape = {"type": "rectangle", "to_world": mi.ScalarTransform4f(m.tolist()),
                 "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": reflectance}}}  # fmt: skip
        radiance = np.asarray(material.emissive) * material.emission
        if radiance.max() > 0:
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": radiance.tolist()}}
        shapes[name] = shape
    return shapes


def _mitsuba_wall_means_and_errors(scene: fr.Scene, spp: int = 64, size: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """``_mitsuba_wall_means`` and the standard error of each mean (pixel standard deviation / √pixels)."""
    import mitsuba as mi  # a test dependency (the oracle): missing, the test fails

    shapes = _mitsuba_shapes(scene)
    transform = mi.ScalarTransform4f
    means, errors = [], []
    for item in scene.items[:5]:
        centre, u, w, n = _wall_frame(item.mesh)
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
    with pytest.raises(RadiosityError, match="form_factors"):
        radiosity(scene, form_factors="exact")
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
