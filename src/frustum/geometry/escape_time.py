"""Escape-time fractals: Mandelbrot and Julia images, and the quaternion Julia set as a mesh.

The self-squaring map z ← z² + c is iterated until |z| > R (the escape radius) or ``max_iter`` steps pass.
Images hold the **escape time**: the iteration count n at which |z_n| > R first held, or with ``smooth=True``
the continuous count $ν = n + 1 − log₂(ln|z_n| / ln R)$ (renormalized iteration count), which removes the
colour bands. Points that never escape within ``max_iter`` get ``np.inf``, so ``np.isfinite(image)`` is the
outside mask.

Pixel (row i, column j) samples the centre of its cell: $x = x_min + (j + ½)·(x_max − x_min)/W$,
$y = y_max − (i + ½)·(y_max − y_min)/H$ (row 0 at the top, as in an image).

References
----------
[HB 15] "Fractal-Geometry Methods" ("Self-Squaring Fractals"); [seed] "Quaternion Methods for 3-D Rotations"
(quaternions "are useful in … the generation of fractal objects").
"""

from __future__ import annotations

import math
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_scalar, describe
from frustum.budgets import check_operations
from frustum.errors import GeometryError
from frustum.geometry.fractals.checks import byte_budget, check_fractal_memory
from frustum.geometry.mesh import Mesh

__all__ = ["escape_time_colors", "julia", "mandelbrot", "quaternion_julia", "quaternion_julia_mesh"]


def _kernels() -> ModuleType:
    """The compiled kernels of this module (``raster/escape_time.py``), imported on first use: ``import frustum``
    never loads Numba."""
    from frustum.raster import escape_time

    return escape_time


def _window(value: Any, where: str) -> tuple[float, float, float, float]:
    try:
        w = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(
            f"{where}: window = {describe(value)} is not numeric; give (x_min, x_max, y_min, y_max)"
        ) from None
    if w.shape != (4,) or not np.isfinite(w).all() or not (w[0] < w[1] and w[2] < w[3]):
        raise GeometryError(
            f"{where}: window = {describe(value)} is not (x_min, x_max, y_min, y_max) with x_min < x_max and "
            "y_min < y_max; give a finite, nonempty rectangle"
        )
    return float(w[0]), float(w[1]), float(w[2]), float(w[3])


def _int_at_least(value: Any, name: str, where: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise GeometryError(f"{where}: {name} = {describe(value)} is not an integer >= {minimum}; give one")
    return int(value)


def _image(where: str, window: Any, width: Any, height: Any, max_iter: Any, escape_radius: Any, smooth: bool,
           max_bytes: Any, julia_c: complex | None) -> NDArray[np.float64]:  # fmt: skip
    x0, x1, y0, y1 = _window(window, where)
    w = _int_at_least(width, "width", where, 1)
    h = _int_at_least(height, "height", where, 1)
    iters = _int_at_least(max_iter, "max_iter", where, 1)
    radius = as_scalar(escape_radius, "escape_radius", where=where, error=GeometryError)
    if radius < 2.0:
        raise GeometryError(f"{where}: escape_radius = {radius!r} is below 2; give R >= 2 (orbits past 2 escape)")
    check_fractal_memory(w * h * 8, byte_budget(max_bytes, where), where=where, name="width·height", value=w * h)
    check_operations(w * h * iters, where=where, cause=f"{w} x {h} pixels x max_iter = {iters}", error=GeometryError)
    xs = x0 + (np.arange(w) + 0.5) * ((x1 - x0) / w)
    ys = y1 - (np.arange(h) + 0.5) * ((y1 - y0) / h)
    out = np.empty((h, w))
    c = 0j if julia_c is None else julia_c
    _kernels()._escape_image(xs, ys, julia_c is not None, c.real, c.imag, iters, radius * radius, bool(smooth), out)
    return out


def mandelbrot(window: ArrayLike = (-2.0, 1.0, -1.5, 1.5), width: int = 512, height: int = 512, *,
               max_iter: int = 256, escape_radius: float = 256.0, smooth: bool = True,
               max_bytes: int | None = None) -> NDArray[np.float64]:  # fmt: skip
    """Mandelbrot set image: escape time of $z ← z² + c$ from $z₀ = 0$, with c the pixel's point.

    $z_{n+1} = z_n² + c$; $ν = n + 1 − log₂(ln|z_n| / ln R)$ when smooth.

    Parameters
    ----------
    window : (x_min, x_max, y_min, y_max)
        The rectangle of the complex plane (x real, y imaginary) the image covers.
    width, height : int
        Image size in pixels (any resolution).
    max_iter : int
        Iterations before a point counts as inside (escape time ``inf``).
    escape_radius : float
        R >= 2; a large R (default 256) makes the smooth count continuous.

    Returns
    -------
    (height, width) float64 escape times; ``inf`` inside.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Self-Squaring Fractals").
    """
    return _image("mandelbrot", window, width, height, max_iter, escape_radius, smooth, max_bytes, None)


def julia(c: complex, window: ArrayLike = (-1.6, 1.6, -1.2, 1.2), width: int = 512, height: int = 384, *,
          max_iter: int = 256, escape_radius: float = 256.0, smooth: bool = True,
          max_bytes: int | None = None) -> NDArray[np.float64]:  # fmt: skip
    """Julia set image of $z ← z² + c$: escape time from z₀ = the pixel's point (same conventions as
    ``mandelbrot``).

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Self-Squaring Fractals").
    """
    where = "julia"
    try:
        cc = complex(c)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: c = {describe(c)} is not a complex number; give e.g. -0.8+0.156j") from None
    if not (math.isfinite(cc.real) and math.isfinite(cc.imag)):
        raise GeometryError(f"{where}: c = {cc!r} is not finite; give a finite complex number")
    return _image(where, window, width, height, max_iter, escape_radius, smooth, max_bytes, cc)


def escape_time_colors(image: ArrayLike, *, period: float = 32.0, inside: ArrayLike = (0.0, 0.0, 0.0)) \
        -> NDArray[np.uint8]:  # fmt: skip
    """Colour an escape-time image with a cyclic cosine palette: (H, W, 3) uint8, `inside` for ``inf``.

    $channel_k = ½ + ½·cos(2π(ν/period + φ_k))$ with phases $φ = (0, 0.15, 0.3)$ (Quilez's cosine palette).
    """
    where = "escape_time_colors"
    nu = np.asarray(image, dtype=np.float64)
    if nu.ndim != 2:
        raise GeometryError(f"{where}: image has shape {nu.shape}; give an (H, W) escape-time image")
    if np.isnan(nu).any():
        raise GeometryError(f"{where}: image has NaN values; give escape times (inf for inside)")
    per = as_scalar(period, "period", where=where, error=GeometryError)
    if per <= 0:
        raise GeometryError(f"{where}: period = {per!r} is not positive; give a period > 0")
    finite = np.isfinite(nu)
    t = np.where(finite, nu, 0.0)[..., None] / per + np.array([0.0, 0.15, 0.3])
    rgb = 0.5 + 0.5 * np.cos(2.0 * np.pi * t)
    rgb[~finite] = np.asarray(inside, dtype=np.float64)
    return np.round(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)


# ------------------------------------------------------------------------------------- quaternion Julia


def quaternion_julia(c: ArrayLike = (-0.2, 0.6, 0.2, 0.0), *, resolution: int = 64, bound: float = 1.5,
                     slice_w: float = 0.0, max_iter: int = 12, escape_radius: float = 4.0,
                     max_bytes: int | None = None) -> NDArray[np.float64]:  # fmt: skip
    """Smooth escape time of the quaternion map q ← q² + c on the 3D slice w = `slice_w` of 4D space.

    $q = (x, y, z, w) = x + y i + z j + w k$; $q² = (s² − |v|², 2 s v)$ for $q = (s, v)$. Points that stay within
    `escape_radius` for `max_iter` steps get the value ``max_iter`` (finite, so the field can be contoured).

    Returns
    -------
    (resolution, resolution, resolution) float64 on the grid ``np.linspace(-bound, bound, resolution)`` along
    x (axis 0), y (axis 1), z (axis 2).

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Self-Squaring Fractals"); A. Norton, "Generation and display of
    geometric fractals in 3-D", SIGGRAPH 1982.
    """
    where = "quaternion_julia"
    try:
        cq = np.asarray(c, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: c = {describe(c)} is not numeric; give a quaternion (w, x, y, z)") from None
    if cq.shape != (4,) or not np.isfinite(cq).all():
        raise GeometryError(f"{where}: c = {describe(c)} is not four finite numbers; give (1, i, j, k) components")
    n = _int_at_least(resolution, "resolution", where, 2)
    b = as_scalar(bound, "bound", where=where, error=GeometryError)
    if b <= 0:
        raise GeometryError(f"{where}: bound = {b!r} is not positive; give a half-width > 0")
    w = as_scalar(slice_w, "slice_w", where=where, error=GeometryError)
    iters = _int_at_least(max_iter, "max_iter", where, 1)
    radius = as_scalar(escape_radius, "escape_radius", where=where, error=GeometryError)
    if radius < 2.0:
        raise GeometryError(f"{where}: escape_radius = {radius!r} is below 2; give R >= 2")
    check_fractal_memory(n**3 * 8 * 4, byte_budget(max_bytes, where), where=where, name="resolution", value=n)
    check_operations(n**3 * iters, where=where, cause=f"resolution = {n} (n³ = {n**3} points) x max_iter = {iters}",
                     error=GeometryError)  # fmt: skip
    axis = np.linspace(-b, b, n)
    out = np.empty((n, n, n))
    _kernels()._quaternion_field(axis, axis, axis, w, np.ascontiguousarray(cq), iters, radius * radius, out)
    return out


def quaternion_julia_mesh(c: ArrayLike = (-0.2, 0.6, 0.2, 0.0), *, resolution: int = 64, bound: float = 1.5,
                          slice_w: float = 0.0, max_iter: int = 12, level: float | None = None,
                          max_bytes: int | None = None) -> Mesh:  # fmt: skip
    """The quaternion Julia set's 3D slice as a triangle mesh (marching cubes, scikit-image).

    Contours ``quaternion_julia(...)`` at `level` (default $max_iter − 1$: points that survive nearly all
    iterations). Faces wind counter-clockwise seen from outside (outward normals); vertex normals point up the
    field's descent, out of the set. The grid is padded by one sample below the level so the surface closes.

    Returns
    -------
    Mesh in the coordinates of the grid, within [-bound, bound]³.

    References
    ----------
    W. E. Lorensen, H. E. Cline, "Marching cubes", SIGGRAPH 1987; [HB 15] "Fractal-Geometry Methods".
    """
    from skimage.measure import marching_cubes

    where = "quaternion_julia_mesh"
    field = quaternion_julia(c, resolution=resolution, bound=bound, slice_w=slice_w, max_iter=max_iter,
                             max_bytes=max_bytes)  # fmt: skip
    iso = float(max_iter) - 1.0 if level is None else as_scalar(level, "level", where=where, error=GeometryError)
    if not (field.min() < iso < field.max()):
        raise GeometryError(
            f"{where}: level = {iso!r} is outside the field's range ({float(field.min())!r}, "
            f"{float(field.max())!r}); give a level inside it (or another c / bound)"
        )
    padded = np.pad(field, 1, constant_values=float(field.min()))
    spacing = 2.0 * float(bound) / (field.shape[0] - 1)
    verts, faces, normals, _ = marching_cubes(padded, level=iso, spacing=(spacing,) * 3)
    verts = verts - (float(bound) + spacing)
    # scikit-image winds faces clockwise seen from the high side (gradient_direction="descent"); the set is
    # the high side, so reverse to counter-clockwise from outside
    faces = np.ascontiguousarray(faces[:, ::-1], dtype=np.int64)
    normals = np.asarray(normals, dtype=np.float64)
    ok = np.linalg.norm(normals, axis=1) > 0
    if not ok.all():
        normals = None
    return Mesh(np.asarray(verts, dtype=np.float64), faces, vertex_normals=normals)
