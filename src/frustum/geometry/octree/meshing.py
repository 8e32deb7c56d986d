"""Octrees to voxels and to meshes: the exposed finest squares of the full cells on the shared vertex lattice (a
closed, outward-facing mesh), or marching cubes for a smooth surface."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from frustum.budgets import check_memory
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh
from frustum.geometry.octree.codes import (
    check_depth,
    morton_decode,
    morton_encode,
)

if TYPE_CHECKING:
    from frustum.geometry.octree.tree import Octree


def to_voxels(octree: Octree, depth: int | None = None) -> NDArray[np.bool_]:
    """``Octree.to_voxels`` (the method's docstring says what it does)."""
    where = "Octree.to_voxels"
    d = octree.depth if depth is None else check_depth(depth, where)
    n = 2**d
    check_memory(float(n) ** 3, where=where, cause=f"depth = {d}", error=GeometryError)
    grid = np.zeros((1, 1, 1), dtype=bool)
    for level in range(d + 1):
        if level:
            grid = np.repeat(np.repeat(np.repeat(grid, 2, 0), 2, 1), 2, 2)
        if level <= octree.depth and octree.full[level].size:
            ijk = morton_decode(octree.full[level])
            grid[ijk[:, 0], ijk[:, 1], ijk[:, 2]] = True
    return grid


def to_mesh(octree: Octree, smooth: bool = False) -> Mesh:
    """``Octree.to_mesh`` (the method's docstring says what it does)."""
    where = "Octree.to_mesh"
    if smooth:
        from skimage.measure import marching_cubes

        voxels = np.pad(octree.to_voxels(), 1).astype(np.float32)
        if not voxels.any():
            return Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=np.int64))
        verts, faces, _, _ = marching_cubes(voxels, 0.5, method="lewiner", allow_degenerate=False)
        verts = octree.bounds[0] + (verts - 0.5) * octree.cell_size
        # skimage winds faces clockwise seen from the high side of the level: flip for outward normals
        return Mesh(verts, np.ascontiguousarray(faces[:, ::-1], dtype=np.int64))
    squares = octree._exposed_squares(where)  # (Q, 4) lattice corner ids, counter-clockwise from outside
    m1 = 2**octree.depth + 1
    if squares.shape[0] == 0:
        return Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=np.int64))
    unique, inverse = np.unique(squares.ravel(), return_inverse=True)
    ijk = np.stack([unique // (m1 * m1), (unique // m1) % m1, unique % m1], axis=1)
    vertices = octree.bounds[0] + ijk * octree.cell_size
    q = inverse.reshape(-1, 4).astype(np.int64)
    faces = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]], axis=1).reshape(-1, 3)
    return Mesh(vertices, faces)


def exposed_squares(octree: Octree, where: str) -> NDArray[np.int64]:
    """``Octree._exposed_squares`` (the method's docstring says what it does)."""
    d = octree.depth
    m1 = 2**d + 1
    out = []
    for direction in range(6):
        axis, sign = direction // 2, 1 if direction % 2 == 0 else -1
        step = np.zeros(3, dtype=np.int64)
        step[axis] = sign
        # pieces: (level, ijk of the full cell's face piece) whose neighbour across the face is to be examined
        for level in range(d + 1):
            if octree.full[level].size == 0:
                continue
            ijk = morton_decode(octree.full[level])
            lvl = level
            while ijk.shape[0]:
                nb = ijk + step
                outside = ((nb < 0) | (nb >= 2**lvl)).any(axis=1)
                state = np.zeros(ijk.shape[0], dtype=np.int8)
                state[~outside] = octree._state(lvl, morton_encode(nb[~outside]))
                exposed = ijk[state == 0]
                if exposed.shape[0]:
                    out.append(_face_squares(exposed, d - lvl, axis, sign, m1))
                    check_memory(sum(o.size for o in out) * 8.0 * 6, where=where, cause=f"depth = {d}",
                                 error=GeometryError)  # fmt: skip
                split = ijk[state == 2]
                if split.shape[0] == 0 or lvl == d:
                    break
                # the 4 children of each piece on this face
                half = np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)], dtype=np.int64)
                half = half[half[:, axis] == (1 if sign > 0 else 0)]
                ijk = (2 * split[:, None, :] + half[None]).reshape(-1, 3)
                lvl += 1
    return np.concatenate(out) if out else np.empty((0, 4), dtype=np.int64)


def _face_squares(ijk: NDArray[np.int64], levels_down: int, axis: int, sign: int, m1: int) -> NDArray[np.int64]:
    """(Q, 4) lattice keys of the finest squares tiling one face of each cell, counter-clockwise from outside."""
    k = 2**levels_down
    base = ijk * k
    u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3
    uu, vv = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    uu, vv = uu.ravel(), vv.ravel()
    corners = np.zeros((base.shape[0], uu.size, 3), dtype=np.int64)
    corners[:] = base[:, None, :]
    corners[:, :, axis] += k if sign > 0 else 0
    corners[:, :, u_axis] += uu[None]
    corners[:, :, v_axis] += vv[None]
    du = np.zeros(3, dtype=np.int64)
    du[u_axis] = 1
    dv = np.zeros(3, dtype=np.int64)
    dv[v_axis] = 1
    # (u, v, axis) is right-handed: u → v is counter-clockwise seen from +axis
    quad = (
        [np.zeros(3, dtype=np.int64), du, du + dv, dv] if sign > 0 else [np.zeros(3, dtype=np.int64), dv, du + dv, du]
    )
    points = corners.reshape(-1, 1, 3) + np.stack(quad)[None]
    return (points[..., 0] * m1 + points[..., 1]) * m1 + points[..., 2]
