"""The octree visible-surface method: front-to-back octant traversal writing each pixel once (Numba).

Plain arrays in: the canonical codes of a linear octree (``frustum.geometry.octree``) concatenated per level
with offsets, the model cube, clip_from_model and the viewing position in model coordinates; caller-owned
color, depth and coverage buffers out. Serial by nature: the order of the traversal is the algorithm.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel

__all__ = ["TILE", "draw_octree", "split_pairs"]

TILE = 8
"""Side of the coverage tiles (pixels): a node whose screen box lies in completely written tiles is skipped."""


@kernel
def _octants(codes, start, stop, parent):
    """Bit o set for each child $8·parent + o$ present in the sorted slice codes[start:stop] (one binary search
    for the first child, then a scan of at most 8 entries)."""
    first = parent << np.uint64(3)
    lo, hi = start, stop
    while lo < hi:
        mid = (lo + hi) >> 1
        if codes[mid] < first:
            lo = mid + 1
        else:
            hi = mid
    bits = 0
    while lo < stop and codes[lo] < first + np.uint64(8):
        bits |= 1 << int(codes[lo] - first)
        lo += 1
    return bits


@kernel
def _fill_face(window, corner_ids, face_rgba, color, depth, written, tile_counts):
    """Write the pixels of one convex projected quad (corners `window[corner_ids]`, (x, y, depth)) that no
    earlier face wrote: pixel centres inside or on every edge; depth from the quad's plane in window space."""
    height, width = written.shape
    x0, y0, z0 = window[corner_ids[0], 0], window[corner_ids[0], 1], window[corner_ids[0], 2]
    x1, y1, z1 = window[corner_ids[1], 0], window[corner_ids[1], 1], window[corner_ids[1], 2]
    x2, y2, z2 = window[corner_ids[2], 0], window[corner_ids[2], 1], window[corner_ids[2], 2]
    area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    if abs(area) < 1e-12:
        return 0
    # z = z0 + a·(x − x0) + b·(y − y0), the plane through three corners
    a = ((z1 - z0) * (y2 - y0) - (z2 - z0) * (y1 - y0)) / area
    b = ((x1 - x0) * (z2 - z0) - (x2 - x0) * (z1 - z0)) / area
    sign = 1.0 if area > 0.0 else -1.0
    xmin, xmax, ymin, ymax = np.inf, -np.inf, np.inf, -np.inf
    for c in range(4):
        x, y = window[corner_ids[c], 0], window[corner_ids[c], 1]
        xmin, xmax = min(xmin, x), max(xmax, x)
        ymin, ymax = min(ymin, y), max(ymax, y)
    i0 = max(int(np.ceil(xmin - 0.5)), 0)
    i1 = min(int(np.floor(xmax - 0.5)), width - 1)
    j0 = max(int(np.ceil(ymin - 0.5)), 0)
    j1 = min(int(np.floor(ymax - 0.5)), height - 1)
    count = 0
    for j in range(j0, j1 + 1):
        py = j + 0.5
        row = height - 1 - j
        for i in range(i0, i1 + 1):
            if written[row, i]:
                continue
            px = i + 0.5
            inside = True
            for e in range(4):
                ax, ay = window[corner_ids[e], 0], window[corner_ids[e], 1]
                bx, by = window[corner_ids[(e + 1) & 3], 0], window[corner_ids[(e + 1) & 3], 1]
                if sign * ((bx - ax) * (py - ay) - (by - ay) * (px - ax)) < 0.0:
                    inside = False
                    break
            if not inside:
                continue
            written[row, i] = True
            depth[row, i] = z0 + a * (px - x0) + b * (py - y0)
            for k in range(4):
                color[row, i, k] = face_rgba[k]
            tile_counts[row // 8, i // 8] += 1
            count += 1
    return count


@kernel
def _covered(tile_counts, written, i0, i1, j0, j1, height, width):
    """True if every pixel of the box [i0, i1] × [j0, j1] (window rows j, y up) is written: looked up one by one
    for a box of at most 16 pixels, else through the tiles it touches (all completely written)."""
    r0, r1 = height - 1 - j1, height - 1 - j0
    if (i1 - i0 + 1) * (r1 - r0 + 1) <= 16:  # a small box: look at its pixels themselves
        for r in range(r0, r1 + 1):
            for i in range(i0, i1 + 1):
                if not written[r, i]:
                    return False
        return True
    for ty in range(r0 // 8, r1 // 8 + 1):
        rows = min(8, height - ty * 8)
        for tx in range(i0 // 8, i1 // 8 + 1):
            columns = min(8, width - tx * 8)
            if tile_counts[ty, tx] < rows * columns:
                return False
    return True


@kernel
def draw_octree(full_codes, full_offsets, partial_codes, partial_offsets, params, face_rgba, color, depth, written,
                tile_counts, log):  # fmt: skip
    """Draw the full cells of an octree front to back; returns the number of nodes visited.

    params (27,): model cube origin (3), side, depth, clip_from_model row-major (16), viewing position in model
    coordinates (4, w = 0 for a parallel projection), width, height. face_rgba (6, 4) uint8: colors of the faces
    facing +x, −x, +y, −y, +z, −z. `color` (H, W, 4) uint8, `depth` (H, W) float32, `written` (H, W) bool and
    `tile_counts` (⌈H/8⌉, ⌈W/8⌉) int32 are read and updated (a pixel already written is never changed).
    Children are visited in the order ``mask XOR c``, c = 0 … 7, where bit a of `mask` says the eye lies on
    the high side of the node's centre along axis a: a child never hides one visited before it.
    Recording mode: `log` (L, 4) int64 gets a row per node visited while rows are left, ``(level, Morton code,
    outcome, pixels drawn)`` with outcome 0 outside the view volume, 1 on no pixel centre, 2 hidden (every pixel
    under it already written), 3 drawn (a full cell's faces), 4 its children visited, 5 a finest cell crossing
    the near plane (not drawn); (0, 4) records nothing.
    """
    logged = 0
    ox, oy, oz, side = params[0], params[1], params[2], params[3]
    max_level = int(params[4])
    m = params[5:21]
    ex, ey, ez, ew = params[21], params[22], params[23], params[24]
    width, height = int(params[25]), int(params[26])
    total = width * height
    drawn = 0
    for r in range(written.shape[0]):
        for c in range(written.shape[1]):
            if written[r, c]:
                drawn += 1
    stack_level = np.empty(8 * (max_level + 2), dtype=np.int64)
    stack_code = np.empty(8 * (max_level + 2), dtype=np.uint64)
    stack_full = np.empty(8 * (max_level + 2), dtype=np.bool_)
    # the root: full, partial or empty (then nothing to draw)
    stack_level[0], stack_code[0], stack_full[0] = 0, 0, full_offsets[1] > full_offsets[0]
    top = 1 if (full_offsets[1] > full_offsets[0] or partial_offsets[1] > partial_offsets[0]) else 0
    clip = np.empty((8, 4))
    window = np.empty((8, 3))
    quad = np.empty(4, dtype=np.int64)
    visited = 0
    while top > 0 and drawn < total:
        top -= 1
        level, code, full = stack_level[top], stack_code[top], stack_full[top]  # full, else partial
        visited += 1
        log_row = logged
        if logged < log.shape[0]:
            log[log_row, 0], log[log_row, 1], log[log_row, 2], log[log_row, 3] = level, np.int64(code), 4, 0
            logged += 1
        # integer coordinates from the Morton code
        i = j = k = np.uint64(0)
        for bit in range(level):
            i |= ((code >> np.uint64(3 * bit)) & np.uint64(1)) << np.uint64(bit)
            j |= ((code >> np.uint64(3 * bit + 1)) & np.uint64(1)) << np.uint64(bit)
            k |= ((code >> np.uint64(3 * bit + 2)) & np.uint64(1)) << np.uint64(bit)
        s = side / (1 << level)
        lo_x, lo_y, lo_z = ox + int(i) * s, oy + int(j) * s, oz + int(k) * s
        # the 8 corners in clip space (corner c = x + 2y + 4z)
        for c in range(8):
            px, py, pz = lo_x + (c & 1) * s, lo_y + ((c >> 1) & 1) * s, lo_z + ((c >> 2) & 1) * s
            for row in range(4):
                clip[c, row] = m[4 * row] * px + m[4 * row + 1] * py + m[4 * row + 2] * pz + m[4 * row + 3]
        # cull a node outside one plane of the view volume
        outside = False
        for plane in range(6):
            axis, sgn = plane // 2, 1.0 if plane % 2 == 0 else -1.0
            all_out = True
            for c in range(8):
                if clip[c, 3] + sgn * clip[c, axis] >= 0.0:
                    all_out = False
                    break
            if all_out:
                outside = True
                break
        if outside:
            if log_row < log.shape[0]:
                log[log_row, 2] = 0
            continue
        in_front = True
        for c in range(8):
            if clip[c, 2] + clip[c, 3] < 0.0 or clip[c, 3] <= 0.0:
                in_front = False
                break
        if in_front:
            xmin, xmax, ymin, ymax = np.inf, -np.inf, np.inf, -np.inf
            for c in range(8):
                inv_w = 1.0 / clip[c, 3]
                window[c, 0] = (clip[c, 0] * inv_w + 1.0) * 0.5 * width
                window[c, 1] = (clip[c, 1] * inv_w + 1.0) * 0.5 * height
                window[c, 2] = (clip[c, 2] * inv_w + 1.0) * 0.5
                xmin, xmax = min(xmin, window[c, 0]), max(xmax, window[c, 0])
                ymin, ymax = min(ymin, window[c, 1]), max(ymax, window[c, 1])
            i0 = max(int(np.ceil(xmin - 0.5)), 0)
            i1 = min(int(np.floor(xmax - 0.5)), width - 1)
            j0 = max(int(np.ceil(ymin - 0.5)), 0)
            j1 = min(int(np.floor(ymax - 0.5)), height - 1)
            if i0 > i1 or j0 > j1:
                if log_row < log.shape[0]:
                    log[log_row, 2] = 1
                continue  # covers no pixel centre
            if _covered(tile_counts, written, i0, i1, j0, j1, height, width):
                if log_row < log.shape[0]:
                    log[log_row, 2] = 2
                continue  # every pixel under it is already written by nearer cells
            if full:
                before = drawn
                for axis in range(3):
                    lo = lo_x if axis == 0 else (lo_y if axis == 1 else lo_z)
                    e = ex if axis == 0 else (ey if axis == 1 else ez)
                    u, v = (axis + 1) % 3, (axis + 2) % 3
                    for high in range(2):
                        plane_at = lo + high * s
                        facing = (e - plane_at * ew > 0.0) if high == 1 else (e - plane_at * ew < 0.0)
                        if not facing:
                            continue
                        base = high << axis
                        quad[0] = base
                        quad[1] = base | (1 << u)
                        quad[2] = base | (1 << u) | (1 << v)
                        quad[3] = base | (1 << v)
                        drawn += _fill_face(window, quad, face_rgba[2 * axis + (1 - high)], color, depth, written,
                                            tile_counts)  # fmt: skip
                if log_row < log.shape[0]:
                    log[log_row, 2], log[log_row, 3] = 3, drawn - before
                continue
        elif full and level == max_level:
            if log_row < log.shape[0]:
                log[log_row, 2] = 5
            continue  # a finest cell crossing the near plane is not drawn
        # a partial node (or a full one crossing the near plane): its non-empty children, front to back
        if full:
            full_bits, partial_bits = 255, 0
        else:
            full_bits = _octants(full_codes, full_offsets[level + 1], full_offsets[level + 2], code)
            partial_bits = _octants(partial_codes, partial_offsets[level + 1], partial_offsets[level + 2], code)
        cx, cy, cz = lo_x + 0.5 * s, lo_y + 0.5 * s, lo_z + 0.5 * s
        mask = (1 if ex > cx * ew else 0) | (2 if ey > cy * ew else 0) | (4 if ez > cz * ew else 0)
        for c in range(7, -1, -1):  # pushed last-first: child mask ^ 0 is popped first
            o = mask ^ c
            if not ((full_bits | partial_bits) >> o) & 1:
                continue  # an empty child
            stack_level[top] = level + 1
            stack_code[top] = (code << np.uint64(3)) | np.uint64(o)
            stack_full[top] = (full_bits >> o) & 1 == 1
            top += 1
    return visited


@parallel_kernel(lambda corners, triangle_ids, *_: triangle_ids.shape[0])
def split_pairs(corners, triangle_ids, parent_lo, side, reference, parity, touches, crossings, start, stop):
    """For each (cell, triangle) pair and each octant o of the cell: does the triangle touch child o, and does
    it cross the segment from the cell's reference point to the child's (parallel over pairs).

    corners (F, 3, 3) triangle corners; triangle_ids (P,) the pair's triangle; parent_lo (P, 3) the cell's min
    corner (side 2·`side`); reference (3,) the reference point's offset from a cube's centre, in sides.
    touches[p, o]: bounding boxes overlap and the triangle's plane meets the child cube (conservative, closed).
    crossings[p, o] (if `parity`): Möller–Trumbore, t in [0, 1), u, v >= 0, u + v <= 1.
    """
    slack = 1e-12 * max(side, 1.0)
    for p in range(start, stop):
        f = triangle_ids[p]
        ax, ay, az = corners[f, 0, 0], corners[f, 0, 1], corners[f, 0, 2]
        e1x, e1y, e1z = corners[f, 1, 0] - ax, corners[f, 1, 1] - ay, corners[f, 1, 2] - az
        e2x, e2y, e2z = corners[f, 2, 0] - ax, corners[f, 2, 1] - ay, corners[f, 2, 2] - az
        nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
        n1 = abs(nx) + abs(ny) + abs(nz)
        tmin_x = min(ax, min(corners[f, 1, 0], corners[f, 2, 0]))
        tmax_x = max(ax, max(corners[f, 1, 0], corners[f, 2, 0]))
        tmin_y = min(ay, min(corners[f, 1, 1], corners[f, 2, 1]))
        tmax_y = max(ay, max(corners[f, 1, 1], corners[f, 2, 1]))
        tmin_z = min(az, min(corners[f, 1, 2], corners[f, 2, 2]))
        tmax_z = max(az, max(corners[f, 1, 2], corners[f, 2, 2]))
        # the parent's reference point (cube of side 2·side)
        sx0 = parent_lo[p, 0] + (0.5 + reference[0]) * 2.0 * side
        sy0 = parent_lo[p, 1] + (0.5 + reference[1]) * 2.0 * side
        sz0 = parent_lo[p, 2] + (0.5 + reference[2]) * 2.0 * side
        for o in range(8):
            lx = parent_lo[p, 0] + (o & 1) * side
            ly = parent_lo[p, 1] + ((o >> 1) & 1) * side
            lz = parent_lo[p, 2] + ((o >> 2) & 1) * side
            hit = (
                tmin_x <= lx + side + slack and tmax_x >= lx - slack and tmin_y <= ly + side + slack
                and tmax_y >= ly - slack and tmin_z <= lz + side + slack and tmax_z >= lz - slack
            )  # fmt: skip
            if hit:
                cx, cy, cz = lx + 0.5 * side, ly + 0.5 * side, lz + 0.5 * side
                distance = nx * (cx - ax) + ny * (cy - ay) + nz * (cz - az)
                hit = abs(distance) <= 0.5 * side * n1 * (1.0 + 1e-9) + slack * n1
            touches[p, o] = hit
            crossed = False
            if parity:
                dx = lx + (0.5 + reference[0]) * side - sx0
                dy = ly + (0.5 + reference[1]) * side - sy0
                dz = lz + (0.5 + reference[2]) * side - sz0
                px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
                det = e1x * px + e1y * py + e1z * pz
                if det != 0.0:
                    inv = 1.0 / det
                    qx0, qy0, qz0 = sx0 - ax, sy0 - ay, sz0 - az
                    u = (qx0 * px + qy0 * py + qz0 * pz) * inv
                    qx, qy, qz = qy0 * e1z - qz0 * e1y, qz0 * e1x - qx0 * e1z, qx0 * e1y - qy0 * e1x
                    v = (dx * qx + dy * qy + dz * qz) * inv
                    t = (e2x * qx + e2y * qy + e2z * qz) * inv
                    crossed = u >= 0.0 and v >= 0.0 and u + v <= 1.0 and t >= 0.0 and t < 1.0
            crossings[p, o] = crossed
