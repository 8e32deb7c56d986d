"""transforms.py against PyGLM, SciPy and trimesh.transformations, the seed's literal matrices, and properties."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh.transformations as tf
from hypothesis import given
from hypothesis import strategies as st
from pyglm import glm
from scipy.spatial.transform import Rotation

import frustum
from frustum import (
    GeometryError,
    Quaternion,
    TransformError,
    apply,
    apply_homogeneous,
    apply_to_directions,
    apply_to_normals,
    compose,
    invert,
    reflect,
    rotate,
    rotate_steps,
    rotate_x,
    rotate_y,
    rotate_z,
    scale,
    shear,
    swaps_handedness,
    to_row_major,
    translate,
)
from oracles import assert_close, glm_matrix, glm_vec
from strategies import angles, axes, coordinates, point_arrays, scale_factors, vectors

COORDINATE_ROTATIONS = {"x": rotate_x, "y": rotate_y, "z": rotate_z}
UNIT_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


@st.composite
def affine_matrices(draw: st.DrawFn) -> np.ndarray:
    """A random invertible affine composite: scale, shear, rotation about a point, translation."""
    return compose(
        scale(draw(scale_factors), draw(scale_factors), draw(scale_factors)),
        shear(draw(st.sampled_from("xyz")), draw(st.floats(-2, 2)), draw(st.floats(-2, 2))),
        rotate(draw(axes()), draw(angles), draw(vectors())),
        translate(*draw(vectors())),
    )


@st.composite
def projective_matrices(draw: st.DrawFn) -> np.ndarray:
    """An affine composite followed by a perspective-like matrix (w = -z), well conditioned."""
    near, far = draw(st.floats(0.1, 1.0)), draw(st.floats(5.0, 100.0))
    # fmt: off
    clip_from_view = np.array([
        [1.5, 0.0, 0.0,                          0.0],
        [0.0, 2.0, 0.0,                          0.0],
        [0.0, 0.0, -(far + near) / (far - near), -2 * far * near / (far - near)],
        [0.0, 0.0, -1.0,                         0.0],
    ])
    # fmt: on
    return clip_from_view @ draw(affine_matrices())


def homogeneous(points: np.ndarray) -> np.ndarray:
    return np.c_[points, np.ones(len(points))]


# --- oracles ----------------------------------------------------------------------------------------------


def test_pyglm_numpy_layout_is_mathematical():
    # ORACLES trap 1: every oracle comparison below assumes np.array(glm matrix) is the math layout.
    assert np.array(glm.translate(glm.vec3(1, 2, 3)))[0, 3] == 1


@given(vectors())
def test_translate_matches_glm(offset):
    assert_close(translate(*offset), glm_matrix(glm.translate(glm_vec(offset))))
    assert_close(translate(*offset), tf.translation_matrix(offset))


@pytest.mark.parametrize("name", "xyz")
@given(angle=angles)
def test_rotate_about_coordinate_axes_matches_glm_and_scipy(name, angle):
    expected = glm_matrix(glm.rotate(angle, glm_vec(UNIT_AXES[name])))
    assert_close(COORDINATE_ROTATIONS[name](angle), expected)
    assert_close(COORDINATE_ROTATIONS[name](angle)[:3, :3], Rotation.from_euler(name, angle).as_matrix())


@given(axis=axes(), angle=angles, point=vectors())
def test_rotate_about_any_axis_through_any_point_matches_oracles(axis, angle, point):
    assert_close(rotate(axis, angle, point), tf.rotation_matrix(angle, axis, point=point))
    p = glm_vec(point)
    expected = glm.translate(p) * glm.rotate(angle, glm_vec(axis)) * glm.translate(-p)
    assert_close(rotate(axis, angle, point), glm_matrix(expected))


@given(axis=axes(), angle=angles, point=vectors())
def test_rotate_equals_the_quaternion_route(axis, angle, point):
    # The seed's "more efficient method" for arbitrary axes: T(p) · R(q) · T(-p), to 1e-12.
    via_quaternion = compose(translate(*-point), Quaternion.from_axis_angle(axis, angle).to_matrix(), translate(*point))
    assert_close(rotate(axis, angle, point), via_quaternion)


@given(axis=axes(), angle=angles, point=vectors())
def test_rotate_steps_compose_to_rotate(axis, angle, point):
    steps = rotate_steps(axis, angle, point)
    assert len(steps) == 7
    assert_close(compose(*(step.matrix for step in steps)), rotate(axis, angle, point), tol=1e-11)
    # after translating and the two alignment rotations, the axis direction lies on +z
    aligned = apply_to_directions(compose(*(s.matrix for s in steps[:3])), axis / np.linalg.norm(axis))
    assert_close(aligned, [0.0, 0.0, 1.0])


@pytest.mark.parametrize("axis", [(1, 0, 0), (-2, 0, 0), (0, 1, 0), (0, 0, 1)])
def test_rotate_steps_handle_axes_along_coordinate_axes(axis):
    steps = rotate_steps(axis, 0.7, (1, 2, 3))
    assert_close(compose(*(s.matrix for s in steps)), rotate(axis, 0.7, (1, 2, 3)))


@given(angle=angles, point=vectors())
def test_rotate_about_axis_parallel_to_z_is_translate_rotate_translate(angle, point):
    # The seed's special case: translate the axis onto the coordinate axis, rotate, translate back.
    expected = compose(translate(*-point), rotate_z(angle), translate(*point))
    assert_close(rotate((0, 0, 1), angle, point), expected)


@given(sx=scale_factors, sy=scale_factors, sz=scale_factors, fixed=vectors())
def test_scale_about_fixed_point_matches_glm(sx, sy, sz, fixed):
    f = glm_vec(fixed)
    expected = glm.translate(f) * glm.scale(glm_vec((sx, sy, sz))) * glm.translate(-f)
    assert_close(scale(sx, sy, sz, fixed), glm_matrix(expected))
    assert_close(apply(scale(sx, sy, sz, fixed), fixed), fixed)


@given(normal=axes(), point=vectors())
def test_reflect_matches_trimesh_and_glm(normal, point):
    assert_close(reflect(normal, point), tf.reflection_matrix(point, normal))
    direction = np.array([0.3, -1.2, 2.0])
    unit = normal / np.linalg.norm(normal)
    expected = np.array(glm.reflect(glm_vec(direction), glm_vec(unit)))
    assert_close(apply_to_directions(reflect(normal, point), direction), expected)


def test_reflect_about_xy_plane_is_the_seed_m_zreflect():
    # fmt: off
    m_zreflect = np.array([
        [1, 0,  0, 0],
        [0, 1,  0, 0],
        [0, 0, -1, 0],
        [0, 0,  0, 1],
    ], dtype=float)
    # fmt: on
    np.testing.assert_array_equal(reflect("xy"), m_zreflect)
    np.testing.assert_array_equal(reflect((0, 0, 5)), m_zreflect)
    np.testing.assert_array_equal(reflect("yz"), np.diag([-1.0, 1, 1, 1]))
    np.testing.assert_array_equal(reflect("zx"), np.diag([1.0, -1, 1, 1]))


@given(a=st.floats(-3, 3), b=st.floats(-3, 3), ref=coordinates)
def test_z_shear_is_the_seed_m_zshear(a, b, ref):
    # fmt: off
    m_zshear = np.array([
        [1, 0, a, -a * ref],
        [0, 1, b, -b * ref],
        [0, 0, 1, 0],
        [0, 0, 0, 1],
    ], dtype=float)
    # fmt: on
    np.testing.assert_array_equal(shear("z", a, b, ref), m_zshear)


def test_x_and_y_shears_are_the_seed_equations():
    # x-axis shear: y_new = y + sh_y·x, z_new = z + sh_z·x (the seed's matrix, written out)
    # fmt: off
    x_shear = np.array([
        [1,   0, 0, 0],
        [0.5, 1, 0, 0],
        [2.0, 0, 1, 0],
        [0,   0, 0, 1],
    ])
    # fmt: on
    np.testing.assert_array_equal(shear("x", 0.5, 2.0), x_shear)
    # y-axis shear: x_new = x + sh_x·y, z_new = z + sh_z·y
    assert_close(apply(shear("y", 0.5, 2.0), (1.0, 3.0, 4.0)), (1 + 0.5 * 3, 3.0, 4 + 2.0 * 3))


@pytest.mark.parametrize(("axis", "first", "second"), [("x", "y", "z"), ("y", "x", "z"), ("z", "x", "y")])
@given(a=st.floats(-3, 3), b=st.floats(-3, 3), ref=coordinates)
def test_shear_matches_trimesh_shear_composite(axis, first, second, a, b, ref):
    # trimesh shears by an angle: factor = tan(angle); two shears along the two other axes compose.
    normal = np.array(UNIT_AXES[axis])
    on_plane = normal * ref
    expected = tf.shear_matrix(math.atan(a), UNIT_AXES[first], on_plane, normal) @ tf.shear_matrix(
        math.atan(b), UNIT_AXES[second], on_plane, normal
    )
    assert_close(shear(axis, a, b, ref), expected)


def test_coordinate_rotations_are_one_formula_under_cyclic_permutation():
    # x -> y -> z -> x: relabel (x, y, z) as (y, z, x), rotate about the new third axis, relabel back.
    relabel = np.eye(4)[[1, 2, 0, 3]]  # relabel @ (x, y, z, 1) = (y, z, x, 1)
    for angle in np.linspace(-np.pi, np.pi, 13):
        assert_close(rotate_x(angle), relabel.T @ rotate_z(angle) @ relabel)
        assert_close(rotate_y(angle), relabel.T @ rotate_x(angle) @ relabel)
        assert_close(rotate_z(angle), relabel.T @ rotate_y(angle) @ relabel)


def test_seed_row_major_rotation_is_the_transpose_of_the_column_major_one():
    # The seed's row-major R_z (P' = P·R): rows x, y, z, 1; columns x', y', z', 1.
    c, s = math.cos(0.4), math.sin(0.4)
    # fmt: off
    row_major_rz = np.array([
        [ c, s, 0, 0],
        [-s, c, 0, 0],
        [ 0, 0, 1, 0],
        [ 0, 0, 0, 1],
    ])
    # fmt: on
    assert_close(to_row_major(rotate_z(0.4)), row_major_rz)
    point = np.array([[2.0, -1.0, 0.5, 1.0]])
    assert_close(point @ row_major_rz, apply_homogeneous(rotate_z(0.4), point))


# --- composition ------------------------------------------------------------------------------------------


@given(a=affine_matrices(), b=affine_matrices(), c=affine_matrices())
def test_compose_applies_first_argument_first(a, b, c):
    assert_close(compose(a, b, c), c @ b @ a, tol=1e-9)
    assert_close(compose(a, b, c), tf.concatenate_matrices(c, b, a), tol=1e-9)
    assert_close(compose(a, b, c), glm_matrix(glm.dmat4(c) * glm.dmat4(b) * glm.dmat4(a)), tol=1e-9)


@given(a=affine_matrices(), b=affine_matrices(), c=affine_matrices())
def test_compose_is_associative(a, b, c):
    # Products of three random affine matrices have entries up to ~1e4; 1e-9 relative covers the round-off.
    assert_close(compose(compose(a, b), c), compose(a, compose(b, c)), tol=1e-9)


def test_compose_of_nothing_is_identity():
    np.testing.assert_array_equal(compose(), np.eye(4))


def test_compose_order_matters_for_rotate_then_translate():
    # rotate first then translate moves (1,0,0) to (0,1,0)+(5,0,0); the other order rotates the offset too.
    assert_close(apply(compose(rotate_z(np.pi / 2), translate(5, 0, 0)), (1, 0, 0)), (5, 1, 0))
    assert_close(apply(compose(translate(5, 0, 0), rotate_z(np.pi / 2)), (1, 0, 0)), (0, 6, 0))


# --- properties -------------------------------------------------------------------------------------------


@given(axis=axes(), angle=angles, point=vectors())
def test_rotate_is_orthonormal_with_det_plus_one(axis, angle, point):
    block = rotate(axis, angle, point)[:3, :3]
    assert_close(block.T @ block, np.eye(3))
    assert math.isclose(np.linalg.det(block), 1.0, abs_tol=1e-12)
    assert not swaps_handedness(rotate(axis, angle, point))


@given(axis=axes(), angle=angles, points=point_arrays())
def test_rotate_preserves_distances(axis, angle, points):
    moved = apply(rotate(axis, angle, (1.0, -2.0, 3.0)), points)
    before = np.linalg.norm(points[:, None] - points[None], axis=-1)
    after = np.linalg.norm(moved[:, None] - moved[None], axis=-1)
    assert_close(after, before, tol=1e-11)


@given(normal=axes(), point=vectors())
def test_reflect_has_det_minus_one_and_swaps_handedness(normal, point):
    m = reflect(normal, point)
    assert math.isclose(np.linalg.det(m), -1.0, abs_tol=1e-12)
    assert swaps_handedness(m)
    assert_close(m @ m, np.eye(4), tol=1e-11)


def test_swaps_handedness_cases():
    assert swaps_handedness(scale(-1, 1, 1))
    assert not swaps_handedness(scale(-1, -1, 1))
    assert not swaps_handedness(translate(1, 2, 3))
    # a right-handed view space maps to left-handed NDC under a perspective matrix
    perspective = glm_matrix(glm.perspectiveRH_NO(1.0, 1.5, 0.1, 100.0))
    assert swaps_handedness(perspective)


@given(m=affine_matrices())
def test_invert_affine_round_trip(m):
    assert_close(invert(m) @ m, np.eye(4), tol=1e-9)
    assert_close(m @ invert(m), np.eye(4), tol=1e-9)


@given(axis=axes(), angle=angles, offset=vectors())
def test_invert_rigid_is_exactly_the_transpose(axis, angle, offset):
    m = compose(rotate(axis, angle), translate(*offset))
    inverse = invert(m)
    np.testing.assert_array_equal(inverse[:3, :3], m[:3, :3].T)
    assert_close(inverse @ m, np.eye(4), tol=1e-12)


@given(m=projective_matrices())
def test_invert_projective_round_trip(m):
    assert_close(invert(m) @ m, np.eye(4), tol=1e-8)


@given(m=projective_matrices(), points=point_arrays())
def test_apply_equals_row_vector_product_after_divide(m, points):
    # points at the eye plane would have w = 0; keep the random points off it.
    w = homogeneous(points) @ m[3]
    if np.abs(w).min() < 1e-3:
        return
    row = homogeneous(points) @ to_row_major(m)
    assert_close(apply(m, points), row[:, :3] / row[:, 3:], tol=1e-9)
    assert_close(apply_homogeneous(m, points), row, tol=1e-12)


@given(m=projective_matrices(), points=point_arrays())
def test_apply_homogeneous_accepts_homogeneous_points(m, points):
    h = homogeneous(points) * 2.0  # the same points with w = 2
    assert_close(apply_homogeneous(m, h), 2.0 * apply_homogeneous(m, points))


@given(m=affine_matrices(), points=point_arrays(), vector=vectors())
def test_directions_ignore_translation(m, points, vector):
    # a direction is a difference of points: M·(p + d) − M·p = A·d
    moved = apply(m, points + vector) - apply(m, points)
    assert_close(moved, np.broadcast_to(apply_to_directions(m, vector), moved.shape), tol=1e-9)


@given(m=affine_matrices(), t1=vectors(), t2=vectors())
def test_normals_stay_perpendicular_under_nonuniform_scale_and_shear(m, t1, t2):
    normal = np.cross(t1, t2)
    if np.linalg.norm(normal) < 1e-3:
        return
    n = apply_to_normals(m, normal)
    assert math.isclose(np.linalg.norm(n), 1.0, abs_tol=1e-12)
    for tangent in (t1, t2):
        moved = apply_to_directions(m, tangent)
        # relative to the tangent's length: the dot product of a unit normal with a long vector
        assert abs(n @ moved) <= 1e-9 * max(1.0, np.linalg.norm(moved))


def test_naive_normal_transform_is_wrong_and_inverse_transpose_is_right():
    # The reason apply_to_normals exists: A·n is not perpendicular after a non-uniform scale.
    m = scale(4, 1, 1)
    tangent, normal = np.array([1.0, 1.0, 0.0]), np.array([1.0, -1.0, 0.0])
    assert abs(apply_to_directions(m, normal) @ apply_to_directions(m, tangent)) > 1
    assert abs(apply_to_normals(m, normal) @ apply_to_directions(m, tangent)) < 1e-12


def test_single_points_and_empty_arrays():
    assert apply(translate(1, 2, 3), (0, 0, 0)).shape == (3,)
    assert apply(translate(1, 2, 3), np.empty((0, 3))).shape == (0, 3)
    assert apply_homogeneous(translate(1, 2, 3), np.empty((0, 3))).shape == (0, 4)
    assert apply_to_normals(scale(2, 1, 1), np.empty((0, 3))).shape == (0, 3)


def test_public_api_is_reexported():
    for name in ("translate", "rotate", "rotate_steps", "compose", "apply", "invert", "Quaternion", "slerp"):
        assert hasattr(frustum, name)
    assert issubclass(frustum.TransformError, frustum.FrustumError)
    assert issubclass(frustum.FrustumError, ValueError)


# --- bad input --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("call", "error", "pattern"),
    [
        (lambda: rotate((0, 0, 0), 1.0), TransformError, r"rotate: axis = \(0\.0, 0\.0, 0\.0\) has zero length"),
        (lambda: rotate_steps((0, 0, 0), 1.0), TransformError, r"axis .* zero length"),
        (lambda: rotate((1, 0, 0), float("nan")), TransformError, r"rotate: angle = nan is not finite"),
        (lambda: rotate_x(float("inf")), TransformError, r"angle = inf is not finite"),
        (lambda: rotate((1, 0), 1.0), TransformError, r"axis = .* has shape \(2,\); expected three numbers"),
        (lambda: translate(1, float("nan"), 0), TransformError, r"translate: ty = nan is not finite"),
        (lambda: translate("a", 0, 0), TransformError, r"translate: tx = 'a' is not a number"),
        (lambda: scale(1, 1, 1, fixed=(0, np.inf, 0)), TransformError, r"scale: fixed = .*inf.* is not finite"),
        (lambda: reflect((0, 0, 0)), TransformError, r"reflect: normal = .* has zero length"),
        (lambda: reflect("xw"), TransformError, r"reflect: normal = 'xw' names no coordinate plane"),
        (lambda: shear("w", 1, 1), TransformError, r"shear: axis = 'w' is not a coordinate axis"),
        (lambda: compose(np.eye(3)), TransformError, r"compose: matrices\[0\] has shape \(3, 3\)"),
        (lambda: compose(np.full((4, 4), np.nan)), TransformError, r"matrices\[0\]\[0, 0\] = nan is not finite"),
        (lambda: invert(scale(0, 1, 1)), TransformError, r"invert: .* is singular .*scale factor of 0"),
        (lambda: invert(np.zeros((4, 4))), TransformError, r"invert: matrix is singular"),
        (lambda: swaps_handedness(scale(1, 0, 1)), TransformError, r"swaps_handedness: .* singular"),
        (lambda: apply(np.eye(4), [[1, 2]]), GeometryError, r"apply: points has shape \(1, 2\); expected \(N, 3\)"),
        (lambda: apply(np.eye(4), [[1, 2, np.nan]]), GeometryError, r"apply: points\[0\] = .*nan.* is not finite"),
        (lambda: apply(np.eye(4), [[1, 2], [3]]), GeometryError, r"apply: points .* not numeric"),
        (lambda: apply(np.diag([1, 1, 1, 0.0]), [[1, 2, 3]]), TransformError, r"points\[0\] .* maps to w = 0"),
        (lambda: apply_to_normals(np.eye(4), [[0, 0, 0]]), GeometryError, r"normals\[0\] .* has zero length"),
        (lambda: apply_to_normals(scale(0, 1, 1), [[1, 0, 0]]), TransformError, r"singular"),
        (
            lambda: apply_to_normals(glm_matrix(glm.perspectiveRH_NO(1.0, 1.0, 0.1, 10.0)), [[1, 0, 0]]),
            TransformError,
            r"projective",
        ),
        (lambda: apply_homogeneous(np.eye(4), [[1, 2, 3, np.inf]]), GeometryError, r"points\[0\] .* not finite"),
    ],
)
def test_bad_input_raises_named_error(call, error, pattern):
    with pytest.raises(error, match=pattern):
        call()
