"""The ``Octree`` type: a solid as a linear octree of Morton codes over a cube region, its derived structure and
measures; building, set operations, meshing and ray queries are the sibling modules the methods call."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_points, read_only
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh
from frustum.geometry.octree import build, meshing, operations, rays
from frustum.geometry.octree.codes import (
    EMPTY,
    check_depth,
    contains_codes,
    cube_region,
    morton_decode,
    morton_encode,
    normalized_levels,
    unique_codes,
    without_covered,
)
from frustum.geometry.octree.rays import OctreeHits

__all__ = ["TEXTBOOK_OCTANTS", "Octree"]

TEXTBOOK_OCTANTS = np.array([4, 5, 6, 7, 0, 1, 2, 3], dtype=np.int64)
"""Textbook octant number (front 0–3 toward +z, back 4–7) of each octant ``o = x + 2y + 4z``: ``o XOR 4``."""
TEXTBOOK_OCTANTS.flags.writeable = False


@dataclass(frozen=True, eq=False)
class Octree:
    """A solid as a linear octree over the cube `bounds` down to `depth` levels (see the module docstring).

    Build one with ``from_mesh``, ``from_function``, ``from_voxels``, ``from_points``, ``menger_sponge`` or
    ``sierpinski_tetrahedron``; the constructor takes the canonical arrays directly.

    Parameters
    ----------
    bounds : (2, 3) array_like
        Min and max corner of the region, a cube (equal sides, finite, nonzero).
    depth : int
        Number of subdivisions, 0 … ``MAX_DEPTH``; finest cells have side ``size / 2^depth``.
    full : sequence of depth + 1 uint64 arrays
        Morton codes of the full nodes at each level (normalized on construction: merged, sorted, unique).
    boundary : uint64 array, optional
        Finest-level codes of cells the sampled surface crossed (``volume_bounds``).
    """

    scene_geometry: ClassVar[str] = "octree"
    """What a scene places (``scene.graph`` checks this mark and need not import this module)."""

    bounds: NDArray[np.float64]
    depth: int
    full: tuple[NDArray[np.uint64], ...]
    boundary: NDArray[np.uint64] | None = None

    def __post_init__(self) -> None:
        where = "Octree"
        depth = check_depth(self.depth, where)
        object.__setattr__(self, "depth", depth)
        object.__setattr__(self, "bounds", read_only(cube_region(self.bounds, where, expand=False)))
        if len(self.full) != depth + 1:
            raise GeometryError(
                f"{where}: full has {len(self.full)} levels; expected depth + 1 = {depth + 1} arrays of codes"
            )
        levels = []
        for level, codes in enumerate(self.full):
            array = np.asarray(codes)
            if array.size and (array.dtype.kind not in "ui" or array.ndim != 1):
                raise GeometryError(f"{where}: full[{level}] has dtype {array.dtype}; expected (N,) uint64 codes")
            array = array.astype(np.uint64)
            if array.size and int(array.max()) >= 8**level:
                raise GeometryError(f"{where}: full[{level}] holds a code >= 8^{level}; codes of level l are < 8^l")
            levels.append(array)
        object.__setattr__(self, "full", normalized_levels(without_covered(levels)))
        boundary = EMPTY if self.boundary is None else unique_codes(np.asarray(self.boundary, dtype=np.uint64))
        object.__setattr__(self, "boundary", read_only(boundary))

    # --- derived structure --------------------------------------------------------------------------------

    @property
    def size(self) -> float:
        """Side of the region (world units)."""
        return float(self.bounds[1, 0] - self.bounds[0, 0])

    @property
    def cell_size(self) -> float:
        """Side of a finest cell: ``size / 2^depth``."""
        return self.size / 2**self.depth

    @cached_property
    def partial(self) -> tuple[NDArray[np.uint64], ...]:
        """Morton codes of the partial (heterogeneous) nodes at each level: strict ancestors of full nodes."""
        out = []
        for level in range(self.depth + 1):
            parts = [
                self.full[deeper] >> np.uint64(3 * (deeper - level)) for deeper in range(level + 1, self.depth + 1)
            ]
            out.append(read_only(unique_codes(np.concatenate(parts))) if parts else EMPTY)
        return tuple(out)

    @cached_property
    def level_counts(self) -> NDArray[np.int64]:
        """(depth + 1, 2) int64: the number of full and of partial nodes at each level."""
        return read_only(np.array([[f.size, p.size] for f, p in zip(self.full, self.partial, strict=True)]))

    @property
    def node_count(self) -> int:
        """Full plus partial nodes (empty nodes are implicit)."""
        return int(self.level_counts.sum())

    @property
    def nbytes(self) -> int:
        """Bytes held by the code arrays (full, partial and boundary)."""
        return int(sum(a.nbytes for a in (*self.full, *self.partial, self.boundary)))

    @cached_property
    def full_cell_count(self) -> int:
        """Number of finest cells inside the solid: $Σ_l |full[l]|·8^(depth − l)$."""
        return int(sum(c.size * 8 ** (self.depth - level) for level, c in enumerate(self.full)))

    @property
    def volume(self) -> float:
        """Exact volume of the full cells: $full_cell_count · cell_size³$."""
        return self.full_cell_count * self.cell_size**3

    @property
    def volume_bounds(self) -> tuple[float, float]:
        """(low, high): the volume with every sampled boundary cell counted empty, and counted full."""
        inside = int(np.count_nonzero(self._covered(self.depth, self.boundary))) if self.boundary.size else 0
        cell = self.cell_size**3
        return (self.full_cell_count - inside) * cell, (self.full_cell_count - inside + self.boundary.size) * cell

    @property
    def is_empty(self) -> bool:
        return all(c.size == 0 for c in self.full)

    def __repr__(self) -> str:
        return (
            f"Octree(depth={self.depth}, bounds={self.bounds.tolist()}, "
            f"full_nodes={int(self.level_counts[:, 0].sum())}, "
            f"partial_nodes={int(self.level_counts[:, 1].sum())})"
        )

    def _covered(self, level: int, codes: NDArray[np.uint64]) -> NDArray[np.bool_]:
        """(N,) True where the node (level, code) lies inside a full node (itself or an ancestor)."""
        result = np.zeros(codes.shape, dtype=bool)
        for up in range(level + 1):
            result |= contains_codes(self.full[up], codes >> np.uint64(3 * (level - up)))
        return result

    def _state(self, level: int, codes: NDArray[np.uint64]) -> NDArray[np.int8]:
        """(N,) 1 full, 0 empty, 2 partial for the nodes (level, codes)."""
        state = self._covered(level, codes).astype(np.int8)
        state[(state == 0) & contains_codes(self.partial[level], codes)] = 2
        return state

    def contains(self, points: ArrayLike) -> NDArray[np.bool_]:
        """(N,) bool: True for the points inside a full cell (cells are half-open, the region's far faces closed)."""
        p = as_points(points, where="Octree.contains")
        inside, codes = self._finest_codes(p)
        result = np.zeros(p.shape[0], dtype=bool)
        result[inside] = self._covered(self.depth, codes[inside])
        return result

    def _finest_codes(self, p: NDArray) -> tuple[NDArray[np.bool_], NDArray[np.uint64]]:
        n = 2**self.depth
        scaled = (p - self.bounds[0]) / self.cell_size
        inside = ((scaled >= 0.0) & (scaled <= n)).all(axis=1)
        ijk = np.clip(np.floor(np.where(inside[:, None], scaled, 0.0)), 0, n - 1).astype(np.int64)
        return inside, morton_encode(ijk)

    def leaves(self) -> tuple[NDArray[np.int64], NDArray[np.uint64]]:
        """(levels, codes) of every full node, coarsest first."""
        levels = np.concatenate([np.full(c.size, level, dtype=np.int64) for level, c in enumerate(self.full)])
        return levels, np.concatenate(self.full)

    def leaf_boxes(self) -> NDArray[np.float64]:
        """(N, 2, 3) min and max corner of every full node, in the order of ``leaves``."""
        levels, codes = self.leaves()
        ijk = morton_decode(codes).astype(np.float64)
        side = self.size / 2.0 ** levels.astype(np.float64)
        lo = self.bounds[0] + ijk * side[:, None]
        return np.stack([lo, lo + side[:, None]], axis=1)

    # --- building -----------------------------------------------------------------------------------------

    @classmethod
    def from_voxels(cls, voxels: ArrayLike, bounds: ArrayLike) -> Octree:
        """Octree of a dense (n, n, n) bool array indexed ``[i, j, k]`` = (x, y, z), n = 2^depth.

        Exact: the full cells are the True voxels; eight full siblings merge upward level by level.
        """
        return build.from_voxels(cls, voxels, bounds)

    @classmethod
    def from_points(cls, points: ArrayLike, depth: int, bounds: ArrayLike | None = None) -> Octree:
        """Occupancy: the finest cells holding at least one point are full (`bounds` default: the points'
        bounding cube). Points outside `bounds` are ignored."""
        return build.from_points(cls, points, depth, bounds)

    @classmethod
    def from_function(
        cls, f: Callable[[NDArray, NDArray, NDArray], ArrayLike], bounds: ArrayLike, depth: int
    ) -> Octree:
        """Octree of the implicit solid $f(x, y, z) <= 0$ inside the cube `bounds` (a box is enlarged to a cube
        about its centre), down to `depth` levels.

        Top-down subdivision: `f` is called on whole batches of points (three (N,) float64 arrays, returning
        (N,) values) at the 3 × 3 × 3 lattice of each candidate node (corners, edge and face midpoints,
        centre; a split node's 5 × 5 × 5 lattice gives its 8 children's). A node whose 27 samples are all
        inside is full, all outside empty, otherwise it is split; a mixed finest cell is full when its centre
        is inside and is recorded in ``boundary``. A node is taken as homogeneous from its samples, so features
        thinner than half a node at that level can be missed (exact for convex solids' insides: a cube whose
        corners lie in a convex set lies in it).

        Raises
        ------
        GeometryError
            A bad depth or region, `f` returning the wrong shape or non-finite values, or a depth over the
            memory budget (the estimate names depth).
        """
        return build.from_function(cls, f, bounds, depth)

    @classmethod
    def from_mesh(cls, mesh: Mesh, depth: int, bounds: ArrayLike | None = None, *, shell: bool = False) -> Octree:
        """Octree of the solid a closed mesh bounds (or, with ``shell=True``, of the cells its surface touches).

        Top-down (the per-pair tests in the kernel ``raster.octree.split_pairs``): each node keeps the
        triangles that may touch it (bounding boxes and the triangle's plane against the cube: conservative);
        a node no triangle touches is homogeneous, and it is inside when its reference point (near its centre)
        is: the parent's reference state flipped once per triangle the segment between the two reference
        points crosses (ray parity, [HB 15]). The root's state is the generalized winding number of its
        reference point. A finest cell a triangle touches is full when its reference point is inside and is
        recorded in ``boundary``.

        Parameters
        ----------
        mesh : Mesh
            Closed (watertight after welding) and outward-facing, unless `shell`.
        depth : int
            Levels of subdivision, 0 … ``MAX_DEPTH``.
        bounds : (2, 3) array_like, optional
            The region; default the mesh's bounding box enlarged to a cube about its centre.
        shell : bool
            True: a surface octree, the finest cells any triangle touches (open meshes allowed).

        Raises
        ------
        GeometryError
            An open mesh without ``shell=True`` (the message gives its boundary edge count), an empty mesh,
            a bad depth or region, or a depth over the memory budget.
        """
        return build.from_mesh(cls, mesh, depth, bounds, shell=shell)

    @classmethod
    def menger_sponge(cls, level: int, size: float = 1.0) -> Octree:
        """The Menger sponge of `level` on [0, size]³ as an exact octree: finest cells of side size / 3^level.

        depth = ⌈log2 3^level⌉ and the region is [0, size·2^depth / 3^level]³, so the sponge's 20^level cubes
        are finest cells (the rest of the region is empty).
        """
        return build.menger_sponge(cls, level, size)

    @classmethod
    def sierpinski_tetrahedron(cls, level: int, size: float = 1.0) -> Octree:
        """The Sierpinski tetrahedron as an exact octree: keep octants 0, 3, 5, 6 (the corners (0,0,0), (1,1,0),
        (1,0,1), (0,1,1) of a regular tetrahedron inscribed in the cube) `level` times; 4^level full cells of
        side size / 2^level on [0, size]³ (D = log 4 / log 2 = 2)."""
        return build.sierpinski_tetrahedron(cls, level, size)

    # --- set operations -----------------------------------------------------------------------------------

    def complement(self) -> Octree:
        """The region minus the solid: the children of partial nodes that are neither full nor partial."""
        return operations.complement(self)

    def union(self, other: Octree) -> Octree:
        """``A ∪ B`` by simultaneous traversal of two octrees of the same region (depth: the larger).

        Full nodes of both, those inside a full node of the other dropped, eight full siblings merged: the
        canonical tree. Exact on the cells; see ``shifted`` (exact) and ``transformed`` (resamples) for moves.
        """
        return operations.union(self, other)

    def intersection(self, other: Octree) -> Octree:
        """$A ∩ B = ¬(¬A ∪ ¬B)$ (De Morgan within the region), canonical."""
        return operations.intersection(self, other)

    def difference(self, other: Octree) -> Octree:
        """$A − B = A ∩ ¬B$, canonical."""
        return operations.difference(self, other)

    __or__ = union
    __and__ = intersection
    __sub__ = difference

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Octree):
            return NotImplemented
        return (
            self.depth == other.depth
            and np.array_equal(self.bounds, other.bounds)
            and all(np.array_equal(x, y) for x, y in zip(self.full, other.full, strict=True))
        )

    __hash__ = None  # type: ignore[assignment]

    def refined(self, depth: int) -> Octree:
        """The same solid with `depth` >= self.depth levels (the cells are the same; finer ones are allowed)."""
        return operations.refined(self, depth)

    def shifted(self, cells: ArrayLike) -> Octree:
        """The solid moved by whole finest cells ``(di, dj, dk)``: exact (cells leaving the region are dropped).

        A node whose side divides the offset moves as a whole; others are split into their children first.
        """
        return operations.shifted(self, cells)

    def transformed(self, matrix: ArrayLike) -> Octree:
        """The solid mapped by an affine `matrix` (4x4) into the same region, **resampled**: a finest cell of the
        result is full when its centre, mapped back by the inverse, lies in a full cell (not exact in general;
        a move by whole cells gives ``shifted``'s cells). Work grows with the mapped volume in finest cells."""
        return operations.transformed(self, matrix)

    # --- conversions --------------------------------------------------------------------------------------

    def to_voxels(self, depth: int | None = None) -> NDArray[np.bool_]:
        """Dense (n, n, n) bool array, n = 2^depth, indexed ``[i, j, k]`` = (x, y, z): True in full cells.

        For `depth` below the octree's, a coarse cell is True when it lies entirely inside the solid.
        """
        return meshing.to_voxels(self, depth)

    def to_mesh(self, smooth: bool = False) -> Mesh:
        """The surface of the solid as a closed, outward-facing triangle mesh.

        ``smooth=False``: the faces of full cells with the faces shared by two full cells removed, cut into
        finest-cell squares (two triangles each) on the shared vertex lattice, so the mesh is watertight.
        ``smooth=True``: scikit-image marching cubes at level 0.5 on the (padded) voxel array, scaled to the
        region (vertices at cell centres' lattice).
        """
        return meshing.to_mesh(self, smooth)

    def _exposed_squares(self, where: str) -> NDArray[np.int64]:
        """(Q, 4) lattice-point keys $(i·m1 + j)·m1 + k$ of every exposed finest square of full cells."""
        return meshing.exposed_squares(self, where)

    # --- ray queries --------------------------------------------------------------------------------------

    @cached_property
    def surface(self) -> Mesh:
        """``to_mesh()``, computed once: the cell faces a scene draws by the depth buffer."""
        return self.to_mesh()

    @cached_property
    def _surface_index(self) -> tuple[Mesh, Any]:
        from frustum.raster import rays

        mesh = self.surface
        return mesh, (rays.build(np.asarray(mesh.vertices[mesh.faces], dtype=np.float64)) if mesh.face_count else None)

    def ray_hits(self, origins: ArrayLike, directions: ArrayLike) -> OctreeHits:
        """First hit of each ray $origin + t·direction$ (t >= 0) on the solid: distance, point and full leaf.

        The rays are traced against the exposed cell faces (``to_mesh``) through a bounding-volume hierarchy
        (``raster.rays``, the index of ``Scene.intersect``); a ray starting inside a full cell hits at t = 0.
        Distances are in units of the direction's length.

        Parameters
        ----------
        origins, directions : (N, 3) or (3,) array_like
            Finite; directions nonzero.
        """
        return rays.ray_hits(self, origins, directions)

    def _leaf_of(self, points: NDArray) -> tuple[NDArray[np.int64], NDArray[np.uint64]]:
        """Level and code of the full node holding each point (−1, 0 where none)."""
        return rays.leaf_of(self, points)
