"""Convex planar polygons for the object-space visible-surface methods (``visibility.bsp``, ``visibility.depth_sort``):
checked input, areas, planes and the split of a polygon by a plane, with one tolerance relative to the scene size.

Coplanar and on-plane decisions use a tolerance relative to the scene size (``1e-9`` × the diagonal of the
bounding box). Polygons of zero area are skipped and counted. Polygons are convex and planar (triangles always
are); fragments of a polygon lie in its plane and tile it exactly (their areas sum to its area).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_points, describe
from frustum.errors import GeometryError

__all__ = [
    "RELATIVE_TOLERANCE", "Polygon", "check_polygons", "plane_of", "polygon_area", "scene_tolerance", "split_polygon",
    "vector_area",
]  # fmt: skip

RELATIVE_TOLERANCE = 1e-9
"""On-plane / coplanar tolerance as a fraction of the scene's bounding-box diagonal."""

Polygon = NDArray[np.float64]


def vector_area(vertices: Polygon) -> NDArray[np.float64]:
    """Half the sum of $P_i × P_(i+1)$: normal times area for a planar polygon (Newell's method)."""
    a, b = vertices, np.concatenate((vertices[1:], vertices[:1]))  # P_i, P_(i+1)
    x = (a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]).sum()
    y = (a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]).sum()
    z = (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum()
    return 0.5 * np.array([x, y, z])


def polygon_area(vertices: Polygon) -> float:
    return float(np.linalg.norm(vector_area(vertices)))


def check_polygons(
    polygons: Sequence[ArrayLike] | NDArray, ids: ArrayLike | None, where: str
) -> tuple[list[Polygon] | NDArray[np.float64], NDArray[np.int64]]:
    if isinstance(polygons, np.ndarray) and polygons.ndim == 3 and polygons.shape[1] >= 3 and polygons.shape[2] == 3:
        checked_array = _check_polygon_array(polygons, where)
        return checked_array, _check_ids(ids, len(checked_array), where)
    if not isinstance(polygons, Sequence) or isinstance(polygons, str):
        raise GeometryError(
            f"{where}: polygons = {describe(polygons)} is not a sequence; expected a list of (k, 3) vertex arrays"
        )
    checked = []
    for i, polygon in enumerate(polygons):
        vertices = as_points(polygon, f"polygons[{i}]", where=where)
        if vertices.shape[0] < 3:
            raise GeometryError(
                f"{where}: polygons[{i}] has {vertices.shape[0]} vertices; a polygon needs at least 3 (k, 3) rows"
            )
        checked.append(vertices)
    return checked, _check_ids(ids, len(checked), where)


def scene_tolerance(polygons: list[Polygon] | NDArray) -> float:
    if len(polygons) == 0:
        return 0.0
    points = polygons.reshape(-1, 3) if isinstance(polygons, np.ndarray) else np.concatenate(polygons)
    return RELATIVE_TOLERANCE * float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


def plane_of(vertices: Polygon) -> NDArray[np.float64]:
    """(4,) unit normal (A, B, C) and D of the polygon's plane $A x + B y + C z + D = 0$."""
    normal = vector_area(vertices)
    normal = normal / np.linalg.norm(normal)
    return np.append(normal, -normal @ vertices.mean(axis=0))


def split_polygon(vertices: Polygon, plane: NDArray, tolerance: float) -> tuple[Polygon | None, Polygon | None]:
    """Front and back part of a convex polygon cut by `plane`; vertices within `tolerance` go to both.

    An edge whose ends lie strictly on opposite sides is cut at $P = P_i + t (P_j − P_i)$,
    $t = d_i / (d_i − d_j)$ with the signed distances $d = N·P + D$.
    """
    distances = vertices @ plane[:3] + plane[3]
    sides = np.where(distances > tolerance, 1, np.where(distances < -tolerance, -1, 0))
    if not (sides < 0).any():
        return vertices, None
    if not (sides > 0).any():
        return None, vertices
    front: list[NDArray] = []
    back: list[NDArray] = []
    count = len(vertices)
    for i in range(count):
        j = (i + 1) % count
        if sides[i] >= 0:
            front.append(vertices[i])
        if sides[i] <= 0:
            back.append(vertices[i])
        if sides[i] * sides[j] < 0:
            t = distances[i] / (distances[i] - distances[j])
            point = vertices[i] + t * (vertices[j] - vertices[i])
            front.append(point)
            back.append(point)
    return np.array(front), np.array(back)


def _check_polygon_array(polygons: NDArray, where: str) -> NDArray[np.float64]:
    """(N, k, 3) polygons all at once: finite float64, or the first bad corner named."""
    try:
        array = np.ascontiguousarray(polygons, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: polygons has dtype {polygons.dtype}; expected numeric coordinates") from None
    bad = np.argwhere(~np.isfinite(array).all(axis=2))
    if bad.size:
        i, j = bad[0].tolist()
        raise GeometryError(
            f"{where}: polygons[{i}][{j}] = {describe(array[i, j])} is not finite; coordinates must be finite numbers"
        )
    return array


def _check_ids(ids: ArrayLike | None, count: int, where: str) -> NDArray[np.int64]:
    if ids is None:
        return np.arange(count, dtype=np.int64)
    id_array = np.asarray(ids)
    if id_array.shape != (count,) or (id_array.size and not np.issubdtype(id_array.dtype, np.integer)):
        raise GeometryError(
            f"{where}: ids = {describe(ids)} has shape {id_array.shape} and dtype {id_array.dtype}; expected "
            f"{count} integers, one per polygon"
        )
    return id_array.astype(np.int64)
