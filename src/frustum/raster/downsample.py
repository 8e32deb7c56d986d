"""Supersampling resolve: s×s blocks of the big buffers into one output pixel (parallel over output rows).

Color: the box filter in integers, ``floor(Σ bytes / s² + 1/2) = (2·Σ + s²) // (2·s²)`` per channel (exactly
the rounded mean). Depth: the nearest (smallest) window depth of the block.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import parallel_kernel, prange

__all__ = ["resolve_color", "resolve_depth"]


@parallel_kernel
def resolve_color(big: np.ndarray, factor: int, out: np.ndarray) -> None:
    """big (H·s, W·s, 4) uint8 → out (H, W, 4) uint8, the rounded mean of each s×s block."""
    area = factor * factor
    for row in prange(out.shape[0]):
        for col in range(out.shape[1]):
            for k in range(4):
                total = 0
                for i in range(factor):
                    for j in range(factor):
                        total += np.int64(big[row * factor + i, col * factor + j, k])
                out[row, col, k] = np.uint8((2 * total + area) // (2 * area))


@parallel_kernel
def resolve_depth(big: np.ndarray, factor: int, out: np.ndarray) -> None:
    """big (H·s, W·s) float32 → out (H, W) float32, the minimum of each s×s block."""
    for row in prange(out.shape[0]):
        for col in range(out.shape[1]):
            nearest = big[row * factor, col * factor]
            for i in range(factor):
                for j in range(factor):
                    nearest = min(nearest, big[row * factor + i, col * factor + j])
            out[row, col] = nearest
