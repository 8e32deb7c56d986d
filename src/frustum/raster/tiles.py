"""Binning kernels: sort triangle records into square screen tiles, keeping drawing order inside each tile.

Count (parallel over chunks of triangles), prefix sum (serial, tile-major so chunk c's triangles precede
chunk c + 1's within every tile), fill (parallel over chunks). A triangle goes to every tile its pixel
bounding box touches. tiling = (tile_size, tiles_x, chunk) int64; tri_int as in ``triangles.py``.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel, prange

__all__ = ["count_tile_triangles", "fill_tile_triangles", "tile_offsets"]


@parallel_kernel
def count_tile_triangles(tri_int: np.ndarray, tiling: np.ndarray, counts: np.ndarray) -> None:
    """``counts[c, t]`` = how many triangles of chunk c touch tile t (counts (C, tiles) int64, written)."""
    size, tiles_x, chunk = tiling[0], tiling[1], tiling[2]
    total = tri_int.shape[0]
    for c in prange(counts.shape[0]):
        for t in range(counts.shape[1]):
            counts[c, t] = 0
        for k in range(c * chunk, min((c + 1) * chunk, total)):
            for ty in range(tri_int[k, 9] // size, tri_int[k, 10] // size + 1):
                for tx in range(tri_int[k, 7] // size, tri_int[k, 8] // size + 1):
                    counts[c, ty * tiles_x + tx] += 1


@kernel
def tile_offsets(counts: np.ndarray, offsets: np.ndarray, tile_starts: np.ndarray) -> None:
    """Exclusive prefix sum in tile-major order: ``offsets[c, t]`` where chunk c writes in tile t's list.

    tile_starts (tiles + 1,) int64 receives each tile's first slot and, last, the total.
    """
    running = 0
    for t in range(counts.shape[1]):
        tile_starts[t] = running
        for c in range(counts.shape[0]):
            offsets[c, t] = running
            running += counts[c, t]
    tile_starts[counts.shape[1]] = running


@parallel_kernel
def fill_tile_triangles(
    tri_int: np.ndarray, tiling: np.ndarray, offsets: np.ndarray, tile_triangles: np.ndarray
) -> None:
    """Write each triangle index into the lists of the tiles it touches (offsets (C, tiles) is consumed)."""
    size, tiles_x, chunk = tiling[0], tiling[1], tiling[2]
    total = tri_int.shape[0]
    for c in prange(offsets.shape[0]):
        for k in range(c * chunk, min((c + 1) * chunk, total)):
            for ty in range(tri_int[k, 9] // size, tri_int[k, 10] // size + 1):
                for tx in range(tri_int[k, 7] // size, tri_int[k, 8] // size + 1):
                    t = ty * tiles_x + tx
                    tile_triangles[offsets[c, t]] = k
                    offsets[c, t] += 1
