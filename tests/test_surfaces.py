"""geometry/surfaces.py against geomdl (Bézier as clamped B-spline, B-spline, NURBS) and SciPy NdBSpline, exact
NURBS quadrics, normals, tessellation, adaptive tessellation and bad input."""

from __future__ import annotations

import geomdl.BSpline
import geomdl.NURBS
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import NdBSpline

from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh
from frustum.geometry.surfaces import BezierSurface, BSplineSurface, NURBSSurface
from oracles import assert_close

TOL = 1e-10


def random_grid(rows: int, columns: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-3.0, 3.0, size=(rows, columns, 3))


def parameter_pairs(low_u=0.0, high_u=1.0, low_v=0.0, high_v=1.0, count=25, seed=0):
    rng = np.random.default_rng(seed)
    u = np.concatenate([[low_u, high_u, low_u], rng.uniform(low_u, high_u, count)])
    v = np.concatenate([[low_v, high_v, high_v], rng.uniform(low_v, high_v, count)])
    return u, v


def geomdl_surface(grid, p, q, knots_u, knots_v, weights=None):
    s = geomdl.NURBS.Surface(normalize_kv=False) if weights is not None else geomdl.BSpline.Surface(normalize_kv=False)
    s.degree_u, s.degree_v = p, q
    s.ctrlpts_size_u, s.ctrlpts_size_v = grid.shape[0], grid.shape[1]
    s.ctrlpts = grid.reshape(-1, 3).tolist()  # ORACLES trap 13: flat with v fastest, u ↔ i
    if weights is not None:
        s.weights = weights.ravel().tolist()
    s.knotvector_u, s.knotvector_v = list(map(float, knots_u)), list(map(float, knots_v))
    return s


def oracle_values(s, u, v):
    points, du, dv, duv = [], [], [], []
    for a, b in zip(u, v, strict=True):
        d = s.derivatives(float(a), float(b), order=1)
        points.append(d[0][0])
        du.append(d[1][0])
        dv.append(d[0][1])
        duv.append(d[1][1])
    return (np.array(x) for x in (points, du, dv, duv))


@pytest.mark.parametrize(("p", "q"), [(1, 1), (3, 3), (2, 4), (5, 1)])
def test_bezier_surface_matches_geomdl(p, q):
    grid = random_grid(p + 1, q + 1, seed=p * 7 + q)
    surface = BezierSurface(grid)
    s = geomdl_surface(grid, p, q, [0] * (p + 1) + [1] * (p + 1), [0] * (q + 1) + [1] * (q + 1))
    u, v = parameter_pairs(seed=p)
    points, du, dv, duv = oracle_values(s, u, v)
    assert_close(surface.evaluate(u, v), points, TOL)
    assert_close(surface.partial(u, v, 1, 0), du, TOL)
    assert_close(surface.partial(u, v, 0, 1), dv, TOL)
    assert_close(surface.partial(u, v, 1, 1), duv, TOL)
    assert_close(surface.evaluate(0.3, 0.6), np.array(s.evaluate_single((0.3, 0.6))), TOL)


def test_bezier_surface_corners_edges_and_split():
    grid = random_grid(4, 4, seed=1)
    surface = BezierSurface(grid)
    assert_close(surface.evaluate([0, 1, 0, 1], [0, 0, 1, 1]), grid[[0, 3, 0, 3], [0, 0, 3, 3]], 1e-14)
    for axis in (0, 1):
        first, second = surface.split(0.4, axis)
        t = np.linspace(0, 1, 9)
        if axis == 0:
            assert_close(first.evaluate(t, t[::-1]), surface.evaluate(0.4 * t, t[::-1]), TOL)
            assert_close(second.evaluate(t, t[::-1]), surface.evaluate(0.4 + 0.6 * t, t[::-1]), TOL)
        else:
            assert_close(first.evaluate(t[::-1], t), surface.evaluate(t[::-1], 0.4 * t), TOL)


@pytest.mark.parametrize("kind", ["clamped", "uniform"])
def test_bspline_surface_matches_geomdl_and_ndbspline(kind):
    grid = random_grid(6, 5, seed=3)
    surface = BSplineSurface(grid, 3, 2, kind, kind)
    (u0, u1), (v0, v1) = surface.domain_u, surface.domain_v
    u, v = parameter_pairs(u0, u1, v0, v1, seed=4)
    s = geomdl_surface(grid, 3, 2, surface.knots_u, surface.knots_v)
    points, du, dv, duv = oracle_values(s, u, v)
    assert_close(surface.evaluate(u, v), points, TOL)
    assert_close(surface.partial(u, v, 1, 0), du, TOL)
    assert_close(surface.partial(u, v, 0, 1), dv, TOL)
    assert_close(surface.partial(u, v, 1, 1), duv, TOL)
    nd = NdBSpline((surface.knots_u, surface.knots_v), grid, (3, 2))
    assert_close(surface.evaluate(u, v), nd(np.stack([u, v], axis=1)), TOL)


def test_nurbs_surface_matches_geomdl():
    grid = random_grid(5, 4, seed=5)
    weights = np.random.default_rng(6).uniform(0.3, 2.5, size=(5, 4))
    surface = NURBSSurface(grid, weights, 2, 3)
    (u0, u1), (v0, v1) = surface.domain_u, surface.domain_v
    u, v = parameter_pairs(u0, u1, v0, v1, seed=7)
    s = geomdl_surface(grid, 2, 3, surface.knots_u, surface.knots_v, weights)
    points, du, dv, duv = oracle_values(s, u, v)
    assert_close(surface.evaluate(u, v), points, TOL)
    assert_close(surface.partial(u, v, 1, 0), du, TOL)
    assert_close(surface.partial(u, v, 0, 1), dv, TOL)
    assert_close(surface.partial(u, v, 1, 1), duv, TOL)


def test_nurbs_sphere_and_cylinder_are_exact():
    center = np.array([1.0, -2.0, 0.5])
    sphere = NURBSSurface.sphere(2.0, center)
    u, v = parameter_pairs(count=500, seed=8)
    distance = np.linalg.norm(sphere.evaluate(u, v) - center, axis=1)
    assert np.abs(distance - 2.0).max() <= 1e-12 * 2.0
    # outward unit normals everywhere, the poles included (limits at the collapsed rows)
    normals = sphere.normal(u, v)
    assert_close(normals, (sphere.evaluate(u, v) - center) / 2.0, 1e-9)
    assert_close(sphere.normal([0.3, 0.7], [0.0, 1.0]), [[0, 0, -1], [0, 0, 1]], 1e-12)
    cylinder = NURBSSurface.cylinder(1.5, 4.0, center)
    p = cylinder.evaluate(u, v) - center
    assert np.abs(np.hypot(p[:, 0], p[:, 1]) - 1.5).max() <= 1e-12
    assert_close(cylinder.evaluate([0.2, 0.2], [0.0, 1.0])[:, 2] - center[2], [-2.0, 2.0], 1e-14)
    n = cylinder.normal(u, v)
    assert_close(n, np.c_[p[:, :2] / 1.5, np.zeros(len(p))], 1e-9)


def test_tessellate_structure_and_winding():
    surface = BezierSurface(random_grid(4, 3, seed=9))
    mesh = surface.tessellate(6, 4)
    assert isinstance(mesh, Mesh)
    assert mesh.vertex_count == 7 * 5 and mesh.face_count == 2 * 6 * 4
    u, v = np.meshgrid(np.linspace(0, 1, 7), np.linspace(0, 1, 5), indexing="ij")
    assert_close(mesh.vertices, surface.evaluate(u.ravel(), v.ravel()), TOL)
    assert_close(mesh.vertex_normals, surface.normal(u.ravel(), v.ravel()), TOL)
    # counter-clockwise seen from the normal side: face normals agree with the analytic normals
    centroids_normal = mesh.vertex_normals[mesh.faces].sum(axis=1)
    assert ((mesh.face_normals * centroids_normal).sum(axis=1) > 0).mean() > 0.95


def test_tessellation_normals_are_finite_at_a_pole():
    grid = random_grid(4, 4, seed=10)
    grid[0] = grid[0, 0]  # collapse the u = 0 edge to one point (a cone-like pole)
    surface = BezierSurface(grid)
    mesh = surface.tessellate(8, 8)
    assert np.isfinite(mesh.vertex_normals).all()
    assert mesh.face_count == 2 * 8 * 8 - 8  # the 8 degenerate triangles at the pole are dropped
    # the pole normal is the limit of the interior normals
    v = np.linspace(0, 1, 5)
    assert_close(surface.normal(np.zeros(5), v), surface.normal(np.full(5, 1e-7), v), 1e-5)


@settings(max_examples=10)
@given(st.integers(0, 1000), st.sampled_from([1e-1, 1e-2]))
def test_property_adaptive_tessellation_is_within_tolerance(seed, tolerance):
    surface = BezierSurface(random_grid(4, 4, seed=seed))
    mesh = surface.tessellate_adaptive(tolerance)
    nu, nv = surface.flatness_resolution(tolerance)
    assert mesh.vertex_count == (nu + 1) * (nv + 1)
    # the surface at each triangle's parameter centroid against the triangle's centroid
    u, v = np.meshgrid(np.linspace(0, 1, nu + 1), np.linspace(0, 1, nv + 1), indexing="ij")
    uv = np.stack([u.ravel(), v.ravel()], axis=1)[mesh.faces].mean(axis=1)
    error = np.linalg.norm(surface.evaluate(uv[:, 0], uv[:, 1]) - mesh.vertices[mesh.faces].mean(axis=1), axis=1)
    assert error.max() <= tolerance
    coarse, fine = surface.flatness_resolution(1.0), surface.flatness_resolution(1e-3)
    assert fine[0] >= coarse[0] and fine[1] >= coarse[1]


@pytest.mark.parametrize(
    ("make", "fragment"),
    [
        (lambda: BezierSurface(np.zeros((4, 4, 2))), "shape (4, 4, 2)"),
        (lambda: BezierSurface(np.zeros((1, 4, 3))), "grid.shape[0] = 1"),
        (lambda: BezierSurface(np.where(np.arange(48).reshape(4, 4, 3) == 7, np.nan, 0.0)), "grid[0, 2]"),
        (lambda: BSplineSurface(random_grid(3, 5, 0), 3, 2), "grid.shape[0] = 3"),
        (lambda: BSplineSurface(random_grid(5, 5, 0), 0, 2), "degree_u = 0"),
        (lambda: BSplineSurface(random_grid(5, 5, 0), 2, 2, [0, 0, 0, 1, 1, 1]), "len(knots_u) = 6"),
        (lambda: BSplineSurface(random_grid(4, 4, 0), 2, 2, "clamped", [0, 0, 0, 2, 1, 1, 1]), "knots_v[4] = 1.0"),
        (lambda: NURBSSurface(random_grid(3, 3, 0), np.ones((3, 2))), "weights has shape (3, 2)"),
        (lambda: NURBSSurface(random_grid(3, 3, 0), np.full((3, 3), -1.0)), "weights[0] = -1.0"),
        (lambda: NURBSSurface.sphere(0.0), "radius = 0.0"),
        (lambda: BezierSurface(random_grid(4, 4, 0)).evaluate(0.5, 1.2), "v = 1.2"),
        (lambda: BezierSurface(random_grid(4, 4, 0)).evaluate([0.5, 0.2], [0.1, 0.2, 0.3]), "u has 2 values"),
        (lambda: BezierSurface(random_grid(4, 4, 0)).tessellate(0, 3), "nu = 0"),
        (lambda: BezierSurface(random_grid(4, 4, 0)).tessellate_adaptive(-1.0), "tolerance = -1.0"),
    ],
)
def test_bad_input_raises_geometry_error_naming_the_value(make, fragment):
    with pytest.raises(GeometryError) as info:
        make()
    assert fragment in str(info.value)
