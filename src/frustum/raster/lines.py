"""Line and point kernels: wireframe edges and vertex dots into the shared color and depth buffers.

Window coordinates are those of ``raster/triangles.py``: $x_w = (x_c / w)·(W/2) + W/2$ (y alike, y up),
snapped to 1/256 pixel as $X = floor(x_w·256 + 0.5)$ (int64), and $z_w = (z_c / w)·0.5 + 0.5$. Pixel
(i, j) has its centre at $(256·i + 128, 256·j + 128)$; buffers are top row first (window row j is array
row $H − 1 − j$). Depth test "less" against float32 ``depth``: a pixel is written (depth ``float32(z)``,
color the item's RGBA bytes) when $float32(z) < depth$.

Line coverage (DDA over pixel centres along the major axis). For snapped ends a, b with $dX = X_b − X_a$,
$dY = Y_b − Y_a$: a zero-length line ($dX = dY = 0$) covers nothing. If $|dX| >= |dY|$ (x-major),
rename the ends so that $X_a < X_b$; the line covers, for every column i whose centre $c = 256·i + 128$
lies in the closed interval ``[X_a, X_b]``, the one pixel (i, j) of the row containing the line's exact
(rational) height there, $j = floor((Y_a·dX + dY·(c − X_a)) / (256·dX))$, with $j = H$ (the line on the
image's top edge) taken as $H − 1$. Its depth is $z = z_a + (z_b − z_a)·t$, $t = (c − X_a) / dX$
(float64; z_w is linear in screen space along the line). A y-major line is the same with x and y swapped
(rows whose centres lie in ``[Y_a, Y_b]``, $i = floor(...)$ with $i = W$ taken as $W − 1$). So every
column (row) the line spans gets exactly one pixel, both ends included, independent of the drawing direction.

Point coverage: a point at snapped ``(X, Y)`` covers the pixel containing it, ``(X // 256, Y // 256)``, with
``W`` and ``H`` (the image's right and top edges) taken as $W − 1$ and $H − 1$.

Style (``style`` (STYLE,) float64, built by ``line_style``): the RGBA bytes; a line width in pixels (w > 1 adds
pixels across the line: offsets $k − (⌊w⌋ − 1)//2$, k < ⌊w⌋, on the minor axis; points become w×w squares);
``write_depth``; a ``test`` mode: 0 = plain "less", 1 = hidden-line: a pixel is visible when
$z − offset < max(depth at the pixel and its 4 neighbours)$ (the surfaces' depth buffer; the neighbours
absorb the half-pixel between the line and the pixel centre on grazing faces), and the hidden pixels are drawn
in the hidden RGBA when ``hidden`` is 1 (solid) or 2 (dashes of ``dash`` pixels along the major axis);
depth cueing $f·c + (1 − f)·cue$ of the bytes with ``f`` of ``frustum.shading.DepthCue``, the view distance
interpolated perspective-correctly from the ends' ``view_depth`` (``d/w`` and ``1/w`` linear on screen).

Determinism: both kernels are serial (no ``prange``), lines in the order of ``edges`` and points in vertex
order, so depth ties resolve to the first drawn, run after run.

Contracts (kernels never validate): clip (N, 4) float64 homogeneous clip coordinates, view_depth (N,) float64
view distances (used for cueing only), edges (E, 2) int64 indices into clip, planes (P, 4) float64
inside-positive (``raster/clip.py``), view = (W/2, H/2) float64, style from ``line_style``, depth (H, W) float32
and color (H, W, 4) uint8 written in place (with ``test`` = 1 depth is read, and written only if asked).
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel
from frustum.raster.clip import clip_segment
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL, snap

__all__ = ["STYLE", "draw_lines", "draw_points", "line_style"]

S_RGBA, S_HIDDEN_RGBA, S_WIDTH, S_WRITE_DEPTH, S_TEST, S_OFFSET, S_HIDDEN, S_DASH = 0, 4, 8, 9, 10, 11, 12, 13
S_CUE_ON, S_CUE_NEAR, S_CUE_FAR, S_CUE_MIN, S_CUE_MAX, S_CUE_COLOR = 14, 15, 16, 17, 18, 19
STYLE = 22


def line_style(
    rgba, *, width: float = 1.0, write_depth: bool = True, hidden_line: bool = False, offset: float = 0.0,
    hidden: int = 0, hidden_rgba=(0, 0, 0, 0), dash: float = 6.0, cue=None,
) -> np.ndarray:  # fmt: skip
    """The (STYLE,) float64 style vector of the module docstring; $cue = (near, far, f_min, f_max, r, g, b)$
    in bytes for the color, or None."""
    style = np.zeros(STYLE)
    style[S_RGBA : S_RGBA + 4] = rgba
    style[S_HIDDEN_RGBA : S_HIDDEN_RGBA + 4] = hidden_rgba
    style[S_WIDTH], style[S_WRITE_DEPTH], style[S_TEST] = width, float(write_depth), float(hidden_line)
    style[S_OFFSET], style[S_HIDDEN], style[S_DASH] = offset, hidden, dash
    if cue is not None:
        style[S_CUE_ON] = 1.0
        style[S_CUE_NEAR : S_CUE_COLOR + 3] = cue
    return style



@kernel
def _cued(style: np.ndarray, base: int, k: int, d: float) -> np.uint8:
    """Byte k of the RGBA at ``style[base:]``, depth-cued at view distance d (alpha is never cued)."""
    value = style[base + k]
    if style[S_CUE_ON] != 0.0 and k < 3:
        low, high = style[S_CUE_MIN], style[S_CUE_MAX]
        f = low + (high - low) * (style[S_CUE_FAR] - d) / (style[S_CUE_FAR] - style[S_CUE_NEAR])
        f = min(max(f, low), high)
        value = f * value + (1.0 - f) * style[S_CUE_COLOR + k]
    return np.uint8(min(max(np.floor(value + 0.5), 0.0), 255.0))


@kernel
def _surface_depth(row: int, col: int, depth: np.ndarray) -> float:
    """max of the depth at (row, col) and its 4 neighbours inside the image (the hidden-line test's surface)."""
    height, width = depth.shape[0], depth.shape[1]
    value = depth[row, col]
    if row > 0:
        value = max(value, depth[row - 1, col])
    if row < height - 1:
        value = max(value, depth[row + 1, col])
    if col > 0:
        value = max(value, depth[row, col - 1])
    if col < width - 1:
        value = max(value, depth[row, col + 1])
    return value


@kernel
def _plot(row: int, col: int, z: float, d: float, step: int, style: np.ndarray, depth: np.ndarray,
          color: np.ndarray) -> None:  # fmt: skip
    """One pixel: the depth test of the style ("less", or the hidden-line test), then the (cued) bytes."""
    if row < 0 or col < 0 or row >= depth.shape[0] or col >= depth.shape[1]:
        return
    z32 = np.float32(z)
    base = S_RGBA
    plain = style[S_TEST] == 0.0
    visible = z32 < depth[row, col] if plain else z - style[S_OFFSET] < _surface_depth(row, col, depth)
    if not visible:
        hidden = style[S_HIDDEN]
        if hidden == 0.0 or (hidden == 2.0 and (step // max(int(style[S_DASH]), 1)) % 2 == 1):
            return
        base = S_HIDDEN_RGBA
    elif style[S_WRITE_DEPTH] != 0.0:
        depth[row, col] = z32
    for k in range(4):
        color[row, col, k] = _cued(style, base, k, d)


@kernel
def _draw_segment(
    xa: int, ya: int, za: float, da: float, wa: float, xb: int, yb: int, zb: float, db: float, wb: float,
    x_major: bool, style: np.ndarray, depth: np.ndarray, color: np.ndarray,
) -> None:  # fmt: skip
    """DDA of one snapped segment along its major axis (the module docstring's rule); a = the lower major end.

    For a y-major segment the caller passes y as "x" and x as "y" (``x_major`` False swaps them back at the
    write). $xa < xb$ is required. d and w at the ends give the cueing distance.
    """
    height, width = depth.shape[0], depth.shape[1]
    major_size, minor_size = (width, height) if x_major else (height, width)
    dx = xb - xa
    dy = yb - ya
    first = max(-((HALF_SUBPIXEL - xa) // SUBPIXEL), 0)  # smallest index whose centre is >= xa
    last = min((xb - HALF_SUBPIXEL) // SUBPIXEL, major_size - 1)
    thickness = max(int(style[S_WIDTH]), 1)
    for i in range(first, last + 1):
        c = SUBPIXEL * i + HALF_SUBPIXEL
        j = (ya * dx + dy * (c - xa)) // (SUBPIXEL * dx)
        if j == minor_size:
            j = minor_size - 1
        if thickness == 1 and (j < 0 or j >= minor_size):
            continue
        t = float(c - xa) / float(dx)
        z = za + (zb - za) * t
        d = 0.0
        if style[S_CUE_ON] != 0.0:
            d = ((1.0 - t) * da / wa + t * db / wb) / ((1.0 - t) / wa + t / wb)
        for k in range(thickness):
            jk = j + k - (thickness - 1) // 2
            if x_major:
                _plot(height - 1 - jk, i, z, d, i - first, style, depth, color)
            else:
                _plot(height - 1 - i, jk, z, d, i - first, style, depth, color)


@kernel
def draw_lines(
    clip: np.ndarray, view_depth: np.ndarray, edges: np.ndarray, planes: np.ndarray, view: np.ndarray,
    style: np.ndarray, depth: np.ndarray, color: np.ndarray,
) -> None:  # fmt: skip
    """Clip (Liang–Barsky in clip space), divide, map, snap and draw every edge, serially in `edges` order.

    Clipped ends are $P1 + (P2 − P1)·u$ (an end with u = 0 or 1 is used bit for bit), as ``clip_segments``
    computes them; clipping against $w + z >= 0$ keeps every drawn point in front of the eye (w > 0), so a
    segment reaching behind the eye is cut, never wrapped through infinity.
    """
    for e in range(edges.shape[0]):
        start = clip[edges[e, 0]]
        end = clip[edges[e, 1]]
        u0, u1 = clip_segment(start, end, planes)
        if u0 > u1:
            continue
        xa, ya, xb, yb = np.int64(0), np.int64(0), np.int64(0), np.int64(0)
        za, zb = 0.0, 0.0
        da, wa, db, wb = 0.0, 1.0, 0.0, 1.0
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
            d = view_depth[edges[e, 0]] + (view_depth[edges[e, 1]] - view_depth[edges[e, 0]]) * u
            if side == 0:
                xa, ya, za, da, wa = x, y, z, d, pw
            else:
                xb, yb, zb, db, wb = x, y, z, d, pw
        if xa == xb and ya == yb:
            continue
        x_major = abs(xb - xa) >= abs(yb - ya)
        if not x_major:  # draw along y: y as "x" (``_draw_segment`` swaps them back)
            xa, ya, xb, yb = ya, xa, yb, xb
        if xa > xb:  # from the lower major end
            xa, ya, za, da, wa, xb, yb, zb, db, wb = xb, yb, zb, db, wb, xa, ya, za, da, wa
        _draw_segment(xa, ya, za, da, wa, xb, yb, zb, db, wb, x_major, style, depth, color)


@kernel
def draw_points(
    clip: np.ndarray, view_depth: np.ndarray, codes: np.ndarray, view: np.ndarray, style: np.ndarray,
    depth: np.ndarray, color: np.ndarray,
) -> None:  # fmt: skip
    """Draw every vertex inside the view volume (``codes[i] == 0``) as the pixel containing it (a w×w square
    for width w > 1), in order."""
    height, width = depth.shape[0], depth.shape[1]
    size = max(int(style[S_WIDTH]), 1)
    for v in range(clip.shape[0]):
        if codes[v] != 0:
            continue
        w = clip[v, 3]
        i = min(snap((clip[v, 0] / w) * view[0] + view[0]) // SUBPIXEL, width - 1)
        j = min(snap((clip[v, 1] / w) * view[1] + view[1]) // SUBPIXEL, height - 1)
        if i < 0 or j < 0:
            continue
        z = (clip[v, 2] / w) * 0.5 + 0.5
        for a in range(size):
            for b in range(size):
                _plot(height - 1 - (j + a - (size - 1) // 2), i + b - (size - 1) // 2, z, view_depth[v], 0,
                      style, depth, color)  # fmt: skip
