"""Quaternions $q = w + x·i + y·j + z·k$ for rotations about arbitrary axes, and slerp between them.

Component order is (w, x, y, z), scalar first, as in glm and pytransform3d (SciPy's default is scalar last:
``docs/conventions.md`` has the table). A unit quaternion $q = (cos θ/2, sin θ/2 · k)$ rotates a point p by
$p' = q·p·q⁻¹$ (p as the pure quaternion (0, p)): θ radians about the unit axis k, right-hand rule.
``q`` and $−q$ are the same rotation. Products apply the right-hand factor first, like matrices:
``(q1 * q2).rotate(p) == q1.rotate(q2.rotate(p))``.

References
----------
[HB 9] "Quaternion Methods for Three-Dimensional Rotations"; [seed] "Quaternion Methods for 3-D Rotations".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import (
    Matrix4,
    Points,
    Vector3,
    as_direction,
    as_points,
    as_scalar,
    as_vector3,
    describe,
    is_numeric,
)
from frustum.errors import GeometryError, TransformError

__all__ = ["Quaternion", "slerp"]

# A matrix whose columns are this close to orthonormal (det +1) is accepted as a rotation by from_matrix;
# float32 round trips land near 1e-7, anything further off is a scale, shear or reflection.
_ROTATION_TOLERANCE = 1e-6


@dataclass(frozen=True)
class Quaternion:
    """A quaternion $w + x·i + y·j + z·k$; the unit ones are rotations (see the module docstring)."""

    w: float
    x: float
    y: float
    z: float

    def __post_init__(self) -> None:
        for name in ("w", "x", "y", "z"):
            object.__setattr__(self, name, as_scalar(getattr(self, name), name, where="Quaternion"))

    # --- constructors -------------------------------------------------------------------------------------

    @classmethod
    def identity(cls) -> Quaternion:
        """The rotation by 0: ``(1, 0, 0, 0)``."""
        return cls(1.0, 0.0, 0.0, 0.0)

    @classmethod
    def from_axis_angle(cls, axis: ArrayLike, angle: float) -> Quaternion:
        """Unit quaternion of the rotation by `angle` radians about `axis`: $(cos θ/2, sin θ/2 · k)$.

        Raises
        ------
        TransformError
            If `axis` has zero length or a value is not finite.
        """
        k = as_direction(axis, "axis", where="Quaternion.from_axis_angle")
        half = 0.5 * as_scalar(angle, "angle", where="Quaternion.from_axis_angle")
        s = np.sin(half)
        return cls(np.cos(half), *(s * k))

    @classmethod
    def from_array(cls, wxyz: ArrayLike) -> Quaternion:
        """Quaternion from a length-4 sequence in (w, x, y, z) order."""
        values = np.asarray(wxyz, dtype=np.float64) if is_numeric(wxyz) else None
        if values is None or values.shape != (4,):
            raise TransformError(
                f"Quaternion.from_array: wxyz = {describe(wxyz)} is not four numbers; expected (w, x, y, z)"
            )
        return cls(*values)

    @classmethod
    def from_matrix(cls, matrix: ArrayLike) -> Quaternion:
        """Unit quaternion (with w >= 0) of a rotation matrix, (3, 3) or (4, 4) without translation.

        Shepperd's method: take the largest of $4w², 4x², 4y², 4z²$ (from the trace and the diagonal) for
        the square root, and the others from the off-diagonal sums and differences, e.g. for w:
        $w = √(1 + R00 + R11 + R22)/2, x = (R21 − R12)/(4w)$.

        Raises
        ------
        TransformError
            If the matrix is not a rotation (orthonormal with det +1, to 1e-6), or a 4x4 one translates
            or projects.
        """
        where = "Quaternion.from_matrix"
        try:
            m = np.asarray(matrix, dtype=np.float64)
        except (TypeError, ValueError):
            raise TransformError(f"{where}: matrix = {describe(matrix)} is not numeric") from None
        if m.shape == (4, 4):
            if np.abs(m[3] - (0.0, 0.0, 0.0, 1.0)).max() > _ROTATION_TOLERANCE or np.abs(m[:3, 3]).max() > 0:
                raise TransformError(
                    f"{where}: matrix has last column {describe(m[:, 3])} and bottom row {describe(m[3])}; a "
                    "rotation has last column and bottom row (0, 0, 0, 1): pass the rotation part m[:3, :3]"
                )
            m = m[:3, :3]
        if m.shape != (3, 3):
            raise TransformError(f"{where}: matrix has shape {m.shape}; expected (3, 3) or (4, 4)")
        if not np.isfinite(m).all():
            raise TransformError(f"{where}: matrix has non-finite entries; entries must be finite numbers")
        error = float(np.abs(m.T @ m - np.eye(3)).max())
        if error > _ROTATION_TOLERANCE or np.linalg.det(m) < 0:
            raise TransformError(
                f"{where}: matrix is not a rotation (|RᵀR − I| = {error:.2g}, det = {np.linalg.det(m):.6g}); "
                "expected an orthonormal matrix with det +1 (no scale, shear or reflection)"
            )
        return cls(*_shepperd(m))

    # --- algebra ------------------------------------------------------------------------------------------

    def as_array(self) -> NDArray[np.float64]:
        """The components as a (4,) float64 array in (w, x, y, z) order."""
        return np.array([self.w, self.x, self.y, self.z])

    @property
    def vector(self) -> Vector3:
        """The vector part (x, y, z) as a (3,) float64 array."""
        return np.array([self.x, self.y, self.z])

    def __mul__(self, other: Quaternion | float) -> Quaternion:
        """Hamilton product $(w1·w2 − v1·v2, w1·v2 + w2·v1 + v1 × v2)$, or scaling by a real number."""
        if isinstance(other, Quaternion):
            v1, v2 = self.vector, other.vector
            return Quaternion(self.w * other.w - v1 @ v2, *(self.w * v2 + other.w * v1 + np.cross(v1, v2)))
        if isinstance(other, int | float | np.integer | np.floating) and not isinstance(other, bool):
            return Quaternion(*(float(other) * self.as_array()))
        return NotImplemented

    def __rmul__(self, other: float) -> Quaternion:
        if isinstance(other, int | float | np.integer | np.floating) and not isinstance(other, bool):
            return self * other
        return NotImplemented

    def __add__(self, other: Quaternion) -> Quaternion:
        if not isinstance(other, Quaternion):
            return NotImplemented
        return Quaternion(*(self.as_array() + other.as_array()))

    def __sub__(self, other: Quaternion) -> Quaternion:
        if not isinstance(other, Quaternion):
            return NotImplemented
        return Quaternion(*(self.as_array() - other.as_array()))

    def __neg__(self) -> Quaternion:
        return Quaternion(-self.w, -self.x, -self.y, -self.z)

    def dot(self, other: Quaternion) -> float:
        """Four-dimensional dot product $w1·w2 + x1·x2 + y1·y2 + z1·z2$ (cos of half the angle between)."""
        return float(self.as_array() @ other.as_array())

    def conjugate(self) -> Quaternion:
        """$q* = (w, −x, −y, −z)$; for a unit quaternion, the inverse rotation."""
        return Quaternion(self.w, -self.x, -self.y, -self.z)

    def norm(self) -> float:
        """$|q| = √(w² + x² + y² + z²)$."""
        return float(np.linalg.norm(self.as_array()))

    def normalized(self) -> Quaternion:
        """``q / |q|``, the unit quaternion of the same rotation."""
        return Quaternion(*(self.as_array() / self._nonzero_norm("normalized")))

    def inverse(self) -> Quaternion:
        """$q⁻¹ = q* / |q|²$, so that ``q * q.inverse()`` is the identity."""
        return Quaternion(*(self.conjugate().as_array() / self._nonzero_norm("inverse") ** 2))

    # --- as a rotation ------------------------------------------------------------------------------------

    def to_matrix(self) -> Matrix4:
        """The (4, 4) rotation matrix of ``q/|q|``, column-vector convention.

        With q unit: $[[1 − 2(y² + z²), 2(xy − wz), 2(xz + wy)], [2(xy + wz), 1 − 2(x² + z²), 2(yz − wx)],
        [2(xz − wy), 2(yz + wx), 1 − 2(x² + y²)]]$ in the upper-left block.
        """
        w, x, y, z = self.as_array() / self._nonzero_norm("to_matrix")
        # fmt: off
        return np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),     0.0],
            [2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),     0.0],
            [2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y), 0.0],
            [0.0,                     0.0,                     0.0,                     1.0],
        ])
        # fmt: on

    def rotate(self, points: ArrayLike) -> Points:
        """$p' = q·p·q⁻¹$ for every row of `points` ((N, 3) or a single (3,) point), vectorized."""
        rotation = self.to_matrix()[:3, :3]
        try:
            single = np.shape(points) == (3,)
        except ValueError:
            single = False
        if single:
            return as_vector3(points, "points", where="Quaternion.rotate", error=GeometryError) @ rotation.T
        return as_points(points, where="Quaternion.rotate") @ rotation.T

    def to_axis_angle(self) -> tuple[Vector3, float]:
        """$(k, θ)$ with θ in [0, π] and k a unit axis: $θ = 2·atan2(|v|, w)$ after choosing w >= 0.

        The identity rotation has no axis; it returns ``((1, 0, 0), 0.0)``.
        """
        q = self.as_array() / self._nonzero_norm("to_axis_angle")
        if q[0] < 0:
            q = -q
        length = float(np.linalg.norm(q[1:]))
        if length == 0.0:
            return np.array([1.0, 0.0, 0.0]), 0.0
        return q[1:] / length, float(2.0 * np.arctan2(length, q[0]))

    def _nonzero_norm(self, operation: str) -> float:
        norm = self.norm()
        if norm == 0.0:
            raise TransformError(
                f"Quaternion.{operation}: q = {describe(self.as_array())} has zero norm; "
                "it is no rotation and has no inverse: give a nonzero quaternion"
            )
        return norm


def slerp(q0: Quaternion, q1: Quaternion, t: float | ArrayLike) -> Quaternion | tuple[Quaternion, ...]:
    """Spherical linear interpolation from `q0` (t = 0) to `q1` (t = 1) along the shorter arc.

    $slerp = (sin((1 − t)·Ω)·q0 + sin(t·Ω)·q1) / sin Ω$ with $cos Ω = q0·q1$ after normalizing both and
    negating q1 when $q0·q1 < 0$ (q and −q are one rotation; the negation picks the short path). Ω is
    computed as $2·atan2(|q0 − q1|, |q0 + q1|)$, accurate for any angle; below 1e-9 rad the result is the
    normalized linear blend. `t` outside [0, 1] extrapolates along the same great circle.

    Returns
    -------
    Quaternion for a scalar `t`; a tuple of Quaternions, one per entry, for a 1-D array `t`.
    """
    for name, q in (("q0", q0), ("q1", q1)):
        if not isinstance(q, Quaternion):
            raise TransformError(f"slerp: {name} = {describe(q)} is not a Quaternion; expected Quaternion(w, x, y, z)")
    a = q0.normalized().as_array()
    b = q1.normalized().as_array()
    if a @ b < 0:
        b = -b
    try:
        ts = np.asarray(t, dtype=np.float64)
    except (TypeError, ValueError):
        raise TransformError(f"slerp: t = {describe(t)} is not numeric; expected a number or 1-D array") from None
    if ts.ndim > 1 or not np.isfinite(ts).all():
        raise TransformError(f"slerp: t = {describe(t)} must be a finite number or a 1-D array of them")
    omega = 2.0 * np.arctan2(np.linalg.norm(a - b), np.linalg.norm(a + b))
    tt = np.atleast_1d(ts)[:, None]
    if omega < 1e-9:
        blend = (1.0 - tt) * a + tt * b
        blend /= np.linalg.norm(blend, axis=1)[:, None]
    else:
        blend = (np.sin((1.0 - tt) * omega) * a + np.sin(tt * omega) * b) / np.sin(omega)
    results = tuple(Quaternion(*row) for row in blend)
    return results[0] if ts.ndim == 0 else results


def _shepperd(m: NDArray[np.float64]) -> NDArray[np.float64]:
    """(w, x, y, z) of a rotation matrix, w >= 0, by Shepperd's largest-pivot rule."""
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    pivots = (trace, m[0, 0], m[1, 1], m[2, 2])
    k = int(np.argmax(pivots))
    if k == 0:
        s = 2.0 * np.sqrt(1.0 + trace)
        q = np.array([s / 4, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s])
    elif k == 1:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = np.array([(m[2, 1] - m[1, 2]) / s, s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s])
    elif k == 2:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = np.array([(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s])
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = np.array([(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4])
    if q[0] < 0:
        q = -q
    return q / np.linalg.norm(q)
