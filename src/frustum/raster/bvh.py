"""A triangle bounding-volume hierarchy built with numpy and its first-hit ray traversal (Numba).

Build: triangles sorted by the Morton code of their centroids (a 1024³ grid over the bounding box), cut into
leaves of ``LEAF_SIZE`` consecutive triangles, and an implicit complete binary tree over the leaves (heap
layout: node i has children 2i + 1 and 2i + 2; the ``P`` leaves are nodes P − 1 … 2P − 2), each node's box the
union of its children's. Traversal: per ray, a stack of nodes, slab test against each box, nearer child first,
Möller–Trumbore against the triangles of a leaf; the nearest t >= 0 wins (ties: the lower triangle index).
``first_hits`` casts given rays (``Scene.pick``); ``cast_pixels`` casts one ray per pixel through the view volume
and writes what the depth buffer writes (``render(..., method="ray-casting")``, ``frustum.visibility.raycast``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel

__all__ = ["CAST_STATS", "LEAF_SIZE", "Hierarchy", "build", "cast_pixels", "first_hits"]

LEAF_SIZE = 4


class Hierarchy(NamedTuple):
    """``lo``/``hi`` (2P − 1, 3) node boxes; ``triangles`` (P·LEAF_SIZE, 3, 3) float64 in leaf order (padding
    rows NaN); ``order`` (P·LEAF_SIZE,) int64 original triangle index of each row (−1 for padding)."""

    lo: np.ndarray
    hi: np.ndarray
    triangles: np.ndarray
    order: np.ndarray


def _spread10(v: np.ndarray) -> np.ndarray:
    x = v.astype(np.uint64) & np.uint64(0x3FF)
    x = (x | (x << np.uint64(16))) & np.uint64(0x30000FF)
    x = (x | (x << np.uint64(8))) & np.uint64(0x300F00F)
    x = (x | (x << np.uint64(4))) & np.uint64(0x30C30C3)
    x = (x | (x << np.uint64(2))) & np.uint64(0x9249249)
    return x


def build(triangles: np.ndarray) -> Hierarchy:
    """The hierarchy of (F, 3, 3) float64 triangles (corner rows), F >= 1."""
    tri = np.ascontiguousarray(triangles, dtype=np.float64)
    count = tri.shape[0]
    centroids = tri.mean(axis=1)
    lo, hi = centroids.min(axis=0), centroids.max(axis=0)
    scale = np.where(hi > lo, 1023.0 / np.where(hi > lo, hi - lo, 1.0), 0.0)
    q = ((centroids - lo) * scale).astype(np.int64)
    codes = _spread10(q[:, 0]) | (_spread10(q[:, 1]) << np.uint64(1)) | (_spread10(q[:, 2]) << np.uint64(2))
    order = np.argsort(codes, kind="stable")
    leaves = max(1, -(-count // LEAF_SIZE))
    p = 1 << (leaves - 1).bit_length()
    rows = p * LEAF_SIZE
    padded = np.full((rows, 3, 3), np.nan)
    padded[:count] = tri[order]
    index = np.full(rows, -1, dtype=np.int64)
    index[:count] = order
    tri_lo = np.full((rows, 3), np.inf)
    tri_hi = np.full((rows, 3), -np.inf)
    tri_lo[:count] = tri[order].min(axis=1)
    tri_hi[:count] = tri[order].max(axis=1)
    node_lo = np.empty((2 * p - 1, 3))
    node_hi = np.empty((2 * p - 1, 3))
    node_lo[p - 1 :] = tri_lo.reshape(p, LEAF_SIZE, 3).min(axis=1)
    node_hi[p - 1 :] = tri_hi.reshape(p, LEAF_SIZE, 3).max(axis=1)
    width = p
    while width > 1:  # one level up: parents (start − 1)/2 … of the children start … start + width − 1
        start = width - 1
        parent = (width // 2) - 1
        node_lo[parent : parent + width // 2] = np.minimum(
            node_lo[start : start + width : 2], node_lo[start + 1 : start + width : 2]
        )
        node_hi[parent : parent + width // 2] = np.maximum(
            node_hi[start : start + width : 2], node_hi[start + 1 : start + width : 2]
        )
        width //= 2
    return Hierarchy(node_lo, node_hi, padded, index)


@kernel
def _box_entry(lo, hi, node, ox, oy, oz, ix, iy, iz, t_max):
    """Entry t of the ray in box `node` (slabs), or inf if it misses or enters beyond t_max."""
    if lo[node, 0] > hi[node, 0]:  # an empty subtree (padding)
        return np.inf
    t0 = 0.0
    t1 = t_max
    for axis in range(3):
        o = ox if axis == 0 else (oy if axis == 1 else oz)
        inv = ix if axis == 0 else (iy if axis == 1 else iz)
        a = (lo[node, axis] - o) * inv
        b = (hi[node, axis] - o) * inv
        if a != a:  # 0·inf: the ray lies in the slab's plane
            a = -np.inf
        if b != b:
            b = np.inf
        if a > b:
            a, b = b, a
        if a > t0:
            t0 = a
        if b < t1:
            t1 = b
        if t0 > t1:
            return np.inf
    return t0


@kernel
def _cast_ray(lo, hi, triangles, order, skip, ox, oy, oz, dx, dy, dz, t_max, cull):
    """First hit of one ray: ``(t, face, u, v, back, box_tests, nodes, tests)``.

    The nearest t in [0, t_max) over the triangles (ties: the lower triangle index), skipping those with
    ``skip[face] != 0`` (`skip` empty: none) and, when `cull`, the back faces (Möller–Trumbore's determinant
    $e1·(d × e2) = −d·N$ negative: the ray meets the side the counter-clockwise normal N points away from).
    u, v are the weights of corners 1 and 2 at the hit (world barycentrics: perspective-correct), back = 1 for a
    back face; inf, −1 for a miss. The counts: box (slab) tests, nodes visited (popped and still nearer than the
    best hit so far), ray–triangle tests. A node is entered nearer child first; a node whose box entry is
    beyond the best hit found since it was pushed is not visited.
    """
    leaves = (lo.shape[0] + 1) // 2
    ix = 1.0 / dx if dx != 0.0 else np.inf
    iy = 1.0 / dy if dy != 0.0 else np.inf
    iz = 1.0 / dz if dz != 0.0 else np.inf
    masked = skip.shape[0] > 0
    best = t_max
    best_face = -1
    best_u, best_v, best_back = 0.0, 0.0, 0
    box_tests, nodes, tests = 1, 0, 0
    stack = np.empty(64, dtype=np.int64)
    entry = np.empty(64)
    top = 0
    t_root = _box_entry(lo, hi, 0, ox, oy, oz, ix, iy, iz, best)
    if t_root < np.inf:
        stack[0] = 0
        entry[0] = t_root
        top = 1
    while top > 0:
        top -= 1
        node = stack[top]
        if entry[top] > best:
            continue
        nodes += 1
        if node >= leaves - 1:
            first = (node - (leaves - 1)) * 4
            for row in range(first, first + 4):
                face = order[row]
                if face < 0 or (masked and skip[face] != 0):
                    continue
                tests += 1
                ax, ay, az = triangles[row, 0, 0], triangles[row, 0, 1], triangles[row, 0, 2]
                e1x, e1y, e1z = triangles[row, 1, 0] - ax, triangles[row, 1, 1] - ay, triangles[row, 1, 2] - az
                e2x, e2y, e2z = triangles[row, 2, 0] - ax, triangles[row, 2, 1] - ay, triangles[row, 2, 2] - az
                px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
                det = e1x * px + e1y * py + e1z * pz
                if det == 0.0 or (cull != 0 and det < 0.0):
                    continue
                inv = 1.0 / det
                sx, sy, sz = ox - ax, oy - ay, oz - az
                u = (sx * px + sy * py + sz * pz) * inv
                if u < 0.0 or u > 1.0:
                    continue
                qx, qy, qz = sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x
                v = (dx * qx + dy * qy + dz * qz) * inv
                if v < 0.0 or u + v > 1.0:
                    continue
                t = (e2x * qx + e2y * qy + e2z * qz) * inv
                if t >= 0.0 and (t < best or (t == best and face < best_face)):
                    best, best_face, best_u, best_v = t, face, u, v
                    best_back = 1 if det < 0.0 else 0
            continue
        left, right = 2 * node + 1, 2 * node + 2
        t_left = _box_entry(lo, hi, left, ox, oy, oz, ix, iy, iz, best)
        t_right = _box_entry(lo, hi, right, ox, oy, oz, ix, iy, iz, best)
        box_tests += 2
        near, far, t_near, t_far = (
            (left, right, t_left, t_right) if t_left <= t_right else (right, left, t_right, t_left)
        )
        if t_far < np.inf:  # the farther child is pushed first: the nearer one is popped next
            stack[top] = far
            entry[top] = t_far
            top += 1
        if t_near < np.inf:
            stack[top] = near
            entry[top] = t_near
            top += 1
    if best_face < 0:
        best = np.inf
    return best, best_face, best_u, best_v, best_back, box_tests, nodes, tests


@kernel
def _trace_ray(lo, hi, triangles, order, ox, oy, oz, dx, dy, dz):
    """(t, face): nearest t >= 0 over all triangles (inf, −1 if none) of one ray."""
    hit = _cast_ray(lo, hi, triangles, order, np.empty(0, dtype=np.uint8), ox, oy, oz, dx, dy, dz, np.inf, 0)
    return hit[0], hit[1]


@kernel
def _trace(lo, hi, triangles, order, origins, directions, t_out, face_out):
    """``_trace_ray`` for each ray, one thread (a few rays: no thread start-up)."""
    for r in range(origins.shape[0]):
        t_out[r], face_out[r] = _trace_ray(lo, hi, triangles, order, origins[r, 0], origins[r, 1], origins[r, 2],
                                           directions[r, 0], directions[r, 1], directions[r, 2])  # fmt: skip


@parallel_kernel(lambda lo, hi, triangles, order, origins, *_: origins.shape[0], grain=256)
def _trace_parallel(lo, hi, triangles, order, origins, directions, t_out, face_out, start, stop):
    """``_trace_ray`` for each ray, parallel over rays."""
    for r in range(start, stop):
        t_out[r], face_out[r] = _trace_ray(lo, hi, triangles, order, origins[r, 0], origins[r, 1], origins[r, 2],
                                           directions[r, 0], directions[r, 1], directions[r, 2])  # fmt: skip


def first_hits(hierarchy: Hierarchy, origins: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N,) nearest t >= 0 of each ray $origin + t·direction$ (inf for a miss) and its triangle index (−1)."""
    o = np.ascontiguousarray(origins, dtype=np.float64)
    d = np.ascontiguousarray(directions, dtype=np.float64)
    t = np.empty(o.shape[0])
    face = np.empty(o.shape[0], dtype=np.int64)
    trace = _trace if o.shape[0] < 64 else _trace_parallel
    trace(hierarchy.lo, hierarchy.hi, hierarchy.triangles, hierarchy.order, o, d, t, face)
    return t, face


CAST_STATS = ("rays", "hits", "box_tests", "nodes_visited", "triangle_tests")
"""Columns of ``cast_pixels``' per-row counts."""


@parallel_kernel(lambda lo, hi, triangles, order, skip, world_from_window, window_from_world, cull, depth, *_:
                 depth.shape[0], work=lambda *args: args[8].size, grain=4096)  # fmt: skip
def cast_pixels(lo, hi, triangles, order, skip, world_from_window, window_from_world, cull, depth, codes, bary,
                stats, start, stop):  # fmt: skip
    """A ray through the centre of every pixel of window rows [start, stop) (y up); the first hit's window depth,
    face code and barycentrics, as the depth buffer writes them.

    Pixel (i, j) casts $origin + t·(end − origin)$, t in [0, 1), from $origin = unproject(i + ½, j + ½, 0)$
    on the near plane to $end = unproject(i + ½, j + ½, 1)$ on the far plane (``Camera.ray``'s line; for a
    parallel projection the projection direction): hits inside the view volume only. At a hit, ``depth`` (H, W)
    float32 (top row first: row H − 1 − j) receives the window depth $z_w = (M₂·P)/(M₃·P)$ (M =
    `window_from_world`), ``codes`` $2·face + back$, ``bary`` the weights of the face's corners 1 and 2; a
    depth that rounds to 1 is not written (the depth buffer's test "less" against its clear value). ``stats``
    (H, len(CAST_STATS)) int64 receives each row's counts. `cull` != 0 skips back faces (the ray goes on to
    what lies behind them, as the depth buffer never draws them); `skip` (F,) uint8 marks triangles not drawn.
    """
    height, width = depth.shape[0], depth.shape[1]
    m = world_from_window
    for j in range(start, stop):
        row = height - 1 - j
        y = j + 0.5
        rays, hits, box_tests, nodes, tests = 0, 0, 0, 0, 0
        for i in range(width):
            x = i + 0.5
            nw = m[3, 0] * x + m[3, 1] * y + m[3, 3]
            ox = (m[0, 0] * x + m[0, 1] * y + m[0, 3]) / nw
            oy = (m[1, 0] * x + m[1, 1] * y + m[1, 3]) / nw
            oz = (m[2, 0] * x + m[2, 1] * y + m[2, 3]) / nw
            fw = nw + m[3, 2]
            dx = (m[0, 0] * x + m[0, 1] * y + m[0, 2] + m[0, 3]) / fw - ox
            dy = (m[1, 0] * x + m[1, 1] * y + m[1, 2] + m[1, 3]) / fw - oy
            dz = (m[2, 0] * x + m[2, 1] * y + m[2, 2] + m[2, 3]) / fw - oz
            t, face, u, v, back, b, n, k = _cast_ray(lo, hi, triangles, order, skip, ox, oy, oz, dx, dy, dz, 1.0,
                                                     cull)  # fmt: skip
            rays += 1
            box_tests += b
            nodes += n
            tests += k
            if face < 0:
                continue
            px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
            w = window_from_world
            z = np.float32((w[2, 0] * px + w[2, 1] * py + w[2, 2] * pz + w[2, 3])
                           / (w[3, 0] * px + w[3, 1] * py + w[3, 2] * pz + w[3, 3]))  # fmt: skip
            if not z < 1.0:
                continue
            hits += 1
            depth[row, i] = z
            codes[row, i] = 2 * face + back
            bary[row, i, 0], bary[row, i, 1] = np.float32(u), np.float32(v)
        stats[j, 0], stats[j, 1], stats[j, 2], stats[j, 3], stats[j, 4] = rays, hits, box_tests, nodes, tests
