"""Set operations on octrees of one region by simultaneous traversal (complement, union, intersection,
difference; canonical results), refinement, and moves: by whole cells (exact) or by an affine map (resampled)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import describe
from frustum.budgets import check_memory
from frustum.errors import GeometryError
from frustum.geometry.octree.codes import (
    EMPTY,
    check_depth,
    children_codes,
    contains_codes,
    descendants,
    morton_decode,
    morton_encode,
    unique_codes,
)

if TYPE_CHECKING:
    from frustum.geometry.octree.tree import Octree


def complement(octree: Octree) -> Octree:
    """``Octree.complement`` (the method's docstring says what it does)."""
    if octree.is_empty:
        return type(octree)(
            octree.bounds, octree.depth, (np.zeros(1, dtype=np.uint64), *[EMPTY] * octree.depth), octree.boundary
        )
    levels = [EMPTY]
    for level in range(1, octree.depth + 1):
        children = children_codes(octree.partial[level - 1])
        keep = ~contains_codes(octree.full[level], children) & ~contains_codes(octree.partial[level], children)
        levels.append(children[keep])
    return type(octree)(octree.bounds, octree.depth, tuple(levels), octree.boundary)


def union(octree: Octree, other: Octree) -> Octree:
    """``Octree.union`` (the method's docstring says what it does)."""
    a, b = _same_region(octree, other, "Octree.union")
    levels = [np.concatenate([a.full[level], b.full[level]]) for level in range(a.depth + 1)]
    return type(octree)(a.bounds, a.depth, tuple(levels), unique_codes(np.concatenate([a.boundary, b.boundary])))


def intersection(octree: Octree, other: Octree) -> Octree:
    """``Octree.intersection`` (the method's docstring says what it does)."""
    a, b = _same_region(octree, other, "Octree.intersection")
    return a.complement().union(b.complement()).complement()


def difference(octree: Octree, other: Octree) -> Octree:
    """``Octree.difference`` (the method's docstring says what it does)."""
    a, b = _same_region(octree, other, "Octree.difference")
    return a.intersection(b.complement())


def refined(octree: Octree, depth: int) -> Octree:
    """``Octree.refined`` (the method's docstring says what it does)."""
    d = check_depth(depth, "Octree.refined")
    if d < octree.depth:
        raise GeometryError(f"Octree.refined: depth = {d} is below the octree's {octree.depth}; give >= {octree.depth}")
    boundary = descendants(octree.boundary, 3 * (d - octree.depth))
    return type(octree)(octree.bounds, d, (*octree.full, *[EMPTY] * (d - octree.depth)), boundary)


def shifted(octree: Octree, cells: ArrayLike) -> Octree:
    """``Octree.shifted`` (the method's docstring says what it does)."""
    where = "Octree.shifted"
    offset = np.asarray(cells)
    if offset.shape != (3,) or offset.dtype.kind not in "iu":
        raise GeometryError(f"{where}: cells = {describe(cells)} is not 3 integers; give (di, dj, dk) in cells")
    offset = offset.astype(np.int64)
    d = octree.depth
    out: list[list[NDArray]] = [[] for _ in range(d + 1)]
    pending = [np.asarray(c) for c in octree.full]
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
            pending[level + 1] = np.concatenate([pending[level + 1], children_codes(codes)])
    levels = [np.concatenate(parts) if parts else EMPTY for parts in out]
    if octree.boundary.size:
        ijk = morton_decode(octree.boundary) + offset
        ok = ((ijk >= 0) & (ijk < 2**d)).all(axis=1)
        boundary = morton_encode(ijk[ok])
    else:
        boundary = EMPTY
    return type(octree)(octree.bounds, d, tuple(levels), boundary)


def transformed(octree: Octree, matrix: ArrayLike) -> Octree:
    """``Octree.transformed`` (the method's docstring says what it does)."""
    from frustum._arrays import as_matrix

    where = "Octree.transformed"
    m = as_matrix(matrix, where=where, error=GeometryError)
    if abs(np.linalg.det(m[:3, :3])) < 1e-12:
        raise GeometryError(f"{where}: matrix is singular (det of its 3x3 part ~ 0); give an invertible map")
    inverse = np.linalg.inv(m)
    n, cell = 2**octree.depth, octree.cell_size
    boxes = octree.leaf_boxes()
    corners = boxes[:, [0, 1]][:, np.array([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)]), [0, 1, 2]]
    image = corners @ m[:3, :3].T + m[:3, 3]
    lo = np.clip(np.floor((image.min(axis=1) - octree.bounds[0]) / cell - 0.5), 0, n - 1).astype(np.int64)
    hi = np.clip(np.ceil((image.max(axis=1) - octree.bounds[0]) / cell - 0.5), 0, n - 1).astype(np.int64)
    total = float(np.prod(hi - lo + 1, axis=1).sum())
    check_memory(total * 64.0, where=where, cause=f"depth = {octree.depth} ({total:.3g} candidate cells)",
                 error=GeometryError)  # fmt: skip
    found = []
    for a, b in zip(lo, hi, strict=True):
        ijk = np.stack(np.meshgrid(*[np.arange(a[i], b[i] + 1) for i in range(3)], indexing="ij"), -1).reshape(-1, 3)
        centres = octree.bounds[0] + (ijk + 0.5) * cell
        keep = octree.contains(centres @ inverse[:3, :3].T + inverse[:3, 3])
        found.append(morton_encode(ijk[keep]))
    codes = unique_codes(np.concatenate(found)) if found else EMPTY
    return type(octree)(octree.bounds, octree.depth, tuple([EMPTY] * octree.depth + [codes]))


def _same_region(a: Any, b: Any, where: str) -> tuple[Octree, Octree]:
    if not isinstance(b, type(a)):
        raise GeometryError(f"{where}: other = {describe(b)} is not an Octree; give an octree of the same region")
    if not np.array_equal(a.bounds, b.bounds):
        raise GeometryError(
            f"{where}: other.bounds = {describe(b.bounds.tolist())} differs from bounds = "
            f"{describe(a.bounds.tolist())}; "
            "set operations need two octrees of the same region"
        )
    depth = max(a.depth, b.depth)
    return (a if a.depth == depth else a.refined(depth)), (b if b.depth == depth else b.refined(depth))
