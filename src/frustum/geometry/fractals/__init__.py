"""Fractals: deterministic self-similar curves and solids, iterated function systems, fractal terrain.

Every generator takes a ``level`` (the number of refinement steps, 0 = the initiator) and refuses, before
allocating anything, a level whose output would exceed the memory budget (``frustum.set_budget``,
``FRUSTUM_MAX_BYTES``, ``--max-bytes``; default 8 GiB) or the per-call override ``max_bytes=``: the
``GeometryError`` states the bytes needed, the budget and how to raise it. Random fractals
take a ``seed`` (``numpy.random.default_rng``): same seed, same bytes.

Curves are returned as (N, 3) float64 polylines (2D curves lie in the plane z = 0); solids as a ``Mesh``.

Why one module: the chapter's generators are short and share the budget check and the polyline helpers.

References
----------
[HB 15] "Fractal-Geometry Methods": "The Fractal Dimension", "Geometric Construction of Deterministic
Self-Similar Fractals", "Affine Fractal-Construction Methods", "Random Midpoint-Displacement Methods".
[seed] "Fractals", "Fractal dimension".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_points, as_scalar, describe, read_only
from frustum.budgets import DEFAULT_BYTES, check_memory
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh

__all__ = [
    "DEFAULT_MAX_BYTES",
    "IFS",
    "barnsley_fern",
    "cantor_set",
    "fbm_terrain",
    "fractal_coastline",
    "heightfield_mesh",
    "hilbert_curve",
    "hilbert_curve_3d",
    "koch_curve",
    "koch_snowflake",
    "menger_sponge",
    "peano_curve",
    "sierpinski_ifs",
    "sierpinski_tetrahedron",
    "sierpinski_triangle",
    "similarity_dimension",
]


def _kernels() -> ModuleType:
    """The compiled kernels of this module (``raster/fractals.py``), imported on first use: ``import frustum``
    never loads Numba."""
    from frustum.raster import fractals

    return fractals


DEFAULT_MAX_BYTES = DEFAULT_BYTES
"""Default memory budget (8 GiB, ``frustum.budgets.DEFAULT_BYTES``); ``max_bytes=None`` (every generator's
default) follows the global budget in force, ``max_bytes=n`` overrides it for one call."""

_SQRT3 = math.sqrt(3.0)
_MAX_LEVEL = 1000


# --------------------------------------------------------------------------------------------- checks


def _level(value: Any, where: str, name: str = "level") -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not an integer; give an integer {name} >= 0")
    if value < 0:
        raise GeometryError(f"{where}: {name} = {int(value)} is negative; give an integer {name} >= 0")
    if value > _MAX_LEVEL:
        # checked before any size arithmetic: base**level with a huge level is itself a huge integer
        raise GeometryError(
            f"{where}: {name} = {int(value)} is above {_MAX_LEVEL}; its output (at least 2^{_MAX_LEVEL} bytes for "
            "any branching fractal) exceeds every memory budget; give a smaller level"
        )
    return int(value)


def _positive_int(value: Any, where: str, name: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise GeometryError(f"{where}: {name} = {describe(value)} is not an integer >= {minimum}; give one")
    return int(value)


def _budget(max_bytes: Any, where: str) -> int | None:
    """The per-call override `max_bytes` as an int, or None (the global budget, ``frustum.budgets``)."""
    if max_bytes is None:
        return None
    if isinstance(max_bytes, bool) or not isinstance(max_bytes, int | np.integer) or max_bytes <= 0:
        raise GeometryError(f"{where}: max_bytes = {describe(max_bytes)} is not a positive integer; give bytes > 0")
    return int(max_bytes)


def _human(nbytes: int) -> str:
    size = float(nbytes)
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"):
        if size < 1024.0 or unit == "EiB":
            return f"{size:.1f} {unit}" if unit != "B" else f"{nbytes} B"
        size /= 1024.0
    return f"{nbytes} B"  # pragma: no cover


def _check_memory(nbytes: int, max_bytes: int | None, *, where: str, name: str, value: Any) -> None:
    """Raise ``GeometryError`` if an output of `nbytes` bytes would exceed the budget.

    `max_bytes` None: the global budget (``frustum.budgets.check_memory``); an int: the per-call override. The
    message states the bytes needed, the budget and how to raise it, so a too-deep level fails at once instead
    of running out of memory.
    """
    if max_bytes is None:
        check_memory(nbytes, where=where, cause=f"{name} = {describe(value)}", error=GeometryError)
    elif nbytes > max_bytes:
        raise GeometryError(
            f"{where}: {name} = {describe(value)} would need {nbytes} bytes ({_human(nbytes)}), over the memory "
            f"budget max_bytes = {max_bytes} ({_human(max_bytes)}); lower {name} or raise max_bytes"
        )


def _point2(value: ArrayLike, name: str, where: str) -> NDArray[np.float64]:
    try:
        point = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not numeric; give (x, y)") from None
    if point.shape != (2,) or not np.isfinite(point).all():
        raise GeometryError(f"{where}: {name} = {describe(value)} is not two finite numbers; give (x, y)")
    return point


def _with_z(points2: NDArray[np.float64]) -> Points:
    out = np.zeros((points2.shape[0], 3))
    out[:, :2] = points2
    return out


# ----------------------------------------------------------------------------------- dimension formula


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
    n = _positive_int(n_copies, where, "n_copies")
    s = as_scalar(scale, "scale", where=where, error=GeometryError)
    if not 0.0 < s < 1.0:
        raise GeometryError(f"{where}: scale = {s!r} is outside (0, 1); give the scaling factor of one piece")
    return math.log(n) / math.log(1.0 / s)


# ------------------------------------------------------------------------------------------ Koch curve


def _koch_refine(points: NDArray[np.float64]) -> NDArray[np.float64]:
    # each segment p→q becomes p, p + d/3, p + d/3 + R(60°)·d/3, p + 2d/3 (bump on the left of p→q)
    p, q = points[:-1], points[1:]
    third = (q - p) / 3.0
    c, s = 0.5, _SQRT3 / 2.0
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
    n = _level(level, where)
    _check_memory((4**n + 1) * 3 * 8 * 3, _budget(max_bytes, where), where=where, name="level", value=n)
    points = np.stack([_point2(start, "start", where), _point2(end, "end", where)])
    for k in range(n):
        points = _koch_refine(points)
        if record is not None:
            record(k + 1, points)
    return _with_z(points)


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
    n = _level(level, where)
    a = as_scalar(size, "size", where=where, error=GeometryError)
    if a <= 0.0:
        raise GeometryError(f"{where}: size = {a!r} is not positive; give a side length > 0")
    _check_memory((3 * 4**n + 1) * 3 * 8 * 3, _budget(max_bytes, where), where=where, name="level", value=n)
    points = np.array([[0.0, 0.0], [a / 2.0, a * _SQRT3 / 2.0], [a, 0.0], [0.0, 0.0]])
    for _ in range(n):
        points = _koch_refine(points)
    return _with_z(points)


# ------------------------------------------------------------------------------------------ Cantor set


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
    n = _level(level, where)
    a = as_scalar(start, "start", where=where, error=GeometryError)
    b = as_scalar(end, "end", where=where, error=GeometryError)
    if not b > a:
        raise GeometryError(f"{where}: end = {b!r} is not greater than start = {a!r}; give start < end")
    _check_memory(2**n * 2 * 8 * 3, _budget(max_bytes, where), where=where, name="level", value=n)
    index = np.arange(2**n, dtype=np.int64)
    left = np.zeros(2**n)
    for bit in range(n):  # digit 0 or 2 in base 3, most significant first
        left += 2.0 * ((index >> (n - 1 - bit)) & 1) * 3.0 ** -(bit + 1)
    width = 3.0**-n
    return np.column_stack([a + (b - a) * left, a + (b - a) * (left + width)])


# ------------------------------------------------------------------------------------------ Sierpinski


def sierpinski_triangle(level: int, corners: ArrayLike = ((0.0, 0.0), (1.0, 0.0), (0.5, _SQRT3 / 2.0)), *,
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
    n = _level(level, where)
    try:
        tri = np.asarray(corners, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: corners = {describe(corners)} is not numeric; give (3, 2) points") from None
    if tri.shape != (3, 2) or not np.isfinite(tri).all():
        raise GeometryError(f"{where}: corners = {describe(corners)} is not (3, 2) finite numbers; give 3 (x, y)")
    _check_memory(3**n * (9 * 8 * 4 + 3 * 8), _budget(max_bytes, where), where=where, name="level", value=n)
    tris = tri[None]
    for _ in range(n):
        a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
        ab, bc, ca = (a + b) / 2.0, (b + c) / 2.0, (c + a) / 2.0
        tris = np.stack([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1), np.stack([ca, bc, c], 1)], 1)
        tris = tris.reshape(-1, 3, 2)
    vertices = _with_z(tris.reshape(-1, 2))
    faces = np.arange(vertices.shape[0], dtype=np.int64).reshape(-1, 3)
    return Mesh(vertices, faces)


_TETRA_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int64)


def sierpinski_tetrahedron(level: int, size: float = 1.0, *, max_bytes: int | None = None) -> Mesh:
    """Sierpinski tetrahedron: keep the four corner half-size tetrahedra, `level` times.

    $D = log 4 / log 2 = 2$. The initiator is the regular tetrahedron with corners (0, 0, 0), (s, 0, 0),
    (s/2, s√3/2, 0), (s/2, s√3/6, s√(2/3)). Each kept tetrahedron contributes 4 outward faces with their own
    vertices (flat shading).

    Returns
    -------
    Mesh with 4^level tetrahedra: 4^(level+1) faces, 4^(level+1) vertices.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Geometric Construction of Deterministic Self-Similar Fractals").
    """
    where = "sierpinski_tetrahedron"
    n = _level(level, where)
    s = as_scalar(size, "size", where=where, error=GeometryError)
    if s <= 0.0:
        raise GeometryError(f"{where}: size = {s!r} is not positive; give an edge length > 0")
    _check_memory(4**n * (12 * 3 * 8 * 4 + 12 * 8), _budget(max_bytes, where), where=where, name="level", value=n)
    tet = s * np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, _SQRT3 / 2, 0.0], [0.5, _SQRT3 / 6, math.sqrt(2 / 3)]])
    tets = tet[None]
    for _ in range(n):
        # corner i keeps vertex i and the midpoints towards the others: (v_i + v_j) / 2
        tets = ((tets[:, :, None, :] + tets[:, None, :, :]) / 2.0).reshape(-1, 4, 3)
    vertices = tets[:, _TETRA_FACES.ravel()].reshape(-1, 3)
    faces = np.arange(vertices.shape[0], dtype=np.int64).reshape(-1, 3)
    return Mesh(vertices, faces)


# ------------------------------------------------------------------------------------------ Menger sponge

# the four corners of each cube face, counter-clockwise seen from outside; normal +x, -x, +y, -y, +z, -z
_CUBE_FACE_CORNERS = np.array(
    [
        [[1, 0, 0], [1, 1, 0], [1, 1, 1], [1, 0, 1]],
        [[0, 0, 0], [0, 0, 1], [0, 1, 1], [0, 1, 0]],
        [[0, 1, 0], [0, 1, 1], [1, 1, 1], [1, 1, 0]],
        [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]],
        [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
        [[0, 0, 0], [0, 1, 0], [1, 1, 0], [1, 0, 0]],
    ],
    dtype=np.int64,
)
_CUBE_FACE_STEPS = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=np.int64)
_MENGER_KEEP = np.array(
    [(i, j, k) for i in range(3) for j in range(3) for k in range(3) if (i == 1) + (j == 1) + (k == 1) <= 1],
    dtype=np.int64,
)


def _menger_cells(n: int) -> NDArray[np.int64]:
    """(20^n, 3) integer corners of the kept cubes on the 3^n grid."""
    cells = np.zeros((1, 3), dtype=np.int64)
    for _ in range(n):
        cells = (3 * cells[:, None, :] + _MENGER_KEEP[None]).reshape(-1, 3)
    return cells


def menger_sponge(
    level: int, size: float = 1.0, *, shared_vertices: bool = True, max_bytes: int | None = None
) -> Mesh:
    """Menger sponge on the cube [0, size]³, with the faces between touching cubes removed.

    Each cube is split into 27 and the centre cube plus the six face centres are removed (20 kept), `level`
    times. Only cube faces without a kept neighbour are emitted, as two counter-clockwise triangles with
    outward normals. With ``shared_vertices`` (default) vertices are merged on the 3^level lattice, so the mesh
    is closed (watertight); with ``shared_vertices=False`` every square has its own 4 vertices whose normal is
    the face normal, for flat shading of the cube faces.
    $D = log 20 / log 3 ≈ 2.7268$; volume $(20/27)^level·size³$; exposed squares $2·20^level + 4·8^level$.

    Returns
    -------
    Mesh with 2·(2·20^level + 4·8^level) faces.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Geometric Construction of Deterministic Self-Similar Fractals").
    """
    where = "menger_sponge"
    n = _level(level, where)
    s = as_scalar(size, "size", where=where, error=GeometryError)
    if s <= 0.0:
        raise GeometryError(f"{where}: size = {s!r} is not positive; give an edge length > 0")
    # working set: cells and keys (20^n·32 B), candidate faces (6·20^n·(4·3·8 + ...)) ~ 1 KiB per cube
    _check_memory(20**n * 1024, _budget(max_bytes, where), where=where, name="level", value=n)
    m = 3**n
    cells = _menger_cells(n)
    keys = np.sort((cells[:, 0] * m + cells[:, 1]) * m + cells[:, 2])
    quads = []
    for corners, step in zip(_CUBE_FACE_CORNERS, _CUBE_FACE_STEPS, strict=True):
        nb = cells + step
        inside = ((nb >= 0) & (nb < m)).all(axis=1)
        nb_keys = (nb[:, 0] * m + nb[:, 1]) * m + nb[:, 2]
        pos = np.clip(np.searchsorted(keys, nb_keys), 0, keys.size - 1)
        exposed = ~(inside & (keys[pos] == nb_keys))
        quads.append(cells[exposed][:, None, :] + corners[None])
    quad_corners = np.concatenate(quads).reshape(-1, 3)  # (4Q, 3) lattice points
    if not shared_vertices:
        q = np.arange(quad_corners.shape[0], dtype=np.int64).reshape(-1, 4)
        faces = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]], axis=1).reshape(-1, 3)
        normals = np.repeat(np.concatenate([np.repeat(st[None], len(c), 0) for st, c in
                                            zip(_CUBE_FACE_STEPS, quads, strict=True)]), 4, axis=0)  # fmt: skip
        return Mesh(quad_corners.astype(np.float64) * (s / m), faces, vertex_normals=normals.astype(np.float64))
    m1 = m + 1
    lattice = (quad_corners[:, 0] * m1 + quad_corners[:, 1]) * m1 + quad_corners[:, 2]
    unique, inverse = np.unique(lattice, return_inverse=True)
    ijk = np.column_stack([unique // (m1 * m1), (unique // m1) % m1, unique % m1])
    vertices = ijk.astype(np.float64) * (s / m)
    q = inverse.reshape(-1, 4).astype(np.int64)
    faces = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]], axis=1).reshape(-1, 3)
    return Mesh(vertices, faces)


# -------------------------------------------------------------------------------- space-filling curves


def _curve_budget(count: int, where: str, n: int, max_bytes: Any) -> None:
    _check_memory(count * 3 * 8 * 4, _budget(max_bytes, where), where=where, name="level", value=n)


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
    n = _level(level, where)
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
    return _with_z((np.column_stack([x, y]).astype(np.float64) + 0.5) / side)


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
    n = _level(level, where)
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
    n = _level(level, where)
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
    return _with_z((np.column_stack([x, y]).astype(np.float64) + 0.5) / 3**n)


# ----------------------------------------------------------------------------- iterated function systems


@dataclass(frozen=True, eq=False)
class IFS:
    """An iterated function system: contractive affine maps $wᵢ(P) = Aᵢ·P + bᵢ$ chosen with probabilities $pᵢ$.

    The attractor is the unique set with $S = ∪ᵢ wᵢ(S)$ (Hutchinson); ``points`` iterates that union
    deterministically, ``chaos_game`` walks it at random (Barnsley).

    Parameters
    ----------
    affine_maps : (k, 3, 3) or (k, 4, 4) array_like
        Homogeneous affine matrices, column-vector convention (last row (0, …, 0, 1)): 2D maps as 3×3,
        3D maps as 4×4. Each linear part must be a contraction (largest singular value < 1).
    probabilities : (k,) array_like, optional
        Nonnegative, summing to 1 (within 1e-9). Default: proportional to |det Aᵢ| (2D or 3D part), each at
        least 1 % of the total, the usual choice that fills the attractor evenly.

    Attributes
    ----------
    linear : (k, 3, 3) float64  ·  offset : (k, 3) float64  ·  probabilities : (k,) float64  ·  dim : 2 or 3.

    References
    ----------
    [HB 15] "Fractal-Geometry Methods" ("Affine Fractal-Construction Methods"); M. Barnsley, *Fractals
    Everywhere*, 1988, ch. III.
    """

    affine_maps: Any
    probabilities: Any = None

    def __post_init__(self) -> None:
        where = "IFS"
        try:
            maps = np.asarray(self.affine_maps, dtype=np.float64)
        except (TypeError, ValueError):
            raise GeometryError(
                f"{where}: affine_maps = {describe(self.affine_maps)} is not numeric; give (k, 3, 3) or (k, 4, 4)"
            ) from None
        if maps.ndim != 3 or maps.shape[0] < 1 or maps.shape[1:] not in ((3, 3), (4, 4)):
            raise GeometryError(
                f"{where}: affine_maps has shape {maps.shape}; give (k, 3, 3) 2D or (k, 4, 4) 3D homogeneous maps"
            )
        if not np.isfinite(maps).all():
            raise GeometryError(f"{where}: affine_maps has non-finite entries; give finite matrices")
        k, d = maps.shape[0], maps.shape[1] - 1
        bottom = np.zeros(d + 1)
        bottom[-1] = 1.0
        bad = np.flatnonzero(np.abs(maps[:, d, :] - bottom).max(axis=1) > 0.0)
        if bad.size:
            i = int(bad[0])
            raise GeometryError(
                f"{where}: affine_maps[{i}] has last row {describe(maps[i, d])}; an affine map's last row is "
                f"{describe(bottom)}"
            )
        linear = np.zeros((k, 3, 3))
        offset = np.zeros((k, 3))
        linear[:, :d, :d] = maps[:, :d, :d]
        offset[:, :d] = maps[:, :d, d]
        sigma = np.linalg.svd(maps[:, :d, :d], compute_uv=False)[:, 0]
        bad = np.flatnonzero(sigma >= 1.0)
        if bad.size:
            i = int(bad[0])
            raise GeometryError(
                f"{where}: affine_maps[{i}] stretches by {float(sigma[i])!r}; each map must be a contraction "
                "(largest singular value < 1)"
            )
        if self.probabilities is None:
            det = np.abs(np.linalg.det(maps[:, :d, :d]))
            det = det / det.sum() if det.sum() > 0 else np.full(k, 1.0 / k)
            p = np.maximum(det, 0.01)
            p = p / p.sum()
        else:
            try:
                p = np.asarray(self.probabilities, dtype=np.float64)
            except (TypeError, ValueError):
                raise GeometryError(
                    f"{where}: probabilities = {describe(self.probabilities)} is not numeric; give k numbers"
                ) from None
            if p.shape != (k,):
                raise GeometryError(
                    f"{where}: probabilities = {describe(self.probabilities)} has shape {p.shape}; give {k} "
                    "numbers, one per map"
                )
            if not np.isfinite(p).all() or (p < 0).any():
                raise GeometryError(
                    f"{where}: probabilities = {describe(p)} has a negative or non-finite entry; give numbers >= 0"
                )
            total = float(p.sum())
            if abs(total - 1.0) > 1e-9:
                raise GeometryError(f"{where}: probabilities = {describe(p)} sum to {total!r}; they must sum to 1")
        object.__setattr__(self, "affine_maps", read_only(maps))
        object.__setattr__(self, "probabilities", read_only(np.ascontiguousarray(p)))
        object.__setattr__(self, "linear", read_only(linear))
        object.__setattr__(self, "offset", read_only(offset))
        object.__setattr__(self, "dim", d)

    @property
    def map_count(self) -> int:
        """k, the number of maps."""
        return int(self.affine_maps.shape[0])

    def fixed_point(self, i: int = 0) -> Points:
        """(3,) the fixed point of map i, $P = Aᵢ·P + bᵢ$ (it lies on the attractor)."""
        d = self.dim
        point = np.zeros(3)
        point[:d] = np.linalg.solve(np.eye(d) - self.linear[i, :d, :d], self.offset[i, :d])
        return point

    def points(self, level: int, *, max_bytes: int | None = None) -> Points:
        """Deterministic algorithm: apply every map to the point set `level` times, from map 0's fixed point.

        $S_{n+1} = ∪ᵢ wᵢ(S_n)$, $S_0$ = {fixed point of $w₀$}; every point lies on the attractor.

        Returns
        -------
        (k^level, 3) float64, in map order (point j's base-k digits name the maps, outermost first).
        """
        where = "IFS.points"
        n = _level(level, where)
        _check_memory(self.map_count**n * 3 * 8 * 3, _budget(max_bytes, where), where=where, name="level", value=n)
        pts = self.fixed_point(0)[None]
        for _ in range(n):
            # (k, N, 3): map i applied to every point; outer index = map
            pts = (np.einsum("kab,nb->kna", self.linear, pts) + self.offset[:, None, :]).reshape(-1, 3)
        return pts

    def chaos_game(self, n_points: int, *, seed: int, skip: int = 100,
                   max_bytes: int | None = None) -> Points:  # fmt: skip
        """Random iteration (chaos game): x ← w_k(x) with k drawn with the map probabilities.

        Starts at map 0's fixed point; the first `skip` iterates are dropped. Same seed, same bytes.

        Returns
        -------
        (n_points, 3) float64.
        """
        where = "IFS.chaos_game"
        count = _positive_int(n_points, where, "n_points")
        skip = _positive_int(skip, where, "skip", minimum=0)
        _check_memory((count + skip) * (3 * 8 + 16), _budget(max_bytes, where), where=where, name="n_points",
                     value=count)  # fmt: skip
        rng = np.random.default_rng(_seed(seed, where))
        cumulative = np.cumsum(self.probabilities)
        cumulative[-1] = 1.0
        choices = np.searchsorted(cumulative, rng.random(count + skip), side="right").astype(np.int64)
        choices = np.minimum(choices, self.map_count - 1)
        out = np.empty((count, 3))
        _kernels()._chaos_game_kernel(np.ascontiguousarray(self.linear), np.ascontiguousarray(self.offset), choices,
                           self.fixed_point(0), skip, out)  # fmt: skip
        return out


def _seed(seed: Any, where: str) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise GeometryError(f"{where}: seed = {describe(seed)} is not an integer >= 0; give a seed like 0 or 42")
    return int(seed)


def barnsley_fern() -> IFS:
    """Barnsley's fern: four 2D maps with probabilities 0.01, 0.85, 0.07, 0.07 (Fractals Everywhere, 1988)."""
    maps = np.array(
        [
            [[0.0, 0.0, 0.0], [0.0, 0.16, 0.0], [0, 0, 1]],
            [[0.85, 0.04, 0.0], [-0.04, 0.85, 1.6], [0, 0, 1]],
            [[0.2, -0.26, 0.0], [0.23, 0.22, 1.6], [0, 0, 1]],
            [[-0.15, 0.28, 0.0], [0.26, 0.24, 0.44], [0, 0, 1]],
        ]
    )
    return IFS(maps, [0.01, 0.85, 0.07, 0.07])


def sierpinski_ifs(corners: ArrayLike = ((0.0, 0.0), (1.0, 0.0), (0.5, _SQRT3 / 2.0))) -> IFS:
    """The Sierpinski triangle as an IFS: $wᵢ(P) = (P + cᵢ)/2$ for the three corners $cᵢ$, probabilities 1/3."""
    tri = np.asarray(corners, dtype=np.float64)
    if tri.shape != (3, 2) or not np.isfinite(tri).all():
        raise GeometryError(f"sierpinski_ifs: corners = {describe(corners)} is not (3, 2) finite numbers")
    maps = np.zeros((3, 3, 3))
    maps[:, 0, 0] = maps[:, 1, 1] = 0.5
    maps[:, :2, 2] = tri / 2.0
    maps[:, 2, 2] = 1.0
    return IFS(maps, [1 / 3, 1 / 3, 1 - 2 / 3])


# ------------------------------------------------------------------------------------------ fBm terrain


def _hurst(value: Any, where: str) -> float:
    h = as_scalar(value, "hurst", where=where, error=GeometryError)
    if not 0.0 < h < 1.0:
        raise GeometryError(f"{where}: hurst = {h!r} is outside (0, 1); give a Hurst exponent H with 0 < H < 1")
    return h


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
    n = _level(level, where)
    H = _hurst(hurst, where)
    s0 = as_scalar(sigma, "sigma", where=where, error=GeometryError)
    if s0 < 0.0:
        raise GeometryError(f"{where}: sigma = {s0!r} is negative; give a standard deviation >= 0")
    if method not in ("diamond-square", "midpoint"):
        raise GeometryError(f"{where}: method = {method!r} is unknown; give 'diamond-square' or 'midpoint'")
    side = 2**n + 1
    _check_memory(side * side * 8 * 6, _budget(max_bytes, where), where=where, name="level", value=n)
    rng = np.random.default_rng(_seed(seed, where))
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
    _check_memory(R * C * (6 * 8 * 3) + (R - 1) * (C - 1) * 2 * 3 * 8 * 3, _budget(max_bytes, where), where=where,
                 name="heights.shape", value=z.shape)  # fmt: skip
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
    n = _level(level, where)
    H = _hurst(hurst, where)
    amp = as_scalar(amplitude, "amplitude", where=where, error=GeometryError)
    if amp < 0.0:
        raise GeometryError(f"{where}: amplitude = {amp!r} is negative; give a relative amplitude >= 0")
    _check_memory(((points.shape[0] - 1) * 2**n + 1) * 3 * 8 * 3, _budget(max_bytes, where), where=where,
                 name="level", value=n)  # fmt: skip
    rng = np.random.default_rng(_seed(seed, where))
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
