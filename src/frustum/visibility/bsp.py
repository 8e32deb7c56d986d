"""The BSP tree: object-space visible-surface ordering for filled vector output, view-independent.

``BSPTree`` partitions space by the plane of one polygon at each node; polygons that straddle the plane are split
into a front and a back fragment. The tree depends on the scene only, and any viewing position reads it back to
front in linear time: at each node draw first the side of the plane away from the viewer, then the node's own
polygons, then the viewer's side. Fragments stay convex polygons. A group of polygons that all lie behind each
other's planes (a convex polyhedron) is kept as one leaf, a convex cell, painted faces-turned-away first: that keeps
a convex mesh at one node instead of a chain of one node per face. Painting the fragments in that order (later
polygons cover earlier ones) gives the picture a depth buffer gives, where there is no per-pixel depth (SVG, PDF).

The painter's depth sort (Newell–Newell–Sancha) is ``visibility.depth_sort``; the plane tests, the splitting and
the tolerance both use are ``visibility.polygons``.

References
----------
[HB 16] "BSP-Tree Method"; [seed] "BSP Trees" (General Modeling Techniques).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_vector3, describe, read_only
from frustum.camera import Camera
from frustum.errors import CameraError, GeometryError
from frustum.geometry import Mesh
from frustum.transforms import apply
from frustum.visibility.polygons import (
    Polygon,
    check_polygons,
    plane_of,
    polygon_area,
    scene_tolerance,
    split_polygon,
)

__all__ = ["BSPTree"]

_SPLIT_WEIGHT = 8
"""Splitter score = 8 · (polygons split) + |front − back|: fewer fragments first, balance second."""
_SPLITTER_CANDIDATES = 8
"""At most this many polygons (evenly spaced in the node's list) are tried as the splitting plane."""
_SPLITTER_SAMPLE = 256
"""Splitter candidates are scored on at most this many polygons (evenly spaced) of the node's list."""
_DIRECTION_TOLERANCE = 1e-12
_MAX_CORNERS = 8
"""Polygons are stored with at most this many corners (padded); a larger one is stored as several pieces."""


def _pieces(polygon: Polygon, area_tolerance: float) -> list[Polygon]:
    """The polygon as pieces of at most 8 corners (fans P0, P_j, …, P_j+6 beyond that), zero-area ones dropped."""
    if len(polygon) <= _MAX_CORNERS:
        pieces = [polygon]
    else:
        span = _MAX_CORNERS - 2
        pieces = [
            np.concatenate((polygon[:1], polygon[j : j + _MAX_CORNERS - 1])) for j in range(1, len(polygon) - 1, span)
        ]
    return [piece for piece in pieces if len(piece) >= 3 and polygon_area(piece) > area_tolerance]


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
        if polygon_area(polygon) <= area_tolerance:
            degenerate += 1
            continue
        planes[i] = plane_of(polygon)
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
        polys, labels = check_polygons(polygons, ids, "BSPTree")
        self.tolerance = scene_tolerance(polys)
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
                front, back = split_polygon(self._corners[index, : self._counts[index]], plane, eps)
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
