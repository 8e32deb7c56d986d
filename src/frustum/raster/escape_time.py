"""Escape-time kernels of ``geometry/escape_time.py``: Mandelbrot and Julia images, the quaternion Julia field.

Kernels only (numpy + numba): imported on first use by the module named above, so ``import frustum`` never
loads Numba.
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel


@kernel
def _escape(zx, zy, cx, cy, max_iter, radius2, log_radius, smooth):  # pragma: no cover - compiled
    """Iterate z ← z² + c from z; return the (smooth) escape time or inf."""
    for n in range(max_iter + 1):  # the test after the last step too (the step after it is never used)
        x2 = zx * zx
        y2 = zy * zy
        if x2 + y2 > radius2:
            if smooth:
                return n + 1.0 - math.log2(0.5 * math.log(x2 + y2) / log_radius)
            return float(n)
        zy = 2.0 * zx * zy + cy
        zx = x2 - y2 + cx
    return np.inf


@kernel
def _in_cardioid_or_bulb(x, y):  # pragma: no cover - compiled
    """c in the main cardioid, q(q + x − ¼) <= y²/4 with q = (x − ¼)² + y², or the period-2 disc |c + 1| <= ¼.

    Their orbits converge (to an attracting fixed point or 2-cycle), so they never escape: skipping them saves
    max_iter iterations per interior pixel and changes no value.
    """
    xq = x - 0.25
    q = xq * xq + y * y
    if q * (q + xq) <= 0.25 * y * y:
        return True
    return (x + 1.0) * (x + 1.0) + y * y <= 0.0625


@parallel_kernel(lambda xs, ys, *_: ys.shape[0])
def _escape_image(xs, ys, julia_mode, cx, cy, max_iter, radius2, smooth, out, start, stop):  # pragma: no cover
    """out[i, j] for the pixel at (xs[j], ys[i]); Mandelbrot (z₀ = 0, c = pixel) or Julia (z₀ = pixel)."""
    log_radius = 0.5 * math.log(radius2)
    for i in range(start, stop):
        for j in range(xs.shape[0]):
            if julia_mode:
                out[i, j] = _escape(xs[j], ys[i], cx, cy, max_iter, radius2, log_radius, smooth)
            elif _in_cardioid_or_bulb(xs[j], ys[i]):
                out[i, j] = np.inf
            else:
                out[i, j] = _escape(0.0, 0.0, xs[j], ys[i], max_iter, radius2, log_radius, smooth)


@parallel_kernel(lambda xs, *_: xs.shape[0])
def _quaternion_field(xs, ys, zs, w, c, max_iter, radius2, out, start, stop):  # pragma: no cover - compiled
    """Smooth escape time of q ← q² + c from q₀ = (x, y, z, w) (components 1, i, j, k); max_iter inside."""
    log_radius = 0.5 * math.log(radius2)
    for a in range(start, stop):
        for b in range(ys.shape[0]):
            for d in range(zs.shape[0]):
                q0, q1, q2, q3 = xs[a], ys[b], zs[d], w
                value = float(max_iter)
                for n in range(max_iter):
                    norm2 = q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3
                    if norm2 > radius2:
                        value = min(n + 1.0 - math.log2(0.5 * math.log(norm2) / log_radius), float(max_iter))
                        break
                    # (s, v)² = (s² − v·v, 2 s v)
                    s = q0
                    q0 = s * s - q1 * q1 - q2 * q2 - q3 * q3 + c[0]
                    q1 = 2.0 * s * q1 + c[1]
                    q2 = 2.0 * s * q2 + c[2]
                    q3 = 2.0 * s * q3 + c[3]
                out[a, b, d] = value
