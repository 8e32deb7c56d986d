"""Random fractals: fractional Brownian terrain (diamond-square, midpoint displacement), height fields as meshes and
fractal coastlines."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_points, as_scalar, describe
from frustum.errors import GeometryError
from frustum.geometry.fractals.checks import byte_budget, check_fractal_memory, check_hurst, check_level, check_seed
from frustum.geometry.mesh import Mesh

__all__ = ["fbm_terrain", "fractal_coastline", "heightfield_mesh"]


def _square_step_means(h: NDArray, step: int) -> tuple[NDArray, NDArray]:
    """Diamond-square's square step: each edge midpoint's mean of its (up to 4) neighbours at distance step/2.

    Returns the means for the midpoints on the corner rows (x midpoints, shape (m + 1, m)) and on the corner
    columns (y midpoints, shape (m, m + 1)), m = N / step; the neighbours off the grid are skipped.
    """
    half = step // 2
    centres = h[half::step, half::step]  # (m, m), set by the diamond step
    m = centres.shape[0]
    # x midpoints (row r·step, column half + c·step): left/right corners, centres above/below
    row_sum = h[0::step, 0:-1:step] + h[0::step, step::step]
    row_count = np.full(row_sum.shape, 2.0)
    row_sum[1:] += centres
    row_sum[:-1] += centres
    row_count[1:] += 1.0
    row_count[:-1] += 1.0
    # y midpoints (row half + r·step, column c·step): corners above/below, centres left/right
    col_sum = h[0:-1:step, 0::step] + h[step::step, 0::step]
    col_count = np.full(col_sum.shape, 2.0)
    col_sum[:, 1:] += centres
    col_sum[:, :-1] += centres
    col_count[:, 1:] += 1.0
    col_count[:, :-1] += 1.0
    assert row_sum.shape == (m + 1, m) and col_sum.shape == (m, m + 1)
    return row_sum / row_count, col_sum / col_count


def fbm_terrain(level: int, hurst: float = 0.8, *, seed: int, method: str = "diamond-square",
                sigma: float = 1.0, max_bytes: int | None = None) -> NDArray[np.float64]:  # fmt: skip
    """Fractional Brownian heightfield on a (2^level + 1)² grid by random midpoint displacement.

    Corners start as N(0, σ²) samples. At refinement step k (squares of side 2^(level-k) cells) every new point
    is the mean of its parents plus a Gaussian offset of standard deviation $σ_k = σ·2^(-k·H)$, and the
    second half-step of diamond-square uses σ_k·2^(-H/2):

    - ``"diamond-square"``: centres from the 4 square corners (diamond), then edge midpoints from their up to
      4 diamond neighbours (square).
    - ``"midpoint"``: edge midpoints from their 2 edge ends, centres from the 4 corners (the textbook scheme).

    The surface's expected fractal dimension is $D = 3 − H$ (H near 1 smooth, near 0 rough).

    Returns
    -------
    (2^level + 1, 2^level + 1) float64 heights; row i is y, column j is x. Same seed, same bytes.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Random Midpoint-Displacement Methods"); A. Fournier, D. Fussell,
    L. Carpenter, "Computer rendering of stochastic models", CACM 25(6), 1982.
    """
    where = "fbm_terrain"
    n = check_level(level, where)
    H = check_hurst(hurst, where)
    s0 = as_scalar(sigma, "sigma", where=where, error=GeometryError)
    if s0 < 0.0:
        raise GeometryError(f"{where}: sigma = {s0!r} is negative; give a standard deviation >= 0")
    if method not in ("diamond-square", "midpoint"):
        raise GeometryError(f"{where}: method = {method!r} is unknown; give 'diamond-square' or 'midpoint'")
    side = 2**n + 1
    check_fractal_memory(side * side * 8 * 6, byte_budget(max_bytes, where), where=where, name="level", value=n)
    rng = np.random.default_rng(check_seed(seed, where))
    N = side - 1
    h = np.zeros((side, side))
    h[0::N, 0::N] = s0 * rng.standard_normal((2, 2)) if N > 0 else s0 * rng.standard_normal((1, 1))
    step = N
    k = 0
    while step > 1:
        half = step // 2
        scale = s0 * 2.0 ** (-(k + 1) * H)
        centre_mean = (h[0:-1:step, 0:-1:step] + h[step::step, 0:-1:step] + h[0:-1:step, step::step]
                       + h[step::step, step::step]) / 4.0  # fmt: skip
        if method == "diamond-square":
            h[half::step, half::step] = centre_mean + scale * rng.standard_normal(centre_mean.shape)
            scale2 = scale * 2.0 ** (-H / 2.0)
            row_mean, col_mean = _square_step_means(h, step)
            h[0::step, half::step] = row_mean + scale2 * rng.standard_normal(row_mean.shape)
            h[half::step, 0::step] = col_mean + scale2 * rng.standard_normal(col_mean.shape)
        else:
            row_mean = (h[0::step, 0:-1:step] + h[0::step, step::step]) / 2.0
            col_mean = (h[0:-1:step, 0::step] + h[step::step, 0::step]) / 2.0
            h[0::step, half::step] = row_mean + scale * rng.standard_normal(row_mean.shape)
            h[half::step, 0::step] = col_mean + scale * rng.standard_normal(col_mean.shape)
            h[half::step, half::step] = centre_mean + scale * rng.standard_normal(centre_mean.shape)
        step = half
        k += 1
    return h


def heightfield_mesh(heights: ArrayLike, size: float = 1.0, *, max_bytes: int | None = None) -> Mesh:
    """Triangulate a heightfield z = heights[i, j] over the square [0, size]² (x = column, y = row).

    Two counter-clockwise triangles per grid cell (seen from +z); vertex normals from central differences,
    $n = (−∂z/∂x, −∂z/∂y, 1)$ normalized.

    Returns
    -------
    Mesh with R·C vertices (row-major) and 2·(R − 1)·(C − 1) faces.
    """
    where = "heightfield_mesh"
    try:
        z = np.asarray(heights, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: heights = {describe(heights)} is not numeric; give (R, C) numbers") from None
    if z.ndim != 2 or z.shape[0] < 2 or z.shape[1] < 2:
        raise GeometryError(f"{where}: heights has shape {z.shape}; give an (R, C) grid with R, C >= 2")
    if not np.isfinite(z).all():
        raise GeometryError(f"{where}: heights has non-finite values; give finite heights")
    a = as_scalar(size, "size", where=where, error=GeometryError)
    if a <= 0.0:
        raise GeometryError(f"{where}: size = {a!r} is not positive; give a side length > 0")
    R, C = z.shape
    check_fractal_memory(R * C * (6 * 8 * 3) + (R - 1) * (C - 1) * 2 * 3 * 8 * 3, byte_budget(max_bytes, where),
                         where=where, name="heights.shape", value=z.shape)  # fmt: skip
    dx, dy = a / (C - 1), a / (R - 1)
    x, y = np.meshgrid(np.arange(C) * dx, np.arange(R) * dy)
    vertices = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    gy, gx = np.gradient(z, dy, dx)
    normals = np.column_stack([-gx.ravel(), -gy.ravel(), np.ones(R * C)])
    i, j = np.meshgrid(np.arange(R - 1), np.arange(C - 1), indexing="ij")
    a0 = (i * C + j).ravel()
    faces = np.empty((2 * a0.size, 3), dtype=np.int64)
    faces[0::2] = np.column_stack([a0, a0 + 1, a0 + C + 1])
    faces[1::2] = np.column_stack([a0, a0 + C + 1, a0 + C])
    return Mesh(vertices, faces, vertex_normals=normals)


def fractal_coastline(polyline: ArrayLike, level: int, *, seed: int, hurst: float = 0.5, amplitude: float = 0.3,
                      max_bytes: int | None = None, record: Any = None) -> Points:  # fmt: skip
    """Fractal coastline: midpoint displacement of a polyline in the xy plane, `level` times.

    Each segment p→q gains the midpoint (p + q)/2 + g·σ_k·n̂, with n̂ the unit normal of p→q in the xy plane,
    g ~ N(0, 1) and $σ_k = amplitude·L̄·2^(−k·H)$ at step k (L̄ the mean initial segment length); z is
    interpolated. Endpoints stay fixed; for a closed outline repeat the first point at the end. The curve's
    dimension is about 2 − H. ``record(k, points, sigma)`` (``frustum.steps``), if given, sees the polyline
    after each step k = 1 … level and that step's σ_k.

    Returns
    -------
    ((N − 1)·2^level + 1, 3) float64.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Random Midpoint-Displacement Methods").
    """
    where = "fractal_coastline"
    points = as_points(polyline, "polyline", where=where)
    if points.shape[0] < 2:
        raise GeometryError(f"{where}: polyline has {points.shape[0]} points; give at least 2")
    n = check_level(level, where)
    H = check_hurst(hurst, where)
    amp = as_scalar(amplitude, "amplitude", where=where, error=GeometryError)
    if amp < 0.0:
        raise GeometryError(f"{where}: amplitude = {amp!r} is negative; give a relative amplitude >= 0")
    check_fractal_memory(((points.shape[0] - 1) * 2**n + 1) * 3 * 8 * 3, byte_budget(max_bytes, where), where=where,
                 name="level", value=n)  # fmt: skip
    rng = np.random.default_rng(check_seed(seed, where))
    mean_length = float(np.linalg.norm(np.diff(points, axis=0), axis=1).mean())
    for k in range(n):
        p, q = points[:-1], points[1:]
        d = q - p
        normal = np.column_stack([-d[:, 1], d[:, 0], np.zeros(d.shape[0])])
        length = np.sqrt((normal * normal).sum(axis=1))
        normal = np.divide(normal, length[:, None], out=np.zeros_like(normal), where=length[:, None] > 0)
        sigma = amp * mean_length * 2.0 ** (-(k + 1) * H)
        mid = (p + q) / 2.0 + (sigma * rng.standard_normal(p.shape[0]))[:, None] * normal
        out = np.empty((2 * p.shape[0] + 1, 3))
        out[0:-1:2] = p
        out[1::2] = mid
        out[-1] = points[-1]
        points = out
        if record is not None:
            record(k + 1, points, sigma)
    return points
