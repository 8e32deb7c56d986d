"""Line clipping in homogeneous coordinates: Cohen–Sutherland, Liang–Barsky and Cyrus–Beck, one segment or many."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_homogeneous_points, describe
from frustum.clipping.codes import (
    Recorder,
    as_planes,
    clip_kernels,
    kernel_planes,
    plane_code,
    point4,
    single_point,
    with_view_volume,
)
from frustum.errors import ClippingError

__all__ = ["ClippedLines", "ClippedSegment", "clip_line", "clip_line_convex", "clip_lines"]


_METHODS = ("liang-barsky", "cohen-sutherland", "cyrus-beck")


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
    start = point4(p0, "p0", "clip_line")
    end = point4(p1, "p1", "clip_line")
    if method not in _METHODS:
        raise ClippingError(f"clip_line: method = {method!r} is unknown; expected one of {', '.join(_METHODS)}")
    all_planes = with_view_volume(planes, "clip_line")
    if method == "cohen-sutherland":
        return _cohen_sutherland(start, end, all_planes, record)
    if method == "cyrus-beck":
        return _cyrus_beck(start, end, all_planes)
    if record is not None:
        u0, u1 = _liang_barsky(start, end, all_planes, record)
    else:
        u0, u1 = clip_kernels().clip_segment(start, end, all_planes)
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
    all_planes = kernel_planes(planes, "clip_lines")
    clipped_starts, clipped_ends = np.empty_like(starts), np.empty_like(ends)
    parameters = np.empty((starts.shape[0], 2))
    clip_kernels().clip_segments(starts, ends, all_planes, clipped_starts, clipped_ends, parameters)
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
    start = single_point(p0, "p0", "clip_line_convex", (3, 4))
    end = single_point(p1, "p1", "clip_line_convex", (3, 4))
    if start.shape != end.shape:
        raise ClippingError(
            f"clip_line_convex: p0 = {describe(start)} and p1 = {describe(end)} have different widths; both "
            "(3,) Cartesian or both (4,) homogeneous points"
        )
    cartesian = start.shape[0] == 3
    region = as_planes(planes, "planes", "clip_line_convex", cartesian=cartesian)
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
    codes = [plane_code(ends[0], planes), plane_code(ends[1], planes)]
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
        codes[i] = plane_code(ends[i], planes) & ~done[i]
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
