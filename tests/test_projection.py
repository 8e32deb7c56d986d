"""projection.py against PyGLM and trimesh.transformations, the seed's literal matrices, and properties.

Where the seed's matrices are garbled (M_ortho,norm), the tests write out Hearn & Baker's form from
*Computer Graphics with OpenGL*, chapter 10; the oblique sign is Hearn & Baker's,
``x_p = x + L1·(z_vp − z)·cos φ`` (ORACLES trap 15).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import trimesh.transformations as tf
from hypothesis import given
from hypothesis import strategies as st
from pyglm import glm
from scipy.spatial.transform import Rotation

from frustum.errors import CameraError
from frustum.projection import (
    MULTIVIEWS,
    Axonometric,
    Frustum,
    Oblique,
    Orthographic,
    Perspective,
    axonometric_rotation,
    cabinet,
    cavalier,
    dimetric,
    frustum,
    general_perspective,
    general_perspective_steps,
    isometric,
    multiview,
    oblique,
    oblique_from_vector,
    oblique_normalized,
    orthographic,
    perspective,
    perspective_onto_plane,
    trimetric,
    viewport,
)
from frustum.transforms import apply, compose, translate
from oracles import assert_close, glm_matrix
from strategies import coordinates

# PyGLM's projection builders compute and return float32 (ORACLES trap 2): 1e-6 relative is a few float32 ulps.
GLM_FLOAT32 = {"rtol": 1e-6, "atol": 1e-6}

fovys = st.floats(min_value=0.05, max_value=3.0)
aspects = st.floats(min_value=0.2, max_value=5.0)
nears = st.floats(min_value=0.01, max_value=10.0)
# far/near at most ~1e4: beyond that the float32 oracle loses the depth row (ORACLES tolerance advice).
depth_ratios = st.floats(min_value=1.01, max_value=1000.0)
half_sizes = st.floats(min_value=0.1, max_value=50.0)
oblique_alphas = st.floats(min_value=0.05, max_value=math.pi / 2 - 0.05)
phis = st.floats(min_value=-math.pi, max_value=math.pi)


@st.composite
def windows(draw: st.DrawFn) -> tuple[float, float, float, float]:
    """(left, right, bottom, top) with left < right and bottom < top by at least 0.1."""
    left, bottom = draw(st.floats(-20, 20)), draw(st.floats(-20, 20))
    return left, left + draw(st.floats(0.1, 40)), bottom, bottom + draw(st.floats(0.1, 40))


def f32(*values: float) -> list[float]:
    """Values rounded to float32, so PyGLM's float32 builders see exactly the inputs frustum sees."""
    return [float(np.float32(v)) for v in values]


def ndc(matrix: np.ndarray, points) -> np.ndarray:
    return apply(matrix, np.asarray(points, dtype=float))


# --- orthographic -----------------------------------------------------------------------------------------


@given(windows(), st.floats(-10, 10), st.floats(0.1, 100))
def test_orthographic_matches_glm_ortho_rh_no(window, near, depth):
    *window, near, far = f32(*window, near, near + depth)
    expected = glm_matrix(glm.orthoRH_NO(*window, near, far))
    np.testing.assert_allclose(orthographic(*window, near, far), expected, **GLM_FLOAT32)


def test_orthographic_is_hearn_baker_m_ortho_norm_written_out():
    # The seed's M_ortho,norm is garbled; this is Hearn & Baker's form in z_near = -near, z_far = -far.
    xw_min, xw_max, yw_min, yw_max, near, far = -2.0, 3.0, -1.0, 4.0, 0.5, 20.0
    z_near, z_far = -near, -far
    # fmt: off
    m_ortho_norm = np.array([
        [2 / (xw_max - xw_min), 0, 0, -(xw_max + xw_min) / (xw_max - xw_min)],
        [0, 2 / (yw_max - yw_min), 0, -(yw_max + yw_min) / (yw_max - yw_min)],
        [0, 0, -2 / (z_near - z_far), (z_near + z_far) / (z_near - z_far)],
        [0, 0, 0, 1],
    ])
    # fmt: on
    assert_close(orthographic(xw_min, xw_max, yw_min, yw_max, near, far), m_ortho_norm)


@given(windows(), st.floats(-10, 10), st.floats(0.1, 100))
def test_orthographic_maps_view_box_corners_onto_the_cube(window, near, depth):
    left, right, bottom, top = window
    far = near + depth
    corners = [[x, y, -z] for x in (left, right) for y in (bottom, top) for z in (near, far)]
    expected = [[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    # Entries up to ~1e3 in size; 1e-9 absolute is far above round-off and far below any real error.
    np.testing.assert_allclose(ndc(orthographic(*window, near, far), corners), expected, atol=1e-9)


def test_multiview_presets_are_orthonormal_principal_views():
    assert sorted(MULTIVIEWS) == ["bottom", "front", "left", "rear", "right", "top"]
    for name, view in MULTIVIEWS.items():
        direction, up = np.array(view.direction), np.array(view.up)
        assert multiview(name) is view
        assert np.count_nonzero(direction) == 1 and np.linalg.norm(direction) == 1.0
        assert direction @ up == 0.0 and np.linalg.norm(up) == 1.0
    assert MULTIVIEWS["front"].direction == (0.0, 0.0, -1.0)
    assert MULTIVIEWS["top"].direction == (0.0, -1.0, 0.0)


# --- perspective ------------------------------------------------------------------------------------------


@given(fovys, aspects, nears, depth_ratios)
def test_perspective_matches_glm_perspective_rh_no(fovy, aspect, near, ratio):
    fovy, aspect, near, far = f32(fovy, aspect, near, near * ratio)
    expected = glm_matrix(glm.perspectiveRH_NO(fovy, aspect, near, far))
    np.testing.assert_allclose(perspective(fovy, aspect, near, far), expected, **GLM_FLOAT32)


@given(windows(), nears, depth_ratios)
def test_frustum_matches_glm_frustum_rh_no(window, near, ratio):
    *window, near, far = f32(*window, near, near * ratio)
    expected = glm_matrix(glm.frustumRH_NO(*window, near, far))
    np.testing.assert_allclose(frustum(*window, near, far), expected, **GLM_FLOAT32)


@given(fovys, aspects, nears, depth_ratios)
def test_perspective_is_the_symmetric_frustum(fovy, aspect, near, ratio):
    top = near * math.tan(fovy / 2)
    right = aspect * top
    # Both are O(1)..O(1e3) entries of the same formula evaluated in different order: a few ulps apart.
    assert_close(perspective(fovy, aspect, near, near * ratio), frustum(-right, right, -top, top, near, near * ratio))


@given(windows(), nears, depth_ratios, st.floats(0, 1), st.floats(0, 1))
def test_frustum_maps_near_plane_to_minus_one_and_far_plane_to_plus_one(window, near, ratio, s, t):
    left, right, bottom, top = window
    far = near * ratio
    # A point on the near window and the point on the far plane along the same ray from the eye.
    on_near = np.array([left + s * (right - left), bottom + t * (top - bottom), -near])
    on_far = on_near * (far / near)
    result = ndc(frustum(*window, near, far), [on_near, on_far])
    # NDC values are O(1); the depth row loses ~far/near ulps to cancellation, hence 1e-9.
    np.testing.assert_allclose(result[:, 2], [-1.0, 1.0], atol=1e-9)
    np.testing.assert_allclose(result[0, :2], result[1, :2], atol=1e-9)
    np.testing.assert_allclose(result[0, :2], [2 * s - 1, 2 * t - 1], atol=1e-9)


@given(st.builds(lambda x, y, z: np.array([x, y, z]), coordinates, coordinates, coordinates), st.floats(-50, 50))
def test_perspective_onto_plane_matches_trimesh_projection_matrix(prp, z_vp):
    if abs(prp[2] - z_vp) < 1e-3:
        z_vp = prp[2] - 1.0
    expected = tf.projection_matrix([0.0, 0.0, z_vp], [0.0, 0.0, 1.0], perspective=prp)
    rng = np.random.default_rng(0)
    points = rng.uniform(-10, 10, (20, 3))
    points[:, 2] += prp[2] - 20.0  # all on one side of the PRP, none in its plane (w = 0)
    expected_points = apply(expected, points)
    # Both are the same rational function of O(100) inputs; relative round-off ~1e-13, checked at 1e-9 abs.
    np.testing.assert_allclose(apply(perspective_onto_plane(prp, z_vp), points), expected_points, atol=1e-9)
    np.testing.assert_allclose(expected_points[:, 2], z_vp, atol=1e-9)


def test_perspective_onto_plane_is_the_seed_parametric_line():
    prp, z_vp = np.array([1.0, -2.0, 5.0]), -3.0
    point = np.array([4.0, 7.0, -11.0])
    u = (z_vp - point[2]) / (prp[2] - point[2])  # the seed's parameter where the line meets z = z_vp
    expected = point - (point - prp) * u
    assert_close(apply(perspective_onto_plane(prp, z_vp), point), expected)


@given(windows(), nears, depth_ratios)
def test_general_perspective_with_prp_at_origin_and_view_plane_at_near_is_frustum(window, near, ratio):
    far = near * ratio
    # Same formula reached through four factors: entries agree to a few ulps of their O(far/near) size.
    assert_close(general_perspective((0, 0, 0), -near, window, near, far), frustum(*window, near, far), 1e-10)


@given(
    st.builds(lambda x, y, z: np.array([x, y, z]), coordinates, coordinates, coordinates),
    st.floats(0.5, 20),
    windows(),
    nears,
    depth_ratios,
)
def test_general_perspective_equals_frustum_about_the_prp(prp, distance, window, near, ratio):
    far = near * ratio
    z_vp = prp[2] - distance
    # The window on the view plane, seen from the PRP and scaled onto the near plane, gives the same frustum.
    scale = near / distance
    left, right, bottom, top = window
    relative = ((left - prp[0]) * scale, (right - prp[0]) * scale, (bottom - prp[1]) * scale, (top - prp[1]) * scale)
    expected = frustum(*relative, near, far) @ translate(*-prp)
    # Entries up to ~(far/near)·|prp| ≈ 1e5; the helper scales the 1e-10 tolerance by that size.
    assert_close(general_perspective(prp, z_vp, window, near, far), expected, 1e-10)


def test_general_perspective_steps_shear_then_scale_to_the_canonical_volume():
    prp, z_vp, window, near, far = np.array([1.0, 2.0, 3.0]), -2.0, (-1.0, 5.0, 0.0, 2.0), 1.0, 30.0
    steps = general_perspective_steps(prp, z_vp, window, near, far)
    assert [s.name.split()[0] for s in steps] == ["translate", "shear", "perspective", "scale"]
    window_center = np.array([2.0, 1.0, z_vp])
    moved = apply(steps[0].matrix, window_center)
    sheared = apply(steps[1].matrix, moved)
    # Step 1 puts the frustum centerline (PRP → window center) on the z axis.
    assert_close(sheared, [0.0, 0.0, z_vp - prp[2]])
    # Step 2 (perspective + scale) makes the window corners the cube's x, y extremes.
    total = compose(*(s.matrix for s in steps))
    corners = [[x, y, z_vp] for x in window[:2] for y in window[2:]]
    assert_close(ndc(total, corners)[:, :2], [[-1, -1], [-1, 1], [1, -1], [1, 1]])
    # near and far distances are measured from the PRP along -z.
    on_axis = [np.add(prp, [0, 0, -near]), np.add(prp, [0, 0, -far])]
    assert_close(ndc(total, on_axis)[:, 2], [-1.0, 1.0])


# --- oblique ----------------------------------------------------------------------------------------------


def test_oblique_from_vector_is_the_seed_m_oblique_written_out():
    vp_x, vp_y, vp_z, z_vp = 0.3, -0.7, 2.0, -4.0
    # fmt: off
    m_oblique = np.array([
        [1, 0, -vp_x / vp_z, z_vp * vp_x / vp_z],
        [0, 1, -vp_y / vp_z, z_vp * vp_y / vp_z],
        [0, 0, 1, 0],
        [0, 0, 0, 1],
    ])
    # fmt: on
    assert_close(oblique_from_vector([vp_x, vp_y, vp_z], z_vp), m_oblique)


@given(oblique_alphas, phis, st.floats(-20, 20))
def test_oblique_matches_trimesh_projection_matrix_hearn_baker_sign(alpha, phi, z_vp):
    l1 = 1 / math.tan(alpha)
    direction = [l1 * math.cos(phi), l1 * math.sin(phi), 1.0]
    expected = tf.projection_matrix([0, 0, z_vp], [0, 0, 1], direction=direction)
    points = np.random.default_rng(1).uniform(-10, 10, (16, 3))
    # The z coordinate is collapsed by trimesh and kept (for depth) by M_oblique: compare x, y.
    # Values up to ~L1·30 ≈ 600; 1e-9 absolute covers the round-off of both forms.
    result = apply(oblique(alpha, phi, z_vp), points)[:, :2]
    np.testing.assert_allclose(result, apply(expected, points)[:, :2], atol=1e-9)


@pytest.mark.parametrize(("preset", "length"), [(cavalier, 1.0), (cabinet, 0.5)])
@pytest.mark.parametrize("phi", [math.radians(30), math.radians(45)])
def test_cavalier_and_cabinet_draw_receding_unit_edges_at_length_and_angle_phi(preset, length, phi):
    cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, -1)], dtype=float)
    projected = apply(preset(phi), cube)[:, :2]
    for front in range(0, 8, 2):  # edges along z: (x, y, 0) -> (x, y, -1)
        edge = projected[front + 1] - projected[front]
        assert math.hypot(*edge) == pytest.approx(length, abs=1e-12)
        assert math.atan2(edge[1], edge[0]) == pytest.approx(phi, abs=1e-12)
    # Edges in the view plane keep their length: the front face is drawn true size.
    assert_close(projected[::2], cube[::2, :2])


@given(oblique_alphas, phis, windows(), st.floats(-5, 5), st.floats(0.5, 50))
def test_oblique_normalized_is_m_ortho_norm_times_m_oblique(alpha, phi, window, near, depth):
    l1 = 1 / math.tan(alpha)
    vector = [l1 * math.cos(phi), l1 * math.sin(phi), 1.0]
    expected = orthographic(*window, near, near + depth) @ oblique(alpha, phi, -near)
    assert_close(oblique_normalized(vector, *window, near, near + depth, z_vp=-near), expected, 1e-10)


# --- axonometric ------------------------------------------------------------------------------------------


def foreshortening(matrix: np.ndarray) -> np.ndarray:
    """Projected lengths of the world unit axes (x, y columns of the linear part)."""
    return np.linalg.norm(matrix[:2, :3], axis=0)


def test_isometric_matches_the_classic_rotation_and_foreshortens_equally():
    oracle = Rotation.from_euler("x", math.asin(math.tan(math.radians(30)))) * Rotation.from_euler(
        "y", math.radians(45)
    )
    # The classic angles: tilt 35.264°, turn 45°.
    assert math.degrees(math.asin(math.tan(math.radians(30)))) == pytest.approx(35.26439, abs=1e-5)
    assert_close(axonometric_rotation(math.radians(45), math.radians(35.264389682754654))[:3, :3], oracle.as_matrix())
    assert_close(foreshortening(isometric()), [math.sqrt(2 / 3)] * 3)
    assert_close(foreshortening(isometric(size=2.0)), [math.sqrt(2 / 3) / 2] * 3)


@pytest.mark.parametrize("ratio", [0.25, 0.5, 0.9, 1.2])
def test_dimetric_foreshortens_two_axes_equally_and_the_third_by_ratio(ratio):
    f_x, f_y, f_z = foreshortening(dimetric(ratio))
    assert f_x == pytest.approx(f_z, abs=1e-12)
    assert f_y / f_x == pytest.approx(ratio, abs=1e-12)
    assert abs(f_y - f_x) > 1e-3
    assert f_x**2 + f_y**2 + f_z**2 == pytest.approx(2.0, abs=1e-12)


def test_dimetric_ratio_one_is_isometric():
    assert_close(dimetric(1.0), isometric())


@given(st.floats(0.1, 1.4), st.floats(0.1, 1.4))
def test_trimetric_foreshortenings_satisfy_the_axonometric_identity(rotation_y, rotation_x):
    f = foreshortening(trimetric(rotation_y, rotation_x))
    oracle = (Rotation.from_euler("x", rotation_x) * Rotation.from_euler("y", rotation_y)).as_matrix()
    assert_close(f, np.linalg.norm(oracle[:2], axis=0))
    assert float(f @ f) == pytest.approx(2.0, abs=1e-12)


def test_trimetric_foreshortens_all_three_axes_differently():
    f_x, f_y, f_z = foreshortening(trimetric(math.radians(30), math.radians(20)))
    assert min(abs(f_x - f_y), abs(f_y - f_z), abs(f_x - f_z)) > 0.05


# --- viewport ---------------------------------------------------------------------------------------------


@given(st.floats(-100, 100), st.floats(-100, 100), st.floats(1, 4000), st.floats(1, 4000))
def test_viewport_matches_glm_project_window_formula(x, y, width, height):
    points_ndc = np.random.default_rng(2).uniform(-1, 1, (8, 3))
    expected = np.column_stack(
        [x + width * (points_ndc[:, 0] + 1) / 2, y + height * (points_ndc[:, 1] + 1) / 2, (points_ndc[:, 2] + 1) / 2]
    )
    result = apply(viewport(x, y, width, height), points_ndc)
    # glm.project with identity model/projection is the oracle for the same formula (float64 via dvec types).
    oracle = [
        np.array(glm.project(glm.dvec3(*p), glm.dmat4(1), glm.dmat4(1), glm.dvec4(x, y, width, height)))
        for p in points_ndc
    ]
    assert_close(result, expected, 1e-12)
    assert_close(result, oracle, 1e-12)


def test_viewport_pixel_centers_are_half_integers_and_ndc_edges_are_pixel_edges():
    window_from_ndc = viewport(0, 0, 4, 2)
    assert_close(apply(window_from_ndc, [[-1, -1, -1], [1, 1, 1]]), [[0, 0, 0], [4, 2, 1]])
    # The center of pixel 0 lies half a pixel (2/width in NDC / 2) inside the left edge.
    assert_close(apply(window_from_ndc, [-1 + 1 / 4, -1 + 1 / 2, 0]), [0.5, 0.5, 0.5])


def test_viewport_depth_range_maps_near_and_far():
    assert_close(apply(viewport(0, 0, 10, 10, depth_range=(0.25, 0.75)), [[0, 0, -1], [0, 0, 1]])[:, 2], [0.25, 0.75])


# --- projection types -------------------------------------------------------------------------------------


def test_projection_types_build_their_builders_matrix():
    aspect = 16 / 9
    assert_close(Perspective(1.0, 0.1, 100).matrix(aspect), perspective(1.0, aspect, 0.1, 100))
    assert_close(Frustum(-1, 2, -1, 1, 1, 10).matrix(aspect), frustum(-1, 2, -1, 1, 1, 10))
    assert_close(Orthographic(4, 1, 10).matrix(aspect), orthographic(-2 * aspect, 2 * aspect, -2, 2, 1, 10))
    expected = orthographic(-2 * aspect, 2 * aspect, -2, 2, 1, 9) @ oblique(math.pi / 4, 0.5, -5.0)
    assert_close(Oblique(math.pi / 4, 0.5, 4, 1, 9).matrix(aspect), expected)
    expected = orthographic(-2 * aspect, 2 * aspect, -2, 2, 1, 9) @ cabinet(z_vp=-5.0)
    assert_close(Oblique.cabinet(4, 1, 9).matrix(aspect), expected)
    rotation = Axonometric(math.pi / 4, math.asin(math.tan(math.pi / 6)), 2, -1, 1, pivot=0.0)
    assert_close(rotation.matrix(1.0), isometric())


def test_axonometric_presets_and_pivot():
    iso = Axonometric.isometric(2, -1, 1)
    assert iso.pivot == 0.0
    assert_close(iso.matrix(1.0), isometric())
    assert_close(Axonometric.dimetric(0.5, 2, -1, 1).matrix(1.0), dimetric(0.5))
    assert_close(Axonometric.trimetric(0.3, 0.2, 2, -1, 1).matrix(1.0), trimetric(0.3, 0.2))
    # The pivot (default the middle of [near, far]) stays on the line of sight: it maps to the NDC center.
    off = Axonometric.isometric(4, 5, 15)
    assert off.pivot == 10.0
    assert_close(apply(off.matrix(1.5), [0, 0, -10]), [0, 0, 0])


def test_projection_steps_compose_to_the_matrix():
    for projection in (
        Perspective(1.0, 0.1, 100),
        Frustum(-1, 2, -1, 1, 1, 10),
        Orthographic(4, 1, 10),
        Oblique.cavalier(4, 1, 10, phi=0.3),
        Axonometric.dimetric(0.7, 4, 1, 10),
    ):
        steps = projection.steps(1.25)
        assert all(step.name for step in steps)
        assert_close(compose(*(s.matrix for s in steps)), projection.matrix(1.25))
        assert projection.parallel == isinstance(projection, Orthographic | Oblique | Axonometric)


def test_projection_types_are_frozen_and_comparable():
    projection = Perspective(1, 0.1, 10)
    with pytest.raises(dataclasses.FrozenInstanceError):
        projection.near = 1.0  # type: ignore[misc]
    assert projection == Perspective(1.0, 0.1, 10.0)
    assert isinstance(projection.fovy, float)


# --- bad input --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: perspective(0.0, 1, 0.1, 10), r"perspective: fovy = 0\.0 is outside \(0, pi\)"),
        (lambda: perspective(math.pi, 1, 0.1, 10), r"fovy = 3\.14159\d* is outside \(0, pi\)"),
        (lambda: perspective(1, 1, 0.0, 10), r"perspective: near = 0\.0 must be > 0"),
        (lambda: perspective(1, 1, -1.0, 10), r"near = -1\.0 must be > 0"),
        (lambda: perspective(1, 1, 1.0, 1.0), r"far = 1\.0 must be > near = 1\.0"),
        (lambda: perspective(1, 0.0, 1.0, 10), r"aspect = 0\.0 must be > 0"),
        (lambda: perspective(float("nan"), 1, 0.1, 10), r"fovy = nan is not finite"),
        (lambda: frustum(1, 1, -1, 1, 1, 10), r"frustum: left = 1\.0 is not less than right = 1\.0"),
        (lambda: frustum(-1, 1, 1, 1, 1, 10), r"bottom = 1\.0 is not less than top = 1\.0"),
        (lambda: frustum(-1, 1, -1, 1, 0, 10), r"frustum: near = 0\.0 must be > 0"),
        (lambda: frustum(-1, 1, -1, 1, 5, 2), r"far = 2\.0 must be > near = 5\.0"),
        (lambda: orthographic(2, 2, -1, 1, 1, 10), r"orthographic: left = 2\.0 is not less than right = 2\.0"),
        (lambda: orthographic(-1, 1, -1, 1, 3, 3), r"near = 3\.0 is not less than far = 3\.0"),
        (lambda: oblique(0.0, 0.3), r"oblique: alpha = 0\.0 is outside \(0, pi/2\)"),
        (lambda: oblique(math.pi / 2, 0.3), r"alpha = 1\.57\d* is outside \(0, pi/2\)"),
        (lambda: oblique_from_vector([1, 1, 0]), r"projection_vector = \(1\.0, 1\.0, 0\.0\) is parallel"),
        (lambda: viewport(0, 0, 0, 10), r"viewport: width = 0\.0 must be > 0"),
        (lambda: viewport(0, 0, 10, -1), r"viewport: height = -1\.0 must be > 0"),
        (lambda: viewport(0, 0, 10, 10, depth_range=(0, 1, 2)), r"depth_range = .* is not a pair"),
        (lambda: dimetric(1.5), r"dimetric: ratio = 1\.5 is outside \(0, sqrt\(2\)\)"),
        (lambda: isometric(size=0), r"isometric: size = 0\.0 must be > 0"),
        (lambda: perspective_onto_plane([0, 0, 2], 2.0), r"z_vp = 2\.0 equals the PRP's z = 2\.0"),
        (lambda: general_perspective([0, 0, 0], 1.0, (-1, 1, -1, 1), 1, 10), r"z_vp = 1\.0 is not less than"),
        (lambda: general_perspective([0, 0, 0], -1.0, (1, 1, -1, 1), 1, 10), r"xw_min = 1\.0 is not less than"),
        (lambda: general_perspective([0, 0, 0], -1.0, (1, 2), 1, 10), r"window = \(1\.0, 2\.0\) has shape"),
        (lambda: multiview("side"), r"multiview: name = 'side' is unknown; expected one of"),
        (lambda: Perspective(4.0, 0.1, 10), r"perspective: fovy = 4\.0 is outside"),
        (lambda: Orthographic(0.0, 0.1, 10), r"Orthographic: height = 0\.0 must be > 0"),
        (lambda: Oblique(0.0, 0.3, 2, 1, 10), r"Oblique: alpha = 0\.0 is outside"),
        (lambda: Perspective(1.0, 0.1, 10).matrix(0.0), r"Perspective\.matrix: aspect = 0\.0 must be > 0"),
    ],
)
def test_bad_projection_input_raises_camera_error_naming_the_value(build, match):
    with pytest.raises(CameraError, match=match):
        build()
