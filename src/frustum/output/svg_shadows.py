"""Exact shadow polygons for vector drawings: the object-space shadow method (sciagraphy).

"Apply a hidden-surface method with the light source at the view position" [HB 17, "Shadows"], in object space:
for each face F of the scene (its side toward the camera), every other face G is clipped to the part of space
between F's plane and the light, projected from the light onto F's plane (parallel projection along a directional
light's rays, central projection from a point light) and clipped to F; the union of those projections is F's cast
shadow. A face whose camera side is turned away from the light is wholly in shade (an attached shadow). Then
the visible parts from the camera: every face H is clipped to the camera's side of F's plane and projected to the
window; what of F's shadow lies under those projections is hidden (a point of H in front of F's plane that
projects onto a point of F lies between it and the eye, so this is exact for planar faces). The pieces of each
face plane of each item are merged into outlines (holes included).

All polygon work is convex clipping (Sutherland–Hodgman against one line at a time), differences as disjoint
convex pieces, and unions by cancelling the edges two pieces share: every vertex is an intersection computed in
float64 from the scene's own coordinates, with no rounding to a grid. Which faces meet which is found through
bounding boxes in a uniform grid (``_Grid``), never by trying all pairs: the casters of a face are the faces whose
boxes in the light's projection (parallel: the plane across the light's direction; point: the six faces of a cube
around the light) overlap its own, the faces that may hide it those whose window boxes overlap its shadow's, and
a piece is subtracted or merged only against pieces whose boxes it overlaps. Every test is conservative (boxes
that miss cannot produce a piece), so the polygons are those of all pairs.

``shadow_polygons(scene, camera)`` returns the polygons in window coordinates (y up); ``shadow_group`` writes
them as the SVG group ``<g id="shadows">`` of ``<path>`` elements (absolute M/L/Z, even-odd fill), gray with
``fill=True`` and hatched otherwise.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from frustum.camera import Camera
from frustum.errors import OutputError
from frustum.geometry import Mesh
from frustum.scene import Scene
from frustum.shading import DirectionalLight, PointLight

__all__ = ["ShadowPolygon", "shadow_group", "shadow_polygons"]

_EPSILON = 1e-12
"""Relative tolerance (of the scene's size) for points on a plane and for empty pieces."""


class ShadowPolygon(NamedTuple):
    """One merged shadow region: the light's index among the scene's directional and point lights that cast
    shadows, the receiving item's index in ``scene.items``, ``kind`` ("cast" or "attached": the face turned from
    the light) and the outline loops (each (n, 2) float64 window coordinates, y up; outer loops counter-
    clockwise, holes clockwise)."""

    light: int
    item: int
    kind: str
    loops: list[NDArray[np.float64]]

    @property
    def area(self) -> float:
        """Signed area sum of the loops (holes subtract), in square pixels."""
        return float(sum(_signed_area(loop) for loop in self.loops))


# --- convex polygons in the plane ---------------------------------------------------------------------------


def _signed_area(polygon: NDArray) -> float:
    x, y = polygon[:, 0], polygon[:, 1]
    following = np.concatenate((polygon[1:], polygon[:1]))  # np.roll(polygon, -1, axis=0), without its overhead
    return 0.5 * float(np.dot(x, following[:, 1]) - np.dot(following[:, 0], y))


def _clip_half_plane(polygon: NDArray, normal: Any, offset: float) -> NDArray:
    """The part of a convex polygon (n, 2) where $normal·p + offset >= 0$ (Sutherland–Hodgman, one edge). Plain
    Python floats inside: a polygon has a handful of corners, too few for NumPy's per-call cost."""
    count = polygon.shape[0]
    if count == 0:
        return polygon
    n0, n1 = float(normal[0]), float(normal[1])
    points = polygon.tolist()
    side = [x * n0 + y * n1 + offset for x, y in points]
    if min(side) >= 0.0:
        return polygon
    if max(side) <= 0.0:
        return polygon[:0]
    out = []
    for i in range(count):
        j = (i + 1) % count
        (px, py), (qx, qy) = points[i], points[j]
        sp, sq = side[i], side[j]
        if sp >= 0.0:
            out.append((px, py))
        if (sp > 0.0 > sq) or (sp < 0.0 < sq):
            t = sp / (sp - sq)
            out.append((px + t * (qx - px), py + t * (qy - py)))
    return _distinct(np.array(out, dtype=np.float64).reshape(-1, 2))


def _distinct(polygon: NDArray) -> NDArray:
    """The polygon without repeated consecutive corners (a clip through a corner adds it twice)."""
    count = polygon.shape[0]
    if count < 2:
        return polygon
    points = polygon.tolist()
    limit = _EPSILON * max(1.0, max(abs(v) for point in points for v in point))
    keep = [max(abs(points[i][0] - points[i - 1][0]), abs(points[i][1] - points[i - 1][1])) > limit
            for i in range(count)]  # fmt: skip
    if all(keep):
        return polygon
    return polygon[np.array(keep)] if any(keep) else polygon[:1]


def _edge_lines(polygon: NDArray) -> list[tuple[tuple[float, float], float]]:
    """Inward half-planes ``((n0, n1), offset)`` of a counter-clockwise convex polygon's edges."""
    lines = []
    points = polygon.tolist()
    count = len(points)
    for i in range(count):
        (px, py), (qx, qy) = points[i], points[(i + 1) % count]
        n0, n1 = -(qy - py), qx - px
        if abs(n0) + abs(n1) > _EPSILON * max(1.0, abs(px) + abs(py)):  # a repeated corner: no edge
            lines.append(((n0, n1), -(n0 * px + n1 * py)))
    return lines


def _intersect(a: NDArray, b: NDArray) -> NDArray:
    for normal, offset in _edge_lines(b):
        a = _clip_half_plane(a, normal, offset)
        if a.shape[0] < 3:
            return a[:0]
    return a


def _subtract(a: NDArray, b: NDArray, tiny: float) -> list[NDArray]:
    """$a − b$ for convex counter-clockwise polygons, as disjoint convex pieces."""
    if _intersect(a, b).shape[0] < 3 or abs(_signed_area(_intersect(a, b))) <= tiny:
        return [a]
    pieces = []
    rest = a
    for (n0, n1), offset in _edge_lines(b):
        outside = _clip_half_plane(rest, (-n0, -n1), -offset)
        if outside.shape[0] >= 3 and abs(_signed_area(outside)) > tiny:
            pieces.append(outside)
        rest = _clip_half_plane(rest, (n0, n1), offset)
        if rest.shape[0] < 3:
            break
    return pieces


def _ccw(polygon: NDArray) -> NDArray:
    return polygon if _signed_area(polygon) >= 0.0 else polygon[::-1].copy()


def _box(polygon: NDArray) -> list[float]:
    """The polygon's 2D bounding box: [low x, low y, high x, high y]."""
    xs, ys = polygon[:, 0].tolist(), polygon[:, 1].tolist()
    return [min(xs), min(ys), max(xs), max(ys)]


class _Grid:
    """Boxes (N, 4) (low x, low y, high x, high y) in a uniform grid of about N cells over their extent: ``query``
    gives the boxes that overlap a box (touching counts), in increasing order; NaN rows are candidates of every
    query, and the rows marked in `left_out` of none."""

    def __init__(self, boxes: NDArray, left_out: NDArray | None = None) -> None:
        self.boxes = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
        count = self.boxes.shape[0]
        kept = np.ones(count, dtype=bool) if left_out is None else ~left_out
        finite = np.isfinite(self.boxes).all(axis=1) & kept
        self.always = np.flatnonzero(~finite & kept)  # boxes without finite bounds: candidates of every query
        good = self.boxes[finite]
        if good.shape[0] == 0:
            self.low, self.cell, self.shape = np.zeros(2), np.ones(2), (1, 1)
            self.starts, self.members = np.zeros(2, dtype=np.int64), np.zeros(0, dtype=np.int64)
            return
        self.low = good[:, :2].min(axis=0)
        extent = np.maximum(good[:, 2:].max(axis=0) - self.low, 1e-300)
        side = max(1, int(math.sqrt(count)))
        self.shape = (side, side)
        self.cell = extent / side
        first, last = self._cells(good[:, :2]), self._cells(good[:, 2:])
        spans = (last - first + 1).prod(axis=1)
        owner = np.repeat(np.flatnonzero(finite), spans)
        offset = np.arange(owner.shape[0]) - np.repeat(np.cumsum(spans) - spans, spans)
        width = np.repeat(last[:, 0] - first[:, 0] + 1, spans)
        cx = np.repeat(first[:, 0], spans) + offset % width
        cy = np.repeat(first[:, 1], spans) + offset // width
        cells = cx * side + cy
        order = np.argsort(cells, kind="stable")
        self.members = owner[order]
        self.starts = np.searchsorted(cells[order], np.arange(side * side + 1))

    def _cells(self, points: NDArray) -> NDArray:
        index = np.floor((points - self.low) / self.cell).astype(np.int64)
        return np.clip(index, 0, np.array(self.shape) - 1)

    def query(self, box: NDArray) -> NDArray:
        if not np.isfinite(box).all():
            return np.sort(np.concatenate([self.always, np.unique(self.members)]))
        first, last = self._cells(box[None, :2])[0], self._cells(box[None, 2:])[0]
        side = self.shape[1]
        found = [self.always]
        for cx in range(first[0], last[0] + 1):
            found.append(self.members[self.starts[cx * side + first[1]] : self.starts[cx * side + last[1] + 1]])
        candidates = np.unique(np.concatenate(found))
        boxes = self.boxes[candidates]
        hit = ~((boxes[:, 0] > box[2]) | (boxes[:, 2] < box[0]) | (boxes[:, 1] > box[3]) | (boxes[:, 3] < box[1]))
        return candidates[hit | ~np.isfinite(boxes).all(axis=1)]


def _overlapping(boxes: NDArray, box: NDArray) -> NDArray:
    """Indices of the rows of `boxes` (N, 4) that overlap `box` (touching counts)."""
    return np.flatnonzero(~((boxes[:, 0] > box[2]) | (boxes[:, 2] < box[0]) | (boxes[:, 1] > box[3])
                            | (boxes[:, 3] < box[1])))  # fmt: skip


def _disjoint_union(pieces: list[NDArray], tiny: float) -> list[NDArray]:
    """Disjoint convex pieces covering the union of convex `pieces` (each subtracted from the earlier result
    pieces whose boxes it overlaps: the others leave it whole)."""
    result: list[NDArray] = []
    boxes = np.empty((max(16, 4 * len(pieces)), 4))
    for piece in pieces:
        parts = [piece]
        for k in _overlapping(boxes[: len(result)], np.array(_box(piece))):
            parts = [rest for part in parts for rest in _subtract(part, result[k], tiny)]
            if not parts:
                break
        for part in parts:
            if len(result) == boxes.shape[0]:
                boxes = np.concatenate([boxes, np.empty_like(boxes)])
            boxes[len(result)] = _box(part)
            result.append(part)
    return result


def _outline(pieces: list[NDArray], scale: float) -> list[NDArray]:
    """Boundary loops of the union of disjoint convex counter-clockwise pieces: every edge split at the vertices
    lying on it, edges shared by two pieces (opposite directions) cancelled, the rest chained into loops, and
    vertices between collinear edges dropped."""
    if not pieces:
        return []
    tolerance = _EPSILON * scale * 1e3

    def thickness(piece: NDArray) -> float:
        perimeter = float(np.linalg.norm(np.roll(piece, -1, axis=0) - piece, axis=1).sum())
        return 2.0 * abs(_signed_area(piece)) / perimeter if perimeter > 0.0 else 0.0

    # slivers thinner than the tolerance that merges corners would chain into inconsistent loops: left out
    pieces = [piece for piece in pieces if thickness(piece) > tolerance]
    if not pieces:
        return []
    vertices = np.concatenate(pieces)
    vertices = vertices[np.argsort(vertices[:, 0], kind="stable")]
    xs = vertices[:, 0]
    segments = []
    for whole in pieces:
        count = whole.shape[0]
        for i in range(count):
            p, q = whole[i], whole[(i + 1) % count]
            d = q - p
            length2 = float(d @ d)
            if length2 == 0.0:
                continue
            # only vertices within the tolerance of the edge's x range can lie on it
            low = np.searchsorted(xs, min(p[0], q[0]) - 2.0 * tolerance, side="left")
            high = np.searchsorted(xs, max(p[0], q[0]) + 2.0 * tolerance, side="right")
            near = vertices[low:high]
            t = ((near - p) @ d) / length2
            across = np.abs((near - p) @ np.array([-d[1], d[0]])) / np.sqrt(length2)
            inside = (t > 1e-12) & (t < 1.0 - 1e-12) & (across <= tolerance)
            stops = sorted({float(v) for v in t[inside]})
            points = [p] + [near[np.flatnonzero(inside)[np.argmin(np.abs(t[inside] - s))]] for s in stops] + [q]
            segments.extend((points[k], points[k + 1]) for k in range(len(points) - 1))

    # corners within the tolerance are one corner: each joins the first one met within it (grid cells of the
    # tolerance, the 3 × 3 around it searched), so two corners either side of a cell boundary still meet
    cells: dict[tuple[int, int], list[tuple[float, float, int]]] = {}
    known: dict[tuple[float, float], int] = {}
    corners: list[NDArray] = []  # each merged corner's first point: the loops are written with these

    def key(point: NDArray) -> int:
        x, y = float(point[0]), float(point[1])
        found = known.get((x, y))
        if found is not None:
            return found
        cx, cy = math.floor(x / tolerance), math.floor(y / tolerance)
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for qx, qy, number in cells.get((cx + dx, cy + dy), ()):
                    if abs(qx - x) <= tolerance and abs(qy - y) <= tolerance:
                        known[(x, y)] = number
                        return number
        number = len(corners)
        corners.append(point)
        cells.setdefault((cx, cy), []).append((x, y, number))
        known[(x, y)] = number
        return number

    directed: dict[tuple, list[int]] = {}
    for index, (p, q) in enumerate(segments):
        directed.setdefault((key(p), key(q)), []).append(index)
    alive = set(range(len(segments)))
    for (start, end), indices in directed.items():
        opposite = directed.get((end, start), [])
        for a, b in zip(indices, opposite, strict=False):
            alive.discard(a)
            alive.discard(b)
    starts: dict[tuple, list[int]] = {}
    for index in sorted(alive):
        starts.setdefault(key(segments[index][0]), []).append(index)
    loops = []
    while alive:
        first = min(alive)
        loop = []
        index = first
        while index in alive:
            alive.discard(index)
            p, q = segments[index]
            if not loop or key(p) != key(loop[-1]):  # a corner met twice in a row (merged points): once
                loop.append(corners[key(p)])
            following = [i for i in starts.get(key(q), []) if i in alive]
            if not following:
                break
            index = following[0]
        if len(loop) > 1 and key(loop[0]) == key(loop[-1]):
            loop.pop()
        if len(loop) >= 3:
            loops.append(_without_collinear(np.array(loop), tolerance))
    return [loop for loop in loops if loop.shape[0] >= 3]


def _without_collinear(loop: NDArray, tolerance: float) -> NDArray:
    """The loop without corners lying on the line between their kept neighbours (within `tolerance`, and ahead of
    the previous one): each corner tested against the corners kept so far, so that of two corners closer than the
    tolerance one is kept (each tested against the original neighbours dropped both)."""

    def between(a: NDArray, b: NDArray, c: NDArray) -> bool:
        d = c - a
        length = float(np.hypot(d[0], d[1]))
        return length > 0.0 and abs((b - a) @ np.array([-d[1], d[0]])) / length <= tolerance and (b - a) @ d > 0.0

    kept: list[NDArray] = []
    for point in loop:
        kept.append(point)
        while len(kept) >= 3 and between(kept[-3], kept[-2], kept[-1]):
            del kept[-2]
    while len(kept) >= 3 and between(kept[-2], kept[-1], kept[0]):  # across the loop's start
        kept.pop()
    while len(kept) >= 3 and between(kept[-1], kept[0], kept[1]):
        kept.pop(0)
    return np.array(kept)


# --- faces, lights and projections --------------------------------------------------------------------------


class _Faces(NamedTuple):
    corners: NDArray  # (F, 3, 3) world
    item: NDArray  # (F,) int64
    normal: NDArray  # (F, 3) unit, turned toward the camera
    offset: NDArray  # (F,) plane offset: normal·x + offset = 0
    outward: NDArray  # (F, 3) unit outward normal of a face of a closed item (a watertight mesh), else 0
    bounds: NDArray  # (F, 2, 3) world box of the face's item


def _turned_away(faces: _Faces, point: NDArray | None, direction: NDArray | None) -> NDArray:
    """(F,) bool: faces of closed items whose outside is turned away from a viewpoint outside the item's box — the
    `point` (an eye, a point light) or at infinity toward `direction`. From outside a solid every line of sight
    enters it through a face turned toward the viewpoint first, nearer than any face turned away: a face turned
    away from the eye hides nothing and shows nothing, one turned away from the light shades nothing, that the
    faces turned toward them do not already (exact, and skipped)."""
    if point is not None:
        outside = ((point < faces.bounds[:, 0]) | (point > faces.bounds[:, 1])).any(axis=1)
        facing = (faces.outward * (point - faces.corners[:, 0])).sum(axis=1)
        return outside & (facing <= 0.0) & faces.outward.any(axis=1)
    return (faces.outward @ direction <= 0.0) & faces.outward.any(axis=1)


def _scene_faces(scene: Scene, camera: Camera) -> _Faces:
    corners, items, closed, boxes = [], [], [], []
    for index, item in enumerate(scene.items):
        mesh = item.mesh
        if not isinstance(mesh, Mesh) or mesh.face_count == 0 or item.material.opacity < 1.0:
            continue
        m = np.asarray(item.world_from_model, dtype=np.float64)
        world = mesh.vertices @ m[:3, :3].T + m[:3, 3]
        tri = world[mesh.faces]
        corners.append(tri)
        items.append(np.full(mesh.face_count, index))
        volume = float((tri[:, 0] * np.cross(tri[:, 1], tri[:, 2])).sum()) if mesh.is_watertight else 0.0
        closed.append(np.full(mesh.face_count, np.sign(volume)))  # +1: the faces' normals point out
        boxes.append(np.broadcast_to(np.stack([world.min(axis=0), world.max(axis=0)]), (mesh.face_count, 2, 3)))
    if not corners:
        empty = np.empty((0, 3))
        return _Faces(np.empty((0, 3, 3)), np.empty(0, dtype=np.int64), empty, np.empty(0), empty,
                      np.empty((0, 2, 3)))  # fmt: skip
    tri = np.concatenate(corners)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    good = length > 0.0
    tri, normal, item = tri[good], normal[good] / length[good, None], np.concatenate(items)[good]
    outward = normal * np.concatenate(closed)[good, None]
    offset = -(normal * tri[:, 0]).sum(axis=1)
    # the side toward the camera: a perspective eye, or the direction toward the viewer of a parallel camera
    eye = np.asarray(camera.frame.eye, dtype=np.float64)
    toward = (normal @ eye + offset) if not camera.projection.parallel else (normal @ np.asarray(camera.frame.n, float))
    flip = np.where(toward < 0.0, -1.0, 1.0)
    return _Faces(tri, item, normal * flip[:, None], offset * flip, outward, np.concatenate(boxes)[good])


def _clip_space(polygon: NDArray, normal: NDArray, offset: float, low: float, high: float | None) -> NDArray:
    """The part of a convex 3D polygon (n, 3) with $low < normal·x + offset$ (and ``< high`` if given)."""
    for sign, bound in ((1.0, low), (-1.0, high)):
        if bound is None or polygon.shape[0] == 0:
            continue
        side = sign * (polygon @ normal + offset - bound)
        if (side > 0.0).all():
            continue
        out = []
        count = polygon.shape[0]
        for i in range(count):
            p, q = polygon[i], polygon[(i + 1) % count]
            sp, sq = side[i], side[(i + 1) % count]
            if sp > 0.0:
                out.append(p)
            if (sp > 0.0 >= sq) or (sp <= 0.0 < sq):
                out.append(p + (sp / (sp - sq)) * (q - p))
        polygon = np.array(out).reshape(-1, 3)
    return polygon if polygon.shape[0] >= 3 else polygon[:0]


def _plane_frame(corners: NDArray, normal: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Origin and orthonormal axes (e1, e2) of the face's plane, e1 × e2 = normal."""
    e1 = corners[1] - corners[0]
    e1 = e1 / np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    return corners[0], e1, e2


def _to_window(points: NDArray, camera: Camera) -> NDArray:
    clip = points @ np.asarray(camera.clip_from_world)[:, :3].T + np.asarray(camera.clip_from_world)[:, 3]
    ndc = clip[:, :2] / clip[:, 3:]
    return np.column_stack([(ndc[:, 0] + 1.0) * (camera.width / 2.0), (ndc[:, 1] + 1.0) * (camera.height / 2.0)])


def _shadow_lights(scene: Scene) -> list[Any]:
    return [
        light for light in scene.world_lights()
        if isinstance(light, DirectionalLight | PointLight) and getattr(light, "cast_shadows", True)
    ]  # fmt: skip


def shadow_polygons(scene: Scene, camera: Camera) -> list[ShadowPolygon]:
    """The visible shadow regions of every directional and point light that casts shadows (spot lights are
    drawn as point lights: their cone is not a shadow), merged per light, receiving item and face plane.

    Returns
    -------
    list of ShadowPolygon
        Window coordinates (x right, y up, pixels), exact up to float64 round-off.
    """
    return _shadow_polygons(scene, camera, None)


def _shadow_polygons(scene: Scene, camera: Camera, receivers: NDArray | None) -> list[ShadowPolygon]:
    """``shadow_polygons`` of the faces (``_scene_faces`` order) marked in `receivers` (all where None)."""
    faces = _scene_faces(scene, camera)
    if faces.corners.shape[0] == 0:
        return []
    span = float(np.ptp(faces.corners.reshape(-1, 3), axis=0).max()) or 1.0
    eps = _EPSILON * span
    eye = np.asarray(camera.frame.eye, dtype=np.float64)
    windows = [_to_window(c, camera) for c in faces.corners]
    if camera.projection.parallel:
        hidden = _turned_away(faces, None, np.asarray(camera.frame.n, dtype=np.float64))
    else:
        hidden = _turned_away(faces, eye, None)
    covers = _Grid(_window_boxes(faces, camera, windows), hidden)
    size = float(max(camera.width, camera.height))
    tiny = (_EPSILON * size) ** 2
    result = []
    for light_index, light in enumerate(_shadow_lights(scene)):
        groups: dict[tuple, list[NDArray]] = {}
        light_boxes = _light_boxes(faces.corners, light)
        if isinstance(light, DirectionalLight):
            dark = _turned_away(faces, None, -np.asarray(light.direction, dtype=np.float64))
        else:
            dark = _turned_away(faces, np.asarray(light.position, dtype=np.float64), None)
        casters = _Grid(light_boxes, dark)
        for f in range(faces.corners.shape[0]):
            if hidden[f] or (receivers is not None and not receivers[f]):
                continue
            n, c = faces.normal[f], faces.offset[f]
            if isinstance(light, DirectionalLight):
                lit_side = float(n @ -np.asarray(light.direction))
            else:
                lit_side = float(n @ np.asarray(light.position) + c)
            if lit_side <= 0.0:  # the camera side faces away from the light: all in shade
                pieces_3d = [faces.corners[f]]
                kind = "attached"
            else:
                pieces_3d = _cast_on_face(faces, f, light, eps, casters.query(light_boxes[f]))
                kind = "cast"
            if not pieces_3d:
                continue
            # the visible parts: minus the window images of faces in front of F's plane (camera side)
            pieces = [_ccw(_to_window(p, camera)) for p in pieces_3d]
            pieces = _disjoint_union([p for p in pieces if abs(_signed_area(p)) > tiny], tiny)
            near = np.zeros(0, dtype=np.int64)
            if pieces:
                bounds = np.array([_box(piece) for piece in pieces])
                near = covers.query(np.concatenate([bounds[:, :2].min(axis=0), bounds[:, 2:].max(axis=0)]))
                near = near[near != f]
                near = near[((faces.corners[near] @ n + c) > eps).any(axis=1)]
            boxes = np.array([_box(piece) for piece in pieces]).reshape(-1, 4)
            for h in near:
                if not pieces:
                    break
                if camera.projection.parallel:
                    front = _clip_space(faces.corners[h], n, c, eps, None)
                else:
                    front = _clip_space(faces.corners[h], n, c, eps, float(n @ eye + c))
                if front.shape[0] < 3:
                    continue
                cover = _ccw(_to_window(front, camera) if front is not faces.corners[h] else windows[h])
                hit = _overlapping(boxes, np.array(_box(cover)))
                if hit.size == 0:
                    continue
                for k in hit[::-1].tolist():  # from the end: the earlier indices stay valid
                    rests = _subtract(pieces[k], cover, tiny)
                    if len(rests) == 1 and rests[0] is pieces[k]:
                        continue
                    pieces[k : k + 1] = rests
                    boxes = np.concatenate([boxes[:k], np.array([_box(r) for r in rests]).reshape(-1, 4),
                                            boxes[k + 1 :]])  # fmt: skip
            key = (faces.item[f], kind, *np.round(np.append(n, c / span), 9))
            groups.setdefault(key, []).extend(pieces)
        for (item, kind, *_), pieces in groups.items():
            loops = _outline(pieces, size)
            if loops:
                result.append(ShadowPolygon(light_index, int(item), kind, loops))
    return result


def _window_boxes(faces: _Faces, camera: Camera, windows: list[NDArray]) -> NDArray:
    """(F, 4) window boxes of the faces; NaN rows (candidates of every query) for faces not wholly in front of a
    perspective eye, whose clipped parts may project anywhere."""
    boxes = np.array([_box(w) for w in windows]).reshape(-1, 4)
    if not camera.projection.parallel:
        clip = np.asarray(camera.clip_from_world, dtype=np.float64)
        w = faces.corners @ clip[3, :3] + clip[3, 3]
        boxes[~(w > 0.0).all(axis=1)] = np.nan
    return boxes


_AXES = np.eye(3)


def _light_boxes(corners: NDArray, light: Any) -> NDArray:
    """(F, 4) boxes of the faces (F, 3, 3) in the light's projection: a face can shade another only where these
    overlap. A directional light: coordinates across its direction. A point light: the face of the cube around
    the light that the face lies in (its corners' major axis and sign), at coordinates (a, b) / |m| on it, offset
    by 4 per cube face so that faces on different cube faces never meet; NaN rows (candidates of every query)
    for faces reaching over a cube edge or through the light."""
    if isinstance(light, DirectionalLight):
        direction = np.asarray(light.direction, dtype=np.float64)
        direction = direction / np.linalg.norm(direction)
        u = np.cross(direction, _AXES[int(np.argmin(np.abs(direction)))])
        u /= np.linalg.norm(u)
        v = np.cross(direction, u)
        a, b = corners @ u, corners @ v
        return np.stack([a.min(axis=1), b.min(axis=1), a.max(axis=1), b.max(axis=1)], axis=1)
    d = corners - np.asarray(light.position, dtype=np.float64)  # (F, 3, 3)
    major = np.argmax(np.abs(d), axis=2)  # (F, 3)
    along = np.take_along_axis(d, major[..., None], axis=2)[..., 0]
    cube = major * 2 + (along > 0.0)
    m = np.abs(along)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.take_along_axis(d, ((major + 1) % 3)[..., None], axis=2)[..., 0] / m
        b = np.take_along_axis(d, ((major + 2) % 3)[..., None], axis=2)[..., 0] / m
    shift = 4.0 * cube[:, 0]
    boxes = np.stack([a.min(axis=1) + shift, b.min(axis=1), a.max(axis=1) + shift, b.max(axis=1)], axis=1)
    boxes[~(cube == cube[:, :1]).all(axis=1) | ~(m > 0.0).all(axis=1)] = np.nan
    return boxes


def _cast_on_face(faces: _Faces, f: int, light: Any, eps: float, candidates: NDArray) -> list[NDArray]:
    """The shadow on face f (3D convex pieces in its plane) of the `candidates` among the other faces (every face
    whose shadow can reach f is among them: ``_light_boxes``), clipped to f."""
    n, c = faces.normal[f], faces.offset[f]
    origin, e1, e2 = _plane_frame(faces.corners[f], n)
    face_2d = _ccw(np.stack([(faces.corners[f] - origin) @ e1, (faces.corners[f] - origin) @ e2], axis=1))
    directional = isinstance(light, DirectionalLight)
    if directional:
        direction = np.asarray(light.direction, dtype=np.float64)
        high = None
    else:
        position = np.asarray(light.position, dtype=np.float64)
        high = float(n @ position + c)
    pieces = []
    heights = faces.corners[candidates] @ n + c  # (K, 3)
    candidates = candidates[(heights > eps).any(axis=1)]
    for g in candidates:
        if g == f:
            continue
        part = _clip_space(faces.corners[g], n, c, eps, None if high is None else high - eps)
        if part.shape[0] < 3:
            continue
        d = part @ n + c
        if directional:  # along the rays: x' = x + t·u with n·x' + c = 0
            projected = part - (d / float(n @ direction))[:, None] * direction[None, :]
        else:  # from the point light: x' = L + s·(x − L), s = h_L / (h_L − h_x)
            s = high / (high - d)
            projected = position[None, :] + s[:, None] * (part - position[None, :])
        flat = _ccw(np.stack([(projected - origin) @ e1, (projected - origin) @ e2], axis=1))
        piece = _intersect(flat, face_2d)
        if piece.shape[0] >= 3 and abs(_signed_area(piece)) > eps * eps:
            pieces.append(origin[None, :] + piece[:, :1] * e1[None, :] + piece[:, 1:] * e2[None, :])
    if not pieces:
        return []
    flat_pieces = [np.stack([(p - origin) @ e1, (p - origin) @ e2], axis=1) for p in pieces]
    disjoint = _disjoint_union(flat_pieces, eps * eps)
    return [origin[None, :] + p[:, :1] * e1[None, :] + p[:, 1:] * e2[None, :] for p in disjoint]


# the same as output.svg._number, kept apart on purpose: svg imports this module (no import circle)
def _number(value: float) -> str:
    value = float(value)
    if value == 0.0:
        return "0"
    text = repr(value)
    return text[:-2] if text.endswith(".0") else text


def shadow_group(scene: Scene, camera: Camera, fill: bool) -> str:
    """``<g id="shadows">`` of the scene's shadow polygons (SVG y down): one ``<path>`` per merged region, filled
    translucent gray over the faces (``fill=True``) or hatched at 45° (line drawings)."""
    if not isinstance(camera, Camera):
        raise OutputError("render_svg: shadows need a Camera")
    height = float(camera.height)
    paths = []
    for polygon in shadow_polygons(scene, camera):
        d = " ".join(
            "M " + " L ".join(f"{_number(x)} {_number(height - y)}" for x, y in loop) + " Z" for loop in polygon.loops
        )
        paths.append(f'<path d="{d}" class="{polygon.kind}" data-light="{polygon.light}" data-item="{polygon.item}"/>')
    if fill:
        style = 'fill="#000000" fill-opacity="0.35" fill-rule="evenodd" stroke="none"'
        defs = ""
    else:
        style = 'fill="url(#shadow-hatch)" fill-rule="evenodd" stroke="#000000" stroke-width="0.4"'
        defs = (
            '<defs><pattern id="shadow-hatch" patternUnits="userSpaceOnUse" width="4" height="4" '
            'patternTransform="rotate(45)"><line x1="0" y1="0" x2="0" y2="4" stroke="#000000" '
            'stroke-width="0.6"/></pattern></defs>'
        )
    return f'{defs}<g id="shadows" {style}>{"".join(paths)}</g>'
