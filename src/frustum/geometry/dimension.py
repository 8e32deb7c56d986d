"""Measuring fractal dimension by box counting: $D$ = −slope of $log N(ε)$ against $log ε$.

Three kinds of input:

- **points** (N, d), d = 1, 2 or 3: with given sizes, boxes are the cells $floor(P / ε)$ of a grid
  **anchored at the origin** (not re-centred: a construction on [0, 1]^d then gives exact counts; sample cell
  centres or interior points, not vertices that sit on box edges). With default sizes, boxes of side
  ε = extent/m tile the data's bounding box from its lower corner, the last box closed, and the fit keeps the
  finest three octaves where boxes still hold 4 points on average (inside the scaling range).
- **image**: a boolean (H, W) array; boxes are s × s pixel blocks from the top-left corner; ε = s pixels.
- **heightfield**: a float (H, W) array z = h(x, y) on a grid of spacing ``spacing`` (default 1/(max(H, W) − 1),
  the unit square); differential box counting: a block of s × s cells needs ⌈max/ε⌉ − ⌊min/ε⌋ boxes of
  side ε = s·spacing (at least 1). An fBm surface with Hurst exponent H has $D = 3 − H$.
- **Mesh**: points sampled inside every triangle (sub-triangle centroids finer than the smallest ε), moved
  by 1e-9·ε_min against the face normal so that a face lying on a box boundary counts for the box its solid
  is in.

References
----------
[HB 15] "Fractal-Geometry Methods" ("The Fractal Dimension"); N. Sarkar, B. B. Chaudhuri, "An efficient
differential box-counting approach to compute fractal dimension of image", IEEE SMC 24(1), 1994.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_scalar, describe
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh

__all__ = ["BoxCounting", "box_counting_dimension"]


@dataclass(frozen=True)
class BoxCounting:
    """Result of ``box_counting_dimension``.

    Attributes
    ----------
    dimension : float
        The fitted slope D of $log N(ε) = −D log ε + b$ (least squares).
    interval : (float, float)
        The `confidence` interval of D from the regression's standard error and Student's t with k − 2
        degrees of freedom (k box sizes).
    stderr : float
        Standard error of the slope (0 for an exact power law).
    sizes : (k,) float64
        Box sizes ε (data units; pixels for images).
    counts : (k,) int64
        Occupied boxes N(ε).
    """

    dimension: float
    interval: tuple[float, float]
    stderr: float
    sizes: NDArray[np.float64]
    counts: NDArray[np.int64]


def _count_points(points: NDArray, sizes: NDArray) -> NDArray[np.int64]:
    counts = []
    for eps in sizes:
        cells = np.floor(points / eps).astype(np.int64)
        cells -= cells.min(axis=0)
        span = cells.max(axis=0) + 1
        keys = np.zeros(cells.shape[0], dtype=np.int64)
        for axis in range(cells.shape[1]):
            keys = keys * span[axis] + cells[:, axis]
        counts.append(np.unique(keys).size)
    return np.array(counts, dtype=np.int64)


def _count_image(image: NDArray[np.bool_], sizes: NDArray) -> NDArray[np.int64]:
    counts = []
    H, W = image.shape
    for s in sizes.astype(np.int64):
        h, w = -(-H // s) * s, -(-W // s) * s
        padded = np.zeros((h, w), dtype=bool)
        padded[:H, :W] = image
        counts.append(int(padded.reshape(h // s, s, w // s, s).any(axis=(1, 3)).sum()))
    return np.array(counts, dtype=np.int64)


def _count_heightfield(z: NDArray, sizes_cells: NDArray, spacing: float) -> NDArray[np.int64]:
    # blocks of s × s cells = (s + 1) × (s + 1) samples, neighbours sharing their edge samples; a partial last
    # block (when s does not divide the cell count) is dropped
    counts = []
    for s in sizes_cells.astype(np.int64):
        eps = s * spacing
        blocks = np.lib.stride_tricks.sliding_window_view(z, (s + 1, s + 1))[::s, ::s]
        hi, lo = blocks.max(axis=(2, 3)), blocks.min(axis=(2, 3))
        counts.append(int(np.maximum(np.ceil(hi / eps) - np.floor(lo / eps), 1).sum()))
    return np.array(counts, dtype=np.int64)


def _mesh_points(mesh: Mesh, finest: float) -> NDArray:
    tri = np.asarray(mesh.vertices[mesh.faces], dtype=np.float64)  # (M, 3, 3)
    if tri.shape[0] == 0:
        raise GeometryError("box_counting_dimension: mesh has no faces; give a mesh with triangles")
    edges = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max()
    m = max(1, int(np.ceil(2.0 * edges / finest)))
    # centroids of the m² sub-triangles of the barycentric grid: strictly inside the triangle
    bary = []
    for i in range(m):
        for j in range(m - i):
            bary.append(((i + 1 / 3) / m, (j + 1 / 3) / m))  # upward sub-triangle
            if i + j < m - 1:
                bary.append(((i + 2 / 3) / m, (j + 2 / 3) / m))  # downward sub-triangle
    b = np.array(bary)
    weights = np.column_stack([1.0 - b.sum(axis=1), b])  # (S, 3)
    points = np.einsum("sk,mkd->msd", weights, tri)
    points = points - 1e-9 * finest * mesh.face_normals[:, None, :]
    return points.reshape(-1, 3)


# default sizes for points: ε = extent/m on a ladder of whole m growing by 2^(1/4), down to where boxes hold
# _FILL points on average; the fit uses the finest _OCTAVES octaves of it (see _default_counts)
_LADDER = 2.0**0.25
_FILL = 4
_OCTAVES = 3


def _count_tiling(points: NDArray, m: int) -> tuple[float, int]:
    """(ε, N): boxes of side ε = extent/m tiling the bounding box from its lower corner, the last box of each
    axis closed, so that a line or square sampled to its ends counts exactly m or m² boxes."""
    low = points.min(axis=0)
    extent = points.max(axis=0) - low
    largest = float(extent.max())
    # in box units: the largest axis spans exactly m boxes (1e-9 absorbs the round-off of extent · m / extent)
    last = np.maximum(np.ceil(extent * (m / largest) - 1e-9) - 1.0, 0.0).astype(np.int64)
    cells = np.minimum(np.floor((points - low) * (m / largest)).astype(np.int64), last)
    keys = np.zeros(cells.shape[0], dtype=np.int64)
    for axis in range(cells.shape[1]):
        keys = keys * (last[axis] + 1) + cells[:, axis]
    return largest / m, int(np.unique(keys).size)


def _default_counts(points: NDArray) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Box sizes and counts inside the scaling range of a finite sample.

    The ladder m = round(2 · 2^(j/4)) of whole boxes per extent runs up to the finest size at which boxes still
    hold ``_FILL`` points on average (N(ε) <= n/4: below it the sample, not the set, is counted); the fit keeps
    the finest three octaves of it. Coarse boxes are left out: near the extent the counts of self-similar sets
    overshoot the power law (Koch: N(3^-k+1)/N(3^-k) = 5.0, 4.5, 4.4, 4.2 before settling at 4), and a
    least-squares fit through them is biased by up to 0.07.
    """
    limit = points.shape[0] / _FILL
    sizes, counts = [], []
    m, step = 2, 0
    while len(sizes) < 400:
        eps, count = _count_tiling(points, m)
        if count > limit and sizes:
            break
        sizes.append(eps)
        counts.append(count)
        step += 1
        while round(2.0 * _LADDER**step) <= m:
            step += 1
        m = round(2.0 * _LADDER**step)
    eps, n = np.array(sizes), np.array(counts, dtype=np.int64)
    keep = eps <= eps[-1] * 2.0**_OCTAVES * (1.0 + 1e-9)
    return eps[keep], n[keep]


def box_counting_dimension(data: Any, sizes: ArrayLike | None = None, *, confidence: float = 0.95,
                           spacing: float | None = None) -> BoxCounting:  # fmt: skip
    """Box-counting dimension of points, an image, a heightfield or a mesh: $D = −d log N(ε) / d log ε$.

    N(ε) ∝ ε^(−D); D is the least-squares slope of log N against log(1/ε) over the given box sizes.

    Parameters
    ----------
    data : (N, d) array_like, (H, W) bool array, (H, W) float array, or Mesh
        See the module docstring for how each is covered with boxes.
    sizes : (k,) array_like, optional
        Box sizes ε, k >= 3 distinct positive values: data units for points and meshes, pixels for images,
        grid cells (integers >= 1) for heightfields. Default for points: ε = extent/m for whole m on a ladder
        growing by 2^(1/4), boxes tiling the bounding box from its lower corner (a line or a filled square
        sampled to its ends then counts exactly m or m² boxes), down to where boxes hold 4 points on average,
        and of those the finest three octaves (inside the scaling range: coarse boxes overshoot, see
        ``_default_counts``). With these defaults the documented dimensions come out within 0.02: Koch curve
        (level-7 vertices) 1.263, Cantor set (level-10 interval ends) 0.642, a line 1, a filled square 2; a
        single fit still carries the lattice's log-periodic ripple, about ±0.03 at lower levels (Koch level 6:
        +0.024). Images and heightfields: powers of 2 pixels or cells; meshes: extent·2^-k, k = 1 … 6
        (Sierpinski triangle level 8: 1.602, Menger sponge level 3: 2.728).
    confidence : float
        Level of the returned interval, in (0, 1).
    spacing : float, optional
        Heightfields only: the grid spacing in the units of the heights.

    Returns
    -------
    BoxCounting
        ``dimension``, ``interval``, ``stderr``, ``sizes``, ``counts``.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("The Fractal Dimension").
    """
    where = "box_counting_dimension"
    level = as_scalar(confidence, "confidence", where=where, error=GeometryError)
    if not 0.0 < level < 1.0:
        raise GeometryError(f"{where}: confidence = {level!r} is outside (0, 1); give e.g. 0.95")
    given = None
    if sizes is not None:
        try:
            given = np.asarray(sizes, dtype=np.float64)
        except (TypeError, ValueError):
            raise GeometryError(f"{where}: sizes = {describe(sizes)} is not numeric; give box sizes > 0") from None
        if given.ndim != 1 or given.size < 3 or not np.isfinite(given).all() or (given <= 0).any():
            raise GeometryError(f"{where}: sizes = {describe(sizes)} is not 3 or more finite sizes > 0; give them")
        if np.unique(given).size != given.size:
            raise GeometryError(f"{where}: sizes = {describe(sizes)} repeats a size; give distinct box sizes")

    if isinstance(data, Mesh):
        extent = float(np.ptp(data.vertices, axis=0).max()) if data.vertex_count else 0.0
        if extent <= 0.0:
            raise GeometryError(f"{where}: mesh has zero extent; give a mesh with nonzero size")
        eps = given if given is not None else extent * 2.0 ** -np.arange(1, 7)
        counts = _count_points(_mesh_points(data, float(eps.min())), eps)
    else:
        try:
            array = np.asarray(data)
        except ValueError:
            raise GeometryError(f"{where}: data = {describe(data)} is not an array; give points, an image or a "
                                "Mesh") from None  # fmt: skip
        if array.ndim == 2 and array.dtype == np.bool_ and array.shape[1] > 3:
            if not array.any():
                raise GeometryError(f"{where}: image has no True pixel; give a nonempty binary image")
            eps = given if given is not None else 2.0 ** np.arange(0, int(np.log2(min(array.shape))))
            if given is not None and (eps != np.round(eps)).any():
                raise GeometryError(f"{where}: sizes = {describe(sizes)} are not whole pixels; give integers >= 1")
            counts = _count_image(array, eps)
        elif array.ndim == 2 and array.shape[0] > 3 and array.shape[1] > 3 and np.issubdtype(array.dtype, np.floating):
            z = np.asarray(array, dtype=np.float64)
            if not np.isfinite(z).all():
                raise GeometryError(f"{where}: heightfield has non-finite values; give finite heights")
            step = 1.0 / (max(z.shape) - 1) if spacing is None else as_scalar(
                spacing, "spacing", where=where, error=GeometryError)  # fmt: skip
            if step <= 0.0:
                raise GeometryError(f"{where}: spacing = {step!r} is not positive; give the grid spacing > 0")
            eps = given if given is not None else 2.0 ** np.arange(0, int(np.log2(min(z.shape) - 1)) - 1)
            if given is not None and (eps != np.round(eps)).any():
                raise GeometryError(f"{where}: sizes = {describe(sizes)} are not whole grid cells; give integers")
            counts = _count_heightfield(z, eps, step)
        else:
            try:
                points = np.asarray(data, dtype=np.float64)
            except (TypeError, ValueError):
                raise GeometryError(f"{where}: data = {describe(data)} is not numeric; give (N, d) points") from None
            if points.ndim != 2 or points.shape[0] < 2 or points.shape[1] not in (1, 2, 3):
                raise GeometryError(
                    f"{where}: data has shape {points.shape}; give (N, d) points with N >= 2 and d in 1..3, a "
                    "bool image, a float heightfield, or a Mesh"
                )
            bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
            if bad.size:
                i = int(bad[0])
                raise GeometryError(f"{where}: data[{i}] = {describe(points[i])} is not finite; give finite points")
            extent = float(np.ptp(points, axis=0).max())
            if extent <= 0.0 and given is None:
                raise GeometryError(f"{where}: data has zero extent (all points equal); give distinct points")
            if given is not None:
                eps, counts = given, _count_points(points, given)
            else:
                eps, counts = _default_counts(points)
    if eps.size < 3:
        raise GeometryError(f"{where}: data allows only {eps.size} box sizes; give a larger sample or sizes=")
    x = np.log(1.0 / eps)
    y = np.log(counts.astype(np.float64))
    from scipy import stats  # imported here: scipy.stats costs seconds at `import frustum`

    fit = stats.linregress(x, y)
    stderr = float(fit.stderr) if np.isfinite(fit.stderr) else 0.0
    t = float(stats.t.ppf(0.5 + level / 2.0, eps.size - 2))
    slope = float(fit.slope)
    return BoxCounting(slope, (slope - t * stderr, slope + t * stderr), stderr, eps, counts)
