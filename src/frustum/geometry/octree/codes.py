"""Morton codes of octree nodes and the arrays of them: encode and decode, children, sorted-set membership, the
canonical form (no node inside a full one, eight full siblings merged), and the checks of a depth and a cube region.

A node's Morton code interleaves the bits of its integer coordinates ``(i, j, k)`` (x, y, z, each in ``[0, 2^l)``),
x in the lowest bit, so the child of code c in octant o is $8·c + o$ with $o = x + 2y + 4z$.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, describe, read_only
from frustum.errors import GeometryError

__all__ = [
    "EMPTY",
    "MAX_DEPTH",
    "check_depth",
    "children_codes",
    "contains_codes",
    "cube_region",
    "descendants",
    "morton_decode",
    "morton_encode",
    "normalized_levels",
    "unique_codes",
    "without_covered",
]

MAX_DEPTH = 20
"""Deepest octree: 3·20 = 60 bits of Morton code (a 2^20 = 1,048,576 cells wide grid)."""

EMPTY = np.empty(0, dtype=np.uint64)
"""No codes (read-only)."""
EMPTY.flags.writeable = False


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


def unique_codes(values: ArrayLike) -> NDArray[np.uint64]:
    """Sorted unique uint64 codes (sort + compare: numpy's hashed ``unique`` was 10x slower here)."""
    a = np.sort(np.asarray(values, dtype=np.uint64).ravel())
    return a[np.r_[True, a[1:] != a[:-1]]] if a.size else a


def contains_codes(sorted_codes: NDArray[np.uint64], codes: NDArray[np.uint64]) -> NDArray[np.bool_]:
    if sorted_codes.size == 0 or codes.size == 0:
        return np.zeros(codes.shape, dtype=bool)
    pos = np.minimum(np.searchsorted(sorted_codes, codes), sorted_codes.size - 1)
    return sorted_codes[pos] == codes


def children_codes(codes: NDArray[np.uint64]) -> NDArray[np.uint64]:
    """(8N,) codes of the children of each code, in octant order ``x + 2y + 4z`` (sorted if `codes` is)."""
    return ((codes[:, None] << np.uint64(3)) | np.arange(8, dtype=np.uint64)[None, :]).ravel()


def normalized_levels(levels: list[NDArray[np.uint64]]) -> tuple[NDArray[np.uint64], ...]:
    """Canonical form of disjoint full nodes per level: sorted, unique, and every 8 full siblings merged."""
    out = [unique_codes(np.asarray(codes, dtype=np.uint64)) for codes in levels]
    for level in range(len(out) - 1, 0, -1):
        codes = out[level]
        if codes.size < 8:
            continue
        parents = codes >> np.uint64(3)
        starts = np.flatnonzero(np.r_[True, parents[1:] != parents[:-1]])
        counts = np.diff(np.r_[starts, parents.size])
        whole = parents[starts[counts == 8]]
        if whole.size:
            out[level] = codes[~contains_codes(whole, parents)]
            out[level - 1] = unique_codes(np.concatenate([out[level - 1], whole]))
    return tuple(read_only(np.ascontiguousarray(c, dtype=np.uint64)) for c in out)


def without_covered(levels: list[NDArray[np.uint64]]) -> list[NDArray[np.uint64]]:
    """Drop every node that lies inside a full node of a coarser level (so the nodes are disjoint)."""
    out = [unique_codes(levels[0])]
    coarse = [out[0]]
    for level in range(1, len(levels)):
        codes = unique_codes(levels[level])
        covered = np.zeros(codes.shape, dtype=bool)
        for up, full in enumerate(coarse):
            covered |= contains_codes(full, codes >> np.uint64(3 * (level - up)))
        out.append(codes[~covered])
        coarse.append(out[-1])
    return out


def descendants(codes: NDArray[np.uint64], bits: int) -> NDArray[np.uint64]:
    result = codes
    for _ in range(bits // 3):
        result = children_codes(result)
    return result


def check_depth(value: Any, where: str) -> int:
    d = as_count(value, "depth", 0, where=where)
    if d > MAX_DEPTH:
        raise GeometryError(f"{where}: depth = {d} is above {MAX_DEPTH}; give 0 <= depth <= {MAX_DEPTH} (60-bit codes)")
    return d


def cube_region(value: Any, where: str, *, expand: bool) -> NDArray[np.float64]:
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
