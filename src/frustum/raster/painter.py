"""Painter's kernel: convex fragments of window triangles painted back to front, later ones over earlier ones.

Fragment f is the part of window triangle ``source[f]`` inside the convex polygon ``corners[f, :counts[f]]``
(window x, y in pixels; the pieces of one triangle that a depth sort or a BSP tree cut it into). A pixel is
painted by the fragment when its centre is inside the triangle by the depth buffer's top-left rule (exact, in
integers) and inside the fragment's polygon within ``1e-7`` pixel (the pieces of a triangle tile it, so every
pixel of the triangle is painted by one of its pieces). No depth test: the order decides. Depth, code and
barycentrics are the triangle's own (``window.write_pixel``).
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL
from frustum.raster.window import covers, write_pixel

__all__ = ["paint_fragments"]

_TOLERANCE = 1e-7


@kernel
def paint_fragments(
    order: np.ndarray, corners: np.ndarray, counts: np.ndarray, source: np.ndarray, xy: np.ndarray,
    zq: np.ndarray, weights: np.ndarray, code: np.ndarray, box: np.ndarray,
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray, stats: np.ndarray,
) -> None:  # fmt: skip
    """Paint fragments ``order[0], order[1], …`` (farthest first). stats (2,) int64 += fragments painted, pixels
    written (overdraw included)."""
    height, width = depth.shape[0], depth.shape[1]
    for n in range(order.shape[0]):
        f = order[n]
        t = source[f]
        k = counts[f]
        x_min, x_max, y_min, y_max = np.inf, -np.inf, np.inf, -np.inf
        area = 0.0
        for c in range(k):
            x, y = corners[f, c, 0], corners[f, c, 1]
            x_min, x_max, y_min, y_max = min(x_min, x), max(x_max, x), min(y_min, y), max(y_max, y)
            d = (c + 1) % k
            area += x * corners[f, d, 1] - corners[f, d, 0] * y
        sign = 1.0 if area >= 0.0 else -1.0
        i_min = max(box[t, 0], int(np.floor(x_min - 0.5)))
        i_max = min(box[t, 1], int(np.ceil(x_max - 0.5)), width - 1)
        j_min = max(box[t, 2], int(np.floor(y_min - 0.5)))
        j_max = min(box[t, 3], int(np.ceil(y_max - 0.5)), height - 1)
        stats[0] += 1
        for j in range(j_min, j_max + 1):
            py = j + 0.5
            for i in range(i_min, i_max + 1):
                if not covers(xy, t, SUBPIXEL * i + HALF_SUBPIXEL, SUBPIXEL * j + HALF_SUBPIXEL):
                    continue
                px = i + 0.5
                inside = True
                for c in range(k):
                    d = (c + 1) % k
                    ax, ay = corners[f, c, 0], corners[f, c, 1]
                    ex, ey = corners[f, d, 0] - ax, corners[f, d, 1] - ay
                    cross = sign * (ex * (py - ay) - ey * (px - ax))
                    if cross < -_TOLERANCE * (abs(ex) + abs(ey)):
                        inside = False
                        break
                if inside:
                    stats[1] += 1
                    write_pixel(xy, zq, weights, code, t, i, j, depth, codes, bary)
