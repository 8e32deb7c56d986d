"""geometry/fractals.py: exact counts and first-level coordinates, trimesh volumes, determinism, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum.errors import GeometryError
from frustum.geometry.fractals import (
    IFS,
    barnsley_fern,
    cantor_set,
    fbm_terrain,
    fractal_coastline,
    heightfield_mesh,
    hilbert_curve,
    hilbert_curve_3d,
    koch_curve,
    koch_snowflake,
    menger_sponge,
    peano_curve,
    sierpinski_ifs,
    sierpinski_tetrahedron,
    sierpinski_triangle,
    similarity_dimension,
)

S3 = math.sqrt(3.0)


def _trimesh(mesh):
    return trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)


# ----------------------------------------------------------------------------- counts and coordinates


@pytest.mark.parametrize("level", range(6))
def test_koch_curve_has_4_to_the_n_segments_of_length_3_to_the_minus_n(level):
    curve = koch_curve(level)
    assert curve.shape == (4**level + 1, 3)
    lengths = np.linalg.norm(np.diff(curve, axis=0), axis=1)
    np.testing.assert_allclose(lengths, 3.0**-level, rtol=1e-12)
    np.testing.assert_array_equal(curve[[0, -1]], [[0, 0, 0], [1, 0, 0]])


def test_koch_first_levels_exact_coordinates():
    expected = [[0, 0, 0], [1 / 3, 0, 0], [0.5, S3 / 6, 0], [2 / 3, 0, 0], [1, 0, 0]]
    np.testing.assert_allclose(koch_curve(1), expected, atol=1e-15)
    snow = koch_snowflake(0)
    np.testing.assert_allclose(snow, [[0, 0, 0], [0.5, S3 / 2, 0], [1, 0, 0], [0, 0, 0]], atol=1e-15)
    assert koch_snowflake(3).shape == (3 * 4**3 + 1, 3)
    # the first bump of the snowflake points out of the triangle (to the left of (0,0)→(1/2, √3/2))
    np.testing.assert_allclose(koch_snowflake(1)[2], [0.0, S3 / 3, 0.0], atol=1e-15)


def test_cantor_intervals_exact():
    np.testing.assert_allclose(cantor_set(1), [[0, 1 / 3], [2 / 3, 1]], atol=1e-15)
    np.testing.assert_allclose(cantor_set(2), [[0, 1 / 9], [2 / 9, 1 / 3], [2 / 3, 7 / 9], [8 / 9, 1]], atol=1e-15)
    for level in range(8):
        intervals = cantor_set(level)
        assert intervals.shape == (2**level, 2)
        np.testing.assert_allclose(intervals[:, 1] - intervals[:, 0], 3.0**-level, rtol=1e-12)
    np.testing.assert_allclose(cantor_set(1, 2.0, 5.0), [[2, 3], [4, 5]])


@pytest.mark.parametrize("level", range(6))
def test_sierpinski_triangle_has_3_to_the_n_triangles_of_area_quarter_to_the_n(level):
    mesh = sierpinski_triangle(level)
    assert mesh.face_count == 3**level
    tri = mesh.vertices[mesh.faces]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1) / 2
    np.testing.assert_allclose(area, S3 / 4 * 4.0**-level, rtol=1e-12)
    assert (mesh.face_normals[:, 2] > 0).all()  # counter-clockwise like the corners


def test_sierpinski_triangle_level_1_exact():
    mesh = sierpinski_triangle(1, corners=((0, 0), (1, 0), (0, 1)))
    expected = [
        [[0, 0], [0.5, 0], [0, 0.5]],
        [[0.5, 0], [1, 0], [0.5, 0.5]],
        [[0, 0.5], [0.5, 0.5], [0, 1]],
    ]
    np.testing.assert_array_equal(mesh.vertices[mesh.faces][:, :, :2], expected)


@pytest.mark.parametrize("level", range(4))
def test_sierpinski_tetrahedron_counts_and_volume_against_trimesh(level):
    mesh = sierpinski_tetrahedron(level)
    assert mesh.face_count == 4 ** (level + 1)
    # each of the 4^n tetrahedra has volume (1/8)^n of the regular unit tetrahedron, √2/12
    assert _trimesh(mesh).volume == pytest.approx(math.sqrt(2) / 12 * 0.5**level, rel=1e-12)


def test_sierpinski_tetrahedron_level_1_corners():
    corners = sierpinski_tetrahedron(1).vertices.reshape(4, 12, 3)  # per tetrahedron: its 12 face vertices
    first = np.unique(corners[0], axis=0)
    expected = [[0, 0, 0], [0.25, S3 / 12, math.sqrt(2 / 3) / 2], [0.25, S3 / 4, 0], [0.5, 0, 0]]
    np.testing.assert_allclose(first, expected, atol=1e-15)


@pytest.mark.parametrize("level", range(4))
def test_menger_sponge_20_to_the_n_cubes_exposed_faces_only(level):
    mesh = menger_sponge(level)
    tm = _trimesh(mesh)
    # volume = 20^n cubes of side 3^-n; exposed squares 2·20^n + 4·8^n (area 2(20/9)^n + 4(8/9)^n)
    assert tm.volume == pytest.approx(20**level / 27**level, rel=1e-12)
    assert mesh.face_count == 2 * (2 * 20**level + 4 * 8**level)
    assert tm.area == pytest.approx(2 * (20 / 9) ** level + 4 * (8 / 9) ** level, rel=1e-12)
    assert tm.is_watertight and tm.is_winding_consistent


def test_menger_unshared_vertices_give_flat_normals_and_the_same_surface():
    flat, shared = menger_sponge(2, shared_vertices=False), menger_sponge(2)
    assert flat.face_count == shared.face_count and flat.vertex_count == 2 * flat.face_count
    np.testing.assert_allclose(flat.vertex_normals[flat.faces[:, 0]], flat.face_normals, atol=1e-15)
    assert _trimesh(flat).volume == pytest.approx(_trimesh(shared).volume, rel=1e-12)


def test_menger_level_1_vertices_on_the_third_lattice():
    mesh = menger_sponge(1, size=3.0)
    np.testing.assert_array_equal(mesh.vertices, np.round(mesh.vertices))
    assert mesh.bounds.tolist() == [[0, 0, 0], [3, 3, 3]]
    # the centre tunnels: no vertex at the cube's centre region corner (1.5, 1.5, 1.5) and tunnel walls at 1, 2
    assert {tuple(v) for v in mesh.vertices} >= {(1.0, 1.0, 0.0), (2.0, 2.0, 3.0), (1.0, 1.0, 1.0)}


@pytest.mark.parametrize(
    ("curve", "base", "dim"), [(hilbert_curve, 2, 2), (hilbert_curve_3d, 2, 3), (peano_curve, 3, 2)]
)
@pytest.mark.parametrize("level", range(4))
def test_space_filling_curves_visit_every_cell_once_with_unit_steps(curve, base, dim, level):
    points = curve(level)
    side = base**level
    assert points.shape == (side**dim, 3)
    cells = np.floor(points[:, :dim] * side).astype(int)
    assert len({tuple(c) for c in cells}) == side**dim
    np.testing.assert_allclose((cells + 0.5) / side, points[:, :dim], atol=1e-15)
    if level:
        steps = np.abs(np.diff(cells, axis=0)).sum(axis=1)
        assert (steps == 1).all()


def test_hilbert_and_peano_level_1_exact():
    np.testing.assert_array_equal(hilbert_curve(1)[:, :2], [[0.25, 0.25], [0.25, 0.75], [0.75, 0.75], [0.75, 0.25]])
    expected = [(0, 0), (0, 1), (0, 2), (1, 2), (1, 1), (1, 0), (2, 0), (2, 1), (2, 2)]
    np.testing.assert_allclose(peano_curve(1)[:, :2], (np.array(expected) + 0.5) / 3, atol=1e-15)
    assert hilbert_curve_3d(1)[0].tolist() == [0.25, 0.25, 0.25]


@pytest.mark.parametrize(
    ("n", "s", "d"),
    [
        (4, 1 / 3, math.log(4) / math.log(3)),
        (3, 0.5, math.log2(3)),
        (20, 1 / 3, 2.726833027860842),
        (2, 1 / 3, 0.6309297535714574),
    ],
)
def test_similarity_dimension_known_values(n, s, d):
    assert similarity_dimension(n, s) == pytest.approx(d, abs=1e-12)


@settings(max_examples=30)
@given(st.integers(1, 100), st.floats(0.01, 0.99))
def test_similarity_dimension_is_the_exponent(n, s):
    # N copies at scale s: N·s^D = 1
    assert n * s ** similarity_dimension(n, s) == pytest.approx(1.0, rel=1e-9)


# ----------------------------------------------------------------------------------------- IFS


def test_ifs_deterministic_sierpinski_matches_the_triangle_construction():
    ifs = sierpinski_ifs(((0, 0), (1, 0), (0, 1)))
    points = ifs.points(4)
    assert points.shape == (81, 3)
    # every point lies on a corner of a level-4 Sierpinski sub-triangle: x, y multiples of 1/16, x + y <= 1
    np.testing.assert_array_equal(points[:, :2] * 16, np.round(points[:, :2] * 16))
    assert (points[:, :2].sum(axis=1) <= 1 + 1e-12).all()
    assert (np.bitwise_and((points[:, 0] * 16).astype(int), (points[:, 1] * 16).astype(int)) == 0).all()


def test_chaos_game_is_reproducible_and_stays_on_the_attractor():
    fern = barnsley_fern()
    a = fern.chaos_game(5000, seed=7)
    assert a.tobytes() == fern.chaos_game(5000, seed=7).tobytes()
    assert a.tobytes() != fern.chaos_game(5000, seed=8).tobytes()
    assert (a[:, 0] > -2.2).all() and (a[:, 0] < 2.7).all() and (a[:, 1] >= 0).all() and (a[:, 1] < 10.01).all()
    tri = sierpinski_ifs(((0, 0), (1, 0), (0, 1))).chaos_game(4000, seed=1)
    # after the burn-in every point is within 2^-100 of the gasket: its 1/8-grid cell is one of the 27 kept
    cells = np.floor(tri[:, :2] * 8).astype(int)
    assert (np.bitwise_and(cells[:, 0], cells[:, 1]) == 0).all()


def test_ifs_default_probabilities_follow_determinants():
    maps = np.array([np.diag([0.5, 0.5, 1.0]), np.diag([0.25, 0.25, 1.0])])
    np.testing.assert_allclose(IFS(maps).probabilities, [0.8, 0.2])


# ------------------------------------------------------------------------------------ terrain, coastline


@pytest.mark.parametrize("method", ["diamond-square", "midpoint"])
def test_terrain_is_deterministic_and_seed_dependent(method):
    a = fbm_terrain(6, 0.7, seed=3, method=method)
    assert a.shape == (65, 65)
    assert a.tobytes() == fbm_terrain(6, 0.7, seed=3, method=method).tobytes()
    assert a.tobytes() != fbm_terrain(6, 0.7, seed=4, method=method).tobytes()
    assert np.isfinite(a).all()


def naive_diamond_square(level: int, hurst: float, seed: int, sigma: float = 1.0) -> np.ndarray:
    """Point-by-point diamond-square with the same random draws (same order and shapes) as fbm_terrain."""
    rng = np.random.default_rng(seed)
    n = 2**level
    h = np.zeros((n + 1, n + 1))
    h[0::n, 0::n] = sigma * rng.standard_normal((2, 2))
    step, k = n, 0
    while step > 1:
        half, scale = step // 2, sigma * 2.0 ** (-(k + 1) * hurst)
        m = n // step
        noise = rng.standard_normal((m, m))
        for a in range(m):
            for b in range(m):
                r, c = a * step + half, b * step + half
                mean = (
                    h[r - half, c - half] + h[r - half, c + half] + h[r + half, c - half] + h[r + half, c + half]
                ) / 4
                h[r, c] = mean + scale * noise[a, b]
        scale2 = scale * 2.0 ** (-hurst / 2)
        rows, cols = rng.standard_normal((m + 1, m)), rng.standard_normal((m, m + 1))
        for noise, r0, c0 in ((rows, 0, half), (cols, half, 0)):
            for a in range(noise.shape[0]):
                for b in range(noise.shape[1]):
                    r, c = r0 + a * step, c0 + b * step
                    near = [h[r + dr, c + dc] for dr, dc in ((-half, 0), (half, 0), (0, -half), (0, half))
                            if 0 <= r + dr <= n and 0 <= c + dc <= n]  # fmt: skip
                    h[r, c] = sum(near) / len(near) + scale2 * noise[a, b]
        step, k = half, k + 1
    return h


@pytest.mark.parametrize(("level", "hurst", "seed"), [(1, 0.5, 0), (3, 0.8, 1), (5, 0.3, 2)])
def test_diamond_square_matches_a_point_by_point_reference(level, hurst, seed):
    np.testing.assert_allclose(
        fbm_terrain(level, hurst, seed=seed), naive_diamond_square(level, hurst, seed), atol=1e-13
    )


def test_terrain_refines_without_moving_coarser_points_under_zero_sigma():
    assert (fbm_terrain(5, 0.5, seed=1, sigma=0.0) == 0).all()


def test_heightfield_mesh_layout_and_normals():
    z = np.array([[0.0, 1.0, 2.0], [0.0, 1.0, 2.0]])  # plane z = 2x (size 1, x spacing 1/2)
    mesh = heightfield_mesh(z)
    assert mesh.face_count == 4 and mesh.vertex_count == 6
    np.testing.assert_allclose(mesh.vertices[5], [1.0, 1.0, 2.0])
    expected = np.array([-2.0, 0.0, 1.0]) / math.sqrt(5)
    np.testing.assert_allclose(mesh.vertex_normals, np.tile(expected, (6, 1)), atol=1e-12)
    np.testing.assert_allclose(mesh.face_normals, np.tile(expected, (4, 1)), atol=1e-12)


def test_coastline_keeps_endpoints_and_is_reproducible():
    outline = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 0, 0]]
    a = fractal_coastline(outline, 6, seed=2)
    assert a.shape == (3 * 64 + 1, 3)
    np.testing.assert_array_equal(a[::64], outline)
    assert a.tobytes() == fractal_coastline(outline, 6, seed=2).tobytes()
    assert a.tobytes() != fractal_coastline(outline, 6, seed=5).tobytes()


# -------------------------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "make",
    [
        koch_curve,
        koch_snowflake,
        cantor_set,
        sierpinski_triangle,
        sierpinski_tetrahedron,
        menger_sponge,
        hilbert_curve,
        hilbert_curve_3d,
        peano_curve,
    ],
)
def test_negative_level_is_refused_naming_it(make):
    with pytest.raises(GeometryError, match=r"level = -1 is negative"):
        make(-1)


@pytest.mark.parametrize(
    ("make", "level"), [(koch_curve, 40), (menger_sponge, 12), (sierpinski_triangle, 30), (hilbert_curve_3d, 20)]
)
def test_levels_over_the_memory_budget_fail_before_allocating(make, level):
    expected = r"level = \d+ needs about .* over the memory budget of 8\.0 GiB.*FRUSTUM_MAX_BYTES"
    with pytest.raises(GeometryError, match=expected):
        make(level)


def test_absurd_levels_fail_at_once():
    with pytest.raises(GeometryError, match=r"level = 1000000000 is above 1000"):
        koch_curve(10**9)


def test_memory_budget_is_a_parameter():
    with pytest.raises(GeometryError, match=r"level = 3 would need 4680 bytes .*max_bytes = 1000 "):
        koch_curve(3, max_bytes=1000)
    assert koch_curve(3, max_bytes=10**6).shape == (65, 3)
    with pytest.raises(GeometryError, match=r"level = 8 would need"):
        fbm_terrain(8, seed=0, max_bytes=10_000)


def test_ifs_bad_input():
    maps = np.array([np.diag([0.5, 0.5, 1.0]), np.diag([0.5, 0.5, 1.0])])
    with pytest.raises(GeometryError, match=r"probabilities = \(0.5, 0.4\) sum to 0.9"):
        IFS(maps, [0.5, 0.4])
    with pytest.raises(GeometryError, match=r"probabilities = .* has shape \(3,\)"):
        IFS(maps, [0.2, 0.4, 0.4])
    with pytest.raises(GeometryError, match=r"negative"):
        IFS(maps, [1.5, -0.5])
    with pytest.raises(GeometryError, match=r"affine_maps\[1\] stretches by 2.0"):
        IFS([np.diag([0.5, 0.5, 1.0]), np.diag([2.0, 0.5, 1.0])])
    with pytest.raises(GeometryError, match=r"shape \(2, 2, 2\)"):
        IFS(np.zeros((2, 2, 2)))
    with pytest.raises(GeometryError, match=r"last row"):
        IFS([[[0.5, 0, 0], [0, 0.5, 0], [1, 0, 1]]])
    with pytest.raises(GeometryError, match=r"seed = -1"):
        barnsley_fern().chaos_game(10, seed=-1)


def test_other_bad_input_names_the_value():
    with pytest.raises(GeometryError, match=r"hurst = 1.5 is outside \(0, 1\)"):
        fbm_terrain(3, 1.5, seed=0)
    with pytest.raises(GeometryError, match=r"method = 'plasma' is unknown"):
        fbm_terrain(3, seed=0, method="plasma")
    with pytest.raises(GeometryError, match=r"scale = 1.5 is outside \(0, 1\)"):
        similarity_dimension(2, 1.5)
    with pytest.raises(GeometryError, match=r"level = 2.5 is not an integer"):
        koch_curve(2.5)
    with pytest.raises(GeometryError, match=r"polyline has 1 points"):
        fractal_coastline([[0, 0, 0]], 2, seed=0)
    with pytest.raises(GeometryError, match=r"end = 0.0 is not greater than start = 1.0"):
        cantor_set(2, 1.0, 0.0)
