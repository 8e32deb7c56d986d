"""Particle kernels: round soft sprites, square points and streaks blended into a float color buffer.

Each primitive is depth-tested against the (finished) depth buffer, $z < depth[row, col]$, and never writes
depth. Colors accumulate in a float32 ``(H, W, 3)`` buffer in byte units (0–255): additive blending
$C ← C + α·255·c$ (fire, sparks) or alpha blending $C ← α·255·c + (1 − α)·C$ (smoke, in the caller's
back-to-front order). The caller converts the buffer to bytes once.

Parallel work: primitives are binned into bands of rows (``count_bands`` / ``fill_bands``, a counting sort that
keeps the primitive order inside each band); each band is drawn by one thread, which owns its rows, so there
are no write races and the result does not depend on the thread count.

Contract (kernels never validate): ``sprites`` (N, SPRITE_FIELDS) float64 rows $x, y, z, radius, r, g, b, α$
in window coordinates (y up, pixel centres at half-integers, z window depth in [0, 1]), radius in pixels
> 0; ``streaks`` (N, STREAK_FIELDS) rows $x0, y0, z0, x1, y1, z1, r, g, b, α$; ``rows`` (N, 2) int64 first and
last frame row each primitive touches (clamped to the image); buffers C-contiguous.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel

__all__ = [
    "BAND_ROWS",
    "BLEND_ADDITIVE",
    "BLEND_ALPHA",
    "SHAPE_ROUND",
    "SHAPE_SQUARE",
    "SPRITE_FIELDS",
    "STREAK_FIELDS",
    "count_bands",
    "draw_sprites",
    "draw_streaks",
    "fill_bands",
    "project_sprites",
    "project_streaks",
]

SPRITE_FIELDS = 8
STREAK_FIELDS = 10
BLEND_ADDITIVE = 0
BLEND_ALPHA = 1
SHAPE_ROUND = 0
"""A disc whose opacity falls off as ``α·(1 − r²/R²)²`` from its centre (soft edge, 0 at the rim)."""
SHAPE_SQUARE = 1
"""A hard square of side 2R: every pixel centre in ``[x − R, x + R) × [y − R, y + R)`` at full α."""
BAND_ROWS = 16
"""Rows per band: the unit of parallel work."""


@kernel
def _clip_row(m: np.ndarray, k: int, x: float, y: float, z: float) -> float:
    """Row k of $M·[x, y, z, 1]$."""
    return ((m[k, 0] * x + m[k, 1] * y) + m[k, 2] * z) + m[k, 3]


@kernel
def project_sprites(positions: np.ndarray, sizes: np.ndarray, colors: np.ndarray, opacities: np.ndarray,
                    clip_from_world: np.ndarray, frame: np.ndarray, sprites: np.ndarray,
                    rows: np.ndarray) -> int:  # fmt: skip
    """Project every particle and write the visible ones, in order, as sprite records; returns their number.

    ``frame`` = (width, height, pixel scale |P₁₁|·H/2, minimum radius). A particle is kept when $w > 0$,
    $−w <= z_clip <= w$, its disc of radius $R = size·scale/w$ (at least the minimum, α scaled by
    $(R/minimum)²$ below it) touches the image and its α > 0. Window $x = (x_c/w + 1)·W/2$,
    $y = (y_c/w + 1)·H/2$, depth ``(z_c/w + 1)/2`` (``viewport(0, 0, W, H)``).
    """
    width, height, scale, minimum = frame[0], frame[1], frame[2], frame[3]
    last_row = int(height) - 1
    count = 0
    for k in range(positions.shape[0]):
        x, y, z = positions[k, 0], positions[k, 1], positions[k, 2]
        w = _clip_row(clip_from_world, 3, x, y, z)
        zc = _clip_row(clip_from_world, 2, x, y, z)
        if not (w > 0.0 and -w <= zc <= w):
            continue
        radius = sizes[k] * scale / w
        alpha = opacities[k]
        if radius < minimum:
            alpha *= (radius / minimum) ** 2
            radius = minimum
        if not alpha > 0.0:
            continue
        wx = (_clip_row(clip_from_world, 0, x, y, z) / w + 1.0) * (width / 2.0)
        wy = (_clip_row(clip_from_world, 1, x, y, z) / w + 1.0) * (height / 2.0)
        low_y = math.ceil(wy - radius - 0.5)
        high_y = math.floor(wy + radius - 0.5)
        if high_y < 0 or low_y > last_row or wx + radius <= 0.0 or wx - radius >= width:
            continue
        sprites[count, 0], sprites[count, 1], sprites[count, 2] = wx, wy, (zc / w + 1.0) * 0.5
        sprites[count, 3] = radius
        sprites[count, 4], sprites[count, 5], sprites[count, 6] = colors[k, 0], colors[k, 1], colors[k, 2]
        sprites[count, 7] = alpha
        rows[count, 0] = max(last_row - high_y, 0)
        rows[count, 1] = min(last_row - low_y, last_row)
        count += 1
    return count


@kernel
def project_streaks(heads: np.ndarray, tails: np.ndarray, colors: np.ndarray, opacities: np.ndarray,
                    clip_from_world: np.ndarray, frame: np.ndarray, streaks: np.ndarray,
                    rows: np.ndarray) -> int:  # fmt: skip
    """Project both ends of every particle's streak (tail = previous position, head = current one) and write the
    visible ones, in order; returns their number. Both ends must satisfy $w > 0$ and $−w <= z_clip <= w$."""
    width, height = frame[0], frame[1]
    last_row = int(height) - 1
    count = 0
    for k in range(heads.shape[0]):
        if not opacities[k] > 0.0:
            continue
        inside = True
        for end in range(2):
            points = tails if end == 0 else heads
            x, y, z = points[k, 0], points[k, 1], points[k, 2]
            w = _clip_row(clip_from_world, 3, x, y, z)
            zc = _clip_row(clip_from_world, 2, x, y, z)
            if not (w > 0.0 and -w <= zc <= w):
                inside = False
                break
            streaks[count, 3 * end] = (_clip_row(clip_from_world, 0, x, y, z) / w + 1.0) * (width / 2.0)
            streaks[count, 3 * end + 1] = (_clip_row(clip_from_world, 1, x, y, z) / w + 1.0) * (height / 2.0)
            streaks[count, 3 * end + 2] = (zc / w + 1.0) * 0.5
        if not inside:
            continue
        top = math.floor(max(streaks[count, 1], streaks[count, 4]))
        bottom = math.floor(min(streaks[count, 1], streaks[count, 4]))
        left = min(streaks[count, 0], streaks[count, 3])
        right = max(streaks[count, 0], streaks[count, 3])
        if top < 0 or bottom > last_row or right < 0.0 or left >= width:
            continue
        streaks[count, 6], streaks[count, 7], streaks[count, 8] = colors[k, 0], colors[k, 1], colors[k, 2]
        streaks[count, 9] = opacities[k]
        rows[count, 0] = max(last_row - top, 0)
        rows[count, 1] = min(last_row - bottom, last_row)
        count += 1
    return count


@kernel
def count_bands(rows: np.ndarray, band_rows: int, counts: np.ndarray) -> None:
    """counts[b] = number of primitives whose row range meets band b (counts zeroed by the caller)."""
    for k in range(rows.shape[0]):
        if rows[k, 0] > rows[k, 1]:
            continue
        for b in range(rows[k, 0] // band_rows, rows[k, 1] // band_rows + 1):
            counts[b] += 1


@kernel
def fill_bands(rows: np.ndarray, band_rows: int, starts: np.ndarray, entries: np.ndarray) -> None:
    """entries[starts[b] : starts[b + 1]] = the primitives meeting band b, in primitive order (`starts` is the
    exclusive prefix sum of ``count_bands``, (B + 1,))."""
    cursor = starts[:-1].copy()
    for k in range(rows.shape[0]):
        if rows[k, 0] > rows[k, 1]:
            continue
        for b in range(rows[k, 0] // band_rows, rows[k, 1] // band_rows + 1):
            entries[cursor[b]] = k
            cursor[b] += 1


@kernel
def _blend(accumulator: np.ndarray, row: int, col: int, r: float, g: float, b: float, alpha: float,
           mode: int) -> None:  # fmt: skip
    if mode == BLEND_ADDITIVE:
        accumulator[row, col, 0] += alpha * 255.0 * r
        accumulator[row, col, 1] += alpha * 255.0 * g
        accumulator[row, col, 2] += alpha * 255.0 * b
    else:
        keep = 1.0 - alpha
        accumulator[row, col, 0] = alpha * 255.0 * r + keep * accumulator[row, col, 0]
        accumulator[row, col, 1] = alpha * 255.0 * g + keep * accumulator[row, col, 1]
        accumulator[row, col, 2] = alpha * 255.0 * b + keep * accumulator[row, col, 2]


@parallel_kernel(lambda sprites, starts, *_: starts.size - 1)
def draw_sprites(sprites: np.ndarray, starts: np.ndarray, entries: np.ndarray, band_rows: int, shape: int,
                 mode: int, depth: np.ndarray, accumulator: np.ndarray, start: int, stop: int) -> None:  # fmt: skip
    """Draw every sprite of every band (parallel over bands) into `accumulator`, depth-tested, depth unchanged.

    Pixel (row, col) has its centre at window $(col + ½, H − 1 − row + ½)$.
    """
    height, width = depth.shape
    # kernel specialisation kept on purpose: the same band loop as draw_streaks below and raster/points.py
    # (one band of rows per thread), inlined with each primitive's own coverage loop
    for band in range(start, stop):
        first_row = band * band_rows
        last_row = min(first_row + band_rows, height) - 1
        for e in range(starts[band], starts[band + 1]):
            k = entries[e]
            x, y, z, radius = sprites[k, 0], sprites[k, 1], sprites[k, 2], sprites[k, 3]
            r, g, b, alpha = sprites[k, 4], sprites[k, 5], sprites[k, 6], sprites[k, 7]
            # window rows y_w with centre y_w + ½ inside [y − R, y + R]; frame row = H − 1 − y_w
            low_y = max(math.ceil(y - radius - 0.5), height - 1 - last_row)
            high_y = min(math.floor(y + radius - 0.5), height - 1 - first_row)
            low_x = max(math.ceil(x - radius - 0.5), 0)
            high_x = min(math.floor(x + radius - 0.5), width - 1)
            inverse = 1.0 / (radius * radius)
            for wy in range(low_y, high_y + 1):
                row = height - 1 - wy
                dy = wy + 0.5 - y
                for col in range(low_x, high_x + 1):
                    if not z < depth[row, col]:
                        continue
                    if shape == SHAPE_SQUARE:
                        if col + 0.5 >= x + radius or wy + 0.5 >= y + radius:
                            continue
                        weight = 1.0
                    else:
                        dx = col + 0.5 - x
                        fall = 1.0 - (dx * dx + dy * dy) * inverse
                        if fall <= 0.0:
                            continue
                        weight = fall * fall
                    _blend(accumulator, row, col, r, g, b, alpha * weight, mode)


@parallel_kernel(lambda streaks, starts, *_: starts.size - 1)
def draw_streaks(streaks: np.ndarray, starts: np.ndarray, entries: np.ndarray, band_rows: int, mode: int,
                 depth: np.ndarray, accumulator: np.ndarray, start: int, stop: int) -> None:  # fmt: skip
    """Draw every streak (a 1-pixel DDA line from (x0, y0) to (x1, y1), depth linear along it) of every band.

    The line is sampled at ``n + 1`` evenly spaced points, $n = max(⌈max(|Δx|, |Δy|)⌉, 1)$; sample t = k/n
    lands in the pixel containing it ($⌊x⌋, ⌊y⌋$) and blends with α once per sample.
    """
    height, width = depth.shape
    # kernel specialisation kept on purpose: the same band loop as draw_sprites above, with a DDA line inside
    for band in range(start, stop):
        first_row = band * band_rows
        last_row = min(first_row + band_rows, height) - 1
        for e in range(starts[band], starts[band + 1]):
            k = entries[e]
            x0, y0, z0 = streaks[k, 0], streaks[k, 1], streaks[k, 2]
            dx, dy, dz = streaks[k, 3] - x0, streaks[k, 4] - y0, streaks[k, 5] - z0
            r, g, b, alpha = streaks[k, 6], streaks[k, 7], streaks[k, 8], streaks[k, 9]
            n = max(math.ceil(max(abs(dx), abs(dy))), 1)
            for step in range(n + 1):
                t = step / n
                col = math.floor(x0 + t * dx)
                wy = math.floor(y0 + t * dy)
                row = height - 1 - wy
                if row < first_row or row > last_row or col < 0 or col >= width:
                    continue
                z = z0 + t * dz
                if z < depth[row, col]:
                    _blend(accumulator, row, col, r, g, b, alpha, mode)
