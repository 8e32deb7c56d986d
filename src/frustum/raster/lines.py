"""Line and point kernels: wireframe edges and vertex dots into the shared color and depth buffers.

Window coordinates are those of ``raster/triangles.py``: ``x_w = (x_c / w)·(W/2) + W/2`` (y alike, y up),
snapped to 1/256 pixel as ``X = floor(x_w·256 + 0.5)`` (int64), and ``z_w = (z_c / w)·0.5 + 0.5``. Pixel
(i, j) has its centre at ``(256·i + 128, 256·j + 128)``; buffers are top row first (window row j is array
row ``H − 1 − j``). Depth test "less" against float32 ``depth``: a pixel is written (depth ``float32(z)``,
color the item's RGBA bytes) when ``float32(z) < depth``.

Line coverage (DDA over pixel centres along the major axis). For snapped ends a, b with ``dX = X_b − X_a``,
``dY = Y_b − Y_a``: a zero-length line (``dX = dY = 0``) covers nothing. If ``|dX| >= |dY|`` (x-major),
rename the ends so that ``X_a < X_b``; the line covers, for every column i whose centre ``c = 256·i + 128``
lies in the closed interval ``[X_a, X_b]``, the one pixel (i, j) of the row containing the line's exact
(rational) height there, ``j = floor((Y_a·dX + dY·(c − X_a)) / (256·dX))``, with ``j = H`` (the line on the
image's top edge) taken as ``H − 1``. Its depth is ``z = z_a + (z_b − z_a)·t``, ``t = (c − X_a) / dX``
(float64; z_w is linear in screen space along the line). A y-major line is the same with x and y swapped
(rows whose centres lie in ``[Y_a, Y_b]``, ``i = floor(...)`` with ``i = W`` taken as ``W − 1``). So every
column (row) the line spans gets exactly one pixel, both ends included, independent of the drawing direction.

Point coverage: a point at snapped ``(X, Y)`` covers the pixel containing it, ``(X // 256, Y // 256)``, with
``W`` and ``H`` (the image's right and top edges) taken as ``W − 1`` and ``H − 1``.

Determinism: both kernels are serial (no ``prange``), lines in the order of ``edges`` and points in vertex
order, so depth ties resolve to the first drawn, run after run.

Contracts (kernels never validate): clip (N, 4) float64 homogeneous clip coordinates, edges (E, 2) int64
indices into clip, planes (P, 4) float64 inside-positive (``raster/clip.py``), view = (W/2, H/2) float64,
rgba (4,) uint8, depth (H, W) float32 and color (H, W, 4) uint8 written in place.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel
from frustum.raster.clip import clip_segment
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL, snap

__all__ = ["draw_lines", "draw_points"]



@kernel
def _plot(row: int, col: int, z: float, rgba: np.ndarray, depth: np.ndarray, color: np.ndarray) -> None:
    """Depth test "less" at one pixel; on success write float32 depth and the RGBA bytes."""
    z32 = np.float32(z)
    if z32 < depth[row, col]:
        depth[row, col] = z32
        for k in range(4):
            color[row, col, k] = rgba[k]


@kernel
def _draw_segment(
    xa: int, ya: int, za: float, xb: int, yb: int, zb: float, x_major: bool,
    rgba: np.ndarray, depth: np.ndarray, color: np.ndarray,
) -> None:  # fmt: skip
    """DDA of one snapped segment along its major axis (the module docstring's rule); a = the lower major end.

    For a y-major segment the caller passes y as "x" and x as "y" (``x_major`` False swaps them back at the
    write). ``xa < xb`` is required.
    """
    height, width = depth.shape[0], depth.shape[1]
    major_size, minor_size = (width, height) if x_major else (height, width)
    dx = xb - xa
    dy = yb - ya
    first = max(-((HALF_SUBPIXEL - xa) // SUBPIXEL), 0)  # smallest index whose centre is >= xa
    last = min((xb - HALF_SUBPIXEL) // SUBPIXEL, major_size - 1)
    for i in range(first, last + 1):
        c = SUBPIXEL * i + HALF_SUBPIXEL
        j = (ya * dx + dy * (c - xa)) // (SUBPIXEL * dx)
        if j == minor_size:
            j = minor_size - 1
        if j < 0 or j >= minor_size:
            continue
        t = float(c - xa) / float(dx)
        z = za + (zb - za) * t
        if x_major:
            _plot(height - 1 - j, i, z, rgba, depth, color)
        else:
            _plot(height - 1 - i, j, z, rgba, depth, color)


@kernel
def draw_lines(
    clip: np.ndarray, edges: np.ndarray, planes: np.ndarray, view: np.ndarray, rgba: np.ndarray,
    depth: np.ndarray, color: np.ndarray,
) -> None:  # fmt: skip
    """Clip (Liang–Barsky in clip space), divide, map, snap and draw every edge, serially in `edges` order.

    Clipped ends are ``P1 + (P2 − P1)·u`` (an end with u = 0 or 1 is used bit for bit), as ``clip_segments``
    computes them; clipping against ``w + z >= 0`` keeps every drawn point in front of the eye (w > 0), so a
    segment reaching behind the eye is cut, never wrapped through infinity.
    """
    for e in range(edges.shape[0]):
        start = clip[edges[e, 0]]
        end = clip[edges[e, 1]]
        u0, u1 = clip_segment(start, end, planes)
        if u0 > u1:
            continue
        xa, ya, za, xb, yb, zb = 0, 0, 0.0, 0, 0, 0.0
        for side in range(2):
            u = u0 if side == 0 else u1
            moved = u != (0.0 if side == 0 else 1.0)
            px = start[0] + (end[0] - start[0]) * u if moved else (start[0] if side == 0 else end[0])
            py = start[1] + (end[1] - start[1]) * u if moved else (start[1] if side == 0 else end[1])
            pz = start[2] + (end[2] - start[2]) * u if moved else (start[2] if side == 0 else end[2])
            pw = start[3] + (end[3] - start[3]) * u if moved else (start[3] if side == 0 else end[3])
            x = snap((px / pw) * view[0] + view[0])
            y = snap((py / pw) * view[1] + view[1])
            z = (pz / pw) * 0.5 + 0.5
            if side == 0:
                xa, ya, za = x, y, z
            else:
                xb, yb, zb = x, y, z
        if xa == xb and ya == yb:
            continue
        if abs(xb - xa) >= abs(yb - ya):
            if xa < xb:
                _draw_segment(xa, ya, za, xb, yb, zb, True, rgba, depth, color)
            else:
                _draw_segment(xb, yb, zb, xa, ya, za, True, rgba, depth, color)
        elif ya < yb:
            _draw_segment(ya, xa, za, yb, xb, zb, False, rgba, depth, color)
        else:
            _draw_segment(yb, xb, zb, ya, xa, za, False, rgba, depth, color)


@kernel
def draw_points(
    clip: np.ndarray, codes: np.ndarray, view: np.ndarray, rgba: np.ndarray, depth: np.ndarray, color: np.ndarray
) -> None:  # fmt: skip
    """Draw every vertex inside the view volume (``codes[i] == 0``) as the one pixel containing it, in order."""
    height, width = depth.shape[0], depth.shape[1]
    for v in range(clip.shape[0]):
        if codes[v] != 0:
            continue
        w = clip[v, 3]
        i = min(snap((clip[v, 0] / w) * view[0] + view[0]) // SUBPIXEL, width - 1)
        j = min(snap((clip[v, 1] / w) * view[1] + view[1]) // SUBPIXEL, height - 1)
        if i < 0 or j < 0:
            continue
        _plot(height - 1 - j, i, (clip[v, 2] / w) * 0.5 + 0.5, rgba, depth, color)
