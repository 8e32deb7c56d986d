"""Triangle kernels: the per-face box and cull, clipping of crossing faces, and the tile fill (edge functions, depth).

Fixed point. Window x and y are snapped to 1/256 pixel: $X = floor(x_w·256 + 0.5)$ (int64), and every
edge function is evaluated exactly in int64 at pixel centres $(256·i + 128, 256·j + 128)$. For the edge
a → b, $E_ab(p) = (X_b − X_a)(Y_p − Y_a) − (Y_b − Y_a)(X_p − X_a)$: positive on its left. Front faces are
counter-clockwise in window coordinates (y up), so inside a front face all three edge functions are
positive and $E_12 + E_20 + E_01 = 2·area$.

Top-left rule (y up, counter-clockwise): the interior lies left of every directed edge, so a *top* edge
(horizontal, interior below it) runs right to left ($dy = 0, dx < 0$) and a *left* edge (interior to its
right) runs downward ($dy < 0$). A pixel centre exactly on an edge belongs to the triangle only for top and
left edges: the test is $E >= 0$ on those and $E > 0$ ($E − 1 >= 0$ in integers) on the others. Two
triangles sharing an edge traverse it in opposite directions, so exactly one of them owns the centres on it.

What the fill reads. A face whose three vertices lie inside the view volume (trivial accept) is drawn straight
from its vertices' records of ``vertices.project_vertices`` (snapped ``X, Y``; ``z_w`` and ``1/w``): nothing per
triangle is stored, the tile lists hold its face index. A face crossing the view volume is clipped
(Sutherland–Hodgman) into a fan whose triangles get records (tile list entry $−1 − r$ for record r):
``tri_int`` (R, 11) int64: ``X0, Y0, X1, Y1, X2, Y2`` snapped corners, $code = 2·face + back$, the pixel
bounding box ``i_min, i_max, j_min, j_max`` (inclusive, inside the image);
``tri_float`` (R, 3, 2 or 4) float64 per corner: window depth ``z_w`` and ``1/w_clip`` (and the snap residuals);
``tri_weights`` (R, 3, 2) float64 per corner: its barycentric weights ``(u1, u2)`` with respect to the source
face's corners 1 and 2 ($u0 = 1 − u1 − u2$ is never read). A trivially accepted face's corners are its own
corners 0, 1, 2 in drawing order (1 and 2 swapped when back = 1), so its weights are one-hot and the fill takes
the pixel's own barycentrics instead, which is bit-identical to weighting by one-hot vectors
($(b0·0 + b1·1) + b2·0 = b1$ exactly for b_k >= 0).

Depth and weights at a covered pixel centre P. Window depth is affine in screen space, so it is the plane through
the corners ``(X_k, Y_k, z_k)`` written from corner 0 with its gradients (``depth_plane``: the corners before the
snap where the vertex records carry their residuals, which the frame's own pass asks for):
$z(P) = (z_0 + β·(Y_P − Y_0)) + α·(X_P − X_0)$, $α = −Σ dy_k z_k · r$, $β = Σ dx_k z_k · r$, $r = 1/(2·area)$
(edge k opposite corner k) — the depth-buffer method's incremental form $z' = z − A/C$ per step along a scan
line [HB 9 "Depth-Buffer Method"], evaluated from the corner instead of accumulated, so every pixel's value is
independent of the tiles and of the order pixels are visited in (no division per pixel). The perspective-correct
weights: $g_k = E_k(P)·(1/w_k)$, $r = 1 / Σ g_k$, $b_k = g_k·r$.

A clockwise triangle is culled, or (two-sided) drawn with corners 1 and 2 swapped and $back = 1$; a triangle
of zero area, or whose box holds no pixel centre, is dropped.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel, prefetch
from frustum.raster.clip import clip_triangle
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL, SUBPIXEL_BITS, snap
from frustum.raster.vertices import clip_vertex

__all__ = [
    "CROSSING",
    "FACE_CROSSING",
    "FACE_DRAWN",
    "FACE_NONE",
    "FAN_MAX",
    "RECORD_FIELDS",
    "SUBPIXEL",
    "clip_faces",
    "covers_centre",
    "depth_plane",
    "face_box",
    "list_crossing",
    "rasterize_tiles",
]

RECORD_FIELDS = 11
NARROW = 8
"""Rows of a triangle's box at most this wide test every centre; wider ones find their covered span first."""
AHEAD = 16
"""Tile entries between a prefetch of an entry's face and its gather (``_jit.prefetch``): gathers of a mesh that does
not fit in cache (2M triangles) took 10–25 % less time."""
_LOWEST_BIT = np.array([0, 0, 1, 0, 2, 0, 1, 0, 3, 0, 1, 0, 2, 0, 1, 0], dtype=np.int64)
"""Index of the lowest set bit of a 4-bit mask (``_fill_tile``'s 2 × 2 boxes: bit ci + 2·cj)."""
FAN_MAX = 7
"""Most triangles one clipped face makes: a triangle clipped by the six view-volume planes has at most 3 + 6
corners, a fan of at most 7 triangles (``clip_faces``'s one-pass mode)."""
CROSSING = -2
"""``tiles.count_tiles``'s ``listed_tiles`` mark of a face crossing the view volume (its clipped records are
filled in its place)."""
FACE_NONE, FACE_DRAWN, FACE_CROSSING = 0, 1, 2
"""``face_box`` states: nothing to draw (rejected, culled, no area or no pixel centre), drawn from its vertices,
or crossing the view volume (to be clipped)."""


@kernel
def _first_centre(low: int) -> int:
    """Smallest pixel index whose centre $256·i + 128$ is >= `low` (fixed point): $−floor((128 − low)/256)$."""
    return -((HALF_SUBPIXEL - low) >> SUBPIXEL_BITS)


@kernel
def _span(e: int, step: int, bias: int, inverse: float, first: int, last: int) -> tuple[int, int]:
    """``[first, last]`` narrowed to the columns k where $e − step·k >= bias$ (an edge function stepped along a
    row), exactly: k bound by $(e − bias)/step$ estimated in float64 ($inverse = 1/step$; off by at most one
    for |E| < 2^51) and corrected by the integer test, no division and almost no mispredicted branch."""
    if step == 0:
        return (first, last) if e >= bias else (last + 1, last)
    k = (e - bias) * inverse
    if step > 0:  # falling: k <= (e − bias)/step
        bound = np.int64(math.floor(k)) if k < last else last
        if e - step * (bound + 1) >= bias:
            bound += 1
        elif e - step * bound < bias:
            bound -= 1
        return first, min(last, bound)
    bound = np.int64(math.ceil(k)) if k > first else first  # rising: k >= (e − bias)/step
    if e - step * (bound - 1) >= bias:
        bound -= 1
    elif e - step * bound < bias:
        bound += 1
    return max(first, bound), last


@kernel
def depth_plane(
    x0: int, y0: int, x1: int, y1: int, x2: int, y2: int, r0: float, s0: float, r1: float, s1: float, r2: float,
    s2: float, z0: float, z1: float, z2: float,
) -> tuple[float, float, float]:  # fmt: skip
    """$(z_0', α, β)$: window depth's plane through the unsnapped corners $(X_k + r_k, Y_k + s_k, z_k)$ (r, s the
    snap residuals, 1/256 pixel), $z(P) = (z_0' + β·(Y_P − Y_0)) + α·(X_P − X_0)$ from the snapped corner 0:
    $α = −Σ dy_k z_k / (2·area)$, $β = Σ dx_k z_k / (2·area)$, $z_0' = z_0 − α·r_0 − β·s_0$ (module docstring).

    The snapped corners' plane instead where the unsnapped triangle's area is under half the snapped one's or of
    the other sign (a sliver whose shape the snap decides). Residuals 0 give the snapped corners' plane, bit for
    bit: every coordinate is an integer below 2^26, so the differences and products are exact.
    """
    fx0, fy0, fx1, fy1, fx2, fy2 = x0 + r0, y0 + s0, x1 + r1, y1 + s1, x2 + r2, y2 + s2
    snapped = float((x1 - x0) * (y2 - y0) - (y1 - y0) * (x2 - x0))
    area = (fx1 - fx0) * (fy2 - fy0) - (fy1 - fy0) * (fx2 - fx0)
    if area * snapped < 0.5 * snapped * snapped:  # np.divide below: no ZeroDivisionError branch
        fx0, fy0, fx1, fy1, fx2, fy2 = float(x0), float(y0), float(x1), float(y1), float(x2), float(y2)
        area = snapped
        r0, s0 = 0.0, 0.0
    reciprocal = np.divide(1.0, area)
    alpha = -(((fy2 - fy1) * z0 + (fy0 - fy2) * z1) + (fy1 - fy0) * z2) * reciprocal
    beta = (((fx2 - fx1) * z0 + (fx0 - fx2) * z1) + (fx1 - fx0) * z2) * reciprocal
    return (z0 - alpha * r0) - beta * s0, alpha, beta


@kernel
def _window_box(
    xa: int, ya: int, xb: int, yb: int, xc: int, yc: int, width: int, height: int, cull: int
) -> tuple[int, int, int, int, int, int]:  # fmt: skip
    """Cull and pixel bounding box of a triangle with snapped corners, scalars only (so it inlines).

    Returns ``(made, back, i_min, i_max, j_min, j_max)``: back = 1 for a clockwise triangle (the caller swaps
    corners b and c; the box does not depend on the order); made = 0 for zero area, a culled back face or a box
    (clamped to the image) that holds no pixel centre.
    """
    area = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya)
    back = 1 if area < 0 else 0
    if area == 0 or (back == 1 and cull != 0):
        return 0, back, 0, -1, 0, -1
    i_min = max(_first_centre(min(xa, min(xb, xc))), 0)
    i_max = min((max(xa, max(xb, xc)) - HALF_SUBPIXEL) >> SUBPIXEL_BITS, width - 1)
    j_min = max(_first_centre(min(ya, min(yb, yc))), 0)
    j_max = min((max(ya, max(yb, yc)) - HALF_SUBPIXEL) >> SUBPIXEL_BITS, height - 1)
    made = 0 if (i_min > i_max or j_min > j_max) else 1
    return made, back, i_min, i_max, j_min, j_max


@kernel
def covers_centre(x0: int, y0: int, x1: int, y1: int, x2: int, y2: int, px: int, py: int) -> bool:
    """Whether the counter-clockwise triangle covers the centre (px, py) by the top-left rule: the fill's edge
    functions $E = dx·(Y − Y_a) − dy·(X − X_a)$ and biases (``_fill_tile``)."""
    dx0, dy0 = x2 - x1, y2 - y1
    dx1, dy1 = x0 - x2, y0 - y2
    dx2, dy2 = x1 - x0, y1 - y0
    bias0 = 0 if (dy0 < 0 or (dy0 == 0 and dx0 < 0)) else 1
    bias1 = 0 if (dy1 < 0 or (dy1 == 0 and dx1 < 0)) else 1
    bias2 = 0 if (dy2 < 0 or (dy2 == 0 and dx2 < 0)) else 1
    return (  # & rather than and: no branch per edge (whether a sub-pixel triangle covers its centre is random)
        (dx0 * (py - y1) - dy0 * (px - x1) >= bias0)
        & (dx1 * (py - y2) - dy1 * (px - x2) >= bias1)
        & (dx2 * (py - y0) - dy2 * (px - x0) >= bias2)
    )


@kernel
def face_box(
    faces: np.ndarray, codes: np.ndarray, win_int: np.ndarray, f: int, width: int, height: int, cull: int
) -> tuple[int, int, int, int, int, int]:  # fmt: skip
    """``(state, back, i_min, i_max, j_min, j_max)`` of face f: trivial reject by region codes (FACE_NONE),
    crossing (FACE_CROSSING, no box), else ``_window_box`` of its snapped vertices (FACE_DRAWN or FACE_NONE)."""
    i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
    c0, c1, c2 = codes[i0], codes[i1], codes[i2]
    if (c0 & c1 & c2) != 0:
        return FACE_NONE, 0, 0, -1, 0, -1
    if (c0 | c1 | c2) != 0:
        return FACE_CROSSING, 0, 0, -1, 0, -1
    made, back, i_min, i_max, j_min, j_max = _window_box(
        np.int64(win_int[i0, 0]), np.int64(win_int[i0, 1]), np.int64(win_int[i1, 0]), np.int64(win_int[i1, 1]),
        np.int64(win_int[i2, 0]), np.int64(win_int[i2, 1]), width, height, cull,
    )  # fmt: skip
    return (FACE_DRAWN if made != 0 else FACE_NONE), back, i_min, i_max, j_min, j_max


@parallel_kernel(lambda listed, listed_tiles, chunk, listed_counts, crossing_starts, *_: crossing_starts.shape[0])
def list_crossing(
    listed: np.ndarray, listed_tiles: np.ndarray, chunk: int, listed_counts: np.ndarray, crossing_starts: np.ndarray,
    crossing: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """The faces crossing the view volume, in order, picked from the faces ``tiles.count_tiles`` listed (those
    marked ``CROSSING`` in ``listed_tiles``): chunk c ($listed[c·chunk : c·chunk + listed_counts[c]]$)
    writes its crossing faces' indices into ``crossing`` from ``crossing_starts[c]`` on."""
    for c in range(start, stop):
        k = crossing_starts[c]
        for n in range(c * chunk, c * chunk + listed_counts[c]):
            if listed_tiles[n] == CROSSING:
                crossing[k] = listed[n]
                k += 1


@kernel
def _setup_triangle(
    corners: np.ndarray, weights: np.ndarray, a: int, b: int, c: int, code: int, view: np.ndarray,
    size: np.ndarray, tri_int: np.ndarray, tri_float: np.ndarray, tri_weights: np.ndarray, slot: int,
) -> int:  # fmt: skip
    """Divide, viewport, snap and cull the triangle of polygon corners a, b, c; write record `slot` if slot >= 0.

    corners (K, 4) clip coordinates and weights (K, 3) of a clipped polygon; view = (width/2, height/2);
    size = (width, height, cull). Returns 1 if the triangle is drawn (``_window_box``), else 0.
    """
    xa = snap((corners[a, 0] / corners[a, 3]) * view[0] + view[0])
    ya = snap((corners[a, 1] / corners[a, 3]) * view[1] + view[1])
    xb = snap((corners[b, 0] / corners[b, 3]) * view[0] + view[0])
    yb = snap((corners[b, 1] / corners[b, 3]) * view[1] + view[1])
    xc = snap((corners[c, 0] / corners[c, 3]) * view[0] + view[0])
    yc = snap((corners[c, 1] / corners[c, 3]) * view[1] + view[1])
    made, back, i_min, i_max, j_min, j_max = _window_box(xa, ya, xb, yb, xc, yc, size[0], size[1], size[2])
    if made == 0 or slot < 0:
        return made
    if back == 1:
        b, c, xb, xc, yb, yc = c, b, xc, xb, yc, yb
    tri_int[slot, 0], tri_int[slot, 1], tri_int[slot, 2] = xa, ya, xb
    tri_int[slot, 3], tri_int[slot, 4], tri_int[slot, 5] = yb, xc, yc
    for v in range(3):
        p = a if v == 0 else (b if v == 1 else c)
        w = corners[p, 3]
        tri_float[slot, v, 0] = (corners[p, 2] / w) * 0.5 + 0.5
        tri_float[slot, v, 1] = 1.0 / w
        if tri_float.shape[2] >= 4:  # the snap residuals (``depth_plane``)
            x_w, y_w = (corners[p, 0] / w) * view[0] + view[0], (corners[p, 1] / w) * view[1] + view[1]
            tri_float[slot, v, 2] = x_w * SUBPIXEL - (xa if v == 0 else (xb if v == 1 else xc))
            tri_float[slot, v, 3] = y_w * SUBPIXEL - (ya if v == 0 else (yb if v == 1 else yc))
        tri_weights[slot, v, 0], tri_weights[slot, v, 1] = weights[p, 1], weights[p, 2]
    tri_int[slot, 6] = 2 * code + back
    tri_int[slot, 7], tri_int[slot, 8], tri_int[slot, 9], tri_int[slot, 10] = i_min, i_max, j_min, j_max
    return 1


@parallel_kernel(lambda crossing, *_: crossing.shape[0], grain=64)
def clip_faces(
    crossing: np.ndarray, faces: np.ndarray, vertices: np.ndarray, clip_from_model: np.ndarray,
    planes: np.ndarray, view: np.ndarray, options: np.ndarray, record_starts: np.ndarray,
    tri_int: np.ndarray, tri_float: np.ndarray, tri_weights: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Sutherland–Hodgman clip of each crossing face, then set up its fan (0, k, k + 1) as records.

    The clip coordinates of the corners are recomputed (``vertices.clip_vertex``, the same bytes as the vertex
    stage). options = (width, height, cull, face_offset, write) int64. With write = 0, ``record_starts[k]``
    receives how many records crossing face k makes; with write = 1 its records go to slots
    ``record_starts[k]`` on, in fan order; with write = 2 they go there too and ``record_starts[k]`` then
    receives their number (one pass, into ``FAN_MAX`` slots per face).
    """
    write = options[4]
    size = options[0:3]
    capacity = 3 + planes.shape[0]
    for k in range(start, stop):
        f = crossing[k]
        corners = np.empty((3, 4))
        for v in range(3):
            clip_vertex(vertices, faces[f, v], clip_from_model, corners[v])
        positions = np.empty((2, capacity, 4))
        weights = np.empty((2, capacity, 3))
        count = clip_triangle(corners[0], corners[1], corners[2], planes, positions, weights)
        slot = record_starts[k] if write != 0 else -1
        made = 0
        for t in range(1, count - 1):
            one = _setup_triangle(
                positions[0], weights[0], 0, t, t + 1, options[3] + f, view, size, tri_int, tri_float, tri_weights,
                slot,
            )  # fmt: skip
            made += one
            if slot >= 0:
                slot += one
        if write != 1:
            record_starts[k] = made


FILL_BLOCK = 128
"""Tile entries per block of ``_fill_tile`` (its work blocks, 13 + 14 rows of FILL_BLOCK int64 and float64,
27 KiB, stay in the L1 cache)."""
_GENERAL = 16
"""``_setup_entries`` kind of an entry filled by the row loop (a larger box, or a clipped record); 0: nothing to
draw, 1–15: the covered centres of a box of at most 2 × 2 (bit ci + 2·cj)."""
_INT_ROWS, _FLOAT_ROWS = 13, 14
(_X0, _Y0, _X1, _Y1, _X2, _Y2, _CODE, _ENTRY, _KIND, _IMIN, _IMAX, _JMIN, _JMAX) = (
    np.uint64(k * FILL_BLOCK) for k in range(_INT_ROWS)
)
"""Rows of the int64 work block (unsigned offsets): corners (counter-clockwise once set up), code, tile entry, kind,
box."""
(_Z0, _Z1, _Z2, _Q0, _Q1, _Q2, _ALPHA, _BETA, _R0, _S0, _R1, _S1, _R2, _S2) = (
    np.uint64(k * FILL_BLOCK) for k in range(_FLOAT_ROWS)
)
"""Rows of the float64 work block: corners' ``z_w`` and ``1/w``, depth gradients, corners' snap residuals."""


@kernel
def _setup_entries(
    tile_entries: np.ndarray, first: int, stop: int, faces: np.ndarray, win_int: np.ndarray, win_float: np.ndarray,
    tri_int: np.ndarray, tri_float: np.ndarray, face_offset: int, block: np.ndarray, values: np.ndarray, last_slot: int,
    col0: int, col1: int, row0: int, row1: int,
) -> None:  # fmt: skip
    """A block of ``_fill_tile``: tile entries [first, stop) ($tile_entries[last_slot − 1]$ the tile's last) into
    the work blocks (``_X0``…, ``_Z0``…), then set up without a branch.

    The gather, in order: corners as stored (a face's from its vertices' records, a clipped record's from
    ``tri_int``/``tri_float``), code without the back bit ($2·face$; a record's whole code), the entry. The set
    up (vectorized by LLVM, 8 entries an AVX-512 instruction): a clockwise face's corners 1 and 2 swapped and its
    back bit added to the code, the pixel box clamped to the tile [col0, col1) × [row0, row1), the kind
    (``_GENERAL``; the 2 × 2 coverage mask) and the depth plane (``depth_plane``'s formulas). The depths of
    the 2 × 2 centres computed here as well were 2 % faster but cost 0.25 s more compile time; the two passes in
    two kernels, 0.1 s more.
    """
    residuals, record_residuals = win_float.shape[1] >= 4, tri_float.shape[2] >= 4
    if not (residuals and record_residuals):  # the snapped corners' plane (the rows stay 0 where not read)
        for k in range(6 * FILL_BLOCK):
            values[_R0 + np.uint64(k)] = 0.0
    for n in range(stop - first):
        u = np.uint64(n)
        slot = first + n
        if slot + AHEAD < last_slot:  # prefetch the face AHEAD entries on and the corners of the one AHEAD/2 on
            ahead = np.int64(tile_entries[np.uint64(slot + AHEAD)])
            if ahead >= 0:
                prefetch(faces, ahead, 0)
            ahead = np.int64(tile_entries[np.uint64(slot + AHEAD // 2)])
            if ahead >= 0:
                for v in range(3):
                    prefetch(win_int, faces[np.uint64(ahead), v], 0)
                    prefetch(win_float, faces[np.uint64(ahead), v], 0)
        entry = np.int64(tile_entries[np.uint64(slot)])
        if entry >= 0:
            at = np.uint64(entry)  # unsigned indices: no negative-index fix-up
            v0, v1, v2 = np.uint64(faces[at, 0]), np.uint64(faces[at, 1]), np.uint64(faces[at, 2])
            block[u + _X0], block[u + _Y0] = win_int[v0, 0], win_int[v0, 1]
            block[u + _X1], block[u + _Y1] = win_int[v1, 0], win_int[v1, 1]
            block[u + _X2], block[u + _Y2] = win_int[v2, 0], win_int[v2, 1]
            values[u + _Z0], values[u + _Q0] = win_float[v0, 0], win_float[v0, 1]
            values[u + _Z1], values[u + _Q1] = win_float[v1, 0], win_float[v1, 1]
            values[u + _Z2], values[u + _Q2] = win_float[v2, 0], win_float[v2, 1]
            if residuals:
                values[u + _R0], values[u + _S0] = win_float[v0, 2], win_float[v0, 3]
                values[u + _R1], values[u + _S1] = win_float[v1, 2], win_float[v1, 3]
                values[u + _R2], values[u + _S2] = win_float[v2, 2], win_float[v2, 3]
            block[u + _CODE] = 2 * (face_offset + entry)
        else:
            r = -1 - entry
            block[u + _X0], block[u + _Y0], block[u + _X1] = tri_int[r, 0], tri_int[r, 1], tri_int[r, 2]
            block[u + _Y1], block[u + _X2], block[u + _Y2] = tri_int[r, 3], tri_int[r, 4], tri_int[r, 5]
            values[u + _Z0], values[u + _Q0] = tri_float[r, 0, 0], tri_float[r, 0, 1]
            values[u + _Z1], values[u + _Q1] = tri_float[r, 1, 0], tri_float[r, 1, 1]
            values[u + _Z2], values[u + _Q2] = tri_float[r, 2, 0], tri_float[r, 2, 1]
            if record_residuals:
                values[u + _R0], values[u + _S0] = tri_float[r, 0, 2], tri_float[r, 0, 3]
                values[u + _R1], values[u + _S1] = tri_float[r, 1, 2], tri_float[r, 1, 3]
                values[u + _R2], values[u + _S2] = tri_float[r, 2, 2], tri_float[r, 2, 3]
            block[u + _CODE] = tri_int[r, 6]
        block[u + _ENTRY] = entry
    m = stop - first
    for n in range(m):
        u = np.uint64(n)
        x0, y0, x1, y1 = block[u + _X0], block[u + _Y0], block[u + _X1], block[u + _Y1]
        x2, y2 = block[u + _X2], block[u + _Y2]
        z0, z1, z2, q1, q2 = values[u + _Z0], values[u + _Z1], values[u + _Z2], values[u + _Q1], values[u + _Q2]
        rx0, ry0, rx1, ry1 = values[u + _R0], values[u + _S0], values[u + _R1], values[u + _S1]
        rx2, ry2 = values[u + _R2], values[u + _S2]
        back = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0) < 0  # never for a record (set up counter-clockwise)
        x1, x2 = (x2, x1) if back else (x1, x2)
        y1, y2 = (y2, y1) if back else (y1, y2)
        z1, z2 = (z2, z1) if back else (z1, z2)
        q1, q2 = (q2, q1) if back else (q1, q2)
        rx1, rx2 = (rx2, rx1) if back else (rx1, rx2)
        ry1, ry2 = (ry2, ry1) if back else (ry1, ry2)
        i_min = max((min(x0, min(x1, x2)) + (HALF_SUBPIXEL - 1)) >> SUBPIXEL_BITS, col0)  # _first_centre
        i_max = min((max(x0, max(x1, x2)) - HALF_SUBPIXEL) >> SUBPIXEL_BITS, col1 - 1)
        j_min = max((min(y0, min(y1, y2)) + (HALF_SUBPIXEL - 1)) >> SUBPIXEL_BITS, row0)
        j_max = min((max(y0, max(y1, y2)) - HALF_SUBPIXEL) >> SUBPIXEL_BITS, row1 - 1)
        # edge a → b: E = dx·(Y − Ya) − dy·(X − Xa); bias 0 on top/left edges, 1 elsewhere (E − bias >= 0)
        dx0, dy0 = x2 - x1, y2 - y1  # edge 1 → 2, opposite corner 0
        dx1, dy1 = x0 - x2, y0 - y2  # edge 2 → 0
        dx2, dy2 = x1 - x0, y1 - y0  # edge 0 → 1
        bias0 = 1 - np.int64((dy0 < 0) | ((dy0 == 0) & (dx0 < 0)))
        bias1 = 1 - np.int64((dy1 < 0) | ((dy1 == 0) & (dx1 < 0)))
        bias2 = 1 - np.int64((dy2 < 0) | ((dy2 == 0) & (dx2 < 0)))
        px0, py0 = SUBPIXEL * i_min + HALF_SUBPIXEL, SUBPIXEL * j_min + HALF_SUBPIXEL
        a0 = dx0 * (py0 - y1) - dy0 * (px0 - x1) - bias0  # E_k − bias_k at the box's first centre; − dy·256 per
        a1 = dx1 * (py0 - y2) - dy1 * (px0 - x2) - bias1  # column, + dx·256 per row
        a2 = dx2 * (py0 - y0) - dy2 * (px0 - x0) - bias2
        s0, s1, s2 = dy0 * SUBPIXEL, dy1 * SUBPIXEL, dy2 * SUBPIXEL
        t0, t1, t2 = dx0 * SUBPIXEL, dx1 * SUBPIXEL, dx2 * SUBPIXEL
        wide, tall = i_max > i_min, j_max > j_min
        mask = (  # & rather than and: no branch
            np.int64((a0 >= 0) & (a1 >= 0) & (a2 >= 0))
            | np.int64((a0 - s0 >= 0) & (a1 - s1 >= 0) & (a2 - s2 >= 0) & wide) << 1
            | np.int64((a0 + t0 >= 0) & (a1 + t1 >= 0) & (a2 + t2 >= 0) & tall) << 2
            | np.int64((a0 - s0 + t0 >= 0) & (a1 - s1 + t1 >= 0) & (a2 - s2 + t2 >= 0) & wide & tall) << 3
        )  # fmt: skip
        empty = (i_min > i_max) | (j_min > j_max)
        small = (i_max - i_min <= 1) & (j_max - j_min <= 1) & (block[u + _ENTRY] >= 0)
        kind = 0 if empty else (mask if small else _GENERAL)
        # depth_plane, without a branch (selects), so the loop vectorizes; 2·area ≠ 0 here
        snapped = float(dx2 * (y2 - y0) - dy2 * (x2 - x0))
        fdx0, fdy0 = float(dx0) + (rx2 - rx1), float(dy0) + (ry2 - ry1)
        fdx1, fdy1 = float(dx1) + (rx0 - rx2), float(dy1) + (ry0 - ry2)
        fdx2, fdy2 = float(dx2) + (rx1 - rx0), float(dy2) + (ry1 - ry0)
        area = fdx2 * (float(y2 - y0) + (ry2 - ry0)) - fdy2 * (float(x2 - x0) + (rx2 - rx0))
        sliver = area * snapped < 0.5 * snapped * snapped
        fdx0, fdy0 = (float(dx0), float(dy0)) if sliver else (fdx0, fdy0)
        fdx1, fdy1 = (float(dx1), float(dy1)) if sliver else (fdx1, fdy1)
        fdx2, fdy2 = (float(dx2), float(dy2)) if sliver else (fdx2, fdy2)
        rx0, ry0, area = (0.0, 0.0, snapped) if sliver else (rx0, ry0, area)
        reciprocal = np.divide(1.0, area)
        alpha = -((fdy0 * z0 + fdy1 * z1) + fdy2 * z2) * reciprocal
        beta = ((fdx0 * z0 + fdx1 * z1) + fdx2 * z2) * reciprocal
        values[u + _Z0] = (z0 - alpha * rx0) - beta * ry0
        values[u + _Z1], values[u + _Z2], values[u + _Q1], values[u + _Q2] = z1, z2, q1, q2
        values[u + _ALPHA], values[u + _BETA] = alpha, beta
        block[u + _X1], block[u + _X2], block[u + _Y1], block[u + _Y2] = x1, x2, y1, y2
        block[u + _CODE] += np.int64(back)
        block[u + _KIND] = kind
        block[u + _IMIN], block[u + _IMAX], block[u + _JMIN], block[u + _JMAX] = i_min, i_max, j_min, j_max


# kernel specialisation kept on purpose: raster.shadow._fill_depth_tile repeats its set-up for depth alone
@kernel
def _fill_tile(
    tile: int, faces: np.ndarray, win_int: np.ndarray, win_float: np.ndarray, tri_int: np.ndarray,
    tri_float: np.ndarray, tri_weights: np.ndarray, tile_starts: np.ndarray, tile_entries: np.ndarray,
    tiling: np.ndarray, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, origin_row: int, origin_col: int,
) -> None:  # fmt: skip
    """Tile `tile` of ``rasterize_tiles``: edge-function fill of its triangles in order (depth and weights by the
    module docstring's formulas).

    Image pixel (row, col) is element $[row − origin_row, col − origin_col]$ of ``depth``, ``codes`` and
    ``bary``: origin (0, 0) for image-sized buffers, the tile's top-left pixel for a tile's own (``raster.tiled``:
    contiguous, so the tile stays in L1 cache whatever the image's row stride).

    The tile owns the pixel columns [col0, col1) and window rows [row0, row1). Per triangle: top-left rule,
    depth test "less"; each covered pixel whose depth $z = (E_12·z_0 + E_20·z_1 + E_01·z_2) / (2·area)$ (affine
    in screen space) is less than ``depth`` gets depth (float32), $codes = 2·face + back$ and the
    perspective-correct barycentric weights (u1, u2) of the pixel with respect to the source face (float32).
    Coordinates are read as int64 (the edge-function products need 64 bits whatever their stored type).
    Buffers are top row first: window row j is array row $H − 1 − j$.

    The entries go in blocks of ``FILL_BLOCK`` through three passes (as ``tiles.count_tiles``): their corners
    gathered into work blocks (``_gather_entries``), everything per triangle that needs no order set up without a
    branch, vectorized (``_setup_entries``: box, biases, 2 × 2 coverage mask, depth gradients),
    then the depth tests and writes in order (ties in depth go to the first drawn). A face whose box holds at most
    2 × 2 centres (two thirds of a 2M-triangle terrain's) visits its covered centres alone (the mask); a larger box
    (or a clipped record) runs the row loop, inline (no per-triangle call taking arrays: its reference counts cost
    more than a small triangle's fill): a box wider than ``NARROW`` columns finds each row's first and last covered
    centre (``_span``) and visits only those. Indices are unsigned (``np.uint64``): Numba adds a negative-index
    fix-up to every signed one. Single thread, terrain_2m tile pipeline 71 -> 64 ms (entry by entry before;
    compile +0.4 s).
    """
    size, tiles_x, face_offset, width, height = tiling[0], tiling[1], tiling[2], tiling[3], tiling[4]
    col0 = (tile % tiles_x) * size
    col1 = min(col0 + size, width)
    row0 = (tile // tiles_x) * size
    row1 = min(row0 + size, height)
    first_slot, last_slot = tile_starts[tile], tile_starts[tile + 1]
    if first_slot == last_slot:
        return
    block = np.empty(_INT_ROWS * FILL_BLOCK, dtype=np.int64)
    values = np.empty(_FLOAT_ROWS * FILL_BLOCK)
    top = height - 1 - origin_row
    for first in range(first_slot, last_slot, FILL_BLOCK):
        m = min(first + FILL_BLOCK, last_slot) - first
        _setup_entries(
            tile_entries, first, first + m, faces, win_int, win_float, tri_int, tri_float, face_offset, block, values,
            last_slot, col0, col1, row0, row1,
        )  # fmt: skip
        for n in range(m):
            u = np.uint64(n)
            kind = block[u + _KIND]
            if kind == 0:
                continue
            code = block[u + _CODE]
            x0, y0, x1, y1 = block[u + _X0], block[u + _Y0], block[u + _X1], block[u + _Y1]
            x2, y2 = block[u + _X2], block[u + _Y2]
            q0, q1, q2 = values[u + _Q0], values[u + _Q1], values[u + _Q2]
            i_min, j_min = block[u + _IMIN], block[u + _JMIN]
            swap = code & 1  # unclipped: source corner 1 is drawn as corner 1 + swap, corner 2 as 2 − swap
            z0, alpha, beta = values[u + _Z0], values[u + _ALPHA], values[u + _BETA]
            if kind < _GENERAL:  # a box of at most 2 × 2 centres: only the covered ones (the mask)
                mask = kind
                while mask != 0:
                    k = _LOWEST_BIT[mask]
                    mask &= mask - 1
                    ci, cj = k & 1, k >> 1
                    py, px = SUBPIXEL * (j_min + cj) + HALF_SUBPIXEL, SUBPIXEL * (i_min + ci) + HALF_SUBPIXEL
                    z = np.float32((z0 + beta * float(py - y0)) + alpha * float(px - x0))  # the row loop's value
                    at_row, at = np.uint64(top - (j_min + cj)), np.uint64(i_min + ci - origin_col)
                    if z < depth[at_row, at]:
                        depth[at_row, at] = z
                        codes[at_row, at] = code
                        e0 = (x2 - x1) * (py - y1) - (y2 - y1) * (px - x1)
                        e1 = (x0 - x2) * (py - y2) - (y0 - y2) * (px - x2)
                        e2 = (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0)
                        g0, g1, g2 = float(e0) * q0, float(e1) * q1, float(e2) * q2
                        reciprocal = 1.0 / ((g0 + g1) + g2)
                        b1, b2 = g1 * reciprocal, g2 * reciprocal
                        bary[at_row, at, 0] = np.float32(b2 if swap == 1 else b1)
                        bary[at_row, at, 1] = np.float32(b1 if swap == 1 else b2)
                continue
            entry = block[u + _ENTRY]
            record = -1 - entry  # >= 0 for a clipped record
            i_max, j_max = block[u + _IMAX], block[u + _JMAX]
            dx0, dy0 = x2 - x1, y2 - y1  # edge 1 → 2, opposite corner 0
            dx1, dy1 = x0 - x2, y0 - y2  # edge 2 → 0
            dx2, dy2 = x1 - x0, y1 - y0  # edge 0 → 1
            bias0 = 0 if (dy0 < 0 or (dy0 == 0 and dx0 < 0)) else 1
            bias1 = 0 if (dy1 < 0 or (dy1 == 0 and dx1 < 0)) else 1
            bias2 = 0 if (dy2 < 0 or (dy2 == 0 and dx2 < 0)) else 1
            px0 = SUBPIXEL * i_min + HALF_SUBPIXEL
            columns = i_max - i_min + 1
            step0, step1, step2 = dy0 * SUBPIXEL, dy1 * SUBPIXEL, dy2 * SUBPIXEL  # E_k falls by these per column
            inverse0, inverse1, inverse2 = 0.0, 0.0, 0.0
            if columns > NARROW:
                inverse0 = 1.0 / step0 if step0 != 0 else 0.0
                inverse1 = 1.0 / step1 if step1 != 0 else 0.0
                inverse2 = 1.0 / step2 if step2 != 0 else 0.0
            for j in range(j_min, j_max + 1):
                py = SUBPIXEL * j + HALF_SUBPIXEL
                e0 = dx0 * (py - y1) - dy0 * (px0 - x1)
                e1 = dx1 * (py - y2) - dy1 * (px0 - x2)
                e2 = dx2 * (py - y0) - dy2 * (px0 - x0)
                z_row = z0 + beta * float(py - y0)
                x_off = float(px0 - x0)  # X_P − X_0, exact in float64
                at_row = np.uint64(top - j)  # unsigned indices: no negative-index fix-up
                first_column, last_column = 0, columns - 1
                if columns > NARROW:  # the covered centres of a row are consecutive (three half-planes): find them
                    first_column, last_column = _span(e0, step0, bias0, inverse0, first_column, last_column)
                    first_column, last_column = _span(e1, step1, bias1, inverse1, first_column, last_column)
                    first_column, last_column = _span(e2, step2, bias2, inverse2, first_column, last_column)
                    e0, e1, e2 = e0 - step0 * first_column, e1 - step1 * first_column, e2 - step2 * first_column
                    x_off += SUBPIXEL * first_column
                for i in range(i_min + first_column - origin_col, i_min + last_column + 1 - origin_col):
                    if columns > NARROW or (e0 >= bias0 and e1 >= bias1 and e2 >= bias2):
                        z = np.float32(z_row + alpha * x_off)
                        at = np.uint64(i)
                        if z < depth[at_row, at]:
                            depth[at_row, at] = z
                            codes[at_row, at] = code
                            # perspective-correct weights b_k = (E_k / w_k) / Σ E_j / w_j, then onto the source face
                            g0, g1, g2 = float(e0) * q0, float(e1) * q1, float(e2) * q2
                            reciprocal = 1.0 / ((g0 + g1) + g2)
                            b1, b2 = g1 * reciprocal, g2 * reciprocal
                            if record < 0:  # one-hot weights: (b0·0 + b1·1) + b2·0 is b1 exactly (b_k >= 0)
                                bary[at_row, at, 0] = np.float32(b2 if swap == 1 else b1)
                                bary[at_row, at, 1] = np.float32(b1 if swap == 1 else b2)
                            else:
                                b0 = g0 * reciprocal
                                for k in range(2):
                                    w0, w1, w2 = (
                                        tri_weights[record, 0, k],
                                        tri_weights[record, 1, k],
                                        tri_weights[record, 2, k],
                                    )
                                    bary[at_row, at, k] = np.float32((b0 * w0 + b1 * w1) + b2 * w2)
                    e0 -= step0
                    e1 -= step1
                    e2 -= step2
                    x_off += SUBPIXEL


@parallel_kernel(lambda *args: args[6].shape[0] - 1, work=lambda *args: args[7].shape[0], grain=256)
# items: tiles (tile_starts has tiles + 1 entries); work: the tile entries (tile_entries)
def rasterize_tiles(
    faces: np.ndarray, win_int: np.ndarray, win_float: np.ndarray, tri_int: np.ndarray, tri_float: np.ndarray,
    tri_weights: np.ndarray, tile_starts: np.ndarray, tile_entries: np.ndarray, tiling: np.ndarray,
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Each tile owns its pixels of ``depth``, ``codes`` and ``bary``: no write races, deterministic output.

    tiling = (tile_size, tiles_x, face_offset, width, height) int64; the buffers hold earlier items' results
    (``render.clear_buffers`` first). Tile ``t`` covers columns $[tx·s, tx·s + s)$ and window rows
    $[ty·s, ty·s + s)$ with $tx = t % tiles_x$, $ty = t // tiles_x$; its triangles, in drawing order, are
    ``tile_entries[tile_starts[t]:tile_starts[t + 1]]`` (``raster.tiles``): a face index f >= 0 (drawn from
    ``win_int``/``win_float`` of its vertices) or $−1 − r$ for clipped record r.
    """
    for t in range(start, stop):
        _fill_tile(
            t, faces, win_int, win_float, tri_int, tri_float, tri_weights, tile_starts, tile_entries, tiling,
            depth, codes, bary, 0, 0,
        )  # fmt: skip
