"""quaternion.py against PyGLM and SciPy (scalar-first order passed explicitly), and its algebraic properties."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from pyglm import glm
from scipy.spatial.transform import Rotation, Slerp

from frustum import GeometryError, Quaternion, TransformError, rotate, slerp
from oracles import assert_close, assert_same_rotation, glm_matrix, glm_vec, glm_wxyz
from strategies import angles, axes, point_arrays

components = st.floats(min_value=-10, max_value=10, allow_nan=False, allow_infinity=False)


@st.composite
def quaternions(draw: st.DrawFn) -> Quaternion:
    """A quaternion of norm at least 1e-2 (any norm: rotations use q/|q|)."""
    q = Quaternion(*(draw(components) for _ in range(4)))
    return q if q.norm() >= 1e-2 else Quaternion(1.0, 0.0, 0.0, 0.0)


@st.composite
def unit_quaternions(draw: st.DrawFn) -> Quaternion:
    return Quaternion.from_axis_angle(draw(axes()), draw(angles))


def glm_quat(q: Quaternion) -> glm.dquat:
    return glm.dquat(q.w, q.x, q.y, q.z)  # PyGLM's constructor is (w, x, y, z) (ORACLES trap 4)


def scipy_rotation(q: Quaternion) -> Rotation:
    return Rotation.from_quat(q.as_array(), scalar_first=True)  # SciPy defaults to (x, y, z, w)


# --- oracles ----------------------------------------------------------------------------------------------


@given(axis=axes(), angle=angles)
def test_from_axis_angle_matches_glm_and_scipy(axis, angle):
    q = Quaternion.from_axis_angle(axis, angle)
    assert_close(q.as_array(), glm_wxyz(glm.angleAxis(angle, glm.normalize(glm_vec(axis)))))
    rotvec = angle * axis / np.linalg.norm(axis)
    assert_same_rotation(q.as_array(), Rotation.from_rotvec(rotvec).as_quat(scalar_first=True))


@given(quaternions())
def test_to_matrix_matches_glm_and_scipy(q):
    unit = q.normalized()
    assert_close(q.to_matrix(), glm_matrix(glm.mat4_cast(glm_quat(unit))))
    assert_close(q.to_matrix()[:3, :3], scipy_rotation(q).as_matrix())


@given(unit_quaternions())
def test_from_matrix_matches_scipy_up_to_sign_and_round_trips(q):
    matrix = q.to_matrix()
    r = Quaternion.from_matrix(matrix)
    assert_same_rotation(r.as_array(), Rotation.from_matrix(matrix[:3, :3]).as_quat(scalar_first=True))
    assert_same_rotation(r.as_array(), q.as_array())
    assert r.w >= 0
    assert_close(Quaternion.from_matrix(matrix[:3, :3]).to_matrix(), matrix)


@pytest.mark.parametrize("axis", [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (1, -1, 1)])
def test_from_matrix_handles_half_turns(axis):
    # trace = -1: w = 0, the pivot must come from the diagonal (Shepperd's rule)
    q = Quaternion.from_matrix(rotate(axis, np.pi))
    assert_close(q.to_matrix(), rotate(axis, np.pi))


@given(quaternions(), quaternions())
def test_product_matches_glm_and_scipy_composition(q1, q2):
    assert_close((q1 * q2).as_array(), glm_wxyz(glm_quat(q1) * glm_quat(q2)), tol=1e-12 * 100)
    composed = scipy_rotation(q1) * scipy_rotation(q2)  # applies q2 first, like q1 * q2
    assert_close((q1 * q2).to_matrix()[:3, :3], composed.as_matrix())


@given(quaternions())
def test_conjugate_and_inverse_match_glm(q):
    assert_close(q.conjugate().as_array(), glm_wxyz(glm.conjugate(glm_quat(q))))
    assert_close(q.inverse().as_array(), glm_wxyz(glm.inverse(glm_quat(q))))


@given(unit_quaternions(), point_arrays())
def test_rotate_matches_scipy_and_the_sandwich_product(q, points):
    assert_close(q.rotate(points), scipy_rotation(q).apply(points), tol=1e-12)
    p = points[0]
    sandwich = q * Quaternion(0.0, *p) * q.inverse()  # p' = q·p·q⁻¹
    assert_close(q.rotate(p), sandwich.vector)
    assert abs(sandwich.w) < 1e-10


@given(unit_quaternions(), unit_quaternions(), st.floats(0.0, 1.0))
def test_slerp_matches_glm_and_scipy(q0, q1, t):
    result = slerp(q0, q1, t)
    assert_same_rotation(result.as_array(), glm_wxyz(glm.slerp(glm_quat(q0), glm_quat(q1), t)), tol=1e-9)
    key_rotations = Rotation.from_quat(np.array([q0.as_array(), q1.as_array()]), scalar_first=True)
    expected = Slerp([0.0, 1.0], key_rotations)(t)
    assert_close(result.to_matrix()[:3, :3], expected.as_matrix(), tol=1e-9)


# glm and scipy compute the angle with acos, which loses about half the digits near cos Ω = 1; frustum uses
# 2·atan2(|q0 − q1|, |q0 + q1|). 1e-9 covers the oracles' error on random pairs, not frustum's.


def test_slerp_takes_the_short_path_and_accepts_arrays():
    q0 = Quaternion.identity()
    q1 = -Quaternion.from_axis_angle((0, 0, 1), 0.5)  # same rotation, opposite hemisphere
    halfway = slerp(q0, q1, 0.5)
    assert_close(halfway.to_matrix(), rotate((0, 0, 1), 0.25))
    frames = slerp(q0, q1, np.linspace(0, 1, 5))
    assert isinstance(frames, tuple) and len(frames) == 5
    for t, frame in zip(np.linspace(0, 1, 5), frames, strict=True):
        assert_close(frame.to_matrix(), rotate((0, 0, 1), 0.5 * t))


def test_slerp_of_equal_rotations_is_constant():
    q = Quaternion.from_axis_angle((1, 2, 3), 0.7)
    for t in (0.0, 0.3, 1.0):
        assert_same_rotation(slerp(q, q, t).as_array(), q.as_array())


# --- properties -------------------------------------------------------------------------------------------


@given(quaternions())
def test_inverse_is_a_two_sided_inverse(q):
    assert_close((q * q.inverse()).as_array(), [1, 0, 0, 0])
    assert_close((q.inverse() * q).as_array(), [1, 0, 0, 0])


@given(quaternions(), quaternions(), quaternions())
def test_product_is_associative(a, b, c):
    # entries up to 1e3 (three factors of size 10); relative 1e-12 scales to ~1e-9 absolute
    assert_close(((a * b) * c).as_array(), (a * (b * c)).as_array(), tol=1e-11)


@given(quaternions(), quaternions())
def test_norm_is_multiplicative(a, b):
    assert math.isclose((a * b).norm(), a.norm() * b.norm(), rel_tol=1e-12)


@given(unit_quaternions(), unit_quaternions(), point_arrays())
def test_product_rotates_right_factor_first(q1, q2, points):
    assert_close((q1 * q2).rotate(points), q1.rotate(q2.rotate(points)), tol=1e-11)


@given(axes(), st.floats(0.0, np.pi))
def test_to_axis_angle_round_trips(axis, angle):
    unit_axis, recovered = Quaternion.from_axis_angle(axis, angle).to_axis_angle()
    assert math.isclose(recovered, angle, abs_tol=1e-12)
    if angle > 1e-6:
        assert_close(unit_axis, axis / np.linalg.norm(axis), tol=1e-9)


def test_identity_and_scalar_algebra():
    q = Quaternion(1.0, 2.0, 3.0, 4.0)
    assert Quaternion.identity() * q == q
    assert (2 * q).as_array().tolist() == [2.0, 4.0, 6.0, 8.0]
    assert (q + q) - q == q
    assert (-q).as_array().tolist() == [-1.0, -2.0, -3.0, -4.0]
    assert math.isclose(q.norm(), math.sqrt(30))
    assert Quaternion.identity().to_axis_angle()[1] == 0.0
    assert Quaternion.from_array([1, 0, 0, 0]) == Quaternion.identity()
    assert q.rotate(np.empty((0, 3))).shape == (0, 3)
    assert math.isclose(q.normalized().norm(), 1.0)


# --- bad input --------------------------------------------------------------------------------------------


ZERO = Quaternion(0.0, 0.0, 0.0, 0.0)


@pytest.mark.parametrize(
    ("call", "error", "pattern"),
    [
        (ZERO.inverse, TransformError, r"Quaternion.inverse: q = \(0\.0, 0\.0, 0\.0, 0\.0\) has zero norm"),
        (ZERO.normalized, TransformError, r"normalized: .* zero norm"),
        (ZERO.to_matrix, TransformError, r"to_matrix: .* zero norm"),
        (ZERO.to_axis_angle, TransformError, r"to_axis_angle: .* zero norm"),
        (lambda: ZERO.rotate([[1, 0, 0]]), TransformError, r"zero norm"),
        (lambda: slerp(ZERO, Quaternion.identity(), 0.5), TransformError, r"zero norm"),
        (lambda: slerp(Quaternion.identity(), (1, 0, 0, 0), 0.5), TransformError, r"slerp: q1 = .* not a Quaternion"),
        (lambda: slerp(Quaternion.identity(), Quaternion.identity(), np.nan), TransformError, r"slerp: t = .*finite"),
        (lambda: Quaternion(float("nan"), 0, 0, 0), TransformError, r"Quaternion: w = nan is not finite"),
        (lambda: Quaternion.from_axis_angle((0, 0, 0), 1.0), TransformError, r"axis = .* has zero length"),
        (lambda: Quaternion.from_matrix(np.diag([2.0, 1, 1])), TransformError, r"from_matrix: matrix is not a rot"),
        (lambda: Quaternion.from_matrix(np.diag([-1.0, 1, 1])), TransformError, r"not a rotation .*det = -1"),
        (lambda: Quaternion.from_matrix(rotate((0, 0, 1), 1.0, (1, 0, 0))), TransformError, r"last column"),
        (lambda: Quaternion.from_matrix(np.eye(2)), TransformError, r"shape \(2, 2\)"),
        (lambda: Quaternion.from_array([1, 2, 3]), TransformError, r"from_array: wxyz = .* not four numbers"),
        (lambda: Quaternion.identity().rotate([[1, 2]]), GeometryError, r"Quaternion.rotate: points has shape"),
    ],
)
def test_bad_input_raises_named_error(call, error, pattern):
    with pytest.raises(error, match=pattern):
        call()
