"""Eye-dome lighting (EDL): a post-pass that shows the shape of unlit geometry (point clouds of scans) from the
depth buffer alone.

For each drawn pixel p (depth < 1), with $L = log₂ d$ of its view distance d (from the window depth through the
projection matrix), the obscurance of its 8 neighbours q at a distance of ``RADIUS`` pixels is
$R(p) = Σ_q max(0, L(p) − L(q)) / 8$ (background neighbours count 0), and its color is multiplied by
$exp(−300·strength·R(p))$: pixels with nearer neighbours (edges, creases, the far side of a silhouette) darken.

References
----------
Boucheny, "Visualisation scientifique de grands volumes de données" (PhD thesis, 2009), §4.4 (eye-dome
lighting); the constants (8 neighbours, 300) are those of Potree's and CloudCompare's EDL shaders.
"""

from __future__ import annotations

import numpy as np

from frustum.camera import Camera
from frustum.render.context import FrameContext
from frustum.render.options import RenderOptions

__all__ = ["RADIUS", "obscurance", "shade"]

RADIUS = 1
"""Neighbour distance in pixels of the image drawn (√samples times it when supersampling)."""


def view_distance(depth: np.ndarray, clip_from_view: np.ndarray) -> np.ndarray:
    """(H, W) float64 view distance $−z_view$ of window depths: $z_ndc = 2·depth − 1$ and
    $z_view = (P₂₃ − z_ndc·P₃₃)/(z_ndc·P₃₂ − P₂₂)$ (P the projection matrix)."""
    z_ndc = 2.0 * depth.astype(np.float64) - 1.0
    p = clip_from_view
    return -(p[2, 3] - z_ndc * p[3, 3]) / (z_ndc * p[3, 2] - p[2, 2])


def obscurance(depth: np.ndarray, clip_from_view: np.ndarray, radius: int = RADIUS) -> np.ndarray:
    """(H, W) float64 R(p) of the module docstring (0 on background)."""
    drawn = depth < 1.0
    level = np.zeros(depth.shape)
    level[drawn] = np.log2(np.maximum(view_distance(depth, clip_from_view)[drawn], 1e-30))
    height, width = depth.shape
    padded = np.pad(level, radius)
    padded_drawn = np.pad(drawn, radius)
    total = np.zeros(depth.shape)
    for dy in (-radius, 0, radius):
        for dx in (-radius, 0, radius):
            if dx == 0 and dy == 0:
                continue
            neighbour = padded[radius + dy : radius + dy + height, radius + dx : radius + dx + width]
            seen = padded_drawn[radius + dy : radius + dy + height, radius + dx : radius + dx + width]
            total += np.where(seen, np.maximum(level - neighbour, 0.0), 0.0)
    total[~drawn] = 0.0
    return total / 8.0


def shade(camera: Camera, options: RenderOptions, buffers: FrameContext) -> None:
    """Multiply the drawn pixels' colors by $exp(−300·strength·R)$ (in place), when ``options.eye_dome`` > 0."""
    if not options.eye_dome > 0.0:
        return
    response = obscurance(buffers.depth, np.asarray(camera.projection_matrix, dtype=np.float64),
                          RADIUS * options.factor)  # fmt: skip
    factor = np.exp(-300.0 * options.eye_dome * response)
    color = buffers.color
    color[..., :3] = np.floor(color[..., :3] * factor[..., None] + 0.5).astype(np.uint8)
