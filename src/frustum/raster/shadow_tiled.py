"""The one-mesh tile pipeline (``raster.tiled``) with shadow maps: clear, fill and shade tile by tile, each drawn
pixel's shadow-map lookups done inside the shading of its chunk.

Off the ordinary path: compiled only when ``render(..., shadows=True)`` draws a frame of one opaque mesh whose
shading is the directional fast path (``render.shadows.draw_tiled``); ``raster.tiled`` itself is unchanged.

Per chunk of drawn pixels: ``shade._gather_chunk`` (interpolated normal and world point), then ``_fractions``
(the unit face normal turned toward the viewer, and each light's fraction through ``raster.shadow._lookup`` on
its map, as ``raster.shadow.map_visibility`` finds it for the stage-by-stage path), then ``_shade_chunk_shadowed``
(``shade._shade_chunk`` with each light's diffuse and specular terms scaled by its fraction, the operations of
``raster.shadow._illuminate_visible`` in the same order).
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import fence, kernel, parallel_kernel, prefetch, stream
from frustum.raster.shade import (
    _CHUNK,
    _DB,
    _DG,
    _DR,
    _FIELDS,
    _NDL,
    _NX,
    _NY,
    _NZ,
    _POW,
    _PX,
    _PY,
    _PZ,
    _SB,
    _SG,
    _SIGN,
    _SR,
    _VX,
    _VY,
    _VZ,
    _X,
    I_FACE_OFFSET,
    P_AMBIENT,
    P_COLOR,
    P_DIFFUSE,
    P_EMISSIVE,
    P_EYE,
    P_LIGHT_AMBIENT,
    P_SHININESS,
    P_SPECULAR,
    _gather_chunk,
    _squarable,
    _to_byte,
)  # fmt: skip
from frustum.raster.shadow import M_FAR, M_NEAR, M_TEXEL, SLOPE_LIMIT
from frustum.raster.tiled import SPAN, segments
from frustum.raster.triangles import _fill_tile

__all__ = ["draw_tiles_shadowed"]


# Kernel specialization kept on purpose: ``raster.tiled.draw_tiles_directional`` with shadow-map lookups per pixel.
@parallel_kernel(lambda *args: segments(args[6].shape[0] - 1, args[8][1], args[8][0]), work=lambda *args: args[9].size,
                 grain=65536, pieces_per_thread=8)  # fmt: skip
def draw_tiles_shadowed(
    faces: np.ndarray, win_int: np.ndarray, win_float: np.ndarray, tri_int: np.ndarray, tri_float: np.ndarray,
    tri_weights: np.ndarray, tile_starts: np.ndarray, tile_entries: np.ndarray, tiling: np.ndarray,
    depth: np.ndarray, world: np.ndarray, normals: np.ndarray, params: np.ndarray, lights: np.ndarray,
    item: np.ndarray, background: np.ndarray, color: np.ndarray, maps: np.ndarray, views: np.ndarray,
    map_of: np.ndarray, softness: float, owner: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """``raster.tiled.draw_tiles_directional`` with shadows: maps (M, S, S) float32 and their records views
    (M, MAP_FIELDS) (``raster.shadow``), map_of (K,) int64 the map of each light (row of `lights`), −1 for a light
    casting no shadow; softness the PCF radius in texels (``raster.shadow._lookup``). Several items drawn as one
    mesh: `params` (I, P) one row of shading parameters per item and `owner` (F,) the row of each face (a chunk of
    pixels is shaded with one row: it is finished where the row changes); one item: `owner` empty, row 0."""
    size, tiles_x = tiling[0], tiling[1]
    height, width = depth.shape[0], depth.shape[1]
    near = np.empty((size, size), dtype=np.float32)
    codes = np.empty((size, size), dtype=np.int64)
    bary = np.empty((size, size, 2), dtype=np.float32)
    per_segment = SPAN // size
    span = per_segment * size
    band_depth = np.empty((size, span + 16), dtype=np.float32)
    band_words = np.empty((size, span + 16, 1), dtype=np.uint32)
    scratch = np.empty((_FIELDS + lights.shape[0]) * _CHUNK)
    where = np.empty(3 * _CHUNK, dtype=np.int64)
    corners = np.empty(3 * _CHUNK, dtype=np.int64)
    image_words = color.view(np.uint32).reshape((height, width))
    word = background.view(np.uint32)[0]
    per_row = -(-tiles_x // per_segment)
    for segment in range(start, stop):
        band, first = segment // per_row, (segment % per_row) * per_segment
        top = max(height - (band + 1) * size, 0)
        bottom = height - band * size
        left, right = first * size, min((first + per_segment) * size, width)
        n, current = 0, 0
        for t in range(band * tiles_x + first, band * tiles_x + min(first + per_segment, tiles_x)):
            col0 = (t % tiles_x) * size
            col1 = min(col0 + size, width)
            if tile_starts[t] == tile_starts[t + 1]:
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
            n, current = _shade_tile(n, current, bottom - top, col1 - col0, col0 - left, near, codes, bary, faces,
                                     world, normals, params, lights, item, word, band_words, scratch, where, corners,
                                     maps, views, map_of, softness, owner)  # fmt: skip
            for row in range(bottom - top):
                for col in range(col1 - col0):
                    band_depth[np.uint64(row), np.uint64(col0 - left + col)] = near[np.uint64(row), np.uint64(col)]
        _finish_chunk(n, scratch, where, corners, faces, world, normals, params[np.uint64(current)], lights,
                      band_words, maps, views, map_of, softness)  # fmt: skip
        for row in range(bottom - top):
            at_row = np.uint64(row)
            for col in range(right - left):
                stream(depth, top + row, left + col, band_depth[at_row, np.uint64(col)])
            for col in range(right - left):
                stream(image_words, top + row, left + col, band_words[at_row, np.uint64(col), 0])
    fence()


@kernel
def _shade_tile(
    n: int, current: int, rows: int, cols: int, offset: int, depth: np.ndarray, codes: np.ndarray,
    bary: np.ndarray, faces: np.ndarray, world: np.ndarray, normals: np.ndarray, params: np.ndarray,
    lights: np.ndarray, item: np.ndarray, word: np.uint32, words: np.ndarray, scratch: np.ndarray,
    where: np.ndarray, corners: np.ndarray, maps: np.ndarray, views: np.ndarray, map_of: np.ndarray,
    softness: float, owner: np.ndarray,
) -> tuple[int, int]:  # fmt: skip
    """``raster.tiled._shade_tile`` whose full chunks (and chunks whose item row `current` changes, ``owner``)
    are finished by ``_finish_chunk``; the pixels listed and the row they are shaded with."""
    face_offset = item[I_FACE_OFFSET]
    several = owner.shape[0] > 0
    for row in range(rows):
        at_row = np.uint64(row)
        for col in range(cols):
            at = np.uint64(col)
            if not depth[at_row, at] < 1.0:
                words[at_row, np.uint64(offset + col), 0] = word
                continue
            code = codes[at_row, at]
            face = (code >> 1) - face_offset
            if several:
                found = owner[np.uint64(face)]
                if found != current:
                    if n > 0:
                        _finish_chunk(n, scratch, where, corners, faces, world, normals, params[np.uint64(current)],
                                      lights, words, maps, views, map_of, softness)  # fmt: skip
                        n = 0
                    current = found
            scratch[_X + n], scratch[_NDL + n] = float(bary[at_row, at, 0]), float(bary[at_row, at, 1])
            scratch[_SIGN + n] = -1.0 if code & 1 else 1.0
            where[n], where[_CHUNK + n], where[2 * _CHUNK + n] = row, offset + col, face
            n += 1
            if n == _CHUNK:
                _finish_chunk(n, scratch, where, corners, faces, world, normals, params[np.uint64(current)], lights,
                              words, maps, views, map_of, softness)  # fmt: skip
                n = 0
    return n, current


@kernel
def _finish_chunk(
    n: int, scratch: np.ndarray, where: np.ndarray, corners: np.ndarray, faces: np.ndarray, world: np.ndarray,
    normals: np.ndarray, params: np.ndarray, lights: np.ndarray, words: np.ndarray, maps: np.ndarray,
    views: np.ndarray, map_of: np.ndarray, softness: float,
) -> None:  # fmt: skip
    """Gather, find the lights' fractions, shade and store the first n listed pixels."""
    _gather_chunk(n, scratch, where, corners, faces, world, normals)
    _unit_normals(n, scratch)
    _fractions(n, scratch, corners, world, lights, maps, views, map_of, softness)
    _shade_chunk_shadowed(n, scratch, where, params, lights, words)


@kernel
def _unit_toward(nx: float, ny: float, nz: float, sign: float) -> tuple[float, float, float]:
    """(nx, ny, nz) made unit and turned to the drawn side (`sign` ±1); a zero vector gives (0, 0, sign) — the
    operations of ``shade._shade_chunk``'s first step, in its order (the same bytes)."""
    length = math.sqrt((nx * nx + ny * ny) + nz * nz)
    zero = length == 0.0
    nx = 0.0 if zero else nx
    ny = 0.0 if zero else ny
    nz = 1.0 if zero else nz
    length = 1.0 if zero else length
    return sign * nx / length, sign * ny / length, sign * nz / length


@kernel
def _unit_normals(n: int, s: np.ndarray) -> None:
    """The interpolated normals of the first n gathered pixels made unit and turned to the drawn side, in place
    (the first step of ``shade._shade_chunk``, the same operations): ``_fractions`` reads them to skip the
    lookups of pixels that turn away from a light."""
    for i in range(n):
        s[_NX + i], s[_NY + i], s[_NZ + i] = _unit_toward(s[_NX + i], s[_NY + i], s[_NZ + i], s[_SIGN + i])


@kernel
def _fractions(
    n: int, s: np.ndarray, corners: np.ndarray, world: np.ndarray, lights: np.ndarray, maps: np.ndarray,
    views: np.ndarray, map_of: np.ndarray, softness: float,
) -> None:  # fmt: skip
    """Row ``_FIELDS + k`` of the scratch: the fraction of light k reaching each of the first n gathered pixels
    (float32 values, as the stage-by-stage path stores them): 0 where the drawn side of the face looks away from
    the light, the map's lookup inside it (``raster.shadow._lookup``'s test for an orthographic map, inline), 1
    outside it and for a light without a map. The unit face normals, turned toward the viewer, go to the ``_VX``
    rows (``_shade_chunk_shadowed`` writes them later)."""
    for i in range(n):
        needed = False  # only a pixel whose shading normal faces a light with a map is looked up
        for k in range(lights.shape[0]):
            ndl = (s[_NX + i] * lights[k, 7] + s[_NY + i] * lights[k, 8]) + s[_NZ + i] * lights[k, 9]
            needed = needed or (map_of[k] >= 0 and ndl > 0.0)
        if not needed:
            s[_VX + i], s[_VY + i], s[_VZ + i] = 0.0, 0.0, 0.0
            continue
        a, b, c = np.uint64(corners[i]), np.uint64(corners[_CHUNK + i]), np.uint64(corners[2 * _CHUNK + i])
        e1x, e1y, e1z = world[b, 0] - world[a, 0], world[b, 1] - world[a, 1], world[b, 2] - world[a, 2]
        e2x, e2y, e2z = world[c, 0] - world[a, 0], world[c, 1] - world[a, 1], world[c, 2] - world[a, 2]
        nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
        s[_VX + i], s[_VY + i], s[_VZ + i] = _unit_toward(nx, ny, nz, s[_SIGN + i])
    for k in range(lights.shape[0]):
        row_k = (_FIELDS + k) * _CHUNK
        at = map_of[k]
        if at < 0:
            for i in range(n):
                s[row_k + i] = 1.0
            continue
        shadow_map = maps[np.uint64(at)]
        v = views[np.uint64(at)]
        lx, ly, lz = lights[k, 7], lights[k, 8], lights[k, 9]
        texel, near, depth_range = v[M_TEXEL], v[M_NEAR], v[M_FAR] - v[M_NEAR]
        if not 0.0 < softness <= 1.0:  # hard, or a wider grid: the general filter
            _fractions_general(n, s, row_k, shadow_map, v, lx, ly, lz, texel, near, depth_range, softness)
            continue
        _fractions_bilinear(n, s, row_k, shadow_map, v, lx, ly, lz, texel, near, depth_range, softness)


@kernel
def _fractions_general(
    n: int, s: np.ndarray, row_k: int, shadow_map: np.ndarray, v: np.ndarray, lx: float, ly: float, lz: float,
    texel: float, near: float, depth_range: float, softness: float,
) -> None:  # fmt: skip
    """``_fractions`` of one light with the general filter (``_filter``): hard, or a grid wider than 2 × 2."""
    size = shadow_map.shape[0]
    for i in range(n):
        nx, ny, nz = s[_VX + i], s[_VY + i], s[_VZ + i]
        cos_theta = (nx * lx + ny * ly) + nz * lz
        if cos_theta <= 0.0 or (s[_NX + i] * lx + s[_NY + i] * ly) + s[_NZ + i] * lz <= 0.0:
            s[row_k + i] = 0.0
            continue
        cos_theta = min(cos_theta, 1.0)
        sine = math.sqrt(1.0 - cos_theta * cos_theta)
        tan_theta = SLOPE_LIMIT if cos_theta * SLOPE_LIMIT <= sine else sine / cos_theta
        px, py, pz = s[_PX + i] + texel * nx, s[_PY + i] + texel * ny, s[_PZ + i] + texel * nz
        x = ((v[0] * px + v[1] * py) + v[2] * pz) + v[3]
        y = ((v[4] * px + v[5] * py) + v[6] * pz) + v[7]
        z = ((v[8] * px + v[9] * py) + v[10] * pz) + v[11]
        if not (0.0 <= x < size and 0.0 <= y < size):
            s[row_k + i] = 1.0
            continue
        receiver = near + min(max(z, 0.0), 1.0) * depth_range
        limit = receiver - texel * (1.0 + (1.0 + softness) * tan_theta)  # bias taken off
        s[row_k + i] = float(np.float32(_filter(shadow_map, x, y, limit, near, depth_range, softness)))


_LOOKUP, _LIT, _UNLIT, _EDGE = 2.0, 1.0, 0.0, 3.0


@kernel
def _fractions_bilinear(
    n: int, s: np.ndarray, row_k: int, shadow_map: np.ndarray, v: np.ndarray, lx: float, ly: float, lz: float,
    texel: float, near: float, depth_range: float, softness: float,
) -> None:  # fmt: skip
    """``_fractions`` of one light with the default filter: 2 × 2 texels bilinearly weighted (``_filter``'s first
    case, the same operations). Three passes over the chunk: where each point falls on the map, its weights and
    the test's limit, without a branch (vectorized); the texel rows prefetched; the four taps, without a branch
    for points whose taps all lie on the map (a point at the map's border: ``_filter``)."""
    size = shadow_map.shape[0]
    extent = float(size)
    ramp = 1.0 / softness
    slope = 1.0 + softness
    v0, v1, v2, v3, v4, v5, v6, v7 = v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]
    v8, v9, v10, v11 = v[8], v[9], v[10], v[11]
    # scratch rows free until _shade_chunk_shadowed: _DR, _DG the weights, _DB the limit, _SR what to do
    # (_UNLIT, _LIT, _LOOKUP, _EDGE), _SG, _SB the texel column and row
    for i in range(n):
        nx, ny, nz = s[_VX + i], s[_VY + i], s[_VZ + i]
        cos_theta = (nx * lx + ny * ly) + nz * lz
        facing = (cos_theta > 0.0) & ((s[_NX + i] * lx + s[_NY + i] * ly) + s[_NZ + i] * lz > 0.0)
        cos_theta = min(cos_theta, 1.0) if cos_theta > 0.0 else 1.0
        sine = math.sqrt(1.0 - cos_theta * cos_theta)
        tan_theta = SLOPE_LIMIT if cos_theta * SLOPE_LIMIT <= sine else sine / cos_theta
        px, py, pz = s[_PX + i] + texel * nx, s[_PY + i] + texel * ny, s[_PZ + i] + texel * nz
        x = ((v0 * px + v1 * py) + v2 * pz) + v3
        y = ((v4 * px + v5 * py) + v6 * pz) + v7
        z = ((v8 * px + v9 * py) + v10 * pz) + v11
        inside = (x >= 0.0) & (x < extent) & (y >= 0.0) & (y < extent)
        receiver = near + min(max(z, 0.0), 1.0) * depth_range
        gx, gy = x - 0.5, y - 0.5
        fx, fy = math.floor(gx), math.floor(gy)
        s[_DR + i] = min(max((gx - fx - 0.5) * ramp + 0.5, 0.0), 1.0)
        s[_DG + i] = min(max((gy - fy - 0.5) * ramp + 0.5, 0.0), 1.0)
        s[_DB + i] = receiver - texel * (1.0 + slope * tan_theta)  # bias taken off
        row = (extent - 1.0) - fy  # texel columns col, col + 1; rows row (lower), row − 1
        interior = (fx >= 0.0) & (fx < extent - 1.0) & (row >= 1.0) & (row < extent)
        state = (_LOOKUP if interior else _EDGE) if inside else _LIT
        s[_SR + i] = state if facing else _UNLIT
        s[_X + i], s[_NDL + i] = x, y  # (free until the shading) for a point at the border
        s[_SG + i] = fx if interior else 0.0
        s[_SB + i] = row if interior else 1.0
    for i in range(n):
        if s[_SR + i] == _LOOKUP:
            at_row, at = np.uint64(s[_SB + i]), np.uint64(s[_SG + i])
            prefetch(shadow_map, at_row, at)
            prefetch(shadow_map, at_row - np.uint64(1), at)
    for i in range(n):  # every point's taps (clamped onto the map where not looked up), selects for the tests
        wx, wy, limit = s[_DR + i], s[_DG + i], s[_DB + i]
        lower, left = np.uint64(s[_SB + i]), np.uint64(s[_SG + i])
        upper, right = lower - np.uint64(1), left + np.uint64(1)
        a, b = shadow_map[lower, left], shadow_map[lower, right]
        c, d = shadow_map[upper, left], shadow_map[upper, right]
        t00 = 1.0 if (a >= 1.0) | (limit <= near + a * depth_range) else 0.0
        t10 = 1.0 if (b >= 1.0) | (limit <= near + b * depth_range) else 0.0
        t01 = 1.0 if (c >= 1.0) | (limit <= near + c * depth_range) else 0.0
        t11 = 1.0 if (d >= 1.0) | (limit <= near + d * depth_range) else 0.0
        taps = (1.0 - wy) * ((1.0 - wx) * t00 + wx * t10) + wy * ((1.0 - wx) * t01 + wx * t11)
        state = s[_SR + i]
        s[row_k + i] = float(np.float32(taps)) if state == _LOOKUP else (1.0 if state == _LIT else 0.0)
    for i in range(n):  # points at the map's border: the filter with its bounds tests
        if s[_SR + i] == _EDGE:
            found = _edge_taps(shadow_map, s[_X + i], s[_NDL + i], s[_DB + i], near, depth_range, ramp)
            s[row_k + i] = float(np.float32(found))


@kernel
def _edge_taps(
    shadow_map: np.ndarray, x: float, y: float, limit: float, near: float, depth_range: float, ramp: float
) -> float:  # fmt: skip
    """The 2 × 2 bilinear filter at window point (x, y) of a point at the map's border: taps off the map count as
    lit (``_tap``); the weights ramp over 1 / `ramp` texels."""
    size = shadow_map.shape[0]
    gx, gy = x - 0.5, y - 0.5
    fx, fy = math.floor(gx), math.floor(gy)
    wx = min(max((gx - fx - 0.5) * ramp + 0.5, 0.0), 1.0)
    wy = min(max((gy - fy - 0.5) * ramp + 0.5, 0.0), 1.0)
    col, row = int(fx), size - 1 - int(fy)  # texel columns col, col + 1; rows row (lower), row − 1
    t00 = _tap(shadow_map, row, col, limit, near, depth_range)
    t10 = _tap(shadow_map, row, col + 1, limit, near, depth_range)
    t01 = _tap(shadow_map, row - 1, col, limit, near, depth_range)
    t11 = _tap(shadow_map, row - 1, col + 1, limit, near, depth_range)
    return (1.0 - wy) * ((1.0 - wx) * t00 + wx * t10) + wy * ((1.0 - wx) * t01 + wx * t11)


@kernel
def _filter(
    shadow_map: np.ndarray, x: float, y: float, limit: float, near: float, depth_range: float, softness: float
) -> float:  # fmt: skip
    """``raster.shadow._lookup``'s filter on an orthographic map at window point (x, y): the share of its taps whose
    stored distance $near + stored·range$ is not nearer than `limit` (or that are empty, or off the map)."""
    size = shadow_map.shape[0]
    if 0.0 < softness <= 1.0:
        gx, gy = x - 0.5, y - 0.5
        fx, fy = math.floor(gx), math.floor(gy)
        col, up = int(fx), int(fy)
        wx = min(max((gx - fx - 0.5) / softness + 0.5, 0.0), 1.0)
        wy = min(max((gy - fy - 0.5) / softness + 0.5, 0.0), 1.0)
        t00 = _tap(shadow_map, size - 1 - up, col, limit, near, depth_range)
        t10 = _tap(shadow_map, size - 1 - up, col + 1, limit, near, depth_range)
        t01 = _tap(shadow_map, size - 2 - up, col, limit, near, depth_range)
        t11 = _tap(shadow_map, size - 2 - up, col + 1, limit, near, depth_range)
        return (1.0 - wy) * ((1.0 - wx) * t00 + wx * t10) + wy * ((1.0 - wx) * t01 + wx * t11)
    steps = int(math.ceil(softness))  # noqa: RUF046 (an int in Python, a float's type for Numba's typing)
    step = softness / steps if steps > 0 else 0.0
    lit = 0.0
    for j in range(-steps, steps + 1):
        row = size - 1 - int(math.floor(y + j * step))  # noqa: RUF046
        for i in range(-steps, steps + 1):
            lit += _tap(shadow_map, row, int(math.floor(x + i * step)), limit, near, depth_range)  # noqa: RUF046
    return lit / ((2 * steps + 1) * (2 * steps + 1))


@kernel
def _tap(shadow_map: np.ndarray, row: int, col: int, limit: float, near: float, depth_range: float) -> float:
    """1.0 where texel (row, col) lets a point whose biased distance is `limit` see the light (or lies off the
    map)."""
    size = shadow_map.shape[0]
    if row < 0 or row >= size or col < 0 or col >= size:
        return 1.0
    stored = shadow_map[np.uint64(row), np.uint64(col)]
    return 1.0 if stored >= 1.0 or limit <= near + stored * depth_range else 0.0


# Kernel specialization kept on purpose: ``raster.shade._shade_chunk`` with each light's fraction as its visibility.
@kernel
def _shade_chunk_shadowed(
    n: int, s: np.ndarray, where: np.ndarray, params: np.ndarray, lights: np.ndarray, words: np.ndarray
) -> None:  # fmt: skip
    """``shade._shade_chunk`` with light k's diffuse and specular terms scaled by its fraction (scratch row
    ``_FIELDS + k``): $k_d·(f·ndl)$, $k_s·(f·spec)$, nothing added where $f = 0$ (``_illuminate_visible``)."""
    ex, ey, ez = params[P_EYE], params[P_EYE + 1], params[P_EYE + 2]
    ka, kd, ks, shininess = params[P_AMBIENT], params[P_DIFFUSE], params[P_SPECULAR], params[P_SHININESS]
    ar, ag, ab = ka * params[P_LIGHT_AMBIENT], ka * params[P_LIGHT_AMBIENT + 1], ka * params[P_LIGHT_AMBIENT + 2]
    for i in range(n):  # the normals are unit already (_unit_normals)
        vx, vy, vz = ex - s[_PX + i], ey - s[_PY + i], ez - s[_PZ + i]
        length = math.sqrt((vx * vx + vy * vy) + vz * vz)
        positive = length > 0.0
        s[_VX + i] = vx / length if positive else vx
        s[_VY + i] = vy / length if positive else vy
        s[_VZ + i] = vz / length if positive else vz
        s[_DR + i], s[_DG + i], s[_DB + i] = ar, ag, ab
        s[_SR + i], s[_SG + i], s[_SB + i] = 0.0, 0.0, 0.0
    for k in range(lights.shape[0]):
        lx, ly, lz = lights[k, 7], lights[k, 8], lights[k, 9]
        seen = (_FIELDS + k) * _CHUNK
        for i in range(n):
            nx, ny, nz = s[_NX + i], s[_NY + i], s[_NZ + i]
            hx, hy, hz = lx + s[_VX + i], ly + s[_VY + i], lz + s[_VZ + i]
            length = math.sqrt((hx * hx + hy * hy) + hz * hz)
            positive = length > 0.0
            hx = hx / length if positive else hx
            hy = hy / length if positive else hy
            hz = hz / length if positive else hz
            s[_NDL + i] = (nx * lx + ny * ly) + nz * lz
            s[_X + i] = max((nx * hx + ny * hy) + nz * hz, 0.0)
            s[_POW + i] = 1.0
        if _squarable(shininess):
            e = int(shininess)
            while e > 0:
                if e & 1:
                    for i in range(n):
                        s[_POW + i] *= s[_X + i]
                e >>= 1
                if e > 0:
                    for i in range(n):
                        s[_X + i] *= s[_X + i]
        else:
            for i in range(n):
                s[_POW + i] = s[_X + i] ** shininess
        r, g, b = lights[k, 1], lights[k, 2], lights[k, 3]
        for i in range(n):
            ndl = s[_NDL + i]
            fraction = s[seen + i]
            lit = not (ndl <= 0.0 or fraction == 0.0)
            diffuse = kd * (fraction * ndl)
            specular = ks * (fraction * s[_POW + i])
            s[_DR + i] = s[_DR + i] + diffuse * r if lit else s[_DR + i]
            s[_DG + i] = s[_DG + i] + diffuse * g if lit else s[_DG + i]
            s[_DB + i] = s[_DB + i] + diffuse * b if lit else s[_DB + i]
            s[_SR + i] = s[_SR + i] + specular * r if lit else s[_SR + i]
            s[_SG + i] = s[_SG + i] + specular * g if lit else s[_SG + i]
            s[_SB + i] = s[_SB + i] + specular * b if lit else s[_SB + i]
    r, g, b = params[P_COLOR], params[P_COLOR + 1], params[P_COLOR + 2]
    er, eg, eb = params[P_EMISSIVE], params[P_EMISSIVE + 1], params[P_EMISSIVE + 2]
    for i in range(n):
        where[2 * _CHUNK + i] = (
            int(_to_byte((r * s[_DR + i] + s[_SR + i]) + er))
            | int(_to_byte((g * s[_DG + i] + s[_SG + i]) + eg)) << 8
            | int(_to_byte((b * s[_DB + i] + s[_SB + i]) + eb)) << 16
            | 255 << 24
        )
    for i in range(n):
        words[np.uint64(where[i]), np.uint64(where[_CHUNK + i]), 0] = where[2 * _CHUNK + i]
