"""Kernels of ``hidden_lines.py``: the screen grid of occluding triangles and the hidden intervals of segments.

Kernels only (numpy + numba): imported on first use by the module named above, so ``import frustum`` never
loads Numba.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel


@kernel
def _cell_range(low, high, grid, boxes):  # pragma: no cover - compiled
    """Cell index ranges (column0, row0, column1, row1) of boxes [low, high], clamped to the grid."""
    cell, columns, rows = grid[2], int(grid[3]), int(grid[4])
    for i in range(low.shape[0]):
        boxes[i, 0] = min(max(math.floor((low[i, 0] - grid[0]) / cell), 0), columns - 1)
        boxes[i, 1] = min(max(math.floor((low[i, 1] - grid[1]) / cell), 0), rows - 1)
        boxes[i, 2] = min(max(math.floor((high[i, 0] - grid[0]) / cell), 0), columns - 1)
        boxes[i, 3] = min(max(math.floor((high[i, 1] - grid[1]) / cell), 0), rows - 1)


@kernel
def _count_cells(boxes, columns, counts):  # pragma: no cover - compiled
    """Number of triangles per cell (each triangle counted in every cell of its box)."""
    for i in range(boxes.shape[0]):
        for row in range(boxes[i, 1], boxes[i, 3] + 1):
            for column in range(boxes[i, 0], boxes[i, 2] + 1):
                counts[row * columns + column] += 1


@kernel
def _fill_cells(boxes, columns, cursor, cell_triangles):  # pragma: no cover - compiled
    """Triangle indices per cell, in triangle order (deterministic)."""
    for i in range(boxes.shape[0]):
        for row in range(boxes[i, 1], boxes[i, 3] + 1):
            for column in range(boxes[i, 0], boxes[i, 2] + 1):
                cell = row * columns + column
                cell_triangles[cursor[cell]] = i
                cursor[cell] += 1


@kernel
def _triangle_interval(a, b, tri, depth_tolerance):  # pragma: no cover - compiled
    """(t0, t1) of segment a→b (window x, y, z) hidden by window triangle `tri`; t0 >= t1 when none.

    Liang–Barsky on four linear inequalities in t: three edge functions $σ·E_k(t) >= 0$ (inside the closed
    projected triangle, σ its orientation) and $z_a + t(z_b − z_a) − z_T(t) > 0$ (behind its plane), kept
    only where the depth gap exceeds ε at one of its ends.
    """
    x0, y0, z0 = tri[0, 0], tri[0, 1], tri[0, 2]
    x1, y1, z1 = tri[1, 0], tri[1, 1], tri[1, 2]
    x2, y2, z2 = tri[2, 0], tri[2, 1], tri[2, 2]
    area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    if area == 0.0:
        return 1.0, 0.0
    sigma = 1.0 if area > 0.0 else -1.0
    lo, hi = 0.0, 1.0
    # barycentric numerators at both ends: E_12, E_20, E_01
    e_a = np.empty(3)
    e_b = np.empty(3)
    for k in range(3):
        i = (k + 1) % 3
        j = (k + 2) % 3
        xi, yi, xj, yj = tri[i, 0], tri[i, 1], tri[j, 0], tri[j, 1]
        e_a[k] = (xj - xi) * (a[1] - yi) - (yj - yi) * (a[0] - xi)
        e_b[k] = (xj - xi) * (b[1] - yi) - (yj - yi) * (b[0] - xi)
    # kernel specialisation kept on purpose: the same parameter clipping (Cyrus–Beck, u in [lo, hi] against
    # half-planes) as the ray's half-spaces in raster/volume.py, here on 2-D edge functions
    for k in range(3):
        c0 = sigma * e_a[k]
        c = sigma * (e_b[k] - e_a[k])
        if c == 0.0:
            if c0 < 0.0:
                return 1.0, 0.0
        elif c > 0.0:
            lo = max(lo, -c0 / c)
        else:
            hi = min(hi, -c0 / c)
        if lo >= hi:
            return 1.0, 0.0
    # depth of the plane at both ends (barycentric interpolation), then z_edge − z_plane > 0; the interval
    # ends exactly where the edge pierces the plane, and counts only if somewhere in it the triangle lies
    # more than the tolerance in front (an edge in the triangle's plane is never hidden by round-off)
    za = (e_a[0] * z0 + e_a[1] * z1 + e_a[2] * z2) / area
    zb = (e_b[0] * z0 + e_b[1] * z1 + e_b[2] * z2) / area
    g0 = a[2] - za
    g = (b[2] - zb) - g0
    if g == 0.0:
        if g0 <= 0.0:
            return 1.0, 0.0
    elif g > 0.0:
        lo = max(lo, -g0 / g)
    else:
        hi = min(hi, -g0 / g)
    if lo >= hi or max(g0 + lo * g, g0 + hi * g) <= depth_tolerance:
        return 1.0, 0.0
    return lo, hi


@kernel
def _row_span(a, b, grid, row, box):  # pragma: no cover - compiled
    """First and last column of the cells in grid row `row` that the window segment a→b passes through.

    The segment's part inside the row's band of y (the whole segment below the first / above the last row
    of its box, which the box clamps to the grid) spans x from xa to xb; a slack of 1e-9 cells keeps a
    crossing exactly on a cell border in both cells. Clamped to the segment's box columns.
    """
    cell = grid[2]
    ax, ay = (a[0] - grid[0]) / cell, (a[1] - grid[1]) / cell
    bx, by = (b[0] - grid[0]) / cell, (b[1] - grid[1]) / cell
    band_lo = min(ay, by) if row == box[1] else max(float(row), min(ay, by))
    band_hi = max(ay, by) if row == box[3] else min(float(row + 1), max(ay, by))
    if by != ay:
        xa = ax + (band_lo - ay) / (by - ay) * (bx - ax)
        xb = ax + (band_hi - ay) / (by - ay) * (bx - ax)
    else:
        xa, xb = ax, bx
    slack = 1e-9 * (abs(ax) + abs(bx) + 1.0)
    first = math.floor(min(xa, xb) - slack)
    last = math.floor(max(xa, xb) + slack)
    return max(first, box[0]), min(last, box[2])


@parallel_kernel(lambda seg, *_: seg.shape[0], grain=256)
def _segment_intervals(
    seg, lengths, boxes, edge_faces, occluders, occluder_faces, tri_boxes, cell_starts, cell_triangles,
    grid, tolerances, counts, offsets, out, write, start, stop,
):  # pragma: no cover - compiled  # fmt: skip
    """Merged hidden intervals of every segment: counts them (write = 0) or writes them at offsets (write = 1).

    Only the cells the segment passes through are visited (row by row, ``_row_span``), and each (segment,
    triangle) pair once: in the first of those cells that the triangle's bounding box covers.
    """
    columns = int(grid[3])
    depth_tolerance, gap_pixels = tolerances[0], tolerances[1]
    for e in range(start, stop):
        r0, r1 = boxes[e, 1], boxes[e, 3]
        capacity = 0
        for row in range(r0, r1 + 1):
            first, last = _row_span(seg[e, 0], seg[e, 1], grid, row, boxes[e])
            for column in range(first, last + 1):
                cell = row * columns + column
                capacity += cell_starts[cell + 1] - cell_starts[cell]
        starts = np.empty(capacity)
        ends = np.empty(capacity)
        n = 0
        zmax = max(seg[e, 0, 2], seg[e, 1, 2])
        xlo, xhi = min(seg[e, 0, 0], seg[e, 1, 0]), max(seg[e, 0, 0], seg[e, 1, 0])
        ylo, yhi = min(seg[e, 0, 1], seg[e, 1, 1]), max(seg[e, 0, 1], seg[e, 1, 1])
        before_first, before_last = 0, -1
        for row in range(r0, r1 + 1):
            first, last = _row_span(seg[e, 0], seg[e, 1], grid, row, boxes[e])
            for column in range(first, last + 1):
                cell = row * columns + column
                for slot in range(cell_starts[cell], cell_starts[cell + 1]):
                    t = cell_triangles[slot]
                    # visit the pair only in the first cell on the segment's path inside the triangle's box:
                    # not if an earlier cell of this row, or a cell of the row before, lies in the box
                    if column > max(first, tri_boxes[t, 0]):
                        continue
                    if row > max(r0, tri_boxes[t, 1]) and max(before_first, tri_boxes[t, 0]) <= min(
                        before_last, tri_boxes[t, 2]
                    ):
                        continue
                    face = occluder_faces[t]
                    if face == edge_faces[e, 0] or face == edge_faces[e, 1]:
                        continue
                    tri = occluders[t]
                    if min(tri[0, 2], tri[1, 2], tri[2, 2]) >= zmax:
                        continue  # wholly behind the edge
                    if max(tri[0, 0], tri[1, 0], tri[2, 0]) < xlo or min(tri[0, 0], tri[1, 0], tri[2, 0]) > xhi:
                        continue
                    if max(tri[0, 1], tri[1, 1], tri[2, 1]) < ylo or min(tri[0, 1], tri[1, 1], tri[2, 1]) > yhi:
                        continue
                    lo, hi = _triangle_interval(seg[e, 0], seg[e, 1], tri, depth_tolerance)
                    if hi > lo:
                        starts[n] = lo
                        ends[n] = hi
                        n += 1
            before_first, before_last = first, last
        # union of the intervals: sort by start, merge overlaps and gaps below gap_pixels
        order = np.argsort(starts[:n], kind="mergesort")
        gap = gap_pixels / lengths[e]
        merged_lo = np.empty(n)
        merged_hi = np.empty(n)
        merged = 0
        for k in range(n):
            lo = starts[order[k]]
            hi = ends[order[k]]
            if merged > 0 and lo <= merged_hi[merged - 1] + gap:
                merged_hi[merged - 1] = max(merged_hi[merged - 1], hi)
            else:
                merged_lo[merged] = lo
                merged_hi[merged] = hi
                merged += 1
        # snap ends within the gap of 0 and 1; drop hidden pieces no longer than the gap
        kept = 0
        for k in range(merged):
            lo = merged_lo[k] if merged_lo[k] > gap else 0.0
            hi = merged_hi[k] if merged_hi[k] < 1.0 - gap else 1.0
            if hi - lo <= gap:
                continue
            if write == 1:
                out[offsets[e] + kept, 0] = lo
                out[offsets[e] + kept, 1] = hi
            kept += 1
        counts[e] = kept


@kernel
def _complement(offsets, hidden, counts, out, write):  # pragma: no cover - compiled
    """Visible intervals of each segment: [0, 1] minus its sorted, disjoint hidden intervals (count or write)."""
    cursor = 0
    for e in range(offsets.shape[0] - 1):
        lo = 0.0
        count = 0
        for k in range(offsets[e], offsets[e + 1] + 1):
            hi = hidden[k, 0] if k < offsets[e + 1] else 1.0
            if hi > lo:
                if write == 1:
                    out[cursor, 0] = lo
                    out[cursor, 1] = hi
                cursor += 1
                count += 1
            if k < offsets[e + 1]:
                lo = hidden[k, 1]
        counts[e] = count
