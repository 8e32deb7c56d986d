"""A-buffer kernels (Carpenter): per pixel a list of fragments with 4×4 coverage masks, resolved front to back.

A fragment is one triangle's part of one pixel: the triangle t, a 16-bit coverage mask of the 4×4 subsamples
at $(256·i + 32 + 64·a, 256·j + 32 + 64·b)$ (fixed point, a, b = 0..3; bit $4·b + a$; top-left rule at each
subsample), and the shading inputs at the centroid of its covered subsamples (depth, face code, barycentrics:
shaded once per fragment by the shading kernel). ``count_fragments`` counts them per triangle and
``write_fragments`` writes them triangle by triangle (both in parallel over triangles), ``group_by_pixel`` orders
them pixel by pixel (a counting sort keeping the triangle order within a pixel), and
``resolve`` composites each subsample: the fragments covering it sorted by their plane's depth at the subsample,
$C = Σ_k T_k·α_k·c_k + T·under$ with $T_k = Π_{m<k} (1 − α_m)$ (premultiplied colors), the pixel the mean of
its 16 subsamples. Intersecting and cyclically overlapping surfaces come out right per subsample.
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel, parallel_kernel
from frustum.raster.fixed_point import HALF_SUBPIXEL, SUBPIXEL
from frustum.raster.window import edge_setup, plane_depth

__all__ = ["SAMPLES", "count_fragments", "group_by_pixel", "resolve", "write_fragments"]

SAMPLES = 16
_STEP = SUBPIXEL // 4
_FIRST = _STEP // 2


@kernel
def _sample_box(xy: np.ndarray, t: int, width: int, height: int) -> tuple[int, int, int, int]:
    """Pixels of triangle t's box whose subsample grid can meet it (clamped to the image)."""
    x_min = min(xy[t, 0], min(xy[t, 2], xy[t, 4]))
    x_max = max(xy[t, 0], max(xy[t, 2], xy[t, 4]))
    y_min = min(xy[t, 1], min(xy[t, 3], xy[t, 5]))
    y_max = max(xy[t, 1], max(xy[t, 3], xy[t, 5]))
    last = SUBPIXEL - _FIRST
    i_min = max(-((last - x_min) // SUBPIXEL), 0)
    i_max = min((x_max - _FIRST) // SUBPIXEL, width - 1)
    j_min = max(-((last - y_min) // SUBPIXEL), 0)
    j_max = min((y_max - _FIRST) // SUBPIXEL, height - 1)
    return i_min, i_max, j_min, j_max


@kernel
def _mask(xy: np.ndarray, t: int, i: int, j: int) -> tuple[int, int, int]:
    """Coverage mask of triangle t in pixel (i, j), and the sums of the covered subsamples' X and Y."""
    dx0, dy0, dx1, dy1, dx2, dy2, bias0, bias1, bias2, _area = edge_setup(xy, t)
    mask, sum_x, sum_y = 0, 0, 0
    for b in range(4):
        py = SUBPIXEL * j + _FIRST + _STEP * b
        for a in range(4):
            px = SUBPIXEL * i + _FIRST + _STEP * a
            e0 = dx0 * (py - xy[t, 3]) - dy0 * (px - xy[t, 2])
            e1 = dx1 * (py - xy[t, 5]) - dy1 * (px - xy[t, 4])
            e2 = dx2 * (py - xy[t, 1]) - dy2 * (px - xy[t, 0])
            if e0 >= bias0 and e1 >= bias1 and e2 >= bias2:
                mask |= 1 << (4 * b + a)
                sum_x += px
                sum_y += py
    return mask, sum_x, sum_y


@parallel_kernel(lambda xy, *_: xy.shape[0])
def count_fragments(xy: np.ndarray, size: np.ndarray, counts: np.ndarray, start: int, stop: int) -> None:
    """counts (T,) int64: the fragments (pixels with a nonzero coverage mask) of each triangle; size = (W, H)."""
    width, height = size[0], size[1]
    for t in range(start, stop):
        i_min, i_max, j_min, j_max = _sample_box(xy, t, width, height)
        n = 0
        for j in range(j_min, j_max + 1):
            for i in range(i_min, i_max + 1):
                mask, _sum_x, _sum_y = _mask(xy, t, i, j)
                if mask != 0:
                    n += 1
        counts[t] = n


@parallel_kernel(lambda xy, *_: xy.shape[0])
def write_fragments(
    xy: np.ndarray, zq: np.ndarray, weights: np.ndarray, code: np.ndarray, size: np.ndarray, first: np.ndarray,
    pixel: np.ndarray, triangle: np.ndarray, masks: np.ndarray, frag_depth: np.ndarray, frag_code: np.ndarray,
    frag_bary: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Write triangle t's fragments from slot ``first[t]`` on (triangle-major, row by row): pixel (N,) int64
    (row-major, top row first), triangle (N,) int64, masks (N,) uint16, and the shading column frag_depth (N,)
    float32 (below 1), frag_code (N,) int32 or int64 and frag_bary (N, 2) float32 at the centroid of the covered
    subsamples. size = (W, H)."""
    width, height = size[0], size[1]
    for t in range(start, stop):
        i_min, i_max, j_min, j_max = _sample_box(xy, t, width, height)
        dx0, dy0, dx1, dy1, dx2, dy2, _bias0, _bias1, _bias2, area = edge_setup(xy, t)
        slot = first[t]
        for j in range(j_min, j_max + 1):
            for i in range(i_min, i_max + 1):
                mask, sum_x, sum_y = _mask(xy, t, i, j)
                if mask == 0:
                    continue
                covered = 0
                for bit in range(SAMPLES):
                    covered += (mask >> bit) & 1
                px, py = sum_x / covered, sum_y / covered
                f0 = dx0 * (py - xy[t, 3]) - dy0 * (px - xy[t, 2])
                f1 = dx1 * (py - xy[t, 5]) - dy1 * (px - xy[t, 4])
                f2 = dx2 * (py - xy[t, 1]) - dy2 * (px - xy[t, 0])
                z = ((f0 * zq[t, 0, 0] + f1 * zq[t, 1, 0]) + f2 * zq[t, 2, 0]) / area
                g0, g1, g2 = f0 * zq[t, 0, 1], f1 * zq[t, 1, 1], f2 * zq[t, 2, 1]
                total = (g0 + g1) + g2
                b0, b1, b2 = g0 / total, g1 / total, g2 / total
                pixel[slot] = (height - 1 - j) * width + i
                triangle[slot] = t
                masks[slot] = mask
                frag_depth[slot] = np.float32(min(max(z, 0.0), 0.99999994))
                frag_code[slot] = code[t]
                frag_bary[slot, 0] = np.float32((b0 * weights[t, 0, 0] + b1 * weights[t, 1, 0]) + b2 * weights[t, 2, 0])
                frag_bary[slot, 1] = np.float32((b0 * weights[t, 0, 1] + b1 * weights[t, 1, 1]) + b2 * weights[t, 2, 1])
                slot += 1


@kernel
def group_by_pixel(pixel: np.ndarray, cursor: np.ndarray, order: np.ndarray) -> None:
    """Counting sort: ``order`` (N,) the fragments pixel by pixel, triangle order kept within a pixel; cursor
    (H·W,) int64 holds each pixel's first slot (advanced)."""
    for f in range(pixel.shape[0]):
        p = pixel[f]
        order[cursor[p]] = f
        cursor[p] += 1


@parallel_kernel(lambda starts, *_: starts.shape[0] - 1)
def resolve(
    starts: np.ndarray, triangle: np.ndarray, masks: np.ndarray, premultiplied: np.ndarray, xy: np.ndarray,
    zq: np.ndarray, under: np.ndarray, under_depth: np.ndarray, color: np.ndarray, depth: np.ndarray,
    stats: np.ndarray,
    start: int, stop: int,
) -> None:  # fmt: skip
    """Composite pixels [start, stop) (row-major over the (H, W) image) front to back per subsample.

    starts (H·W + 1,) int64: pixel p's fragments are ``starts[p]:starts[p + 1]``; premultiplied (N, 4) uint8
    $α·c$ and $α$ of each fragment; under (H, W, 4) uint8: what lies behind every fragment (background, or
    the opaque surfaces), and under_depth (H, W) float32 its depth: subsamples of fragments at or behind it are
    dropped. color (H, W, 4) uint8 receives the rounded mean of the 16 subsamples; depth (H, W) float32 the
    nearest opaque fragment's depth at the pixel centre where one covers it (left alone elsewhere).
    stats (H·W, 2) int64: fragments of the pixel and fragment–subsample pairs composited.
    """
    width = color.shape[1]
    height = color.shape[0]
    order = np.empty(64, dtype=np.int64)
    keys = np.empty(64)
    planes = np.empty((64, 3))
    for p in range(start, stop):
        row, i = p // width, p % width
        j = height - 1 - row
        first, last = starts[p], starts[p + 1]
        stats[p, 0] = last - first
        if last == first:
            color[row, i, 0], color[row, i, 1] = under[row, i, 0], under[row, i, 1]
            color[row, i, 2], color[row, i, 3] = under[row, i, 2], under[row, i, 3]
            continue
        if last - first > order.shape[0]:
            order = np.empty(2 * (last - first), dtype=np.int64)
            keys = np.empty(2 * (last - first))
            planes = np.empty((2 * (last - first), 3))
        limit = under_depth[row, i]
        # each fragment's plane over the subsample grid: z(a, b) = z00 + a·step_x + b·step_y (depth is affine)
        for f in range(first, last):
            t = triangle[f]
            dx0, dy0, dx1, dy1, dx2, dy2, _bias0, _bias1, _bias2, area = edge_setup(xy, t)
            for corner in range(3):
                px = float(SUBPIXEL * i + _FIRST + (_STEP if corner == 1 else 0))
                py = float(SUBPIXEL * j + _FIRST + (_STEP if corner == 2 else 0))
                f0 = dx0 * (py - xy[t, 3]) - dy0 * (px - xy[t, 2])
                f1 = dx1 * (py - xy[t, 5]) - dy1 * (px - xy[t, 4])
                f2 = dx2 * (py - xy[t, 1]) - dy2 * (px - xy[t, 0])
                planes[f - first, corner] = ((f0 * zq[t, 0, 0] + f1 * zq[t, 1, 0]) + f2 * zq[t, 2, 0]) / area
            planes[f - first, 1] -= planes[f - first, 0]
            planes[f - first, 2] -= planes[f - first, 0]
        total_r, total_g, total_b, total_a = 0.0, 0.0, 0.0, 0.0
        pairs = 0
        for b in range(4):
            for a in range(4):
                bit = 1 << (4 * b + a)
                n = 0
                for f in range(first, last):
                    if masks[f] & bit == 0:
                        continue
                    k = f - first
                    z = planes[k, 0] + a * planes[k, 1] + b * planes[k, 2]
                    if not z < limit:
                        continue
                    m = n - 1  # insertion by depth; equal depths keep the drawing order
                    while m >= 0 and keys[m] > z:
                        keys[m + 1], order[m + 1] = keys[m], order[m]
                        m -= 1
                    keys[m + 1], order[m + 1] = z, f
                    n += 1
                clear = 1.0
                r, g, bb, alpha = 0.0, 0.0, 0.0, 0.0
                for m in range(n):
                    f = order[m]
                    pairs += 1
                    r += clear * premultiplied[f, 0]
                    g += clear * premultiplied[f, 1]
                    bb += clear * premultiplied[f, 2]
                    alpha += clear * premultiplied[f, 3]
                    clear *= 1.0 - premultiplied[f, 3] / 255.0
                    if clear <= 0.0:
                        break
                r += clear * under[row, i, 0]
                g += clear * under[row, i, 1]
                bb += clear * under[row, i, 2]
                alpha += clear * under[row, i, 3]
                total_r, total_g, total_b, total_a = total_r + r, total_g + g, total_b + bb, total_a + alpha
        color[row, i, 0] = np.uint8(min(np.floor(total_r / SAMPLES + 0.5), 255.0))
        color[row, i, 1] = np.uint8(min(np.floor(total_g / SAMPLES + 0.5), 255.0))
        color[row, i, 2] = np.uint8(min(np.floor(total_b / SAMPLES + 0.5), 255.0))
        color[row, i, 3] = np.uint8(min(np.floor(total_a / SAMPLES + 0.5), 255.0))
        stats[p, 1] = pairs
        # the depth at the pixel centre: the nearest opaque fragment whose triangle covers it
        cx, cy = SUBPIXEL * i + HALF_SUBPIXEL, SUBPIXEL * j + HALF_SUBPIXEL
        best = np.float32(depth[row, i])
        for f in range(first, last):
            if premultiplied[f, 3] != 255:
                continue
            t = triangle[f]
            dx0, dy0, dx1, dy1, dx2, dy2, bias0, bias1, bias2, _area = edge_setup(xy, t)
            e0 = dx0 * (cy - xy[t, 3]) - dy0 * (cx - xy[t, 2])
            e1 = dx1 * (cy - xy[t, 5]) - dy1 * (cx - xy[t, 4])
            e2 = dx2 * (cy - xy[t, 1]) - dy2 * (cx - xy[t, 0])
            if e0 >= bias0 and e1 >= bias1 and e2 >= bias2:
                z = np.float32(plane_depth(xy, zq, t, cx, cy))
                if z < best:
                    best = z
        depth[row, i] = best
