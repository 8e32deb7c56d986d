"""Fractal curves and sets by geometric construction: similarity dimension, Koch curve and snowflake, Cantor set,
Sierpinski triangle, Hilbert (2D and 3D) and Peano space-filling curves."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_scalar, describe
from frustum.errors import GeometryError
from frustum.geometry.fractals.checks import (
    SQRT3,
    as_point2,
    byte_budget,
    check_fractal_memory,
    check_level,
    check_positive_int,
    with_z,
)
from frustum.geometry.mesh import Mesh

__all__ = [
    "cantor_set",
    "hilbert_curve",
    "hilbert_curve_3d",
    "koch_curve",
    "koch_snowflake",
    "peano_curve",
    "sierpinski_triangle",
    "similarity_dimension",
]


def similarity_dimension(n_copies: Any, scale: Any) -> float:
    """Similarity (fractal) dimension of a set made of `n_copies` copies of itself scaled by `scale`.

    $D = log N / log(1/s)$ (the seed writes $D = log N / log r$ with $r = 1/s$ the magnification)

    Parameters
    ----------
    n_copies : int
        N >= 1, the number of self-similar pieces.
    scale : float
        s in (0, 1), the scaling factor of each piece.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("The Fractal Dimension"); [seed] "Fractal dimension".
    """
    where = "similarity_dimension"
    n = check_positive_int(n_copies, where, "n_copies")
    s = as_scalar(scale, "scale", where=where, error=GeometryError)
    if not 0.0 < s < 1.0:
        raise GeometryError(f"{where}: scale = {s!r} is outside (0, 1); give the scaling factor of one piece")
    return math.log(n) / math.log(1.0 / s)


def _koch_refine(points: NDArray[np.float64]) -> NDArray[np.float64]:
    # each segment p→q becomes p, p + d/3, p + d/3 + R(60°)·d/3, p + 2d/3 (bump on the left of p→q)
    p, q = points[:-1], points[1:]
    third = (q - p) / 3.0
    c, s = 0.5, SQRT3 / 2.0
    bump = np.column_stack([c * third[:, 0] - s * third[:, 1], s * third[:, 0] + c * third[:, 1]])
    out = np.empty((4 * p.shape[0] + 1, 2))
    out[0:-1:4] = p
    out[1::4] = p + third
    out[2::4] = p + third + bump
    out[3::4] = p + 2.0 * third
    out[-1] = points[-1]
    return out


def koch_curve(level: int, start: ArrayLike = (0.0, 0.0), end: ArrayLike = (1.0, 0.0), *,
               max_bytes: int | None = None, record: Any = None) -> Points:  # fmt: skip
    """Koch curve from `start` to `end`: a polyline of 4^level segments in the plane z = 0.

    Each segment is replaced by four of a third of its length, the middle third raised into an equilateral
    bump on the left of the direction of travel. $D = log 4 / log 3 ≈ 1.2619$. ``record(k, points)``
    (``frustum.steps``), if given, sees the (M, 2) polyline after each iteration k = 1 … level.

    Returns
    -------
    (4^level + 1, 3) float64 polyline vertices.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Geometric Construction of Deterministic Self-Similar Fractals").
    """
    where = "koch_curve"
    n = check_level(level, where)
    check_fractal_memory((4**n + 1) * 3 * 8 * 3, byte_budget(max_bytes, where), where=where, name="level", value=n)
    points = np.stack([as_point2(start, "start", where), as_point2(end, "end", where)])
    for k in range(n):
        points = _koch_refine(points)
        if record is not None:
            record(k + 1, points)
    return with_z(points)


def koch_snowflake(level: int, size: float = 1.0, *, max_bytes: int | None = None) -> Points:
    """Koch snowflake: a Koch curve on each side of an equilateral triangle, bumps outward.

    The triangle has corners (0, 0), (size/2, size·√3/2), (size, 0), traversed clockwise so the bumps point
    out. Closed polyline (the last vertex repeats the first) of 3·4^level segments.

    Returns
    -------
    (3·4^level + 1, 3) float64.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Geometric Construction of Deterministic Self-Similar Fractals").
    """
    where = "koch_snowflake"
    n = check_level(level, where)
    a = as_scalar(size, "size", where=where, error=GeometryError)
    if a <= 0.0:
        raise GeometryError(f"{where}: size = {a!r} is not positive; give a side length > 0")
    check_fractal_memory((3 * 4**n + 1) * 3 * 8 * 3, byte_budget(max_bytes, where), where=where, name="level", value=n)
    points = np.array([[0.0, 0.0], [a / 2.0, a * SQRT3 / 2.0], [a, 0.0], [0.0, 0.0]])
    for _ in range(n):
        points = _koch_refine(points)
    return with_z(points)


def cantor_set(level: int, start: float = 0.0, end: float = 1.0, *,
               max_bytes: int | None = None) -> NDArray[np.float64]:  # fmt: skip
    """Cantor set: remove the open middle third of every interval, `level` times.

    $D = log 2 / log 3 ≈ 0.6309$.

    Returns
    -------
    (2^level, 2) float64: the kept closed intervals [a, b], left to right.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("The Fractal Dimension").
    """
    where = "cantor_set"
    n = check_level(level, where)
    a = as_scalar(start, "start", where=where, error=GeometryError)
    b = as_scalar(end, "end", where=where, error=GeometryError)
    if not b > a:
        raise GeometryError(f"{where}: end = {b!r} is not greater than start = {a!r}; give start < end")
    check_fractal_memory(2**n * 2 * 8 * 3, byte_budget(max_bytes, where), where=where, name="level", value=n)
    index = np.arange(2**n, dtype=np.int64)
    left = np.zeros(2**n)
    for bit in range(n):  # digit 0 or 2 in base 3, most significant first
        left += 2.0 * ((index >> (n - 1 - bit)) & 1) * 3.0 ** -(bit + 1)
    width = 3.0**-n
    return np.column_stack([a + (b - a) * left, a + (b - a) * (left + width)])


def sierpinski_triangle(level: int, corners: ArrayLike = ((0.0, 0.0), (1.0, 0.0), (0.5, SQRT3 / 2.0)), *,
                        max_bytes: int | None = None) -> Mesh:  # fmt: skip
    """Sierpinski triangle (gasket): keep the three corner half-size triangles, `level` times.

    $D = log 3 / log 2 ≈ 1.5850$. Each kept triangle is one face with its own three vertices (no sharing),
    wound like `corners`; in the plane z = 0.

    Parameters
    ----------
    corners : (3, 2) array_like
        The initiator triangle (default equilateral with unit side).

    Returns
    -------
    Mesh with 3^level faces and 3·3^level vertices.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Geometric Construction of Deterministic Self-Similar Fractals").
    """
    where = "sierpinski_triangle"
    n = check_level(level, where)
    try:
        tri = np.asarray(corners, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: corners = {describe(corners)} is not numeric; give (3, 2) points") from None
    if tri.shape != (3, 2) or not np.isfinite(tri).all():
        raise GeometryError(f"{where}: corners = {describe(corners)} is not (3, 2) finite numbers; give 3 (x, y)")
    check_fractal_memory(3**n * (9 * 8 * 4 + 3 * 8), byte_budget(max_bytes, where), where=where, name="level", value=n)
    tris = tri[None]
    for _ in range(n):
        a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
        ab, bc, ca = (a + b) / 2.0, (b + c) / 2.0, (c + a) / 2.0
        tris = np.stack([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1)], 1)
        tris = tris.reshape(-1, 3, 2)
    vertices = with_z(tris.reshape(-1, 2))
    faces = np.arange(vertices.shape[0], dtype=np.int64).reshape(-1, 3)
    return Mesh(vertices, faces)


def _curve_budget(count: int, where: str, n: int, max_bytes: Any) -> None:
    check_fractal_memory(count * 3 * 8 * 4, byte_budget(max_bytes, where), where=where, name="level", value=n)


def hilbert_curve(level: int, *, max_bytes: int | None = None) -> Points:
    """2D Hilbert curve: the 4^level cell centres of the unit square's 2^level × 2^level grid in curve order.

    Starts at the cell at (0, 0), ends at the cell at (1, 0); consecutive points are one cell (2^-level)
    apart. Level 1: (¼, ¼), (¼, ¾), (¾, ¾), (¾, ¼).

    Returns
    -------
    (4^level, 3) float64 polyline in z = 0.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Geometric Construction of Deterministic Self-Similar Fractals").
    """
    where = "hilbert_curve"
    n = check_level(level, where)
    _curve_budget(4**n, where, n, max_bytes)
    side = 2**n
    t = np.arange(side * side, dtype=np.int64)
    x = np.zeros_like(t)
    y = np.zeros_like(t)
    s = 1
    while s < side:  # the classic d2xy: rotate/flip the quadrant, then add its offset
        rx = 1 & (t // 2)
        ry = 1 & (t ^ rx)
        flip = ry == 0
        swap_x = np.where(flip & (rx == 1), s - 1 - x, x)
        swap_y = np.where(flip & (rx == 1), s - 1 - y, y)
        x, y = np.where(flip, swap_y, swap_x), np.where(flip, swap_x, swap_y)
        x = x + s * rx
        y = y + s * ry
        t = t // 4
        s *= 2
    return with_z((np.column_stack([x, y]).astype(np.float64) + 0.5) / side)


def hilbert_curve_3d(level: int, *, max_bytes: int | None = None) -> Points:
    """3D Hilbert curve: the 8^level cell centres of the unit cube's grid in curve order (Skilling's method).

    Consecutive points are one cell (2^-level) apart, and every cell is visited once.

    Returns
    -------
    (8^level, 3) float64.

    References
    ----------
    J. Skilling, "Programming the Hilbert curve", AIP Conf. Proc. 707 (2004); [HB 15] "Fractal-Geometry
    Methods".
    """
    where = "hilbert_curve_3d"
    n = check_level(level, where)
    _curve_budget(8**n, where, n, max_bytes)
    count = 8**n
    h = np.arange(count, dtype=np.int64)
    # transpose the index: X[i] collects bits 3b - 1 - i, 3b - 4 - i, ... (most significant first)
    X = [np.zeros(count, dtype=np.int64) for _ in range(3)]
    for bit in range(n):
        for i in range(3):
            X[i] |= ((h >> (3 * (n - 1 - bit) + (2 - i))) & 1) << (n - 1 - bit)
    if n > 0:
        t = X[2] >> 1  # Gray decode
        for i in (2, 1):
            X[i] ^= X[i - 1]
        X[0] ^= t
        q = 2
        while q != (1 << n):  # undo excess work
            p = q - 1
            for i in (2, 1, 0):
                has = (X[i] & q) != 0
                t = (X[0] ^ X[i]) & p
                x0_flip = X[0] ^ p
                x0_swap = X[0] ^ t
                xi_swap = X[i] ^ t
                new_x0 = np.where(has, x0_flip, x0_swap)
                if i != 0:
                    X[i] = np.where(has, X[i], xi_swap)
                X[0] = new_x0
            q <<= 1
    return (np.column_stack(X).astype(np.float64) + 0.5) / (1 << n)


def peano_curve(level: int, *, max_bytes: int | None = None) -> Points:
    """Peano curve: the 9^level cell centres of the unit square's 3^level × 3^level grid in curve order.

    From the base-3 digits a₁…a₂ₙ of the index: xⱼ = k^(a₂+a₄+…+a₂ⱼ₋₂)(a₂ⱼ₋₁), yⱼ = k^(a₁+a₃+…+a₂ⱼ₋₁)(a₂ⱼ)
    with k(a) = 2 − a (Peano's own formula). Level 1 runs up the first column, down the second, up the third.

    Returns
    -------
    (9^level, 3) float64 polyline in z = 0.

    References
    ----------
    H. Sagan, *Space-Filling Curves*, Springer 1994, §3.1; [HB 15] "Fractal-Geometry Methods".
    """
    where = "peano_curve"
    n = check_level(level, where)
    _curve_budget(9**n, where, n, max_bytes)
    count = 9**n
    index = np.arange(count, dtype=np.int64)
    digits = [(index // 3 ** (2 * n - 1 - d)) % 3 for d in range(2 * n)]  # a₁ … a₂ₙ
    x = np.zeros(count, dtype=np.int64)
    y = np.zeros(count, dtype=np.int64)
    even_sum = np.zeros(count, dtype=np.int64)  # a₂ + a₄ + … so far
    odd_sum = np.zeros(count, dtype=np.int64)  # a₁ + a₃ + … so far
    for j in range(n):
        a_odd, a_even = digits[2 * j], digits[2 * j + 1]
        xj = np.where(even_sum % 2 == 1, 2 - a_odd, a_odd)
        odd_sum = odd_sum + a_odd
        yj = np.where(odd_sum % 2 == 1, 2 - a_even, a_even)
        even_sum = even_sum + a_even
        x = 3 * x + xj
        y = 3 * y + yj
    return with_z((np.column_stack([x, y]).astype(np.float64) + 0.5) / 3**n)
