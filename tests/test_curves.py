"""geometry/curves/ against bezier, SciPy (BPoly, BSpline, CubicSpline, CubicHermiteSpline) and geomdl, the seed's
curve properties as Hypothesis properties, and bad input."""

from __future__ import annotations

import math

import bezier
import geomdl.BSpline
import geomdl.NURBS
import numpy as np
import pytest
import scipy.interpolate as si
from geomdl import knotvector
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from frustum.errors import GeometryError
from frustum.geometry.curves import (
    M_B,
    M_H,
    BezierCurve,
    BSpline,
    Continuity,
    CubicSpline,
    HermiteCurve,
    NURBSCurve,
    PiecewiseBezier,
    bernstein,
    bezier_matrix_form,
    cardinal_spline,
    catmull_rom,
    continuity,
    cox_de_boor,
    hermite_blending,
    open_uniform_knots,
)
from oracles import assert_close

TOL = 1e-10  # the tolerance for every oracle comparison (the observed errors are ~1e-15)
TS = np.linspace(0.0, 1.0, 23)


def random_points(count: int, dimension: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-5.0, 5.0, size=(count, dimension))


def bezier_oracle(P: np.ndarray) -> bezier.Curve:
    # ORACLES trap 12: nodes are columns (dim, n), Fortran order
    return bezier.Curve(np.asfortranarray(P.T), degree=len(P) - 1)


coordinates = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)


def control_polygons(min_count: int = 2, max_count: int = 7, dimensions=(2, 3)):
    return st.tuples(st.integers(min_count, max_count), st.sampled_from(dimensions)).flatmap(
        lambda shape: arrays(np.float64, shape, elements=coordinates)
    )


# --- Bézier: oracles ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("degree", [1, 2, 3, 5, 8])
@pytest.mark.parametrize("dimension", [2, 3])
def test_bezier_evaluate_matches_bezier_and_bpoly(degree, dimension):
    P = random_points(degree + 1, dimension, seed=degree * 10 + dimension)
    curve = BezierCurve(P)
    assert_close(curve.evaluate(TS), bezier_oracle(P).evaluate_multi(TS).T, TOL)
    assert_close(curve.evaluate(TS), si.BPoly(P[:, None, :], [0.0, 1.0])(TS), TOL)
    assert_close(curve.evaluate(0.37), bezier_oracle(P).evaluate(0.37)[:, 0], TOL)


@pytest.mark.parametrize("degree", [1, 2, 3, 6])
def test_bezier_derivative_matches_hodograph(degree):
    P = random_points(degree + 1, 3, seed=degree)
    curve = BezierCurve(P)
    expected = np.array([bezier_oracle(P).evaluate_hodograph(t)[:, 0] for t in TS])
    assert_close(curve.derivative().evaluate(TS), expected, TOL)
    assert_close(curve.tangent(TS), si.BPoly(P[:, None, :], [0.0, 1.0]).derivative()(TS), TOL)
    assert curve.derivative().degree == degree - 1


@pytest.mark.parametrize("t0", [0.0, 0.25, 0.5, 0.9, 1.0])
def test_bezier_split_matches_specialize(t0):
    P = random_points(5, 2, seed=3)
    left, right = BezierCurve(P).split(t0)
    oracle = bezier_oracle(P)
    assert_close(left.control_points, oracle.specialize(0.0, t0).nodes.T, TOL)
    assert_close(right.control_points, oracle.specialize(t0, 1.0).nodes.T, TOL)


def test_bezier_split_is_the_seeds_construction():
    # the seed's figure: first half A, AB, ABC, ABCD; second half ABCD, BCD, CD, D (midpoints at t = 1/2)
    A, B, C, D = np.array([[0.0, 0.0], [1.0, 2.0], [3.0, 2.0], [4.0, 0.0]])
    AB, BC, CD = (A + B) / 2, (B + C) / 2, (C + D) / 2
    ABC, BCD = (AB + BC) / 2, (BC + CD) / 2
    ABCD = (ABC + BCD) / 2
    left, right = BezierCurve([A, B, C, D]).split(0.5)
    assert_close(left.control_points, [A, AB, ABC, ABCD], 1e-15)
    assert_close(right.control_points, [ABCD, BCD, CD, D], 1e-15)


def test_bezier_elevate_and_length_match_bezier():
    P = random_points(4, 3, seed=7)
    curve, oracle = BezierCurve(P), bezier_oracle(P)
    assert_close(curve.elevate().control_points, oracle.elevate().nodes.T, TOL)
    assert_close(curve.elevate().evaluate(TS), curve.evaluate(TS), TOL)
    assert math.isclose(curve.length(), oracle.length, rel_tol=TOL)


def test_bezier_length_of_a_straight_segment_is_exact():
    assert math.isclose(BezierCurve([[0, 0, 0], [1, 2, 2], [2, 4, 4], [3, 6, 6]]).length(), 9.0, rel_tol=1e-13)


@pytest.mark.parametrize("n", [1, 3, 6])
def test_bernstein_matches_bpoly_basis(n):
    for i in range(n + 1):
        unit = np.zeros((n + 1, 1))
        unit[i] = 1.0
        assert_close(bernstein(n, i, TS), si.BPoly(unit, [0.0, 1.0])(TS), TOL)
    assert bernstein(3, 1, 0.5) == pytest.approx(3 * 0.5 * 0.25)


def test_matrix_form_is_the_seeds_M_B_and_matches_de_casteljau():
    assert_close(M_B, [[-1, 3, -3, 1], [3, -6, 3, 0], [-3, 3, 0, 0], [1, 0, 0, 0]], 0)
    G = random_points(4, 3, seed=11)
    assert_close(bezier_matrix_form(TS, G), bezier_oracle(G).evaluate_multi(TS).T, TOL)
    assert_close(bezier_matrix_form(0.3, G), BezierCurve(G).evaluate(0.3), TOL)


def test_bounding_box_is_tight_and_contains_the_curve():
    P = np.array([[0.0, 0.0], [2.0, 5.0], [4.0, -5.0], [6.0, 0.0]])
    box = BezierCurve(P).bounding_box
    samples = BezierCurve(P).evaluate(np.linspace(0, 1, 200001))
    assert (samples >= box[0] - 1e-12).all() and (samples <= box[1] + 1e-12).all()
    assert_close(box, [samples.min(axis=0), samples.max(axis=0)], 1e-9)  # extremes between samples ~1e-10
    assert box[1, 1] < 5.0  # tighter than the control polygon's box


def test_convex_hull_contains_handles_degenerate_hulls():
    line = BezierCurve([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [3.0, 3.0, 3.0]])
    assert line.convex_hull_contains(line.evaluate(TS)).all()
    assert not line.convex_hull_contains([[4.0, 4.0, 4.0], [1.0, 0.0, 0.0]]).any()
    flat = BezierCurve([[0.0, 0.0, 1.0], [1.0, 2.0, 1.0], [2.0, 0.0, 1.0]])  # coplanar in 3D
    assert flat.convex_hull_contains([[1.0, 0.5, 1.0]]).all()
    assert not flat.convex_hull_contains([[1.0, 0.5, 1.1], [1.0, 2.5, 1.0]]).any()


def test_flatten_tolerance_bounds_the_distance_to_the_curve():
    P = np.array([[0.0, 0.0], [1.0, 3.0], [3.0, -2.0], [4.0, 1.0]])
    curve = BezierCurve(P)
    for tolerance in (1e-1, 1e-3):
        polyline = curve.flatten(tolerance)
        assert_close(polyline[[0, -1]], P[[0, -1]], 1e-15)
        samples = curve.evaluate(np.linspace(0, 1, 4001))
        assert _distance_to_polyline(samples, polyline).max() <= tolerance
    assert len(curve.flatten(1e-3)) > len(curve.flatten(1e-1))


def test_flatten_pixel_size_with_a_projection_gives_pixel_sized_pieces():
    curve = BezierCurve([[0.0, 0.0, 0.0], [0.2, 0.5, 0.0], [0.8, 0.5, 0.0], [1.0, 0.0, 0.0]])

    def project(points):  # a stand-in for camera.project: 200 pixels per unit, y up
        return 200.0 * points[:, :2] + 10.0

    polyline = curve.flatten(pixel_size=1.0, project=project)
    window = project(polyline)
    assert np.abs(np.diff(window, axis=0)).max() <= 1.0  # "no bigger than individual pixels"
    assert len(polyline) > 200  # the curve is about 230 pixels long
    coarse = curve.flatten(tolerance=0.5, project=project)  # flatness in pixels
    assert _distance_to_polyline(project(curve.evaluate(np.linspace(0, 1, 2001))), project(coarse)).max() <= 0.5


def test_flatten_with_a_camera_projection():
    # the seed: split "until the sections are no bigger than individual pixels", measured through a camera
    from frustum.camera import Camera, ViewFrame
    from frustum.projection import Perspective

    frame = ViewFrame(eye=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))
    camera = Camera(frame, Perspective(1.0, 0.5, 50.0), 160, 120)
    curve = BezierCurve([[-1.0, -1.0, 0.0], [-0.5, 2.0, 1.0], [0.5, -2.0, -1.0], [1.0, 1.0, 0.0]])
    polyline = curve.flatten(pixel_size=1.0, project=camera.project)
    window = camera.project(polyline)[:, :2]
    assert np.abs(np.diff(window, axis=0)).max() <= 1.0
    far = BezierCurve([[-1.0, -1.0, -40.0], [-0.5, 2.0, -40.0], [0.5, -2.0, -40.0], [1.0, 1.0, -40.0]])
    assert len(far.flatten(pixel_size=1.0, project=camera.project)) < len(polyline)  # fewer pixels far away


def _distance_to_polyline(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    rel = points[:, None, :] - a[None]
    s = np.clip((rel * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0, 1)
    return np.linalg.norm(rel - s[..., None] * ab, axis=-1).min(axis=1)


# --- Bézier: the seed's properties ---------------------------------------------------------------------------


@settings(max_examples=40)
@given(control_polygons())
def test_property_endpoints_and_end_tangents(P):
    curve = BezierCurve(P)
    n = len(P) - 1
    scale = max(1.0, np.abs(P).max())
    assert_close(curve.evaluate(np.array([0.0, 1.0])), P[[0, -1]], 1e-12 * scale)
    # property 2: C'(0) = n(P1 − P0), C'(1) = n(Pn − Pn−1): along the first and last legs
    assert_close(curve.tangent(0.0), n * (P[1] - P[0]), 1e-12 * scale)
    assert_close(curve.tangent(1.0), n * (P[-1] - P[-2]), 1e-12 * scale)


@settings(max_examples=40)
@given(control_polygons(min_count=3, max_count=6))
def test_property_curve_inside_convex_hull(P):
    curve = BezierCurve(P)
    assert curve.convex_hull_contains(curve.evaluate(TS), tolerance=1e-9).all()


@settings(max_examples=40)
@given(control_polygons(), st.floats(0.05, 0.95))
def test_property_subdivision_reproduces_the_curve(P, t0):
    curve = BezierCurve(P)
    left, right = curve.split(t0)
    scale = max(1.0, np.abs(P).max())
    assert_close(left.evaluate(TS), curve.evaluate(t0 * TS), 1e-11 * scale)
    assert_close(right.evaluate(TS), curve.evaluate(t0 + (1 - t0) * TS), 1e-11 * scale)


@settings(max_examples=30)
@given(st.integers(1, 9), st.floats(0.0, 1.0))
def test_property_bernstein_partition_of_unity(n, t):
    assert math.isclose(sum(bernstein(n, i, t) for i in range(n + 1)), 1.0, abs_tol=1e-14)


@settings(max_examples=40)
@given(control_polygons(min_count=3, max_count=6, dimensions=(2,)), st.floats(0, math.pi), st.floats(-5, 5))
def test_property_variation_diminishing(P, angle, offset):
    # a line crosses the curve no more often than it crosses the control polygon
    normal = np.array([math.cos(angle), math.sin(angle)])

    def crossings(polyline):
        side = polyline @ normal - offset
        side = side[np.abs(side) > 1e-9]  # touching points are not crossings
        return int((np.sign(side[:-1]) != np.sign(side[1:])).sum())

    curve = BezierCurve(P).evaluate(np.linspace(0, 1, 2001))
    assert crossings(curve) <= crossings(P)


# --- piecewise Bézier and continuity -------------------------------------------------------------------------


def test_continuity_classifies_parametric_and_geometric_joins():
    curve = BezierCurve(random_points(4, 3, seed=5))
    left, right = curve.split(0.3)
    # same curve, unit-width pieces: the derivatives are scaled by 0.3 and 0.7, so only proportional
    uneven = PiecewiseBezier([left, right])
    assert continuity(uneven, 0) == Continuity(0, 2)
    # with breakpoints at the split parameter the pieces are one polynomial: C2
    assert continuity(PiecewiseBezier([left, right], [0.0, 0.3, 1.0]), 0) == Continuity(2, 2)
    kink = PiecewiseBezier([[[0, 0], [1, 0], [2, 0], [3, 0]], [[3, 0], [3, 1], [3, 2], [3, 3]]])
    assert continuity(kink) == [Continuity(0, 0)]
    gap = PiecewiseBezier([[[0, 0], [1, 0], [2, 0], [3, 0]], [[4, 0], [5, 0], [6, 0], [7, 0]]])
    assert continuity(gap, 0) == Continuity(-1, -1)
    # C1 but different curvature: the second legs bend to opposite sides
    c1 = PiecewiseBezier([[[0, 0], [1, 1], [2, 0], [3, 0]], [[3, 0], [4, 0], [5, -1], [6, 0]]])
    assert continuity(c1, 0) == Continuity(1, 1)
    assert str(Continuity(1, 2)) == "C1 G2"


def test_from_tangents_is_c1_and_interpolate_c2_is_c2():
    P = random_points(6, 3, seed=9)
    R = random_points(6, 3, seed=10)
    c1 = PiecewiseBezier.from_tangents(P, R)
    assert all(j.parametric >= 1 for j in continuity(c1))
    assert_close(c1.evaluate(np.arange(6.0)), P, TOL)
    assert_close(c1.derivative().evaluate(np.arange(6.0)), R, TOL)
    c2 = PiecewiseBezier.interpolate_c2(P)
    assert all(j == Continuity(2, 2) for j in continuity(c2))
    assert_close(c2.evaluate(np.arange(6.0)), P, TOL)


def test_piecewise_matches_cubic_hermite_spline():
    P, R = random_points(5, 2, seed=1), random_points(5, 2, seed=2)
    x = np.array([0.0, 0.5, 2.0, 2.5, 4.0])
    u = np.linspace(0, 4, 41)
    curve = PiecewiseBezier.from_tangents(P, R, x)
    assert_close(curve.evaluate(u), si.CubicHermiteSpline(x, P, R)(u), TOL)
    assert_close(curve.derivative().evaluate(u), si.CubicHermiteSpline(x, P, R)(u, 1), TOL)
    assert len(curve.flatten(1e-2)) > 10


# --- Hermite, cardinal, Catmull–Rom ------------------------------------------------------------------------


def test_hermite_matches_cubic_hermite_spline_and_seed_blending():
    p0, p1, r0, r1 = random_points(4, 3, seed=4)
    curve = HermiteCurve(p0, p1, r0, r1)
    oracle = si.CubicHermiteSpline([0.0, 1.0], np.stack([p0, p1]), np.stack([r0, r1]))
    assert_close(curve.evaluate(TS), oracle(TS), TOL)
    assert_close(curve.tangent(TS), oracle(TS, 1), TOL)
    assert_close(curve.to_bezier().evaluate(TS), oracle(TS), TOL)
    # the seed's H1..H4: (2t³ − 3t² + 1), (−2t³ + 3t²), (t³ − 2t² + t), (t³ − t²)
    t = TS
    expected = np.stack([2 * t**3 - 3 * t**2 + 1, -2 * t**3 + 3 * t**2, t**3 - 2 * t**2 + t, t**3 - t**2], axis=1)
    assert_close(hermite_blending(t), expected, 1e-15)
    assert_close(M_H, np.linalg.inv([[0, 0, 0, 1], [1, 1, 1, 1], [0, 0, 1, 0], [3, 2, 1, 0]]), 1e-15)


@pytest.mark.parametrize("tension", [0.0, 0.5, -0.3])
def test_cardinal_spline_matches_hermite_with_cardinal_tangents(tension):
    P = random_points(7, 3, seed=12)
    tangents = (1 - tension) / 2 * (P[2:] - P[:-2])  # ORACLES: m_k = (1 − c)/2 · (P[k+1] − P[k−1])
    x = np.arange(5.0)
    u = np.linspace(0, 4, 37)
    assert_close(cardinal_spline(P, tension).evaluate(u), si.CubicHermiteSpline(x, P[1:-1], tangents)(u), TOL)
    if tension == 0.0:
        assert_close(catmull_rom(P).evaluate(u), cardinal_spline(P, 0.0).evaluate(u), 0)


# --- cubic spline interpolation ----------------------------------------------------------------------------


@pytest.mark.parametrize("end", ["natural", "clamped", "periodic", "not-a-knot"])
@pytest.mark.parametrize("parameterization", ["uniform", "chordal", "centripetal"])
def test_cubic_spline_matches_scipy(end, parameterization):
    P = random_points(7, 3, seed=21)
    tangents = random_points(2, 3, seed=22)
    spline = CubicSpline(P, end, parameterization, end_tangents=tangents if end == "clamped" else None)
    Y = spline.points  # periodic appends the first point
    # ORACLES trap 14: scipy's 'clamped' means zero slopes; given slopes are ((1, d0), (1, dn))
    bc = ((1, tangents[0]), (1, tangents[1])) if end == "clamped" else end
    oracle = si.CubicSpline(spline.knots, Y, bc_type=bc)
    s = np.linspace(*spline.domain, 57)
    for order in range(4):  # P''' jumps at knots; scipy's periodic wrap takes the first segment at the end
        inside = s if order < 3 else s[:-1]
        assert_close(spline.evaluate(inside, order), oracle(inside, order), TOL)
    # per-segment (a, b, c, d) in the local u in [0, 1]: scipy's c[m] multiplies (x − x_k)^(3−m)
    h = np.diff(spline.knots)[:, None]
    expected = np.stack([oracle.c[0] * h**3, oracle.c[1] * h**2, oracle.c[2] * h, oracle.c[3]], axis=1)
    assert_close(spline.coefficients, expected, TOL)
    assert_close(spline.to_bezier().evaluate(s), oracle(s), TOL)


def test_cubic_spline_parameterizations():
    P = np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 5.0], [8.0, 5.0]])
    assert_close(CubicSpline(P, parameterization="chordal").knots, [0, 5, 6, 11], 0)
    assert_close(CubicSpline(P, parameterization="centripetal").knots, np.cumsum([0, 5**0.5, 1, 5**0.5]), 1e-15)
    assert_close(CubicSpline(P).knots, [0, 1, 2, 3], 0)


# --- B-splines ---------------------------------------------------------------------------------------------


def _geomdl_curve(spline: BSpline) -> geomdl.BSpline.Curve:
    g = geomdl.BSpline.Curve(normalize_kv=False)  # ORACLES trap 13
    g.degree = spline.degree
    g.ctrlpts = spline.control_points.tolist()
    g.knotvector = spline.knots.tolist()
    return g


@pytest.mark.parametrize("kind", ["clamped", "uniform", "closed"])
@pytest.mark.parametrize("degree", [1, 2, 3, 4])
def test_bspline_matches_scipy_and_geomdl(kind, degree):
    P = random_points(8, 3, seed=degree)
    spline = BSpline(P, degree, kind)
    u = np.linspace(*spline.domain, 41)
    if kind == "closed":  # ORACLES: BSpline(arange(n + 2k + 1), vstack([P, P[:k]]), k, extrapolate='periodic')
        oracle = si.BSpline(np.arange(8 + 2 * degree + 1.0), np.vstack([P, P[:degree]]), degree, extrapolate="periodic")
    else:
        oracle = si.BSpline(spline.knots, P, degree)
    assert_close(spline.evaluate(u), oracle(u), TOL)
    g = _geomdl_curve(spline)
    assert_close(spline.evaluate(u), np.array(g.evaluate_list(u.tolist())), TOL)
    for m in range(1, degree + 1):  # the degree-th derivative jumps at knots: scipy's periodic wrap differs at the end
        inside = u if m < degree else u[:-1]
        assert_close(spline.derivative(m).evaluate(inside), oracle.derivative(m)(inside), TOL)
    assert_close(spline.derivative().evaluate(u[5]), g.derivatives(float(u[5]), order=1)[1], TOL)


def test_closed_bspline_is_periodic_and_smooth_across_the_seam():
    spline = BSpline(random_points(6, 2, seed=3), 3, "closed")
    low, high = spline.domain
    for m in range(3):  # C^(p−1) = C2 across the seam
        d = spline.derivative(m)
        assert_close(d.evaluate(low), d.evaluate(high), TOL)


def test_uniform_cubic_at_knots_is_the_one_four_one_average():
    P = random_points(7, 2, seed=4)
    spline = BSpline(P, 3, "uniform")
    knots_inside = np.arange(3.0, 8.0)
    i = knots_inside.astype(int)
    assert_close(spline.evaluate(knots_inside), (P[i - 3] + 4 * P[i - 2] + P[i - 1]) / 6, TOL)


def test_open_uniform_knots_is_the_seeds_formula_and_clamps():
    # seed: n + 1 = 7 control points, order k = 3 -> x = 0,0,0,1,2,3,4,5,5,5
    assert_close(open_uniform_knots(7, 2), [0, 0, 0, 1, 2, 3, 4, 5, 5, 5], 0)
    for count, degree in [(4, 3), (7, 2), (10, 3), (5, 1)]:
        knots = open_uniform_knots(count, degree)
        generated = np.array(knotvector.generate(degree, count)) * (count - degree)
        assert_close(knots, generated, 1e-12)
    P = random_points(7, 3, seed=8)
    spline = BSpline(P, 2)
    assert_close(spline.evaluate(np.array(spline.domain)), P[[0, -1]], 1e-14)
    assert spline.domain == (0.0, 5.0)  # the seed's 5 segments Q1..Q5 on [0, 1], ..., [4, 5]


@pytest.mark.parametrize("order", [1, 2, 3, 4])
def test_cox_de_boor_matches_scipy_basis_and_sums_to_one(order):
    knots = np.array([0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 3.5, 5.0, 5.0, 5.0])
    # off the knots: scipy's basis elements are closed at their right knot, the seed's steps half-open
    u = np.linspace(0.013, 4.987, 50)
    total = np.zeros_like(u)
    for i in range(knots.size - order):
        if knots[i] == knots[i + order]:  # empty support: 0 by the 0/0 = 0 rule (scipy returns 1 at the knot)
            expected = np.zeros_like(u)
        else:
            expected = si.BSpline.basis_element(knots[i : i + order + 1], extrapolate=False)(u)
        value = cox_de_boor(knots, i, order, u)
        assert_close(value, np.nan_to_num(expected), TOL)
        total += value
    if order == 3:  # degree 2 on a clamped vector: the domain is the whole vector
        assert_close(total, np.ones_like(u), 1e-14)
    assert cox_de_boor([0.0, 0.0, 1.0, 1.0], 1, 1, 0.5) == 1.0  # 0/0 = 0 elsewhere
    at_knots = np.array([0.0, 1.0, 2.0, 3.5, 5.0])  # half-open steps, the last one closed: still sums to 1
    assert_close(sum(cox_de_boor(knots, i, 3, at_knots) for i in range(knots.size - 3)), np.ones(5), 1e-14)


@settings(max_examples=25)
@given(st.integers(1, 4), st.integers(0, 5), st.floats(0.0, 1.0))
def test_property_bspline_partition_of_unity(degree, extra, fraction):
    spline = BSpline(random_points(degree + 1 + extra, 2, seed=0), degree, "uniform")
    low, high = spline.domain
    u = low + fraction * (high - low)
    total = sum(spline.basis(i, spline.order, u) for i in range(spline.count))
    assert math.isclose(total, 1.0, abs_tol=1e-13)


@settings(max_examples=25)
@given(st.integers(1, 4), st.integers(0, 6), st.sampled_from(["clamped", "uniform"]), st.data())
def test_property_local_control(degree, extra, kind, data):
    # moving control point i changes the curve only on [t_i, t_{i+k}] (k = order): the seed's local control
    P = random_points(degree + 1 + extra, 3, seed=extra)
    i = data.draw(st.integers(0, len(P) - 1))
    moved = P.copy()
    moved[i] += 1.0
    a, b = BSpline(P, degree, kind), BSpline(moved, degree, kind)
    u = np.linspace(*a.domain, 301)
    changed = np.abs(a.evaluate(u) - b.evaluate(u)).max(axis=1) > 1e-12
    low, high = a.support(i)
    assert ((u[changed] >= low) & (u[changed] <= high)).all()
    assert changed.any()


@pytest.mark.parametrize("kind", ["clamped", "uniform", "closed"])
def test_insert_knot_keeps_the_curve_and_matches_fitpack(kind):
    P = random_points(7, 3, seed=31)
    spline = BSpline(P, 3, kind)
    low, high = spline.domain
    u = np.linspace(low, high, 53)
    value = low + 0.37 * (high - low)
    inserted = spline.insert_knot(value, 2)
    assert inserted.count == spline.count + 2 and inserted.knots.size == spline.knots.size + 2
    assert_close(inserted.evaluate(u), spline.evaluate(u), TOL)
    if kind == "clamped":
        t, c, _ = si.insert(value, (spline.knots, list(P.T), 3), m=2)
        assert_close(inserted.knots, t, 1e-14)
        assert_close(inserted.control_points, np.array(c)[:, : inserted.count].T, TOL)


@pytest.mark.parametrize("kind", ["clamped", "uniform", "closed"])
def test_to_bezier_reproduces_the_spline_with_c2_joins(kind):
    spline = BSpline(random_points(8, 3, seed=41), 3, kind)
    pieces = spline.to_bezier()
    u = np.linspace(*spline.domain, 61)
    assert_close(pieces.evaluate(u), spline.evaluate(u), TOL)
    assert len(pieces) == len(np.unique(spline.knots[spline.degree : spline.count + 1])) - 1
    assert all(j == Continuity(2, 2) for j in continuity(pieces))
    assert_close(pieces.derivative().evaluate(u), spline.derivative().evaluate(u), TOL)


# --- NURBS -------------------------------------------------------------------------------------------------


def test_nurbs_circle_is_exact():
    for radius, center in [(1.0, (0.0, 0.0, 0.0)), (2.5, (1.0, -2.0, 3.0)), (0.3, (4.0, 5.0))]:
        circle = NURBSCurve.circle(radius, center)
        points = circle.evaluate(np.linspace(0.0, 1.0, 2001))
        distance = np.linalg.norm(points - np.asarray(center), axis=1)
        assert np.abs(distance - radius).max() <= 1e-12 * max(1.0, radius)
    unit = NURBSCurve.circle()
    assert_close(unit.knots, [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1], 0)
    w = math.sqrt(2) / 2
    assert_close(unit.weights, [1, w, 1, w, 1, w, 1, w, 1], 1e-15)


def test_nurbs_matches_geomdl():
    c = geomdl.NURBS.Curve()
    c.degree = 2
    c.ctrlpts = [
        [1, 0, 0],
        [1, 1, 0],
        [0, 1, 0],
        [-1, 1, 0],
        [-1, 0, 0],
        [-1, -1, 0],
        [0, -1, 0],
        [1, -1, 0],
        [1, 0, 0],
    ]
    w = math.sqrt(2) / 2
    c.weights = [1, w, 1, w, 1, w, 1, w, 1]
    c.knotvector = [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1]
    u = np.linspace(0, 1, 101)
    assert_close(NURBSCurve.circle().evaluate(u), np.array(c.evaluate_list(u.tolist())), TOL)
    # a random cubic NURBS
    P, weights = random_points(6, 3, seed=51), np.random.default_rng(52).uniform(0.2, 3.0, 6)
    curve = NURBSCurve(P, weights, 3)
    g = geomdl.NURBS.Curve(normalize_kv=False)
    g.degree, g.ctrlpts, g.weights, g.knotvector = 3, P.tolist(), weights.tolist(), curve.knots.tolist()
    u = np.linspace(*curve.domain, 37)
    assert_close(curve.evaluate(u), np.array(g.evaluate_list(u.tolist())), TOL)
    assert_close(curve.tangent(u[7]), g.derivatives(float(u[7]), order=1)[1], TOL)


def test_nurbs_and_bspline_flatten_within_tolerance():
    circle = NURBSCurve.circle(2.0, (1.0, 1.0))
    for tolerance in (1e-1, 1e-3):
        polyline = circle.flatten(tolerance)
        assert np.abs(np.linalg.norm(polyline - 1.0, axis=1) - 2.0).max() <= 1e-12  # points on the circle
        middles = (polyline[1:] + polyline[:-1]) / 2  # the chord's farthest point from the arc
        assert (2.0 - np.linalg.norm(middles - 1.0, axis=1)).max() <= tolerance
    assert len(circle.flatten(1e-3)) > len(circle.flatten(1e-1))
    spline = BSpline(random_points(7, 3, seed=54), 3)
    polyline = spline.flatten(1e-2)
    samples = spline.evaluate(np.linspace(*spline.domain, 3001))
    assert _distance_to_polyline(samples, polyline).max() <= 1e-2


def test_nurbs_with_unit_weights_is_the_bspline():
    P = random_points(6, 2, seed=53)
    u = np.linspace(0, 3, 19)
    assert_close(NURBSCurve(P, np.ones(6), 3).evaluate(u), BSpline(P, 3).evaluate(u), TOL)


def test_nurbs_ellipse_and_arc():
    ellipse = NURBSCurve.ellipse(3.0, 1.5, (1.0, 2.0))
    p = ellipse.evaluate(np.linspace(0, 1, 501)) - [1.0, 2.0]
    assert np.abs((p[:, 0] / 3.0) ** 2 + (p[:, 1] / 1.5) ** 2 - 1).max() <= 1e-12
    arc = NURBSCurve.arc(2.0, 0.25, 2.0, (0.0, 0.0, 1.0))
    ends = arc.evaluate(np.array([0.0, 1.0]))
    assert_close(
        ends, [[2 * math.cos(0.25), 2 * math.sin(0.25), 1.0], [2 * math.cos(2.0), 2 * math.sin(2.0), 1.0]], 1e-14
    )
    mid = arc.evaluate(np.linspace(0, 1, 301))
    assert np.abs(np.linalg.norm(mid[:, :2], axis=1) - 2.0).max() <= 1e-12
    angles = np.arctan2(mid[:, 1], mid[:, 0])
    assert (np.diff(angles) > 0).all()  # counter-clockwise, monotone
    assert len(arc.control_points) == 5  # a 1.75 rad sweep: two quadratic segments


@settings(max_examples=30)
@given(st.floats(-10.0, 10.0), st.floats(0.01, 2 * math.pi), st.floats(0.1, 100.0), st.tuples(coordinates, coordinates))
def test_property_nurbs_arcs_lie_on_their_circle(start, sweep, radius, center):
    arc = NURBSCurve.arc(radius, start, start + sweep, center)
    points = arc.evaluate(np.linspace(0.0, 1.0, 101)) - np.asarray(center)
    assert np.abs(np.linalg.norm(points, axis=1) - radius).max() <= 1e-12 * max(radius, np.abs(center).max(), 1.0)
    assert_close(
        points[[0, -1]],
        radius * np.array([[np.cos(start), np.sin(start)], [np.cos(start + sweep), np.sin(start + sweep)]]),
        1e-11 * (radius + 10),
    )


# --- bad input ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("make", "fragment"),
    [
        (lambda: BSpline(random_points(5, 2, 0), 0), "degree = 0"),
        (lambda: BSpline(random_points(5, 2, 0), 2.5), "degree = 2.5"),
        (lambda: BSpline(random_points(3, 2, 0), 3), "len(control_points) = 3"),
        (lambda: BezierCurve([[1.0, 2.0]]), "len(control_points) = 1"),
        (lambda: BSpline(random_points(4, 2, 0), 2, [0, 0, 0, 2, 1, 3, 3]), "knots[4] = 1.0"),
        (lambda: BSpline(random_points(4, 2, 0), 2, [0, 0, 0, 1, 2, 2]), "len(knots) = 6"),
        (lambda: BSpline(random_points(4, 2, 0), 2, "open"), "knots = 'open'"),
        (lambda: NURBSCurve(random_points(4, 2, 0), [1, 0.0, 1, 1], 2), "weights[1] = 0.0"),
        (lambda: NURBSCurve(random_points(4, 2, 0), [1, 1, -2.0, 1], 2), "weights[2] = -2.0"),
        (lambda: NURBSCurve(random_points(4, 2, 0), [1, 1, 1], 2), "weights has shape (3,)"),
        (lambda: BezierCurve([[0.0, 0.0], [np.nan, 1.0]]), "control_points[1] = (nan, 1.0)"),
        (lambda: BSpline([[0.0, 0.0], [1.0, 1.0], [2.0, np.inf]], 1), "control_points[2] = (2.0, inf)"),
        (lambda: BezierCurve(np.zeros((3, 4))), "shape (3, 4)"),
        (lambda: BezierCurve([[0, 0], [1, 1]]).evaluate(1.5), "t = 1.5"),
        (lambda: BezierCurve([[0, 0], [1, 1]]).evaluate([0.5, -0.1]), "t = -0.1"),
        (lambda: BSpline(random_points(5, 2, 0), 2).evaluate(3.5), "u = 3.5"),
        (lambda: NURBSCurve.circle().evaluate(1.01), "u = 1.01"),
        (lambda: CubicSpline(random_points(5, 2, 0)).evaluate(-1.0), "s = -1.0"),
        (lambda: CubicSpline(random_points(5, 2, 0), end="free"), "end = 'free'"),
        (lambda: CubicSpline(random_points(5, 2, 0), parameterization="arc"), "parameterization = 'arc'"),
        (lambda: CubicSpline(random_points(5, 2, 0), end="clamped"), "end_tangents = None"),
        (lambda: CubicSpline([[0, 0], [0, 0], [1, 1]], parameterization="chordal"), "points[1] = (0.0, 0.0)"),
        (lambda: CubicSpline(random_points(3, 2, 0), end="not-a-knot"), "len(points) = 3"),
        (lambda: cardinal_spline(random_points(3, 2, 0)), "len(points) = 3"),
        (lambda: NURBSCurve.circle(-1.0), "radius = -1.0"),
        (lambda: BezierCurve([[0, 0], [1, 1]]).flatten(0.0), "tolerance = 0.0"),
        (lambda: BezierCurve([[0, 0], [1, 1]]).flatten(), "give exactly one"),
        (lambda: BSpline(random_points(5, 2, 0), 2).insert_knot(1.0, 3), "times = 3"),
        (lambda: HermiteCurve([0, 0], [1, 1, 1], [0, 0], [0, 0]), "p1 has shape (1, 3)"),
        (lambda: bernstein(3, 4, 0.5), "i = 4"),
        (lambda: continuity(PiecewiseBezier([[[0, 0], [1, 1]]]), 0), "at = 0"),
        (lambda: PiecewiseBezier([[[0, 0], [1, 1]], [[1, 1], [2, 2]]], [0.0, 1.0, 1.0]), "breakpoints[2] = 1.0"),
    ],
)
def test_bad_input_raises_geometry_error_naming_the_value(make, fragment):
    with pytest.raises(GeometryError) as info:
        make()
    assert fragment in str(info.value)
