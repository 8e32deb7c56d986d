"""4x4 homogeneous transformations: builders, composition, and applying them to points, directions, normals.

Column-vector convention throughout: a point is $P = [x, y, z, 1]ᵀ$ and $P' = M · P$. A composite that
applies ``A``, then ``B``, then ``C`` is ``C @ B @ A``; ``compose(A, B, C)`` returns exactly that. Row-vector
readers (the seed's "row major" tables, $P' = P · R$) use ``to_row_major(M)``, which is ``M.T``.
Angles are radians. Every builder returns a fresh, writable ``(4, 4) float64`` array.

References are resolved in ``docs/references.md``: [HB 9] is Hearn & Baker, *Computer Graphics with OpenGL*,
chapter 9, "Three-Dimensional Geometric Transformations"; [seed] is the lecture notes.
"""

from __future__ import annotations

from functools import reduce
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from frustum._arrays import (
    Matrix4,
    Points,
    as_direction,
    as_homogeneous_points,
    as_matrix,
    as_points,
    as_scalar,
    as_vector3,
    describe,
)
from frustum.errors import GeometryError, TransformError

__all__ = [
    "Step",
    "apply",
    "apply_homogeneous",
    "apply_to_directions",
    "apply_to_normals",
    "compose",
    "invert",
    "reflect",
    "rotate",
    "rotate_steps",
    "rotate_x",
    "rotate_y",
    "rotate_z",
    "scale",
    "shear",
    "swaps_handedness",
    "to_row_major",
    "translate",
]

# Entries this close to the exact values still count as "affine" or "orthonormal": builders produce exact
# zeros and ones in the bottom row, composites of rotations drift by a few ulps per product.
_EXACT_TOLERANCE = 1e-12
# Beyond this condition number a 3x3 or 4x4 block is singular to double precision.
_SINGULAR_CONDITION = 1e15


class Step(NamedTuple):
    """One named matrix of a composite transformation, for inspection (``trace``, teaching)."""

    name: str
    matrix: Matrix4


# --- builders ---------------------------------------------------------------------------------------------


def translate(tx: float, ty: float, tz: float) -> Matrix4:
    """Matrix moving every point by (tx, ty, tz).

    $x' = x + tx, y' = y + ty, z' = z + tz$, i.e. $P' = T · P$ with the offsets in the last column.

    References
    ----------
    [HB 9] "Three-Dimensional Translation"; [seed] "Three-dimensional translation".
    """
    offsets = [as_scalar(v, name, where="translate") for v, name in ((tx, "tx"), (ty, "ty"), (tz, "tz"))]
    matrix = np.eye(4)
    matrix[:3, 3] = offsets
    return matrix


def rotate_z(angle: float) -> Matrix4:
    """Counter-clockwise rotation by `angle` radians about the z axis (right-handed, looking down -z).

    $x' = x·cosθ − y·sinθ, y' = x·sinθ + y·cosθ, z' = z$. ``rotate_x`` and ``rotate_y`` are this formula
    under the cyclic permutation x → y → z → x of the seed.

    References
    ----------
    [HB 9] "Three-Dimensional Coordinate-Axis Rotations", eq. for z-axis rotation; [seed] "3-D Rotation".
    """
    c, s = _cos_sin(angle, "rotate_z")
    # fmt: off
    return np.array([
        [c,  -s,  0.0, 0.0],
        [s,   c,  0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ])
    # fmt: on


def rotate_x(angle: float) -> Matrix4:
    """Counter-clockwise rotation by `angle` radians about the x axis.

    $y' = y·cosθ − z·sinθ, z' = y·sinθ + z·cosθ, x' = x$ (``rotate_z`` with x → y → z → x).

    References
    ----------
    [HB 9] "Three-Dimensional Coordinate-Axis Rotations"; [seed] "x axis rotation", column-major form.
    """
    c, s = _cos_sin(angle, "rotate_x")
    # fmt: off
    return np.array([
        [1.0, 0.0, 0.0, 0.0],
        [0.0,  c,  -s,  0.0],
        [0.0,  s,   c,  0.0],
        [0.0, 0.0, 0.0, 1.0],
    ])
    # fmt: on


def rotate_y(angle: float) -> Matrix4:
    """Counter-clockwise rotation by `angle` radians about the y axis.

    $z' = z·cosθ − x·sinθ, x' = z·sinθ + x·cosθ, y' = y$ (``rotate_x`` with x → y → z → x). The seed's
    column-major R_y shows $+sinθ$ in both off-diagonal places; that is a transcription slip: its own
    equations, and Hearn & Baker, give $−sinθ$ in row z', column x, as here.

    References
    ----------
    [HB 9] "Three-Dimensional Coordinate-Axis Rotations"; [seed] "y axis rotation".
    """
    c, s = _cos_sin(angle, "rotate_y")
    # fmt: off
    return np.array([
        [ c,  0.0,  s,  0.0],
        [0.0, 1.0, 0.0, 0.0],
        [-s,  0.0,  c,  0.0],
        [0.0, 0.0, 0.0, 1.0],
    ])
    # fmt: on


def rotate(axis: ArrayLike, angle: float, point: ArrayLike = (0.0, 0.0, 0.0)) -> Matrix4:
    """Rotation by `angle` radians about the line through `point` along `axis` (right-hand rule).

    $M = T(p) · R(k, θ) · T(−p)$ with Rodrigues' rotation
    $R = cosθ·I + sinθ·[k]ₓ + (1 − cosθ)·k·kᵀ$ for the unit axis ``k``. It equals the quaternion route,
    ``T(p) · Quaternion.from_axis_angle(k, θ).to_matrix() · T(−p)``, and the seed's translate–rotate–translate
    sequence for an axis parallel to a coordinate axis; ``rotate_steps`` lists the textbook's seven steps.

    Parameters
    ----------
    axis : (3,) array_like
        Direction of the rotation axis; any nonzero length.
    angle : float
        Radians, counter-clockwise when the axis points toward the viewer.
    point : (3,) array_like
        Any point on the axis.

    Raises
    ------
    TransformError
        If `axis` has zero length or any argument is not finite.

    References
    ----------
    [HB 9] "General Three-Dimensional Rotations", "Quaternion Methods for Three-Dimensional Rotations".
    """
    k = as_direction(axis, "axis", where="rotate")
    p = as_vector3(point, "point", where="rotate")
    c, s = _cos_sin(angle, "rotate")
    # fmt: off
    cross = np.array([
        [0.0,  -k[2],  k[1]],
        [k[2],  0.0,  -k[0]],
        [-k[1], k[0],  0.0],
    ])
    # fmt: on
    rotation = c * np.eye(3) + s * cross + (1.0 - c) * np.outer(k, k)
    matrix = np.eye(4)
    matrix[:3, :3] = rotation
    matrix[:3, 3] = p - rotation @ p
    return matrix


def rotate_steps(axis: ArrayLike, angle: float, point: ArrayLike = (0.0, 0.0, 0.0)) -> tuple[Step, ...]:
    """The textbook's seven matrices for a rotation about an arbitrary axis, first-applied first.

    $R(θ) = T⁻¹ · Rx⁻¹(α) · Ry⁻¹(β) · Rz(θ) · Ry(β) · Rx(α) · T$: translate the axis through the origin,
    rotate about x into the xz plane ($cos α = c/d, sin α = b/d$ with $d = √(b² + c²)$), rotate about y
    onto the z axis ($cos β = d, sin β = −a$), rotate by θ about z, then undo the alignment. ``compose(*m for
    _, m in rotate_steps(...))`` equals ``rotate(axis, angle, point)``. When the axis is the x axis, $d = 0$
    and the x rotation is the identity.

    References
    ----------
    [HB 9] "General Three-Dimensional Rotations" (the seven-step sequence).
    """
    a, b, c = as_direction(axis, "axis", where="rotate_steps")
    p = as_vector3(point, "point", where="rotate_steps")
    theta = as_scalar(angle, "angle", where="rotate_steps")
    d = float(np.hypot(b, c))
    align_x = np.eye(4)
    if d > 0.0:
        align_x[1:3, 1:3] = [[c / d, -b / d], [b / d, c / d]]
    align_y = np.eye(4)
    align_y[0, 0], align_y[0, 2], align_y[2, 0], align_y[2, 2] = d, -a, a, d
    return (
        Step("translate the axis point to the origin", translate(*-p)),
        Step("rotate about x into the xz plane", align_x),
        Step("rotate about y onto the z axis", align_y),
        Step("rotate by the angle about z", rotate_z(theta)),
        Step("undo the y alignment", align_y.T.copy()),
        Step("undo the x alignment", align_x.T.copy()),
        Step("translate back", translate(*p)),
    )


def scale(sx: float, sy: float, sz: float, fixed: ArrayLike = (0.0, 0.0, 0.0)) -> Matrix4:
    """Scaling by (sx, sy, sz) about the fixed point `fixed`, which does not move.

    $x' = x·sx + (1 − sx)·xf$ (and alike for y, z), i.e. $T(f) · S(sx, sy, sz) · T(−f)$. Factors may be
    negative (a reflection) or zero (a flattening, which ``invert`` then refuses).

    References
    ----------
    [HB 9] "Three-Dimensional Scaling" (scaling relative to a fixed point); [seed] "Three-dimensional scaling".
    """
    factors = np.array([as_scalar(v, n, where="scale") for v, n in ((sx, "sx"), (sy, "sy"), (sz, "sz"))])
    f = as_vector3(fixed, "fixed", where="scale")
    matrix = np.diag([*factors, 1.0])
    matrix[:3, 3] = (1.0 - factors) * f
    return matrix


_PLANE_NORMALS = {"xy": (0.0, 0.0, 1.0), "yz": (1.0, 0.0, 0.0), "zx": (0.0, 1.0, 0.0), "xz": (0.0, 1.0, 0.0)}


def reflect(normal: ArrayLike | str, point: ArrayLike = (0.0, 0.0, 0.0)) -> Matrix4:
    """Mirror reflection through the plane with normal `normal` passing through `point`.

    $P' = P − 2·((P − p)·n)·n$ for the unit normal n: the 3x3 block is the Householder matrix
    $I − 2·n·nᵀ$ (det −1, so ``swaps_handedness`` is true). `normal` may also name a coordinate plane:
    ``reflect("xy")`` is the seed's M_zreflect (z → −z); ``"yz"`` flips x, ``"zx"`` (or ``"xz"``) flips y.
    A reflection about an axis (a line) is a rotation by π about it: ``rotate(axis, np.pi, point)``.

    Raises
    ------
    TransformError
        If `normal` has zero length or names no coordinate plane.

    References
    ----------
    [HB 9] "Three-Dimensional Reflections"; [seed] "Three-dimensional Reflections".
    """
    if isinstance(normal, str):
        if normal not in _PLANE_NORMALS:
            raise TransformError(
                f"reflect: normal = {normal!r} names no coordinate plane; "
                f"expected one of {sorted(_PLANE_NORMALS)} or a nonzero vector"
            )
        normal = _PLANE_NORMALS[normal]
    n = as_direction(normal, "normal", where="reflect")
    p = as_vector3(point, "point", where="reflect")
    matrix = np.eye(4)
    matrix[:3, :3] -= 2.0 * np.outer(n, n)
    matrix[:3, 3] = 2.0 * float(n @ p) * n
    return matrix


_SHEAR_AXES = {"x": (0, (1, 2)), "y": (1, (0, 2)), "z": (2, (0, 1))}


def shear(axis: str, a: float, b: float, ref: float = 0.0) -> Matrix4:
    """Shear along the other two coordinates in proportion to the distance along `axis` from `ref`.

    - ``"x"``: $y' = y + a·(x − ref), z' = z + b·(x − ref)$ (the seed's x-axis shear, a = sh_y, b = sh_z)
    - ``"y"``: $x' = x + a·(y − ref), z' = z + b·(y − ref)$
    - ``"z"``: $x' = x + a·(z − ref), y' = y + b·(z − ref)$ (the seed's M_zshear, a = sh_zx, b = sh_zy,
      ref = z_ref; its last column is $−sh_zx·z_ref, −sh_zy·z_ref$)

    `a` always drives the first of the two other axes in x, y, z order, `b` the second. Points on the plane
    $axis = ref$ do not move.

    References
    ----------
    [HB 9] "Three-Dimensional Shears"; [seed] "Three-dimensional shear".
    """
    if axis not in _SHEAR_AXES:
        raise TransformError(f"shear: axis = {axis!r} is not a coordinate axis; expected 'x', 'y' or 'z'")
    a = as_scalar(a, "a", where="shear")
    b = as_scalar(b, "b", where="shear")
    ref = as_scalar(ref, "ref", where="shear")
    driver, (first, second) = _SHEAR_AXES[axis]
    matrix = np.eye(4)
    matrix[first, driver], matrix[second, driver] = a, b
    matrix[first, 3], matrix[second, 3] = -a * ref, -b * ref
    return matrix


# --- composition and inspection ---------------------------------------------------------------------------


def compose(*matrices: ArrayLike) -> Matrix4:
    """The composite that applies the arguments in order: $compose(A, B, C) = C @ B @ A$.

    With no arguments it returns the identity. Read a chain of ``b_from_a`` names right to left:
    $compose(world_from_model, view_from_world) = view_from_world @ world_from_model = view_from_model$.

    References
    ----------
    [HB 9] "Composite Three-Dimensional Transformations".
    """
    checked = [as_matrix(m, f"matrices[{i}]", where="compose") for i, m in enumerate(matrices)]
    return reduce(lambda total, m: m @ total, checked, np.eye(4))


def to_row_major(matrix: ArrayLike) -> Matrix4:
    """The same transformation for row vectors, $P' = P · Mᵀ$: returns the transpose of `matrix`.

    ``P_h @ to_row_major(M)`` equals ``apply_homogeneous(M, P)``, and after dividing by w, ``apply(M, P)``.
    This is the seed's "row major" table: the column-major matrix transposed, composites then read left to
    right ($P · A · B$ applies A first).
    """
    return as_matrix(matrix, where="to_row_major").T.copy()


def invert(matrix: ArrayLike) -> Matrix4:
    """Inverse of `matrix`: exact transpose for rigid motions, affine inverse for affine maps, general otherwise.

    - rigid (orthonormal 3x3 block R, bottom row 0 0 0 1): $M⁻¹ = [Rᵀ, −Rᵀ·t]$
    - affine (bottom row 0 0 0 1): $M⁻¹ = [A⁻¹, −A⁻¹·t]$
    - projective: the general 4x4 inverse.

    Raises
    ------
    TransformError
        If the matrix is singular to double precision (for example a scale factor of 0, or a projection
        onto a plane).
    """
    m = as_matrix(matrix, where="invert")
    if not _is_affine(m):
        _check_invertible(m, "matrix", "invert")
        return np.linalg.inv(m)
    block, offset = m[:3, :3], m[:3, 3]
    if np.abs(block.T @ block - np.eye(3)).max() <= _EXACT_TOLERANCE:
        inverse_block = block.T.copy()
    else:
        _check_invertible(block, "matrix[:3, :3]", "invert")
        inverse_block = np.linalg.inv(block)
    inverse = np.eye(4)
    inverse[:3, :3] = inverse_block
    inverse[:3, 3] = -inverse_block @ offset
    return inverse


def swaps_handedness(matrix: ArrayLike) -> bool:
    """True when `matrix` turns right-handed frames into left-handed ones: $det(M) < 0$.

    Reflections (and an odd number of negative scale factors) swap handedness, so triangles transformed by
    such a matrix reverse their winding; ``Mesh.transformed`` flips faces when this is true. For affine
    matrices $det(M) = det(A)$ of the 3x3 block; for projective ones the sign of ``det(M)`` gives the
    orientation where $w > 0$ (``perspective`` is a swap: right-handed view space to left-handed NDC).

    Raises
    ------
    TransformError
        If the matrix is singular: it flattens space, so it has no handedness.
    """
    m = as_matrix(matrix, where="swaps_handedness")
    _check_invertible(m, "matrix", "swaps_handedness")
    sign, _ = np.linalg.slogdet(m)
    return bool(sign < 0)


# --- applying to points, directions, normals --------------------------------------------------------------


def apply(matrix: ArrayLike, points: ArrayLike) -> Points:
    """$P' = M·P$ for every row P of `points`, then the homogeneous divide by w.

    Parameters
    ----------
    matrix : (4, 4) array_like
    points : (N, 3) or (3,) array_like
        Cartesian points; a single point gives a single point back.

    Returns
    -------
    (N, 3) or (3,) float64
        ``(x_h/w, y_h/w, z_h/w)``. For affine matrices w = 1 and the divide changes nothing.

    Raises
    ------
    TransformError
        If a point maps to $w = 0$ (a point at infinity, e.g. a point in the eye plane under a
        perspective projection); ``apply_homogeneous`` keeps w instead.
    """
    single, rows = _point_rows(points, "apply")
    m = as_matrix(matrix, where="apply")
    xyz = rows @ m[:3, :3].T + m[:3, 3]
    w = rows @ m[3, :3] + m[3, 3]
    at_infinity = np.flatnonzero(w == 0.0)
    if at_infinity.size:
        i = int(at_infinity[0])
        raise TransformError(
            f"apply: points[{i}] = {describe(rows[i])} maps to w = 0 (a point at infinity), which has no "
            "Cartesian coordinates; use apply_homogeneous to keep w, or clip first"
        )
    result = xyz / w[:, None]
    return result[0] if single else result


def apply_homogeneous(matrix: ArrayLike, points: ArrayLike) -> Points:
    """$P_h = M·P$ for every row, without the divide: (N, 3) points (w = 1) or (N, 4) in, (N, 4) out.

    This is how positions enter clip space: $points_clip = apply_homogeneous(clip_from_world, points)$.
    """
    m = as_matrix(matrix, where="apply_homogeneous")
    try:
        shape = np.shape(points)
    except ValueError:  # ragged nested sequences: let as_points report them
        shape = None
    if shape is not None and len(shape) == 2 and shape[1] == 4:
        rows = as_homogeneous_points(points, where="apply_homogeneous")
        return rows @ m.T
    rows = as_points(points, where="apply_homogeneous")
    return rows @ m[:, :3].T + m[:, 3]


def apply_to_directions(matrix: ArrayLike, vectors: ArrayLike) -> Points:
    """$d' = A·d$ with the 3x3 block A of `matrix`: directions have w = 0, so translation does not move them.

    Not normalized: a scale changes a direction's length, as it changes a displacement. For a projective
    matrix this is the x, y, z part of $M·[d, 0]$ (the w part, $M[3, :3]·d$, is the vanishing point's w).

    Parameters
    ----------
    vectors : (N, 3) or (3,) array_like
    """
    single, rows = _point_rows(vectors, "apply_to_directions", name="vectors")
    m = as_matrix(matrix, where="apply_to_directions")
    result = rows @ m[:3, :3].T
    return result[0] if single else result


def apply_to_normals(matrix: ArrayLike, normals: ArrayLike) -> Points:
    """$n' = (A⁻¹)ᵀ·n$, renormalized to unit length, with A the 3x3 block of an affine `matrix`.

    Normals are not directions: under a non-uniform scale or a shear, $A·n$ is no longer perpendicular to
    the transformed surface, but the inverse transpose is (a tangent t with $n·t = 0$ maps to $A·t$ and
    $((A⁻¹)ᵀ n)·(A t) = n·t = 0$). This is pbrt's ``Normal3`` rule. Under a reflection the result is the
    mirrored normal; callers that flip face winding keep it (the surface's outside is mirrored too).

    Parameters
    ----------
    normals : (N, 3) or (3,) array_like
        Nonzero vectors (any length).

    Raises
    ------
    TransformError
        If `matrix` is projective (normals are transformed before projection) or its 3x3 block is singular.
    GeometryError
        If a normal has zero length.
    """
    single, rows = _point_rows(normals, "apply_to_normals", name="normals")
    m = as_matrix(matrix, where="apply_to_normals")
    if not _is_affine(m):
        raise TransformError(
            f"apply_to_normals: matrix bottom row = {describe(m[3])} makes it projective; normals transform "
            "only under affine matrices (bottom row 0, 0, 0, 1): transform them before the projection"
        )
    lengths = np.linalg.norm(rows, axis=1)
    zero = np.flatnonzero(lengths == 0.0)
    if zero.size:
        i = int(zero[0])
        raise GeometryError(
            f"apply_to_normals: normals[{i}] = {describe(rows[i])} has zero length; normals must be nonzero"
        )
    _check_invertible(m[:3, :3], "matrix[:3, :3]", "apply_to_normals")
    transformed = rows @ np.linalg.inv(m[:3, :3])  # row form of (A⁻¹)ᵀ·n
    result = transformed / np.linalg.norm(transformed, axis=1)[:, None]
    return result[0] if single else result


# --- helpers ----------------------------------------------------------------------------------------------


def _cos_sin(angle: float, where: str) -> tuple[float, float]:
    theta = as_scalar(angle, "angle", where=where)
    return float(np.cos(theta)), float(np.sin(theta))


def _is_affine(matrix: Matrix4) -> bool:
    return bool(np.abs(matrix[3] - (0.0, 0.0, 0.0, 1.0)).max() <= _EXACT_TOLERANCE)


def _check_invertible(block: np.ndarray, name: str, where: str) -> None:
    singular_values = np.linalg.svd(block, compute_uv=False)
    if singular_values[-1] == 0.0 or singular_values[0] / singular_values[-1] > _SINGULAR_CONDITION:
        raise TransformError(
            f"{where}: {name} is singular (det = {np.linalg.det(block):.3g}): it flattens space onto a plane, "
            "line or point (a scale factor of 0, or a projection onto a plane); "
            "only an invertible matrix qualifies"
        )


def _point_rows(points: ArrayLike, where: str, name: str = "points") -> tuple[bool, Points]:
    try:
        shape = np.shape(points)
    except ValueError:  # ragged nested sequences: let as_points report them
        shape = None
    if shape == (3,):
        return True, as_vector3(points, name, where=where, error=GeometryError)[None, :]
    return False, as_points(points, name, where=where)
