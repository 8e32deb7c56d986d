"""Ray queries on an octree: the first hit of each ray on the solid through the BVH of its cell faces, and the full
leaf beyond it."""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_points, describe
from frustum.errors import GeometryError
from frustum.geometry.octree.codes import (
    contains_codes,
)

if TYPE_CHECKING:
    from frustum.geometry.octree.tree import Octree


def ray_hits(octree: Octree, origins: ArrayLike, directions: ArrayLike) -> OctreeHits:
    """``Octree.ray_hits`` (the method's docstring says what it does)."""
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
    start_inside = octree.contains(o)
    distance[start_inside] = 0.0
    mesh, index = octree._surface_index
    if mesh.face_count:
        from frustum.raster import rays

        t = rays.closest_hits(index, o, v).t
        distance = np.where(start_inside, 0.0, t)
    hit = np.isfinite(distance)
    point = np.full(o.shape, np.nan)
    point[hit] = o[hit] + distance[hit, None] * v[hit]
    # the leaf hit: the full cell just beyond the hit point along the ray
    probe = point[hit] + (1e-6 * octree.cell_size) * v[hit] / np.linalg.norm(v[hit], axis=1)[:, None]
    level = np.full(o.shape[0], -1, dtype=np.int64)
    code = np.zeros(o.shape[0], dtype=np.uint64)
    lv, cd = octree._leaf_of(probe)
    level[hit], code[hit] = lv, cd
    result = OctreeHits(hit, distance, point, level, code)
    if single:
        return OctreeHits(*(x[0] for x in result))
    return result


def leaf_of(octree: Octree, points: NDArray) -> tuple[NDArray[np.int64], NDArray[np.uint64]]:
    """``Octree._leaf_of`` (the method's docstring says what it does)."""
    inside, codes = octree._finest_codes(points)
    level = np.full(points.shape[0], -1, dtype=np.int64)
    code = np.zeros(points.shape[0], dtype=np.uint64)
    for up in range(octree.depth + 1):
        c = codes >> np.uint64(3 * (octree.depth - up))
        found = inside & (level < 0) & contains_codes(octree.full[up], c)
        level[found], code[found] = up, c[found]
    return level, code


class OctreeHits(NamedTuple):
    """First hits of rays on an octree: ``hit`` (N,) bool, ``distance`` (N,) (inf on a miss), ``point`` (N, 3)
    world point (NaN on a miss), ``level`` and ``code`` (N,) of the full leaf hit (−1 and 0 on a miss)."""

    hit: NDArray[np.bool_]
    distance: NDArray[np.float64]
    point: NDArray[np.float64]
    level: NDArray[np.int64]
    code: NDArray[np.uint64]
