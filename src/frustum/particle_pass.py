"""The particle pass of ``render``: every particle layer of the scene over the finished opaque surfaces.

For each layer (``Scene.add_particles``), in scene order, the particles' world positions go through the camera
(``clip = clip_from_world·[x, 1]``, divide, ``window_from_ndc``); a particle is drawn when ``w > 0`` and
``−w <= z_clip <= w`` (between the near and far planes). Its radius in pixels is the projected size,
``R = size·|P₁₁|·H/2 / w`` (P the projection matrix, w the clip w: the view distance in perspective, 1 in
parallel projections). Sprites smaller than one pixel are drawn with R = 1 and α scaled by R² (the same
total light, no sprite lost between pixel centres); points with R at least ½.

Styles: ``"sprites"`` (camera-facing round discs with soft edges, ``raster.particles.SHAPE_ROUND``), ``"points"``
(hard squares of side 2R), ``"streaks"`` (a 1-pixel line from each particle's previous position to its current
one: motion blur; both ends must be in front of the camera). Blending: ``"additive"`` (fire, sparks: order
free) or ``"alpha"`` (smoke: drawn back to front by clip w, farthest first, a stable sort). Depth: tested
against the depth buffer of the surfaces (``z < depth``), never written, so particles behind a mesh are hidden
and particles do not hide one another.

Colors accumulate in float32 byte units and are rounded once per render (``⌊min(C, 255) + ½⌋``); the alpha
channel is left as the surfaces made it.

References
----------
Reeves 1983 §2.4 (rendering particles as additive point light sources, motion-blurred streaks);
[HB 14] "Particle Systems"; [seed] "Particle systems".
"""

from __future__ import annotations

from typing import Any

import numpy as np

from frustum.camera import Camera
from frustum.scene import ParticleLayer

__all__ = ["draw_particles", "project_particles", "project_streaks"]


def _clip(camera: Camera, points: np.ndarray) -> np.ndarray:
    m = np.asarray(camera.clip_from_world, dtype=np.float64)
    return points @ m[:, :3].T + m[:, 3]


def _window(camera: Camera, clip: np.ndarray) -> np.ndarray:
    """(N, 3) window coordinates (x, y, depth) of clip points with w > 0."""
    v = np.asarray(camera.viewport_matrix, dtype=np.float64)
    ndc = clip[:, :3] / clip[:, 3:4]
    return ndc @ v[:3, :3].T + v[:3, 3]


def _in_depth_range(clip: np.ndarray) -> np.ndarray:
    w = clip[:, 3]
    return (w > 0.0) & (clip[:, 2] >= -w) & (clip[:, 2] <= w)


def project_particles(system: Any, camera: Camera, style: str, blending: str) -> tuple[np.ndarray, np.ndarray]:
    """(sprites (K, 8) float64 rows x, y, z, R, r, g, b, α; rows (K, 2) int64 frame-row ranges) of the visible
    particles of `system`, in drawing order (back to front for alpha blending)."""
    height, width = camera.height, camera.width
    clip = _clip(camera, np.asarray(system.positions))
    visible = np.flatnonzero(_in_depth_range(clip))
    clip = clip[visible]
    window = _window(camera, clip)
    scale = abs(float(camera.projection_matrix[1, 1])) * height / 2.0
    radius = np.asarray(system.sizes)[visible] * scale / clip[:, 3]
    alpha = np.asarray(system.opacities)[visible].copy()
    minimum = 1.0 if style == "sprites" else 0.5
    small = radius < minimum
    alpha[small] *= (radius[small] / minimum) ** 2
    radius = np.maximum(radius, minimum)
    x, y = window[:, 0], window[:, 1]
    low_y = np.ceil(y - radius - 0.5)
    high_y = np.floor(y + radius - 0.5)
    on_screen = (high_y >= 0) & (low_y <= height - 1) & (x + radius > 0.0) & (x - radius < width) & (alpha > 0.0)
    keep = np.flatnonzero(on_screen)
    if blending == "alpha":
        keep = keep[np.argsort(-clip[keep, 3], kind="stable")]
    sprites = np.empty((keep.size, 8))
    sprites[:, :3] = window[keep]
    sprites[:, 3] = radius[keep]
    sprites[:, 4:7] = np.asarray(system.colors)[visible[keep]]
    sprites[:, 7] = alpha[keep]
    rows = np.empty((keep.size, 2), dtype=np.int64)
    rows[:, 0] = np.clip(height - 1 - high_y[keep], 0, height - 1)
    rows[:, 1] = np.clip(height - 1 - low_y[keep], 0, height - 1)
    return sprites, rows


def project_streaks(system: Any, camera: Camera, blending: str) -> tuple[np.ndarray, np.ndarray]:
    """(streaks (K, 10) float64 rows x0, y0, z0, x1, y1, z1, r, g, b, α; rows (K, 2) int64) from each visible
    particle's previous position to its current one."""
    height, width = camera.height, camera.width
    head = _clip(camera, np.asarray(system.positions))
    tail = _clip(camera, np.asarray(system.previous_positions))
    visible = np.flatnonzero(_in_depth_range(head) & _in_depth_range(tail))
    head_w, tail_w = _window(camera, head[visible]), _window(camera, tail[visible])
    top = np.floor(np.maximum(head_w[:, 1], tail_w[:, 1]))
    bottom = np.floor(np.minimum(head_w[:, 1], tail_w[:, 1]))
    left = np.minimum(head_w[:, 0], tail_w[:, 0])
    right = np.maximum(head_w[:, 0], tail_w[:, 0])
    alpha = np.asarray(system.opacities)[visible]
    on_screen = (top >= 0) & (bottom <= height - 1) & (right >= 0.0) & (left < width) & (alpha > 0.0)
    keep = np.flatnonzero(on_screen)
    if blending == "alpha":
        keep = keep[np.argsort(-head[visible[keep], 3], kind="stable")]
    streaks = np.empty((keep.size, 10))
    streaks[:, 0:3] = tail_w[keep]
    streaks[:, 3:6] = head_w[keep]
    streaks[:, 6:9] = np.asarray(system.colors)[visible[keep]]
    streaks[:, 9] = alpha[keep]
    rows = np.empty((keep.size, 2), dtype=np.int64)
    rows[:, 0] = np.clip(height - 1 - top[keep], 0, height - 1)
    rows[:, 1] = np.clip(height - 1 - bottom[keep], 0, height - 1)
    return streaks, rows


def _bands(rows: np.ndarray, height: int) -> tuple[np.ndarray, np.ndarray, int]:
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


def draw_particles(layers: list[ParticleLayer], camera: Camera, depth: np.ndarray, color: np.ndarray) -> None:
    """Blend every layer's particles into `color` ((H, W, 4) uint8, in place), depth-tested against `depth`."""
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
        starts, entries, band_rows = _bands(rows, height)
        if layer.style == "streaks":
            kernels.draw_streaks(primitives, starts, entries, band_rows, mode, depth, accumulator)
        else:
            shape = kernels.SHAPE_SQUARE if layer.style == "points" else kernels.SHAPE_ROUND
            kernels.draw_sprites(primitives, starts, entries, band_rows, shape, mode, depth, accumulator)
    if accumulator is not None:
        np.minimum(accumulator, 255.0, out=accumulator)
        accumulator += 0.5
        color[:, :, :3] = np.floor(accumulator)
