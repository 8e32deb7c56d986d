"""One fused particle step for the common forces: semi-implicit Euler under $a = c − k·v$, then plane collisions.

Gravity, drag and wind are linear in the velocity: $a = g + Σ k_w·w − (Σ k_d + Σ k_w)·v = c − k·v$. One pass per
particle (parallel over particles; each row independent, so the result does not depend on the thread count):
``previous ← x``, $v ← v + (c − k·v)·dt$, $x ← x + v·dt$, ``age ← age + dt``, then for each plane
(point p, unit normal n, restitution e, friction μ) with $d = (x − p)·n < 0$: $x ← x − (1 + e)·d·n$ and, if
$v·n < 0$, $v ← (1 − μ)·(v − (v·n)·n) − e·(v·n)·n$. The same formulas as ``frustum.simulation`` (whole-array
numpy) to round-off.

Contract (kernels never validate): positions, velocities, previous (N, 3) float64; ages (N,) float64; constant
(3,) float64; planes (P, 8) float64 rows $p (3), n (3), e, μ$. Returns the number of rows left non-finite.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import parallel_kernel, prange

__all__ = ["step_linear"]


@parallel_kernel
def step_linear(positions: np.ndarray, velocities: np.ndarray, previous: np.ndarray, ages: np.ndarray,
                constant: np.ndarray, damping: float, planes: np.ndarray, dt: float) -> int:  # fmt: skip
    """Advance every particle by dt under $a = constant − damping·v$ and resolve the planes (module docstring)."""
    bad = 0
    for i in prange(positions.shape[0]):
        for c in range(3):
            previous[i, c] = positions[i, c]
            velocities[i, c] += (constant[c] - damping * velocities[i, c]) * dt
            positions[i, c] += velocities[i, c] * dt
        ages[i] += dt
        for p in range(planes.shape[0]):
            d = ((positions[i, 0] - planes[p, 0]) * planes[p, 3] + (positions[i, 1] - planes[p, 1]) * planes[p, 4]
                 + (positions[i, 2] - planes[p, 2]) * planes[p, 5])  # fmt: skip
            if d < 0.0:
                e, mu = planes[p, 6], planes[p, 7]
                speed = (velocities[i, 0] * planes[p, 3] + velocities[i, 1] * planes[p, 4]
                         + velocities[i, 2] * planes[p, 5])  # fmt: skip
                for c in range(3):
                    positions[i, c] -= (1.0 + e) * d * planes[p, 3 + c]
                if speed < 0.0:
                    for c in range(3):
                        normal = speed * planes[p, 3 + c]
                        velocities[i, c] = (1.0 - mu) * (velocities[i, c] - normal) - e * normal
        finite = True
        for c in range(3):
            if not (math.isfinite(positions[i, c]) and math.isfinite(velocities[i, c])):
                finite = False
        if not finite:
            bad += 1
    return bad
