"""Triangle kernels: setup (clip, divide, viewport, snap, cull) and the tile fill (edge functions, depth test).

Fixed point. Window x and y are snapped to 1/256 pixel: ``X = floor(x_w·256 + 0.5)`` (int64), and every
edge function is evaluated exactly in int64 at pixel centres ``(256·i + 128, 256·j + 128)``. For the edge
a → b, ``E_ab(p) = (X_b − X_a)(Y_p − Y_a) − (Y_b − Y_a)(X_p − X_a)``: positive on its left. Front faces are
counter-clockwise in window coordinates (y up), so inside a front face all three edge functions are
positive and ``E_12 + E_20 + E_01 = 2·area``.

Top-left rule (y up, counter-clockwise): the interior lies left of every directed edge, so a *top* edge
(horizontal, interior below it) runs right to left (``dy = 0, dx < 0``) and a *left* edge (interior to its
right) runs downward (``dy < 0``). A pixel centre exactly on an edge belongs to the triangle only for top and
left edges: the test is ``E >= 0`` on those and ``E > 0`` (``E − 1 >= 0`` in integers) on the others. Two
triangles sharing an edge traverse it in opposite directions, so exactly one of them owns the centres on it.

Triangle records (one per rasterized triangle, after clipping and culling):
``tri_int`` (T, 12) int32 (int64 when a snapped coordinate or a code might not fit in int32; the caller
chooses): ``X0, Y0, X1, Y1, X2, Y2`` snapped corners, ``code = 2·face + back``, the pixel bounding box
``i_min, i_max, j_min, j_max`` (inclusive, inside the image), and ``weight_row``: −1 for a trivially accepted
(unclipped) triangle, else its row in ``tri_weights``;
``tri_float`` (T, 3, 2) float64 per corner: window depth ``z_w`` and ``1/w_clip``;
``tri_weights`` (C, 3, 2) float64, clipped triangles only (C of them): per corner its barycentric weights
``(u1, u2)`` with respect to the source face's corners 1 and 2 (``u0 = 1 − u1 − u2`` is never read). An
unclipped triangle's corners are the source corners 0, 1, 2 in drawing order (1 and 2 swapped when back = 1),
so its weights are one-hot and are not stored: the fill takes the pixel's own barycentrics instead, which is
bit-identical to weighting by one-hot vectors (``(b0·0 + b1·1) + b2·0 = b1`` exactly for b_k >= 0).
Snapped coordinates fit in int32 when ``256·(max(W, H) + 2) < 2^31``: every rasterized corner lies inside the
view volume (trivially accepted vertices have region code 0, clipped corners lie on or inside every plane up
to round-off), so its window coordinates lie in [0, W]×[0, H] up to round-off.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel, prange
from frustum.raster.clip import clip_triangle
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL, snap

__all__ = [
    "INT_FIELDS",
    "SUBPIXEL",
    "rasterize_tiles",
    "setup_triangles",
    "window_vertices",
]

INT_FIELDS = 12
FLOAT_FIELDS = 2
WEIGHT_ROW = 11


@kernel
def _first_centre(low: int) -> int:
    """Smallest pixel index whose centre ``256·i + 128`` is >= `low` (fixed point)."""
    return -((HALF_SUBPIXEL - low) // SUBPIXEL)


@kernel
def _setup_triangle(
    corners: np.ndarray, weights: np.ndarray, a: int, b: int, c: int, code: int, view: np.ndarray,
    size: np.ndarray, tri_int: np.ndarray, tri_float: np.ndarray, tri_weights: np.ndarray, slot: int, row: int,
) -> int:  # fmt: skip
    """Divide, viewport, snap and cull the triangle of polygon corners a, b, c; write its record if slot >= 0.

    The corners' weights go to ``tri_weights[row]`` and `row` to the record's ``weight_row``.

    corners (K, 4) clip coordinates and weights (K, 3) of a clipped polygon; view = (width/2, height/2);
    size = (width, height, cull). Returns 1 if the triangle covers at least one pixel centre's bounding box
    and survives culling, else 0. A clockwise triangle is culled when ``cull`` is set, otherwise its corners
    1 and 2 are swapped (so it is counter-clockwise) and its ``back`` bit set. Zero area is always dropped.
    """
    # perspective divide, viewport and snap
    xa = snap((corners[a, 0] / corners[a, 3]) * view[0] + view[0])
    ya = snap((corners[a, 1] / corners[a, 3]) * view[1] + view[1])
    xb = snap((corners[b, 0] / corners[b, 3]) * view[0] + view[0])
    yb = snap((corners[b, 1] / corners[b, 3]) * view[1] + view[1])
    xc = snap((corners[c, 0] / corners[c, 3]) * view[0] + view[0])
    yc = snap((corners[c, 1] / corners[c, 3]) * view[1] + view[1])
    # back-face test by the signed area in window space (twice the area, exact)
    area = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya)
    if area == 0:
        return 0
    back = 0
    if area < 0:
        if size[2] != 0:
            return 0
        back = 1
        b, c = c, b
        xb, xc = xc, xb
        yb, yc = yc, yb
    # pixel bounding box of the centres it may cover, clamped to the image
    i_min = max(_first_centre(min(xa, min(xb, xc))), 0)
    i_max = min((max(xa, max(xb, xc)) - HALF_SUBPIXEL) // SUBPIXEL, size[0] - 1)
    j_min = max(_first_centre(min(ya, min(yb, yc))), 0)
    j_max = min((max(ya, max(yb, yc)) - HALF_SUBPIXEL) // SUBPIXEL, size[1] - 1)
    if i_min > i_max or j_min > j_max:
        return 0
    if slot < 0:
        return 1
    tri_int[slot, 0], tri_int[slot, 1], tri_int[slot, 2] = xa, ya, xb
    tri_int[slot, 3], tri_int[slot, 4], tri_int[slot, 5] = yb, xc, yc
    for v in range(3):
        p = a if v == 0 else (b if v == 1 else c)
        w = corners[p, 3]
        tri_float[slot, v, 0] = (corners[p, 2] / w) * 0.5 + 0.5
        tri_float[slot, v, 1] = 1.0 / w
        tri_weights[row, v, 0], tri_weights[row, v, 1] = weights[p, 1], weights[p, 2]
    tri_int[slot, 6] = 2 * code + back
    tri_int[slot, 7], tri_int[slot, 8], tri_int[slot, 9], tri_int[slot, 10] = i_min, i_max, j_min, j_max
    tri_int[slot, WEIGHT_ROW] = row
    return 1


@parallel_kernel
def window_vertices(
    clip: np.ndarray, codes: np.ndarray, view: np.ndarray, win_int: np.ndarray, win_float: np.ndarray
) -> None:  # fmt: skip
    """Per vertex inside the view volume (code 0): the divide, viewport and snap ``_setup_triangle`` does per corner.

    win_int (N, 2) int64 receives the snapped ``X, Y``; win_float (N, 2) float64 the window depth ``z_w`` and
    ``1/w_clip``. Rows of vertices with a nonzero code are left unwritten (their faces are clipped or rejected).
    """
    for i in prange(clip.shape[0]):
        if codes[i] != 0:
            continue
        w = clip[i, 3]
        win_int[i, 0] = snap((clip[i, 0] / w) * view[0] + view[0])
        win_int[i, 1] = snap((clip[i, 1] / w) * view[1] + view[1])
        win_float[i, 0] = (clip[i, 2] / w) * 0.5 + 0.5
        win_float[i, 1] = 1.0 / w


@kernel
def _window_box(
    xa: int, ya: int, xb: int, yb: int, xc: int, yc: int, width: int, height: int, cull: int
) -> tuple[int, int, int, int, int, int]:  # fmt: skip
    """``_setup_triangle``'s cull and bounding box on snapped corners, scalars only (so it inlines).

    Returns ``(made, back, i_min, i_max, j_min, j_max)``; made = 0 for zero area, a culled clockwise triangle or
    an empty box. For back = 1 the caller swaps corners b and c; the box does not depend on the order.
    """
    area = (xb - xa) * (yc - ya) - (xc - xa) * (yb - ya)
    back = 1 if area < 0 else 0
    i_min = max(_first_centre(min(xa, min(xb, xc))), 0)
    i_max = min((max(xa, max(xb, xc)) - HALF_SUBPIXEL) // SUBPIXEL, width - 1)
    j_min = max(_first_centre(min(ya, min(yb, yc))), 0)
    j_max = min((max(ya, max(yb, yc)) - HALF_SUBPIXEL) // SUBPIXEL, height - 1)
    made = 0 if (area == 0 or (back == 1 and cull != 0) or i_min > i_max or j_min > j_max) else 1
    return made, back, i_min, i_max, j_min, j_max


@parallel_kernel
def setup_triangles(
    faces: np.ndarray, clip: np.ndarray, codes: np.ndarray, planes: np.ndarray, view: np.ndarray,
    win_int: np.ndarray, win_float: np.ndarray,
    options: np.ndarray, chunk_starts: np.ndarray, tri_int: np.ndarray, tri_float: np.ndarray,
    tri_weights: np.ndarray,
) -> None:  # fmt: skip
    """Per face: trivial accept / reject by region codes, clip the rest, then set up each (fan) triangle.

    faces (M, 3) int64, clip (N, 4) float64, codes (N,) int64, planes (P, 4) float64, view = (width/2,
    height/2); win_int, win_float from ``window_vertices`` (read for trivially accepted faces only);
    options = (width, height, cull, face_offset, chunk, write) int64. Faces are processed in
    chunks of ``chunk`` (chunk c = faces [c·chunk, (c+1)·chunk)). chunk_starts (C, 2) int64: with write = 0,
    ``chunk_starts[c]`` receives the number of triangles chunk c produces and how many of them are clipped; with
    write = 1, chunk c writes its records from slot ``chunk_starts[c, 0]`` on and its clipped weights from row
    ``chunk_starts[c, 1]`` on, in face order (so the output order never depends on the thread count).
    """
    chunk = options[4]
    chunk_count = (faces.shape[0] + chunk - 1) // chunk
    for c in prange(chunk_count):
        _setup_chunk(
            c, faces, clip, codes, planes, view, win_int, win_float, options, chunk_starts, tri_int, tri_float,
            tri_weights,
        )  # fmt: skip


@kernel
def _setup_chunk(
    c: int, faces: np.ndarray, clip: np.ndarray, codes: np.ndarray, planes: np.ndarray, view: np.ndarray,
    win_int: np.ndarray, win_float: np.ndarray,
    options: np.ndarray, chunk_starts: np.ndarray, tri_int: np.ndarray, tri_float: np.ndarray,
    tri_weights: np.ndarray,
) -> None:  # fmt: skip
    """Chunk c of ``setup_triangles``: trivial reject, trivial accept, or clip, per face."""
    face_offset, chunk, write = options[3], options[4], options[5]
    slot = chunk_starts[c, 0] if write != 0 else -1
    row = chunk_starts[c, 1] if write != 0 else -1
    produced = 0
    clipped = 0
    width, height, cull = options[0], options[1], options[2]
    for f in range(c * chunk, min((c + 1) * chunk, faces.shape[0])):
        i0, i1, i2 = faces[f, 0], faces[f, 1], faces[f, 2]
        c0, c1, c2 = codes[i0], codes[i1], codes[i2]
        if (c0 & c1 & c2) != 0:  # trivial reject: all corners outside one plane
            continue
        if (c0 | c1 | c2) != 0:  # crossing: Sutherland–Hodgman
            made = _setup_clipped(f, faces, clip, planes, view, options, tri_int, tri_float, tri_weights, slot, row)
            produced += made
            clipped += made
            if slot >= 0:
                slot += made
                row += made
            continue
        # trivial accept: the corners' window_vertices records, no clip work (same bytes as _setup_triangle);
        # written inline, not by a helper taking arrays: a per-face call costs more than the face's work
        xa, ya, xb, yb = win_int[i0, 0], win_int[i0, 1], win_int[i1, 0], win_int[i1, 1]
        xc, yc = win_int[i2, 0], win_int[i2, 1]
        made, back, i_min, i_max, j_min, j_max = _window_box(xa, ya, xb, yb, xc, yc, width, height, cull)
        produced += made
        if made == 0 or slot < 0:
            continue
        if back == 1:
            i1, i2, xb, xc, yb, yc = i2, i1, xc, xb, yc, yb
        tri_int[slot, 0], tri_int[slot, 1], tri_int[slot, 2] = xa, ya, xb
        tri_int[slot, 3], tri_int[slot, 4], tri_int[slot, 5] = yb, xc, yc
        tri_int[slot, 6] = 2 * (face_offset + f) + back
        tri_int[slot, 7], tri_int[slot, 8], tri_int[slot, 9], tri_int[slot, 10] = i_min, i_max, j_min, j_max
        tri_int[slot, WEIGHT_ROW] = -1  # one-hot weights of the source corners: not stored
        tri_float[slot, 0, 0], tri_float[slot, 0, 1] = win_float[i0, 0], win_float[i0, 1]
        tri_float[slot, 1, 0], tri_float[slot, 1, 1] = win_float[i1, 0], win_float[i1, 1]
        tri_float[slot, 2, 0], tri_float[slot, 2, 1] = win_float[i2, 0], win_float[i2, 1]
        slot += 1
    if write == 0:
        chunk_starts[c, 0] = produced
        chunk_starts[c, 1] = clipped


@kernel
def _setup_clipped(
    f: int, faces: np.ndarray, clip: np.ndarray, planes: np.ndarray, view: np.ndarray, options: np.ndarray,
    tri_int: np.ndarray, tri_float: np.ndarray, tri_weights: np.ndarray, slot: int, row: int,
) -> int:  # fmt: skip
    """Sutherland–Hodgman clip of face f, then set up its fan (0, k, k + 1); returns the records made.

    Record slot + n keeps its weights in ``tri_weights`` row row + n.
    """
    capacity = 3 + planes.shape[0]
    positions = np.empty((2, capacity, 4))
    weights = np.empty((2, capacity, 3))
    count = clip_triangle(clip[faces[f, 0]], clip[faces[f, 1]], clip[faces[f, 2]], planes, positions, weights)
    size = options[0:3]
    made = 0
    for k in range(1, count - 1):
        one = _setup_triangle(
            positions[0], weights[0], 0, k, k + 1, options[3] + f, view, size, tri_int, tri_float, tri_weights,
            slot, row,
        )  # fmt: skip
        made += one
        if slot >= 0:
            slot += one
            row += one
    return made


@kernel
def _fill_tile(
    tile: int, tri_int: np.ndarray, tri_float: np.ndarray, tri_weights: np.ndarray, tile_starts: np.ndarray,
    tile_triangles: np.ndarray, tiling: np.ndarray, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
) -> None:  # fmt: skip
    """Tile `tile` of ``rasterize_tiles``: clear it if asked, then edge-function fill of its triangles in order.

    The tile owns the pixel columns [i0, i1) and window rows [j0, j1). Per triangle: top-left rule, depth test
    "less"; each covered pixel whose depth ``z = (E_12·z_0 + E_20·z_1 + E_01·z_2) / (2·area)`` (affine in screen
    space) is less than ``depth`` gets depth (float32), ``codes = tri_int[t, 6]`` (t the triangle) and the
    perspective-correct barycentric weights (u1, u2) of the pixel with respect to the source face (float32).
    Record fields are read as int64 (the edge-function products need 64 bits whatever ``tri_int``'s dtype).
    Buffers are top row first: window row j is array row ``H − 1 − j``. The triangle loop is inline (no
    per-triangle call taking arrays: for pixel-sized triangles the call would cost more than the fill).
    """
    size, tiles_x = tiling[0], tiling[1]
    height, width = depth.shape[0], depth.shape[1]
    i0 = (tile % tiles_x) * size
    i1 = min(i0 + size, width)
    j0 = (tile // tiles_x) * size
    j1 = min(j0 + size, height)
    if tiling[2] != 0:
        for row in range(height - j1, height - j0):
            for col in range(i0, i1):
                depth[row, col] = 1.0
                codes[row, col] = -1
    for slot in range(tile_starts[tile], tile_starts[tile + 1]):
        t = tile_triangles[slot]
        x0, y0 = np.int64(tri_int[t, 0]), np.int64(tri_int[t, 1])
        x1, y1 = np.int64(tri_int[t, 2]), np.int64(tri_int[t, 3])
        x2, y2 = np.int64(tri_int[t, 4]), np.int64(tri_int[t, 5])
        i_min, i_max = max(np.int64(tri_int[t, 7]), i0), min(np.int64(tri_int[t, 8]), i1 - 1)
        j_min, j_max = max(np.int64(tri_int[t, 9]), j0), min(np.int64(tri_int[t, 10]), j1 - 1)
        if i_min > i_max or j_min > j_max:
            continue
        # edge a → b: E = dx·(Y − Ya) − dy·(X − Xa); bias 0 on top/left edges, 1 elsewhere (E − bias >= 0)
        dx0, dy0 = x2 - x1, y2 - y1  # edge 1 → 2, opposite corner 0
        dx1, dy1 = x0 - x2, y0 - y2  # edge 2 → 0
        dx2, dy2 = x1 - x0, y1 - y0  # edge 0 → 1
        bias0 = 0 if (dy0 < 0 or (dy0 == 0 and dx0 < 0)) else 1
        bias1 = 0 if (dy1 < 0 or (dy1 == 0 and dx1 < 0)) else 1
        bias2 = 0 if (dy2 < 0 or (dy2 == 0 and dx2 < 0)) else 1
        area = float(dx2 * (y2 - y0) - dy2 * (x2 - x0))
        z0, z1, z2 = tri_float[t, 0, 0], tri_float[t, 1, 0], tri_float[t, 2, 0]
        q0, q1, q2 = tri_float[t, 0, 1], tri_float[t, 1, 1], tri_float[t, 2, 1]
        code = np.int64(tri_int[t, 6])
        wrow = np.int64(tri_int[t, WEIGHT_ROW])
        swap = code % 2  # unclipped: source corner 1 is drawn as corner 1 + swap, corner 2 as 2 − swap
        px0 = SUBPIXEL * i_min + HALF_SUBPIXEL
        for j in range(j_min, j_max + 1):
            py = SUBPIXEL * j + HALF_SUBPIXEL
            e0 = dx0 * (py - y1) - dy0 * (px0 - x1)
            e1 = dx1 * (py - y2) - dy1 * (px0 - x2)
            e2 = dx2 * (py - y0) - dy2 * (px0 - x0)
            row = height - 1 - j
            for i in range(i_min, i_max + 1):
                if e0 >= bias0 and e1 >= bias1 and e2 >= bias2:
                    f0, f1, f2 = float(e0), float(e1), float(e2)
                    z = np.float32(((f0 * z0 + f1 * z1) + f2 * z2) / area)
                    if z < depth[row, i]:
                        depth[row, i] = z
                        codes[row, i] = code
                        # perspective-correct weights b_k = (E_k / w_k) / Σ E_j / w_j, then onto the source face
                        g0, g1, g2 = f0 * q0, f1 * q1, f2 * q2
                        total = (g0 + g1) + g2
                        b0, b1, b2 = g0 / total, g1 / total, g2 / total
                        if wrow < 0:  # one-hot weights: (b0·0 + b1·1) + b2·0 is b1 exactly (b_k >= 0)
                            bary[row, i, 0] = np.float32(b2 if swap == 1 else b1)
                            bary[row, i, 1] = np.float32(b1 if swap == 1 else b2)
                        else:
                            for k in range(2):
                                w0, w1, w2 = tri_weights[wrow, 0, k], tri_weights[wrow, 1, k], tri_weights[wrow, 2, k]
                                bary[row, i, k] = np.float32((b0 * w0 + b1 * w1) + b2 * w2)
                e0 -= dy0 * SUBPIXEL
                e1 -= dy1 * SUBPIXEL
                e2 -= dy2 * SUBPIXEL


@parallel_kernel
def rasterize_tiles(
    tri_int: np.ndarray, tri_float: np.ndarray, tri_weights: np.ndarray, tile_starts: np.ndarray,
    tile_triangles: np.ndarray, tiling: np.ndarray, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
) -> None:  # fmt: skip
    """Each tile owns its pixels of ``depth``, ``codes`` and ``bary``: no write races, deterministic output.

    tiling = (tile_size, tiles_x, clear) int64; with clear != 0 each tile first sets its depth to 1 and its
    codes to −1 (the buffers may be uninitialized). Tile ``t`` covers columns ``[tx·s, tx·s + s)`` and window rows
    ``[ty·s, ty·s + s)`` with ``tx = t % tiles_x``, ``ty = t // tiles_x``; its triangles, in drawing order, are
    ``tile_triangles[tile_starts[t]:tile_starts[t + 1]]``.
    """
    for t in prange(tile_starts.shape[0] - 1):
        _fill_tile(t, tri_int, tri_float, tri_weights, tile_starts, tile_triangles, tiling, depth, codes, bary)
