"""Object-space hidden-line removal: the visible and hidden parts of every drawn mesh edge, exact in floating point.

The seed's object-space methods compare objects with each other "to float data precision", independent of any
pixel grid. For line drawings that means: for every drawn edge, find the parts that other faces hide.

1. **Edges to draw.** From each placed mesh, faces adjacent by shared vertex positions: *boundary* edges (one
   adjacent face), *creases* (the angle between the two adjacent unit world normals exceeds ``crease_angle``),
   *silhouettes* (one adjacent face front-facing, the other not, by the plane test against the centre of
   projection) — never between coplanar neighbours (``COPLANAR_ANGLE``) — or *all* edges; and the segments of
   every ``Polyline`` (curves, control polygons), which faces hide but which hide nothing.
2. **Clip.** Edges (Liang–Barsky) and occluding triangles (Sutherland–Hodgman) are clipped in homogeneous clip
   space against the view volume, so edges that cross the near plane or pass behind the eye keep only their
   visible part; then divide and map to window coordinates.
3. **Projected overlap.** A projective map sends lines to lines and planes to planes, so in window space
   ``(x_w, y_w, z_ndc)`` each edge is a straight segment and each triangle is planar: the depth of both is an
   affine function of the segment parameter t (this is what makes the test perspective-correct). A uniform
   grid over the window bins the projected triangles' bounding boxes; an edge meets only the triangles of the
   cells it passes through (each pair once: in the first such cell the triangle's box covers).
4. **Hidden intervals.** Triangle T hides the t for which the point lies inside T's projection (three edge
   functions $E_k(t) >= 0$) and behind T's plane ($z_edge(t) − z_T(t) > 0$): four linear inequalities in
   t, solved like Liang–Barsky clipping. The interval ends are exactly where the edge crosses a projected
   triangle edge or pierces the triangle's plane; it counts only if the gap exceeds ε = 1e-9 (NDC z) at one
   end, so an edge lying in a face's plane is never hidden by round-off. The union of these intervals is the
   hidden part, the rest is visible.

The edge's own adjacent faces never hide it, and a projected triangle of zero area hides nothing. Intersection
curves between surfaces that cut through each other are not edges and are not drawn.

References
----------
[HB 16] "Classification of Visible-Surface Detection Algorithms" (object-space vs image-space methods),
"Wire-Frame Visibility Methods" (depth cueing and hidden-line removal); [seed] "Visible-Surface Detection",
"Wire-frame visibility" ("identifying visible lines").
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Matrix4, as_matrix, as_scalar, describe, read_only
from frustum.camera import Camera
from frustum.clipping import clip_lines, clip_triangles
from frustum.errors import FrustumError, GeometryError
from frustum.geometry import Mesh, Polyline

__all__ = [
    "COPLANAR_ANGLE",
    "EDGE_BOUNDARY",
    "EDGE_CREASE",
    "EDGE_KINDS",
    "EDGE_LINE",
    "EDGE_SILHOUETTE",
    "HiddenLines",
    "feature_edges",
    "remove_hidden_lines",
]


def _kernels() -> ModuleType:
    """The compiled kernels of this module (``raster/hidden_lines.py``), imported on first use: ``import frustum``
    never loads Numba."""
    from frustum.raster import hidden_lines

    return hidden_lines

EDGE_BOUNDARY = 1
"""Edge-kind bit: the edge has one adjacent face (or more than two: a non-manifold edge)."""
EDGE_CREASE = 2
"""Edge-kind bit: the angle between the two adjacent unit normals exceeds the crease angle."""
EDGE_SILHOUETTE = 4
"""Edge-kind bit: one adjacent face is front-facing and the other is not (view dependent)."""
EDGE_LINE = 8
"""Edge-kind bit: a segment of a ``Polyline`` (a curve or control polygon); always drawn, never hides anything."""
EDGE_KINDS = {
    "boundary": EDGE_BOUNDARY,
    "crease": EDGE_CREASE,
    "silhouette": EDGE_SILHOUETTE,
    "feature": EDGE_BOUNDARY | EDGE_CREASE | EDGE_SILHOUETTE,
    "all": 0,
}
"""Names accepted by ``edges=``: each selects the mesh edges carrying any of its bits; ``"all"`` selects every edge.
Polyline segments are drawn whatever the selection."""

DEFAULT_CREASE_ANGLE = math.pi / 6
"""Default crease threshold: 30 degrees between adjacent face normals."""

# Depth margin in NDC z (range 2): a face hides part of an edge only if it lies this far in front of it at one
# end of that part, so that an edge lying in a face's plane (coplanar neighbours) is never hidden by round-off.
_DEPTH_TOLERANCE = 1e-9
# Hidden intervals closer than this fraction of the image size are merged, and visible or hidden pieces this
# short are dropped: neighbouring triangles compute their shared crossing with different round-off, and the
# depth margin leaves slivers of that order where an edge runs into a face at a shared corner.
_GAP_FRACTION = 1e-7
# A projected edge shorter than this fraction of the image size is a point (an edge along the line of sight).
_POINT_FRACTION = 1e-12
# A face whose |(P1 − P0) × (P2 − P0)| is below this fraction of its longest squared edge has no normal.
_DEGENERATE_FRACTION = 1e-12
# Two neighbouring faces whose unit normals differ by at most this angle (radians) are coplanar: their shared
# edge is never a crease or a silhouette, whatever crease_angle says, so a flat face split into triangles draws
# no inner lines. 1e-4 rad covers float32 vertices (relative error 6e-8) on slivers up to ~1000:1, and is far
# below the facet angle of any tessellated curved surface (2π/60000 for a 60000-segment circle).
COPLANAR_ANGLE = 1e-4
# A projected triangle whose doubled area is below this fraction of its longest squared window edge is seen
# edge-on (height <= 1e-9 of its length): it hides nothing.
_SLIVER_FRACTION = 1e-9
# A face whose plane test det[a; b; c] is within this fraction of |a|·|b − a|·|c − a| is seen edge-on.
_EDGE_ON_FRACTION = 1e-9
# Round-off of a dihedral angle computed from float64 unit normals, radians.
_ANGLE_ROUNDOFF = 1e-9
# Vertices closer than this fraction of the mesh's extent are one vertex for the edge adjacency (meshes with
# split vertices for flat normals or texture seams): positions are rounded to this grid before matching.
_WELD_FRACTION = 1e-9


@dataclass(frozen=True, eq=False, repr=False)
class HiddenLines:
    """The visible and hidden pieces of the drawn edges: what ``remove_hidden_lines`` returns.

    Window coordinates are the camera's: x right in [0, width], **y up** in [0, height] (OpenGL; an SVG flips
    y), depth in [0, 1] with 1 = far. Every piece is a straight segment, in window and in world coordinates
    (a projective map keeps lines straight; the world ends are found perspective-correctly).

    Attributes
    ----------
    visible, hidden : (K, 2, 2) float64
        Window (x, y) of the two ends of each visible / hidden piece.
    visible_depth, hidden_depth : (K, 2) float64
        Window depth of both ends.
    visible_world, hidden_world : (K, 2, 3) float64
        World coordinates of both ends.
    visible_edges, hidden_edges : (K,) int64
        Index of each piece's source edge into ``edges``.
    edges : (E, 2, 3) float64
        World ends of every drawn edge (before clipping and visibility).
    edge_kinds : (E,) int64
        Bit mask of ``EDGE_BOUNDARY``, ``EDGE_CREASE``, ``EDGE_SILHOUETTE`` (or ``EDGE_LINE``) per drawn edge.
    edge_meshes : (E,) int64
        Index of the placed mesh (or polyline) each edge belongs to, in the order given.
    width, height : int
        The camera's image size.
    """

    visible: NDArray[np.float64]
    visible_depth: NDArray[np.float64]
    visible_world: NDArray[np.float64]
    visible_edges: NDArray[np.int64]
    hidden: NDArray[np.float64]
    hidden_depth: NDArray[np.float64]
    hidden_world: NDArray[np.float64]
    hidden_edges: NDArray[np.int64]
    edges: NDArray[np.float64]
    edge_kinds: NDArray[np.int64]
    edge_meshes: NDArray[np.int64]
    width: int
    height: int

    def __post_init__(self) -> None:
        for name in (
            "visible", "visible_depth", "visible_world", "visible_edges", "hidden", "hidden_depth",
            "hidden_world", "hidden_edges", "edges", "edge_kinds", "edge_meshes",
        ):  # fmt: skip
            object.__setattr__(self, name, read_only(np.ascontiguousarray(getattr(self, name))))

    def __repr__(self) -> str:
        return (
            f"HiddenLines({self.visible.shape[0]} visible and {self.hidden.shape[0]} hidden pieces of "
            f"{self.edges.shape[0]} edges, {self.width}x{self.height} window)"
        )

    def visible_length(self) -> float:
        """Total window length of the visible pieces, in pixels."""
        return float(np.linalg.norm(self.visible[:, 1] - self.visible[:, 0], axis=1).sum())

    def hidden_length(self) -> float:
        """Total window length of the hidden pieces, in pixels."""
        return float(np.linalg.norm(self.hidden[:, 1] - self.hidden[:, 0], axis=1).sum())


# --- placed meshes --------------------------------------------------------------------------------------


Drawable = Mesh | Polyline


def _placed(meshes: Any, where: str) -> list[tuple[Drawable, Matrix4]]:
    """(geometry, world_from_model) pairs from a Mesh or Polyline, such a pair, or a sequence of either."""
    if isinstance(meshes, Drawable):
        return [(meshes, np.eye(4))]
    if isinstance(meshes, tuple) and len(meshes) == 2 and isinstance(meshes[0], Drawable):
        return [(meshes[0], _affine(meshes[1], where, 0))]
    if not isinstance(meshes, Iterable) or isinstance(meshes, str | bytes):
        raise GeometryError(
            f"{where}: meshes = {describe(meshes)} is not a Mesh or a sequence of meshes; give a Mesh, "
            "(Mesh, world_from_model) pairs, or a list of them"
        )
    placed = []
    for index, entry in enumerate(meshes):
        if isinstance(entry, Drawable):
            placed.append((entry, np.eye(4)))
        elif isinstance(entry, tuple | list) and len(entry) == 2 and isinstance(entry[0], Drawable):
            placed.append((entry[0], _affine(entry[1], where, index)))
        else:
            raise GeometryError(
                f"{where}: meshes[{index}] = {describe(entry)} is not a Mesh or a (Mesh, world_from_model) pair; "
                "give Mesh (or Polyline) objects, optionally with a 4x4 modeling transform"
            )
    return placed


def _polyline_segments(polyline: Polyline) -> NDArray[np.int64]:
    """(S, 2) point indices of the drawn segments of a polyline (none for markers)."""
    count = polyline.points.shape[0]
    if polyline.markers or count < 2:
        return np.empty((0, 2), np.int64)
    if polyline.pairs is not None:
        return np.asarray(polyline.pairs, dtype=np.int64)
    starts = np.arange(count if polyline.closed and count > 2 else count - 1)
    return np.stack([starts, (starts + 1) % count], axis=1)


def _affine(matrix: ArrayLike, where: str, index: int) -> Matrix4:
    world_from_model = as_matrix(matrix, f"meshes[{index}] world_from_model", where=where, error=GeometryError)
    if np.any(world_from_model[3] != (0.0, 0.0, 0.0, 1.0)):
        raise GeometryError(
            f"{where}: meshes[{index}] world_from_model bottom row = {describe(world_from_model[3])} is projective; "
            "a modeling transform is affine (bottom row 0, 0, 0, 1)"
        )
    return world_from_model


def _edge_selection(edges: Any, where: str) -> int:
    names = [edges] if isinstance(edges, str) else edges
    if isinstance(names, Iterable) and not isinstance(names, bytes):
        names = list(names)
        if names and all(isinstance(name, str) and name in EDGE_KINDS for name in names):
            if "all" in names:
                return 0
            mask = 0
            for name in names:
                mask |= EDGE_KINDS[name]
            return mask
    raise FrustumError(
        f"{where}: edges = {describe(edges)} is unknown; expected one of {', '.join(map(repr, EDGE_KINDS))} "
        "or a sequence of them"
    )


# --- edges ----------------------------------------------------------------------------------------------


def feature_edges(
    points_world: ArrayLike, faces: ArrayLike, camera: Camera | None = None, crease_angle: float = DEFAULT_CREASE_ANGLE
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """Every undirected edge of a triangle mesh with its adjacent faces and kind bits.

    Faces are adjacent when they share two vertex *positions* (``welded_faces``: split vertices at shading
    seams do not make boundaries). An edge is a *boundary* with one adjacent face (or more than two), a
    *crease* when the angle between its two unit face normals, $atan2(|n1 × n2|, n1·n2)$, exceeds
    `crease_angle`, a *silhouette* when exactly one of the two faces is front-facing for `camera`. Neighbours
    within ``COPLANAR_ANGLE`` (1e-4 rad) of each other are coplanar: their edge is neither, so the triangles of
    a flat face never draw lines between them. Front-facing is the plane test against the centre of
    projection, computed in clip space as ``det[(x, y, w)_0; (x, y, w)_1; (x, y, w)_2] > 0`` (the signed
    window area times $w0·w1·w2$, valid also for corners behind the eye). Faces of zero area have no
    normal: their edges are neither creases nor silhouettes.

    Parameters
    ----------
    points_world : (N, 3) array_like
    faces : (M, 3) array_like of int
    camera : Camera, optional
        Without a camera no edge is a silhouette.
    crease_angle : float
        Radians, in [0, pi].

    Returns
    -------
    edges : (E, 2) int64
        Vertex pairs (low, high), sorted.
    edge_faces : (E, 2) int64
        The first two adjacent faces; −1 where there is no second one.
    kinds : (E,) int64
        Bit masks of ``EDGE_BOUNDARY``, ``EDGE_CREASE``, ``EDGE_SILHOUETTE``.

    References
    ----------
    [HB 16] "Back-Face Detection" (the plane test); [seed] "Back-face detection".
    """
    mesh = Mesh(points_world, faces)
    angle = _crease(crease_angle, "feature_edges")
    facing = None if camera is None else front_facing(camera.clip_from_world, mesh.vertices, mesh.faces)
    return _edges_of(mesh.vertices, mesh.faces, facing, angle)


def _crease(value: Any, where: str) -> float:
    angle = as_scalar(value, "crease_angle", where=where, error=FrustumError)
    if not 0.0 <= angle <= math.pi:
        raise FrustumError(f"{where}: crease_angle = {angle!r} is outside [0, pi]; give an angle in radians")
    return angle


def front_facing(clip_from_world: Matrix4, points_world: NDArray, faces: NDArray) -> NDArray[np.bool_]:
    """(M,) True for faces whose front the camera sees: the plane test against the centre of projection, as
    ``det[(x, y, w)_0; (x, y, w)_1; (x, y, w)_2] > 0`` of the corners' clip rows (valid behind the eye too).

    A face seen edge-on ($det = a·((b − a) × (c − a))$ within 1e-9 of $|a|·|b − a|·|c − a|$, about 1e-9
    rad) counts as not front-facing, whatever the round-off sign: the silhouette is then the boundary of the
    front-facing region, the nearest of the edges that project onto the edge-on face's line.
    """
    clip = points_world @ clip_from_world[[0, 1, 3], :3].T + clip_from_world[[0, 1, 3], 3]
    a, b, c = clip[faces[:, 0]], clip[faces[:, 1]], clip[faces[:, 2]]
    determinant = np.einsum("ij,ij->i", a, np.cross(b, c))  # det[a; b; c] = a·(b × c)
    size = np.linalg.norm(a, axis=1) * np.linalg.norm(b - a, axis=1) * np.linalg.norm(c - a, axis=1)
    return determinant > _EDGE_ON_FRACTION * size


def _unit_normals(points: NDArray, faces: NDArray) -> tuple[NDArray, NDArray[np.bool_]]:
    points = np.asarray(points, dtype=np.float64)  # float32 vertices: the same float64 arithmetic as before
    p0, p1, p2 = points[faces[:, 0]], points[faces[:, 1]], points[faces[:, 2]]
    cross = np.cross(p1 - p0, p2 - p0)
    length = np.sqrt((cross * cross).sum(axis=1))
    longest = np.maximum.reduce([((p1 - p0) ** 2).sum(1), ((p2 - p1) ** 2).sum(1), ((p0 - p2) ** 2).sum(1)])
    degenerate = length <= _DEGENERATE_FRACTION * longest
    with np.errstate(invalid="ignore", divide="ignore"):
        normals = np.where(degenerate[:, None], 0.0, cross / np.where(degenerate, 1.0, length)[:, None])
    return normals, degenerate


class EdgeAdjacency(NamedTuple):
    """Every undirected edge of a triangle list once, with its faces: what ``feature_edges`` classifies.

    ``edges`` (E, 2) sorted (low, high) rows in lexicographic order; ``first``/``second`` (E,) the first two
    adjacent faces (second −1 when there is none); ``counts`` (E,) the number of adjacent faces. It depends on
    the faces only, so callers that draw the same mesh again (the renderer) keep it.
    """

    edges: NDArray[np.int64]
    first: NDArray[np.int64]
    second: NDArray[np.int64]
    counts: NDArray[np.int64]


def edge_adjacency(faces: NDArray, vertex_count: int) -> EdgeAdjacency:
    """The ``EdgeAdjacency`` of (M, 3) faces over `vertex_count` vertices (one sort of int64 edge keys)."""
    face_count = faces.shape[0]
    if face_count == 0:
        empty = np.empty(0, np.int64)
        return EdgeAdjacency(np.empty((0, 2), np.int64), empty, empty, empty)
    pairs = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).astype(np.int64, copy=False)
    pairs.sort(axis=1)  # int64 (a Mesh's faces are int32): the keys below and the edges returned
    owner = np.tile(np.arange(face_count, dtype=np.int64), 3)
    key = pairs[:, 0] * np.int64(max(vertex_count, 1)) + pairs[:, 1]
    order = np.argsort(key, kind="stable")
    key, owner = key[order], owner[order]
    starts = np.flatnonzero(np.concatenate([[True], key[1:] != key[:-1]]))
    counts = np.diff(np.append(starts, key.size))
    edges = np.ascontiguousarray(pairs[order][starts])
    first = owner[starts]
    second = np.where(counts >= 2, owner[np.minimum(starts + 1, key.size - 1)], -1)
    return EdgeAdjacency(edges, first, second, counts)


def classify_edges(
    adjacency: EdgeAdjacency, points: NDArray, faces: NDArray, facing: NDArray[np.bool_] | None, crease_angle: float
) -> NDArray[np.int64]:
    """(E,) kind bits of each edge of `adjacency` for these (world) `points` and this `facing` (or None)."""
    first, second, counts = adjacency.first, adjacency.second, adjacency.counts
    if first.size == 0:
        return np.empty(0, np.int64)
    kinds = np.where(counts != 2, EDGE_BOUNDARY, 0).astype(np.int64)
    normals, degenerate = _unit_normals(points, faces)
    other = np.maximum(second, 0)
    # the dihedral angle from atan2(|n1 × n2|, n1 · n2): accurate near 0 and pi, where acos(n1 · n2) is not
    n1, n2 = normals[first], normals[other]
    angle = np.arctan2(np.linalg.norm(np.cross(n1, n2), axis=1), (n1 * n2).sum(axis=1))
    # coplanar neighbours (within COPLANAR_ANGLE) share no drawn edge: neither crease nor silhouette
    both = (counts == 2) & ~degenerate[first] & ~degenerate[other] & (angle > COPLANAR_ANGLE)
    # "exceeds": by more than the normals' round-off, so a regular 12-gon prism (exactly 30°) has no creases
    kinds |= np.where(both & (angle > crease_angle + _ANGLE_ROUNDOFF), EDGE_CREASE, 0)
    if facing is not None:
        kinds |= np.where(both & (facing[first] != facing[other]), EDGE_SILHOUETTE, 0)
    return kinds


def welded_faces(points: NDArray, faces: NDArray) -> NDArray[np.int64]:
    """(M, 3) faces re-indexed so that vertices at the same position (within 1e-9 of the extent) are one vertex.

    Meshes often split a vertex where shading needs two normals (the rim of a cylinder's cap) or two texture
    coordinates (a seam): by index those edges have one face each and would read as boundaries. The
    representative of each position is its lowest index, so the result still indexes `points`. Positions are
    rounded to a grid of 1e-9 of the extent; two copies of a vertex that straddle a grid line (round-off of
    about 1e-9 of the extent exactly at a cell border) stay apart.
    """
    faces = np.asarray(faces, dtype=np.int64)
    if points.shape[0] == 0:
        return faces
    points = np.asarray(points, dtype=np.float64)  # float32 vertices: round on the same float64 grid as before
    low, high = points.min(axis=0), points.max(axis=0)
    step = max(float((high - low).max()), 1e-300) * _WELD_FRACTION
    keys = np.round((points - low) / step).astype(np.int64)
    order = np.lexsort(keys.T[::-1])  # stable: equal positions keep index order, the lowest first
    ordered = keys[order]
    starts = np.concatenate([[True], (ordered[1:] != ordered[:-1]).any(axis=1)])
    representative = np.empty(points.shape[0], dtype=np.int64)
    representative[order] = order[np.flatnonzero(starts)][np.cumsum(starts) - 1]
    return representative[faces]


_WELDED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def welded_adjacency(mesh: Mesh) -> EdgeAdjacency:
    """The mesh's edges by shared vertex positions, computed once per mesh (welding in model space equals welding
    after any affine modeling transform)."""
    cached = _WELDED.get(mesh)
    if cached is None:
        faces = np.asarray(mesh.faces, dtype=np.int64)
        cached = _WELDED[mesh] = edge_adjacency(welded_faces(mesh.vertices, faces), mesh.vertex_count)
    return cached


def _edges_of(
    points: NDArray, faces: NDArray, facing: NDArray[np.bool_] | None, crease_angle: float
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    adjacency = edge_adjacency(welded_faces(points, faces), points.shape[0])
    kinds = classify_edges(adjacency, points, faces, facing, crease_angle)
    return adjacency.edges, np.stack([adjacency.first, adjacency.second], axis=1), kinds


# --- the public driver ----------------------------------------------------------------------------------


def remove_hidden_lines(
    meshes: Mesh | Sequence[Mesh | tuple[Mesh, ArrayLike]],
    camera: Camera,
    *,
    edges: str | Sequence[str] = "feature",
    crease_angle: float = DEFAULT_CREASE_ANGLE,
    cull_back_faces: bool = False,
) -> HiddenLines:
    """Visible and hidden pieces of the drawn edges of `meshes` seen by `camera`, exact in floating point.

    A point ``E(t)`` of a projected edge is hidden by triangle T when it lies inside T's projection and
    $z_edge(t) − z_T(t) > 0$ (depth along the line of sight; the gap must exceed ε = 1e-9 in NDC z somewhere
    on the interval); both depths are affine in the window-space parameter t, so each hidden interval is found
    exactly, like a Liang–Barsky clip.

    Parameters
    ----------
    meshes : Mesh, (Mesh, world_from_model), or a sequence of them
        Triangle meshes placed in the world by optional 4x4 affine modeling transforms. ``Polyline`` objects
        (curves, control polygons) may be given the same way: their segments are drawn whatever `edges`
        says (kind ``EDGE_LINE``), split where faces hide them, and hide nothing themselves; marker
        polylines (points) are left out.
    camera : Camera
        Any projection: orthographic, axonometric, oblique, perspective or an off-axis frustum.
    edges : {"feature", "silhouette", "crease", "boundary", "all"} or a sequence of them
        Which edges to draw; ``"feature"`` is silhouettes, creases and boundaries.
    crease_angle : float
        Radians in [0, pi]: an edge is a crease when its two face normals differ by more than this.
    cull_back_faces : bool
        False (default): every face hides what lies behind it (right for open surfaces). True: only
        front-facing faces hide edges; the same result for closed meshes, and faster.

    Returns
    -------
    HiddenLines

    Raises
    ------
    GeometryError
        If `meshes` is not a mesh or a sequence of (mesh, transform), or a transform is not affine.
    FrustumError
        If `camera` is not a Camera, or `edges` / `crease_angle` is invalid.

    References
    ----------
    [HB 16] "Wire-Frame Visibility Methods", "Classification of Visible-Surface Detection Algorithms";
    [HB 10] "Clipping in Three-Dimensional Homogeneous Coordinates"; [seed] "Wire-frame visibility".
    """
    where = "remove_hidden_lines"
    if not isinstance(camera, Camera):
        raise FrustumError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at")
    mask = _edge_selection(edges, where)
    angle = _crease(crease_angle, where)
    placed = _placed(meshes, where)
    clip_from_world = np.asarray(camera.clip_from_world)

    # world vertices and faces of all meshes, as one soup
    points_parts, faces_parts, edge_parts, edge_face_parts, kind_parts, mesh_parts = [], [], [], [], [], []
    vertex_offset = face_offset = 0
    for index, (mesh, world_from_model) in enumerate(placed):
        if isinstance(mesh, Polyline):
            # curve segments: drawn always, hidden by faces, hiding nothing
            points = mesh.points @ world_from_model[:3, :3].T + world_from_model[:3, 3]
            segments = _polyline_segments(mesh)
            points_parts.append(points)
            edge_parts.append(segments + vertex_offset)
            edge_face_parts.append(np.full((segments.shape[0], 2), -1, dtype=np.int64))
            kind_parts.append(np.full(segments.shape[0], EDGE_LINE, dtype=np.int64))
            mesh_parts.append(np.full(segments.shape[0], index, dtype=np.int64))
            vertex_offset += points.shape[0]
            continue
        points = mesh.vertices @ world_from_model[:3, :3].T + world_from_model[:3, 3]
        faces = np.asarray(mesh.faces, dtype=np.int64)
        facing = front_facing(clip_from_world, points, faces)
        adjacency = welded_adjacency(mesh)
        kinds = classify_edges(adjacency, points, faces, facing, angle)
        pairs, pair_faces = adjacency.edges, np.stack([adjacency.first, adjacency.second], axis=1)
        chosen = np.ones(kinds.shape, bool) if mask == 0 else (kinds & mask) != 0
        points_parts.append(points)
        faces_parts.append(faces + vertex_offset)
        edge_parts.append(pairs[chosen] + vertex_offset)
        edge_face_parts.append(np.where(pair_faces[chosen] >= 0, pair_faces[chosen] + face_offset, -1))
        kind_parts.append(kinds[chosen])
        mesh_parts.append(np.full(int(chosen.sum()), index, dtype=np.int64))
        vertex_offset += points.shape[0]
        face_offset += faces.shape[0]
    points_world = np.concatenate([np.empty((0, 3)), *points_parts])
    faces_all = np.concatenate([np.empty((0, 3), np.int64), *faces_parts])
    edge_vertices = np.concatenate([np.empty((0, 2), np.int64), *edge_parts])
    edge_faces = np.concatenate([np.empty((0, 2), np.int64), *edge_face_parts])
    edge_kinds = np.concatenate([np.empty(0, np.int64), *kind_parts])
    edge_meshes = np.concatenate([np.empty(0, np.int64), *mesh_parts])
    edges_world = points_world[edge_vertices]  # (E, 2, 3)

    points_clip = points_world @ clip_from_world[:, :3].T + clip_from_world[:, 3]
    occluders, occluder_faces = _window_triangles(points_world, points_clip, faces_all, camera, cull_back_faces)
    segments, parameters, kept = _window_segments(edges_world, clip_from_world, camera)

    hidden_t = _hidden_intervals(segments, edge_faces[kept], occluders, occluder_faces, camera)
    return _assemble(
        edges_world, edge_kinds, edge_meshes, kept, segments, parameters, hidden_t, camera.width, camera.height
    )


def _to_window(points_clip: NDArray, camera: Camera) -> NDArray:
    """(N, 3) window x, y (y up) and NDC z of clip points with w > 0."""
    ndc = points_clip[:, :3] / points_clip[:, 3:]
    return np.stack(
        [(ndc[:, 0] + 1.0) * (camera.width / 2.0), (ndc[:, 1] + 1.0) * (camera.height / 2.0), ndc[:, 2]], axis=1
    )


def _window_triangles(
    points_world: NDArray, points_clip: NDArray, faces: NDArray, camera: Camera, cull_back_faces: bool
) -> tuple[NDArray, NDArray[np.int64]]:
    """(T, 3, 3) window triangles (x, y, z_ndc) clipped to the view volume, and their source faces."""
    if faces.shape[0] == 0:
        return np.empty((0, 3, 3)), np.empty(0, np.int64)
    _, degenerate = _unit_normals(points_world, faces)
    keep = ~degenerate
    if cull_back_faces:
        keep &= front_facing(np.asarray(camera.clip_from_world), points_world, faces)
    source = np.flatnonzero(keep)
    clipped = clip_triangles(points_clip, faces[source])
    window = _to_window(clipped.vertices, camera)[clipped.faces]
    # a face seen edge-on projects to a sliver that covers nothing, but its plane's depth, interpolated over a
    # round-off area, is noise that would hide the edges lying along it (a tessellated cylinder's silhouette)
    sides = window[:, [1, 2, 0], :2] - window[:, :, :2]
    area = np.abs(sides[:, 0, 0] * sides[:, 2, 1] - sides[:, 0, 1] * sides[:, 2, 0])
    covers = area > _SLIVER_FRACTION * (sides**2).sum(axis=2).max(axis=1)
    return np.ascontiguousarray(window[covers]), source[clipped.face_sources][covers]


def _window_segments(
    edges_world: NDArray, clip_from_world: Matrix4, camera: Camera
) -> tuple[NDArray, NDArray, NDArray[np.int64]]:
    """Clipped edges: (K, 2, 4) window x, y, z_ndc, w; (K, 2) world parameters; (K,) indices of kept edges."""
    count = edges_world.shape[0]
    if count == 0:
        return np.empty((0, 2, 4)), np.empty((0, 2)), np.empty(0, np.int64)
    ends_clip = edges_world @ clip_from_world[:, :3].T + clip_from_world[:, 3]
    clipped = clip_lines(ends_clip[:, 0], ends_clip[:, 1])
    starts, ends = clipped.starts, clipped.ends
    window = np.zeros((count, 2, 4))
    keep = clipped.keep.copy()
    for end, points in enumerate((starts, ends)):
        rows = np.flatnonzero(keep)
        window[rows, end, :3] = _to_window(points[rows], camera)
        window[rows, end, 3] = points[rows, 3]
    # an edge along the line of sight projects to a point: nothing to draw
    extent = np.hypot(window[:, 1, 0] - window[:, 0, 0], window[:, 1, 1] - window[:, 0, 1])
    keep &= ~(extent <= _POINT_FRACTION * max(camera.width, camera.height))
    kept = np.flatnonzero(keep)
    return np.ascontiguousarray(window[kept]), np.ascontiguousarray(clipped.parameters[kept]), kept


def _grid(occluders: NDArray, camera: Camera) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
    """Bin the projected triangles' bounding boxes into a uniform grid over the window.

    Returns ``cell_starts`` (C + 1,), ``cell_triangles`` and ``grid`` = (x0, y0, cell size, columns, rows).
    """
    count = occluders.shape[0]
    width, height = float(camera.width), float(camera.height)
    low = occluders[:, :, :2].min(axis=1) if count else np.zeros((0, 2))
    high = occluders[:, :, :2].max(axis=1) if count else np.zeros((0, 2))
    # cells about the size of a typical triangle, about two triangles per cell, at most 4M cells; coarser
    # while large triangles would fill more than 16 cell entries per triangle (a few big faces among many
    # small ones)
    typical = float(np.median((high - low).max(axis=1))) if count else width
    cell = max(typical, math.sqrt(width * height / max(1, count // 2)), max(width, height) / 2048.0, 1e-9)
    boxes = np.empty((count, 4), dtype=np.int64)
    while True:
        columns = max(1, math.ceil(width / cell))
        rows = max(1, math.ceil(height / cell))
        grid = np.array([0.0, 0.0, cell, columns, rows])
        _kernels()._cell_range(low, high, grid, boxes)
        entries = int(((boxes[:, 2] - boxes[:, 0] + 1) * (boxes[:, 3] - boxes[:, 1] + 1)).sum())
        if entries <= max(16 * count, 1 << 20) or columns * rows == 1:
            break
        cell *= 2.0
    counts = np.zeros(columns * rows + 1, dtype=np.int64)
    _kernels()._count_cells(boxes, columns, counts)
    cell_starts = np.zeros(columns * rows + 1, dtype=np.int64)
    np.cumsum(counts[:-1], out=cell_starts[1:])
    cell_triangles = np.empty(int(cell_starts[-1]), dtype=np.int64)
    _kernels()._fill_cells(boxes, columns, cell_starts.copy(), cell_triangles)
    return cell_starts, cell_triangles, grid


def _hidden_intervals(
    segments: NDArray, edge_faces: NDArray, occluders: NDArray, occluder_faces: NDArray, camera: Camera
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Merged hidden t-intervals of each window segment: (K + 1,) offsets and (H, 2) intervals."""
    count = segments.shape[0]
    if count == 0 or occluders.shape[0] == 0:
        return np.zeros(count + 1, dtype=np.int64), np.empty((0, 2))
    cell_starts, cell_triangles, grid = _grid(occluders, camera)
    low = segments[:, :, :2].min(axis=1)
    high = segments[:, :, :2].max(axis=1)
    boxes = np.empty((count, 4), dtype=np.int64)
    _kernels()._cell_range(low, high, grid, boxes)
    tri_boxes = np.empty((occluders.shape[0], 4), dtype=np.int64)
    _kernels()._cell_range(occluders[:, :, :2].min(axis=1), occluders[:, :, :2].max(axis=1), grid, tri_boxes)
    lengths = np.hypot(segments[:, 1, 0] - segments[:, 0, 0], segments[:, 1, 1] - segments[:, 0, 1])
    seg = np.ascontiguousarray(segments[:, :, :3])
    tolerances = np.array([_DEPTH_TOLERANCE, _GAP_FRACTION * max(camera.width, camera.height)])
    counts = np.zeros(count, dtype=np.int64)
    offsets = np.zeros(count + 1, dtype=np.int64)
    out = np.empty((0, 2))
    args = (seg, lengths, boxes, np.ascontiguousarray(edge_faces), occluders, occluder_faces, tri_boxes,
            cell_starts, cell_triangles, grid, tolerances)  # fmt: skip
    _kernels()._segment_intervals(*args, counts, offsets, out, 0)
    np.cumsum(counts, out=offsets[1:])
    out = np.empty((int(offsets[-1]), 2))
    _kernels()._segment_intervals(*args, counts, offsets, out, 1)
    return offsets, out


def _assemble(
    edges_world: NDArray, edge_kinds: NDArray, edge_meshes: NDArray, kept: NDArray, segments: NDArray,
    parameters: NDArray, hidden_t: tuple[NDArray, NDArray], width: int, height: int,
) -> HiddenLines:  # fmt: skip
    offsets, hidden = hidden_t
    count = kept.size
    # visible = complement of the merged hidden intervals in [0, 1]
    per_edge = np.diff(offsets)
    visible_counts = np.zeros(count, dtype=np.int64)
    _kernels()._complement(offsets, hidden, visible_counts, np.empty((0, 2)), 0)
    visible_t = np.empty((int(visible_counts.sum()), 2))
    _kernels()._complement(offsets, hidden, visible_counts, visible_t, 1)
    visible_owner = np.repeat(np.arange(count), visible_counts)
    # drop visible slivers no longer than the gap
    lengths = np.hypot(segments[:, 1, 0] - segments[:, 0, 0], segments[:, 1, 1] - segments[:, 0, 1])
    long_enough = (visible_t[:, 1] - visible_t[:, 0]) * lengths[visible_owner] > _GAP_FRACTION * max(width, height)
    visible_owner, visible_t = visible_owner[long_enough], visible_t[long_enough]
    hidden_owner = np.repeat(np.arange(count), per_edge)

    def pieces(owner: NDArray, t: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        seg = segments[owner]  # (K, 2, 4): x, y, z_ndc, w
        start, end = seg[:, 0], seg[:, 1]
        window = start[:, None, :3] + t[:, :, None] * (end - start)[:, None, :3]
        # window parameter t -> clip parameter s (perspective-correct), then world parameter u
        w0, w1 = start[:, 3:], end[:, 3:]
        s = t * w0 / ((1.0 - t) * w1 + t * w0)
        u0, u1 = parameters[owner, :1], parameters[owner, 1:]
        u = u0 + s * (u1 - u0)
        p0, p1 = edges_world[kept[owner], 0], edges_world[kept[owner], 1]
        world = p0[:, None, :] + u[:, :, None] * (p1 - p0)[:, None, :]
        return window[:, :, :2], (window[:, :, 2] + 1.0) / 2.0, world, kept[owner]

    visible = pieces(visible_owner, visible_t)
    hidden_pieces = pieces(hidden_owner, hidden)
    return HiddenLines(*visible, *hidden_pieces, edges_world, edge_kinds, edge_meshes, int(width), int(height))


# --- kernels --------------------------------------------------------------------------------------------

