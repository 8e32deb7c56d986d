"""The one place where shapes, dtypes and finiteness are checked at the public boundary.

Every checker returns the normalized array (C-contiguous float64) or raises the given ``FrustumError``
subclass with a message ``<where>: <name> = <value> <problem>; <what would be valid>``. Kernels and
internal helpers never validate: they trust what these functions return.
"""

from __future__ import annotations

from typing import Any, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum.errors import FrustumError, GeometryError, TransformError

__all__ = [
    "Matrix4",
    "Points",
    "Vector3",
    "as_count",
    "as_direction",
    "as_faces",
    "as_homogeneous_points",
    "as_matrix",
    "as_points",
    "as_scalar",
    "as_vector3",
    "describe",
    "escape_control",
    "is_numeric",
    "read_only",
]

Matrix4: TypeAlias = NDArray[np.float64]
"""A (4, 4) float64 homogeneous matrix, column-vector convention: ``P' = M @ P``."""
Points: TypeAlias = NDArray[np.float64]
"""An (N, 3) float64 array of points or vectors, one per row (or (N, 4) homogeneous, where stated)."""
Vector3: TypeAlias = NDArray[np.float64]
"""A (3,) float64 vector."""

ErrorType: TypeAlias = type[FrustumError]

INT32_LIMIT = 2**31
"""Vertex counts up to this keep their face indices in int32 (``as_faces(..., compact=True)``)."""


_CONTROL = {c: f"\\x{c:02x}" for c in (*range(0x20), 0x7F)} | {c: f"\\u{c:04x}" for c in range(0x80, 0xA0)}
_CONTROL |= {c: f"\\u{c:04x}" for c in (0x2028, 0x2029, *range(0x202A, 0x202F), *range(0x2066, 0x206A))}
_CONTROL |= {ord("\n"): "\\n", ord("\t"): "\\t", ord("\r"): "\\r"}


def escape_control(text: str, *, keep_newlines: bool = False) -> str:
    """`text` with control characters (C0, DEL, C1, line/paragraph separators, bidi overrides) written as escapes.

    Every message that quotes input goes through this (``describe`` does), so a scene-file key such as
    ``"x\\nerror: all good\\x1b[31m"`` cannot forge an ``error:`` line or color the terminal. `keep_newlines`
    keeps ``\\n`` (for multi-line reports whose parts were escaped already).
    """
    table = _CONTROL if not keep_newlines else {k: v for k, v in _CONTROL.items() if k != ord("\n")}
    return str(text).translate(table)


def describe(value: Any, *, limit: int = 80) -> str:
    """Short, readable text of a value for an error message: floats as Python writes them, long arrays cut,
    control characters escaped."""
    if isinstance(value, np.ndarray):
        value = (value.ravel()[:limit] if value.size > limit else value).tolist()  # a huge array is never listed
    if (
        isinstance(value, list | tuple)
        and len(value) <= limit
        and all(isinstance(v, int | float | np.number) and not isinstance(v, bool | np.bool_) for v in value)
    ):  # a boolean among numbers is shown as itself (False), not as 0.0
        text = "(" + ", ".join(repr(float(v)) for v in value) + ("," if len(value) == 1 else "") + ")"
    elif isinstance(value, np.number):
        text = repr(value.item())
    elif isinstance(value, list | tuple | dict) and len(value) > limit:
        text = f"<{type(value).__name__} of {len(value)} items>"
    else:
        try:
            text = repr(value)
        except Exception:  # a hostile __repr__ (or a recursion-deep structure) must not hide the real error
            text = f"<{type(value).__name__}>"
    text = escape_control(text)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def read_only(array: np.ndarray) -> np.ndarray:
    """A read-only view of `array`: frozen frustum objects hand out arrays nobody can edit, and the flags of the
    array passed in (possibly the caller's own) stay as they were."""
    view = array.view()
    view.flags.writeable = False
    return view


def _as_float_array(
    value: ArrayLike, name: str, where: str, error: ErrorType, expected: str, keep_float32: bool = False,
    share: bool = False,
) -> NDArray:  # fmt: skip
    """A C-contiguous float64 array (float32 where `keep_float32` and the input is float32: a lossless copy) that
    never is (or views) the caller's own array, unless `share` (then it is the caller's array itself when that
    already has the dtype and layout); complex input is refused."""
    try:
        raw = np.asarray(value)
        complex_input = raw.dtype.kind == "c"
        dtype = np.float32 if keep_float32 and raw.dtype == np.float32 else np.float64
        array = None if complex_input else np.asarray(raw, dtype=dtype)
    except (TypeError, ValueError):
        raise error(f"{where}: {name} = {describe(value)} is not numeric; expected {expected}") from None
    if array is None:
        raise error(f"{where}: {name} = {describe(value)} is complex; expected {expected} (real numbers)")
    array = np.ascontiguousarray(array)
    if not share and isinstance(value, np.ndarray) and np.may_share_memory(array, value):
        array = array.copy()  # the checked array is ours: later read-only flags must not reach the caller's
    return array


def is_numeric(value: object) -> bool:
    """Whether `value` converts to a float64 array (``np.asarray(value, dtype=np.float64)`` does not raise)."""
    try:
        np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        return False
    return True


def as_scalar(value: Any, name: str, *, where: str, error: ErrorType = TransformError) -> float:
    """Return `value` as a finite Python float, or raise `error` naming it."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        array = np.asarray(value) if isinstance(value, np.ndarray) else None
        if array is None or array.shape != ():
            raise error(f"{where}: {name} = {describe(value)} is not a number; expected a finite real number")
        value = array.item()
    number = float(value)
    if not np.isfinite(number):
        raise error(f"{where}: {name} = {number!r} is not finite; expected a finite real number")
    return number


def as_count(value: Any, name: str, minimum: int, *, where: str, error: ErrorType = GeometryError) -> int:
    """An integer >= `minimum` (a resolution, a level, a degree); bools and floats are refused."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise error(f"{where}: {name} = {describe(value)} is not an integer; give an integer >= {minimum}")
    if value < minimum:
        raise error(f"{where}: {name} = {int(value)} is below {minimum}; give an integer >= {minimum}")
    return int(value)


def as_vector3(value: ArrayLike, name: str, *, where: str, error: ErrorType = TransformError) -> Vector3:
    """Return `value` as a finite (3,) float64 vector, or raise `error` naming it."""
    vector = _as_float_array(value, name, where, error, "three finite numbers (x, y, z)")
    if vector.shape != (3,):
        raise error(f"{where}: {name} = {describe(value)} has shape {vector.shape}; expected three numbers (x, y, z)")
    if not np.isfinite(vector).all():
        raise error(f"{where}: {name} = {describe(vector)} is not finite; coordinates must be finite numbers")
    return vector


def as_direction(value: ArrayLike, name: str, *, where: str, error: ErrorType = TransformError) -> Vector3:
    """Return `value` normalized to unit length as a (3,) float64 vector; zero length raises `error`."""
    vector = as_vector3(value, name, where=where, error=error)
    length = float(np.linalg.norm(vector))
    if length == 0.0 or not np.isfinite(length):
        raise error(f"{where}: {name} = {describe(vector)} has zero length; give a nonzero direction")
    return vector / length


def as_matrix(value: ArrayLike, name: str = "matrix", *, where: str, error: ErrorType = TransformError) -> Matrix4:
    """Return `value` as a finite, C-contiguous (4, 4) float64 matrix, or raise `error` naming it."""
    matrix = _as_float_array(value, name, where, error, "a (4, 4) matrix of finite numbers")
    if matrix.shape != (4, 4):
        raise error(f"{where}: {name} has shape {matrix.shape}; expected a (4, 4) homogeneous matrix")
    if not np.isfinite(matrix).all():
        row, column = np.argwhere(~np.isfinite(matrix))[0]
        raise error(
            f"{where}: {name}[{row}, {column}] = {float(matrix[row, column])!r} is not finite; "
            "matrix entries must be finite numbers"
        )
    return matrix


def _as_rows(
    value: ArrayLike, width: int, name: str, where: str, error: ErrorType, what: str, keep_float32: bool = False,
    share: bool = False,
) -> NDArray:  # fmt: skip
    rows = _as_float_array(value, name, where, error, f"an (N, {width}) array of {what}", keep_float32, share)
    if rows.ndim == 2 and rows.shape[0] == 0 and rows.shape[1] in (0, width):
        return np.empty((0, width), dtype=rows.dtype)
    if rows.ndim == 1 and rows.size == 0:
        return np.empty((0, width), dtype=rows.dtype)
    if rows.ndim != 2 or rows.shape[1] != width:
        raise error(f"{where}: {name} has shape {rows.shape}; expected (N, {width}) {what}, one per row")
    bad = _nonfinite_rows(rows)
    if bad.size:
        i = int(bad[0])
        raise error(f"{where}: {name}[{i}] = {describe(rows[i])} is not finite; coordinates must be finite numbers")
    return rows


def _nonfinite_rows(rows: NDArray) -> NDArray[np.intp]:
    """Indices of the rows holding a NaN or an infinity, checked in blocks (no full-size temporary)."""
    step = 1 << 16
    for start in range(0, rows.shape[0], step):
        bad = np.flatnonzero(~np.isfinite(rows[start : start + step]).all(axis=1))
        if bad.size:
            return bad + start
    return np.empty(0, dtype=np.intp)


def as_points(
    value: ArrayLike, name: str = "points", *, where: str, error: ErrorType = GeometryError, keep_float32: bool = False,
    share: bool = False,
) -> Points:  # fmt: skip
    """Return `value` as a finite, C-contiguous (N, 3) float64 array; (0, 3) is valid.

    With `keep_float32`, a float32 array stays float32 (a copy: float32 → float64 is exact, so a caller computing
    in float64 from it gets the same numbers; storage is half); every other input is converted to float64. With
    `share`, an input array that already has that dtype and layout is returned itself, not copied.
    """
    return _as_rows(value, 3, name, where, error, "points (x, y, z)", keep_float32, share)


def as_homogeneous_points(
    value: ArrayLike, name: str = "points", *, where: str, error: ErrorType = GeometryError
) -> Points:
    """Return `value` as a finite, C-contiguous (N, 4) float64 array of homogeneous points (x, y, z, w)."""
    return _as_rows(value, 4, name, where, error, "homogeneous points (x, y, z, w)")


def as_faces(
    value: ArrayLike,
    vertex_count: int,
    name: str = "faces",
    *,
    where: str,
    error: ErrorType = GeometryError,
    compact: bool = False,
    share: bool = False,
) -> NDArray[np.int64]:
    """Return `value` as a C-contiguous (M, 3) int64 array of vertex indices in [0, vertex_count); (0, 3) is valid.

    Indices must already be integers (an integer dtype): a float array is refused rather than rounded. With
    `compact`, the array is int32 when every index fits ($vertex_count <= 2**31$): lossless, half the memory;
    code combining such indices arithmetically (edge keys $i·N + j$) must widen to int64 first. With `share`,
    an input array that already has that dtype and layout is returned itself, not copied.
    """
    index_type = np.int32 if compact and vertex_count <= INT32_LIMIT else np.int64
    try:
        faces = np.asarray(value)
    except ValueError:  # ragged nested sequences
        raise error(f"{where}: {name} = {describe(value)} is not an array; expected (M, 3) vertex indices") from None
    if faces.size == 0 and (faces.ndim == 1 or (faces.ndim == 2 and faces.shape[1] in (0, 3))):
        return np.empty((0, 3), dtype=index_type)
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise error(f"{where}: {name} has shape {faces.shape}; expected (M, 3) vertex indices, one triangle per row")
    if faces.dtype == np.bool_ or not np.issubdtype(faces.dtype, np.integer):
        raise error(f"{where}: {name} has dtype {faces.dtype}; expected integer vertex indices")
    if faces.shape[0] and (faces.min() < 0 or faces.max() >= vertex_count):
        i = int(np.flatnonzero(((faces < 0) | (faces >= vertex_count)).any(axis=1))[0])
        raise error(
            f"{where}: {name}[{i}] = {faces[i].tolist()} indexes outside the {vertex_count} vertices; "
            f"indices must lie in [0, {vertex_count - 1}]"
        )
    checked = np.ascontiguousarray(faces, dtype=index_type)
    mine = share or not (isinstance(value, np.ndarray) and np.may_share_memory(checked, value))
    return checked if mine else checked.copy()
