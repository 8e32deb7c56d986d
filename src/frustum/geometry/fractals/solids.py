"""Fractal solids as meshes: the Sierpinski tetrahedron and the Menger sponge."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import as_scalar
from frustum.errors import GeometryError
from frustum.geometry.fractals.checks import SQRT3, byte_budget, check_fractal_memory, check_level
from frustum.geometry.mesh import Mesh

__all__ = ["menger_sponge", "sierpinski_tetrahedron"]


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
    n = check_level(level, where)
    s = as_scalar(size, "size", where=where, error=GeometryError)
    if s <= 0.0:
        raise GeometryError(f"{where}: size = {s!r} is not positive; give an edge length > 0")
    check_fractal_memory(
        4**n * (12 * 3 * 8 * 4 + 12 * 8), byte_budget(max_bytes, where), where=where, name="level", value=n
    )
    tet = s * np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, SQRT3 / 2, 0.0], [0.5, SQRT3 / 6, math.sqrt(2 / 3)]])
    tets = tet[None]
    for _ in range(n):
        # corner i keeps vertex i and the midpoints towards the others: (v_i + v_j) / 2
        tets = ((tets[:, :, None, :] + tets[:, None, :, :]) / 2.0).reshape(-1, 4, 3)
    vertices = tets[:, _TETRA_FACES.ravel()].reshape(-1, 3)
    faces = np.arange(vertices.shape[0], dtype=np.int64).reshape(-1, 3)
    return Mesh(vertices, faces)


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


def menger_sponge(level: int, size: float = 1.0, *, shared_vertices: bool = True, max_bytes: int | None = None) -> Mesh:
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
    n = check_level(level, where)
    s = as_scalar(size, "size", where=where, error=GeometryError)
    if s <= 0.0:
        raise GeometryError(f"{where}: size = {s!r} is not positive; give an edge length > 0")
    # working set: cells and keys (20^n·32 B), candidate faces (6·20^n·(4·3·8 + ...)) ~ 1 KiB per cube
    check_fractal_memory(20**n * 1024, byte_budget(max_bytes, where), where=where, name="level", value=n)
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
