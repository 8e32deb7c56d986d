"""Building octrees: from voxels, points, an implicit function or a closed mesh (top-down, with the kernel
``raster.octree.split_pairs``), and the Menger sponge and Sierpinski tetrahedron as exact octrees."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, as_points, as_scalar, describe
from frustum.budgets import check_memory, check_operations
from frustum.errors import GeometryError
from frustum.geometry.mesh import Mesh
from frustum.geometry.octree.codes import (
    EMPTY,
    check_depth,
    children_codes,
    contains_codes,
    cube_region,
    morton_decode,
    morton_encode,
    unique_codes,
)

if TYPE_CHECKING:
    from frustum.geometry.octree.tree import Octree

_CHUNK = 1 << 18  # cells per batch of samples / triangle tests (bounded working memory)
# generic offset of a cell's reference point from its centre, in cell sides: keeps parity segments off the
# dyadic planes where cell-aligned geometry lies
_REFERENCE = np.array([0.0731, 0.1193, 0.0437])


def from_voxels(cls: type[Octree], voxels: ArrayLike, bounds: ArrayLike) -> Octree:
    """``Octree.from_voxels`` (the method's docstring says what it does)."""
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
    check_depth(depth, where)
    region = cube_region(bounds, where, expand=False)
    grids = [array]
    for _ in range(depth):  # a node is full when its 8 children are
        g = grids[-1]
        m = g.shape[0] // 2
        grids.append(g.reshape(m, 2, m, 2, m, 2).all(axis=(1, 3, 5)))
    grids.reverse()  # grids[l] is level l
    levels = []
    for level, grid in enumerate(grids):
        maximal = grid if level == 0 else grid & ~np.repeat(np.repeat(np.repeat(grids[level - 1], 2, 0), 2, 1), 2, 2)
        levels.append(np.sort(morton_encode(np.argwhere(maximal))))
    return cls(region, depth, tuple(levels))


def from_points(cls: type[Octree], points: ArrayLike, depth: int, bounds: ArrayLike | None = None) -> Octree:
    """``Octree.from_points`` (the method's docstring says what it does)."""
    where = "Octree.from_points"
    p = as_points(points, where=where)
    d = check_depth(depth, where)
    if bounds is None:
        if p.shape[0] == 0:
            raise GeometryError(f"{where}: points is empty and bounds is None; give points or bounds")
        region = cube_region(np.array([p.min(axis=0), p.max(axis=0)]), where, expand=True)
    else:
        region = cube_region(bounds, where, expand=False)
    check_memory(p.shape[0] * 48.0, where=where, cause=f"{p.shape[0]} points", error=GeometryError)
    empty = cls(region, d, tuple(EMPTY for _ in range(d + 1)))
    inside, codes = empty._finest_codes(p)
    levels = [EMPTY] * d + [unique_codes(codes[inside])]
    return cls(region, d, tuple(levels))


def from_function(
    cls: type[Octree], f: Callable[[NDArray, NDArray, NDArray], ArrayLike], bounds: ArrayLike, depth: int
) -> Octree:
    """``Octree.from_function`` (the method's docstring says what it does)."""
    where = "Octree.from_function"
    if not callable(f):
        raise GeometryError(f"{where}: f = {describe(f)} is not callable; give f(x, y, z) -> values")
    d = check_depth(depth, where)
    region = cube_region(bounds, where, expand=True)
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
    boundary = EMPTY
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
        candidates = children_codes(candidates[mixed])
    levels += [EMPTY] * (d + 1 - len(levels))
    return cls(region, d, tuple(levels), boundary)


def from_mesh(
    cls: type[Octree], mesh: Mesh, depth: int, bounds: ArrayLike | None = None, *, shell: bool = False
) -> Octree:
    """``Octree.from_mesh`` (the method's docstring says what it does)."""
    from frustum.raster import octree as kernels

    where = "Octree.from_mesh"
    if not isinstance(mesh, Mesh):
        raise GeometryError(f"{where}: mesh = {describe(mesh)} is not a Mesh; give a frustum Mesh")
    d = check_depth(depth, where)
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
        region = cube_region(np.array([solid.vertices.min(axis=0), solid.vertices.max(axis=0)]), where, expand=True)
    else:
        region = cube_region(bounds, where, expand=False)
    _check_surface_budget(d, where, faces=solid.face_count)
    corners = np.ascontiguousarray(solid.vertices[solid.faces], dtype=np.float64)  # (F, 3, 3)
    size = float(region[1, 0] - region[0, 0])
    cell_pairs = np.zeros(solid.face_count, dtype=np.uint64)  # (cell code, triangle) pairs of this level
    triangle_ids = np.arange(solid.face_count, dtype=np.int64)
    keep = _triangle_touches_box(corners, region[0], size)
    cell_pairs, triangle_ids = cell_pairs[keep], triangle_ids[keep]
    root_reference = region[0] + (0.5 + _REFERENCE) * size
    root_inside = False if shell else bool(abs(_winding_number(corners, root_reference[None])[0]) > 0.5)
    partial = np.zeros(1, dtype=np.uint64) if cell_pairs.size else EMPTY
    partial_inside = np.array([root_inside]) if cell_pairs.size else np.zeros(0, dtype=bool)
    levels: list[NDArray[np.uint64]] = [np.zeros(1, dtype=np.uint64) if (root_inside and not cell_pairs.size)
                                        else EMPTY]  # fmt: skip
    boundary = EMPTY
    if d == 0 and cell_pairs.size:
        levels = [np.zeros(1, dtype=np.uint64) if (root_inside or shell) else EMPTY]
        boundary = np.zeros(1, dtype=np.uint64)
    for level in range(1, d + 1):
        if partial.size == 0:
            levels.append(EMPTY)
            continue
        side = size / 2**level
        children = children_codes(partial)
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
        touched = unique_codes(cell_pairs)
        is_touched = contains_codes(touched, children)
        if shell:
            child_inside[:] = False
        if level == d:
            boundary = touched
            levels.append(children[is_touched] if shell else children[child_inside])
            break
        levels.append(children[child_inside & ~is_touched])
        partial, partial_inside = children[is_touched], child_inside[is_touched]
    levels += [EMPTY] * (d + 1 - len(levels))
    return cls(region, d, tuple(levels), boundary)


def menger_sponge(cls: type[Octree], level: int, size: float = 1.0) -> Octree:
    """``Octree.menger_sponge`` (the method's docstring says what it does)."""
    from frustum.geometry.fractals.solids import _menger_cells

    where = "Octree.menger_sponge"
    n = as_count(level, "level", 0, where=where)
    s = as_scalar(size, "size", where=where, error=GeometryError)
    if not s > 0.0:
        raise GeometryError(f"{where}: size = {s!r} is not positive; give an edge length > 0")
    d = (3**n - 1).bit_length() if n else 0
    check_depth(d, where)
    check_memory(20**n * 64.0, where=where, cause=f"level = {n}", error=GeometryError)
    cells = _menger_cells(n)
    side = s * 2**d / 3**n
    region = np.array([[0.0, 0.0, 0.0], [side, side, side]])
    return cls(region, d, tuple([EMPTY] * d + [np.sort(morton_encode(cells))]))


def sierpinski_tetrahedron(cls: type[Octree], level: int, size: float = 1.0) -> Octree:
    """``Octree.sierpinski_tetrahedron`` (the method's docstring says what it does)."""
    where = "Octree.sierpinski_tetrahedron"
    n = check_depth(as_count(level, "level", 0, where=where), where)
    s = as_scalar(size, "size", where=where, error=GeometryError)
    if not s > 0.0:
        raise GeometryError(f"{where}: size = {s!r} is not positive; give an edge length > 0")
    check_memory(4**n * 64.0, where=where, cause=f"level = {n}", error=GeometryError)
    codes = np.zeros(1, dtype=np.uint64)
    keep = np.array([0, 3, 5, 6], dtype=np.uint64)
    for _ in range(n):
        codes = ((codes[:, None] << np.uint64(3)) | keep[None]).ravel()
    return cls(np.array([[0.0] * 3, [s] * 3]), n, tuple([EMPTY] * n + [np.sort(codes)]))


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


def _boundary_edge_count(faces: NDArray[np.int64]) -> int:
    """Edges used by exactly one face (after welding)."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int((counts == 1).sum())


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
