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
float64 from the scene's own coordinates, with no rounding to a grid. The cost grows with the product of the
face counts: meant for drawings of up to a few hundred faces.

``shadow_polygons(scene, camera)`` returns the polygons in window coordinates (y up); ``shadow_group`` writes
them as the SVG group ``<g id="shadows">`` of ``<path>`` elements (absolute M/L/Z, even-odd fill), gray with
``fill=True`` and hatched otherwise.
"""

from __future__ import annotations

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
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _clip_half_plane(polygon: NDArray, normal: NDArray, offset: float) -> NDArray:
    """The part of a convex polygon (n, 2) where $normal·p + offset >= 0$ (Sutherland–Hodgman, one edge)."""
    if polygon.shape[0] == 0:
        return polygon
    side = polygon @ normal + offset
    if (side >= 0.0).all():
        return polygon
    if (side <= 0.0).all():
        return polygon[:0]
    out = []
    count = polygon.shape[0]
    for i in range(count):
        p, q = polygon[i], polygon[(i + 1) % count]
        sp, sq = side[i], side[(i + 1) % count]
        if sp >= 0.0:
            out.append(p)
        if (sp > 0.0 > sq) or (sp < 0.0 < sq):
            out.append(p + (sp / (sp - sq)) * (q - p))
    return _distinct(np.array(out).reshape(-1, 2))


def _distinct(polygon: NDArray) -> NDArray:
    """The polygon without repeated consecutive corners (a clip through a corner adds it twice)."""
    if polygon.shape[0] < 2:
        return polygon
    scale = max(1.0, float(np.abs(polygon).max()))
    keep = np.abs(polygon - np.roll(polygon, 1, axis=0)).max(axis=1) > _EPSILON * scale
    return polygon[keep] if keep.any() else polygon[:1]


def _edge_lines(polygon: NDArray) -> list[tuple[NDArray, float]]:
    """Inward half-planes ``(normal, offset)`` of a counter-clockwise convex polygon's edges."""
    lines = []
    count = polygon.shape[0]
    for i in range(count):
        p, q = polygon[i], polygon[(i + 1) % count]
        normal = np.array([-(q[1] - p[1]), q[0] - p[0]])
        if abs(normal[0]) + abs(normal[1]) > _EPSILON * max(1.0, abs(p[0]) + abs(p[1])):  # a repeated corner: no edge
            lines.append((normal, -float(normal @ p)))
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
    for normal, offset in _edge_lines(b):
        outside = _clip_half_plane(rest, -normal, -offset)
        if outside.shape[0] >= 3 and abs(_signed_area(outside)) > tiny:
            pieces.append(outside)
        rest = _clip_half_plane(rest, normal, offset)
        if rest.shape[0] < 3:
            break
    return pieces


def _ccw(polygon: NDArray) -> NDArray:
    return polygon if _signed_area(polygon) >= 0.0 else polygon[::-1].copy()


def _disjoint_union(pieces: list[NDArray], tiny: float) -> list[NDArray]:
    """Disjoint convex pieces covering the union of convex `pieces`."""
    result: list[NDArray] = []
    for piece in pieces:
        parts = [piece]
        for other in result:
            parts = [rest for part in parts for rest in _subtract(part, other, tiny)]
            if not parts:
                break
        result.extend(parts)
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
    segments = []
    for piece in pieces:
        count = piece.shape[0]
        for i in range(count):
            p, q = piece[i], piece[(i + 1) % count]
            d = q - p
            length2 = float(d @ d)
            if length2 == 0.0:
                continue
            t = ((vertices - p) @ d) / length2
            across = np.abs((vertices - p) @ np.array([-d[1], d[0]])) / np.sqrt(length2)
            inside = (t > 1e-12) & (t < 1.0 - 1e-12) & (across <= tolerance)
            stops = sorted({float(v) for v in t[inside]})
            points = [p] + [vertices[np.flatnonzero(inside)[np.argmin(np.abs(t[inside] - s))]] for s in stops] + [q]
            segments.extend((points[k], points[k + 1]) for k in range(len(points) - 1))

    def key(point: NDArray) -> tuple[int, int]:
        return (round(float(point[0]) / tolerance), round(float(point[1]) / tolerance))

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
            loop.append(p)
            following = [i for i in starts.get(key(q), []) if i in alive]
            if not following:
                break
            index = following[0]
        if len(loop) >= 3:
            loops.append(_without_collinear(np.array(loop), tolerance))
    return [loop for loop in loops if loop.shape[0] >= 3]


def _without_collinear(loop: NDArray, tolerance: float) -> NDArray:
    keep = []
    count = loop.shape[0]
    for i in range(count):
        a, b, c = loop[i - 1], loop[i], loop[(i + 1) % count]
        d = c - a
        length = float(np.hypot(d[0], d[1]))
        if length > 0.0 and abs((b - a) @ np.array([-d[1], d[0]])) / length <= tolerance and (b - a) @ d > 0.0:
            continue
        keep.append(b)
    return np.array(keep)


# --- faces, lights and projections --------------------------------------------------------------------------


class _Faces(NamedTuple):
    corners: NDArray  # (F, 3, 3) world
    item: NDArray  # (F,) int64
    normal: NDArray  # (F, 3) unit, turned toward the camera
    offset: NDArray  # (F,) plane offset: normal·x + offset = 0


def _scene_faces(scene: Scene, camera: Camera) -> _Faces:
    corners, items = [], []
    for index, item in enumerate(scene.items):
        mesh = item.mesh
        if not isinstance(mesh, Mesh) or mesh.face_count == 0 or item.material.opacity < 1.0:
            continue
        m = np.asarray(item.world_from_model, dtype=np.float64)
        world = mesh.vertices @ m[:3, :3].T + m[:3, 3]
        corners.append(world[mesh.faces])
        items.append(np.full(mesh.face_count, index))
    if not corners:
        empty = np.empty((0, 3))
        return _Faces(np.empty((0, 3, 3)), np.empty(0, dtype=np.int64), empty, np.empty(0))
    tri = np.concatenate(corners)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    good = length > 0.0
    tri, normal, item = tri[good], normal[good] / length[good, None], np.concatenate(items)[good]
    offset = -(normal * tri[:, 0]).sum(axis=1)
    # the side toward the camera: a perspective eye, or the direction toward the viewer of a parallel camera
    eye = np.asarray(camera.frame.eye, dtype=np.float64)
    toward = (normal @ eye + offset) if not camera.projection.parallel else (normal @ np.asarray(camera.frame.n, float))
    flip = np.where(toward < 0.0, -1.0, 1.0)
    return _Faces(tri, item, normal * flip[:, None], offset * flip)


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
    faces = _scene_faces(scene, camera)
    if faces.corners.shape[0] == 0:
        return []
    span = float(np.ptp(faces.corners.reshape(-1, 3), axis=0).max()) or 1.0
    eps = _EPSILON * span
    eye = np.asarray(camera.frame.eye, dtype=np.float64)
    windows = [_to_window(c, camera) for c in faces.corners]
    size = float(max(camera.width, camera.height))
    tiny = (_EPSILON * size) ** 2
    result = []
    for light_index, light in enumerate(_shadow_lights(scene)):
        groups: dict[tuple, list[NDArray]] = {}
        for f in range(faces.corners.shape[0]):
            n, c = faces.normal[f], faces.offset[f]
            if isinstance(light, DirectionalLight):
                lit_side = float(n @ -np.asarray(light.direction))
            else:
                lit_side = float(n @ np.asarray(light.position) + c)
            if lit_side <= 0.0:  # the camera side faces away from the light: all in shade
                pieces_3d = [faces.corners[f]]
                kind = "attached"
            else:
                pieces_3d = _cast_on_face(faces, f, light, eps)
                kind = "cast"
            if not pieces_3d:
                continue
            # the visible parts: minus the window images of faces in front of F's plane (camera side)
            pieces = [_ccw(_to_window(p, camera)) for p in pieces_3d]
            pieces = _disjoint_union([p for p in pieces if abs(_signed_area(p)) > tiny], tiny)
            for h in range(faces.corners.shape[0]):
                if h == f or not pieces:
                    continue
                side = faces.corners[h] @ n + c
                if not (side > eps).any():
                    continue
                if camera.projection.parallel:
                    front = _clip_space(faces.corners[h], n, c, eps, None)
                else:
                    front = _clip_space(faces.corners[h], n, c, eps, float(n @ eye + c))
                if front.shape[0] < 3:
                    continue
                cover = _ccw(_to_window(front, camera) if front is not faces.corners[h] else windows[h])
                pieces = [rest for piece in pieces for rest in _subtract(piece, cover, tiny)]
            key = (faces.item[f], kind, *np.round(np.append(n, c / span), 9))
            groups.setdefault(key, []).extend(pieces)
        for (item, kind, *_), pieces in groups.items():
            loops = _outline(pieces, size)
            if loops:
                result.append(ShadowPolygon(light_index, int(item), kind, loops))
    return result


def _cast_on_face(faces: _Faces, f: int, light: Any, eps: float) -> list[NDArray]:
    """The shadow on face f (3D convex pieces in its plane) of every other face, clipped to f."""
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
    heights = faces.corners @ n + c  # (F, 3)
    candidates = np.flatnonzero((heights > eps).any(axis=1))
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
