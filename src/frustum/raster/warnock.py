"""Area-subdivision (Warnock) visible-surface kernel: an explicit stack of areas, quartered down to a pixel.

An area is a rectangle of pixels $[i0, i1) × [j0, j1)$ (window rows); its sample points are the pixel centres.
Each triangle of the parent's list is classified against it by its edge functions at the area's four corner
centres (an edge function is affine, so the corners bound it over the whole area):

* **outside**: its pixel box misses the area, or one edge fails at all four corners (dropped from the list);
* **surrounding**: all three edges hold at all four corners, so every pixel centre of the area is inside;
* **inside**: its pixel box lies within the area;
* **overlapping**: anything else.

The area is finished when (1) no triangle is left (background); (2) a surrounding triangle is nearer at its
farthest corner than every other triangle at its nearest possible point (its plane's least depth over the area's
corners, or its nearest vertex) — "the surrounding surface hides all others", which covers the case of a single
surrounding triangle — and fills the area; (3) a single inside or overlapping triangle is left, drawn into the
area; (4) the area is one pixel: the nearest of the triangles covering its centre (float32 depth, ties to the
triangle drawn first). Otherwise it is quartered and the quarters pushed.

Each area's list is written above its parent's in one array (``lists``); popping an area frees the lists of the
finished siblings above its parent's (depth-first order). Counts: ``stats[level]`` areas visited per level (the
root is level 0); after ``LEVELS`` entries the exits (empty, hidden by a surrounding surface, single surface,
pixel), the relations met (outside, surrounding, inside, overlapping) and the depth tests.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL
from frustum.raster.window import edge_setup, pixel_values, plane_depth

__all__ = ["DECISIONS", "LEVELS", "LOG_COLUMNS", "STATS", "subdivide"]

LEVELS = 32
STATS = (
    "exit_empty", "exit_surrounding", "exit_single", "exit_pixel",
    "outside", "surrounding", "inside", "overlapping", "depth_tests",
)  # fmt: skip
OUTSIDE, SURROUNDING, INSIDE, OVERLAPPING = 0, 1, 2, 3
DECISIONS = ("empty", "surrounding", "single", "pixel", "subdivided")
"""What finished an area (the log's ``decision`` column): exits 0–3 as in ``STATS``, or 4, quartered."""
LOG_COLUMNS = ("i0", "j0", "i1", "j1", "level", "decision", "surfaces", "triangle", "relation")
"""The recording mode's log: one row per area visited, in visiting order (``triangle`` the one drawn or −1;
``relation`` that triangle's relation to the area, or −1)."""


@kernel
def _relation(xy: np.ndarray, box: np.ndarray, t: int, i0: int, j0: int, i1: int, j1: int) -> int:
    """Relation of triangle t to the area [i0, i1) × [j0, j1)."""
    if box[t, 1] < i0 or box[t, 0] >= i1 or box[t, 3] < j0 or box[t, 2] >= j1:
        return OUTSIDE
    _dx0, _dy0, _dx1, _dy1, _dx2, _dy2, bias0, bias1, bias2, _area = edge_setup(xy, t)
    xa, xb = SUBPIXEL * i0 + HALF_SUBPIXEL, SUBPIXEL * (i1 - 1) + HALF_SUBPIXEL
    ya, yb = SUBPIXEL * j0 + HALF_SUBPIXEL, SUBPIXEL * (j1 - 1) + HALF_SUBPIXEL
    every = True
    for k in range(3):
        a = (k + 1) % 3
        dx = xy[t, 2 * ((k + 2) % 3)] - xy[t, 2 * a]
        dy = xy[t, 2 * ((k + 2) % 3) + 1] - xy[t, 2 * a + 1]
        bias = bias0 if k == 0 else (bias1 if k == 1 else bias2)
        x0, y0 = xy[t, 2 * a], xy[t, 2 * a + 1]
        e00 = dx * (ya - y0) - dy * (xa - x0)
        e10 = dx * (ya - y0) - dy * (xb - x0)
        e01 = dx * (yb - y0) - dy * (xa - x0)
        e11 = dx * (yb - y0) - dy * (xb - x0)
        if max(max(e00, e10), max(e01, e11)) < bias:
            return OUTSIDE
        if min(min(e00, e10), min(e01, e11)) < bias:
            every = False
    if every:
        return SURROUNDING
    if box[t, 0] >= i0 and box[t, 1] < i1 and box[t, 2] >= j0 and box[t, 3] < j1:
        return INSIDE
    return OVERLAPPING


@kernel
def _plane_range(xy: np.ndarray, zq: np.ndarray, t: int, i0: int, j0: int, i1: int, j1: int) -> tuple[float, float]:
    """Least and greatest depth of triangle t's plane over the corner pixel centres of the area."""
    low, high = np.inf, -np.inf
    for corner in range(4):
        px = SUBPIXEL * (i0 if corner % 2 == 0 else i1 - 1) + HALF_SUBPIXEL
        py = SUBPIXEL * (j0 if corner < 2 else j1 - 1) + HALF_SUBPIXEL
        z = plane_depth(xy, zq, t, px, py)
        low, high = min(low, z), max(high, z)
    return low, high


@kernel
def _draw(
    xy: np.ndarray, zq: np.ndarray, weights: np.ndarray, code: np.ndarray, t: int, i0: int, j0: int, i1: int,
    j1: int, test: bool, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
) -> None:  # fmt: skip
    """Triangle t into the area (only where it covers the pixel centre when `test`), the depth buffer's values."""
    dx0, dy0, dx1, dy1, dx2, dy2, bias0, bias1, bias2, _area = edge_setup(xy, t)
    height = depth.shape[0]
    c = code[t]
    for j in range(j0, j1):
        py = SUBPIXEL * j + HALF_SUBPIXEL
        px = SUBPIXEL * i0 + HALF_SUBPIXEL
        e0 = dx0 * (py - xy[t, 3]) - dy0 * (px - xy[t, 2])
        e1 = dx1 * (py - xy[t, 5]) - dy1 * (px - xy[t, 4])
        e2 = dx2 * (py - xy[t, 1]) - dy2 * (px - xy[t, 0])
        for i in range(i0, i1):
            if not test or (e0 >= bias0 and e1 >= bias1 and e2 >= bias2):
                z, u1, u2 = pixel_values(xy, zq, weights, t, e0, e1, e2, SUBPIXEL * i + HALF_SUBPIXEL, py)
                if z < 1.0:
                    depth[height - 1 - j, i] = z
                    codes[height - 1 - j, i] = c
                    bary[height - 1 - j, i, 0], bary[height - 1 - j, i, 1] = u1, u2
            e0 -= dy0 * SUBPIXEL
            e1 -= dy1 * SUBPIXEL
            e2 -= dy2 * SUBPIXEL


@kernel
def subdivide(
    xy: np.ndarray, zq: np.ndarray, weights: np.ndarray, code: np.ndarray, box: np.ndarray, lists: np.ndarray,
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, stats: np.ndarray, log: np.ndarray,
) -> None:  # fmt: skip
    """Warnock's recursion over the whole image (module docstring). lists: int array of at least
    T·(levels + 2) entries; stats (LEVELS + len(STATS),) int64, added to. Recording mode: `log` (A, 9) int64
    gets one row per area visited (``LOG_COLUMNS``) while rows are left; (0, 9) records nothing."""
    height, width = depth.shape[0], depth.shape[1]
    count = xy.shape[0]
    for t in range(count):
        lists[t] = t
    stack = np.empty((4 * LEVELS + 8, 8), dtype=np.int64)  # i0, j0, i1, j1, level, parent list, length, top
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = 0, 0, width, height
    stack[0, 4], stack[0, 5], stack[0, 6], stack[0, 7] = 0, 0, count, count
    size = 1
    s = LEVELS
    logged = 0
    while size > 0:
        size -= 1
        i0, j0, i1, j1 = stack[size, 0], stack[size, 1], stack[size, 2], stack[size, 3]
        level, parent, length, top = stack[size, 4], stack[size, 5], stack[size, 6], stack[size, 7]
        stats[min(level, LEVELS - 1)] += 1
        n = 0
        best, best_far = -1, np.inf
        last_relation = -1
        if logged < log.shape[0]:
            log[logged, 0], log[logged, 1], log[logged, 2], log[logged, 3], log[logged, 4] = i0, j0, i1, j1, level
            log[logged, 5], log[logged, 6], log[logged, 7], log[logged, 8] = 4, 0, -1, -1
        for m in range(parent, parent + length):
            t = np.int64(lists[m])  # one compiled version of the helpers, whatever the list type
            relation = _relation(xy, box, t, i0, j0, i1, j1)
            stats[s + 4 + relation] += 1
            if relation == OUTSIDE:
                continue
            lists[top + n] = t
            n += 1
            last_relation = relation
            if relation == SURROUNDING:
                near, far = _plane_range(xy, zq, t, i0, j0, i1, j1)
                if far < best_far:
                    best, best_far = t, far
        row = logged
        if logged < log.shape[0]:
            log[row, 6] = n
            logged += 1
        if n == 0:
            stats[s + 0] += 1
            if row < log.shape[0]:
                log[row, 5] = 0
            continue
        if best >= 0:  # does the nearest surrounding surface hide all others?
            hides = True
            for m in range(top, top + n):
                t = np.int64(lists[m])  # one compiled version of the helpers, whatever the list type
                if t == best:
                    continue
                stats[s + 8] += 1
                near, far = _plane_range(xy, zq, t, i0, j0, i1, j1)
                nearest_vertex = min(zq[t, 0, 0], min(zq[t, 1, 0], zq[t, 2, 0]))
                if not best_far < max(near, nearest_vertex):
                    hides = False
                    break
            if hides:
                stats[s + 1] += 1
                if row < log.shape[0]:
                    log[row, 5], log[row, 7], log[row, 8] = 1, best, SURROUNDING
                _draw(xy, zq, weights, code, best, i0, j0, i1, j1, False, depth, codes, bary)
                continue
        if n == 1:
            stats[s + 2] += 1
            if row < log.shape[0]:
                log[row, 5], log[row, 7], log[row, 8] = 2, lists[top], last_relation
            _draw(xy, zq, weights, code, np.int64(lists[top]), i0, j0, i1, j1, True, depth, codes, bary)
            continue
        if i1 - i0 == 1 and j1 - j0 == 1:
            stats[s + 3] += 1
            px, py = SUBPIXEL * i0 + HALF_SUBPIXEL, SUBPIXEL * j0 + HALF_SUBPIXEL
            chosen, chosen_z = -1, np.float32(2.0)
            for m in range(top, top + n):
                t = np.int64(lists[m])  # one compiled version of the helpers, whatever the list type
                dx0, dy0, dx1, dy1, dx2, dy2, bias0, bias1, bias2, _area = edge_setup(xy, t)
                e0 = dx0 * (py - xy[t, 3]) - dy0 * (px - xy[t, 2])
                e1 = dx1 * (py - xy[t, 5]) - dy1 * (px - xy[t, 4])
                e2 = dx2 * (py - xy[t, 1]) - dy2 * (px - xy[t, 0])
                if e0 >= bias0 and e1 >= bias1 and e2 >= bias2:
                    stats[s + 8] += 1
                    z, _u1, _u2 = pixel_values(xy, zq, weights, t, e0, e1, e2, px, py)
                    if z < chosen_z:
                        chosen, chosen_z = t, z
            if row < log.shape[0]:
                log[row, 5], log[row, 7] = 3, chosen
            if chosen >= 0:
                _draw(xy, zq, weights, code, chosen, i0, j0, i1, j1, False, depth, codes, bary)
            continue
        im, jm = (i0 + i1) // 2, (j0 + j1) // 2
        for quarter in range(4):  # pushed in reverse so that the lower-left quarter is visited first
            q = 3 - quarter
            a0, a1 = (i0, im) if q % 2 == 0 else (im, i1)
            b0, b1 = (j0, jm) if q < 2 else (jm, j1)
            if a1 <= a0 or b1 <= b0:
                continue
            stack[size, 0], stack[size, 1], stack[size, 2], stack[size, 3] = a0, b0, a1, b1
            stack[size, 4], stack[size, 5], stack[size, 6], stack[size, 7] = level + 1, top, n, top + n
            size += 1
