"""Clipping in homogeneous clip space, before the perspective divide: points, lines, polygons, triangle batches.

The view volume is the symmetric cube $−w <= x, y, z <= w$ of clip space (NDC $[−1, 1]³$ before the
divide). Clipping here, not after the divide, is what handles points behind the eye ($w < 0$) correctly: a
segment from in front of the eye to behind it keeps only its visible part and never wraps around through
infinity, because the divide is done only on what survives.

**Planes.** A clip-space plane is a 4-vector ``(a, b, c, d)``; a point ``(x, y, z, w)`` is inside when
$a·x + b·y + c·z + d·w >= 0$ (exact sign test, no tolerance). ``VIEW_VOLUME_PLANES`` holds the cube's six, in
region-code order. User planes (a cutaway) take the same form and are always applied *in addition* to the
cube; ``plane_from_point_normal`` builds one in world space and ``transform_plane`` carries it to clip space.
In clip space the plane's normal is the whole 4-vector (``(0, 0, 0, 1)``, i.e. $w >= 0$, is a real plane), so
only the zero 4-vector is degenerate; for Cartesian points (``clip_line_convex`` with (3,) points) the normal
is ``(a, b, c)`` and must be nonzero.

**Region codes** (the seed's six bits, bit 1 the lowest-order bit, written right to left as in its tables):

====  =====  ==========  ========================
bit   value  name        set when
====  =====  ==========  ========================
1     1      left        $w + x < 0$
2     2      right       $w − x < 0$
3     4      bottom      $w + y < 0$
4     8      top         $w − y < 0$
5     16     near        $w + z < 0$
6     32     far         $w − z < 0$
====  =====  ==========  ========================

The seed's transcription prints these inequalities with x and z swapped ($h + z_n < 0 (left)$, ...,
$h − x_n < 0 (far)$); its own tables decide: ``010000`` is the centre of "in front of near plane" and
``011001`` its top-left corner, so bit 5 is near and bits 1 and 4 are left and top. That is Hearn & Baker's
order, used here.

**Nothing with w <= 0 survives.** The near and far planes together give $2w >= 0$ for every kept point, and
$w = 0$ only at the clip-space origin ``(0, 0, 0, 0)``, which is the image of no point under an invertible
``clip_from_world``. So the divide after clipping is safe without an extra $w > ε$ plane (which would not be
homogeneous); for a point exactly on the near plane the divide gives $z_ndc = −1$.

Why one module: every clipping algorithm of the chapter on the one homogeneous region-code and plane convention.

References are resolved in ``docs/references.md``: [HB 10] is Hearn & Baker chapter 10, "Three-Dimensional
Viewing", which holds 3D clipping; [seed] is the lecture notes.
"""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_faces, as_homogeneous_points, as_matrix, as_points, describe
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
    "ClippedLines",
    "ClippedPolygon",
    "ClippedSegment",
    "ClippedTriangles",
    "clip_line",
    "clip_line_convex",
    "clip_lines",
    "clip_polygon",
    "clip_triangles",
    "inside_view_volume",
    "plane_from_point_normal",
    "region_code",
    "transform_plane",
    "trivially_accepted",
    "trivially_rejected",
]


def _kernels() -> ModuleType:
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

_METHODS = ("liang-barsky", "cohen-sutherland", "cyrus-beck")

Recorder = Callable[..., Any]
"""A ``record=`` hook: called as ``record(event, **values)`` at each step of an algorithm (``frustum.steps``)."""


# --- region codes and point clipping ----------------------------------------------------------------------


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
    inside = (_kernel_codes(points, _with_view_volume(None, "inside_view_volume")) == 0) & (points[:, 3] > 0)
    return bool(inside[0]) if single else inside


# --- planes -----------------------------------------------------------------------------------------------


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
    p = _single_point(point, "point", "plane_from_point_normal", (3,))
    n = _single_point(normal, "normal", "plane_from_point_normal", (3,))
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
    planes = _as_planes(plane, "plane", "transform_plane")
    singular_values = np.linalg.svd(matrix, compute_uv=False)
    if singular_values[-1] <= singular_values[0] * 1e-15:
        raise ClippingError(
            f"transform_plane: clip_from_world is singular (singular values {describe(singular_values)}); "
            "planes transform by the inverse transpose, so the matrix must be invertible"
        )
    transformed = np.linalg.solve(matrix.T, planes.T).T
    return transformed[0] if single else transformed


# --- line clipping ----------------------------------------------------------------------------------------


class ClippedSegment(NamedTuple):
    """The visible part of a segment: endpoints and their parameters on $P = P1 + (P2 − P1)u$."""

    start: NDArray[np.float64]
    """(4,) (or (3,) for Cartesian input to ``clip_line_convex``) float64: the point at ``u_start``."""
    end: NDArray[np.float64]
    """Same shape: the point at ``u_end``."""
    u_start: float
    """Parameter of `start` on the input segment, 0 when the first end was inside."""
    u_end: float
    """Parameter of `end`, 1 when the second end was inside; ``u_start <= u_end``."""


class ClippedLines(NamedTuple):
    """Result of ``clip_lines``: per-segment clipped endpoints, parameters and a keep mask."""

    starts: NDArray[np.float64]
    """(N, 4) float64 clipped first ends; NaN rows where ``keep`` is False."""
    ends: NDArray[np.float64]
    """(N, 4) float64 clipped second ends; NaN rows where ``keep`` is False."""
    parameters: NDArray[np.float64]
    """(N, 2) float64 ``(u_start, u_end)`` on ``P = P1 + (P2 − P1)u``; ``(1, 0)`` where not kept."""
    keep: NDArray[np.bool_]
    """(N,) bool: True where some part of the segment is inside."""


def clip_line(
    p0: ArrayLike,
    p1: ArrayLike,
    method: str = "liang-barsky",
    planes: ArrayLike | None = None,
    *,
    record: Recorder | None = None,
) -> ClippedSegment | None:
    """The part of the clip-space segment p0 → p1 inside the view volume (and any user planes), or None.

    Three algorithms, equal up to round-off:

    - ``"liang-barsky"`` (default): parametric $P = P1 + (P2 − P1)u$; per plane $p_k·u <= q_k$ with
      $p_k = d(P1) − d(P2)$, $q_k = d(P1)$, narrowing ``[u0, u1]`` from ``[0, 1]`` (a compiled kernel).
    - ``"cohen-sutherland"``: region codes; trivially accept (``c1 | c2 == 0``) or reject (``c1 & c2 != 0``),
      else move an outside end to its lowest set bit's plane and recompute its code.
    - ``"cyrus-beck"``: $t = −N·P1 / N·D$ for the inward normals N (the cube's six here).

    An end inside every plane is returned bit for bit. The segment crossing $w = 0$ (one end behind the eye)
    keeps only the part in front, as a segment: it is never wrapped around through infinity.

    Parameters
    ----------
    p0, p1 : (4,) array_like
        Clip-space points ``(x, y, z, w)``.
    method : {"liang-barsky", "cohen-sutherland", "cyrus-beck"}
    planes : (K, 4) or (4,) array_like, optional
        Extra clip-space planes (inside $a·x + b·y + c·z + d·w >= 0$), applied after the cube's six.
    record : callable, optional
        Called as ``record(event, **values)`` at each step (``frustum.steps`` builds its record from it).
        Liang–Barsky then runs in the Python twin of its kernel (``_liang_barsky``, tested equal bit for bit).

    Returns
    -------
    ClippedSegment or None (nothing inside).

    Raises
    ------
    ClippingError
        If a point is not a finite (4,) vector, `method` is unknown, or a plane is degenerate or not finite.

    References
    ----------
    [HB 10] "Three-Dimensional Point and Line Clipping", "Clipping in Three-Dimensional Homogeneous
    Coordinates"; [seed] "3D Point and Line Clipping" ($P = P1 + (P2 − P1)u$).
    """
    start = _point4(p0, "p0", "clip_line")
    end = _point4(p1, "p1", "clip_line")
    if method not in _METHODS:
        raise ClippingError(f"clip_line: method = {method!r} is unknown; expected one of {', '.join(_METHODS)}")
    all_planes = _with_view_volume(planes, "clip_line")
    if method == "cohen-sutherland":
        return _cohen_sutherland(start, end, all_planes, record)
    if method == "cyrus-beck":
        return _cyrus_beck(start, end, all_planes)
    if record is not None:
        u0, u1 = _liang_barsky(start, end, all_planes, record)
    else:
        u0, u1 = _kernels().clip_segment(start, end, all_planes)
    return _segment(start, end, u0, u1)


def clip_lines(p0s: ArrayLike, p1s: ArrayLike, planes: ArrayLike | None = None) -> ClippedLines:
    """Liang–Barsky on a batch of clip-space segments (a compiled kernel); same results as ``clip_line``.

    Parameters
    ----------
    p0s, p1s : (N, 4) array_like
        First and second ends of each segment.
    planes : (K, 4) array_like, optional
        Extra clip-space planes, at most $MAX_KERNEL_PLANES − 6$.

    Returns
    -------
    ClippedLines
        ``starts``, ``ends`` (N, 4), ``parameters`` (N, 2), ``keep`` (N,) bool.

    Raises
    ------
    ClippingError
        If the shapes differ or are not (N, 4), a coordinate is not finite, or a plane is bad.

    References
    ----------
    [HB 10] "Three-Dimensional Point and Line Clipping"; [seed] "3D Point and Line Clipping".
    """
    starts = as_homogeneous_points(p0s, "p0s", where="clip_lines", error=ClippingError)
    ends = as_homogeneous_points(p1s, "p1s", where="clip_lines", error=ClippingError)
    if starts.shape != ends.shape:
        raise ClippingError(
            f"clip_lines: p0s has {starts.shape[0]} rows and p1s has {ends.shape[0]}; "
            "expected one second end per first end"
        )
    all_planes = _kernel_planes(planes, "clip_lines")
    clipped_starts, clipped_ends = np.empty_like(starts), np.empty_like(ends)
    parameters = np.empty((starts.shape[0], 2))
    _kernels().clip_segments(starts, ends, all_planes, clipped_starts, clipped_ends, parameters)
    return ClippedLines(clipped_starts, clipped_ends, parameters, parameters[:, 0] <= parameters[:, 1])


def clip_line_convex(p0: ArrayLike, p1: ArrayLike, planes: ArrayLike) -> ClippedSegment | None:
    """Cyrus–Beck: the part of segment p0 → p1 inside the convex region bounded by `planes` (no cube), or None.

    With inward normals N_k: $N·P(t) >= 0$ for $P(t) = P1 + D·t$, $D = P2 − P1$. Where $N·D > 0$ the
    segment enters at $t = −N·P1 / N·D$ (raise t_lower), where $N·D < 0$ it leaves (lower t_upper), where
    $N·D = 0$ it is parallel and is rejected if $N·P1 < 0$. Visible iff $t_lower <= t_upper$.

    Parameters
    ----------
    p0, p1 : (3,) or (4,) array_like
        Both Cartesian ``(x, y, z)`` (taken with w = 1, e.g. world space for a cutaway box) or both
        homogeneous ``(x, y, z, w)`` (clip space). The result has the same width.
    planes : (K, 4) or (4,) array_like
        ``(a, b, c, d)``, inside $a·x + b·y + c·z + d·w >= 0$: the region is their intersection.

    Raises
    ------
    ClippingError
        If the points have different or wrong widths, are not finite, or a plane is degenerate: zero normal
        ``(a, b, c)`` for Cartesian points, the zero 4-vector for homogeneous ones.

    References
    ----------
    [HB 10] "Three-Dimensional Point and Line Clipping" (Cyrus–Beck, extended to 3D); [seed] "3D Point and
    Line Clipping".
    """
    start = _single_point(p0, "p0", "clip_line_convex", (3, 4))
    end = _single_point(p1, "p1", "clip_line_convex", (3, 4))
    if start.shape != end.shape:
        raise ClippingError(
            f"clip_line_convex: p0 = {describe(start)} and p1 = {describe(end)} have different widths; both "
            "(3,) Cartesian or both (4,) homogeneous points"
        )
    cartesian = start.shape[0] == 3
    region = _as_planes(planes, "planes", "clip_line_convex", cartesian=cartesian)
    if cartesian:
        start, end = np.append(start, 1.0), np.append(end, 1.0)
    clipped = _cyrus_beck(start, end, region)
    if clipped is None or not cartesian:
        return clipped
    return clipped._replace(start=clipped.start[:3], end=clipped.end[:3])


def _cohen_sutherland(
    start: NDArray, end: NDArray, planes: NDArray, record: Recorder | None = None
) -> ClippedSegment | None:
    ends = [start.copy(), end.copy()]
    u = [0.0, 1.0]
    done = [0, 0]  # planes an end was already moved onto: on it up to round-off, so inside from then on
    codes = [_plane_code(ends[0], planes), _plane_code(ends[1], planes)]
    while True:
        if record is not None:
            record("codes", ends=(ends[0].copy(), ends[1].copy()), codes=tuple(codes), u=tuple(u))
        if codes[0] | codes[1] == 0:  # trivial accept
            if record is not None:
                record("accept", codes=tuple(codes))
            return ClippedSegment(ends[0], ends[1], float(u[0]), float(u[1]))
        if codes[0] & codes[1]:  # trivial reject: both ends outside one plane
            if record is not None:
                record("reject", codes=tuple(codes), common=codes[0] & codes[1])
            return None
        i = 0 if codes[0] else 1  # an end outside some plane
        k = (codes[i] & -codes[i]).bit_length() - 1  # its lowest-order set bit
        d_out, d_in = planes[k] @ ends[i], planes[k] @ ends[1 - i]
        if d_out == d_in:  # parallel to the plane and outside it
            if record is not None:
                record("parallel", end=i, plane=k)
            return None
        t = d_out / (d_out - d_in)
        ends[i] = ends[i] + (ends[1 - i] - ends[i]) * t
        u[i] = u[i] + (u[1 - i] - u[i]) * t
        done[i] |= 1 << k
        codes[i] = _plane_code(ends[i], planes) & ~done[i]
        if record is not None:
            record("intersect", end=i, plane=k, d_out=float(d_out), d_in=float(d_in), t=float(t),
                   point=ends[i].copy(), u=float(u[i]))  # fmt: skip


def _liang_barsky(start: NDArray, end: NDArray, planes: NDArray, record: Recorder) -> tuple[float, float]:
    """The Python twin of the kernel ``raster.clip.clip_segment`` (same operations, same order; a test holds
    them equal bit for bit), calling ``record`` for each plane's ``p_k``, ``q_k`` and the narrowed ``[u0, u1]``."""
    u0, u1 = 0.0, 1.0
    for k in range(planes.shape[0]):
        plane = planes[k]
        q = plane[0] * start[0] + plane[1] * start[1] + plane[2] * start[2] + plane[3] * start[3]
        p = q - (plane[0] * end[0] + plane[1] * end[1] + plane[2] * end[2] + plane[3] * end[3])
        if p == 0.0:
            if q < 0.0:
                record("plane", plane=k, p=float(p), q=float(q), u0=u0, u1=u1, case="parallel, outside")
                record("reject", plane=k)
                return 1.0, 0.0
            case = "parallel, inside"
        elif p < 0.0:
            u0 = max(u0, q / p)
            case = "entering"
        else:
            u1 = min(u1, q / p)
            case = "leaving"
        record("plane", plane=k, p=float(p), q=float(q), u0=float(u0), u1=float(u1), case=case)
        if u0 > u1:
            record("reject", plane=k)
            return 1.0, 0.0
    record("accept", u0=float(u0), u1=float(u1))
    return u0, u1


def _cyrus_beck(start: NDArray, end: NDArray, planes: NDArray) -> ClippedSegment | None:
    direction = end - start
    numerator = planes @ start  # N·P1, >= 0 inside
    denominator = planes @ direction  # N·D
    parallel = denominator == 0
    if np.any(parallel & (numerator < 0)):
        return None
    t = -numerator[~parallel] / denominator[~parallel]
    entering = denominator[~parallel] > 0
    t_lower = max(0.0, float(t[entering].max(initial=0.0)))
    t_upper = min(1.0, float(t[~entering].min(initial=1.0)))
    if t_lower > t_upper:
        return None
    return _segment(start, end, t_lower, t_upper)


def _segment(start: NDArray, end: NDArray, u0: float, u1: float) -> ClippedSegment | None:
    if u0 > u1:
        return None
    direction = end - start
    first = start.copy() if u0 == 0.0 else start + direction * u0
    second = end.copy() if u1 == 1.0 else start + direction * u1
    return ClippedSegment(first, second, float(u0), float(u1))


def _plane_code(point: NDArray, planes: NDArray) -> int:
    return sum(1 << int(k) for k in np.flatnonzero(planes @ point < 0))


# --- polygon clipping -------------------------------------------------------------------------------------


class ClippedPolygon(NamedTuple):
    """Result of ``clip_polygon``."""

    vertices: Points
    """(K, 4) float64 clip-space vertices of the clipped polygon, in the input's order; (0, 4) if invisible."""
    attributes: NDArray[np.float64] | None
    """(K, C) (or (K,)) float64 attributes interpolated with the vertices, or None if none were given."""


def clip_polygon(
    vertices_h: ArrayLike,
    attributes: ArrayLike | None = None,
    planes: ArrayLike | None = None,
    *,
    record: Recorder | None = None,
) -> ClippedPolygon:
    """Sutherland–Hodgman: the polygon cut by the cube's six planes (and any user planes), in clip space.

    Plane after plane, each edge S → E of the current polygon gives: E inside and S outside → the
    intersection then E; both inside → E; S inside and E outside → the intersection; both outside → nothing.
    The intersection is $P = P_in + (P_out − P_in)u$ with $u = d_in / (d_in − d_out)$, computed from the
    inside end; attributes interpolate with the same u, i.e. linearly in clip space (the perspective-correct
    choice: they are then divided by w with the position). A convex polygon stays convex; a concave one may
    come back with zero-width connecting edges along a plane (the algorithm's known trait; its area is right).

    Parameters
    ----------
    vertices_h : (N, 4) array_like
        Clip-space vertices in order, N >= 3 (or 0).
    attributes : (N, C) or (N,) array_like, optional
        Per-vertex values to interpolate (colors, normals, uv, ...).
    planes : (K, 4) or (4,) array_like, optional
        Extra clip-space planes, applied after the cube's six.
    record : callable, optional
        Called as ``record(event, **values)``: the polygon after each plane (``frustum.steps``).

    Returns
    -------
    ClippedPolygon
        ``vertices`` (M, 4) and ``attributes`` (M, C) or None. A polygon wholly inside comes back unchanged;
        one that keeps fewer than 3 vertices (it touches the volume at a point or an edge), or whose every
        vertex has w <= 0 (it collapsed onto the clip-space origin, e.g. a triangle lying in the eye plane),
        comes back empty.

    Raises
    ------
    ClippingError
        If shapes are wrong (including attributes with a different row count), or a value is not finite.

    References
    ----------
    [HB 10] "Three-Dimensional Polygon Clipping", "Clipping in Three-Dimensional Homogeneous Coordinates";
    [seed] "3D Polygon clipping".
    """
    vertices = as_homogeneous_points(vertices_h, "vertices_h", where="clip_polygon", error=ClippingError)
    if 0 < vertices.shape[0] < 3:
        raise ClippingError(
            f"clip_polygon: vertices_h has {vertices.shape[0]} rows; a polygon needs at least 3 vertices"
        )
    values = _with_attributes(vertices, attributes)
    if record is not None:
        record("start", polygon=values[:, :4].copy())
    for k, plane in enumerate(_with_view_volume(planes, "clip_polygon")):
        if values.shape[0] == 0:
            break
        before = values
        values = _clip_against_plane(values, plane)
        if record is not None:
            record("plane", plane=k, distances=before[:, :4] @ plane, before=before[:, :4].copy(),
                   polygon=values[:, :4].copy())  # fmt: skip
    # touching a plane at a point or along an edge leaves no area; and a polygon with no vertex of w > 0 is
    # collapsed onto the clip-space origin (0, 0, 0, 0), the one code-0 point that is no visible position
    if values.shape[0] < 3 or not (values[:, 3] > 0).any():
        values = values[:0]
    if attributes is None:
        return ClippedPolygon(values[:, :4], None)
    clipped_attributes = values[:, 4:].reshape((values.shape[0], *np.shape(attributes)[1:]))
    return ClippedPolygon(values[:, :4], clipped_attributes)


def _clip_against_plane(values: NDArray, plane: NDArray) -> NDArray:
    distances = values[:, :4] @ plane
    out: list[NDArray] = []
    s = values.shape[0] - 1
    for e in range(values.shape[0]):
        d_s, d_e = distances[s], distances[e]
        if d_e >= 0:
            if d_s < 0 and d_e > 0:  # entering: intersection, computed from the inside end E
                out.append(values[e] + (values[s] - values[e]) * (d_e / (d_e - d_s)))
            out.append(values[e])
        elif d_s > 0:  # leaving: intersection, computed from the inside end S
            out.append(values[s] + (values[e] - values[s]) * (d_s / (d_s - d_e)))
        s = e
    return np.array(out).reshape(-1, values.shape[1])


def _with_attributes(vertices: NDArray, attributes: ArrayLike | None) -> NDArray:
    """Positions and attributes side by side, (N, 4 + C): one interpolation moves both."""
    if attributes is None:
        return vertices
    try:
        array = np.asarray(attributes, dtype=np.float64)
    except (TypeError, ValueError):
        raise ClippingError(
            f"clip_polygon: attributes = {describe(attributes)} is not numeric; expected (N, C) numbers"
        ) from None
    if array.ndim not in (1, 2) or array.shape[0] != vertices.shape[0]:
        raise ClippingError(
            f"clip_polygon: attributes has shape {array.shape}; expected ({vertices.shape[0]}, C) or "
            f"({vertices.shape[0]},), one row per vertex"
        )
    bad = np.flatnonzero(~np.isfinite(array.reshape(array.shape[0], -1)).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise ClippingError(
            f"clip_polygon: attributes[{i}] = {describe(array[i])} is not finite; attributes must be finite"
        )
    return np.hstack([vertices, array.reshape(array.shape[0], -1)])


# --- triangle batches -------------------------------------------------------------------------------------


class ClippedTriangles(NamedTuple):
    """Result of ``clip_triangles``: an indexed triangle mesh in clip space, with where every piece came from.

    ``vertices`` starts with the V input vertices, unchanged and in order, followed by the K new vertices
    that clipping made. Triangles wholly inside keep their input indices; clipped ones are fanned out of
    their polygon, reusing the input index of every corner that survived.
    """

    vertices: Points
    """(V + K, 4) float64: the input vertices, then the new ones."""
    faces: NDArray[np.int64]
    """(F, 3) int64 output triangles, in input order (a clipped triangle's fan where the triangle was), same
    winding as their source."""
    face_sources: NDArray[np.int64]
    """(F,) int64: the input triangle each output triangle comes from (for per-face data)."""
    new_vertex_sources: NDArray[np.int64]
    """(K,) int64: the input triangle each new vertex ``vertices[V + k]`` lies in."""
    new_vertex_weights: NDArray[np.float64]
    """(K, 3) float64 barycentric weights of each new vertex w.r.t. its source triangle's corners (clip space:
    ``vertices[V + k] = Σ_j weights[k, j]·vertices[faces_in[source, j]]`` up to round-off)."""

    def interpolate(self, faces: ArrayLike, attributes: ArrayLike) -> NDArray[np.float64]:
        """Per-vertex `attributes` (V, ...) of the input mesh extended to all V + K output vertices.

        `faces` are the input faces given to ``clip_triangles``. New vertices get $Σ_j w_j·attribute_j$
        over their source triangle's corners (linear in clip space).
        """
        values = np.asarray(attributes, dtype=np.float64)
        corners = np.asarray(faces)[self.new_vertex_sources]  # (K, 3) input vertex indices
        new_values = np.einsum("kj,kj...->k...", self.new_vertex_weights, values[corners])
        return np.concatenate([values, new_values])


def clip_triangles(vertices_h: ArrayLike, faces: ArrayLike, planes: ArrayLike | None = None) -> ClippedTriangles:
    """Clip a triangle mesh in clip space against the cube (and any user planes): the renderer's batch clipper.

    Region codes per vertex give each triangle a trivial accept (``c0 | c1 | c2 == 0``: kept untouched, same
    indices), a trivial reject (``c0 & c1 & c2 != 0``: dropped at the cost of two integer operations) or a
    clip: Sutherland–Hodgman on that triangle (``raster.clip.clip_triangle``, a kernel other kernels call),
    whose convex polygon is fanned into triangles ``(0, i, i + 1)``. Polygons that degenerate to fewer than
    three vertices (a triangle touching a plane at a point or an edge) are dropped.

    Parameters
    ----------
    vertices_h : (V, 4) array_like
        Clip-space vertices, e.g. ``apply_homogeneous(clip_from_world, points_world)``.
    faces : (M, 3) array_like of int
        Vertex indices of each triangle.
    planes : (K, 4) array_like, optional
        Extra clip-space planes (a cutaway: ``transform_plane(clip_from_world, plane_world)``), at most
        $MAX_KERNEL_PLANES − 6$.

    Returns
    -------
    ClippedTriangles
        Output vertices, faces, each face's source triangle, and each new vertex's source triangle and
        barycentric weights (``ClippedTriangles.interpolate`` extends any per-vertex attribute).

    Raises
    ------
    ClippingError
        If a shape or dtype is wrong, a coordinate is not finite, an index is out of range, or a plane is bad.

    References
    ----------
    [HB 10] "Three-Dimensional Polygon Clipping", "Clipping in Three-Dimensional Homogeneous Coordinates";
    [seed] "Three-dimensional Region Codes", "3D Polygon clipping".
    """
    vertices = as_homogeneous_points(vertices_h, "vertices_h", where="clip_triangles", error=ClippingError)
    triangles = as_faces(faces, vertices.shape[0], where="clip_triangles", error=ClippingError)
    all_planes = _kernel_planes(planes, "clip_triangles")
    # trivial accept / reject from the vertices' region codes
    status = np.empty(triangles.shape[0], dtype=np.int8)
    _kernels().classify_triangles(triangles, _kernel_codes(vertices, all_planes), status)
    crossing = np.flatnonzero(status == _kernels().TRIANGLE_CROSSING)
    # Sutherland–Hodgman on the rest
    capacity = 3 + all_planes.shape[0]
    positions = np.empty((crossing.size, capacity, 4))
    weights = np.empty((crossing.size, capacity, 3))
    counts = np.empty(crossing.size, dtype=np.int64)
    _kernels().clip_crossing_triangles(vertices, triangles, crossing, all_planes, positions, weights, counts)
    counts[counts < 3] = 0  # points and slivers have no area
    return _assemble(vertices, triangles, status, crossing, positions, weights, counts)


def _assemble(
    vertices: NDArray, triangles: NDArray, status: NDArray, crossing: NDArray,
    positions: NDArray, weights: NDArray, counts: NDArray,
) -> ClippedTriangles:  # fmt: skip
    capacity = positions.shape[1]
    used = np.arange(capacity) < counts[:, None]  # (C, capacity) polygon slots in use
    # a surviving corner has its exact one-hot weights: reuse the input vertex index
    corner = used & (weights == 1.0).any(axis=2) & ((weights == 0.0).sum(axis=2) == 2)
    new = used & ~corner
    index = np.zeros((crossing.size, capacity), dtype=np.int64)
    corner_rows, corner_slots = np.nonzero(corner)
    index[corner_rows, corner_slots] = triangles[
        crossing[corner_rows], np.argmax(weights[corner_rows, corner_slots], axis=1)
    ]
    new_rows, new_slots = np.nonzero(new)
    index[new_rows, new_slots] = vertices.shape[0] + np.arange(new_rows.size)
    # fan (0, i, i + 1) of each polygon, placed where its source triangle was
    face_count = int(np.count_nonzero(status == _kernels().TRIANGLE_INSIDE) + np.maximum(counts - 2, 0).sum())
    out_faces = np.empty((face_count, 3), dtype=np.int64)
    face_sources = np.empty(face_count, dtype=np.int64)
    _kernels().assemble_faces(triangles, status, index, counts, out_faces, face_sources)
    return ClippedTriangles(
        vertices=np.concatenate([vertices, positions[new_rows, new_slots]]),
        faces=out_faces,
        face_sources=face_sources,
        new_vertex_sources=crossing[new_rows],
        new_vertex_weights=weights[new_rows, new_slots],
    )


# --- validation helpers -----------------------------------------------------------------------------------


def _kernel_codes(points: NDArray, planes: NDArray) -> NDArray[np.int64]:
    codes = np.empty(points.shape[0], dtype=np.int64)
    _kernels().region_codes(points, planes, codes)
    return codes


def _single_point(value: ArrayLike, name: str, where: str, widths: tuple[int, ...]) -> NDArray[np.float64]:
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


def _point4(value: ArrayLike, name: str, where: str) -> NDArray[np.float64]:
    try:
        shape = np.shape(value)
    except ValueError:
        shape = None
    if shape != (4,):
        raise ClippingError(
            f"{where}: {name} = {describe(value)} has shape {shape}; expected a (4,) homogeneous point (x, y, z, w)"
        )
    return as_homogeneous_points([value], name, where=where, error=ClippingError)[0]


def _as_planes(value: ArrayLike, name: str, where: str, cartesian: bool = False) -> NDArray[np.float64]:
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


def _with_view_volume(planes: ArrayLike | None, where: str) -> NDArray[np.float64]:
    if planes is None:
        return np.array(VIEW_VOLUME_PLANES)
    return np.concatenate([VIEW_VOLUME_PLANES, _as_planes(planes, "planes", where)])


def _kernel_planes(planes: ArrayLike | None, where: str) -> NDArray[np.float64]:
    all_planes = _with_view_volume(planes, where)
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
