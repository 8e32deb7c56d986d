"""Octrees: solids as linear octrees of Morton codes, their set operations, measures and conversions.

The region is a cube $bounds = (min_corner, max_corner)$ cut `depth` times in halves along x, y and z; a
node at level l (0 = the whole region, `depth` = the finest cells) is one of ``8^l`` cubes of side
``size / 2^l``. Every node is **full** (inside the solid), **empty** (the textbook's "void") or **partial**
(heterogeneous: subdivided into eight children). Finest cells are full or empty.

Storage is array-based, no Python object per node: ``full[l]`` is the sorted ``uint64`` array of the Morton
codes of the maximal full nodes at level l; the partial nodes (every strict ancestor of a full node that is not
itself covered) are derived from it. A node's Morton code interleaves the bits of its integer coordinates
``(i, j, k)`` (x, y, z, each in ``[0, 2^l)``), x in the lowest bit, so the child of code c in octant o is
$8·c + o$ with $o = x + 2y + 4z$ (x, y, z ∈ {0, 1} the child's halves). The tree is canonical: eight full
siblings are always merged into their full parent, so equal sets give identical arrays.

**Octant numbering.** The textbook [HB 15, "Octrees"] numbers the octants of a node 0–3 in the front
(the half toward a viewer on +z) and 4–7 in the back, each face counted like a quadrant: 0 = (x low, y low),
1 = (x high, y low), 2 = (x low, y high), 3 = (x high, y high). So textbook $t = x + 2y + 4(1 − z)$ and
$o = t XOR 4$ (``TEXTBOOK_OCTANTS[o]`` is t).

Besides the full cells an octree built by sampling keeps ``boundary``: the finest cells the surface crossed
(mixed samples, or a triangle touching the cell); their state was decided by one sample near the cell's
centre. ``volume_bounds`` counts them as empty and as full.

Why one module: every operation works on the one Morton-code representation and its helpers.

References
----------
[HB 15] "Octrees" (octree encoding, set operations by simultaneous traversal); [HB 16] "Octree Methods"
(visible surfaces); [seed] "General modeling techniques: octrees".
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, as_points, as_scalar, describe, read_only
from frustum.budgets import check_memory, check_operations
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh

__all__ = ["MAX_DEPTH", "TEXTBOOK_OCTANTS", "Octree", "OctreeHits"]

MAX_DEPTH = 20
"""Deepest octree: 3·20 = 60 bits of Morton code (a 2^20 = 1,048,576 cells wide grid)."""
TEXTBOOK_OCTANTS = np.array([4, 5, 6, 7, 0, 1, 2, 3], dtype=np.int64)
"""Textbook octant number (front 0–3 toward +z, back 4–7) of each octant ``o = x + 2y + 4z``: ``o XOR 4``."""
TEXTBOOK_OCTANTS.flags.writeable = False

_EMPTY = np.empty(0, dtype=np.uint64)
_EMPTY.flags.writeable = False
_CHUNK = 1 << 18  # cells per batch of samples / triangle tests (bounded working memory)
# generic offset of a cell's reference point from its centre, in cell sides: keeps parity segments off the
# dyadic planes where cell-aligned geometry lies
_REFERENCE = np.array([0.0731, 0.1193, 0.0437])

# --- Morton codes -----------------------------------------------------------------------------------------


def _spread(v: NDArray) -> NDArray[np.uint64]:
    """Bits b0 b1 b2 … of each value to positions 0, 3, 6, … (values < 2^21)."""
    x = v.astype(np.uint64) & np.uint64(0x1FFFFF)
    x = (x | (x << np.uint64(32))) & np.uint64(0x1F00000000FFFF)
    x = (x | (x << np.uint64(16))) & np.uint64(0x1F0000FF0000FF)
    x = (x | (x << np.uint64(8))) & np.uint64(0x100F00F00F00F00F)
    x = (x | (x << np.uint64(4))) & np.uint64(0x10C30C30C30C30C3)
    x = (x | (x << np.uint64(2))) & np.uint64(0x1249249249249249)
    return x


def _compact(x: NDArray[np.uint64]) -> NDArray[np.int64]:
    x = x & np.uint64(0x1249249249249249)
    x = (x ^ (x >> np.uint64(2))) & np.uint64(0x10C30C30C30C30C3)
    x = (x ^ (x >> np.uint64(4))) & np.uint64(0x100F00F00F00F00F)
    x = (x ^ (x >> np.uint64(8))) & np.uint64(0x1F0000FF0000FF)
    x = (x ^ (x >> np.uint64(16))) & np.uint64(0x1F00000000FFFF)
    x = (x ^ (x >> np.uint64(32))) & np.uint64(0x1FFFFF)
    return x.astype(np.int64)


def morton_encode(ijk: ArrayLike) -> NDArray[np.uint64]:
    """(N,) uint64 Morton codes of (N, 3) integer cell coordinates (i, j, k), x in the lowest bit."""
    a = np.asarray(ijk, dtype=np.int64).reshape(-1, 3)
    return _spread(a[:, 0]) | (_spread(a[:, 1]) << np.uint64(1)) | (_spread(a[:, 2]) << np.uint64(2))


def morton_decode(codes: ArrayLike) -> NDArray[np.int64]:
    """(N, 3) int64 cell coordinates (i, j, k) of (N,) uint64 Morton codes."""
    c = np.asarray(codes, dtype=np.uint64).ravel()
    return np.stack([_compact(c), _compact(c >> np.uint64(1)), _compact(c >> np.uint64(2))], axis=1)


def _unique(values: ArrayLike) -> NDArray[np.uint64]:
    """Sorted unique uint64 codes (sort + compare: numpy's hashed ``unique`` was 10x slower here)."""
    a = np.sort(np.asarray(values, dtype=np.uint64).ravel())
    return a[np.r_[True, a[1:] != a[:-1]]] if a.size else a


def _contains(sorted_codes: NDArray[np.uint64], codes: NDArray[np.uint64]) -> NDArray[np.bool_]:
    if sorted_codes.size == 0 or codes.size == 0:
        return np.zeros(codes.shape, dtype=bool)
    pos = np.minimum(np.searchsorted(sorted_codes, codes), sorted_codes.size - 1)
    return sorted_codes[pos] == codes


def _children(codes: NDArray[np.uint64]) -> NDArray[np.uint64]:
    """(8N,) codes of the children of each code, in octant order ``x + 2y + 4z`` (sorted if `codes` is)."""
    return ((codes[:, None] << np.uint64(3)) | np.arange(8, dtype=np.uint64)[None, :]).ravel()


def _normalized(levels: list[NDArray[np.uint64]]) -> tuple[NDArray[np.uint64], ...]:
    """Canonical form of disjoint full nodes per level: sorted, unique, and every 8 full siblings merged."""
    out = [_unique(np.asarray(codes, dtype=np.uint64)) for codes in levels]
    for level in range(len(out) - 1, 0, -1):
        codes = out[level]
        if codes.size < 8:
            continue
        parents = codes >> np.uint64(3)
        starts = np.flatnonzero(np.r_[True, parents[1:] != parents[:-1]])
        counts = np.diff(np.r_[starts, parents.size])
        whole = parents[starts[counts == 8]]
        if whole.size:
            out[level] = codes[~_contains(whole, parents)]
            out[level - 1] = _unique(np.concatenate([out[level - 1], whole]))
    return tuple(read_only(np.ascontiguousarray(c, dtype=np.uint64)) for c in out)


class OctreeHits(NamedTuple):
    """First hits of rays on an octree: ``hit`` (N,) bool, ``distance`` (N,) (inf on a miss), ``point`` (N, 3)
    world point (NaN on a miss), ``level`` and ``code`` (N,) of the full leaf hit (−1 and 0 on a miss)."""

    hit: NDArray[np.bool_]
    distance: NDArray[np.float64]
    point: NDArray[np.float64]
    level: NDArray[np.int64]
    code: NDArray[np.uint64]


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

    bounds: NDArray[np.float64]
    depth: int
    full: tuple[NDArray[np.uint64], ...]
    boundary: NDArray[np.uint64] | None = None

    def __post_init__(self) -> None:
        where = "Octree"
        depth = _depth(self.depth, where)
        object.__setattr__(self, "depth", depth)
        object.__setattr__(self, "bounds", read_only(_cube(self.bounds, where, expand=False)))
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
        object.__setattr__(self, "full", _normalized(_without_covered(levels)))
        boundary = _EMPTY if self.boundary is None else _unique(np.asarray(self.boundary, dtype=np.uint64))
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
            out.append(read_only(_unique(np.concatenate(parts))) if parts else _EMPTY)
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
            result |= _contains(self.full[up], codes >> np.uint64(3 * (level - up)))
        return result

    def _state(self, level: int, codes: NDArray[np.uint64]) -> NDArray[np.int8]:
        """(N,) 1 full, 0 empty, 2 partial for the nodes (level, codes)."""
        state = self._covered(level, codes).astype(np.int8)
        state[(state == 0) & _contains(self.partial[level], codes)] = 2
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
        where = "Octree.from_voxels"
        try:
            array = np.asarray(voxels)
        except ValueError:
            raise GeometryError(
                f"{where}: voxels = {describe(voxels)} is not an array; give an (n, n, n) bool array"
            ) from None
        n = array.shape[0] if array.ndim == 3 else 0
        if array.ndim != 3 or array.shape != (n, n, n) or n < 1 or n & (n - 1):
            raise GeometryError(
                f"{where}: voxels has shape {array.shape}; expected (n, n, n) with n a power of two (2^depth)"
            )
        if array.dtype != np.bool_:
            raise GeometryError(f"{where}: voxels has dtype {array.dtype}; expected bool (True inside)")
        depth = n.bit_length() - 1
        _depth(depth, where)
        region = _cube(bounds, where, expand=False)
        grids = [array]
        for _ in range(depth):  # a node is full when its 8 children are
            g = grids[-1]
            m = g.shape[0] // 2
            grids.append(g.reshape(m, 2, m, 2, m, 2).all(axis=(1, 3, 5)))
        grids.reverse()  # grids[l] is level l
        levels = []
        for level, grid in enumerate(grids):
            maximal = (
                grid if level == 0 else grid & ~np.repeat(np.repeat(np.repeat(grids[level - 1], 2, 0), 2, 1), 2, 2)
            )
            levels.append(np.sort(morton_encode(np.argwhere(maximal))))
        return cls(region, depth, tuple(levels))

    @classmethod
    def from_points(cls, points: ArrayLike, depth: int, bounds: ArrayLike | None = None) -> Octree:
        """Occupancy: the finest cells holding at least one point are full (`bounds` default: the points'
        bounding cube). Points outside `bounds` are ignored."""
        where = "Octree.from_points"
        p = as_points(points, where=where)
        d = _depth(depth, where)
        if bounds is None:
            if p.shape[0] == 0:
                raise GeometryError(f"{where}: points is empty and bounds is None; give points or bounds")
            region = _cube(np.array([p.min(axis=0), p.max(axis=0)]), where, expand=True)
        else:
            region = _cube(bounds, where, expand=False)
        check_memory(p.shape[0] * 48.0, where=where, cause=f"{p.shape[0]} points", error=GeometryError)
        empty = cls(region, d, tuple(_EMPTY for _ in range(d + 1)))
        inside, codes = empty._finest_codes(p)
        levels = [_EMPTY] * d + [_unique(codes[inside])]
        return cls(region, d, tuple(levels))

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
        where = "Octree.from_function"
        if not callable(f):
            raise GeometryError(f"{where}: f = {describe(f)} is not callable; give f(x, y, z) -> values")
        d = _depth(depth, where)
        region = _cube(bounds, where, expand=True)
        _check_surface_budget(d, where)
        size = float(region[1, 0] - region[0, 0])
        fine = np.stack(np.meshgrid(*[np.arange(5)] * 3, indexing="ij"), axis=-1).reshape(-1, 3) * 0.25
        # the 3 x 3 x 3 lattice of child o = (x, y, z) is the block [2x:2x+3, 2y:2y+3, 2z:2z+3] of its parent's 5^3
        blocks = np.array([[((2 * (o & 1) + a) * 5 + 2 * ((o >> 1) & 1) + b) * 5 + 2 * ((o >> 2) & 1) + c
                            for a in range(3) for b in range(3) for c in range(3)] for o in range(8)])  # fmt: skip

        def children_samples(level: int, codes: NDArray[np.uint64]) -> NDArray[np.bool_]:
            """(8N, 27) inside flags at the lattices of the children of each node, from its 5 x 5 x 5 lattice."""
            out = np.empty((codes.size, 8, 27), dtype=bool)
            side = size / 2**level
            step = _CHUNK // 125 + 1
            for start in range(0, codes.size, step):
                chunk = codes[start : start + step]
                lo = region[0] + morton_decode(chunk) * side
                pts = (lo[:, None, :] + fine[None] * side).reshape(-1, 3)
                out[start : start + chunk.size] = _evaluate(f, pts, where).reshape(-1, 125)[:, blocks]
            return out.reshape(-1, 27)

        levels: list[NDArray[np.uint64]] = []
        boundary = _EMPTY
        candidates = np.zeros(1, dtype=np.uint64)
        root = np.stack(np.meshgrid(*[np.arange(3)] * 3, indexing="ij"), axis=-1).reshape(-1, 3) * 0.5
        inside = _evaluate(f, region[0] + root * size, where)[None]  # (1, 27) at the root's lattice
        for level in range(d + 1):
            all_in, any_in = inside.all(axis=1), inside.any(axis=1)
            mixed = any_in & ~all_in
            if level == d:
                boundary = candidates[mixed]
                levels.append(candidates[all_in | (mixed & inside[:, 13])])  # 13: the centre sample
                break
            levels.append(candidates[all_in])
            check_memory(mixed.sum() * 125 * 32.0, where=where, cause=f"depth = {d}", error=GeometryError)
            inside = children_samples(level, candidates[mixed])
            candidates = _children(candidates[mixed])
        levels += [_EMPTY] * (d + 1 - len(levels))
        return cls(region, d, tuple(levels), boundary)

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
        from frustum.raster import octree as kernels

        where = "Octree.from_mesh"
        if not isinstance(mesh, Mesh):
            raise GeometryError(f"{where}: mesh = {describe(mesh)} is not a Mesh; give a frustum Mesh")
        d = _depth(depth, where)
        if mesh.face_count == 0:
            raise GeometryError(f"{where}: mesh has 0 faces; give a mesh with triangles")
        if not isinstance(shell, bool):
            raise GeometryError(f"{where}: shell = {describe(shell)} is not a bool; give True or False")
        solid = mesh.welded()
        if not shell and not solid.is_watertight:
            open_edges = _boundary_edge_count(solid.faces)
            raise GeometryError(
                f"{where}: mesh is open ({open_edges} boundary edges) or not consistently wound; the inside of a "
                "solid needs a closed mesh: close its holes, or give shell=True for the cells its surface touches"
            )
        if bounds is None:
            region = _cube(np.array([solid.vertices.min(axis=0), solid.vertices.max(axis=0)]), where, expand=True)
        else:
            region = _cube(bounds, where, expand=False)
        _check_surface_budget(d, where, faces=solid.face_count)
        corners = np.ascontiguousarray(solid.vertices[solid.faces], dtype=np.float64)  # (F, 3, 3)
        size = float(region[1, 0] - region[0, 0])
        cell_pairs = np.zeros(solid.face_count, dtype=np.uint64)  # (cell code, triangle) pairs of this level
        triangle_ids = np.arange(solid.face_count, dtype=np.int64)
        keep = _triangle_touches_box(corners, region[0], size)
        cell_pairs, triangle_ids = cell_pairs[keep], triangle_ids[keep]
        root_reference = region[0] + (0.5 + _REFERENCE) * size
        root_inside = False if shell else bool(abs(_winding_number(corners, root_reference[None])[0]) > 0.5)
        partial = np.zeros(1, dtype=np.uint64) if cell_pairs.size else _EMPTY
        partial_inside = np.array([root_inside]) if cell_pairs.size else np.zeros(0, dtype=bool)
        levels: list[NDArray[np.uint64]] = [np.zeros(1, dtype=np.uint64) if (root_inside and not cell_pairs.size)
                                            else _EMPTY]  # fmt: skip
        boundary = _EMPTY
        if d == 0 and cell_pairs.size:
            levels = [np.zeros(1, dtype=np.uint64) if (root_inside or shell) else _EMPTY]
            boundary = np.zeros(1, dtype=np.uint64)
        for level in range(1, d + 1):
            if partial.size == 0:
                levels.append(_EMPTY)
                continue
            side = size / 2**level
            children = _children(partial)
            # child reference state: parent's, flipped per crossing of the segment parent ref → child ref
            child_inside = np.repeat(partial_inside, 8)
            parent_of_pair = np.searchsorted(partial, cell_pairs)
            check_memory(cell_pairs.size * 8 * 24.0, where=where, cause=f"depth = {d}", error=GeometryError)
            parent_lo = region[0] + morton_decode(cell_pairs) * (2 * side)
            touches = np.empty((cell_pairs.size, 8), dtype=bool)
            crossings = np.empty((cell_pairs.size, 8), dtype=bool)
            kernels.split_pairs(corners, triangle_ids, parent_lo, side, _REFERENCE, not shell, touches, crossings)
            if not shell:
                slots = (parent_of_pair[:, None] * 8 + np.arange(8)[None]).ravel()
                flips = np.bincount(slots[crossings.ravel()], minlength=8 * partial.size) & 1
                child_inside ^= flips.astype(bool)
            child_codes = (cell_pairs[:, None] << np.uint64(3)) | np.arange(8, dtype=np.uint64)[None]
            pair_codes = child_codes[touches]
            pair_triangles = np.broadcast_to(triangle_ids[:, None], touches.shape)[touches]
            order = np.argsort(pair_codes, kind="stable")
            cell_pairs, triangle_ids = pair_codes[order], pair_triangles[order]
            touched = _unique(cell_pairs)
            is_touched = _contains(touched, children)
            if shell:
                child_inside[:] = False
            if level == d:
                boundary = touched
                levels.append(children[is_touched] if shell else children[child_inside])
                break
            levels.append(children[child_inside & ~is_touched])
            partial, partial_inside = children[is_touched], child_inside[is_touched]
        levels += [_EMPTY] * (d + 1 - len(levels))
        return cls(region, d, tuple(levels), boundary)

    @classmethod
    def menger_sponge(cls, level: int, size: float = 1.0) -> Octree:
        """The Menger sponge of `level` on [0, size]³ as an exact octree: finest cells of side size / 3^level.

        depth = ⌈log2 3^level⌉ and the region is [0, size·2^depth / 3^level]³, so the sponge's 20^level cubes
        are finest cells (the rest of the region is empty).
        """
        from frustum.geometry.fractals import _menger_cells

        where = "Octree.menger_sponge"
        n = as_count(level, "level", 0, where=where)
        s = as_scalar(size, "size", where=where, error=GeometryError)
        if not s > 0.0:
            raise GeometryError(f"{where}: size = {s!r} is not positive; give an edge length > 0")
        d = (3**n - 1).bit_length() if n else 0
        _depth(d, where)
        check_memory(20**n * 64.0, where=where, cause=f"level = {n}", error=GeometryError)
        cells = _menger_cells(n)
        side = s * 2**d / 3**n
        region = np.array([[0.0, 0.0, 0.0], [side, side, side]])
        return cls(region, d, tuple([_EMPTY] * d + [np.sort(morton_encode(cells))]))

    @classmethod
    def sierpinski_tetrahedron(cls, level: int, size: float = 1.0) -> Octree:
        """The Sierpinski tetrahedron as an exact octree: keep octants 0, 3, 5, 6 (the corners (0,0,0), (1,1,0),
        (1,0,1), (0,1,1) of a regular tetrahedron inscribed in the cube) `level` times; 4^level full cells of
        side size / 2^level on [0, size]³ (D = log 4 / log 2 = 2)."""
        where = "Octree.sierpinski_tetrahedron"
        n = _depth(as_count(level, "level", 0, where=where), where)
        s = as_scalar(size, "size", where=where, error=GeometryError)
        if not s > 0.0:
            raise GeometryError(f"{where}: size = {s!r} is not positive; give an edge length > 0")
        check_memory(4**n * 64.0, where=where, cause=f"level = {n}", error=GeometryError)
        codes = np.zeros(1, dtype=np.uint64)
        keep = np.array([0, 3, 5, 6], dtype=np.uint64)
        for _ in range(n):
            codes = ((codes[:, None] << np.uint64(3)) | keep[None]).ravel()
        return cls(np.array([[0.0] * 3, [s] * 3]), n, tuple([_EMPTY] * n + [np.sort(codes)]))

    # --- set operations -----------------------------------------------------------------------------------

    def complement(self) -> Octree:
        """The region minus the solid: the children of partial nodes that are neither full nor partial."""
        if self.is_empty:
            return Octree(
                self.bounds, self.depth, (np.zeros(1, dtype=np.uint64), *[_EMPTY] * self.depth), self.boundary
            )
        levels = [_EMPTY]
        for level in range(1, self.depth + 1):
            children = _children(self.partial[level - 1])
            keep = ~_contains(self.full[level], children) & ~_contains(self.partial[level], children)
            levels.append(children[keep])
        return Octree(self.bounds, self.depth, tuple(levels), self.boundary)

    def union(self, other: Octree) -> Octree:
        """``A ∪ B`` by simultaneous traversal of two octrees of the same region (depth: the larger).

        Full nodes of both, those inside a full node of the other dropped, eight full siblings merged: the
        canonical tree. Exact on the cells; see ``shifted`` (exact) and ``transformed`` (resamples) for moves.
        """
        a, b = _same_region(self, other, "Octree.union")
        levels = [np.concatenate([a.full[level], b.full[level]]) for level in range(a.depth + 1)]
        return Octree(a.bounds, a.depth, tuple(levels), _unique(np.concatenate([a.boundary, b.boundary])))

    def intersection(self, other: Octree) -> Octree:
        """$A ∩ B = ¬(¬A ∪ ¬B)$ (De Morgan within the region), canonical."""
        a, b = _same_region(self, other, "Octree.intersection")
        return a.complement().union(b.complement()).complement()

    def difference(self, other: Octree) -> Octree:
        """$A − B = A ∩ ¬B$, canonical."""
        a, b = _same_region(self, other, "Octree.difference")
        return a.intersection(b.complement())

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
        d = _depth(depth, "Octree.refined")
        if d < self.depth:
            raise GeometryError(f"Octree.refined: depth = {d} is below the octree's {self.depth}; give >= {self.depth}")
        boundary = _descendants(self.boundary, 3 * (d - self.depth))
        return Octree(self.bounds, d, (*self.full, *[_EMPTY] * (d - self.depth)), boundary)

    def shifted(self, cells: ArrayLike) -> Octree:
        """The solid moved by whole finest cells ``(di, dj, dk)``: exact (cells leaving the region are dropped).

        A node whose side divides the offset moves as a whole; others are split into their children first.
        """
        where = "Octree.shifted"
        offset = np.asarray(cells)
        if offset.shape != (3,) or offset.dtype.kind not in "iu":
            raise GeometryError(f"{where}: cells = {describe(cells)} is not 3 integers; give (di, dj, dk) in cells")
        offset = offset.astype(np.int64)
        d = self.depth
        out: list[list[NDArray]] = [[] for _ in range(d + 1)]
        pending = [np.asarray(c) for c in self.full]
        for level in range(d + 1):
            codes = pending[level]
            if codes.size == 0:
                continue
            step = 2 ** (d - level)
            if (offset % step == 0).all():
                ijk = morton_decode(codes) + offset // step
                ok = ((ijk >= 0) & (ijk < 2**level)).all(axis=1)
                out[level].append(morton_encode(ijk[ok]))
            else:
                pending[level + 1] = np.concatenate([pending[level + 1], _children(codes)])
        levels = [np.concatenate(parts) if parts else _EMPTY for parts in out]
        if self.boundary.size:
            ijk = morton_decode(self.boundary) + offset
            ok = ((ijk >= 0) & (ijk < 2**d)).all(axis=1)
            boundary = morton_encode(ijk[ok])
        else:
            boundary = _EMPTY
        return Octree(self.bounds, d, tuple(levels), boundary)

    def transformed(self, matrix: ArrayLike) -> Octree:
        """The solid mapped by an affine `matrix` (4x4) into the same region, **resampled**: a finest cell of the
        result is full when its centre, mapped back by the inverse, lies in a full cell (not exact in general;
        a move by whole cells gives ``shifted``'s cells). Work grows with the mapped volume in finest cells."""
        from frustum._arrays import as_matrix

        where = "Octree.transformed"
        m = as_matrix(matrix, where=where, error=GeometryError)
        if abs(np.linalg.det(m[:3, :3])) < 1e-12:
            raise GeometryError(f"{where}: matrix is singular (det of its 3x3 part ~ 0); give an invertible map")
        inverse = np.linalg.inv(m)
        n, cell = 2**self.depth, self.cell_size
        boxes = self.leaf_boxes()
        corners = boxes[:, [0, 1]][:, np.array([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)]), [0, 1, 2]]
        image = corners @ m[:3, :3].T + m[:3, 3]
        lo = np.clip(np.floor((image.min(axis=1) - self.bounds[0]) / cell - 0.5), 0, n - 1).astype(np.int64)
        hi = np.clip(np.ceil((image.max(axis=1) - self.bounds[0]) / cell - 0.5), 0, n - 1).astype(np.int64)
        total = float(np.prod(hi - lo + 1, axis=1).sum())
        check_memory(total * 64.0, where=where, cause=f"depth = {self.depth} ({total:.3g} candidate cells)",
                     error=GeometryError)  # fmt: skip
        found = []
        for a, b in zip(lo, hi, strict=True):
            ijk = np.stack(np.meshgrid(*[np.arange(a[i], b[i] + 1) for i in range(3)], indexing="ij"), -1).reshape(
                -1, 3
            )
            centres = self.bounds[0] + (ijk + 0.5) * cell
            keep = self.contains(centres @ inverse[:3, :3].T + inverse[:3, 3])
            found.append(morton_encode(ijk[keep]))
        codes = _unique(np.concatenate(found)) if found else _EMPTY
        return Octree(self.bounds, self.depth, tuple([_EMPTY] * self.depth + [codes]))

    # --- conversions --------------------------------------------------------------------------------------

    def to_voxels(self, depth: int | None = None) -> NDArray[np.bool_]:
        """Dense (n, n, n) bool array, n = 2^depth, indexed ``[i, j, k]`` = (x, y, z): True in full cells.

        For `depth` below the octree's, a coarse cell is True when it lies entirely inside the solid.
        """
        where = "Octree.to_voxels"
        d = self.depth if depth is None else _depth(depth, where)
        n = 2**d
        check_memory(float(n) ** 3, where=where, cause=f"depth = {d}", error=GeometryError)
        grid = np.zeros((1, 1, 1), dtype=bool)
        for level in range(d + 1):
            if level:
                grid = np.repeat(np.repeat(np.repeat(grid, 2, 0), 2, 1), 2, 2)
            if level <= self.depth and self.full[level].size:
                ijk = morton_decode(self.full[level])
                grid[ijk[:, 0], ijk[:, 1], ijk[:, 2]] = True
        return grid

    def to_mesh(self, smooth: bool = False) -> Mesh:
        """The surface of the solid as a closed, outward-facing triangle mesh.

        ``smooth=False``: the faces of full cells with the faces shared by two full cells removed, cut into
        finest-cell squares (two triangles each) on the shared vertex lattice, so the mesh is watertight.
        ``smooth=True``: scikit-image marching cubes at level 0.5 on the (padded) voxel array, scaled to the
        region (vertices at cell centres' lattice).
        """
        where = "Octree.to_mesh"
        if smooth:
            from skimage.measure import marching_cubes

            voxels = np.pad(self.to_voxels(), 1).astype(np.float32)
            if not voxels.any():
                return Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=np.int64))
            verts, faces, _, _ = marching_cubes(voxels, 0.5, method="lewiner", allow_degenerate=False)
            verts = self.bounds[0] + (verts - 0.5) * self.cell_size
            # skimage winds faces clockwise seen from the high side of the level: flip for outward normals
            return Mesh(verts, np.ascontiguousarray(faces[:, ::-1], dtype=np.int64))
        squares = self._exposed_squares(where)  # (Q, 4) lattice corner ids, counter-clockwise from outside
        m1 = 2**self.depth + 1
        if squares.shape[0] == 0:
            return Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=np.int64))
        unique, inverse = np.unique(squares.ravel(), return_inverse=True)
        ijk = np.stack([unique // (m1 * m1), (unique // m1) % m1, unique % m1], axis=1)
        vertices = self.bounds[0] + ijk * self.cell_size
        q = inverse.reshape(-1, 4).astype(np.int64)
        faces = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]], axis=1).reshape(-1, 3)
        return Mesh(vertices, faces)

    def _exposed_squares(self, where: str) -> NDArray[np.int64]:
        """(Q, 4) lattice-point keys $(i·m1 + j)·m1 + k$ of every exposed finest square of full cells."""
        d = self.depth
        m1 = 2**d + 1
        out = []
        for direction in range(6):
            axis, sign = direction // 2, 1 if direction % 2 == 0 else -1
            step = np.zeros(3, dtype=np.int64)
            step[axis] = sign
            # pieces: (level, ijk of the full cell's face piece) whose neighbour across the face is to be examined
            for level in range(d + 1):
                if self.full[level].size == 0:
                    continue
                ijk = morton_decode(self.full[level])
                lvl = level
                while ijk.shape[0]:
                    nb = ijk + step
                    outside = ((nb < 0) | (nb >= 2**lvl)).any(axis=1)
                    state = np.zeros(ijk.shape[0], dtype=np.int8)
                    state[~outside] = self._state(lvl, morton_encode(nb[~outside]))
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

    # --- ray queries --------------------------------------------------------------------------------------

    @cached_property
    def surface(self) -> Mesh:
        """``to_mesh()``, computed once: the cell faces a scene draws by the depth buffer."""
        return self.to_mesh()

    @cached_property
    def _surface_index(self) -> tuple[Mesh, Any]:
        from frustum.raster import bvh

        mesh = self.surface
        return mesh, (bvh.build(np.asarray(mesh.vertices[mesh.faces], dtype=np.float64)) if mesh.face_count else None)

    def ray_hits(self, origins: ArrayLike, directions: ArrayLike) -> OctreeHits:
        """First hit of each ray $origin + t·direction$ (t >= 0) on the solid: distance, point and full leaf.

        The rays are traced against the exposed cell faces (``to_mesh``) through a bounding-volume hierarchy
        (``raster.bvh``); a ray starting inside a full cell hits at t = 0. Distances are in units of the
        direction's length.

        Parameters
        ----------
        origins, directions : (N, 3) or (3,) array_like
            Finite; directions nonzero.
        """
        where = "Octree.ray_hits"
        single = np.shape(origins) == (3,)
        o = as_points(np.atleast_2d(origins), "origins", where=where)
        v = as_points(np.atleast_2d(directions), "directions", where=where)
        if o.shape != v.shape:
            raise GeometryError(f"{where}: origins has shape {o.shape} and directions {v.shape}; give one per ray")
        if v.shape[0] and not (np.abs(v).sum(axis=1) > 0).all():
            i = int(np.flatnonzero(~(np.abs(v).sum(axis=1) > 0))[0])
            raise GeometryError(f"{where}: directions[{i}] = {describe(v[i])} has zero length; give nonzero directions")
        distance = np.full(o.shape[0], np.inf)
        start_inside = self.contains(o)
        distance[start_inside] = 0.0
        mesh, index = self._surface_index
        if mesh.face_count:
            from frustum.raster import bvh

            t, _ = bvh.first_hits(index, o, v)
            distance = np.where(start_inside, 0.0, t)
        hit = np.isfinite(distance)
        point = np.full(o.shape, np.nan)
        point[hit] = o[hit] + distance[hit, None] * v[hit]
        # the leaf hit: the full cell just beyond the hit point along the ray
        probe = point[hit] + (1e-6 * self.cell_size) * v[hit] / np.linalg.norm(v[hit], axis=1)[:, None]
        level = np.full(o.shape[0], -1, dtype=np.int64)
        code = np.zeros(o.shape[0], dtype=np.uint64)
        lv, cd = self._leaf_of(probe)
        level[hit], code[hit] = lv, cd
        result = OctreeHits(hit, distance, point, level, code)
        if single:
            return OctreeHits(*(x[0] for x in result))
        return result

    def _leaf_of(self, points: NDArray) -> tuple[NDArray[np.int64], NDArray[np.uint64]]:
        """Level and code of the full node holding each point (−1, 0 where none)."""
        inside, codes = self._finest_codes(points)
        level = np.full(points.shape[0], -1, dtype=np.int64)
        code = np.zeros(points.shape[0], dtype=np.uint64)
        for up in range(self.depth + 1):
            c = codes >> np.uint64(3 * (self.depth - up))
            found = inside & (level < 0) & _contains(self.full[up], c)
            level[found], code[found] = up, c[found]
        return level, code


# --- helpers ------------------------------------------------------------------------------------------------


def _depth(value: Any, where: str) -> int:
    d = as_count(value, "depth", 0, where=where)
    if d > MAX_DEPTH:
        raise GeometryError(f"{where}: depth = {d} is above {MAX_DEPTH}; give 0 <= depth <= {MAX_DEPTH} (60-bit codes)")
    return d


def _cube(value: Any, where: str, *, expand: bool) -> NDArray[np.float64]:
    """(2, 3) min and max corner of a cube region; a box is enlarged to a cube about its centre if `expand`."""
    try:
        box = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(
            f"{where}: bounds = {describe(value)} is not numeric; give (min_corner, max_corner)"
        ) from None
    if box.shape != (2, 3):
        raise GeometryError(f"{where}: bounds has shape {box.shape}; expected (2, 3): (min_corner, max_corner)")
    if not np.isfinite(box).all():
        raise GeometryError(f"{where}: bounds = {describe(box.tolist())} is not finite; give finite corners")
    sides = box[1] - box[0]
    if not (sides > 0).all() and not (expand and sides.max() > 0 and (sides >= 0).all()):
        raise GeometryError(
            f"{where}: bounds = {describe(box.tolist())} has a side <= 0; give min_corner < max_corner on every axis"
        )
    side = float(sides.max())
    if expand:
        center = 0.5 * (box[0] + box[1])
        return np.array([center - side / 2, center + side / 2])
    if sides.max() - sides.min() > 1e-9 * side:
        raise GeometryError(
            f"{where}: bounds = {describe(box.tolist())} is not a cube (sides {describe(sides)}); give equal sides"
        )
    return np.array([box[0], box[0] + side])


def _check_surface_budget(depth: int, where: str, faces: int = 0) -> None:
    """A surface at `depth` crosses about 6·4^depth finest cells (a cube's faces); each costs ~27 samples or a
    few triangle tests (~96 bytes of working arrays) and 8 bytes of code."""
    cells = 6.0 * 4.0**depth
    check_memory(cells * 96.0 + faces * 200.0, where=where, cause=f"depth = {depth}", error=GeometryError)
    check_operations(cells * 27.0, where=where, cause=f"depth = {depth}", error=GeometryError)


def _evaluate(f: Callable, points: NDArray, where: str) -> NDArray[np.bool_]:
    try:
        values = np.asarray(f(points[:, 0], points[:, 1], points[:, 2]), dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise GeometryError(f"{where}: f(x, y, z) failed on {points.shape[0]} points ({error}); f takes three "
                            "(N,) arrays and returns (N,) numbers") from None  # fmt: skip
    if values.shape != (points.shape[0],):
        raise GeometryError(
            f"{where}: f returned shape {values.shape} for {points.shape[0]} points; expected ({points.shape[0]},)"
        )
    if not np.isfinite(values).all():
        i = int(np.flatnonzero(~np.isfinite(values))[0])
        raise GeometryError(f"{where}: f{tuple(points[i].tolist())} = {values[i]!r} is not finite; f must be finite")
    return values <= 0.0


def _same_region(a: Any, b: Any, where: str) -> tuple[Octree, Octree]:
    if not isinstance(b, Octree):
        raise GeometryError(f"{where}: other = {describe(b)} is not an Octree; give an octree of the same region")
    if not np.array_equal(a.bounds, b.bounds):
        raise GeometryError(
            f"{where}: other.bounds = {describe(b.bounds.tolist())} differs from bounds = "
            f"{describe(a.bounds.tolist())}; "
            "set operations need two octrees of the same region"
        )
    depth = max(a.depth, b.depth)
    return (a if a.depth == depth else a.refined(depth)), (b if b.depth == depth else b.refined(depth))


def _without_covered(levels: list[NDArray[np.uint64]]) -> list[NDArray[np.uint64]]:
    """Drop every node that lies inside a full node of a coarser level (so the nodes are disjoint)."""
    out = [_unique(levels[0])]
    coarse = [out[0]]
    for level in range(1, len(levels)):
        codes = _unique(levels[level])
        covered = np.zeros(codes.shape, dtype=bool)
        for up, full in enumerate(coarse):
            covered |= _contains(full, codes >> np.uint64(3 * (level - up)))
        out.append(codes[~covered])
        coarse.append(out[-1])
    return out


def _descendants(codes: NDArray[np.uint64], bits: int) -> NDArray[np.uint64]:
    result = codes
    for _ in range(bits // 3):
        result = _children(result)
    return result


def _boundary_edge_count(faces: NDArray[np.int64]) -> int:
    """Edges used by exactly one face (after welding)."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int((counts == 1).sum())


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


def _triangle_touches_box(tri: NDArray, lo: NDArray, side: float) -> NDArray[np.bool_]:
    """(N,) conservative triangle–cube overlap: bounding boxes overlap and the triangle's plane meets the cube
    (closed sets; never false for a triangle that touches the cube)."""
    lo = np.broadcast_to(lo, (tri.shape[0], 3))
    hi = lo + side
    slack = 1e-12 * max(side, 1.0)
    ok = ((tri.min(axis=1) <= hi + slack) & (tri.max(axis=1) >= lo - slack)).all(axis=1)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    center = lo + 0.5 * side
    radius = 0.5 * side * np.abs(normal).sum(axis=1)
    distance = np.einsum("ij,ij->i", normal, center - tri[:, 0])
    return ok & (np.abs(distance) <= radius * (1.0 + 1e-9) + slack * np.abs(normal).sum(axis=1))


def _segment_crosses(tri: NDArray, a: NDArray, b: NDArray) -> NDArray[np.bool_]:
    """(N,) True where segment a→b crosses triangle `tri` (Möller–Trumbore, t in [0, 1), inside the triangle)."""
    direction = b - a
    e1 = tri[:, 1] - tri[:, 0]
    e2 = tri[:, 2] - tri[:, 0]
    p = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = det != 0.0
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = a - tri[:, 0]
    u = np.einsum("ij,ij->i", s, p) * inv
    q = np.cross(s, e1)
    v = np.einsum("ij,ij->i", direction, q) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    return ok & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (t >= 0.0) & (t < 1.0)


def _winding_number(tri: NDArray, points: NDArray) -> NDArray[np.float64]:
    """Generalized winding number Σ Ω_f / 4π of each point (Van Oosterom–Strackee solid angles)."""
    out = np.empty(points.shape[0])
    for i, p in enumerate(points):
        a, b, c = tri[:, 0] - p, tri[:, 1] - p, tri[:, 2] - p
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        numerator = np.einsum("ij,ij->i", a, np.cross(b, c))
        denominator = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la
                       + np.einsum("ij,ij->i", c, a) * lb)  # fmt: skip
        out[i] = 2.0 * np.arctan2(numerator, denominator).sum() / (4.0 * math.pi)
    return out
