"""Region codes and planes of clipping in homogeneous coordinates: the six planes $−w ≤ x, y, z ≤ w$ of the view
volume and any extra planes, the codes of points against them, trivial accept and reject, and the checks of the
clipping functions' arguments."""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_homogeneous_points, as_matrix, as_points, describe
from frustum.errors import ClippingError

__all__ = [
    "MAX_KERNEL_PLANES",
    "REGION_BOTTOM",
    "REGION_FAR",
    "REGION_LEFT",
    "REGION_NEAR",
    "REGION_RIGHT",
    "REGION_TOP",
    "VIEW_VOLUME_PLANES",
    "Recorder",
    "as_planes",
    "clip_kernels",
    "inside_view_volume",
    "kernel_codes",
    "kernel_planes",
    "plane_code",
    "plane_from_point_normal",
    "point4",
    "region_code",
    "region_names",
    "single_point",
    "transform_plane",
    "trivially_accepted",
    "trivially_rejected",
    "with_view_volume",
]


def clip_kernels() -> ModuleType:
    """The compiled clipping kernels (``raster/clip.py``), imported on first use: ``import frustum`` never loads
    Numba."""
    from frustum.raster import clip

    return clip


REGION_LEFT = 1
"""Region-code bit 1: ``w + x < 0`` (x < −w)."""


REGION_RIGHT = 2
"""Region-code bit 2: ``w − x < 0`` (x > w)."""


REGION_BOTTOM = 4
"""Region-code bit 3: ``w + y < 0``."""


REGION_TOP = 8
"""Region-code bit 4: ``w − y < 0``."""


REGION_NEAR = 16
"""Region-code bit 5: ``w + z < 0`` (in front of the near plane)."""


REGION_FAR = 32
"""Region-code bit 6: ``w − z < 0`` (behind the far plane)."""

_REGION_NAMES = (
    (REGION_LEFT, "left"),
    (REGION_RIGHT, "right"),
    (REGION_BOTTOM, "bottom"),
    (REGION_TOP, "top"),
    (REGION_NEAR, "near"),
    (REGION_FAR, "far"),
)


def region_names(code: int) -> list[str]:
    """The planes a region code says a point is outside of, in bit order: e.g. ``["left", "far"]`` for 33."""
    return [name for bit, name in _REGION_NAMES if code & bit]


# fmt: off
VIEW_VOLUME_PLANES: NDArray[np.float64] = np.array([
    [ 1.0,  0.0,  0.0, 1.0],  # left:   w + x >= 0
    [-1.0,  0.0,  0.0, 1.0],  # right:  w − x >= 0
    [ 0.0,  1.0,  0.0, 1.0],  # bottom: w + y >= 0
    [ 0.0, -1.0,  0.0, 1.0],  # top:    w − y >= 0
    [ 0.0,  0.0,  1.0, 1.0],  # near:   w + z >= 0
    [ 0.0,  0.0, -1.0, 1.0],  # far:    w − z >= 0
])
# fmt: on
VIEW_VOLUME_PLANES.flags.writeable = False
"""The six planes of ``−w <= x, y, z <= w`` as (6, 4) inside-positive 4-vectors; row k is region-code bit k+1."""


MAX_KERNEL_PLANES = 63
"""Planes (the cube's six included) that ``clip_lines`` and ``clip_triangles`` accept: one int64 code bit each."""


Recorder = Callable[..., Any]
"""A ``record=`` hook: called as ``record(event, **values)`` at each step of an algorithm (``frustum.steps``)."""


def region_code(points_h: ArrayLike) -> NDArray[np.int64] | int:
    """The six-bit region code of each homogeneous point: which cube planes it is outside of.

    $code = [w+x<0]·1 | [w−x<0]·2 | [w+y<0]·4 | [w−y<0]·8 | [w+z<0]·16 | [w−z<0]·32$ (module docstring
    for the bit order). A code of 0 means inside (or on the boundary of) $−w <= x, y, z <= w$.

    Parameters
    ----------
    points_h : (N, 4) or (4,) array_like
        Clip-space points ``(x, y, z, w)``.

    Returns
    -------
    (N,) int64, or int for a single point.

    Raises
    ------
    ClippingError
        If the shape is not (N, 4) or (4,), or a coordinate is not finite.

    References
    ----------
    [HB 10] "Clipping in Three-Dimensional Homogeneous Coordinates" (region codes); [seed] "Three-dimensional
    Region Codes".
    """
    single, points = _homogeneous_rows(points_h, "points_h", "region_code")
    x, y, z, w = points.T
    codes = (
        (w + x < 0) * REGION_LEFT
        | (w - x < 0) * REGION_RIGHT
        | (w + y < 0) * REGION_BOTTOM
        | (w - y < 0) * REGION_TOP
        | (w + z < 0) * REGION_NEAR
        | (w - z < 0) * REGION_FAR
    ).astype(np.int64)
    return int(codes[0]) if single else codes


def trivially_accepted(codes: ArrayLike) -> NDArray[np.bool_] | bool:
    """True where a primitive lies wholly inside: the OR of its vertices' region codes is 0.

    `codes` has the vertices of one primitive along its last axis: ``(2,)`` for one segment, ``(N, 2)`` for
    ``np.stack([region_code(p0s), region_code(p1s)], axis=-1)``, ``(K,)`` for the K vertices of a polygon.
    Works for codes against any plane set (one bit per plane).

    References
    ----------
    [HB 10] "Three-Dimensional Region Codes"; [seed] "Three-dimensional Region Codes".
    """
    array = _as_codes(codes, "trivially_accepted")
    result = np.bitwise_or.reduce(array, axis=-1) == 0
    return bool(result) if result.ndim == 0 else result


def trivially_rejected(codes: ArrayLike) -> NDArray[np.bool_] | bool:
    """True where a primitive lies wholly outside one plane: the AND of its vertices' region codes is nonzero.

    Same layout as ``trivially_accepted``. A primitive that is neither accepted nor rejected needs clipping
    (it may still turn out to be invisible, e.g. a segment passing outside a corner of the cube).

    References
    ----------
    [HB 10] "Three-Dimensional Region Codes"; [seed] "Three-dimensional Region Codes".
    """
    array = _as_codes(codes, "trivially_rejected")
    result = np.bitwise_and.reduce(array, axis=-1) != 0
    return bool(result) if result.ndim == 0 else result


def inside_view_volume(points_h: ArrayLike) -> NDArray[np.bool_] | bool:
    """Point clipping: True where $−w <= x, y, z <= w$ and $w > 0$.

    ``region_code(P) == 0`` is the textbook test; the extra $w > 0$ only excludes the clip-space origin
    ``(0, 0, 0, 0)``, the one point with code 0 that has no Cartesian position.

    Parameters
    ----------
    points_h : (N, 4) or (4,) array_like

    Returns
    -------
    (N,) bool, or bool for a single point.

    Raises
    ------
    ClippingError
        If the shape is not (N, 4) or (4,), or a coordinate is not finite.

    References
    ----------
    [HB 10] "Three-Dimensional Point and Line Clipping"; [seed] "3D Point and Line Clipping".
    """
    single, points = _homogeneous_rows(points_h, "points_h", "inside_view_volume")
    inside = (kernel_codes(points, with_view_volume(None, "inside_view_volume")) == 0) & (points[:, 3] > 0)
    return bool(inside[0]) if single else inside


def plane_from_point_normal(point: ArrayLike, normal: ArrayLike) -> NDArray[np.float64]:
    """The world-space plane through `point` whose inside is the side `normal` points to.

    $(a, b, c, d) = (n_x, n_y, n_z, −n·p)$: a Cartesian point q (w = 1) is inside when $n·q − n·p >= 0$.
    The normal is not normalized (its length does not change the inside).

    Raises
    ------
    ClippingError
        If `normal` has zero length or any value is not finite.

    References
    ----------
    [HB 10] "Arbitrary Clipping Planes" (cutaway views cut by a plane $A·x + B·y + C·z + D = 0$).
    """
    p = single_point(point, "point", "plane_from_point_normal", (3,))
    n = single_point(normal, "normal", "plane_from_point_normal", (3,))
    if not np.any(n):
        raise ClippingError(f"plane_from_point_normal: normal = {describe(n)} has zero length; give a nonzero normal")
    return np.append(n, -float(n @ p))


def transform_plane(clip_from_world: ArrayLike, plane: ArrayLike) -> NDArray[np.float64]:
    """Carry a plane (or (K, 4) planes) from world to clip space: $plane_clip = (M⁻¹)ᵀ · plane_world$.

    For a world point ``P`` and $P_clip = M·P$: $plane_clip · P_clip = plane_worldᵀ·M⁻¹·M·P =
    plane_world · P$, so every point keeps its inside/outside side, also where $w_clip < 0$. Planes are
    covectors, like normals: they transform by the inverse transpose (pbrt's ``Normal3`` rule).

    Parameters
    ----------
    clip_from_world : (4, 4) array_like
        Invertible matrix, e.g. ``clip_from_view @ view_from_world``.
    plane : (4,) or (K, 4) array_like
        ``(a, b, c, d)`` with inside $a·x + b·y + c·z + d >= 0$ for world points.

    Returns
    -------
    (4,) or (K, 4) float64, ready for the `planes` argument of the clippers.

    Raises
    ------
    ClippingError
        If the matrix is singular or not finite, or a plane is degenerate (all zero) or not finite.

    References
    ----------
    [HB 10] "Arbitrary Clipping Planes"; pbrt ``Normal3`` (inverse transpose).
    """
    matrix = as_matrix(clip_from_world, "clip_from_world", where="transform_plane", error=ClippingError)
    single = np.shape(plane) == (4,)
    planes = as_planes(plane, "plane", "transform_plane")
    singular_values = np.linalg.svd(matrix, compute_uv=False)
    if singular_values[-1] <= singular_values[0] * 1e-15:
        raise ClippingError(
            f"transform_plane: clip_from_world is singular (singular values {describe(singular_values)}); "
            "planes transform by the inverse transpose, so the matrix must be invertible"
        )
    transformed = np.linalg.solve(matrix.T, planes.T).T
    return transformed[0] if single else transformed


def plane_code(point: NDArray, planes: NDArray) -> int:
    return sum(1 << int(k) for k in np.flatnonzero(planes @ point < 0))


def kernel_codes(points: NDArray, planes: NDArray) -> NDArray[np.int64]:
    codes = np.empty(points.shape[0], dtype=np.int64)
    clip_kernels().region_codes(points, planes, codes)
    return codes


def single_point(value: ArrayLike, name: str, where: str, widths: tuple[int, ...]) -> NDArray[np.float64]:
    try:
        shape = np.shape(value)
    except ValueError:  # ragged nested sequences
        shape = None
    if shape is None or len(shape) != 1 or shape[0] not in widths:
        expected = " or ".join(f"({w},)" for w in widths)
        raise ClippingError(f"{where}: {name} = {describe(value)} has shape {shape}; expected a {expected} vector")
    checker = as_homogeneous_points if shape[0] == 4 else as_points
    return checker([value], name, where=where, error=ClippingError)[0]


def _homogeneous_rows(value: ArrayLike, name: str, where: str) -> tuple[bool, Points]:
    try:
        shape = np.shape(value)
    except ValueError:  # ragged: let the checker report it
        shape = None
    if shape == (4,):
        return True, as_homogeneous_points([value], name, where=where, error=ClippingError)
    return False, as_homogeneous_points(value, name, where=where, error=ClippingError)


def point4(value: ArrayLike, name: str, where: str) -> NDArray[np.float64]:
    try:
        shape = np.shape(value)
    except ValueError:
        shape = None
    if shape != (4,):
        raise ClippingError(
            f"{where}: {name} = {describe(value)} has shape {shape}; expected a (4,) homogeneous point (x, y, z, w)"
        )
    return as_homogeneous_points([value], name, where=where, error=ClippingError)[0]


def as_planes(value: ArrayLike, name: str, where: str, cartesian: bool = False) -> NDArray[np.float64]:
    planes = as_homogeneous_points(
        [value] if np.shape(value) == (4,) else value, name, where=where, error=ClippingError
    )
    normal_part = planes[:, :3] if cartesian else planes
    degenerate = np.flatnonzero(~normal_part.any(axis=1))
    if degenerate.size:
        i = int(degenerate[0])
        what = "normal (a, b, c)" if cartesian else "4-vector (a, b, c, d)"
        raise ClippingError(
            f"{where}: {name}[{i}] = {describe(planes[i])} is degenerate (zero {what}); "
            f"a plane a·x + b·y + c·z + d·w >= 0 needs a nonzero {what}"
        )
    return planes


def with_view_volume(planes: ArrayLike | None, where: str) -> NDArray[np.float64]:
    if planes is None:
        return np.array(VIEW_VOLUME_PLANES)
    return np.concatenate([VIEW_VOLUME_PLANES, as_planes(planes, "planes", where)])


def kernel_planes(planes: ArrayLike | None, where: str) -> NDArray[np.float64]:
    all_planes = with_view_volume(planes, where)
    if all_planes.shape[0] > MAX_KERNEL_PLANES:
        raise ClippingError(
            f"{where}: planes has {all_planes.shape[0] - 6} rows; at most {MAX_KERNEL_PLANES - 6} user planes "
            f"(one region-code bit each, the cube taking 6 of {MAX_KERNEL_PLANES}); clip_polygon and "
            "clip_line_convex take any number"
        )
    return all_planes


def _as_codes(codes: ArrayLike, where: str) -> NDArray[np.int64]:
    array = np.asarray(codes)
    if array.ndim == 0 or array.dtype == np.bool_ or not np.issubdtype(array.dtype, np.integer):
        raise ClippingError(
            f"{where}: codes = {describe(codes)} has shape {array.shape}, dtype {array.dtype}; expected integer "
            "region codes with a primitive's vertices along the last axis"
        )
    return array.astype(np.int64, copy=False)
