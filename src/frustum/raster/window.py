"""Window triangles: one flat list of the scene's drawn triangles for the visible-surface methods other than the
depth buffer, and the per-pixel values every method writes (the depth buffer's own formulas, bit for bit).

A window triangle t is what ``triangles._fill_tile`` draws: a trivially accepted face (from its vertices' records)
or a clipped triangle record, with counter-clockwise snapped corners. Arrays (T triangles):

* ``xy`` (T, 6) int64: ``X0, Y0, X1, Y1, X2, Y2`` snapped to 1/256 pixel (``fixed_point.snap``), counter-clockwise;
* ``zq`` (T, 3, 2) float64: window depth ``z_w`` and ``1/w_clip`` per corner;
* ``weights`` (T, 3, 2) float64: barycentric weights (u1, u2) of each corner with respect to the source face
  (one-hot for an accepted face: weighting by them is bit-identical to taking the pixel's own barycentrics);
* ``code`` (T,) int64: $2·face + back$ (face numbered across the scene's items, as the shading kernel reads it);
* ``box`` (T, 4) int64: pixel bounding box ``i_min, i_max, j_min, j_max`` (inclusive, inside the image).

Edge functions at a point ``(X, Y)`` (1/256 pixel): $E_k = dx_k·(Y − Y_a) − dy_k·(X − X_a)$ for the edge
opposite corner k, top-left rule by ``bias_k`` ($E_k >= bias_k$); depth on the plane through the corners,
$z = (z_0 + β·(Y − Y_0)) + α·(X − X_0)$ (``plane_depth``), and the perspective-correct barycentrics, as in
``triangles._fill_tile`` (its module docstring).
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL
from frustum.raster.triangles import FACE_DRAWN, depth_plane, face_box

__all__ = [
    "count_covered",
    "covers",
    "edge_setup",
    "edges_at",
    "gather_faces",
    "pixel_values",
    "plane_depth",
    "write_pixel",
]


@parallel_kernel(lambda faces, *_: faces.shape[0])
def gather_faces(
    faces: np.ndarray, codes: np.ndarray, win_int: np.ndarray, win_float: np.ndarray, options: np.ndarray,
    slots: np.ndarray, xy: np.ndarray, zq: np.ndarray, weights: np.ndarray, code: np.ndarray, box: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Window triangles of the trivially accepted, drawn faces (``triangles.face_box``).

    options = (width, height, cull, face_offset, write) int64. With write = 0, ``slots[f]`` receives 1 for a drawn
    face, else 0; with write = 1 a drawn face f fills row ``slots[f]`` of the outputs (slots: exclusive prefix sum).
    """
    width, height, cull, face_offset, write = options[0], options[1], options[2], options[3], options[4]
    for f in range(start, stop):
        state, back, i_min, i_max, j_min, j_max = face_box(faces, codes, win_int, f, width, height, cull)
        if write == 0:
            slots[f] = 1 if state == FACE_DRAWN else 0
            continue
        if state != FACE_DRAWN:
            continue
        t = slots[f]
        v0, v1, v2 = faces[f, 0], faces[f, 1], faces[f, 2]
        w1, w2 = 1.0, 0.0
        if back == 1:
            v1, v2 = v2, v1
            w1, w2 = 0.0, 1.0
        for k in range(3):
            v = v0 if k == 0 else (v1 if k == 1 else v2)
            xy[t, 2 * k], xy[t, 2 * k + 1] = win_int[v, 0], win_int[v, 1]
            zq[t, k, 0], zq[t, k, 1] = win_float[v, 0], win_float[v, 1]
            if zq.shape[2] >= 4:
                zq[t, k, 2], zq[t, k, 3] = win_float[v, 2], win_float[v, 3]
        weights[t, 0, 0], weights[t, 0, 1] = 0.0, 0.0
        weights[t, 1, 0], weights[t, 1, 1] = w1, w2
        weights[t, 2, 0], weights[t, 2, 1] = w2, w1
        code[t] = 2 * (face_offset + f) + back
        box[t, 0], box[t, 1], box[t, 2], box[t, 3] = i_min, i_max, j_min, j_max


@kernel
def edge_setup(xy: np.ndarray, t: int) -> tuple[int, int, int, int, int, int, int, int, int, float]:
    """$(dx0, dy0, dx1, dy1, dx2, dy2, bias0, bias1, bias2, 2·area)$ of triangle t (edge k opposite corner k)."""
    x0, y0, x1, y1, x2, y2 = xy[t, 0], xy[t, 1], xy[t, 2], xy[t, 3], xy[t, 4], xy[t, 5]
    # the same edge deltas and top-left biases stand inline in raster/triangles.py:covers_centre and the depth fill
    # of raster/shadow.py (kernel specialisations: they take corners, not a row of xy)
    dx0, dy0 = x2 - x1, y2 - y1
    dx1, dy1 = x0 - x2, y0 - y2
    dx2, dy2 = x1 - x0, y1 - y0
    bias0 = 0 if (dy0 < 0 or (dy0 == 0 and dx0 < 0)) else 1
    bias1 = 0 if (dy1 < 0 or (dy1 == 0 and dx1 < 0)) else 1
    bias2 = 0 if (dy2 < 0 or (dy2 == 0 and dx2 < 0)) else 1
    area = float(dx2 * (y2 - y0) - dy2 * (x2 - x0))
    return dx0, dy0, dx1, dy1, dx2, dy2, bias0, bias1, bias2, area


@kernel
def edges_at(xy: np.ndarray, t: int, px: int, py: int) -> tuple[int, int, int]:
    """The three edge functions of triangle t at the fixed-point point (px, py)."""
    x0, y0, x1, y1, x2, y2 = xy[t, 0], xy[t, 1], xy[t, 2], xy[t, 3], xy[t, 4], xy[t, 5]
    e0 = (x2 - x1) * (py - y1) - (y2 - y1) * (px - x1)
    e1 = (x0 - x2) * (py - y2) - (y0 - y2) * (px - x2)
    e2 = (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0)
    return e0, e1, e2


@kernel
def covers(xy: np.ndarray, t: int, px: int, py: int) -> bool:
    """Whether the fixed-point point (px, py) is inside triangle t by the top-left rule."""
    _dx0, _dy0, _dx1, _dy1, _dx2, _dy2, bias0, bias1, bias2, _area = edge_setup(xy, t)
    e0, e1, e2 = edges_at(xy, t, px, py)
    return e0 >= bias0 and e1 >= bias1 and e2 >= bias2


@kernel
def plane_depth(xy: np.ndarray, zq: np.ndarray, t: int, px: int, py: int) -> float:
    """Window depth (float64) of triangle t's plane at the fixed-point point (px, py):
    $(z_0' + β·(py − Y_0)) + α·(px − X_0)$ with ``(z_0', α, β) = triangles.depth_plane`` (the depth buffer's bits)."""
    x0, y0 = xy[t, 0], xy[t, 1]
    r0 = s0 = r1 = s1 = r2 = s2 = 0.0
    if zq.shape[2] >= 4:
        r0, s0, r1, s1, r2, s2 = zq[t, 0, 2], zq[t, 0, 3], zq[t, 1, 2], zq[t, 1, 3], zq[t, 2, 2], zq[t, 2, 3]
    z0, alpha, beta = depth_plane(x0, y0, xy[t, 2], xy[t, 3], xy[t, 4], xy[t, 5], r0, s0, r1, s1, r2, s2,
                                  zq[t, 0, 0], zq[t, 1, 0], zq[t, 2, 0])  # fmt: skip
    return (z0 + beta * float(py - y0)) + alpha * float(px - x0)


@kernel
def pixel_values(
    xy: np.ndarray, zq: np.ndarray, weights: np.ndarray, t: int, e0: int, e1: int, e2: int, px: int, py: int
) -> tuple[np.float32, np.float32, np.float32]:  # fmt: skip
    """``(z, u1, u2)`` float32 of triangle t at the fixed-point point (px, py), where its edge functions are e0, e1,
    e2: the depth buffer's formulas."""
    z = np.float32(plane_depth(xy, zq, t, px, py))
    g0, g1, g2 = float(e0) * zq[t, 0, 1], float(e1) * zq[t, 1, 1], float(e2) * zq[t, 2, 1]
    reciprocal = 1.0 / ((g0 + g1) + g2)
    b0, b1, b2 = g0 * reciprocal, g1 * reciprocal, g2 * reciprocal
    u1 = np.float32((b0 * weights[t, 0, 0] + b1 * weights[t, 1, 0]) + b2 * weights[t, 2, 0])
    u2 = np.float32((b0 * weights[t, 0, 1] + b1 * weights[t, 1, 1]) + b2 * weights[t, 2, 1])
    return z, u1, u2


@kernel
def write_pixel(
    xy: np.ndarray, zq: np.ndarray, weights: np.ndarray, code: np.ndarray, t: int, i: int, j: int,
    depth: np.ndarray, codes: np.ndarray, bary: np.ndarray,
) -> None:  # fmt: skip
    """Write triangle t's depth, code and barycentrics at pixel column i, window row j (no depth test; a depth
    of 1 or more, which the depth buffer's test "less" against its clear value never draws, is not written)."""
    px, py = SUBPIXEL * i + HALF_SUBPIXEL, SUBPIXEL * j + HALF_SUBPIXEL
    e0, e1, e2 = edges_at(xy, t, px, py)
    z, u1, u2 = pixel_values(xy, zq, weights, t, e0, e1, e2, px, py)
    if not z < 1.0:
        return
    row = depth.shape[0] - 1 - j
    depth[row, i] = z
    codes[row, i] = code[t]
    bary[row, i, 0], bary[row, i, 1] = u1, u2


@parallel_kernel(lambda xy, *_: xy.shape[0])
def count_covered(xy: np.ndarray, box: np.ndarray, covered: np.ndarray, start: int, stop: int) -> None:
    """covered (T,) int64: the pixel centres each triangle covers (the depth buffer's depth tests)."""
    for t in range(start, stop):
        _dx0, dy0, _dx1, dy1, _dx2, dy2, bias0, bias1, bias2, _area = edge_setup(xy, t)
        n = 0
        for j in range(box[t, 2], box[t, 3] + 1):
            py = SUBPIXEL * j + HALF_SUBPIXEL
            px = SUBPIXEL * box[t, 0] + HALF_SUBPIXEL
            e0, e1, e2 = edges_at(xy, t, px, py)
            for _ in range(box[t, 0], box[t, 1] + 1):
                if e0 >= bias0 and e1 >= bias1 and e2 >= bias2:
                    n += 1
                e0 -= dy0 * SUBPIXEL
                e1 -= dy1 * SUBPIXEL
                e2 -= dy2 * SUBPIXEL
        covered[t] = n
