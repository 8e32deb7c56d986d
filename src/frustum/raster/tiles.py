"""Binning kernels: sort the faces to draw into square screen tiles, keeping drawing order inside each tile.

This is also the per-face half of triangle setup (``triangles.face_box``: trivial reject and accept by region
codes, back-face cull by the signed window area, pixel bounding box): nothing per face is stored but its tile
list entries, and the count pass's list of the faces that draw anything (with the one tile of each small face),
so the fill visits those only. Count (parallel over chunks of faces), records of the clipped faces added to
their face's chunk, prefix sum (serial, tile-major so chunk c's entries precede chunk c + 1's within every
tile), fill (parallel over chunks). A face goes to every tile its pixel
bounding box touches; a crossing face's clipped triangles (``triangles.clip_faces``) go, in fan order, where the
face is. options = (width, height, cull, tile_bits, tiles_x, chunk, face_offset) int64: tiles are
``2^tile_bits`` pixels square, so a pixel's tile index is a shift.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL
from frustum.raster.triangles import CROSSING, FACE_CROSSING, FACE_DRAWN, covers_centre, face_box

__all__ = ["add_record_tiles", "count_tiles", "fill_tiles", "tile_offsets"]

O_WIDTH, O_HEIGHT, O_CULL, O_BITS, O_TILES_X, O_CHUNK, O_FACE_OFFSET = 0, 1, 2, 3, 4, 5, 6


@parallel_kernel(lambda *args: args[4].shape[0])  # counts: one row per chunk of faces
def count_tiles(
    faces: np.ndarray, codes: np.ndarray, win_int: np.ndarray, options: np.ndarray, counts: np.ndarray,
    crossing: np.ndarray, listed: np.ndarray, listed_tiles: np.ndarray, listed_counts: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """``counts[c, t]`` = how many drawn faces of chunk c touch tile t; ``crossing[c]`` = its crossing faces.

    counts (C, tiles), crossing (C,) and listed_counts (C,) int64 are written; chunk c is faces
    [c·chunk, (c+1)·chunk); a face whose box holds one pixel centre counts only if it covers it (most sub-pixel
    triangles of a fine mesh do not). The chunk's drawn and crossing faces, in order, go to ``listed`` (M,) from
    ``c·chunk`` on, ``listed_counts[c]`` of them: the fill visits only those (most faces of a fine mesh draw
    nothing, being back faces or falling between pixel centres). ``listed_tiles`` (M,) beside each: the one
    tile a drawn face touches, −1 when it touches several (the fill then reads the face again; small faces, the
    many, are filled from these two sequential arrays alone), ``triangles.CROSSING`` when it crosses the view
    volume.
    """
    width, height, cull = options[O_WIDTH], options[O_HEIGHT], options[O_CULL]
    bits, tiles_x, chunk = options[O_BITS], options[O_TILES_X], options[O_CHUNK]
    for c in range(start, stop):
        for t in range(counts.shape[1]):
            counts[c, t] = 0
        crossed = 0
        n = c * chunk
        for f in range(c * chunk, min((c + 1) * chunk, faces.shape[0])):
            state, back, i_min, i_max, j_min, j_max = face_box(faces, codes, win_int, f, width, height, cull)
            if state == FACE_CROSSING:
                crossed += 1
                listed[n], listed_tiles[n] = f, CROSSING
                n += 1
            elif state == FACE_DRAWN:
                if i_min == i_max and j_min == j_max and not _covers_its_centre(faces, win_int, f, back, i_min, j_min):
                    continue  # a sub-pixel triangle missing the one centre of its box (most of a fine mesh's)
                one = (j_min >> bits) == (j_max >> bits) and (i_min >> bits) == (i_max >> bits)
                listed[n], listed_tiles[n] = f, ((j_min >> bits) * tiles_x + (i_min >> bits)) if one else -1
                n += 1
                for ty in range(j_min >> bits, (j_max >> bits) + 1):
                    for tx in range(i_min >> bits, (i_max >> bits) + 1):
                        counts[c, ty * tiles_x + tx] += 1
        crossing[c] = crossed
        listed_counts[c] = n - c * chunk


@kernel
def _covers_its_centre(faces: np.ndarray, win_int: np.ndarray, f: int, back: int, i: int, j: int) -> bool:
    """Whether face f (drawn from its vertices; corners 1 and 2 swapped when back) covers pixel (i, j)'s centre."""
    a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
    if back == 1:
        b, c = c, b
    return covers_centre(
        np.int64(win_int[a, 0]), np.int64(win_int[a, 1]), np.int64(win_int[b, 0]), np.int64(win_int[b, 1]),
        np.int64(win_int[c, 0]), np.int64(win_int[c, 1]), SUBPIXEL * i + HALF_SUBPIXEL, SUBPIXEL * j + HALF_SUBPIXEL,
    )  # fmt: skip


@kernel
def add_record_tiles(tri_int: np.ndarray, options: np.ndarray, counts: np.ndarray) -> None:
    """Add to ``counts[c, t]`` the clipped triangle records (``triangles``) whose source face is in chunk c."""
    bits, tiles_x, chunk = options[O_BITS], options[O_TILES_X], options[O_CHUNK]
    for r in range(tri_int.shape[0]):
        c = (tri_int[r, 6] // 2 - options[O_FACE_OFFSET]) // chunk
        for ty in range(tri_int[r, 9] >> bits, (tri_int[r, 10] >> bits) + 1):
            for tx in range(tri_int[r, 7] >> bits, (tri_int[r, 8] >> bits) + 1):
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


@parallel_kernel(lambda *args: args[7].shape[0])  # offsets: one row per chunk of faces
def fill_tiles(
    faces: np.ndarray, codes: np.ndarray, win_int: np.ndarray, options: np.ndarray, listed: np.ndarray,
    listed_tiles: np.ndarray, listed_counts: np.ndarray, offsets: np.ndarray, crossing_starts: np.ndarray,
    record_starts: np.ndarray, tri_int: np.ndarray, tile_entries: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Write each drawn face's index (and ``−1 − r`` for each record r of a clipped face) into the lists of the
    tiles it touches, in face order: the faces ``count_tiles`` listed, a one-tile face straight from
    ``listed_tiles``, the others by ``face_box`` again. offsets (C, tiles) is consumed;
    crossing_starts (C,) is the index of chunk c's first crossing face among all crossing faces, whose records
    are ``record_starts[k]:record_starts[k + 1]``.
    """
    width, height, cull = options[O_WIDTH], options[O_HEIGHT], options[O_CULL]
    bits, tiles_x, chunk = options[O_BITS], options[O_TILES_X], options[O_CHUNK]
    for c in range(start, stop):
        k = crossing_starts[c]
        for n in range(c * chunk, c * chunk + listed_counts[c]):
            f = listed[n]
            t = listed_tiles[n]
            if t >= 0:
                tile_entries[offsets[c, t]] = f
                offsets[c, t] += 1
                continue
            if t == CROSSING:
                for r in range(record_starts[k], record_starts[k + 1]):
                    for ty in range(tri_int[r, 9] >> bits, (tri_int[r, 10] >> bits) + 1):
                        for tx in range(tri_int[r, 7] >> bits, (tri_int[r, 8] >> bits) + 1):
                            t = ty * tiles_x + tx
                            tile_entries[offsets[c, t]] = -1 - r
                            offsets[c, t] += 1
                k += 1
                continue
            state, _, i_min, i_max, j_min, j_max = face_box(faces, codes, win_int, f, width, height, cull)
            if state == FACE_DRAWN:
                for ty in range(j_min >> bits, (j_max >> bits) + 1):
                    for tx in range(i_min >> bits, (i_max >> bits) + 1):
                        t = ty * tiles_x + tx
                        tile_entries[offsets[c, t]] = f
                        offsets[c, t] += 1
