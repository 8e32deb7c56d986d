"""Object-space visible-surface ordering: the BSP tree and the painter's depth sort (Newell–Newell–Sancha).

Both produce the polygons of a scene **back to front**, split where no order exists, so that painting them in
that order (later polygons cover earlier ones) gives the picture a depth buffer gives: the visible-surface
methods for filled vector output (SVG, PDF) where there is no per-pixel depth.

* ``BSPTree`` partitions space by the plane of one polygon at each node; polygons that straddle the plane are
  split into a front and a back fragment. The tree depends on the scene only, and any viewing position reads
  it back to front in linear time: at each node draw first the side of the plane away from the viewer, then
  the node's own polygons, then the viewer's side. Fragments stay convex polygons. A group of polygons
  that all lie behind each other's planes (a convex polyhedron) is kept as one leaf, a convex cell, painted
  faces-turned-away first: that keeps a convex mesh at one node instead of a chain of one node per face.
* ``depth_sort`` is the painter's algorithm of Newell, Newell and Sancha: sort by greatest depth, then check
  each polygon P against the polygons Q whose depth ranges overlap it with the textbook tests (1) bounding
  rectangles disjoint, (2) P wholly behind Q's plane, (3) Q wholly in front of P's plane, (4) projections
  disjoint; here (4) is made exact by intersecting the projections and comparing the two plane depths at the
  corners of their common region. A Q that P hides moves to the head of the list; a Q already moved once
  means a cyclic overlap (or two polygons that pierce each other), resolved by splitting along a plane.

Coplanar and on-plane decisions use a tolerance relative to the scene size (``1e-9`` × the diagonal of the
bounding box). Polygons of zero area are skipped and counted. Polygons are convex and planar (triangles
always are); fragments of a polygon lie in its plane and tile it exactly (their areas sum to its area).

Why one module: the BSP tree and the depth sort share the plane tests, the splitting and the tolerance.

References
----------
[HB 16] "Depth-Sorting Method", "BSP-Tree Method"; [seed] "BSP Trees" (General Modeling Techniques).
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_points, as_vector3, describe, read_only
from frustum.camera import Camera
from frustum.errors import CameraError, GeometryError
from frustum.geometry import Mesh
from frustum.transforms import apply

__all__ = ["BSPTree", "DepthOrder", "depth_sort"]

_RELATIVE_TOLERANCE = 1e-9
"""On-plane / coplanar tolerance as a fraction of the scene's bounding-box diagonal."""
_SPLIT_WEIGHT = 8
"""Splitter score = 8 · (polygons split) + |front − back|: fewer fragments first, balance second."""
_SPLITTER_CANDIDATES = 8
"""At most this many polygons (evenly spaced in the node's list) are tried as the splitting plane."""
_SPLITTER_SAMPLE = 256
"""Splitter candidates are scored on at most this many polygons (evenly spaced) of the node's list."""
_DIRECTION_TOLERANCE = 1e-12
_MAX_CORNERS = 8
"""Polygons are stored with at most this many corners (padded); a larger one is stored as several pieces."""

Polygon = NDArray[np.float64]


# --- shared geometry -------------------------------------------------------------------------------------


def _vector_area(vertices: Polygon) -> NDArray[np.float64]:
    """Half the sum of $P_i × P_(i+1)$: normal times area for a planar polygon (Newell's method)."""
    a, b = vertices, np.concatenate((vertices[1:], vertices[:1]))  # P_i, P_(i+1)
    x = (a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]).sum()
    y = (a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]).sum()
    z = (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum()
    return 0.5 * np.array([x, y, z])


def _polygon_area(vertices: Polygon) -> float:
    return float(np.linalg.norm(_vector_area(vertices)))


def _check_polygons(
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


def _scene_tolerance(polygons: list[Polygon] | NDArray) -> float:
    if len(polygons) == 0:
        return 0.0
    points = polygons.reshape(-1, 3) if isinstance(polygons, np.ndarray) else np.concatenate(polygons)
    return _RELATIVE_TOLERANCE * float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))


def _plane(vertices: Polygon) -> NDArray[np.float64]:
    """(4,) unit normal (A, B, C) and D of the polygon's plane $A x + B y + C z + D = 0$."""
    normal = _vector_area(vertices)
    normal = normal / np.linalg.norm(normal)
    return np.append(normal, -normal @ vertices.mean(axis=0))


def _split(vertices: Polygon, plane: NDArray, tolerance: float) -> tuple[Polygon | None, Polygon | None]:
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


def _pieces(polygon: Polygon, area_tolerance: float) -> list[Polygon]:
    """The polygon as pieces of at most 8 corners (fans P0, P_j, …, P_j+6 beyond that), zero-area ones dropped."""
    if len(polygon) <= _MAX_CORNERS:
        pieces = [polygon]
    else:
        span = _MAX_CORNERS - 2
        pieces = [
            np.concatenate((polygon[:1], polygon[j : j + _MAX_CORNERS - 1])) for j in range(1, len(polygon) - 1, span)
        ]
    return [piece for piece in pieces if len(piece) >= 3 and _polygon_area(piece) > area_tolerance]


def _padded(pieces: list[Polygon]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """(n, 8, 3) corners, each polygon padded by repeating its last corner (which changes neither its plane
    distances' extremes nor its area), and (n,) corner counts."""
    corners = np.empty((len(pieces), _MAX_CORNERS, 3))
    counts = np.empty(len(pieces), dtype=np.int64)
    for i, piece in enumerate(pieces):
        corners[i, : len(piece)] = piece
        corners[i, len(piece) :] = piece[-1]
        counts[i] = len(piece)
    return corners, counts


def _padded_polygons(
    polygons: list[Polygon] | NDArray, area_tolerance: float
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64], NDArray[np.float64], int]:
    """Padded corners, corner counts, owner polygon, per-polygon planes, and the count of zero-area polygons."""
    if isinstance(polygons, np.ndarray) and polygons.shape[1] <= _MAX_CORNERS:  # (N, k, 3): all at once
        count = polygons.shape[1]
        following = np.roll(polygons, -1, axis=1)
        vector_areas = 0.5 * np.stack(
            [
                (polygons[..., 1] * following[..., 2] - polygons[..., 2] * following[..., 1]).sum(axis=1),
                (polygons[..., 2] * following[..., 0] - polygons[..., 0] * following[..., 2]).sum(axis=1),
                (polygons[..., 0] * following[..., 1] - polygons[..., 1] * following[..., 0]).sum(axis=1),
            ],
            axis=1,
        )
        areas = np.sqrt((vector_areas**2).sum(axis=1))
        good = areas > area_tolerance
        normals = np.zeros_like(vector_areas)
        normals[good] = vector_areas[good] / areas[good, None]
        planes = np.concatenate([normals, -(normals * polygons.mean(axis=1)).sum(axis=1, keepdims=True)], axis=1)
        kept = polygons[good]
        corners = np.concatenate([kept, np.repeat(kept[:, -1:], _MAX_CORNERS - count, axis=1)], axis=1)
        counts = np.full(len(kept), count, dtype=np.int64)
        return np.ascontiguousarray(corners), counts, np.flatnonzero(good), planes, int((~good).sum())
    planes = np.zeros((len(polygons), 4))
    pieces: list[Polygon] = []
    owners: list[int] = []
    degenerate = 0
    for i, polygon in enumerate(polygons):
        if _polygon_area(polygon) <= area_tolerance:
            degenerate += 1
            continue
        planes[i] = _plane(polygon)
        parts = _pieces(polygon, area_tolerance)
        pieces.extend(parts)
        owners.extend([i] * len(parts))
    corners, counts = _padded(pieces)
    return corners, counts, np.array(owners, dtype=np.int64), planes, degenerate


def _evenly_spaced(length: int, most: int) -> NDArray[np.int64]:
    """At most `most` distinct indices spread evenly over range(length), first and last included."""
    if length <= most:
        return np.arange(length)
    return np.arange(most) * (length - 1) // (most - 1)


def _viewer(camera: Camera, where: str) -> NDArray[np.float64]:
    """(4,) homogeneous centre of projection: (eye, 1), or (unit direction toward the viewer, 0) if parallel.

    It is the null vector of the x, y and w rows of clip_from_world (the point every projection line passes
    through), oriented for a parallel projection so that it lies on the near side (clip z decreasing).
    """
    if not isinstance(camera, Camera):
        raise CameraError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera")
    clip_from_world = np.asarray(camera.clip_from_world)
    centre = np.linalg.svd(clip_from_world[[0, 1, 3]])[2][-1]
    if abs(centre[3]) > 1e-12 * np.abs(centre).max():
        return np.append(np.asarray(camera.frame.eye, dtype=np.float64), 1.0)
    centre = np.append(centre[:3] / np.linalg.norm(centre[:3]), 0.0)
    return -centre if clip_from_world[2] @ centre > 0.0 else centre


# --- BSP tree --------------------------------------------------------------------------------------------


class BSPTree:
    """Binary space-partitioning tree of polygons, read back to front from any viewing position.

    Each node holds a partitioning plane (the plane of one of its polygons), the polygons lying in that plane,
    and a front subtree ($N·P + D > 0$) and a back subtree. A polygon straddling the plane is split into
    its front and back part, both convex polygons (k, 3) (a polygon of more than 8 corners is stored as a fan
    of pieces of at most 8). The splitter at each node is the candidate plane (up to 8, evenly spaced through
    the node's list) that splits the fewest polygons, then balances the two sides best, counted on up to 256
    evenly spaced polygons: deterministic.

    Parameters
    ----------
    polygons : sequence of (k, 3) array_like, or an (N, k, 3) array
        Convex planar polygons in world coordinates, k >= 3, corners in order.
    ids : (len(polygons),) array_like of int, optional
        A label per polygon handed back with each of its fragments; default 0, 1, 2, ….

    Attributes
    ----------
    fragment_count : int
        Polygons stored after splitting (the fragments ``back_to_front`` returns).
    node_count : int
        Nodes of the tree: one partitioning plane each, or one convex cell (a leaf of mutually unhidden faces).
    degenerate_count : int
        Input polygons of zero area (within the tolerance) that were skipped.
    split_count : int
        Polygons cut in two by a partitioning plane while building.
    tolerance : float
        The on-plane distance, 1e-9 × the diagonal of the scene's bounding box.

    Raises
    ------
    GeometryError
        For a polygon that is not a (k, 3) array of finite numbers with k >= 3, or ids of the wrong length.

    References
    ----------
    [HB 16] "BSP-Tree Method"; [seed] "BSP Trees".
    """

    def __init__(
        self, polygons: Sequence[ArrayLike] | NDArray, ids: ArrayLike | None = None, *, record: Any = None
    ) -> None:
        polys, labels = _check_polygons(polygons, ids, "BSPTree")
        self.tolerance = _scene_tolerance(polys)
        self._area_tolerance = self.tolerance**2
        corners, counts, owners, planes, degenerate = _padded_polygons(polys, self._area_tolerance)
        self.degenerate_count = degenerate
        self.split_count = 0
        self._source_planes = planes  # (P, 4) plane of each input polygon
        self._corners = corners  # (F, 8, 3) padded fragment corners, grows as splits add fragments
        self._counts = counts  # (F,) corners of each fragment
        self._owners = owners  # (F,) input polygon of each fragment
        self._size = len(corners)
        self._labels = labels
        self._planes: list[NDArray[np.float64]] = []
        self._front: list[int] = []
        self._back: list[int] = []
        self._members: list[NDArray[np.int64]] = []
        self._cells: list[bool] = []
        self._build(record)
        # keep only the fragments the tree holds (a split polygon is replaced by its parts), renumbered
        alive = np.concatenate(self._members) if self._members else np.empty(0, dtype=np.int64)
        alive.sort()
        renumber = np.full(self._size, -1, dtype=np.int64)
        renumber[alive] = np.arange(len(alive))
        self._members = [renumber[members] for members in self._members]
        self._corners = read_only(np.ascontiguousarray(self._corners[alive]))
        self._counts = self._counts[alive]
        self._owners = self._owners[alive]
        self.fragment_count = len(alive)

    @classmethod
    def from_mesh(cls, mesh: Mesh, world_from_model: ArrayLike | None = None) -> BSPTree:
        """BSP tree of a mesh's triangles placed by `world_from_model`; each fragment's id is its face index."""
        if not isinstance(mesh, Mesh):
            raise GeometryError(f"BSPTree.from_mesh: mesh = {describe(mesh)} is not a Mesh; build one with Mesh")
        model = world_from_model
        vertices = np.asarray(mesh.vertices, np.float64) if model is None else apply(model, mesh.vertices)
        return cls(vertices[mesh.faces], np.arange(mesh.face_count))

    @property
    def node_count(self) -> int:
        """Number of nodes (partitioning planes and convex cells)."""
        return len(self._planes)

    def _append(self, pieces: list[Polygon], owner: int) -> NDArray[np.int64]:
        """Store new fragments (capacity doubling); returns their indices."""
        corners, counts = _padded(pieces)
        count = len(pieces)
        if self._size + count > len(self._corners):
            capacity = max(2 * len(self._corners), self._size + count, 16)
            grown = np.empty((capacity, _MAX_CORNERS, 3))
            grown[: self._size] = self._corners[: self._size]
            grown_counts = np.empty(capacity, dtype=np.int64)
            grown_counts[: self._size] = self._counts[: self._size]
            owners = np.empty(capacity, dtype=np.int64)
            owners[: self._size] = self._owners[: self._size]
            self._corners, self._counts, self._owners = grown, grown_counts, owners
        self._corners[self._size : self._size + count] = corners
        self._counts[self._size : self._size + count] = counts
        self._owners[self._size : self._size + count] = owner
        self._size += count
        return np.arange(self._size - count, self._size)

    def _build(self, record: Any = None) -> None:
        """Iterative construction (no recursion limit): each stack entry is (parent, side, fragment indices).

        A group whose polygons all lie behind (or on) every one of their planes is a convex cell, such as a
        convex polyhedron: it becomes one leaf, painted as "faces turned away, then faces turned toward the
        viewer" (within each half no two overlap on the screen), instead of a chain of one node per face.
        ``record("node", ...)`` (``frustum.steps``), if given, sees each node as it is made: its plane, the
        polygons on it, the numbers in front and behind, and each split (the polygon and its two parts).
        """
        eps = self.tolerance
        stack: list[tuple[int, int, NDArray[np.int64]]] = [(-1, 0, np.arange(self._size))] if self._size else []
        cell_check_below = np.inf  # check for convex cells only in groups under half the last failed one
        while stack:
            parent, side, group = stack.pop()
            if len(group) == 1:  # a leaf: one polygon in its own plane
                node = self._new_node(self._source_planes[self._owners[group[0]]], parent, side, False)
                self._members.append(group)
                if record is not None:
                    record("node", node=node, parent=parent, side=side, plane=self._planes[node], cell=False,
                           on=[self._corners[i, : self._counts[i]].copy() for i in group.tolist()],
                           in_front=0, behind=0, splits=[])  # fmt: skip
                continue
            plane = self._choose_splitter(group)
            distances = self._corners[group] @ plane[:3] + plane[3]  # (m, 8)
            highest, lowest = distances.max(axis=1), distances.min(axis=1)
            on = (highest <= eps) & (lowest >= -eps)
            in_front = (lowest >= -eps) & ~on
            behind = (highest <= eps) & ~on
            straddle = ~(on | in_front | behind)
            cell = False
            if len(group) > 2 and not in_front.any() and not straddle.any() and len(group) < cell_check_below:
                cell = self._is_convex_cell(group)
                if not cell:
                    cell_check_below = len(group) / 2
            node = self._new_node(plane, parent, side, cell)
            if cell:
                self._members.append(group)
                if record is not None:
                    record("node", node=node, parent=parent, side=side, plane=plane, cell=True,
                           on=[self._corners[i, : self._counts[i]].copy() for i in group.tolist()],
                           in_front=0, behind=0, splits=[])  # fmt: skip
                continue
            self._members.append(group[on])
            front_parts, back_parts = [group[in_front]], [group[behind]]
            splits = []
            for index in group[straddle].tolist():
                owner = int(self._owners[index])
                front, back = _split(self._corners[index, : self._counts[index]], plane, eps)
                self.split_count += 1
                if record is not None:
                    splits.append((self._corners[index, : self._counts[index]].copy(), front, back))
                for part, parts in ((front, front_parts), (back, back_parts)):
                    pieces = _pieces(part, self._area_tolerance) if part is not None else []
                    if pieces:
                        parts.append(self._append(pieces, owner))
            back_group, front_group = np.concatenate(back_parts), np.concatenate(front_parts)
            if record is not None:
                record("node", node=node, parent=parent, side=side, plane=plane, cell=False,
                       on=[self._corners[i, : self._counts[i]].copy() for i in group[on].tolist()],
                       in_front=int(in_front.sum()), behind=int(behind.sum()), splits=splits)  # fmt: skip
            if back_group.size:
                stack.append((node, -1, back_group))
            if front_group.size:
                stack.append((node, +1, front_group))

    def _new_node(self, plane: NDArray, parent: int, side: int, cell: bool) -> int:
        node = len(self._planes)
        self._planes.append(plane)
        self._front.append(-1)
        self._back.append(-1)
        self._cells.append(cell)
        if parent >= 0:
            (self._front if side > 0 else self._back)[parent] = node
        return node

    def _is_convex_cell(self, group: NDArray[np.int64]) -> bool:
        """True if every corner of the group lies behind or on the plane of every polygon of the group."""
        planes = self._source_planes[np.unique(self._owners[group])]
        corners = self._corners[group].reshape(-1, 3)
        chunk = max(1, 2_000_000 // max(len(corners), 1))
        for start in range(0, len(planes), chunk):
            block = planes[start : start + chunk]
            if (corners @ block[:, :3].T + block[:, 3]).max() > self.tolerance:
                return False
        return True

    def _choose_splitter(self, group: NDArray[np.int64]) -> NDArray:
        owners = self._owners[group]
        if len(group) == 1:
            return self._source_planes[owners[0]]
        picks = _evenly_spaced(len(group), _SPLITTER_CANDIDATES)
        candidates = np.unique(owners[picks])
        planes = self._source_planes[candidates]  # (K, 4)
        sample = group[_evenly_spaced(len(group), _SPLITTER_SAMPLE)]
        distances = self._corners[sample] @ planes[:, :3].T + planes[:, 3]  # (s, 8, K)
        highest, lowest = distances.max(axis=1), distances.min(axis=1)
        eps = self.tolerance
        straddle = (highest > eps) & (lowest < -eps)
        in_front = (lowest >= -eps) & (highest > eps)
        behind = (highest <= eps) & (lowest < -eps)
        score = _SPLIT_WEIGHT * straddle.sum(axis=0) + np.abs(in_front.sum(axis=0) - behind.sum(axis=0))
        return planes[int(np.argmin(score))]

    def back_to_front(
        self, eye: ArrayLike | None = None, direction: ArrayLike | None = None, *, camera: Camera | None = None
    ) -> list[tuple[Polygon, int]]:
        """Fragments in painting order (farthest first) seen from `eye`, along view `direction`, or by `camera`.

        At each node with plane $N·P + D = 0$: if the viewer is in front ($N·E + D > 0$, or
        $−N·d > 0$ for a viewer at infinity looking along d) draw the back subtree, the node's polygons, then
        the front subtree; otherwise the reverse. A viewer in the plane sees its polygons edge-on. A convex
        cell paints its faces turned away from the viewer first.

        Parameters
        ----------
        eye : (3,) array_like, optional
            World position of the viewer (perspective projection: the camera's eye).
        direction : (3,) array_like, optional
            View direction, from the viewer into the scene (parallel projection: the direction of the
            projection lines, which for an oblique projection is not the view-plane normal).
        camera : Camera, optional
            Takes the centre of projection from the camera: its eye, or for any parallel projection (oblique
            included) the direction of its projection lines. Give exactly one of `eye`, `direction`, `camera`.

        Returns
        -------
        list of ((k, 3) float64, int)
            World-space fragment polygon (read-only) and the id of its source polygon.

        Raises
        ------
        CameraError
            If not exactly one of `eye`, `direction`, `camera` is given, or the one given is not a finite
            3-vector (or a zero direction, or not a Camera).

        References
        ----------
        [HB 16] "BSP-Tree Method".
        """
        indices = self.back_to_front_indices(eye, direction, camera=camera)
        labels = self._labels[self._owners[indices]].tolist()
        corners, counts = self._corners, self._counts[indices].tolist()
        return [(corners[i, :count], label) for i, count, label in zip(indices.tolist(), counts, labels, strict=True)]

    def back_to_front_indices(
        self,
        eye: ArrayLike | None = None,
        direction: ArrayLike | None = None,
        *,
        camera: Camera | None = None,
        record: Any = None,
    ) -> NDArray[np.int64]:
        """(F,) int64 indices into ``fragments`` (and ``ids``) in painting order: the array form of
        ``back_to_front``, for drawing many fragments at once. ``record("emit", node=..., fragments=...,
        viewer_in_front=...)`` (``frustum.steps``), if given, sees each node's fragments as they are emitted."""
        where = "BSPTree.back_to_front"
        if sum(value is not None for value in (eye, direction, camera)) != 1:
            raise CameraError(
                f"{where}: eye = {describe(eye)}, direction = {describe(direction)} and camera = {describe(camera)}; "
                "give exactly one of them (the viewer's position, the view direction of a parallel projection, or "
                "the camera)"
            )
        if camera is not None:
            viewer, tolerance = _viewer(camera, where), self.tolerance
            if viewer[3] == 0.0:
                tolerance = _DIRECTION_TOLERANCE
        elif eye is not None:
            viewer = np.append(as_vector3(eye, "eye", where=where, error=CameraError), 1.0)
            tolerance = self.tolerance
        else:
            d = as_vector3(direction, "direction", where=where, error=CameraError)
            length = float(np.linalg.norm(d))
            if length == 0.0:
                raise CameraError(f"{where}: direction = {describe(d)} has zero length; give a nonzero direction")
            viewer = np.append(-d / length, 0.0)
            tolerance = _DIRECTION_TOLERANCE
        if not self._planes:
            return np.empty(0, dtype=np.int64)
        sides = np.array(self._planes) @ viewer
        order: list[NDArray[np.int64]] = []
        stack: list[int] = [0]  # node index >= 0: visit; -1 - index: emit the node's polygons
        while stack:
            entry = stack.pop()
            if entry < 0:
                order.append(self._members[-1 - entry])
                if record is not None:
                    record("emit", node=-1 - entry, fragments=order[-1], viewer_in_front=bool(
                        sides[-1 - entry] >= -tolerance))  # fmt: skip
                continue
            if self._cells[entry]:  # convex cell: faces turned away first, then faces turned toward the viewer
                members = self._members[entry]
                toward = self._source_planes[self._owners[members]] @ viewer > tolerance
                order.extend((members[~toward], members[toward]))
                if record is not None:
                    record("emit", node=entry, fragments=np.concatenate(order[-2:]), viewer_in_front=None)
                continue
            if sides[entry] < -tolerance:  # viewer behind: the front subtree is farther
                near, far = self._back[entry], self._front[entry]
            else:
                near, far = self._front[entry], self._back[entry]
            if near >= 0:
                stack.append(near)
            stack.append(-1 - entry)
            if far >= 0:
                stack.append(far)
        return np.concatenate(order)

    @property
    def fragments(self) -> list[Polygon]:
        """The F fragments, (k, 3) read-only world-space polygons, in storage order (``back_to_front_indices``
        indexes this list)."""
        return [self._corners[i, :count] for i, count in enumerate(self._counts.tolist())]

    @property
    def ids(self) -> NDArray[np.int64]:
        """(F,) id of the source polygon of each fragment, in storage order."""
        return read_only(self._labels[self._owners])


# --- depth sort ------------------------------------------------------------------------------------------


class DepthOrder(NamedTuple):
    """What ``depth_sort`` returns: the fragments in painting order and what it had to do to get there.

    ``fragments``: (world-space (k, 3) polygon, source id) pairs, farthest first, like
    ``BSPTree.back_to_front``. ``split_count``: splits made to break cyclic overlaps and piercing polygons.
    ``degenerate_count``: zero-area input polygons skipped. ``clipped_count``: polygons cut (or dropped) by the
    near plane. ``unresolved_count``: conflicts the sort gave up on (expected 0; see ``depth_sort``).
    """

    fragments: list[tuple[Polygon, int]]
    split_count: int
    degenerate_count: int
    clipped_count: int
    unresolved_count: int


class _SortItem(NamedTuple):
    world: Polygon
    label: int
    world_plane: NDArray
    screen: Polygon  # (k, 3) normalized NDC: x, y and depth z (larger = farther), viewer at z = −∞
    plane: NDArray  # (4,) screen-space plane, normal pointing toward the viewer (n_z < 0); zeros if edge-on
    low: NDArray  # (3,) bounding box
    high: NDArray


def depth_sort(
    polygons: Sequence[ArrayLike], camera: Camera, ids: ArrayLike | None = None, *, record: Any = None
) -> DepthOrder:
    """Painter's algorithm: order `polygons` back to front for `camera`, splitting cyclic overlaps.

    The polygons are clipped by the near plane, then mapped to normalized device coordinates, where every
    projection (perspective, oblique, orthographic) is a parallel one along z and planes stay planes; each
    axis is rescaled to the scene's extent. Sorted by greatest depth z_max, the list is processed from its
    farthest polygon P: every Q with $z_max(Q) > z_min(P)$ is checked by the tests of [HB 16], in order of
    cost, each of which shows that P cannot hide Q:

    1. the bounding rectangles of P and Q in xy do not overlap;
    2. P lies wholly behind the plane of Q (on the far side from the viewer);
    3. Q lies wholly in front of the plane of P;
    4. the projections of P and Q do not overlap, or where they do, P is behind Q: each plane
       $A x + B y + C z + D = 0$ is the affine depth $z(x, y) = −(A x + B y + D)/C$, so comparing the
       two at the corners of the common (convex) region of the projections is exact.

    If all fail, P hides part of Q: Q is moved to the head of the list and marked. A marked Q met again
    closes a cycle (marks last until the next polygon is painted): Q is split by P's plane, or P by Q's, or
    else one member of the cycle by another's plane (one always straddles another's plane, or the members'
    planes would order them like a BSP tree), and the fragments replace it. Two polygons that pierce each
    other are split the same way at once. When no test passes and no split is possible within the
    tolerance, P is painted as is and counted in ``unresolved_count``.

    Parameters
    ----------
    polygons : sequence of (k, 3) array_like
        Convex planar polygons in world coordinates.
    camera : Camera
    ids : (len(polygons),) array_like of int, optional
        Labels returned with the fragments; default 0, 1, 2, ….
    record : callable, optional
        ``record(event, **values)`` (``frustum.steps``): ``"sorted"`` (the list by z_max), ``"test"`` (which of
        the tests 1–4 showed that P cannot hide Q), ``"hides"``, ``"move"``, ``"split"``, ``"paint"``,
        ``"unresolved"``; items are numbered as created (a split's parts get new numbers).

    Returns
    -------
    DepthOrder

    Raises
    ------
    GeometryError
        For a malformed polygon or ids.
    CameraError
        If `camera` is not a Camera.

    References
    ----------
    [HB 16] "Depth-Sorting Method"; M. E. Newell, R. G. Newell, T. L. Sancha, "A solution to the hidden
    surface problem", Proc. ACM National Conference, 1972.
    """
    where = "depth_sort"
    polys, labels = _check_polygons(polygons, ids, where)
    if not isinstance(camera, Camera):
        raise CameraError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera")
    tolerance = _scene_tolerance(polys)
    area_tolerance = tolerance**2
    clip_from_world = np.asarray(camera.clip_from_world)
    near_plane = clip_from_world[2] + clip_from_world[3]  # z_c + w_c >= 0: on the far side of the near plane
    near_plane = near_plane / np.linalg.norm(near_plane[:3])
    kept: list[tuple[Polygon, int, NDArray]] = []
    degenerate = clipped = 0
    for vertices, label in zip(polys, labels.tolist(), strict=True):
        if _polygon_area(vertices) <= area_tolerance:
            degenerate += 1
            continue
        inside, outside = _split(vertices, near_plane, tolerance)
        if outside is not None:
            clipped += 1
            if inside is None or _polygon_area(inside) <= area_tolerance:
                continue
        kept.append((inside, int(label), _plane(vertices)))
    sorter = _DepthSorter(clip_from_world, kept, tolerance, record)
    fragments = sorter.run()
    return DepthOrder(fragments, sorter.split_count, degenerate, clipped, sorter.unresolved_count)


class _DepthSorter:
    """State of one Newell–Newell–Sancha sort in normalized screen space (see ``depth_sort``)."""

    def __init__(
        self, clip_from_world: NDArray, kept: list[tuple[Polygon, int, NDArray]], tolerance: float, record: Any = None
    ) -> None:
        self.record = record
        self.clip_from_world = clip_from_world
        self.world_tolerance = tolerance
        self.area_tolerance = tolerance**2
        self.tolerance = 3.0 * _RELATIVE_TOLERANCE  # the screen box is rescaled to [0, 1]³
        self.split_count = 0
        self.unresolved_count = 0
        if kept:
            ndc = self._ndc(np.concatenate([item[0] for item in kept]))
            self.offset = ndc.min(axis=0)
            extent = ndc.max(axis=0) - self.offset
            self.scale = np.where(extent > 0.0, extent, 1.0)
        self.bounds = np.empty((max(2 * len(kept), 16), 6))  # low and high corner of each item, growing
        self.items: list[_SortItem] = []
        for world, label, plane in kept:
            self._add(self._item(world, label, plane))

    def _add(self, item: _SortItem) -> int:
        index = len(self.items)
        if index == len(self.bounds):
            self.bounds = np.concatenate([self.bounds, np.empty_like(self.bounds)])
        self.bounds[index, :3], self.bounds[index, 3:] = item.low, item.high
        self.items.append(item)
        return index

    def _ndc(self, points: Polygon) -> Polygon:
        clip = points @ self.clip_from_world[:, :3].T + self.clip_from_world[:, 3]
        return clip[:, :3] / clip[:, 3:]

    def _item(self, world: Polygon, label: int, world_plane: NDArray) -> _SortItem:
        screen = (self._ndc(world) - self.offset) / self.scale
        normal = _vector_area(screen)
        length = float(np.linalg.norm(normal))
        projected_area = abs(float(normal[2]))
        if length == 0.0 or projected_area <= 1e-12:  # edge-on: covers no area on the screen
            plane = np.zeros(4)
        else:
            normal = normal / length
            if normal[2] > 0.0:
                normal = -normal
            plane = np.append(normal, -normal @ screen.mean(axis=0))
        return _SortItem(read_only(world), label, world_plane, screen, plane, screen.min(axis=0), screen.max(axis=0))

    def _z_max(self, index: int) -> float:
        return float(self.bounds[index, 5])

    def run(self) -> list[tuple[Polygon, int]]:
        """The list of [HB 16], kept as `main`, sorted by z_max ascending (the farthest polygon last, so
        painting pops from the end), and `moved`, the polygons moved ahead of it (the head is the last one
        moved). A polygon can only hide Q with z_max(Q) > its z_min: a bisection finds those in `main`."""
        items = self.items
        edge_on = [i for i, item in enumerate(items) if item.plane[2] == 0.0]
        visible = [i for i, item in enumerate(items) if item.plane[2] != 0.0]
        order: list[tuple[Polygon, int]] = [(items[i].world, items[i].label) for i in edge_on]  # paint nothing
        z_max = np.array([self._z_max(i) for i in visible])
        main = [visible[i] for i in np.argsort(z_max, kind="stable")]
        record = self.record
        if record is not None:
            record("sorted", order=list(main[::-1]), edge_on=list(edge_on), polygons=[item.world for item in items],
                   labels=[item.label for item in items])  # fmt: skip
        moved: list[int] = []
        # the chain of moves since the last paint or split: each polygon hides the next, so meeting a member
        # again closes a cycle
        chain: list[int] = []
        budget = 50 * len(main) + 1000  # steps before giving up on reordering (never reached in the tests)
        while moved or main:
            budget -= 1
            head = moved[-1] if moved else main[-1]
            conflict = self._first_conflict(head, self._candidates(head, moved, main)) if budget > 0 else None
            if conflict is None:
                order.append((items[head].world, items[head].label))
                (moved if moved else main).pop()
                chain.clear()
                if record is not None:
                    record("paint", item=head, label=items[head].label)
                continue
            q, pierce = conflict
            if record is not None:
                record("hides", p=head, q=q, pierce=pierce)
            if not pierce and q not in chain:  # P hides Q, Q does not hide P: paint Q first
                chain.extend([head, q] if not chain else [q])
                (moved if q in moved else main).remove(q)
                moved.append(q)
                if record is not None:
                    record("move", p=head, q=q)
                continue
            # piercing polygons or a cycle: split Q by P's plane, else P by Q's plane, else one member of the
            # cycle by the plane of another
            cycle = chain[chain.index(q) :] if q in chain else [head, q]
            chain.clear()
            if self._replace_split(q, head, moved, main) or self._replace_split(head, q, moved, main):
                continue
            if self._split_cycle(cycle, moved, main):
                continue
            self.unresolved_count += 1
            if record is not None:
                record("unresolved", item=head)
            order.append((items[head].world, items[head].label))
            (moved if moved else main).pop()
        return order

    def _candidates(self, head: int, moved: list[int], main: list[int]) -> list[int]:
        """Polygons P = head might hide, in list order: the other moved ones, then those of `main` whose
        z_max exceeds z_min(P) (a suffix of `main`), farthest first."""
        start = bisect.bisect_right(main, float(self.bounds[head, 2]) + self.tolerance, key=self._z_max)
        deeper = main[start:][::-1]
        return [i for i in moved[::-1] if i != head] + [i for i in deeper if i != head]

    def _replace_split(self, victim: int, by: int, moved: list[int], main: list[int]) -> bool:
        """Split item `victim` by the world plane of `by` and put the parts in its place; True if it fell in two."""
        item = self.items[victim]
        if not self._straddles(item.screen, self.items[by].plane):
            return False
        front, back = _split(item.world, self.items[by].world_plane, self.world_tolerance)
        if front is None or back is None:
            return False
        parts = [p for p in (front, back) if _polygon_area(p) > self.area_tolerance]
        if len(parts) < 2:
            return False
        new = [self._add(self._item(part, item.label, item.world_plane)) for part in parts]
        if self.record is not None:
            self.record("split", victim=victim, by=by, parts=new, polygons=[self.items[i].world for i in new])
        if victim in moved:
            position = moved.index(victim)
            moved[position : position + 1] = new
        else:
            main.remove(victim)
            for index in new:
                bisect.insort_right(main, index, key=self._z_max)
        self.split_count += 1
        return True

    def _split_cycle(self, cycle: list[int], moved: list[int], main: list[int]) -> bool:
        """Split the first member of `cycle` that straddles another member's plane (one always does for a true
        cycle: were there none, the members' own planes would order them, as a BSP tree without splits)."""
        for victim in cycle:
            for by in cycle:
                if victim != by and self._replace_split(victim, by, moved, main):
                    return True
        return False

    def _straddles(self, screen: Polygon, plane: NDArray) -> bool:
        distances = screen @ plane[:3] + plane[3]
        return bool(distances.max() > self.tolerance and distances.min() < -self.tolerance)

    def _first_conflict(self, head: int, candidates: list[int]) -> tuple[int, bool] | None:
        """First Q among `candidates` that P = items[head] hides in part: (Q, pierce).

        `pierce` is False when Q is wholly behind P where they overlap (a reorder fixes it), True when their
        depths cross inside the overlap (they pierce each other: only a split fixes it).
        """
        items, eps = self.items, self.tolerance
        p = items[head]
        if not candidates:
            return None
        rest = np.array(candidates)
        bounds = self.bounds[rest]
        low, high = bounds[:, :3], bounds[:, 3:]
        # depth ranges overlap (Q reaches farther than P's nearest point), then test 1: bounding rectangles
        overlap = (high[:, 2] > p.low[2] + eps) & (low[:, :2] < p.high[:2] - eps).all(axis=1)
        overlap &= (high[:, :2] > p.low[:2] + eps).all(axis=1)
        record = self.record
        if record is not None:
            for k in np.flatnonzero(~overlap):
                record("test", p=head, q=int(rest[k]), passed=1)
        for k in np.flatnonzero(overlap):
            q = items[int(rest[k])]
            # test 2: P wholly behind Q's plane; test 3: Q wholly in front of P's plane
            if (p.screen @ q.plane[:3] + q.plane[3]).max() <= eps:
                if record is not None:
                    record("test", p=head, q=int(rest[k]), passed=2)
                continue
            if (q.screen @ p.plane[:3] + p.plane[3]).min() >= -eps:
                if record is not None:
                    record("test", p=head, q=int(rest[k]), passed=3)
                continue
            # test 4: the common region of the projections, and the depth difference at its corners
            region = _convex_intersection(p.screen[:, :2], q.screen[:, :2], eps)
            if region is None:
                if record is not None:
                    record("test", p=head, q=int(rest[k]), passed=4)
                continue
            depth_p = -(region @ p.plane[:2] + p.plane[3]) / p.plane[2]
            depth_q = -(region @ q.plane[:2] + q.plane[3]) / q.plane[2]
            difference = depth_p - depth_q  # > 0 where P is farther
            # a plane's depth carries its on-plane tolerance divided by |C| (steep planes amplify round-off)
            depth_eps = eps * (1.0 / abs(p.plane[2]) + 1.0 / abs(q.plane[2]))
            if difference.min() >= -depth_eps:
                if record is not None:
                    record("test", p=head, q=int(rest[k]), passed=4)
                continue
            return int(rest[k]), bool(difference.max() > depth_eps)
        return None


def _ccw(polygon: NDArray) -> NDArray:
    x, y = polygon[:, 0], polygon[:, 1]
    area = float((x * np.roll(y, -1) - np.roll(x, -1) * y).sum())
    return polygon if area >= 0.0 else polygon[::-1]


def _convex_intersection(a: NDArray, b: NDArray, eps: float) -> NDArray | None:
    """Common region of two convex 2D polygons (Sutherland–Hodgman), or None if it has no interior."""
    region = _ccw(a)
    clipper = _ccw(b)
    for i in range(len(clipper)):
        if len(region) == 0:
            return None
        start, end = clipper[i], clipper[(i + 1) % len(clipper)]
        edge = end - start
        length = float(np.hypot(*edge))
        if length == 0.0:
            continue
        # signed distance to the left of the edge (inside for a counter-clockwise clipper)
        inside = (edge[0] * (region[:, 1] - start[1]) - edge[1] * (region[:, 0] - start[0])) / length
        if inside.min() >= -eps:
            continue
        if inside.max() <= eps:
            return None
        points = []
        count = len(region)
        for j in range(count):
            k = (j + 1) % count
            if inside[j] >= 0.0:
                points.append(region[j])
            if (inside[j] >= 0.0) != (inside[k] >= 0.0):
                t = inside[j] / (inside[j] - inside[k])
                points.append(region[j] + t * (region[k] - region[j]))
        region = np.array(points) if points else np.empty((0, 2))
    if len(region) < 3:
        return None
    x, y = region[:, 0], region[:, 1]
    if abs(float((x * np.roll(y, -1) - np.roll(x, -1) * y).sum())) / 2 <= eps * eps:
        return None
    return region
