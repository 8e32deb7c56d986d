"""One pass per screen tile for a frame of one opaque mesh shaded by the metallic–roughness model (kernel module).

``raster.tiled``'s tile pipeline with ``raster.pbr``'s shading: per 64-pixel tile its triangles filled
(``triangles._fill_tile``) into tile-sized depth, codes and weights, the drawn pixels gathered
(``shade._gather_chunk``) and shaded a chunk at a time (``pbr.shade_chunk_pbr``: the same helpers in the same order
as ``pbr.shade_pixels_pbr``, so the bytes of the general path), the others painted with the background. For an
opaque item without textures, vertex colours, normal maps, depth cue, shadows or extra buffers
(``render.pbr.tiled``).
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import fence, kernel, parallel_kernel, stream
from frustum.raster.pbr import shade_chunk_pbr
from frustum.raster.shade import _CHUNK, _FIELDS, _NDL, _SIGN, _X, I_FACE_OFFSET, _gather_chunk
from frustum.raster.tiled import SPAN, segments
from frustum.raster.triangles import _fill_tile

__all__ = ["draw_tiles_pbr"]


# Kernel specialisation kept on purpose: raster.tiled.draw_tiles_directional's (and raster.shadow_tiled's) segment
# loop with the PBR chunk shader (a cached Numba kernel cannot take its shading step as an argument; the Phong one
# compiles no PBR term).
@parallel_kernel(lambda *args: segments(args[6].shape[0] - 1, args[8][1], args[8][0]), work=lambda *args: args[9].size,
                 grain=65536, pieces_per_thread=8)  # fmt: skip
def draw_tiles_pbr(
    faces: np.ndarray, win_int: np.ndarray, win_float: np.ndarray, tri_int: np.ndarray, tri_float: np.ndarray,
    tri_weights: np.ndarray, tile_starts: np.ndarray, tile_entries: np.ndarray, tiling: np.ndarray,
    depth: np.ndarray, world: np.ndarray, normals: np.ndarray, params: np.ndarray, lights: np.ndarray,
    item: np.ndarray, background: np.ndarray, color: np.ndarray, pbr: np.ndarray, sh: np.ndarray, maps: np.ndarray,
    table: np.ndarray, start: int, stop: int,
) -> None:  # fmt: skip
    """Segments [start, stop) of the frame as ``tiled.draw_tiles_directional`` (the same arguments, then
    ``pbr.shade_pixels_pbr``'s pbr, sh, maps and table): depth (H, W) float32 and color (H, W, 4) uint8 written."""
    size, tiles_x = tiling[0], tiling[1]
    height, width = depth.shape[0], depth.shape[1]
    near = np.empty((size, size), dtype=np.float32)  # the tile's own depth, codes and weights
    codes = np.empty((size, size), dtype=np.int64)
    bary = np.empty((size, size, 2), dtype=np.float32)
    per_segment = SPAN // size
    band_depth = np.empty((size, per_segment * size + 16), dtype=np.float32)
    band_words = np.empty((size, per_segment * size + 16, 1), dtype=np.uint32)
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
            n = _shade_tile_pbr(n, bottom - top, col1 - col0, col0 - left, near, codes, bary, faces, world, normals,
                                params, lights, item, word, band_words, scratch, where, corners, pbr, sh, maps,
                                table)  # fmt: skip
            for row in range(bottom - top):
                for col in range(col1 - col0):
                    band_depth[np.uint64(row), np.uint64(col0 - left + col)] = near[np.uint64(row), np.uint64(col)]
        _gather_chunk(n, scratch, where, corners, faces, world, normals)
        shade_chunk_pbr(n, scratch, where, params, pbr, lights, sh, maps, table, band_words)
        for row in range(bottom - top):  # the image is output only: written past the caches (no line read first)
            at_row = np.uint64(row)
            for col in range(right - left):
                stream(depth, top + row, left + col, band_depth[at_row, np.uint64(col)])
            for col in range(right - left):
                stream(image_words, top + row, left + col, band_words[at_row, np.uint64(col), 0])
    fence()


# Kernel specialisation kept on purpose: raster.tiled._shade_tile's listing with the PBR chunk shader.
@kernel
def _shade_tile_pbr(
    n: int, rows: int, cols: int, offset: int, depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
    faces: np.ndarray, world: np.ndarray, normals: np.ndarray, params: np.ndarray, lights: np.ndarray,
    item: np.ndarray, word: np.uint32, words: np.ndarray, scratch: np.ndarray, where: np.ndarray,
    corners: np.ndarray, pbr: np.ndarray, sh: np.ndarray, maps: np.ndarray, table: np.ndarray,
) -> int:  # fmt: skip
    """``tiled._shade_tile`` with each full chunk shaded by ``pbr.shade_chunk_pbr``: list the tile's drawn pixels
    after the n listed already, paint the others with the background word; return how many are listed now."""
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
                shade_chunk_pbr(n, scratch, where, params, pbr, lights, sh, maps, table, words)
                n = 0
    return n
