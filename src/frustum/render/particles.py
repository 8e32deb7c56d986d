"""The particle pass of ``render``: every particle layer of the scene over the finished opaque surfaces.

For each layer (``Scene.add_particles``), in scene order, the particles' world positions go through the camera
($clip = clip_from_world·[x, 1]$, divide, ``window_from_ndc``); a particle is drawn when $w > 0$ and
$−w <= z_clip <= w$ (between the near and far planes). Its radius in pixels is the projected size,
$R = size·|P₁₁|·H/2 / w$ (P the projection matrix, w the clip w: the view distance in perspective, 1 in
parallel projections). Sprites smaller than one pixel are drawn with R = 1 and α scaled by R² (the same
total light, no sprite lost between pixel centres); points with R at least ½.

Styles: ``"sprites"`` (camera-facing round discs with soft edges, ``raster.particles.SHAPE_ROUND``), ``"points"``
(hard squares of side 2R), ``"streaks"`` (a 1-pixel line from each particle's previous position to its current
one: motion blur; both ends must be in front of the camera). Blending: ``"additive"`` (fire, sparks: order
free) or ``"alpha"`` (smoke: drawn back to front by clip w, farthest first, a stable sort). Depth: tested
against the depth buffer of the surfaces ($z < depth$), never written, so particles behind a mesh are hidden
and particles do not hide one another.

Colors accumulate in float32 byte units and are rounded once per render ($⌊min(C, 255) + ½⌋$); the alpha
channel is left as the surfaces made it.

References
----------
Reeves 1983 §2.4 (rendering particles as additive point light sources, motion-blurred streaks);
[HB 15] "Particle Systems"; [seed] "Particle systems".
"""

from __future__ import annotations

from typing import Any

import numpy as np

from frustum.camera import Camera
from frustum.scene import ParticleLayer

__all__ = ["bands", "draw_particles", "project_particles", "project_streaks"]


def bands(rows: np.ndarray, height: int) -> tuple[np.ndarray, np.ndarray, int]:
    """(starts, entries, band_rows): the primitives of each band of ``BAND_ROWS`` rows, by first `rows` (count,
    prefix sum, fill; order kept), for the banded kernels of particles and point clouds."""
    from frustum.raster import particles as kernels

    band_rows = kernels.BAND_ROWS
    bands = (height + band_rows - 1) // band_rows
    counts = np.zeros(bands, dtype=np.int64)
    kernels.count_bands(rows, band_rows, counts)
    starts = np.zeros(bands + 1, dtype=np.int64)
    np.cumsum(counts, out=starts[1:])
    entries = np.empty(int(starts[-1]), dtype=np.int64)
    kernels.fill_bands(rows, band_rows, starts, entries)
    return starts, entries, band_rows


def _frame(camera: Camera, minimum: float) -> np.ndarray:
    """(width, height, |P₁₁|·H/2, minimum radius) for ``raster.particles.project_*``."""
    scale = abs(float(camera.projection_matrix[1, 1])) * camera.height / 2.0
    return np.array([camera.width, camera.height, scale, minimum], dtype=np.float64)


def _back_to_front(records: np.ndarray, rows: np.ndarray, depth_column: int) -> tuple[np.ndarray, np.ndarray]:
    """Records sorted by window depth, farthest first (stable): window depth grows with clip w."""
    order = np.argsort(-records[:, depth_column], kind="stable")
    return np.ascontiguousarray(records[order]), np.ascontiguousarray(rows[order])


def project_particles(system: Any, camera: Camera, style: str, blending: str) -> tuple[np.ndarray, np.ndarray]:
    """(sprites (K, 8) float64 rows x, y, z, R, r, g, b, α; rows (K, 2) int64 frame-row ranges) of the visible
    particles of `system`, in drawing order (back to front for alpha blending)."""
    from frustum.raster import particles as kernels

    count = system.count
    sprites = np.empty((count, kernels.SPRITE_FIELDS))
    rows = np.empty((count, 2), dtype=np.int64)
    kept = kernels.project_sprites(
        np.ascontiguousarray(system.positions), np.ascontiguousarray(system.sizes, dtype=np.float64),
        np.ascontiguousarray(system.colors, dtype=np.float64), np.ascontiguousarray(system.opacities, dtype=np.float64),
        np.ascontiguousarray(camera.clip_from_world, dtype=np.float64),
        _frame(camera, 1.0 if style == "sprites" else 0.5), sprites, rows,
    )  # fmt: skip
    sprites, rows = sprites[:kept], rows[:kept]
    return _back_to_front(sprites, rows, 2) if blending == "alpha" else (sprites, rows)


def project_streaks(system: Any, camera: Camera, blending: str) -> tuple[np.ndarray, np.ndarray]:
    """(streaks (K, 10) float64 rows x0, y0, z0, x1, y1, z1, r, g, b, α; rows (K, 2) int64) from each visible
    particle's previous position to its current one."""
    from frustum.raster import particles as kernels

    count = system.count
    streaks = np.empty((count, kernels.STREAK_FIELDS))
    rows = np.empty((count, 2), dtype=np.int64)
    kept = kernels.project_streaks(
        np.ascontiguousarray(system.positions), np.ascontiguousarray(system.previous_positions),
        np.ascontiguousarray(system.colors, dtype=np.float64), np.ascontiguousarray(system.opacities, dtype=np.float64),
        np.ascontiguousarray(camera.clip_from_world, dtype=np.float64), _frame(camera, 0.0), streaks, rows,
    )  # fmt: skip
    streaks, rows = streaks[:kept], rows[:kept]
    return _back_to_front(streaks, rows, 5) if blending == "alpha" else (streaks, rows)


def _spatial_order(primitives: np.ndarray, rows: np.ndarray, width: int) -> np.ndarray:
    """The drawing order of additive primitives: by (band of their first row, 32-pixel column tile), a stable
    counting sort (``count_bands``/``fill_bands`` over one key per primitive). Neighbours in the order are
    neighbours on screen, so the buffers stay in cache (1M random sprites at 1080p: 3.6x faster to draw). Addition
    commutes, so only the float32 rounding of the sums changes, the same on every run and thread count."""
    from frustum.raster import particles as kernels

    tiles_x = (width + 31) // 32
    keys = np.empty((rows.shape[0], 2), dtype=np.int64)
    np.floor_divide(rows[:, 0], kernels.BAND_ROWS, out=keys[:, 0])
    keys[:, 0] *= tiles_x
    keys[:, 0] += np.clip(primitives[:, 0] // 32, 0, tiles_x - 1).astype(np.int64)
    keys[:, 1] = keys[:, 0]
    count = int(keys[:, 0].max()) + 1 if keys.shape[0] else 0
    counts = np.zeros(count, dtype=np.int64)
    kernels.count_bands(keys, 1, counts)
    starts = np.zeros(count + 1, dtype=np.int64)
    np.cumsum(counts, out=starts[1:])
    order = np.empty(keys.shape[0], dtype=np.int64)
    kernels.fill_bands(keys, 1, starts, order)
    return order


def draw_particles(layers: list[ParticleLayer], camera: Camera, depth: np.ndarray, color: np.ndarray) -> None:
    """Blend every layer's particles into `color` ((H, W, 4) uint8, in place), depth-tested against `depth`."""
    if not layers:
        return
    from frustum.raster import particles as kernels

    height = depth.shape[0]
    accumulator = None
    for layer in layers:
        if layer.system.count == 0:
            continue
        mode = kernels.BLEND_ADDITIVE if layer.blending == "additive" else kernels.BLEND_ALPHA
        if layer.style == "streaks":
            primitives, rows = project_streaks(layer.system, camera, layer.blending)
        else:
            primitives, rows = project_particles(layer.system, camera, layer.style, layer.blending)
        if primitives.shape[0] == 0:
            continue
        if accumulator is None:
            accumulator = color[:, :, :3].astype(np.float32)
        if mode == kernels.BLEND_ADDITIVE:  # draw in screen order (records gathered, read sequentially)
            order = _spatial_order(primitives, rows, depth.shape[1])
            primitives, rows = np.take(primitives, order, axis=0), np.take(rows, order, axis=0)
        starts, entries, band_rows = bands(rows, height)
        if layer.style == "streaks":
            kernels.draw_streaks(primitives, starts, entries, band_rows, mode, depth, accumulator)
        else:
            shape = kernels.SHAPE_SQUARE if layer.style == "points" else kernels.SHAPE_ROUND
            kernels.draw_sprites(primitives, starts, entries, band_rows, shape, mode, depth, accumulator)
    if accumulator is not None:
        np.minimum(accumulator, 255.0, out=accumulator)
        accumulator += 0.5
        color[:, :, :3] = np.floor(accumulator)
