"""The ray-query index: a surface-area-heuristic BVH over world triangles and its traversal kernels (Numba).

kernel module: the BVH's build and its traversals (binary for pictures and lessons, four-wide for queries) are one
algorithm's flat loops, kept in one module so the kernels inline one another; hence its length.

Build (``build``): a binary bounding-volume hierarchy by the binned surface area heuristic [Wald 2007]: each
triangle's box is rounded outward to float32 once (``_prepare``; outward rounding is monotone, so every union of
them is the float64 union rounded outward: a box never shrinks below its triangles) and these rows are partitioned
in place with the triangle numbers, so each node reads its range sequentially. At a node the triangles' box centres
are put into ``BINS`` bins along the longest extent of the centres, and the plane between two bins with the least
$A_left·N_left + A_right·N_right$ (A: surface area of the side's bounding box, N: its triangle count) splits them;
the partition pass also gathers each side's centre bounds, so no node rescans its range for them. A range of at most
``SMALL`` triangles is split by the exact SAH (every cut of the triangles sorted by centre, on each axis), one of at
most ``LEAF_SIZE`` is a leaf (shallow leaves: one triangle test per leaf), and a range whose centres coincide is cut
in the middle. Nodes hold the boxes of their two children, and a node over triangles ``[s, e)`` numbered ``k`` has
its left child at ``k + 1`` and its right child at $k + (m − s)$ (m: the split), so every subtree owns a fixed
range of node numbers: the top of the tree is built on one thread, the subtrees below ``PARALLEL_CUTOFF`` triangles
(or a sixteenth of them all) in parallel (``_jit.parallel_kernel``), and the result is the same bytes on any number
of threads.

Traversal (``closest_hits``, ``any_hits``, ``intersect``): the binary tree is collapsed into nodes of ``WIDTH`` = 4
children (``_collapse``: from a node's two children, the inner child of the largest surface area is replaced by its
own two until four are held; Embree's BVH4 [Wald et al. 2008]; a subtree of at most ``LEAF_WIDE`` = 4 triangles
becomes one leaf of the wide tree, its rows consecutive, as Embree's four-triangle leaves), whose bounds are stored
as rows of four float32 (``wide_boxes`` (M, 6, 4): lo x, y, z, hi x, y, z, one value per child; the float32-rounded
values of the binary boxes, so no box changes). Per ray, the four boxes of a node are tested at once (``_slab4``:
LLVM vector code, each bound row one load of four float32 widened to ``<4 x double>``, the slab test in float64 with
the far bound widened by $1 + 2γ₃$ so that rounding never loses a hit, PBRT 3.9.2, operation for operation the
scalar test); the children met are pushed sorted by their entry distance, the nearest on top, and an entry popped
beyond the best hit so far is skipped. Leaves are tested with the Möller–Trumbore ray–triangle test in
float64 (``_triangle``; the arithmetic ``tests/test_rays.py``'s brute force repeats; in the wide tree four
triangles at once, ``_triangles4``, the same bytes lane by lane). Closest hit: the least t in
``[t_min, t_max)``, ties to the lower triangle index (boxes are searched up to $best·(1 + 2⁻⁴⁰)$, so a triangle
whose t rounds a few ulps below its box's entry, or ties, is still found): one triangle whatever order the boxes
are searched in, so the wide traversal gives the binary one's hits to the byte (``_closest``, kept for
``cast_pixels``, whose counts are the binary tree's, and for the step-by-step view; a test holds them equal).
Any hit (``any_hits``): the leaves met are tested at once, and the traversal stops at the first triangle with t
in ``[t_min, t_max)`` (shadow rays). ``intersect`` computes, in the traversal's pass, the columns of
``Scene.intersect`` that are asked for (item, face, barycentrics, point, both normals, back). Rays run in
parallel over pieces of the ray array.

Chosen by measurement (one thread, process CPU seconds for 262,144 rays, medians of 3, the bunny and a
1.31 M-triangle sphere, camera / random rays; the shared 2-core host at load 8–16, Embree 4 in the same conditions
0.041 / 0.031 and 0.088 / 0.059 s): binary tree 0.085 / 0.080 and 0.206 / 0.165 s; four-wide, scalar slab tests
0.078 / 0.066 and 0.191 / 0.167; four-wide, vector slab tests 0.060 / 0.054 and 0.180 / 0.151 (the bounds in float32
or float64: the same within noise, float32 kept for half the memory). Testing a met leaf at once instead of pushing
it in the any-hit path: within noise (0.055 against 0.058 s on the bunny's shadow rays). Tried and dropped: the hit
mask of the four tests (``movmskpd``) with one met child entered and two ordered by a single compare (no stack
sort): first hits within noise, occlusion 5–25 % slower; links as int32: no change. The sphere's rays are
memory-bound (18 wide nodes and 5 triangles per shadow ray from the camera's hits at about 35 ns a node); the
bunny's cost some 20 ns a node. Leaves of up to four triangles in the wide tree (``LEAF_WIDE``; 3.4× fewer wide
nodes: bunny 34,801 → 10,281, sphere 634,069 → 189,478), against one triangle a leaf, both trees in one process
(load 15, medians of 5, first hit / occlusion, camera then random rays): bunny 0.060 / 0.053 → 0.060 / 0.049 and
0.061 / 0.042 → 0.054 / 0.041 s, sphere 0.153 / 0.172 → 0.137 / 0.150 and 0.109 / 0.123 → 0.102 / 0.104 s; up to
seven (``leaf_wide=7``, scalar tests) against four: 0–5 % slower on three rows of four, kept at four. Then a leaf's
triangles tested four at once (``_triangles4``: each corner coordinate of the four rows gathered into a
``<4 x double>``, Möller–Trumbore on the four lanes, the rejections a mask) against one after another
(``_triangle``), one process (load 15, medians of 5): bunny 0.056 / 0.049 → 0.045 / 0.036 and 0.056 / 0.040 → 0.050
/ 0.028 s, sphere 0.138 / 0.150 → 0.125 / 0.122 and 0.109 / 0.109 → 0.102 / 0.092 s (first hits 6–21 % and occlusion
15–31 % faster). Packing a wide node's bounds and links into one 128-byte-aligned record (as Embree's nodes) against
the two arrays: within noise (−3 … +11 %), not kept.
The default fields of ``Scene.intersect`` add 15–25 ms of CPU to (t, item, face) for 262,144 bunny rays, a part
of it their size alone: the eight columns are 30 MB, whose allocation and first writes (page faults) take some
7 ms (NumPy, no kernel).
Through the public API (``benchmarks/bench_rays.py``, CPU with one thread / Embree's one thread, load 9–10,
alternate runs; rows bunny camera, random, sphere camera, random), before these leaves → after: first hit, every
field 2.01 / 3.42 / 2.45 / 2.78 → 1.59 / 2.56 / 2.08 / 2.10, (t, item, face) 1.66 / 2.50 / 2.01 / 2.44 →
1.15 / 1.88 / 1.51 / 1.61; occlusion 1.90 / 2.26 / 2.37 / 2.15 → 1.42 / 1.50 / 1.46 / 1.54.

``cast_pixels`` casts one ray per pixel through the view volume and writes what the depth buffer writes
(``render(..., method="ray-casting")``).

References
----------
I. Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", IEEE Symposium on Interactive Ray
Tracing 2007; T. Möller, B. Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection", JGT 1997;
M. Pharr, W. Jakob, G. Humphreys, "Physically Based Rendering" 3rd ed., 3.9.2 (robust ray–box test);
I. Wald, C. Benthin, S. Boulos, "Getting Rid of Packets: Efficient SIMD Single-Ray Traversal using Multi-branching
BVHs", IEEE Symposium on Interactive Ray Tracing 2008.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic

from frustum.raster._jit import kernel, parallel_kernel

__all__ = [
    "BINS", "CAST_STATS", "FIELDS", "LEAF_SIZE", "LEAF_WIDE", "WIDTH", "Index", "any_hits", "build", "cast_pixels",
    "closest_hits", "intersect",
]

LEAF_SIZE = 1
"""Most triangles in a leaf: one (measured on the bunny against Embree in the same run: first-hit 1.44×, occlusion
1.62× Embree's time with 1, 1.8–2.0× and 2.0–2.3× with 2, 2.3× and 2.4× with 4; the build pays some 15 % more)."""
BINS = 16
"""Bins of the binned SAH, along the longest extent of a node's box centres (binning all three axes built 1.3–1.6×
slower for 1–3 % more nodes visited per ray, measured on the bunny, bunny_like_100k and sphere_1m)."""
PARALLEL_CUTOFF = 16384
"""Subtrees of at most this many triangles (or a sixteenth of them all, if more) are built in parallel, after the
top of the tree."""
_ROBUST = 1.0 + 2.0 * (3.0 * 2.0**-53) / (1.0 - 3.0 * 2.0**-53)
_WIDE = 1.0 + 2.0**-40
"""The best hit's t times this bounds the boxes still searched: a triangle's Möller–Trumbore t may round a few
ulps below its box's entry, and a tie (the same t) must still reach the lower-numbered triangle."""
_TASKS = 4096
WIDTH = 4
"""Children of a node of the traversal tree (``Index.wide_boxes``): the binary tree collapsed, four boxes tested at
once (one AVX2 register of float64 per bound)."""
LEAF_WIDE = 4
"""Most triangles in a leaf of the wide tree: a subtree of at most this many becomes one leaf whose triangles are
tested one after another, instead of a wide node whose boxes are tested first (``_collapse``)."""
SMALL = 8
"""Ranges of at most this many triangles are split by the exact SAH (every cut on every axis) instead of bins."""


class Index(NamedTuple):
    """``boxes`` (N, 12) float64 holding float32 values rounded outward: the boxes of each node's two children (left
    lo, left hi, right lo, right hi);
    ``links`` (N, 2) int64: each child, a node number (>= 0) or a leaf $~(start·8 + count)$; ``triangles``
    (F, 3, 3) float64 corners in leaf order; ``order`` (F,) int64 original index of each; ``depth`` the deepest
    node's depth (the traversal stack's size); ``nodes`` inner nodes built;
    ``wide_boxes`` (M, 6, WIDTH) float32: the same tree collapsed to ``WIDTH`` children a node, the children's
    bounds as rows (lo x y z, hi x y z) of one value per child (an empty slot: lo +inf, hi −inf), and
    ``wide_links`` (M, WIDTH) int64: each child, a wide node number or a leaf code as in ``links``. ``boxes`` and
    ``links`` serve ``cast_pixels`` (whose counts are the binary tree's) and the step-by-step traversal. A leaf
    code of the wide tree holds up to ``LEAF_WIDE`` consecutive rows."""

    boxes: np.ndarray
    links: np.ndarray
    triangles: np.ndarray
    order: np.ndarray
    depth: int
    nodes: int
    wide_boxes: np.ndarray
    wide_links: np.ndarray


# --- build -----------------------------------------------------------------------------------------------------


@parallel_kernel(lambda triangles, *_: triangles.shape[0], grain=32768)
def _prepare(triangles, data, start, stop):
    """Each triangle's bounding box in float32 rounded outward (``data`` rows lo x y z, hi x y z), for
    triangles [start, stop). Outward rounding is monotone, so a union of these boxes is the float64 union
    rounded outward: a node's box never shrinks below its triangles."""
    for f in range(start, stop):
        for a in range(3):
            x0, x1, x2 = triangles[f, 0, a], triangles[f, 1, a], triangles[f, 2, a]
            low = min(x0, x1, x2)
            high = max(x0, x1, x2)
            low32 = np.float32(low)
            if low32 > low:
                low32 = np.nextafter(low32, np.float32(-np.inf))
            high32 = np.float32(high)
            if high32 < high:
                high32 = np.nextafter(high32, np.float32(np.inf))
            data[f, a] = low32
            data[f, 3 + a] = high32


@kernel
def _union(data, s, e, box, at):
    """``box[at : at + 6]`` = the union of ``data[s:e]`` (lo, hi)."""
    for q in range(3):
        box[at + q] = np.inf
        box[at + 3 + q] = -np.inf
    for k in range(s, e):
        for q in range(3):
            if data[k, q] < box[at + q]:
                box[at + q] = data[k, q]
            if data[k, 3 + q] > box[at + 3 + q]:
                box[at + 3 + q] = data[k, 3 + q]


@kernel
def _swap(data, index, i, j):
    for q in range(6):
        data[i, q], data[j, q] = data[j, q], data[i, q]
    index[i], index[j] = index[j], index[i]


@kernel
def _sweep(data, index, s, e, box, keys, order, costs, rows, ids):
    """The exact SAH split of a small range ``[s, e)`` (at most ``SMALL`` triangles): on each axis the triangles
    sorted by box centre (stable), every cut tried; the range is put in the best axis's order and the cut
    returned; `box` receives the two sides' boxes. The rest: scratch."""
    n = e - s
    best_cost = np.inf
    best_axis, best_cut = 0, 1
    for a in range(3):
        for p in range(n):
            keys[p] = np.float64(data[s + p, a]) + np.float64(data[s + p, 3 + a])
            order[a, p] = p
        for p in range(1, n):  # insertion sort (stable)
            item = order[a, p]
            key = keys[item]
            q = p - 1
            while q >= 0 and keys[order[a, q]] > key:
                order[a, q + 1] = order[a, q]
                q -= 1
            order[a, q + 1] = item
        x0, y0, z0, x1, y1, z1 = np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf
        for p in range(n - 1, 0, -1):  # costs[p]: the area of order[p:] times its count
            r = s + order[a, p]
            x0, y0, z0 = min(x0, data[r, 0]), min(y0, data[r, 1]), min(z0, data[r, 2])
            x1, y1, z1 = max(x1, data[r, 3]), max(y1, data[r, 4]), max(z1, data[r, 5])
            dx, dy, dz = np.float64(x1) - x0, np.float64(y1) - y0, np.float64(z1) - z0
            costs[p] = (dx * dy + dy * dz + dz * dx) * (n - p)
        x0, y0, z0, x1, y1, z1 = np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf
        for p in range(1, n):  # cut before order[p]
            r = s + order[a, p - 1]
            x0, y0, z0 = min(x0, data[r, 0]), min(y0, data[r, 1]), min(z0, data[r, 2])
            x1, y1, z1 = max(x1, data[r, 3]), max(y1, data[r, 4]), max(z1, data[r, 5])
            dx, dy, dz = np.float64(x1) - x0, np.float64(y1) - y0, np.float64(z1) - z0
            cost = (dx * dy + dy * dz + dz * dx) * p + costs[p]
            if cost < best_cost:
                best_cost, best_axis, best_cut = cost, a, p
    for p in range(n):
        r = s + order[best_axis, p]
        for q in range(6):
            rows[p, q] = data[r, q]
        ids[p] = index[r]
    for p in range(n):
        for q in range(6):
            data[s + p, q] = rows[p, q]
        index[s + p] = ids[p]
    m = s + best_cut
    _union(data, s, m, box, 0)
    _union(data, m, e, box, 6)
    return m


@kernel
def _split(data, index, s, e, cb, box, child_cb, bins, bin_count, area_right, count_right):
    """The binned SAH split of ``[s, e)`` whose box centres (doubled: lo + hi, float64) lie in `cb` (lo x y z,
    hi x y z), along the axis of their longest extent: partitions ``data[s:e]``/``index[s:e]`` in place and
    returns the cut m (``[s, m)`` the left side); `box` receives the sides' boxes (left lo, hi, right lo, hi) and
    `child_cb` their centre bounds. `bins` (BINS, 6), `bin_count`, `area_right`, `count_right`: scratch."""
    w0, w1, w2 = cb[3] - cb[0], cb[4] - cb[1], cb[5] - cb[2]
    a = 0 if w0 >= w1 and w0 >= w2 else (1 if w1 >= w2 else 2)
    width = cb[3 + a] - cb[a]
    if not width > 0.0:  # all centres coincide: cut in the middle
        m = (s + e) // 2
        _union(data, s, m, box, 0)
        _union(data, m, e, box, 6)
        for q in range(6):
            child_cb[q] = cb[q]
            child_cb[6 + q] = cb[q]
        return m
    scale = BINS * (1.0 - 1e-9) / width
    low = cb[a]
    for b in range(BINS):
        bin_count[b] = 0
        for q in range(3):
            bins[b, q] = np.inf
            bins[b, 3 + q] = -np.inf
    for k in range(s, e):
        b = int((np.float64(data[k, a]) + np.float64(data[k, 3 + a]) - low) * scale)
        if b >= BINS:
            b = BINS - 1
        bin_count[b] += 1
        for q in range(3):
            if data[k, q] < bins[b, q]:
                bins[b, q] = data[k, q]
            if data[k, 3 + q] > bins[b, 3 + q]:
                bins[b, 3 + q] = data[k, 3 + q]
    bx0, by0, bz0, bx1, by1, bz1 = np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf
    n = 0
    for b in range(BINS - 1, 0, -1):  # area_right[b]: bins b … BINS − 1
        if bin_count[b] > 0:
            bx0, by0, bz0 = min(bx0, bins[b, 0]), min(by0, bins[b, 1]), min(bz0, bins[b, 2])
            bx1, by1, bz1 = max(bx1, bins[b, 3]), max(by1, bins[b, 4]), max(bz1, bins[b, 5])
            n += bin_count[b]
        dx, dy, dz = bx1 - bx0, by1 - by0, bz1 - bz0
        area_right[b] = dx * dy + dy * dz + dz * dx if n > 0 else 0.0
        count_right[b] = n
    best_cost = np.inf
    best_bin = BINS // 2 - 1
    bx0, by0, bz0, bx1, by1, bz1 = np.inf, np.inf, np.inf, -np.inf, -np.inf, -np.inf
    n = 0
    for b in range(BINS - 1):  # split between bins b and b + 1
        if bin_count[b] > 0:
            bx0, by0, bz0 = min(bx0, bins[b, 0]), min(by0, bins[b, 1]), min(bz0, bins[b, 2])
            bx1, by1, bz1 = max(bx1, bins[b, 3]), max(by1, bins[b, 4]), max(bz1, bins[b, 5])
            n += bin_count[b]
        if n == 0 or count_right[b + 1] == 0:
            continue
        dx, dy, dz = bx1 - bx0, by1 - by0, bz1 - bz0
        cost = (dx * dy + dy * dz + dz * dx) * n + area_right[b + 1] * count_right[b + 1]
        if cost < best_cost:
            best_cost, best_bin = cost, b
    for q in range(3):
        child_cb[q] = np.inf
        child_cb[3 + q] = -np.inf
        child_cb[6 + q] = np.inf
        child_cb[9 + q] = -np.inf
    i, j = s, e - 1
    while i <= j:  # partition: bins <= best_bin to the left; each side's centre bounds on the way
        b = int((np.float64(data[i, a]) + np.float64(data[i, 3 + a]) - low) * scale)
        if b <= best_bin:
            at = 0
            r = i
            i += 1
        else:
            _swap(data, index, i, j)
            at = 6
            r = j
            j -= 1
        for q in range(3):
            c = np.float64(data[r, q]) + np.float64(data[r, 3 + q])
            if c < child_cb[at + q]:
                child_cb[at + q] = c
            if c > child_cb[at + 3 + q]:
                child_cb[at + 3 + q] = c
    m = i
    for q in range(3):
        box[q], box[3 + q], box[6 + q], box[9 + q] = np.inf, -np.inf, np.inf, -np.inf
    for b in range(BINS):
        if bin_count[b] == 0:
            continue
        at = 0 if b <= best_bin else 6
        for q in range(3):
            box[at + q] = min(box[at + q], bins[b, q])
            box[at + 3 + q] = max(box[at + 3 + q], bins[b, 3 + q])
    if m in (s, e):  # (cannot happen: the extreme centres fall in the first and the last bin) a middle cut
        m = (s + e) // 2
        _union(data, s, m, box, 0)
        _union(data, m, e, box, 6)
        for q in range(6):
            child_cb[q] = cb[q]
            child_cb[6 + q] = cb[q]
    return m


@kernel
def _build_from(data, index, root_slot, root_s, root_e, root_depth, root_cb, boxes, links, cutoff, tasks, task_cb):
    """Build the subtree over ``[root_s, root_e)`` (> LEAF_SIZE triangles, centre bounds `root_cb`) at node
    `root_slot`. With `cutoff` > 0, inner subtrees of at most `cutoff` triangles are appended to `tasks` (rows
    slot, s, e, depth; row 0 column 0 counts them; their centre bounds in `task_cb`) instead of being built,
    while there is room. Returns (deepest depth, nodes)."""
    bins = np.empty((BINS, 6), dtype=np.float32)  # each bin's box: lo, hi
    bin_count = np.empty(BINS, dtype=np.int64)
    area_right = np.empty(BINS)
    count_right = np.empty(BINS, dtype=np.int64)
    keys = np.empty(SMALL)
    order = np.empty((3, SMALL), dtype=np.int64)
    rows = np.empty((SMALL, 6), dtype=np.float32)
    ids = np.empty(SMALL, dtype=np.int64)
    box = np.empty(12, dtype=np.float32)
    child_cb = np.empty(12)
    stack = np.empty((256, 4), dtype=np.int64)
    stack_cb = np.empty((256, 6))
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = root_slot, root_s, root_e, root_depth
    stack_cb[0] = root_cb
    if np.isnan(root_cb[0]):  # the root: its centre bounds
        for q in range(3):
            stack_cb[0, q] = np.inf
            stack_cb[0, 3 + q] = -np.inf
        for k in range(root_s, root_e):
            for q in range(3):
                c = np.float64(data[k, q]) + np.float64(data[k, 3 + q])
                stack_cb[0, q] = min(stack_cb[0, q], c)
                stack_cb[0, 3 + q] = max(stack_cb[0, 3 + q], c)
    top = 1
    deepest = root_depth
    built = 0
    while top > 0:
        top -= 1
        slot, s, e, depth = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3]
        built += 1
        n = e - s
        if n == 2:
            m = s + 1
            _union(data, s, m, box, 0)
            _union(data, m, e, box, 6)
        elif n <= SMALL:
            m = _sweep(data, index, s, e, box, keys, order, area_right, rows, ids)
        else:
            m = _split(data, index, s, e, stack_cb[top], box, child_cb, bins, bin_count, area_right, count_right)
        for q in range(12):
            boxes[slot, q] = box[q]
        if depth + 1 > deepest:
            deepest = depth + 1
        for side in range(2):
            cs, ce = (s, m) if side == 0 else (m, e)
            child = slot + 1 if side == 0 else slot + (m - s)
            if ce - cs <= LEAF_SIZE:
                links[slot, side] = ~(cs * 8 + (ce - cs))
                continue
            links[slot, side] = child
            if cutoff > 0 and ce - cs <= cutoff and tasks[0, 0] + 1 < tasks.shape[0]:
                tasks[0, 0] += 1
                row = tasks[0, 0]
                tasks[row, 0], tasks[row, 1], tasks[row, 2], tasks[row, 3] = child, cs, ce, depth + 1
                for q in range(6):
                    task_cb[row, q] = child_cb[6 * side + q]
                continue
            if top == stack.shape[0]:
                grown = np.empty((2 * top, 4), dtype=np.int64)
                grown[:top] = stack
                stack = grown
                grown_cb = np.empty((2 * top, 6))
                grown_cb[:top] = stack_cb
                stack_cb = grown_cb
            stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = child, cs, ce, depth + 1
            for q in range(6):
                stack_cb[top, q] = child_cb[6 * side + q]
            top += 1
    return deepest, built


@parallel_kernel(lambda data, index, tasks, *_: tasks.shape[0], pieces_per_thread=16)
def _build_tasks(data, index, tasks, task_cb, boxes, links, results, start, stop):
    """``_build_from`` for each task row (slot, s, e, depth; centre bounds `task_cb`); (deepest, nodes) into
    `results`."""
    none = np.zeros((1, 4), dtype=np.int64)
    none_cb = np.zeros((1, 6))
    for r in range(start, stop):
        results[r, 0], results[r, 1] = _build_from(data, index, tasks[r, 0], tasks[r, 1], tasks[r, 2], tasks[r, 3],
                                                   task_cb[r], boxes, links, 0, none, none_cb)  # fmt: skip


@parallel_kernel(lambda triangles, index, *_: index.shape[0], grain=32768)
def _gather(triangles, index, out, start, stop):
    """``out[k] = triangles[index[k]]`` for k in [start, stop)."""
    for k in range(start, stop):
        f = index[k]
        for i in range(3):
            for a in range(3):
                out[k, i, a] = triangles[f, i, a]


@kernel
def _subtrees(links, size, first):
    """``size[k]``, ``first[k]``: the triangles under binary node k and the first of their rows (a subtree's
    triangles are the rows ``[first, first + size)``; 0 for a number no node holds). Children are numbered above
    their parent: marked reachable from the root going up, summed going down."""
    size[:] = 0
    size[0] = 1
    for k in range(links.shape[0]):
        if size[k] != 0:
            for side in range(2):
                if links[k, side] >= 0:
                    size[links[k, side]] = 1
    for k in range(links.shape[0] - 1, -1, -1):
        if size[k] == 0:
            continue
        total = 0
        for side in range(2):
            link = links[k, side]
            if link >= 0:
                total += size[link]
                start = first[link]
            else:
                total += ~link & 7
                start = ~link >> 3
            if side == 0:
                first[k] = start
        size[k] = total


@kernel
def _collapse(boxes, links, depth, leaf_wide, wide_boxes, wide_links):
    """The binary tree (``boxes``, ``links``) collapsed into ``WIDTH``-wide nodes: from each node's two children,
    the inner child of the largest surface area is replaced by its own two children while fewer than ``WIDTH``
    are held and an inner one is left (the order of the children kept); every inner child left becomes a wide node
    of its own (numbered depth first), unless it holds at most `leaf_wide` triangles: then it becomes one leaf
    of them all (tested one after another, no box of its own). Fills ``wide_boxes``/``wide_links``; returns the
    wide nodes made. (A node with fewer than ``WIDTH`` children has leaves only, so at most $(2F − 1)/3 + 1$ nodes
    for F triangles.)"""
    size = np.empty(links.shape[0], dtype=np.int64)
    first = np.empty(links.shape[0], dtype=np.int64)
    _subtrees(links, size, first)
    child = np.empty(WIDTH, dtype=np.int64)
    box = np.empty((WIDTH, 6))
    stack = np.empty((3 * depth + 8, 2), dtype=np.int64)  # (binary node, its wide slot)
    stack[0, 0], stack[0, 1] = 0, 0
    top = 1
    made = 1
    while top > 0:
        top -= 1
        b, w = stack[top, 0], stack[top, 1]
        n = 2
        for side in range(2):
            child[side] = links[b, side]
            for q in range(6):
                box[side, q] = boxes[b, 6 * side + q]
        while n < WIDTH:
            best, best_area = -1, -1.0
            for c in range(n):
                if child[c] >= 0:
                    dx, dy, dz = box[c, 3] - box[c, 0], box[c, 4] - box[c, 1], box[c, 5] - box[c, 2]
                    area = dx * dy + dy * dz + dz * dx
                    if area > best_area:
                        best, best_area = c, area
            if best < 0:
                break
            k = child[best]
            for c in range(n, best + 1, -1):  # its two children take its slot and the next
                child[c] = child[c - 1]
                for q in range(6):
                    box[c, q] = box[c - 1, q]
            for side in range(2):
                child[best + side] = links[k, side]
                for q in range(6):
                    box[best + side, q] = boxes[k, 6 * side + q]
            n += 1
        for c in range(WIDTH):
            if c < n:
                for q in range(6):
                    wide_boxes[w, q, c] = box[c, q]
                if child[c] >= 0 and size[child[c]] <= leaf_wide:
                    wide_links[w, c] = ~(first[child[c]] * 8 + size[child[c]])
                elif child[c] >= 0:
                    wide_links[w, c] = made
                    stack[top, 0], stack[top, 1] = child[c], made
                    top += 1
                    made += 1
                else:
                    wide_links[w, c] = child[c]
            else:
                for q in range(3):
                    wide_boxes[w, q, c] = np.inf
                    wide_boxes[w, 3 + q, c] = -np.inf
                wide_links[w, c] = ~0
    return made


def _wide_nodes(count: int) -> int:
    """Most wide nodes for `count` triangles (``_collapse``)."""
    return (2 * count) // 3 + 2


def build(triangles: np.ndarray, leaf_wide: int = LEAF_WIDE) -> Index:
    """The index of (F, 3, 3) float64 triangles (corner rows), F >= 1; `leaf_wide` (1 … 7): the most triangles in
    a leaf of the wide tree (``LEAF_WIDE``; the hits are the same for any)."""
    if not 1 <= leaf_wide <= 7:  # a leaf code holds its count in three bits
        raise ValueError(f"build: leaf_wide = {leaf_wide!r}; expected 1 … 7")
    tri = np.ascontiguousarray(triangles, dtype=np.float64)
    count = tri.shape[0]
    data = np.empty((count, 6), dtype=np.float32)
    _prepare(tri, data)
    index = np.arange(count, dtype=np.int64)
    slots = max(1, count - 1)
    boxes = np.empty((slots, 12))  # float32 values (rounded outward) held as float64: no conversions per test
    links = np.empty((slots, 2), dtype=np.int64)
    if count <= LEAF_SIZE:  # one node: the leaf on the left, an empty box on the right
        boxes[0, 0:3] = data[:, :3].min(axis=0)
        boxes[0, 3:6] = data[:, 3:].max(axis=0)
        boxes[0, 6:9] = np.inf
        boxes[0, 9:12] = -np.inf
        links[0, 0] = ~np.int64(count)
        links[0, 1] = ~np.int64(0)  # ~0: an empty leaf
        depth, nodes = 1, 1
    else:
        root_cb = np.full(6, np.nan)  # NaN: found by _build_from
        cutoff = max(PARALLEL_CUTOFF, count // 16) if count > 2 * PARALLEL_CUTOFF else 0
        tasks = np.zeros((_TASKS if cutoff else 1, 4), dtype=np.int64)
        task_cb = np.zeros((tasks.shape[0], 6))
        depth, nodes = _build_from(data, index, 0, 0, count, 0, root_cb, boxes, links, cutoff, tasks, task_cb)
        found = int(tasks[0, 0])
        if found:
            rank = np.argsort(tasks[1 : found + 1, 1] - tasks[1 : found + 1, 2], kind="stable") + 1  # largest first
            work = np.ascontiguousarray(tasks[rank])
            results = np.zeros((found, 2), dtype=np.int64)
            _build_tasks(data, index, work, np.ascontiguousarray(task_cb[rank]), boxes, links, results)
            depth = max(depth, int(results[:, 0].max()))
            nodes += int(results[:, 1].sum())
    del data
    ordered = np.empty_like(tri)
    _gather(tri, index, ordered)
    wide_boxes = np.empty((_wide_nodes(count), 6, WIDTH), dtype=np.float32)
    wide_links = np.empty((wide_boxes.shape[0], WIDTH), dtype=np.int64)
    made = _collapse(boxes, links, int(depth), int(leaf_wide), wide_boxes, wide_links)
    return Index(boxes, links, ordered, index, int(depth), int(nodes), wide_boxes[:made].copy(),
                 wide_links[:made].copy())  # (copies: the unused rows' memory goes back)


def memory_bytes(count: int) -> int:
    """Bytes ``build`` holds at its peak for `count` triangles: float32 boxes while building (24), the order (8),
    the triangles in leaf order (72), per node the boxes (96) and the links (16), and per wide node (at most
    ``_wide_nodes``) its float32 boxes (24·WIDTH) and links (8·WIDTH)."""
    return count * (24 + 8 + 72) + max(1, count - 1) * (96 + 16) + _wide_nodes(count) * 32 * WIDTH


# --- traversal -------------------------------------------------------------------------------------------------


@kernel
def _reciprocal(dx, dy, dz):
    """A ray's reciprocal direction (inf for a zero component) and the rows of the bounds it enters first
    (0/3, 1/4, 2/5 by its signs): ``(ix, iy, iz, nx, ny, nz)``, what every traversal's slab tests read."""
    ix = 1.0 / dx if dx != 0.0 else np.inf
    iy = 1.0 / dy if dy != 0.0 else np.inf
    iz = 1.0 / dz if dz != 0.0 else np.inf
    return ix, iy, iz, 0 if ix >= 0.0 else 3, 1 if iy >= 0.0 else 4, 2 if iz >= 0.0 else 5


@kernel
def _slab(x0, y0, z0, x1, y1, z1, ox, oy, oz, ix, iy, iz, t_min, reach):
    """Where the ray enters the box within [t_min, reach] (inf: it misses), from the bounds it enters first
    (x0, y0, z0) and last (x1 …): the slab test $t = (b − o)·(1/d)$, the far distances widened by
    $1 + 2γ₃$ (``_ROBUST``, PBRT 3.9.2) so that rounding never loses a box."""
    t0, t1 = t_min, reach
    a0, b0, g0 = (x0 - ox) * ix, (y0 - oy) * iy, (z0 - oz) * iz
    t0 = a0 if a0 > t0 else t0
    t0 = b0 if b0 > t0 else t0
    t0 = g0 if g0 > t0 else t0
    a1, b1, g1 = (x1 - ox) * ix * _ROBUST, (y1 - oy) * iy * _ROBUST, (z1 - oz) * iz * _ROBUST
    t1 = a1 if a1 < t1 else t1
    t1 = b1 if b1 < t1 else t1
    t1 = g1 if g1 < t1 else t1
    return t0 if t0 <= t1 else np.inf


@kernel
def _triangle(triangles, row, ox, oy, oz, dx, dy, dz):
    """Möller–Trumbore of one ray and triangle ``triangles[row]``: ``(t, u, v, det)`` (det = 0: no hit; the one
    ray–triangle arithmetic of every traversal here, which ``tests/test_rays.py``'s brute force repeats)."""
    ax, ay, az = triangles[row, 0, 0], triangles[row, 0, 1], triangles[row, 0, 2]
    e1x, e1y, e1z = triangles[row, 1, 0] - ax, triangles[row, 1, 1] - ay, triangles[row, 1, 2] - az
    e2x, e2y, e2z = triangles[row, 2, 0] - ax, triangles[row, 2, 1] - ay, triangles[row, 2, 2] - az
    px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
    det = e1x * px + e1y * py + e1z * pz
    if det == 0.0:
        return 0.0, 0.0, 0.0, 0.0
    inv = 1.0 / det
    sx, sy, sz = ox - ax, oy - ay, oz - az
    u = (sx * px + sy * py + sz * pz) * inv
    if u < 0.0 or u > 1.0:
        return 0.0, 0.0, 0.0, 0.0
    qx, qy, qz = sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x
    v = (dx * qx + dy * qy + dz * qz) * inv
    if v < 0.0 or u + v > 1.0:
        return 0.0, 0.0, 0.0, 0.0
    return (e2x * qx + e2y * qy + e2z * qz) * inv, u, v, det


def _splat(builder, value):
    """LLVM IR: a vector of ``WIDTH`` copies of scalar `value` (insert into lane 0, shuffle to all)."""
    vector = ir.VectorType(value.type, WIDTH)
    one = builder.insert_element(ir.Constant(vector, ir.Undefined), value, ir.Constant(ir.IntType(32), 0))
    return builder.shuffle_vector(one, ir.Constant(vector, ir.Undefined),
                                  ir.Constant(ir.VectorType(ir.IntType(32), WIDTH), [0] * WIDTH))  # fmt: skip


@intrinsic
def _triangles4_vector(typingctx, triangles, first, count, ox, oy, oz, dx, dy, dz, out):
    """``_triangles4`` as LLVM vector code: the corners of rows ``first`` … ``first + 3`` loaded into
    ``<4 x double>`` lanes (a lane past `count` repeats row `first` and is masked), then ``_triangle``'s
    arithmetic operation for operation on the four at once (IEEE: the same bytes), its rejections as a mask."""

    def codegen(context, builder, signature, args):  # (its preamble as _slab4_vector's: kept on purpose, per intrinsic)
        kind = signature.args[0]
        data = context.make_array(kind)(context, builder, args[0])
        result = context.make_array(signature.args[9])(context, builder, args[9])
        double = ir.DoubleType()
        vector = ir.VectorType(double, WIDTH)
        shape = cgutils.unpack_tuple(builder, data.shape)
        strides = cgutils.unpack_tuple(builder, data.strides)
        start = context.cast(builder, args[1], signature.args[1], types.intp)
        count = context.cast(builder, args[2], signature.args[2], types.intp)
        index = ir.IntType(64)
        rows = []
        for lane in range(WIDTH):
            there = builder.icmp_signed("<", ir.Constant(index, lane), count)
            rows.append(builder.select(there, builder.add(start, ir.Constant(index, lane)), start))

        def column(corner, axis):
            value = ir.Constant(vector, ir.Undefined)
            for lane in range(WIDTH):
                pointer = cgutils.get_item_pointer2(context, builder, data.data, shape, strides, kind.layout,
                                                    [rows[lane], ir.Constant(index, corner), ir.Constant(index, axis)],
                                                    wraparound=False)  # fmt: skip
                value = builder.insert_element(value, builder.load(pointer), ir.Constant(ir.IntType(32), lane))
            return value

        def splat(value):
            return _splat(builder, value)

        mul, sub, add = builder.fmul, builder.fsub, builder.fadd
        o = [splat(args[3 + a]) for a in range(3)]
        d = [splat(args[6 + a]) for a in range(3)]
        a = [column(0, q) for q in range(3)]
        e1 = [sub(column(1, q), a[q]) for q in range(3)]
        e2 = [sub(column(2, q), a[q]) for q in range(3)]
        p = [sub(mul(d[1], e2[2]), mul(d[2], e2[1])), sub(mul(d[2], e2[0]), mul(d[0], e2[2])),
             sub(mul(d[0], e2[1]), mul(d[1], e2[0]))]  # fmt: skip
        det = add(add(mul(e1[0], p[0]), mul(e1[1], p[1])), mul(e1[2], p[2]))
        zero, one = splat(ir.Constant(double, 0.0)), splat(ir.Constant(double, 1.0))
        inv = builder.fdiv(one, det)
        sv = [sub(o[q], a[q]) for q in range(3)]
        u = mul(add(add(mul(sv[0], p[0]), mul(sv[1], p[1])), mul(sv[2], p[2])), inv)
        qv = [sub(mul(sv[1], e1[2]), mul(sv[2], e1[1])), sub(mul(sv[2], e1[0]), mul(sv[0], e1[2])),
              sub(mul(sv[0], e1[1]), mul(sv[1], e1[0]))]  # fmt: skip
        v = mul(add(add(mul(d[0], qv[0]), mul(d[1], qv[1])), mul(d[2], qv[2])), inv)
        t = mul(add(add(mul(e2[0], qv[0]), mul(e2[1], qv[1])), mul(e2[2], qv[2])), inv)
        lanes = ir.Constant(ir.VectorType(index, WIDTH), list(range(WIDTH)))
        miss = builder.icmp_signed(">=", lanes, splat(count))
        for test in (builder.fcmp_ordered("==", det, zero), builder.fcmp_ordered("<", u, zero),
                     builder.fcmp_ordered(">", u, one), builder.fcmp_ordered("<", v, zero),
                     builder.fcmp_ordered(">", add(u, v), one)):  # fmt: skip
            miss = builder.or_(miss, test)
        for row, value in enumerate((t, u, v, det)):
            pointer = cgutils.get_item_pointer2(context, builder, result.data,
                                                cgutils.unpack_tuple(builder, result.shape),
                                                cgutils.unpack_tuple(builder, result.strides), signature.args[9].layout,
                                                [ir.Constant(index, row), ir.Constant(index, 0)],
                                                wraparound=False)  # fmt: skip
            builder.store(builder.select(miss, zero, value), builder.bitcast(pointer, vector.as_pointer()), align=8)
        return context.get_dummy_value()

    return types.void(triangles, first, count, ox, oy, oz, dx, dy, dz, out), codegen


def _triangles4_scalar(triangles, first, count, ox, oy, oz, dx, dy, dz, out):
    """``out[:, c]`` = ``_triangle`` of row ``first + c`` as (t, u, v, det) for c < `count` (<= ``WIDTH``),
    zeros (det 0: no hit) past it."""
    for c in range(WIDTH):
        out[0, c], out[1, c], out[2, c], out[3, c] = 0.0, 0.0, 0.0, 0.0
        if c < count:
            out[0, c], out[1, c], out[2, c], out[3, c] = _triangle(triangles, first + c, ox, oy, oz, dx, dy, dz)


_triangles4 = _triangles4_scalar if numba.config.DISABLE_JIT else _triangles4_vector
"""``_triangles4(triangles, first, count, ox, oy, oz, dx, dy, dz, out)`` in a kernel: Möller–Trumbore of the ray
and up to ``WIDTH`` consecutive rows at once into `out` (4, ``WIDTH``): rows t, u, v, det (det 0: no hit)."""


@kernel
def _nearer(t, face, t_min, best, best_face):
    """Whether a hit at t on `face` replaces the best so far: t >= t_min and nearer, a tie to the lower face."""
    return t >= t_min and (t < best or (t == best and face < best_face))


@kernel
def _pop(stack, entry, top, reach, node):
    """The next pushed node whose box entry is still within `reach` (the best hit so far, widened):
    ``(found, node, top)``; not found: the stack is spent (`node` returned as given)."""
    while top > 0:
        top -= 1
        if entry[top] <= reach:
            return True, stack[top], top
    return False, node, top


@kernel
def _closest(boxes, links, triangles, order, skip, ox, oy, oz, dx, dy, dz, t_min, t_max, cull, stack, entry):
    """The first hit of one ray: ``(t, row, u, v, back, box_tests, nodes, tests)``.

    The least t in [t_min, t_max) over the triangles (ties: the lower original index ``order[row]``), skipping
    ``skip[order[row]] != 0`` (`skip` empty: none) and, when `cull`, back faces (Möller–Trumbore's determinant
    $e1·(d × e2) = −d·N$ negative). u, v: the weights of corners 1 and 2; back = 1 for a back face; a miss
    is (inf, −1, …). Counts: box (slab) tests, nodes visited (inner nodes and leaves entered), ray–triangle
    tests. `stack`, `entry`: scratch of at least the index's depth + 1.
    """
    ix, iy, iz, nx, ny, nz = _reciprocal(dx, dy, dz)
    masked = skip.shape[0] > 0
    best = t_max
    reach = t_max
    best_row = -1
    best_face = -1
    best_u, best_v, best_back = 0.0, 0.0, 0
    box_tests, nodes, tests = 0, 0, 0
    node = 0
    top = 0
    while True:
        nodes += 1
        if node >= 0:
            box_tests += 2
            t_near0 = _slab(boxes[node, nx], boxes[node, ny], boxes[node, nz], boxes[node, 3 - nx],
                            boxes[node, 5 - ny], boxes[node, 7 - nz], ox, oy, oz, ix, iy, iz, t_min,
                            reach)  # fmt: skip
            t_near1 = _slab(boxes[node, 6 + nx], boxes[node, 6 + ny], boxes[node, 6 + nz], boxes[node, 9 - nx],
                            boxes[node, 11 - ny], boxes[node, 13 - nz], ox, oy, oz, ix, iy, iz, t_min,
                            reach)  # fmt: skip
            left, right = links[node, 0], links[node, 1]
            swap = t_near1 < t_near0  # selects, not branches: the order is a coin toss for the predictor
            if (t_near1 if swap else t_near0) < np.inf:  # the nearer child now, the other one pushed if met
                far = t_near0 if swap else t_near1
                stack[top] = left if swap else right
                entry[top] = far
                top += 1 if far < np.inf else 0
                node = right if swap else left
                continue
        else:
            code = ~node
            first = code >> 3
            for row in range(first, first + (code & 7)):
                face = order[row]
                if masked and skip[face] != 0:
                    continue
                tests += 1
                t, u, v, det = _triangle(triangles, row, ox, oy, oz, dx, dy, dz)
                if det == 0.0 or (cull != 0 and det < 0.0):
                    continue
                if _nearer(t, face, t_min, best, best_face):
                    best, best_row, best_face, best_u, best_v = t, row, face, u, v
                    best_back = 1 if det < 0.0 else 0
                    reach = best * _WIDE
        popped, node, top = _pop(stack, entry, top, reach, node)
        if not popped:
            break
    if best_row < 0:
        best = np.inf
    return best, best_row, best_u, best_v, best_back, box_tests, nodes, tests


@kernel
def _any(boxes, links, triangles, ox, oy, oz, dx, dy, dz, t_min, t_max, stack):
    """Whether one ray meets any triangle at t in [t_min, t_max) (Möller–Trumbore as in ``_closest``; back faces
    count): the traversal stops at the first such triangle."""
    ix, iy, iz, nx, ny, nz = _reciprocal(dx, dy, dz)
    node = 0
    top = 0
    while True:
        if node >= 0:
            near0 = _slab(boxes[node, nx], boxes[node, ny], boxes[node, nz], boxes[node, 3 - nx], boxes[node, 5 - ny],
                          boxes[node, 7 - nz], ox, oy, oz, ix, iy, iz, t_min, t_max)  # fmt: skip
            near1 = _slab(boxes[node, 6 + nx], boxes[node, 6 + ny], boxes[node, 6 + nz], boxes[node, 9 - nx],
                          boxes[node, 11 - ny], boxes[node, 13 - nz], ox, oy, oz, ix, iy, iz, t_min, t_max)  # fmt: skip
            left, right = links[node, 0], links[node, 1]
            swap = near1 < near0
            if (near1 if swap else near0) < np.inf:
                stack[top] = left if swap else right
                top += 1 if (near0 if swap else near1) < np.inf else 0
                node = right if swap else left
                continue
        else:
            code = ~node
            first = code >> 3
            for row in range(first, first + (code & 7)):
                t, _, _, det = _triangle(triangles, row, ox, oy, oz, dx, dy, dz)
                if det == 0.0:
                    continue
                if t >= t_min and t < t_max:
                    return True
        if top == 0:
            return False
        top -= 1
        node = stack[top]


@intrinsic
def _slab4_vector(typingctx, boxes, node, nx, ny, nz, ox, oy, oz, ix, iy, iz, t_min, reach, near):
    """``_slab4`` as LLVM vector code: each bound row of the node is one load of four float32 widened to float64
    (``<4 x double>``, one AVX2 register), and the arithmetic, compares and selects are ``_slab4_scalar``'s
    operation for operation (IEEE: the same bytes), on all four children at once."""

    def codegen(context, builder, signature, args):  # (its preamble as _triangles4_vector's: kept on purpose)
        kind = signature.args[0]
        data = context.make_array(kind)(context, builder, args[0])
        out = context.make_array(signature.args[13])(context, builder, args[13])
        double = ir.DoubleType()
        vector = ir.VectorType(double, WIDTH)
        lanes = ir.VectorType(ir.FloatType() if kind.dtype == types.float32 else double, WIDTH)
        shape = cgutils.unpack_tuple(builder, data.shape)
        strides = cgutils.unpack_tuple(builder, data.strides)
        at = context.cast(builder, args[1], signature.args[1], types.intp)
        zero = ir.Constant(ir.IntType(64), 0)

        def row(number):
            pointer = cgutils.get_item_pointer2(context, builder, data.data, shape, strides, kind.layout,
                                                [at, number, zero], wraparound=False)  # fmt: skip
            value = builder.load(builder.bitcast(pointer, lanes.as_pointer()), align=4)
            return value if lanes is vector or kind.dtype != types.float32 else builder.fpext(value, vector)

        def splat(value):
            return _splat(builder, value)

        near_rows = [context.cast(builder, args[2 + a], signature.args[2 + a], types.intp) for a in range(3)]
        far_rows = [builder.sub(ir.Constant(ir.IntType(64), 3 + 2 * a), near_rows[a]) for a in range(3)]
        origin = [splat(args[5 + a]) for a in range(3)]
        inverse = [splat(args[8 + a]) for a in range(3)]
        robust = splat(ir.Constant(double, _ROBUST))
        t0, t1 = splat(args[11]), splat(args[12])
        for a in range(3):
            low = builder.fmul(builder.fsub(row(near_rows[a]), origin[a]), inverse[a])
            t0 = builder.select(builder.fcmp_ordered(">", low, t0), low, t0)
        for a in range(3):
            high = builder.fmul(builder.fmul(builder.fsub(row(far_rows[a]), origin[a]), inverse[a]), robust)
            t1 = builder.select(builder.fcmp_ordered("<", high, t1), high, t1)
        met = builder.fcmp_ordered("<=", t0, t1)
        result = builder.select(met, t0, splat(ir.Constant(double, np.inf)))
        builder.store(result, builder.bitcast(out.data, vector.as_pointer()), align=8)
        return context.get_dummy_value()

    return types.void(boxes, node, nx, ny, nz, ox, oy, oz, ix, iy, iz, t_min, reach, near), codegen


def _slab4_scalar(boxes, node, nx, ny, nz, ox, oy, oz, ix, iy, iz, t_min, reach, near):
    """``near[c]`` = where the ray enters child c's box of wide node `node` within [t_min, reach] (inf: it
    misses): ``_slab`` on one child after another."""
    for c in range(WIDTH):
        near[c] = _slab(np.float64(boxes[node, nx, c]), np.float64(boxes[node, ny, c]), np.float64(boxes[node, nz, c]),
                        np.float64(boxes[node, 3 - nx, c]), np.float64(boxes[node, 5 - ny, c]),
                        np.float64(boxes[node, 7 - nz, c]), ox, oy, oz, ix, iy, iz, t_min, reach)  # fmt: skip


_slab4 = _slab4_scalar if numba.config.DISABLE_JIT else _slab4_vector
"""``_slab4(wide_boxes, node, nx, ny, nz, ox, oy, oz, ix, iy, iz, t_min, reach, near)`` in a kernel: the entry
distances of a wide node's ``WIDTH`` children into ``near`` (inf where missed); ``nx`` … the rows of the
bounds the ray enters first (0/3, 1/4, 2/5 by the signs of its direction)."""


@kernel
def _closest4(wide_boxes, wide_links, triangles, order, skip, ox, oy, oz, dx, dy, dz, t_min, t_max, cull, stack, entry,
              near, found):  # fmt: skip
    """``_closest`` on the wide tree: ``(t, row, u, v, back)``, the same hit to the byte (the least t, ties to
    the lower original index, is one triangle whatever the order the boxes are searched in). At a node the
    ``WIDTH`` boxes are tested at once (``_slab4``) and the children met are pushed sorted by entry distance,
    the nearest on top (popped next); a popped entry beyond the best hit so far is skipped; a leaf's triangles are
    tested four at once (``_triangles4``). `stack`, `entry`: scratch of at least 3·depth + 2, `near` of
    ``WIDTH``, `found` (4, ``WIDTH``)."""
    ix, iy, iz, nx, ny, nz = _reciprocal(dx, dy, dz)
    masked = skip.shape[0] > 0
    best = t_max
    reach = t_max
    best_row = -1
    best_face = -1
    best_u, best_v, best_back = 0.0, 0.0, 0
    node = 0
    top = 0
    while True:
        if node >= 0:
            _slab4(wide_boxes, node, nx, ny, nz, ox, oy, oz, ix, iy, iz, t_min, reach, near)
            k = top
            for c in range(WIDTH):
                d = near[c]
                if d < np.inf:  # insert, keeping [top, k) sorted by entry, the nearest last
                    j = k
                    while j > top and entry[j - 1] < d:
                        entry[j] = entry[j - 1]
                        stack[j] = stack[j - 1]
                        j -= 1
                    entry[j] = d
                    stack[j] = wide_links[node, c]
                    k += 1
            if k > top:
                top = k - 1
                node = stack[top]
                continue
        else:
            code = ~node
            for first in range(code >> 3, (code >> 3) + (code & 7), WIDTH):
                _triangles4(triangles, first, (code >> 3) + (code & 7) - first, ox, oy, oz, dx, dy, dz, found)
                for c in range(WIDTH):
                    det = found[3, c]
                    if det == 0.0 or (cull != 0 and det < 0.0):
                        continue
                    row = first + c
                    face = order[row]
                    if masked and skip[face] != 0:
                        continue
                    t, u, v = found[0, c], found[1, c], found[2, c]
                    if _nearer(t, face, t_min, best, best_face):
                        best, best_row, best_face, best_u, best_v = t, row, face, u, v
                        best_back = 1 if det < 0.0 else 0
                        reach = best * _WIDE
        popped, node, top = _pop(stack, entry, top, reach, node)
        if not popped:
            break
    if best_row < 0:
        best = np.inf
    return best, best_row, best_u, best_v, best_back


@kernel
def _any4(wide_boxes, wide_links, triangles, ox, oy, oz, dx, dy, dz, t_min, t_max, stack, near, found):
    """``_any`` on the wide tree: whether one ray meets a triangle at t in [t_min, t_max): the inner children
    met are pushed in their order, the leaves met tested at once; the traversal stops at the first triangle
    found."""
    ix, iy, iz, nx, ny, nz = _reciprocal(dx, dy, dz)
    node = 0
    top = 0
    while True:
        if node >= 0:
            _slab4(wide_boxes, node, nx, ny, nz, ox, oy, oz, ix, iy, iz, t_min, t_max, near)
            for c in range(WIDTH):
                if near[c] < np.inf:
                    child = wide_links[node, c]
                    if child >= 0:
                        stack[top] = child
                        top += 1
                        continue
                    code = ~child  # a leaf: its triangles now, not pushed
                    for first in range(code >> 3, (code >> 3) + (code & 7), WIDTH):
                        _triangles4(triangles, first, (code >> 3) + (code & 7) - first, ox, oy, oz, dx, dy, dz,
                                    found)  # fmt: skip
                        for k in range(WIDTH):
                            t = found[0, k]
                            if found[3, k] != 0.0 and t >= t_min and t < t_max:
                                return True
        if top == 0:
            return False
        top -= 1
        node = stack[top]


# small pieces (16 per thread): a thread that a busy host holds back leaves a short tail to the others
@parallel_kernel(lambda wide_boxes, wide_links, triangles, order, depth, skip, origins, *_: origins.shape[0],
                 grain=256, pieces_per_thread=16)  # fmt: skip
def _closest_rays(wide_boxes, wide_links, triangles, order, depth, skip, origins, directions, t_min, t_max, cull, t_out,
                  row_out, uv_out, back_out, start, stop):  # fmt: skip
    """``_closest4`` for rays [start, stop): t (inf: miss), leaf-order row (−1), (u, v), back."""
    stack = np.empty(3 * depth + 8, dtype=np.int64)
    entry = np.empty(3 * depth + 8)
    near = np.empty(WIDTH)
    found = np.empty((4, WIDTH))
    for r in range(start, stop):
        t, row, u, v, back = _closest4(
            wide_boxes, wide_links, triangles, order, skip, origins[r, 0], origins[r, 1], origins[r, 2],
            directions[r, 0], directions[r, 1], directions[r, 2], t_min[r], t_max[r], cull, stack, entry, near, found,
        )  # fmt: skip
        t_out[r] = t
        row_out[r] = row
        uv_out[r, 0] = u
        uv_out[r, 1] = v
        back_out[r] = back


@parallel_kernel(lambda wide_boxes, wide_links, triangles, depth, origins, *_: origins.shape[0], grain=256,
                 pieces_per_thread=16)  # fmt: skip
def _any_rays(wide_boxes, wide_links, triangles, depth, origins, directions, t_min, t_max, out, start, stop):
    """``_any4`` for rays [start, stop) into `out` (uint8); `t_min`, `t_max` one value each (shape (1,)) or one
    per ray."""
    stack = np.empty(3 * depth + 8, dtype=np.int64)
    near = np.empty(WIDTH)
    found = np.empty((4, WIDTH))
    each_min, each_max = t_min.shape[0] > 1, t_max.shape[0] > 1
    for r in range(start, stop):
        out[r] = _any4(wide_boxes, wide_links, triangles, origins[r, 0], origins[r, 1], origins[r, 2],
                       directions[r, 0], directions[r, 1], directions[r, 2], t_min[r if each_min else 0],
                       t_max[r if each_max else 0], stack, near, found)  # fmt: skip


def _per_ray(value: float | np.ndarray, count: int) -> np.ndarray:
    return np.ascontiguousarray(np.broadcast_to(np.asarray(value, dtype=np.float64), (count,)))


def _one_or_each(value: float | np.ndarray, count: int) -> np.ndarray:
    """(1,) for one value, else (count,) float64: what ``_any_rays`` reads (no copy of a float64 array)."""
    array = np.asarray(value, dtype=np.float64)
    return array.reshape(1) if array.ndim == 0 else np.ascontiguousarray(np.broadcast_to(array, (count,)))


class Hits(NamedTuple):
    """``closest_hits``: t (inf for a miss), the original triangle index (−1), its row in leaf order
    (``Index.triangles``; −1), the weights (u, v) of corners 1 and 2, back (1 where the ray meets the triangle's
    back: d·N > 0 for N = e1 × e2)."""

    t: np.ndarray
    face: np.ndarray
    row: np.ndarray
    uv: np.ndarray
    back: np.ndarray


def closest_hits(
    index: Index, origins: np.ndarray, directions: np.ndarray, t_min: float | np.ndarray = 0.0,
    t_max: float | np.ndarray = np.inf, skip: np.ndarray | None = None, cull: bool = False,
) -> Hits:  # fmt: skip
    """The first hit of each ray $origin + t·direction$ with t in [t_min, t_max) (scalars or one per ray)."""
    o = np.ascontiguousarray(origins, dtype=np.float64)
    d = np.ascontiguousarray(directions, dtype=np.float64)
    count = o.shape[0]
    t = np.empty(count)
    row = np.empty(count, dtype=np.int64)
    uv = np.empty((count, 2))
    back = np.empty(count, dtype=np.uint8)
    mask = np.empty(0, dtype=np.uint8) if skip is None else np.ascontiguousarray(skip, dtype=np.uint8)
    run = _closest_rays.kernel if count < 64 else _closest_rays
    run(index.wide_boxes, index.wide_links, index.triangles, index.order, index.depth, mask, o, d,
        _per_ray(t_min, count), _per_ray(t_max, count), int(cull), t, row, uv, back,
        *((0, count) if count < 64 else ()))  # fmt: skip
    face = np.where(row >= 0, index.order[np.maximum(row, 0)], -1)
    return Hits(t, face, row, uv, back)


def any_hits(index: Index, origins: np.ndarray, directions: np.ndarray, t_min: float | np.ndarray = 0.0,
             t_max: float | np.ndarray = np.inf) -> np.ndarray:  # fmt: skip
    """(N,) bool: whether each ray meets a triangle at t in [t_min, t_max)."""
    o = np.ascontiguousarray(origins, dtype=np.float64)
    d = np.ascontiguousarray(directions, dtype=np.float64)
    count = o.shape[0]
    out = np.empty(count, dtype=np.uint8)
    args = (index.wide_boxes, index.wide_links, index.triangles, index.depth, o, d, _one_or_each(t_min, count),
            _one_or_each(t_max, count), out)  # fmt: skip
    if count < 64:
        _any_rays.kernel(*args, 0, count)
    else:
        _any_rays(*args)
    return out.view(np.bool_)


FIELDS = ("t", "item", "face", "barycentrics", "point", "normal", "shading_normal", "back")
"""What ``intersect`` can write for each ray (bit i of its `wanted`: ``FIELDS[i]``); ``Scene.intersect``'s
``RayHits`` columns."""


@parallel_kernel(lambda wide_boxes, wide_links, triangles, order, depth, origins, *_: origins.shape[0], grain=256,
                 pieces_per_thread=16)  # fmt: skip
def _intersect_rays(wide_boxes, wide_links, triangles, order, depth, origins, directions, starts, numbers, swapped,
                    face_vertices, vertex_normals, wanted, t_out, item_out, face_out, bary_out, point_out, normal_out,
                    shading_out, back_out, start, stop):  # fmt: skip
    """The first hit of rays [start, stop) (t >= 0, both sides) and, in the same pass, the ``FIELDS`` that
    `wanted` asks for (the others' outputs are not touched: pass empty arrays). Triangle g of the index is face
    $g − starts[k]$ of item ``numbers[k]`` (``starts[k] <= g < starts[k + 1]``), its corners 1 and 2 swapped
    in the index where ``swapped[k]``; barycentrics (w0, w1, w2) are the weights of the face's own corners
    ($w0 = 1 − u − v$); point $o + t·d$; normal the unit $e1 × e2$ of the indexed corners; shading normal the
    unit $Σ wᵢ·N_{vᵢ}$ of ``vertex_normals`` (world, one per row of ``face_vertices[g]``), the normal where that
    is zero; back 1 where the ray meets the back. A miss: t inf, item and face −1, NaN vectors, back 0."""
    stack = np.empty(3 * depth + 8, dtype=np.int64)
    entry = np.empty(3 * depth + 8)
    near = np.empty(WIDTH)
    found = np.empty((4, WIDTH))
    skip = np.empty(0, dtype=np.uint8)
    last = starts.shape[0] - 1
    for r in range(start, stop):
        ox, oy, oz = origins[r, 0], origins[r, 1], origins[r, 2]
        dx, dy, dz = directions[r, 0], directions[r, 1], directions[r, 2]
        t, row, u, v, back = _closest4(wide_boxes, wide_links, triangles, order, skip, ox, oy, oz, dx, dy, dz, 0.0,
                                       np.inf, 0, stack, entry, near, found)  # fmt: skip
        if row < 0:
            if wanted & 1:
                t_out[r] = np.inf
            if wanted & 2:
                item_out[r] = -1
            if wanted & 4:
                face_out[r] = -1
            if wanted & 8:
                bary_out[r, 0], bary_out[r, 1], bary_out[r, 2] = np.nan, np.nan, np.nan
            if wanted & 16:
                point_out[r, 0], point_out[r, 1], point_out[r, 2] = np.nan, np.nan, np.nan
            if wanted & 32:
                normal_out[r, 0], normal_out[r, 1], normal_out[r, 2] = np.nan, np.nan, np.nan
            if wanted & 64:
                shading_out[r, 0], shading_out[r, 1], shading_out[r, 2] = np.nan, np.nan, np.nan
            if wanted & 128:
                back_out[r] = 0
            continue
        if wanted & 1:
            t_out[r] = t
        if wanted & 128:
            back_out[r] = back
        g = order[row]
        lo, hi = 0, last
        while hi - lo > 1:  # the item: starts[lo] <= g < starts[lo + 1]
            mid = (lo + hi) >> 1
            if starts[mid] <= g:
                lo = mid
            else:
                hi = mid
        if wanted & 2:
            item_out[r] = numbers[lo]
        if wanted & 4:
            face_out[r] = g - starts[lo]
        w0 = 1.0 - u - v
        w1, w2 = (v, u) if swapped[lo] != 0 else (u, v)
        if wanted & 8:
            bary_out[r, 0], bary_out[r, 1], bary_out[r, 2] = w0, w1, w2
        if wanted & 16:
            point_out[r, 0], point_out[r, 1], point_out[r, 2] = ox + t * dx, oy + t * dy, oz + t * dz
        if wanted & (32 | 64):
            ax, ay, az = triangles[row, 1, 0] - triangles[row, 0, 0], triangles[row, 1, 1] - triangles[row, 0, 1], \
                triangles[row, 1, 2] - triangles[row, 0, 2]  # fmt: skip
            bx, by, bz = triangles[row, 2, 0] - triangles[row, 0, 0], triangles[row, 2, 1] - triangles[row, 0, 1], \
                triangles[row, 2, 2] - triangles[row, 0, 2]  # fmt: skip
            nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
            length = np.sqrt(nx * nx + ny * ny + nz * nz)
            nx, ny, nz = nx / length, ny / length, nz / length
            if wanted & 32:
                normal_out[r, 0], normal_out[r, 1], normal_out[r, 2] = nx, ny, nz
            if wanted & 64:
                a, b, c = face_vertices[g, 0], face_vertices[g, 1], face_vertices[g, 2]
                sx = w0 * vertex_normals[a, 0] + w1 * vertex_normals[b, 0] + w2 * vertex_normals[c, 0]
                sy = w0 * vertex_normals[a, 1] + w1 * vertex_normals[b, 1] + w2 * vertex_normals[c, 1]
                sz = w0 * vertex_normals[a, 2] + w1 * vertex_normals[b, 2] + w2 * vertex_normals[c, 2]
                length = np.sqrt(sx * sx + sy * sy + sz * sz)
                if length > 0.0:
                    nx, ny, nz = sx / length, sy / length, sz / length
                shading_out[r, 0], shading_out[r, 1], shading_out[r, 2] = nx, ny, nz


def intersect(index: Index, origins: np.ndarray, directions: np.ndarray, wanted: int, starts: np.ndarray,
              numbers: np.ndarray, swapped: np.ndarray, face_vertices: np.ndarray,
              vertex_normals: np.ndarray) -> dict[str, np.ndarray]:  # fmt: skip
    """The first hits (t >= 0) of (N, 3) float64 rays with the ``FIELDS`` whose bits `wanted` sets, by name
    (``_intersect_rays``; `face_vertices`/`vertex_normals` are read only for the shading normal)."""
    count = origins.shape[0]
    shapes = {"t": ((count,), np.float64), "item": ((count,), np.int64), "face": ((count,), np.int64),
              "barycentrics": ((count, 3), np.float64), "point": ((count, 3), np.float64),
              "normal": ((count, 3), np.float64), "shading_normal": ((count, 3), np.float64),
              "back": ((count,), np.uint8)}  # fmt: skip
    outputs = {}
    for bit, name in enumerate(FIELDS):
        shape, dtype = shapes[name]
        outputs[name] = np.empty(shape if wanted >> bit & 1 else (0,) * len(shape), dtype=dtype)
    args = (index.wide_boxes, index.wide_links, index.triangles, index.order, index.depth, origins, directions,
            starts, numbers, swapped, face_vertices, vertex_normals, wanted, *outputs.values())  # fmt: skip
    if count < 64:
        _intersect_rays.kernel(*args, 0, count)
    else:
        _intersect_rays(*args)
    return {name: outputs[name] for bit, name in enumerate(FIELDS) if wanted >> bit & 1}


CAST_STATS = ("rays", "hits", "box_tests", "nodes_visited", "triangle_tests")
"""Columns of ``cast_pixels``' per-row counts."""


@parallel_kernel(lambda boxes, links, triangles, order, depth_max, skip, world_from_window, window_from_world, cull,
                 depth, *_: depth.shape[0], work=lambda *args: args[9].size, grain=4096)  # fmt: skip
def cast_pixels(boxes, links, triangles, order, depth_max, skip, world_from_window, window_from_world, cull, depth,
                codes, bary, stats, start, stop):  # fmt: skip
    """A ray through the centre of every pixel of window rows [start, stop) (y up); the first hit's window depth,
    face code and barycentrics, as the depth buffer writes them.

    Pixel (i, j) casts $origin + t·(end − origin)$, t in [0, 1), from $origin = unproject(i + ½, j + ½, 0)$
    on the near plane to $end = unproject(i + ½, j + ½, 1)$ on the far plane: hits inside the view volume
    only. At a hit, ``depth`` (H, W) float32 (top row first: row H − 1 − j) receives the window depth
    $z_w = (M₂·P)/(M₃·P)$ (M = `window_from_world`), ``codes`` $2·face + back$, ``bary`` the weights of
    the face's corners 1 and 2; a depth that rounds to 1 is not written. ``stats`` (H, len(CAST_STATS)) int64
    receives each row's counts. `cull` != 0 skips back faces; `skip` (F,) uint8 marks triangles not drawn.
    """
    height, width = depth.shape[0], depth.shape[1]
    m = world_from_window
    stack = np.empty(depth_max + 2, dtype=np.int64)
    entry = np.empty(depth_max + 2)
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
            t, hit, u, v, back, b, n, k = _closest(boxes, links, triangles, order, skip, ox, oy, oz, dx, dy, dz,
                                                   0.0, 1.0, cull, stack, entry)  # fmt: skip
            rays += 1
            box_tests += b
            nodes += n
            tests += k
            if hit < 0:
                continue
            px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
            w = window_from_world
            z = np.float32((w[2, 0] * px + w[2, 1] * py + w[2, 2] * pz + w[2, 3])
                           / (w[3, 0] * px + w[3, 1] * py + w[3, 2] * pz + w[3, 3]))  # fmt: skip
            if not z < 1.0:
                continue
            hits += 1
            depth[row, i] = z
            codes[row, i] = 2 * order[hit] + back
            bary[row, i, 0], bary[row, i, 1] = np.float32(u), np.float32(v)
        stats[j, 0], stats[j, 1], stats[j, 2], stats[j, 3], stats[j, 4] = rays, hits, box_tests, nodes, tests
