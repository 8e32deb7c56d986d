"""The 1/256-pixel fixed-point grid shared by the triangle and line kernels (8 fractional bits, as llvmpipe).

Window x and y snap to $X = floor(x_w·256 + 0.5)$; pixel (i, j) has its centre at $(256·i + 128, 256·j + 128)$.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel

__all__ = ["HALF_SUBPIXEL", "SUBPIXEL", "SUBPIXEL_BITS", "snap"]

SUBPIXEL_BITS = 8
"""``X >> SUBPIXEL_BITS`` is ``floor(X / 256)`` for any int64 X (an arithmetic shift floors)."""
SUBPIXEL = 256
"""Subpixel steps per pixel (8 fractional bits), as in llvmpipe."""
HALF_SUBPIXEL = 128
"""Offset of a pixel centre from its lower-left corner, in subpixel steps."""


@kernel
def snap(value: float) -> int:
    """Round a window coordinate to the 1/256 pixel grid: $floor(v·256 + 0.5)$."""
    return np.int64(math.floor(value * 256.0 + 0.5))
