"""Scan-line visible-surface kernel: edge table, active list sorted by x, span coherence, incremental edges.

Per window row j (pixel centres $Y = 256·j + 128$), triangles enter the active list from the edge table (the
triangles bucketed by their first row) and leave after their last row. Each active triangle's three edges give
the row constants $C_k(j) = dx_k·(Y − Y_a) − dy_k·(128 − X_a)$ (which grow by $256·dx_k$ per row: the
textbook's ``x += 1/m`` edge update, exact in integers): its span on the row is the exact top-left-rule interval
$E_k = C_k − 256·dy_k·i >= bias_k$ — a left edge (dy < 0) bounds i from below, a right edge (dy > 0) from above.
The list is kept sorted by span start by insertion sort (coherence: the order hardly changes from row to row),
and a second list by span end; merging them walks the row left to right through spans in which the set of
covering triangles is constant:

* none: background (nothing written);
* one: the triangle fills the span without a depth test;
* several: depth is affine along the span for each plane, so a triangle nearest at both ends is nearest
  throughout and fills it (two depth tests per triangle); otherwise (surfaces cutting through each other
  inside the span) the nearest is found per pixel.

Depth and barycentrics are stepped along the span with the edge functions ($E_k −= 256·dy_k$ per pixel) and
written with the depth buffer's formulas (``window.pixel_values``). Ties on float32 depth go to the triangle
drawn first, as in the depth buffer's test "less".

Counts per row (``stats[j]``): spans drawn, edge updates (non-horizontal edges of active triangles whose
y range holds the row), depth tests, spans resolved per pixel.

Recording mode (``frustum.steps``): ``active_log`` (H, capacity, 3) gets each row's active list in span order
(triangle, span start, span end), ``span_log`` (H, 2·capacity + 1, 4) its spans (first pixel, end, the
triangle that filled it or −1 where it was resolved pixel by pixel, the number of surfaces in); unused entries
keep the caller's fill. With a first dimension of 0 nothing is written.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL
from frustum.raster.window import edge_setup, pixel_values, plane_depth

__all__ = ["STATS", "scan_lines"]

STATS = ("spans", "edge_updates", "depth_tests", "split_spans")


@kernel
def _row_range(ya: int, yb: int) -> tuple[int, int]:
    """First and last row whose pixel centre lies in the closed y range of an edge."""
    low, high = min(ya, yb), max(ya, yb)
    first = -((HALF_SUBPIXEL - low) // SUBPIXEL)
    last = (high - HALF_SUBPIXEL) // SUBPIXEL
    return first, last


@kernel
def _nearest(
    xy: np.ndarray, zq: np.ndarray, current: np.ndarray, count: int, i: int, py: int
) -> int:  # fmt: skip
    """The triangle of ``current[:count]`` nearest at pixel column i (float32 depth; ties: the lowest index)."""
    best, best_z = -1, np.float32(2.0)
    px = SUBPIXEL * i + HALF_SUBPIXEL
    for n in range(count):
        t = current[n]
        z = np.float32(plane_depth(xy, zq, t, px, py))
        if z < best_z or (z == best_z and t < best):
            best, best_z = t, z
    return best


@kernel
def _fill(
    xy: np.ndarray, zq: np.ndarray, weights: np.ndarray, code: np.ndarray, t: int, j: int, i0: int, i1: int,
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
) -> None:  # fmt: skip
    """Triangle t on row j over columns [i0, i1): edge functions stepped per pixel, the depth buffer's values."""
    dx0, dy0, dx1, dy1, dx2, dy2, _bias0, _bias1, _bias2, _area = edge_setup(xy, t)
    x0, y0, x1, y1, x2, y2 = xy[t, 0], xy[t, 1], xy[t, 2], xy[t, 3], xy[t, 4], xy[t, 5]
    py = SUBPIXEL * j + HALF_SUBPIXEL
    px = SUBPIXEL * i0 + HALF_SUBPIXEL
    e0 = dx0 * (py - y1) - dy0 * (px - x1)
    e1 = dx1 * (py - y2) - dy1 * (px - x2)
    e2 = dx2 * (py - y0) - dy2 * (px - x0)
    row = depth.shape[0] - 1 - j
    c = code[t]
    for i in range(i0, i1):
        z, u1, u2 = pixel_values(xy, zq, weights, t, e0, e1, e2, px, py)
        if z < 1.0:
            depth[row, i] = z
            codes[row, i] = c
            bary[row, i, 0], bary[row, i, 1] = u1, u2
        e0 -= dy0 * SUBPIXEL
        e1 -= dy1 * SUBPIXEL
        e2 -= dy2 * SUBPIXEL
        px += SUBPIXEL


@parallel_kernel(lambda xy, zq, weights, code, box, order, bucket, capacity, depth, *_: depth.shape[0])
def scan_lines(
    xy: np.ndarray, zq: np.ndarray, weights: np.ndarray, code: np.ndarray, box: np.ndarray, order: np.ndarray,
    bucket: np.ndarray, capacity: int, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, stats: np.ndarray,
    active_log: np.ndarray, span_log: np.ndarray, start: int, stop: int,
) -> None:  # fmt: skip
    """Rows [start, stop) of the image (window row j is array row H − 1 − j).

    order (T,) int64: triangles sorted by first row (stable), the edge table; bucket (H + 1,) int64: the
    triangles whose first row is j are ``order[bucket[j]:bucket[j + 1]]``; capacity: the most triangles active
    on one row. depth, codes, bary: the buffers (depth cleared to 1); stats (H, 4) int64, written per row;
    active_log, span_log: the recording mode's logs (module docstring), (0, …) when off.
    """
    recording = active_log.shape[0] > 0
    width = depth.shape[1]
    active = np.empty(capacity, dtype=np.int64)  # triangle indices, sorted by span start
    by_end = np.empty(capacity, dtype=np.int64)  # slots sorted by span end
    low = np.empty(capacity, dtype=np.int64)
    high = np.empty(capacity, dtype=np.int64)
    current = np.empty(capacity, dtype=np.int64)
    count = 0
    # the active list at the first row of the band: every triangle begun before it and not yet ended
    for n in range(0, bucket[start]):
        t = order[n]
        if box[t, 3] >= start:
            active[count] = t
            count += 1
    for j in range(start, stop):
        py = SUBPIXEL * j + HALF_SUBPIXEL
        # drop the triangles that ended on the row below, then add those that begin on this one
        kept = 0
        updates = 0
        for n in range(count):
            t = active[n]
            if box[t, 3] < j:
                continue
            active[kept] = t
            kept += 1
        count = kept
        for n in range(bucket[j], bucket[j + 1]):
            active[count] = order[n]
            count += 1
        for n in range(count):
            t = active[n]
            _dx0, _dy0, _dx1, _dy1, _dx2, _dy2, _bias0, _bias1, _bias2, _area = edge_setup(xy, t)
            lo, hi = 0, width - 1
            for k in range(3):
                a = (k + 1) % 3  # edge k runs from corner k + 1 to corner k + 2
                b = (k + 2) % 3
                dx = xy[t, 2 * b] - xy[t, 2 * a]
                dy = xy[t, 2 * b + 1] - xy[t, 2 * a + 1]
                bias = 0 if (dy < 0 or (dy == 0 and dx < 0)) else 1
                constant = dx * (py - xy[t, 2 * a + 1]) - dy * (HALF_SUBPIXEL - xy[t, 2 * a])
                first, last = _row_range(xy[t, 2 * a + 1], xy[t, 2 * b + 1])
                if dy != 0 and first <= j <= last:
                    updates += 1
                if dy < 0:
                    lo = max(lo, -((constant - bias) // (-SUBPIXEL * dy)))  # ceil((bias − C) / (256·(−dy)))
                elif dy > 0:
                    hi = min(hi, (constant - bias) // (SUBPIXEL * dy))
                elif constant < bias:
                    lo, hi = 1, 0
            low[n], high[n] = lo, hi
        # keep the list sorted by span start (insertion sort: nearly sorted from the previous row)
        for n in range(1, count):
            t, lo, hi = active[n], low[n], high[n]
            m = n - 1
            while m >= 0 and low[m] > lo:
                active[m + 1], low[m + 1], high[m + 1] = active[m], low[m], high[m]
                m -= 1
            active[m + 1], low[m + 1], high[m + 1] = t, lo, hi
        if recording:
            for n in range(count):
                active_log[j, n, 0], active_log[j, n, 1], active_log[j, n, 2] = active[n], low[n], high[n]
        for n in range(count):
            by_end[n] = n
        for n in range(1, count):
            s = by_end[n]
            m = n - 1
            while m >= 0 and high[by_end[m]] > high[s]:
                by_end[m + 1] = by_end[m]
                m -= 1
            by_end[m + 1] = s
        # walk the row: merge span starts and span ends (end event at hi + 1)
        spans = 0
        tests = 0
        split = 0
        inside = 0
        next_start, next_end = 0, 0
        while next_start < count and low[next_start] > high[next_start]:
            next_start += 1
        x = 0
        while True:
            while next_end < count and low[by_end[next_end]] > high[by_end[next_end]]:
                next_end += 1
            start_x = low[next_start] if next_start < count else width
            end_x = high[by_end[next_end]] + 1 if next_end < count else width
            event = min(start_x, end_x)
            if inside > 0 and event > x:
                spans += 1
                if recording:
                    span_log[j, spans - 1, 0], span_log[j, spans - 1, 1] = x, event
                    span_log[j, spans - 1, 2], span_log[j, spans - 1, 3] = -1, inside
                if inside == 1:
                    _fill(xy, zq, weights, code, current[0], j, x, event, depth, codes, bary)
                    if recording:
                        span_log[j, spans - 1, 2] = current[0]
                else:
                    left = _nearest(xy, zq, current, inside, x, py)
                    right = _nearest(xy, zq, current, inside, event - 1, py)
                    tests += 2 * inside
                    if left == right:
                        _fill(xy, zq, weights, code, left, j, x, event, depth, codes, bary)
                        if recording:
                            span_log[j, spans - 1, 2] = left
                    else:
                        split += 1
                        for i in range(x, event):
                            tests += inside
                            t = _nearest(xy, zq, current, inside, i, py)
                            _fill(xy, zq, weights, code, t, j, i, i + 1, depth, codes, bary)
            if event >= width:
                break
            x = event
            if end_x <= start_x:  # a span ends: its triangle leaves the set
                t = active[by_end[next_end]]
                next_end += 1
                for m in range(inside):
                    if current[m] == t:
                        current[m] = current[inside - 1]
                        inside -= 1
                        break
            else:
                current[inside] = active[next_start]
                inside += 1
                next_start += 1
                while next_start < count and low[next_start] > high[next_start]:
                    next_start += 1
        stats[j, 0], stats[j, 1], stats[j, 2], stats[j, 3] = spans, updates, tests, split
