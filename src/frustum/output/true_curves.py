"""True curves for vector drawings: the edges of circular features drawn as exact circles, ellipses and arcs.

A tessellated solid draws a circle as the polygon of its facets' edges. Under a parallel projection (any view of
an engineering sheet) the image of a circle $P(θ) = c + r·(cos θ·e1 + sin θ·e2)$ is exactly the ellipse
$p(θ) = C + cos θ·A + sin θ·B$ with ``C``, $A = proj(c + r·e1) − C$, $B = proj(c + r·e2) − C$ (an affine
map keeps the parametrization): a circle seen end-on, an ellipse seen obliquely, a line seen edge-on. So the
polygon's visible and hidden pieces are replaced by the arcs of that ellipse over the same angles.

Circular features are found in any mesh, whoever built it (``find_circles``):

* **edge loops** — a closed chain of feature edges (creases over the crease angle, or boundaries) in which every
  vertex has two chain edges, with at least ``CIRCLE_MIN_VERTICES`` vertices that lie within a tolerance of one
  plane and of one distance r from their centroid. The tolerance is ``CIRCLE_TOLERANCE`` (1e-6) of
  r + the model size, so float32 mesh files qualify and a polygon with one vertex off by a visible amount does
  not. A loop or open chain that is not one circle is searched for **arcs**: runs of at least
  ``ARC_MIN_VERTICES`` consecutive vertices, equally spaced, whose every three consecutive ones have one
  circumcircle (a rounded rectangle's corners, a slot's ends). This finds the rims of cylinders, cones and
  disks (``frustum.geometry`` primitives, any rotation or placement), the rims of holes drilled by CSG
  (``frustum.geometry.csg``: manifold3d keeps the cutter's vertices) and circular loops and arcs in loaded
  meshes;
* **spheres** — a mesh of at least ``SPHERE_MIN_VERTICES`` distinct vertices all at one distance r from their
  centroid (same tolerance), no edge longer than 0.75·r and every face normal within 26° of the radius
  through the face's centroid (a polyhedron with few faces, or a short cylinder, is not a sphere): its
  silhouette under a parallel projection is the great circle perpendicular to the line of sight, drawn as a
  circle of radius r (the faceted silhouette's zigzag lies inside it);
* **tori** — a mesh whose vertices satisfy $(ρ − R)² + h² = r²$ about the axis of their smallest second
  moment (least squares in R and R² − r², same tolerance, r < R, faces turned like the surface): seen along
  its axis, its silhouette is the outer and inner equator, circles of radii R ± r.

Not converted: a circle seen edge-on (its image is a line; the polygon's pieces are kept), silhouettes of tori
seen other than along the axis and of cones (not circles in general), anything under a perspective
projection (the image of a circle is still a conic there, but its arcs are not an affine image of the circle's
angles).

Each piece of a loop's edge maps to the angle interval between the polar angles of its ends (about the centre,
in the circle's plane); a sphere's silhouette pieces likewise in the view plane. Intervals are merged per circle
and per visibility, so a half-hidden hole gives one visible and one hidden arc, split where the polygon's
pieces are split (the visibility change is located on the facet, within the facet's sagitta of the curve).

References
----------
[HB 10] "Orthogonal Projections" (parallel projections are affine maps); [HB 13] "Conic Sections" (the ellipse
as the affine image of a circle); ISO 128-2 (continuous and dashed lines).
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from frustum.camera import Camera
from frustum.geometry import Mesh, Polyline
from frustum.visibility.hidden_lines import (
    DEFAULT_CREASE_ANGLE,
    EDGE_BOUNDARY,
    EDGE_CREASE,
    EDGE_SILHOUETTE,
    HiddenLines,
    classify_edges,
    welded_adjacency,
)

__all__ = [
    "ARC_MIN_VERTICES",
    "CIRCLE_MIN_VERTICES",
    "CIRCLE_TOLERANCE",
    "SPHERE_MIN_VERTICES",
    "Circle",
    "EllipseArc",
    "circle_arcs",
    "find_circles",
]

CIRCLE_MIN_VERTICES = 10
"""An edge loop with fewer vertices is a polygon, not a circle."""
ARC_MIN_VERTICES = 4
"""An arc needs at least this many consecutive chain vertices on one circle (three segments)."""
CIRCLE_TOLERANCE = 1e-6
"""Vertices lie on the circle (or sphere) within this fraction of (radius + model size)."""
SPHERE_MIN_VERTICES = 24
"""A mesh with fewer distinct vertices is a polyhedron, not a sphere."""
_EDGE_ON_RATIO = 1e-6  # an ellipse whose minor / major axis is below this is a line: keep the polygon's pieces
_ANGLE_GAP = 1e-6  # radians: arcs closer than this are one arc; an arc covering 2π − this is the whole circle


@dataclasses.dataclass(frozen=True)
class Circle:
    """A circular feature in world coordinates.

    Attributes
    ----------
    centre : (3,) float64
    normal : (3,) float64
        Unit normal of the circle's plane (for a sphere: unused, the silhouette's plane faces the viewer).
    radius : float
    sides : int
        Vertices of the polygon that stands for it (0 for a sphere).
    mesh : int
        Index of the placed mesh it belongs to (the order given to ``find_circles``).
    middle : (3,) float64 or None
        An arc's middle vertex (where a radius leader points).
    kind : {"loop", "arc", "sphere", "torus"}
        A whole circle (a closed loop), an arc of a chain of feature edges (the rest of the chain is not on the
        circle), or a sphere's outline.
    """

    centre: NDArray[np.float64]
    normal: NDArray[np.float64]
    radius: float
    sides: int
    mesh: int
    kind: str = "loop"
    middle: NDArray[np.float64] | None = None


class EllipseArc(NamedTuple):
    """The arc $p(θ) = centre + cos θ·axes[:, 0] + sin θ·axes[:, 1]$ for θ from `start` to `end` (> start).

    In the drawing's 2D coordinates; `axes` are two conjugate semi-diameters (columns), equal and perpendicular
    for a circle seen end-on. $end − start = 2π$ is the whole ellipse.
    """

    centre: NDArray[np.float64]
    axes: NDArray[np.float64]
    start: float
    end: float

    @property
    def full(self) -> bool:
        return self.end - self.start >= 2.0 * math.pi - _ANGLE_GAP

    def point(self, theta: float | NDArray) -> NDArray[np.float64]:
        """(2,) or (N, 2) points at parameter(s) θ."""
        theta = np.asarray(theta, dtype=np.float64)
        return self.centre + np.cos(theta)[..., None] * self.axes[:, 0] + np.sin(theta)[..., None] * self.axes[:, 1]

    def principal(self) -> tuple[float, float, float]:
        """(semi-major, semi-minor, angle of the major axis from +x in radians): the ellipse's own axes."""
        u, s, _ = np.linalg.svd(self.axes)
        return float(s[0]), float(s[1]), math.atan2(float(u[1, 0]), float(u[0, 0]))

    def mapped(self, transform: object) -> EllipseArc:
        """The same arc under an affine map of the plane, `transform` (N, 2) → (N, 2)."""
        points = np.stack([self.centre, self.centre + self.axes[:, 0], self.centre + self.axes[:, 1]])
        image = transform(points)  # type: ignore[operator]
        return EllipseArc(image[0], np.column_stack([image[1] - image[0], image[2] - image[0]]), self.start, self.end)


def find_circles(
    meshes: list[tuple[Mesh | Polyline, NDArray]], crease_angle: float = DEFAULT_CREASE_ANGLE
) -> list[Circle]:
    """Circular edge loops and spheres of placed meshes (world coordinates), as the module describes."""
    points_all = [
        (mesh.vertices @ m[:3, :3].T + m[:3, 3]) for mesh, m in meshes if isinstance(mesh, Mesh) and mesh.face_count
    ]
    if not points_all:
        return []
    stacked = np.concatenate(points_all)
    size = float(np.linalg.norm(stacked.max(axis=0) - stacked.min(axis=0)))
    found: list[Circle] = []
    for index, (mesh, world_from_model) in enumerate(meshes):
        if not isinstance(mesh, Mesh) or mesh.face_count == 0:
            continue
        points = mesh.vertices @ world_from_model[:3, :3].T + world_from_model[:3, 3]
        sphere = _sphere(points, np.asarray(mesh.faces), size, index)
        if sphere is not None:
            found.append(sphere)
            continue
        rims = _torus(points, np.asarray(mesh.faces), size, index)
        if rims:
            found += rims
            continue
        found += _loops(mesh, points, size, index, crease_angle)
    return found


def _tolerance(radius: float, size: float) -> float:
    return CIRCLE_TOLERANCE * (radius + size)


def _sphere(points: NDArray, faces: NDArray, size: float, index: int) -> Circle | None:
    distinct = np.unique(points, axis=0)
    if distinct.shape[0] < SPHERE_MIN_VERTICES:
        return None
    centre = distinct.mean(axis=0)
    distance = np.linalg.norm(distinct - centre, axis=1)
    radius = float(distance.mean())
    if not radius > 0.0 or np.abs(distance - radius).max() > _tolerance(radius, size):
        return None
    corners = points[faces]
    longest = float(np.linalg.norm(corners - corners[:, [1, 2, 0]], axis=2).max())
    if longest > 0.75 * radius:
        return None
    # every face turned to the centre like a sphere's facets (a short cylinder's vertices also lie on a sphere)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    radial = corners.mean(axis=1) - centre
    lengths = np.linalg.norm(normals, axis=1) * np.linalg.norm(radial, axis=1)
    good = lengths > 0.0
    if np.any(np.abs((normals[good] * radial[good]).sum(axis=1)) < 0.9 * lengths[good]):
        return None
    return Circle(centre, np.array([0.0, 0.0, 1.0]), radius, 0, index, "sphere")


def _torus(points: NDArray, faces: NDArray, size: float, index: int) -> list[Circle]:
    """A ring torus's outer and inner equators (kind "torus", radii R ± r, normal = its axis), or []."""
    distinct = np.unique(points, axis=0)
    if distinct.shape[0] < SPHERE_MIN_VERTICES:
        return []
    centre = distinct.mean(axis=0)
    offsets = distinct - centre
    axis = np.linalg.eigh(offsets.T @ offsets)[1][:, 0]  # the smallest second moment: along the axis
    height = offsets @ axis
    rho = np.linalg.norm(offsets - height[:, None] * axis, axis=1)
    # (ρ − R)² + h² = r²  ⇔  2R·ρ − (R² − r²) = ρ² + h²: linear least squares in R and c = R² − r²
    design = np.column_stack([2.0 * rho, -np.ones_like(rho)])
    singular = np.linalg.svd(design, compute_uv=False)
    if not singular[1] > 1e-9 * singular[0]:
        return []
    (big, c), *_ = np.linalg.lstsq(design, rho**2 + height**2, rcond=None)
    if not big**2 > c:
        return []
    small = math.sqrt(big**2 - c)
    if not 0.0 < small < big:
        return []
    tolerance = _tolerance(small, size)
    if np.abs(np.hypot(rho - big, height) - small).max() > tolerance:
        return []
    # every face turned like the torus's surface there (its normal from the tube's centre circle)
    corners = points[faces]
    middle = corners.mean(axis=1) - centre
    along = middle @ axis
    radial = middle - along[:, None] * axis
    radial /= np.maximum(np.linalg.norm(radial, axis=1, keepdims=True), 1e-300)
    surface = middle - big * radial  # from the tube's centre circle
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1) * np.linalg.norm(surface, axis=1)
    good = lengths > 0.0
    if np.any(np.abs((normals[good] * surface[good]).sum(axis=1)) < 0.9 * lengths[good]):
        return []
    return [Circle(centre, axis, float(big + small), 0, index, "torus"),
            Circle(centre, axis, float(big - small), 0, index, "torus")]  # fmt: skip


def _loops(mesh: Mesh, points: NDArray, size: float, index: int, crease_angle: float) -> list[Circle]:
    adjacency = welded_adjacency(mesh)
    kinds = classify_edges(adjacency, points, np.asarray(mesh.faces), None, crease_angle)
    edges = adjacency.edges[(kinds & (EDGE_BOUNDARY | EDGE_CREASE)) != 0]
    if edges.shape[0] < CIRCLE_MIN_VERTICES:
        return []
    # connected components of the edge graph (label propagation on the few feature vertices)
    vertices, local = np.unique(edges, return_inverse=True)
    local = local.reshape(-1, 2)
    parent = np.arange(vertices.size)
    changed = True
    while changed:
        low = np.minimum(parent[local[:, 0]], parent[local[:, 1]])
        changed = bool((parent[local[:, 0]] != low).any() or (parent[local[:, 1]] != low).any())
        np.minimum.at(parent, local[:, 0], low)
        np.minimum.at(parent, local[:, 1], low)
        parent = parent[parent]
    degree = np.bincount(local.reshape(-1), minlength=vertices.size)
    found = []
    for root in np.unique(parent):
        members = np.flatnonzero(parent == root)
        if (degree[members] > 2).any() or members.size < ARC_MIN_VERTICES:
            continue
        if members.size < CIRCLE_MIN_VERTICES or (degree[members] != 2).any():
            found += _arcs(_ordered(members, local, degree), points[vertices], size, index)
            continue
        ring = points[vertices[members]]
        centre = ring.mean(axis=0)
        offsets = ring - centre
        normal = np.linalg.svd(offsets)[2][2]
        radii = np.linalg.norm(offsets, axis=1)
        radius = float(radii.mean())
        if not radius > 0.0:
            continue
        tolerance = _tolerance(radius, size)
        if np.abs(offsets @ normal).max() > tolerance or np.abs(radii - radius).max() > tolerance:
            found += _arcs(_ordered(members, local, degree), points[vertices], size, index)
            continue
        found.append(Circle(centre, normal, radius, int(members.size), index))
    return found


def _ordered(members: NDArray, local: NDArray, degree: NDArray) -> tuple[list[int], bool]:
    """The vertices of one chain (every degree <= 2) in order along it, and whether it is closed."""
    inside = set(members.tolist())
    neighbours: dict[int, list[int]] = {int(m): [] for m in members}
    for a, b in local.tolist():
        if a in inside:
            neighbours[a].append(b)
            neighbours[b].append(a)
    ends = [m for m in neighbours if degree[m] == 1]
    start = ends[0] if ends else int(members[0])
    order, previous = [start], -1
    while True:
        step = [n for n in neighbours[order[-1]] if n != previous]
        if not step or step[0] == start:
            break
        previous = order[-1]
        order.append(step[0])
        if len(order) > len(neighbours):
            break
    return order, not ends


def _circumcircle(a: NDArray, b: NDArray, c: NDArray) -> tuple[NDArray, float, NDArray] | None:
    """Centre, radius and unit normal of the circle through three points; None for collinear points."""
    ab, ac = b - a, c - a
    normal = np.cross(ab, ac)
    area2 = float(normal @ normal)
    if not area2 > (1e-12 * float(ab @ ab) * float(ac @ ac)):
        return None
    centre = a + (np.cross(normal, ab) * float(ac @ ac) + np.cross(ac, normal) * float(ab @ ab)) / (2.0 * area2)
    return centre, float(np.linalg.norm(a - centre)), normal / math.sqrt(area2)


def _arcs(chain: tuple[list[int], bool], points: NDArray, size: float, index: int) -> list[Circle]:
    """Circular arcs along a chain of feature edges (a loop of lines and arcs, such as a rounded rectangle's
    outline): maximal runs of at least ``ARC_MIN_VERTICES`` consecutive vertices on one circle (every three
    consecutive ones have the same circumcircle, within the tolerance), each an arc of kind "arc"."""
    order, closed = chain
    ring = points[order]
    count = len(order)
    if count < 3:
        return []
    triples = range(count) if closed else range(1, count - 1)
    circles = {}
    for i in triples:
        circle = _circumcircle(ring[i - 1], ring[i], ring[(i + 1) % count])
        if circle is not None and circle[1] < 1e3 * max(size, 1e-300):
            circles[i] = circle

    def same(i: int, j: int) -> bool:
        if i not in circles or j not in circles:
            return False
        (c1, r1, n1), (c2, r2, _) = circles[i], circles[j]
        tolerance = _tolerance(r1, size)
        return bool(
            np.abs(c1 - c2).max() <= tolerance
            and abs(r1 - r2) <= tolerance
            and abs(float(n1 @ circles[j][2])) > 1 - 1e-9
        )

    # runs of consecutive triples on one circle (a closed chain: start after a break)
    indices = list(triples)
    if closed:
        breaks = [k for k in range(count) if not same(indices[k - 1], indices[k])]
        if not breaks:
            return []
        indices = indices[breaks[0] :] + indices[: breaks[0]]
    runs: list[list[int]] = []
    for i in indices:
        if runs and same(runs[-1][-1], i):
            runs[-1].append(i)
        elif i in circles:
            runs.append([i])
    found = []
    for run in runs:
        if len(run) + 2 < ARC_MIN_VERTICES:
            continue
        chosen = [run[0] - 1, *run, (run[-1] + 1) % count]
        arc_points = ring[[k % count for k in chosen]]
        centre = np.mean([circles[i][0] for i in run], axis=0)
        normal = circles[run[0]][2]
        radii = np.linalg.norm(arc_points - centre, axis=1)
        radius = float(radii.mean())
        tolerance = _tolerance(radius, size)
        if np.abs(radii - radius).max() > tolerance or np.abs((arc_points - centre) @ normal).max() > tolerance:
            continue
        # a tessellated arc has equal chords; four points of a symmetric outline (two corners' ends and the
        # straight side between them) lie on a circle too, with unequal ones
        chords = np.linalg.norm(np.diff(arc_points, axis=0), axis=1)
        if chords.max() - chords.min() > 1e-6 * chords.max():
            continue
        step = 2.0 * math.asin(min(1.0, float(np.linalg.norm(arc_points[1] - arc_points[0])) / (2.0 * radius)))
        sides = max(3, round(2.0 * math.pi / step)) if step > 0.0 else 0
        found.append(Circle(centre, normal, radius, sides, index, "arc", arc_points[len(arc_points) // 2].copy()))
    return found


def _basis(normal: NDArray) -> tuple[NDArray, NDArray]:
    """Two unit vectors spanning the plane with unit `normal` (e1 × e2 = normal)."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(normal, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(normal, e1)


def circle_arcs(
    lines: HiddenLines, circles: list[Circle], camera: Camera
) -> tuple[HiddenLines, list[EllipseArc], list[EllipseArc]]:
    """Replace the pieces of `lines` that draw `circles` by exact arcs (window coordinates, y up).

    Returns the remaining pieces, the visible arcs and the hidden arcs. Under a perspective camera nothing is
    replaced. A piece belongs to a loop circle when it lies on an edge of that circle's mesh whose two ends lie
    on the circle (in its plane, at its radius); to a sphere's circle when it is a silhouette edge of the
    sphere's mesh.
    """
    if not camera.projection.parallel or not circles:
        return lines, [], []
    # the line of sight of the projection (an axonometric projection turns it away from the frame's)
    rows = np.asarray(camera.clip_from_world)[[0, 1, 3]]
    direction = np.linalg.svd(rows)[2][-1][:3]
    direction = direction / np.linalg.norm(direction)
    edges = lines.edges
    size = (
        float(np.linalg.norm(edges.reshape(-1, 3).max(axis=0) - edges.reshape(-1, 3).min(axis=0)))
        if len(edges)
        else 0.0
    )
    visible_used = np.zeros(lines.visible.shape[0], bool)
    hidden_used = np.zeros(lines.hidden.shape[0], bool)
    visible_arcs: list[EllipseArc] = []
    hidden_arcs: list[EllipseArc] = []
    for circle in circles:
        if circle.kind == "sphere":
            normal = direction
            on_edge = (lines.edge_meshes == circle.mesh) & ((lines.edge_kinds & EDGE_SILHOUETTE) != 0)
        elif circle.kind == "torus":  # seen along its axis: its silhouette is the outer and the inner equator
            normal = circle.normal
            if abs(float(normal @ direction)) < math.cos(1e-6):
                continue
            offsets = edges - circle.centre
            rho = np.linalg.norm(offsets - (offsets @ normal)[..., None] * normal, axis=2)
            middle = np.mean([c.radius for c in circles if c.kind == "torus" and c.mesh == circle.mesh])
            side = (rho > middle).all(axis=1) if circle.radius > middle else (rho < middle).all(axis=1)
            silhouette = (lines.edge_kinds & EDGE_SILHOUETTE) != 0
            on_edge = (lines.edge_meshes == circle.mesh) & silhouette & side
        else:
            normal = circle.normal
            tolerance = _tolerance(circle.radius, size)
            offsets = edges - circle.centre
            planar = (np.abs(offsets @ normal) <= tolerance).all(axis=1)
            round_ = (np.abs(np.linalg.norm(offsets, axis=2) - circle.radius) <= tolerance).all(axis=1)
            on_edge = (lines.edge_meshes == circle.mesh) & planar & round_
        if not on_edge.any():
            continue
        e1, e2 = _basis(normal)
        ends = camera.project(np.stack([circle.centre, circle.centre + circle.radius * e1,
                                        circle.centre + circle.radius * e2]))[:, :2]  # fmt: skip
        axes = np.column_stack([ends[1] - ends[0], ends[2] - ends[0]])
        singular = np.linalg.svd(axes, compute_uv=False)
        if not singular[0] > 0.0 or singular[1] < _EDGE_ON_RATIO * singular[0]:
            continue  # seen edge-on: a line, drawn by the polygon's pieces
        for world, owners, used, arcs in (
            (lines.visible_world, lines.visible_edges, visible_used, visible_arcs),
            (lines.hidden_world, lines.hidden_edges, hidden_used, hidden_arcs),
        ):
            mine = on_edge[owners] & ~used
            if not mine.any():
                continue
            used |= mine
            offsets = world[mine] - circle.centre  # (K, 2, 3)
            angles = np.arctan2(offsets @ e2, offsets @ e1)  # (K, 2)
            for start, end in _merge(angles):
                arcs.append(EllipseArc(ends[0].copy(), axes.copy(), start, end))
    # a whole circle drawn twice (a cylinder's two rims seen end-on): once; hidden under a visible one: not at all
    visible_arcs = _unique_full(visible_arcs, [])
    hidden_arcs = _unique_full(hidden_arcs, [arc for arc in visible_arcs if arc.full])
    if not (visible_used.any() or hidden_used.any()):
        return lines, visible_arcs, hidden_arcs
    keep_v, keep_h = ~visible_used, ~hidden_used
    remaining = dataclasses.replace(
        lines,
        visible=lines.visible[keep_v], visible_depth=lines.visible_depth[keep_v],
        visible_world=lines.visible_world[keep_v], visible_edges=lines.visible_edges[keep_v],
        hidden=lines.hidden[keep_h], hidden_depth=lines.hidden_depth[keep_h],
        hidden_world=lines.hidden_world[keep_h], hidden_edges=lines.hidden_edges[keep_h],
    )  # fmt: skip
    return remaining, visible_arcs, hidden_arcs


def _unique_full(arcs: list[EllipseArc], covering: list[EllipseArc]) -> list[EllipseArc]:
    """`arcs` without whole ellipses that repeat an earlier one or one of `covering` (same centre and axes
    within 1e-9 of their size)."""
    kept: list[EllipseArc] = []
    for arc in arcs:
        if arc.full:
            tolerance = 1e-9 * max(arc.principal()[0], 1e-300)
            if any(_same_ellipse(arc, other, tolerance) for other in [*covering, *kept] if other.full):
                continue
        kept.append(arc)
    return kept


def _same_ellipse(a: EllipseArc, b: EllipseArc, tolerance: float) -> bool:
    if np.abs(a.centre - b.centre).max() > tolerance:
        return False
    # same ellipse: equal quadratic forms (A·Aᵀ + B·Bᵀ is the shape matrix of both parametrizations)
    return bool(
        np.abs(a.axes @ a.axes.T - b.axes @ b.axes.T).max() <= tolerance * (2 * np.abs(a.axes).max() + tolerance)
    )


def _merge(angles: NDArray) -> list[tuple[float, float]]:
    """Union of short angle intervals (K, 2) (each the short way between its ends) as ascending (start, end)
    pairs, start in [0, 2π), end − start in (0, 2π]; intervals across 0 are joined."""
    two_pi = 2.0 * math.pi
    a, b = angles[:, 0], angles[:, 1]
    step = (b - a + math.pi) % two_pi - math.pi  # signed short difference
    start = np.where(step >= 0.0, a, a + step) % two_pi
    length = np.abs(step)
    order = np.argsort(start, kind="stable")
    merged: list[list[float]] = []
    for s, length_k in zip(start[order].tolist(), length[order].tolist(), strict=True):
        if merged and s <= merged[-1][1] + _ANGLE_GAP:
            merged[-1][1] = max(merged[-1][1], s + length_k)
        else:
            merged.append([s, s + length_k])
    if len(merged) > 1 and merged[-1][1] >= merged[0][0] + two_pi - _ANGLE_GAP:  # wraps across 0
        last = merged.pop()
        merged[0] = [last[0], max(merged[0][1] + two_pi, last[1])]
    result = []
    for s, e in merged:
        if e - s >= two_pi - _ANGLE_GAP:
            result.append((0.0, two_pi))
        elif e - s > _ANGLE_GAP:
            result.append((s, e))
    return result


def svg_arc_elements(arcs: list[EllipseArc], tolerance: float = 1e-9) -> list[str]:
    """SVG elements of arcs in paper coordinates (y down): ``<circle>`` / ``<ellipse>`` for whole ones, an
    elliptical-arc ``<path>`` (pieces of at most π, so no endpoint ambiguity) for the rest."""
    from frustum.output.svg import _number

    elements = []
    for arc in arcs:
        major, minor, angle = arc.principal()
        cx, cy = _number(arc.centre[0]), _number(arc.centre[1])
        round_ = major - minor <= tolerance * major
        if arc.full:
            if round_:
                elements.append(f'<circle cx="{cx}" cy="{cy}" r="{_number(major)}"/>')
            else:
                degrees = _number(math.degrees(angle))
                elements.append(
                    f'<ellipse cx="{cx}" cy="{cy}" rx="{_number(major)}" ry="{_number(minor)}" '
                    f'transform="rotate({degrees} {cx} {cy})"/>'
                )
            continue
        sweep = 1 if np.linalg.det(arc.axes) > 0.0 else 0
        pieces = max(1, math.ceil((arc.end - arc.start) / math.pi - 1e-12))
        thetas = np.linspace(arc.start, arc.end, pieces + 1)
        points = arc.point(thetas)
        rotation = _number(math.degrees(angle))
        rx, ry = _number(major), _number(max(minor, 0.0))
        parts = [f"M{_number(points[0, 0])} {_number(points[0, 1])}"]
        parts += [f"A{rx} {ry} {rotation} 0 {sweep} {_number(x)} {_number(y)}" for x, y in points[1:]]
        elements.append(f'<path class="arc" d="{" ".join(parts)}"/>')
    return elements
