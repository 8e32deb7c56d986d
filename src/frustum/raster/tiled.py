"""One pass per screen tile for a frame of one opaque mesh: clear, fill, shade (llvmpipe's tile pipeline).

The general path runs each stage over the whole image: clear depth and color, fill every tile into image-sized
face codes and weights, then scan the image again to shade. For one opaque mesh shaded by the directional fast
path (``shade.shade_pixels_directional``) all three happen tile by tile instead, while the tile's 32 × 32 pixels
are in the core's L1 cache: its triangles are filled (``triangles._fill_tile``) into depth, codes and weights that
live in tile-sized contiguous scratch (no image-sized codes or weights at all; an image row stride that is a
multiple of 4 KiB would put a tile's rows of the image in one cache set), its drawn pixels gathered and shaded
(``shade._gather_chunk``, ``shade._shade_chunk``, a chunk filling across tiles) and the others painted with the
background. Each tile is owned by one thread, so the bytes are those of the general path on any number of threads.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import fence, kernel, parallel_kernel, stream
from frustum.raster.shade import _CHUNK, _FIELDS, _NDL, _SIGN, _X, I_FACE_OFFSET, _gather_chunk, _shade_chunk
from frustum.raster.triangles import _fill_tile

__all__ = ["SPAN", "draw_tiles_directional", "segments"]


SPAN = 512
"""Pixels per segment: a segment of a tile row (``SPAN // tile size`` tiles) is finished in a buffer (tile size ×
512 pixels, 2 × 128 KiB for 64-pixel tiles: it stays in L2 cache), then copied out. Segments are the pieces the
threads take: 512 rather than 1024 pixels balances them better where the surfaces crowd the image's middle (a
1024² bunny: 16 pieces → 32; 3–8 % less frame time on every standard scene)."""


# kernel specialisation kept on purpose: raster.shadow_tiled.draw_tiles_shadowed repeats its tile loop, and
# raster.pbr_tiled.draw_tiles_pbr with the PBR chunk shader
@parallel_kernel(lambda *args: segments(args[6].shape[0] - 1, args[8][1], args[8][0]), work=lambda *args: args[9].size,
                 grain=65536, pieces_per_thread=8)  # fmt: skip
def draw_tiles_directional(
    faces: np.ndarray, win_int: np.ndarray, win_float: np.ndarray, tri_int: np.ndarray, tri_float: np.ndarray,
    tri_weights: np.ndarray, tile_starts: np.ndarray, tile_entries: np.ndarray, tiling: np.ndarray,
    depth: np.ndarray, world: np.ndarray, normals: np.ndarray, params: np.ndarray, lights: np.ndarray,
    item: np.ndarray, background: np.ndarray, color: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Segments [start, stop) of the frame (``segments``: up to ``SPAN`` pixels of tiles of one tile row):
    depth (H, W) float32 and color (H, W, 4) uint8 (C-contiguous) written.

    The binned triangles and `tiling` as in ``triangles.rasterize_tiles``; world, normals, params, lights and item
    as in ``shade.shade_pixels_directional``; background (4,) uint8, the clear color's bytes. Each finished tile
    goes to a segment buffer whose rows are padded by a cache line (copied from a tile, the rows of an image whose
    stride is a multiple of 4 KiB would all fall in one cache set), and each finished segment (2 × 128 KiB, in
    L2 cache) to the image, row by row, by non-temporal stores (``_jit.stream``: the image is output only, and
    ordinary stores read each of its lines before writing it; 10 % of a 4096² frame).
    """
    size, tiles_x = tiling[0], tiling[1]
    height, width = depth.shape[0], depth.shape[1]
    near = np.empty((size, size), dtype=np.float32)  # the tile's own depth, codes and weights
    codes = np.empty((size, size), dtype=np.int64)
    bary = np.empty((size, size, 2), dtype=np.float32)
    per_segment = SPAN // size
    span = per_segment * size
    band_depth = np.empty((size, span + 16), dtype=np.float32)
    band_words = np.empty((size, span + 16, 1), dtype=np.uint32)
    scratch = np.empty(_FIELDS * _CHUNK)
    where = np.empty(3 * _CHUNK, dtype=np.int64)
    corners = np.empty(3 * _CHUNK, dtype=np.int64)
    image_words = color.view(np.uint32).reshape((height, width))
    word = background.view(np.uint32)[0]
    per_row = -(-tiles_x // per_segment)
    for segment in range(start, stop):
        band, first = segment // per_row, (segment % per_row) * per_segment
        top = max(height - (band + 1) * size, 0)  # image rows [top, bottom): the band's window rows
        bottom = height - band * size
        left, right = first * size, min((first + per_segment) * size, width)  # image columns [left, right)
        n = 0  # pixels listed for shading: a chunk fills across the segment's tiles
        for t in range(band * tiles_x + first, band * tiles_x + min(first + per_segment, tiles_x)):
            col0 = (t % tiles_x) * size
            col1 = min(col0 + size, width)
            if tile_starts[t] == tile_starts[t + 1]:  # no triangle: background
                for row in range(bottom - top):
                    for col in range(col0 - left, col1 - left):
                        band_depth[row, col] = 1.0
                        band_words[row, col, 0] = word
                continue
            near[:, :] = 1.0
            _fill_tile(
                t, faces, win_int, win_float, tri_int, tri_float, tri_weights, tile_starts, tile_entries, tiling,
                near, codes, bary, top, col0,
            )  # fmt: skip
            n = _shade_tile(n, bottom - top, col1 - col0, col0 - left, near, codes, bary, faces, world, normals,
                            params, lights, item, word, band_words, scratch, where, corners)  # fmt: skip
            for row in range(bottom - top):
                for col in range(col1 - col0):
                    band_depth[np.uint64(row), np.uint64(col0 - left + col)] = near[np.uint64(row), np.uint64(col)]
        _gather_chunk(n, scratch, where, corners, faces, world, normals)
        _shade_chunk(n, scratch, where, params, lights, band_words)
        for row in range(bottom - top):  # the image is output only: written past the caches (no line read first)
            at_row = np.uint64(row)
            for col in range(right - left):
                stream(depth, top + row, left + col, band_depth[at_row, np.uint64(col)])
            for col in range(right - left):
                stream(image_words, top + row, left + col, band_words[at_row, np.uint64(col), 0])
    fence()


def segments(tiles: int, tiles_x: int, size: int) -> int:
    """How many segments ``draw_tiles_directional`` splits `tiles` tiles of `size` pixels, `tiles_x` to a row,
    into."""
    return tiles // tiles_x * -(-tiles_x // (SPAN // size))


# Kernel specialisation kept on purpose: raster.pbr_tiled._shade_tile_pbr repeats this listing for the PBR shader.
@kernel
def _shade_tile(
    n: int, rows: int, cols: int, offset: int, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
    faces: np.ndarray, world: np.ndarray, normals: np.ndarray, params: np.ndarray, lights: np.ndarray,
    item: np.ndarray, word: np.uint32, words: np.ndarray, scratch: np.ndarray, where: np.ndarray,
    corners: np.ndarray,
) -> int:  # fmt: skip
    """List the drawn pixels of a tile's own depth, codes and bary (`rows` × `cols`) after the n listed already,
    shading each full chunk (as ``shade._shade_rows_directional``) into the segment's color words (tile column c
    at ``offset + c``), and paint the others with the background word; return how many are listed now."""
    face_offset = item[I_FACE_OFFSET]
    for row in range(rows):
        at_row = np.uint64(row)  # unsigned indices: no negative-index fix-up
        for col in range(cols):
            at = np.uint64(col)
            if not depth[at_row, at] < 1.0:
                words[at_row, np.uint64(offset + col), 0] = word
                continue
            code = codes[at_row, at]  # the one mesh's: written wherever depth < 1
            scratch[_X + n], scratch[_NDL + n] = float(bary[at_row, at, 0]), float(bary[at_row, at, 1])
            scratch[_SIGN + n] = -1.0 if code & 1 else 1.0
            where[n], where[_CHUNK + n], where[2 * _CHUNK + n] = row, offset + col, (code >> 1) - face_offset
            n += 1
            if n == _CHUNK:
                _gather_chunk(n, scratch, where, corners, faces, world, normals)
                _shade_chunk(n, scratch, where, params, lights, words)
                n = 0
    return n
