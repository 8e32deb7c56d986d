"""The chaos-game kernel of ``geometry/fractals.py`` (iterated function systems).

Kernels only (numpy + numba): imported on first use by the module named above, so ``import frustum`` never
loads Numba.
"""

from __future__ import annotations

from frustum.raster._jit import kernel


@kernel
def _chaos_game_kernel(linear, offset, choices, start, skip, out):  # pragma: no cover - compiled
    """x ← A_k x + b_k for k = choices[t]; rows t >= skip are written to out. Arrays contiguous."""
    x0, x1, x2 = start[0], start[1], start[2]
    for t in range(choices.shape[0]):
        k = choices[t]
        y0 = linear[k, 0, 0] * x0 + linear[k, 0, 1] * x1 + linear[k, 0, 2] * x2 + offset[k, 0]
        y1 = linear[k, 1, 0] * x0 + linear[k, 1, 1] * x1 + linear[k, 1, 2] * x2 + offset[k, 1]
        y2 = linear[k, 2, 0] * x0 + linear[k, 2, 1] * x1 + linear[k, 2, 2] * x2 + offset[k, 2]
        x0, x1, x2 = y0, y1, y2
        if t >= skip:
            out[t - skip, 0] = x0
            out[t - skip, 1] = x1
            out[t - skip, 2] = x2
