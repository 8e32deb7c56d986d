"""clipping.py against brute-force sampling, shapely (2D and in each triangle's parameters), each other, the
seed's region-code tables, and properties (inside, idempotent, untouched when inside, area never grows)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from shapely.geometry import Polygon, box

from frustum.clipping import (
    REGION_BOTTOM,
    REGION_FAR,
    REGION_LEFT,
    REGION_NEAR,
    REGION_RIGHT,
    REGION_TOP,
    VIEW_VOLUME_PLANES,
    clip_line,
    clip_line_convex,
    clip_lines,
    clip_polygon,
    clip_triangles,
    inside_view_volume,
    plane_from_point_normal,
    region_code,
    transform_plane,
    trivially_accepted,
    trivially_rejected,
)
from frustum.errors import ClippingError
from frustum.raster import clip as kernels
from frustum.transforms import apply_homogeneous
from reference import (
    CUBE_PLANES,
    clip_triangle_after_divide,
    clip_triangle_in_parameters,
    distance_to_boundary,
    plane_margin,
    polygon_area_3d,
    random_clip_points,
    same_point_sets,
    sampled_interval,
)

# Clipped points are interpolations P_in + (P_out − P_in)·u: each coordinate carries a few ulps of round-off
# relative to the segment's size, so "inside" and "equal" are checked to 1e-12 relative to |P| (coordinates
# here are O(1)..O(10), 1e-12 is ~4500 ulps: ample for a handful of operations, far below any real error).
TOL = 1e-12

# (x, y, z, w) with |x|, |y|, |z| <= 3 and |w| <= 2: the cube's neighbourhood, both signs of w.
clip_coordinates = st.floats(min_value=-3.0, max_value=3.0, allow_nan=False, allow_infinity=False)
triangles_h = arrays(np.float64, (3, 4), elements=clip_coordinates)


def perspective(fovy: float, aspect: float, near: float, far: float) -> np.ndarray:
    """glm::perspectiveRH_NO, written out here so these tests do not depend on the viewing issue."""
    f = 1.0 / np.tan(fovy / 2.0)
    m = np.zeros((4, 4))
    m[0, 0], m[1, 1] = f / aspect, f
    m[2, 2], m[2, 3] = -(far + near) / (far - near), -2.0 * far * near / (far - near)
    m[3, 2] = -1.0
    return m


# --- region codes -----------------------------------------------------------------------------------------

# The seed's three tables, rows top (y > w) to bottom, columns left (x < −w) to right, bit 6 written first.
SEED_TABLES = {
    -2.0: ["011001 011000 011010", "010001 010000 010010", "010101 010100 010110"],  # in front of near
    0.0: ["001001 001000 001010", "000001 000000 000010", "000101 000100 000110"],  # between near and far
    2.0: ["101001 101000 101010", "100001 100000 100010", "100101 100100 100110"],  # behind far
}


def test_region_code_bit_order_matches_seed_tables():
    # The seed's inequalities are garbled (x and z swapped); its tables fix the order: bit 1 (lowest) left
    # w + x < 0, bit 2 right, bit 3 bottom w + y < 0, bit 4 top, bit 5 near w + z < 0, bit 6 far (Hearn–Baker).
    for z, rows in SEED_TABLES.items():
        for row, y in zip(rows, (2.0, 0.0, -2.0), strict=True):
            for code, x in zip(row.split(), (-2.0, 0.0, 2.0), strict=True):
                assert format(region_code([x, y, z, 1.0]), "06b") == code, (x, y, z)
    assert (REGION_LEFT, REGION_RIGHT, REGION_BOTTOM, REGION_TOP, REGION_NEAR, REGION_FAR) == (1, 2, 4, 8, 16, 32)


def test_region_code_bits_are_the_view_volume_planes_in_order():
    rng = np.random.default_rng(0)
    points = random_clip_points(rng, 2000)
    codes = region_code(points)
    for k, plane in enumerate(VIEW_VOLUME_PLANES):
        np.testing.assert_array_equal((codes >> k) & 1, (points @ plane < 0).astype(int))
    kernel_codes = np.empty(len(points), dtype=np.int64)
    kernels.region_codes(points, np.array(VIEW_VOLUME_PLANES), kernel_codes)
    np.testing.assert_array_equal(kernel_codes, codes)


def test_region_code_of_points_behind_the_eye_is_never_zero():
    # w < 0: w + x >= 0 and w − x >= 0 would need 2w >= 0, so some bit is always set.
    rng = np.random.default_rng(1)
    points = random_clip_points(rng, 1000)
    points[:, 3] = -np.abs(points[:, 3]) - 1e-3
    assert (region_code(points) != 0).all()
    assert not inside_view_volume(points).any()


def test_inside_view_volume_is_the_ndc_cube_for_positive_w():
    rng = np.random.default_rng(2)
    points = random_clip_points(rng, 2000, behind=False)
    ndc = points[:, :3] / points[:, 3:]
    np.testing.assert_array_equal(inside_view_volume(points), (np.abs(ndc) <= 1).all(axis=1))
    assert inside_view_volume([0.5, -1.0, 1.0, 1.0]) is True  # on the boundary counts as inside
    assert inside_view_volume([0.0, 0.0, 0.0, 0.0]) is False  # code 0, but no Cartesian position


def test_trivial_accept_and_reject_for_segments_and_polygons():
    inside_point, left, left_top, right = [0, 0, 0, 1.0], [-2, 0, 0, 1.0], [-2, 2, 0, 1.0], [2, 0, 0, 1.0]
    segments = np.stack(
        [region_code(np.array([inside_point, left, left])), region_code(np.array([inside_point] * 2 + [left_top]))],
        axis=-1,
    )
    np.testing.assert_array_equal(trivially_accepted(segments), [True, False, False])
    np.testing.assert_array_equal(trivially_rejected(segments), [False, False, True])
    # left and right ends: neither test decides; the segment crosses the whole cube
    codes = region_code(np.array([left, right]))
    assert not trivially_accepted(codes) and not trivially_rejected(codes)
    assert clip_line(left, right) is not None
    polygon = np.array([left, left_top, [-3, -1, 0, 1.0]])
    assert trivially_rejected(region_code(polygon)) is True
    assert clip_polygon(polygon).vertices.shape == (0, 4)


# --- line clipping ----------------------------------------------------------------------------------------


def _random_segments(seed: int, count: int, behind: bool = True) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return random_clip_points(rng, count, behind), random_clip_points(rng, count, behind)


def test_cohen_sutherland_liang_barsky_and_cyrus_beck_agree():
    p0s, p1s = _random_segments(3, 3000)
    batch = clip_lines(p0s, p1s)
    kept = 0
    for i, (p0, p1) in enumerate(zip(p0s, p1s, strict=True)):
        results = [clip_line(p0, p1, method=m) for m in ("liang-barsky", "cohen-sutherland", "cyrus-beck")]
        results.append(clip_line_convex(p0, p1, VIEW_VOLUME_PLANES))
        visible = [r is not None for r in results]
        assert visible == [bool(batch.keep[i])] * 4, (p0, p1, visible)
        if results[0] is None:
            continue
        kept += 1
        reference = results[0]
        np.testing.assert_array_equal(batch.starts[i], reference.start)
        np.testing.assert_array_equal(batch.parameters[i], [reference.u_start, reference.u_end])
        for other in results[1:]:
            np.testing.assert_allclose(other.start, reference.start, rtol=0, atol=TOL)
            np.testing.assert_allclose(other.end, reference.end, rtol=0, atol=TOL)
            np.testing.assert_allclose([other.u_start, other.u_end], [reference.u_start, reference.u_end], atol=TOL)
    assert 300 < kept < 2700  # both outcomes well represented, so the comparison has teeth
    assert np.isnan(batch.starts[~batch.keep]).all()


def test_clip_line_keeps_exactly_the_inside_part_by_sampling():
    p0s, p1s = _random_segments(4, 400)
    planes = np.array(VIEW_VOLUME_PLANES)
    for p0, p1 in zip(p0s, p1s, strict=True):
        u, inside_samples = sampled_interval(p0, p1, planes)
        clipped = clip_line(p0, p1)
        if clipped is None:
            assert not inside_samples.any()
            continue
        kept = (u >= clipped.u_start) & (u <= clipped.u_end)
        # Samples within 1e-9 of the clipped ends may fall either way by round-off of the end parameters.
        decisive = (np.abs(u - clipped.u_start) > 1e-9) & (np.abs(u - clipped.u_end) > 1e-9)
        np.testing.assert_array_equal(kept[decisive], inside_samples[decisive])
        np.testing.assert_allclose(clipped.start, p0 + (p1 - p0) * clipped.u_start, atol=TOL)


def test_clip_line_equals_clipping_after_the_divide_for_positive_w():
    p0s, p1s = _random_segments(5, 500, behind=False)
    for p0, p1 in zip(p0s, p1s, strict=True):
        a, b = p0[:3] / p0[3], p1[:3] / p1[3]
        # slab method on the NDC segment a + (b − a)s, independent of homogeneous coordinates
        lower, upper = 0.0, 1.0
        for axis in range(3):
            for bound in (-1.0, 1.0):
                da, db = (a[axis] - bound) * -bound, (b[axis] - bound) * -bound  # >= 0 inside
                if da < 0 and db < 0:
                    lower, upper = 1.0, 0.0
                elif da < 0 or db < 0:
                    s = da / (da - db)
                    lower, upper = (max(lower, s), upper) if da < 0 else (lower, min(upper, s))
        clipped = clip_line(p0, p1)
        if lower > upper:
            assert clipped is None
            continue
        ndc_start, ndc_end = a + (b - a) * lower, a + (b - a) * upper
        # The divide loses a few ulps relative to |xyz|/w (w >= 0.2, |xyz| <= 3): 1e-11 covers it.
        np.testing.assert_allclose(clipped.start[:3] / clipped.start[3], ndc_start, atol=1e-11)
        np.testing.assert_allclose(clipped.end[:3] / clipped.end[3], ndc_end, atol=1e-11)


def test_segment_crossing_w_zero_is_clipped_not_wrapped():
    clip_from_view = perspective(np.radians(60.0), 1.0, 0.5, 10.0)
    front, behind = np.array([0.3, 0.2, -4.0, 1.0]), np.array([-0.2, 0.1, 3.0, 1.0])  # behind: z > 0
    p0, p1 = clip_from_view @ front, clip_from_view @ behind
    assert p0[3] > 0 > p1[3]
    for method in ("liang-barsky", "cohen-sutherland", "cyrus-beck"):
        clipped = clip_line(p0, p1, method=method)
        assert clipped is not None
        # The kept part is the piece of the real segment between view depths −4 and −near: it lies in front,
        # at the same u, never on the far side of infinity that dividing the ends first would give.
        view_start = np.linalg.solve(clip_from_view, clipped.start)
        view_end = np.linalg.solve(clip_from_view, clipped.end)
        np.testing.assert_allclose(view_start[:3] / view_start[3], front[:3], atol=1e-12)
        u_near = (-0.5 - front[2]) / (behind[2] - front[2])
        np.testing.assert_allclose(clipped.u_end, u_near, atol=1e-12)
        np.testing.assert_allclose(view_end[:3] / view_end[3], front[:3] + (behind - front)[:3] * u_near, atol=1e-12)
        assert clipped.start[3] > 0 and clipped.end[3] > 0
        np.testing.assert_allclose(clipped.end[2] / clipped.end[3], -1.0, atol=1e-12)  # it ends on the near plane
    # Dividing first would wrap around: the point behind the eye lands beyond the *far* plane in NDC, so an
    # NDC clipper would keep a piece running off toward z_ndc = +1, away from the eye's side entirely.
    assert p1[2] / p1[3] > 1.0


def test_clip_line_output_inside_and_idempotent():
    p0s, p1s = _random_segments(6, 1000)
    batch = clip_lines(p0s, p1s)
    starts, ends = batch.starts[batch.keep], batch.ends[batch.keep]
    # Interpolated ends sit on a plane up to round-off: relative margin >= -TOL.
    assert plane_margin(starts).min() >= -TOL and plane_margin(ends).min() >= -TOL
    assert (starts[:, 3] > 0).all() and (ends[:, 3] > 0).all()  # nothing with w <= 0 survives
    again = clip_lines(starts, ends)
    assert again.keep.all()
    np.testing.assert_allclose(again.starts, starts, atol=TOL)
    np.testing.assert_allclose(again.ends, ends, atol=TOL)


def test_segment_fully_inside_is_returned_bit_for_bit():
    p0, p1 = np.array([0.1, -0.9, 0.5, 1.0]), np.array([1.9, 0.3, -1.2, 2.0])
    for method in ("liang-barsky", "cohen-sutherland", "cyrus-beck"):
        clipped = clip_line(p0, p1, method=method)
        assert clipped.u_start == 0.0 and clipped.u_end == 1.0
        np.testing.assert_array_equal(clipped.start, p0)
        np.testing.assert_array_equal(clipped.end, p1)


def test_user_plane_clips_lines_like_the_cube():
    plane = np.array([0.3, -1.0, 0.2, 0.25])
    p0s, p1s = _random_segments(7, 300)
    batch = clip_lines(p0s, p1s, planes=plane)
    all_planes = np.vstack([CUBE_PLANES, plane])
    for i in range(len(p0s)):
        cs = clip_line(p0s[i], p1s[i], method="cohen-sutherland", planes=plane)
        cb = clip_line_convex(p0s[i], p1s[i], all_planes)
        assert (cs is not None) == (cb is not None) == bool(batch.keep[i])
        if cs is not None:
            np.testing.assert_allclose(cs.start, batch.starts[i], atol=TOL)
            np.testing.assert_allclose(cb.end, batch.ends[i], atol=TOL)
    assert plane_margin(batch.starts[batch.keep], all_planes[None, -1]).min() >= -TOL


def test_cyrus_beck_clips_to_a_cartesian_box_by_sampling():
    # the cutaway box 0 <= x <= 1, −1 <= y <= 2, −0.5 <= z <= 0.5 as six inward planes on Cartesian points
    planes = np.array(
        [
            plane_from_point_normal((0, 0, 0), (1, 0, 0)),
            plane_from_point_normal((1, 0, 0), (-1, 0, 0)),
            plane_from_point_normal((0, -1, 0), (0, 1, 0)),
            plane_from_point_normal((0, 2, 0), (0, -1, 0)),
            plane_from_point_normal((0, 0, -0.5), (0, 0, 1)),
            plane_from_point_normal((0, 0, 0.5), (0, 0, -1)),
        ]
    )
    rng = np.random.default_rng(8)
    for _ in range(300):
        p0, p1 = rng.uniform(-2, 3, size=3), rng.uniform(-2, 3, size=3)
        u = np.linspace(0, 1, 2001)
        points = p0 + (p1 - p0) * u[:, None]
        in_box = (points >= [0, -1, -0.5]).all(axis=1) & (points <= [1, 2, 0.5]).all(axis=1)
        clipped = clip_line_convex(p0, p1, planes)
        if clipped is None:
            assert not in_box.any()
            continue
        assert clipped.start.shape == (3,)
        kept = (u >= clipped.u_start) & (u <= clipped.u_end)
        # samples within 1e-9 of an end parameter may go either way by round-off
        decisive = (np.abs(u - clipped.u_start) > 1e-9) & (np.abs(u - clipped.u_end) > 1e-9)
        np.testing.assert_array_equal(kept[decisive], in_box[decisive])


# --- polygon clipping -------------------------------------------------------------------------------------


def _random_polygon_2d(rng: np.random.Generator, convex: bool) -> np.ndarray:
    count = int(rng.integers(3, 9))
    # jittered but ordered angles, gaps below pi: the polygon is star-shaped about its center, hence simple
    angles = (np.arange(count) + rng.uniform(0.0, 0.5, count)) * 2 * np.pi / count
    radii = rng.uniform(0.5, 2.5) * (np.ones(count) if convex else rng.uniform(0.3, 1.0, count))
    center = rng.uniform(-1.5, 1.5, 2)
    return center + np.stack([np.cos(angles), np.sin(angles)], axis=1) * radii[:, None]


def test_clip_polygon_matches_shapely_in_2d():
    rng = np.random.default_rng(9)
    for trial in range(300):
        polygon_2d = _random_polygon_2d(rng, convex=trial % 2 == 0)
        w = rng.uniform(0.5, 3.0)  # a constant w > 0 scales the polygon: the divide undoes it
        z = rng.uniform(-0.9, 0.9)
        vertices_h = np.hstack([polygon_2d * w, np.full((len(polygon_2d), 1), z * w), np.full((len(polygon_2d), 1), w)])
        clipped = clip_polygon(vertices_h).vertices
        ndc = clipped[:, :2] / clipped[:, 3:]
        expected = Polygon(polygon_2d).intersection(box(-1, -1, 1, 1))
        # Areas are O(1); the divide and interpolation cost a few ulps each: 1e-12.
        area = Polygon(ndc).area if len(ndc) >= 3 else 0.0
        assert abs(area - expected.area) < 1e-12, trial
        if trial % 2 == 0 and expected.area > 0:  # convex: Sutherland–Hodgman gives exactly shapely's vertices
            expected_vertices = np.asarray(shapely.get_coordinates(expected.exterior))[:-1]
            assert same_point_sets(ndc, expected_vertices, 1e-12), trial


def test_clip_polygon_equals_clipping_after_the_divide_for_positive_w():
    rng = np.random.default_rng(10)
    for trial in range(200):
        triangle = random_clip_points(rng, 3, behind=False)
        clipped = clip_polygon(triangle).vertices
        expected = clip_triangle_after_divide(triangle)
        ndc = clipped[:, :3] / clipped[:, 3:]
        # NDC coordinates are O(1)..O(15) (w >= 0.2): 1e-10 absolute is ~1e-11 relative, a few hundred ulps
        # for shapely's intersections plus the divide.
        assert same_point_sets(ndc, expected, 1e-10), trial
        assert abs(polygon_area_3d(ndc) - polygon_area_3d(expected)) < 1e-10


def test_clip_polygon_matches_the_parameter_space_oracle_for_any_w():
    rng = np.random.default_rng(11)
    nonempty = 0
    for trial in range(300):
        triangle = random_clip_points(rng, 3)
        clipped = clip_polygon(triangle, attributes=np.eye(3))  # attributes = barycentric weights
        expected = clip_triangle_in_parameters(triangle)
        st_points = clipped.attributes[:, 1:]
        area = Polygon(st_points).area if len(st_points) >= 3 else 0.0
        # (s, t) lie in the unit triangle: areas to 1e-12 (round-off in interpolated weights)
        assert abs(area - expected.area) < 1e-12, trial
        if expected.area > 1e-9:
            nonempty += 1
            expected_st = np.asarray(shapely.get_coordinates(expected.exterior))[:-1]
            assert same_point_sets(st_points, expected_st, 1e-9), trial
            # positions are the barycentric combination of the corners
            np.testing.assert_allclose(clipped.vertices, clipped.attributes @ triangle, atol=1e-12)
    assert nonempty > 50


def test_clip_polygon_keeps_exactly_the_inside_part_by_sampling():
    rng = np.random.default_rng(12)
    for _ in range(60):
        triangle = random_clip_points(rng, 3)
        clipped = clip_polygon(triangle, attributes=np.eye(3))
        weights = rng.dirichlet(np.ones(3), size=2000)
        samples = weights @ triangle
        margin = plane_margin(samples)
        decisive = np.abs(margin) > 1e-9  # closer to a plane than 1e-9: either answer is round-off
        region = Polygon(clipped.attributes[:, 1:]) if len(clipped.vertices) >= 3 else Polygon()
        covered = (
            shapely.contains_xy(region, weights[:, 1], weights[:, 2]) if not region.is_empty else np.zeros(2000, bool)
        )
        np.testing.assert_array_equal(covered[decisive], margin[decisive] > 0)


def test_clip_polygon_returns_a_fully_inside_polygon_unchanged():
    vertices = np.array([[0.5, 0.5, 0.0, 1.0], [-0.9, 0.2, 0.3, 1.0], [-1.5, -1.5, 1.0, 2.0], [0.1, -0.7, -0.6, 1.0]])
    colors = np.arange(12.0).reshape(4, 3)
    result = clip_polygon(vertices, attributes=colors)
    np.testing.assert_array_equal(result.vertices, vertices)
    np.testing.assert_array_equal(result.attributes, colors)


@given(triangles_h)
def test_clip_polygon_output_is_inside_and_clipping_is_idempotent(triangle):
    scale = max(1.0, float(np.abs(triangle).max()))
    once = clip_polygon(triangle).vertices
    if len(once) == 0:
        return
    # on a plane up to round-off, relative to the size of the triangle the points were interpolated from
    assert plane_margin(once, scale=scale).min() >= -TOL
    # w > 0, except at the clip-space origin (0, 0, 0, 0), which no invertible matrix produces
    behind = once[:, 3] <= 0
    assert (np.abs(once[behind]).max(axis=1, initial=0.0) <= TOL * scale).all()
    twice = clip_polygon(once).vertices
    # Clipping again moves nothing but round-off: every corner is kept (within TOL·scale), and any extra
    # vertex lies on the first result's boundary (an edge lying on a plane to within round-off may be cut
    # at an arbitrary point of itself, adding a collinear vertex).
    tolerance = TOL * scale
    assert len(twice) > 0
    assert (np.linalg.norm(once[:, None] - twice[None], axis=2).min(axis=1) <= tolerance).all()
    assert (distance_to_boundary(twice, once) <= tolerance).all()


def test_polygon_in_the_eye_plane_is_invisible():
    # every vertex has w = 0: clipping collapses it onto the clip-space origin, which is no visible point
    # (Hypothesis found this one: a subnormal x made the first pass keep origin-like vertices)
    triangle = np.array([[2.2250738585072014e-308, 0, 0, 0], [-2.4375, 0, 0, 0], [0, 0, 0, 0.0]])
    assert len(clip_polygon(triangle).vertices) == 0
    assert len(clip_polygon([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0]]).vertices) == 0


def test_clip_polygon_area_never_grows_in_ndc():
    rng = np.random.default_rng(13)
    for _ in range(300):
        triangle = random_clip_points(rng, 3, behind=False)
        clipped = clip_polygon(triangle).vertices
        before = polygon_area_3d(triangle[:, :3] / triangle[:, 3:])
        after = polygon_area_3d(clipped[:, :3] / clipped[:, 3:])
        assert after <= before * (1 + 1e-12) + 1e-15  # equal when inside; round-off only


def test_clip_polygon_interpolates_attributes_linearly_in_clip_space():
    rng = np.random.default_rng(14)
    affine = rng.normal(size=(4, 5))  # attributes that are a linear function of the position
    for _ in range(100):
        polygon = random_clip_points(rng, 5)
        result = clip_polygon(polygon, attributes=polygon @ affine)
        np.testing.assert_allclose(result.attributes, result.vertices @ affine, atol=1e-11)  # O(10) values
    one_dim = clip_polygon(np.array([[-2.0, 0, 0, 1], [2.0, 0, 0, 1], [0, 2.0, 0, 1]]), attributes=[0.0, 1.0, 2.0])
    assert one_dim.attributes.ndim == 1 and len(one_dim.attributes) == len(one_dim.vertices)


def test_polygon_crossing_w_zero_keeps_only_w_positive_part():
    clip_from_view = perspective(np.radians(90.0), 1.0, 0.1, 50.0)
    view = np.array([[-1.0, -1.0, -5.0, 1.0], [1.0, -1.0, -5.0, 1.0], [0.0, -1.0, 5.0, 1.0]])  # one corner behind
    triangle = view @ clip_from_view.T
    assert triangle[2, 3] < 0
    clipped = clip_polygon(triangle).vertices
    assert len(clipped) >= 3 and (clipped[:, 3] > 0).all()
    back_in_view = np.linalg.solve(clip_from_view, clipped.T).T
    back_in_view = back_in_view[:, :3] / back_in_view[:, 3:]
    assert (back_in_view[:, 2] <= -0.1 + 1e-12).all()  # every kept point is beyond the near plane
    np.testing.assert_allclose(back_in_view[:, 1], -1.0, atol=1e-12)  # and on the triangle's plane y = −1


# --- triangle batches -------------------------------------------------------------------------------------


def _random_mesh(seed: int, vertex_count: int, face_count: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    vertices = random_clip_points(rng, vertex_count)
    faces = np.array([rng.choice(vertex_count, 3, replace=False) for _ in range(face_count)])
    return vertices, faces


def _output_face_weights(result, faces: np.ndarray, vertex_count: int) -> np.ndarray:
    """(F, 3, 3): each output face's vertices as barycentric weights of its source triangle."""
    weights = np.empty((len(result.faces), 3, 3))
    for f, (face, source) in enumerate(zip(result.faces, result.face_sources, strict=True)):
        for j, index in enumerate(face):
            if index < vertex_count:
                weights[f, j] = faces[source] == index
            else:
                assert result.new_vertex_sources[index - vertex_count] == source
                weights[f, j] = result.new_vertex_weights[index - vertex_count]
    return weights


def test_clip_triangles_matches_clip_polygon_and_the_parameter_space_oracle():
    vertices, faces = _random_mesh(15, 60, 400)
    result = clip_triangles(vertices, faces)
    face_weights = _output_face_weights(result, faces, len(vertices))
    np.testing.assert_allclose(  # output vertices are the weights' combinations of their source corners
        result.vertices[result.faces],
        np.einsum("fjk,fkc->fjc", face_weights, vertices[faces[result.face_sources]]),
        atol=1e-12,
    )
    for t, face in enumerate(faces):
        mine = result.face_sources == t
        textbook = clip_polygon(vertices[face]).vertices
        assert mine.sum() == max(len(textbook) - 2, 0)
        if not mine.any():
            assert clip_triangle_in_parameters(vertices[face]).area < 1e-12
            continue
        used = np.unique(result.faces[mine])
        assert same_point_sets(result.vertices[used], textbook, 1e-12), t
        pieces = shapely.union_all([Polygon(w[:, 1:]) for w in face_weights[mine]])
        expected = clip_triangle_in_parameters(vertices[face])
        # pieces tile the oracle's polygon: symmetric difference is round-off (unit-triangle areas)
        assert pieces.symmetric_difference(expected).area < 1e-12, t


def test_clip_triangles_leaves_inside_triangles_untouched_and_drops_outside_ones():
    inside_tri = [[0.1, 0.1, 0, 1.0], [0.5, 0.1, 0, 1.0], [0.1, 0.5, 0, 1.0]]
    outside_tri = [[2.0, 0, 0, 1.0], [3.0, 0, 0, 1.0], [2.0, 1, 0, 1.0]]
    crossing_tri = [[0.0, 0, 0, 1.0], [3.0, 0, 0, 1.0], [0.0, 0.5, 0, 1.0]]
    vertices = np.array(inside_tri + outside_tri + crossing_tri)
    faces = np.arange(9).reshape(3, 3)
    result = clip_triangles(vertices, faces)
    np.testing.assert_array_equal(result.vertices[:9], vertices)
    np.testing.assert_array_equal(result.faces[0], faces[0])
    np.testing.assert_array_equal(result.face_sources, [0, 2, 2])  # triangle 1 gone; 2 fanned in place
    assert {0, 1, 2} <= set(result.faces.ravel()) and not {3, 4, 5} & set(result.faces.ravel())
    assert {6, 8} <= set(result.faces[1:].ravel())  # surviving corners keep their input index
    status = np.empty(3, dtype=np.int8)
    codes = region_code(vertices)
    kernels.classify_triangles(faces, codes, status)
    np.testing.assert_array_equal(
        status, [kernels.TRIANGLE_INSIDE, kernels.TRIANGLE_OUTSIDE, kernels.TRIANGLE_CROSSING]
    )


def test_clip_triangles_output_inside_with_w_positive_and_winding_kept():
    rng = np.random.default_rng(16)
    vertices = random_clip_points(rng, 300, behind=False)
    faces = np.array([rng.choice(300, 3, replace=False) for _ in range(500)])
    result = clip_triangles(vertices, faces)
    used = np.unique(result.faces)
    assert plane_margin(result.vertices[used]).min() >= -TOL and (result.vertices[used, 3] > 0).all()

    def signed_area(tris_h):  # of the NDC triangles' xy projection
        xy = tris_h[:, :, :2] / tris_h[:, :, 3:]
        a, b = xy[:, 1] - xy[:, 0], xy[:, 2] - xy[:, 0]
        return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]

    output, source = signed_area(result.vertices[result.faces]), signed_area(vertices[faces[result.face_sources]])
    significant = np.abs(output) > 1e-9  # slivers' sign is round-off
    assert (np.sign(output[significant]) == np.sign(source[significant])).all()


def test_clip_triangles_interpolate_extends_any_attribute():
    vertices, faces = _random_mesh(17, 40, 200)
    rng = np.random.default_rng(17)
    affine = rng.normal(size=(4, 3))
    result = clip_triangles(vertices, faces)
    colors = result.interpolate(faces, vertices @ affine)
    assert colors.shape == (len(result.vertices), 3)
    np.testing.assert_allclose(colors, result.vertices @ affine, atol=1e-11)  # linear in clip space


def test_clip_triangles_with_a_world_space_cutaway_plane():
    clip_from_world = perspective(np.radians(70.0), 1.5, 0.2, 30.0) @ np.array(
        [[1.0, 0, 0, 0], [0, 1, 0, -0.5], [0, 0, 1, -6], [0, 0, 0, 1]]
    )
    rng = np.random.default_rng(18)
    world = rng.uniform(-4, 4, size=(200, 3))
    faces = np.array([rng.choice(200, 3, replace=False) for _ in range(300)])
    plane_world = plane_from_point_normal((0.5, 0.0, 0.0), (-1.0, 0.2, 0.0))  # keep x − 0.2y <= 0.5
    plane_clip = transform_plane(clip_from_world, plane_world)
    result = clip_triangles(apply_homogeneous(clip_from_world, world), faces, planes=plane_clip)
    used = np.unique(result.faces)
    kept_world = np.linalg.solve(clip_from_world, result.vertices[used].T).T
    kept_world = kept_world[:, :3] / kept_world[:, 3:]
    # world coordinates are O(10): plane values to 1e-10 after the inverse and the divide
    assert (kept_world @ plane_world[:3] + plane_world[3]).min() >= -1e-10
    without = clip_triangles(apply_homogeneous(clip_from_world, world), faces)
    assert len(result.faces) != len(without.faces)  # the cut changed something


def test_transform_plane_keeps_every_point_on_its_side():
    rng = np.random.default_rng(19)
    clip_from_world = perspective(np.radians(50.0), 1.0, 0.1, 100.0) @ np.array(
        [[0.0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, -3], [0, 0, 0, 1]]
    )
    planes = rng.normal(size=(5, 4))
    points = rng.uniform(-6, 6, size=(500, 3))
    clip_points = apply_homogeneous(clip_from_world, points)
    assert (clip_points[:, 3] < 0).any()  # some points behind the eye
    transformed = transform_plane(clip_from_world, planes)
    world_values = np.hstack([points, np.ones((500, 1))]) @ planes.T
    np.testing.assert_allclose(clip_points @ transformed.T, world_values, rtol=1e-9, atol=1e-9)  # O(10) values
    # one plane or many: the same solve, up to LAPACK's blocking (1 ulp)
    np.testing.assert_allclose(transform_plane(clip_from_world, planes[0]), transformed[0], rtol=1e-15)


def test_kernel_clip_triangle_writes_into_caller_scratch():
    planes = np.array(VIEW_VOLUME_PLANES)
    positions, weights = np.empty((2, 9, 4)), np.empty((2, 9, 3))
    p0, p1, p2 = np.array([-2.0, -2, 0, 1]), np.array([2.0, -2, 0, 1]), np.array([0.0, 2, 0, 1])
    count = kernels.clip_triangle(p0, p1, p2, planes, positions, weights)
    expected = clip_polygon(np.array([p0, p1, p2]), attributes=np.eye(3))
    assert count == len(expected.vertices)
    np.testing.assert_allclose(positions[0, :count], expected.vertices, atol=TOL)
    np.testing.assert_allclose(weights[0, :count], expected.attributes, atol=TOL)


# --- bad input --------------------------------------------------------------------------------------------

ZERO_PLANE = [0.0, 0.0, 0.0, 0.0]


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: region_code([[1.0, 2.0, 3.0]]), r"region_code: points_h has shape \(1, 3\)"),
        (lambda: region_code([[1.0, np.nan, 3.0, 1.0]]), r"points_h\[0\] = \(1.0, nan, 3.0, 1.0\) is not finite"),
        (lambda: inside_view_volume([1.0, 2.0]), r"inside_view_volume: points_h has shape \(2,\)"),
        (lambda: trivially_accepted([0.5, 1.0]), r"trivially_accepted: codes .* expected integer region codes"),
        (lambda: clip_line([0, 0, 0], [0, 0, 0, 1]), r"clip_line: p0 = .* has shape \(3,\)"),
        (lambda: clip_line([0, 0, 0, 1], [0, 0, np.inf, 1]), r"p1\[0\] = .* is not finite"),
        (lambda: clip_line([0, 0, 0, 1], [1, 0, 0, 1], method="sutherland"), r"method = 'sutherland' is unknown"),
        (lambda: clip_line([0, 0, 0, 1], [1, 0, 0, 1], planes=ZERO_PLANE), r"planes\[0\] = .* is degenerate"),
        (lambda: clip_lines(np.zeros((3, 4)), np.zeros((2, 4))), r"p0s has 3 rows and p1s has 2"),
        (lambda: clip_lines(np.zeros((3, 4)), np.zeros((3, 4)), planes=np.ones((58, 4))), r"at most 57 user planes"),
        (lambda: clip_line_convex([0, 0, 0], [1, 1, 1], [[0, 0, 0, 1.0]]), r"zero normal \(a, b, c\)"),
        (lambda: clip_line_convex([0, 0, 0], [1, 1, 1, 1], [[1, 0, 0, 1.0]]), r"different widths"),
        (lambda: clip_line_convex([0, 0, 0, 1], [1, 1, 1, 1], [[1, 0, 0]]), r"planes has shape \(1, 3\)"),
        (lambda: clip_polygon(np.zeros((2, 4))), r"vertices_h has 2 rows; a polygon needs at least 3"),
        (lambda: clip_polygon(np.ones((3, 4)), attributes=np.ones((4, 2))), r"attributes has shape \(4, 2\)"),
        (lambda: clip_polygon(np.ones((3, 4)), attributes=[1, np.nan, 2]), r"attributes\[1\] = .* is not finite"),
        (lambda: clip_polygon(np.ones((3, 4)), planes=[ZERO_PLANE]), r"clip_polygon: planes\[0\] .* degenerate"),
        (lambda: clip_triangles(np.ones((3, 4)), [[0, 1, 3]]), r"faces\[0\] = \[0, 1, 3\] indexes outside the 3"),
        (lambda: clip_triangles(np.ones((3, 4)), [[0.0, 1.0, 2.0]]), r"faces has dtype float64"),
        (lambda: clip_triangles(np.ones((3, 4)), [[0, 1]]), r"faces has shape \(1, 2\)"),
        (lambda: clip_triangles(np.ones((3, 3)), [[0, 1, 2]]), r"vertices_h has shape \(3, 3\)"),
        (lambda: transform_plane(np.zeros((4, 4)), [1, 0, 0, 1]), r"clip_from_world is singular"),
        (lambda: transform_plane(np.eye(4), ZERO_PLANE), r"plane\[0\] = .* is degenerate"),
        (lambda: plane_from_point_normal((0, 0, 0), (0, 0, 0)), r"normal = \(0.0, 0.0, 0.0\) has zero length"),
    ],
)
def test_bad_input_raises_clipping_error_naming_the_value(call, match):
    with pytest.raises(ClippingError, match=match):
        call()


def test_empty_inputs_give_empty_outputs():
    assert region_code(np.empty((0, 4))).shape == (0,)
    assert clip_lines(np.empty((0, 4)), np.empty((0, 4))).keep.shape == (0,)
    assert clip_polygon(np.empty((0, 4))).vertices.shape == (0, 4)
    result = clip_triangles(np.empty((0, 4)), np.empty((0, 3), dtype=np.int64))
    assert result.vertices.shape == (0, 4) and result.faces.shape == (0, 3)
