"""The painter's depth sort of Newell, Newell and Sancha: the polygons of a scene back to front, split where no order
exists.

Sort by greatest depth, then check each polygon P against the polygons Q whose depth ranges overlap it with the
textbook tests (1) bounding rectangles disjoint, (2) P wholly behind Q's plane, (3) Q wholly in front of P's plane,
(4) projections disjoint; here (4) is made exact by intersecting the projections and comparing the two plane
depths at the corners of their common region. A Q that P hides moves to the head of the list; a Q already moved
once means a cyclic overlap (or two polygons that pierce each other), resolved by splitting along a plane. The
plane tests, the splitting and the tolerance are ``visibility.polygons`` (shared with ``visibility.bsp``).

References
----------
[HB 16] "Depth-Sorting Method".
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import describe, read_only
from frustum.camera import Camera
from frustum.errors import CameraError
from frustum.visibility.polygons import (
    RELATIVE_TOLERANCE,
    Polygon,
    check_polygons,
    plane_of,
    polygon_area,
    scene_tolerance,
    split_polygon,
    vector_area,
)

__all__ = ["DepthOrder", "depth_sort"]


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
    polys, labels = check_polygons(polygons, ids, where)
    if not isinstance(camera, Camera):
        raise CameraError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera")
    tolerance = scene_tolerance(polys)
    area_tolerance = tolerance**2
    clip_from_world = np.asarray(camera.clip_from_world)
    near_plane = clip_from_world[2] + clip_from_world[3]  # z_c + w_c >= 0: on the far side of the near plane
    near_plane = near_plane / np.linalg.norm(near_plane[:3])
    kept: list[tuple[Polygon, int, NDArray]] = []
    degenerate = clipped = 0
    for vertices, label in zip(polys, labels.tolist(), strict=True):
        if polygon_area(vertices) <= area_tolerance:
            degenerate += 1
            continue
        inside, outside = split_polygon(vertices, near_plane, tolerance)
        if outside is not None:
            clipped += 1
            if inside is None or polygon_area(inside) <= area_tolerance:
                continue
        kept.append((inside, int(label), plane_of(vertices)))
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
        self.tolerance = 3.0 * RELATIVE_TOLERANCE  # the screen box is rescaled to [0, 1]³
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
        normal = vector_area(screen)
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
        front, back = split_polygon(item.world, self.items[by].world_plane, self.world_tolerance)
        if front is None or back is None:
            return False
        parts = [p for p in (front, back) if polygon_area(p) > self.area_tolerance]
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
