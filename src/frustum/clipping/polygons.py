"""Polygon and triangle clipping in homogeneous coordinates (Sutherland–Hodgman), with attributes carried along."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_faces, as_homogeneous_points, describe
from frustum.clipping.codes import Recorder, clip_kernels, kernel_codes, kernel_planes, with_view_volume
from frustum.errors import ClippingError

__all__ = ["ClippedPolygon", "ClippedTriangles", "clip_polygon", "clip_triangles"]


class ClippedPolygon(NamedTuple):
    """Result of ``clip_polygon``."""

    vertices: Points
    """(K, 4) float64 clip-space vertices of the clipped polygon, in the input's order; (0, 4) if invisible."""
    attributes: NDArray[np.float64] | None
    """(K, C) (or (K,)) float64 attributes interpolated with the vertices, or None if none were given."""


def clip_polygon(
    vertices_h: ArrayLike,
    attributes: ArrayLike | None = None,
    planes: ArrayLike | None = None,
    *,
    record: Recorder | None = None,
) -> ClippedPolygon:
    """Sutherland–Hodgman: the polygon cut by the cube's six planes (and any user planes), in clip space.

    Plane after plane, each edge S → E of the current polygon gives: E inside and S outside → the
    intersection then E; both inside → E; S inside and E outside → the intersection; both outside → nothing.
    The intersection is $P = P_in + (P_out − P_in)u$ with $u = d_in / (d_in − d_out)$, computed from the
    inside end; attributes interpolate with the same u, i.e. linearly in clip space (the perspective-correct
    choice: they are then divided by w with the position). A convex polygon stays convex; a concave one may
    come back with zero-width connecting edges along a plane (the algorithm's known trait; its area is right).

    Parameters
    ----------
    vertices_h : (N, 4) array_like
        Clip-space vertices in order, N >= 3 (or 0).
    attributes : (N, C) or (N,) array_like, optional
        Per-vertex values to interpolate (colors, normals, uv, ...).
    planes : (K, 4) or (4,) array_like, optional
        Extra clip-space planes, applied after the cube's six.
    record : callable, optional
        Called as ``record(event, **values)``: the polygon after each plane (``frustum.steps``).

    Returns
    -------
    ClippedPolygon
        ``vertices`` (M, 4) and ``attributes`` (M, C) or None. A polygon wholly inside comes back unchanged;
        one that keeps fewer than 3 vertices (it touches the volume at a point or an edge), or whose every
        vertex has w <= 0 (it collapsed onto the clip-space origin, e.g. a triangle lying in the eye plane),
        comes back empty.

    Raises
    ------
    ClippingError
        If shapes are wrong (including attributes with a different row count), or a value is not finite.

    References
    ----------
    [HB 10] "Three-Dimensional Polygon Clipping", "Clipping in Three-Dimensional Homogeneous Coordinates";
    [seed] "3D Polygon clipping".
    """
    vertices = as_homogeneous_points(vertices_h, "vertices_h", where="clip_polygon", error=ClippingError)
    if 0 < vertices.shape[0] < 3:
        raise ClippingError(
            f"clip_polygon: vertices_h has {vertices.shape[0]} rows; a polygon needs at least 3 vertices"
        )
    values = _with_attributes(vertices, attributes)
    if record is not None:
        record("start", polygon=values[:, :4].copy())
    for k, plane in enumerate(with_view_volume(planes, "clip_polygon")):
        if values.shape[0] == 0:
            break
        before = values
        values = _clip_against_plane(values, plane)
        if record is not None:
            record("plane", plane=k, distances=before[:, :4] @ plane, before=before[:, :4].copy(),
                   polygon=values[:, :4].copy())  # fmt: skip
    # touching a plane at a point or along an edge leaves no area; and a polygon with no vertex of w > 0 is
    # collapsed onto the clip-space origin (0, 0, 0, 0), the one code-0 point that is no visible position
    if values.shape[0] < 3 or not (values[:, 3] > 0).any():
        values = values[:0]
    if attributes is None:
        return ClippedPolygon(values[:, :4], None)
    clipped_attributes = values[:, 4:].reshape((values.shape[0], *np.shape(attributes)[1:]))
    return ClippedPolygon(values[:, :4], clipped_attributes)


def _clip_against_plane(values: NDArray, plane: NDArray) -> NDArray:
    distances = values[:, :4] @ plane
    out: list[NDArray] = []
    s = values.shape[0] - 1
    for e in range(values.shape[0]):
        d_s, d_e = distances[s], distances[e]
        if d_e >= 0:
            if d_s < 0 and d_e > 0:  # entering: intersection, computed from the inside end E
                out.append(values[e] + (values[s] - values[e]) * (d_e / (d_e - d_s)))
            out.append(values[e])
        elif d_s > 0:  # leaving: intersection, computed from the inside end S
            out.append(values[s] + (values[e] - values[s]) * (d_s / (d_s - d_e)))
        s = e
    return np.array(out).reshape(-1, values.shape[1])


def _with_attributes(vertices: NDArray, attributes: ArrayLike | None) -> NDArray:
    """Positions and attributes side by side, (N, 4 + C): one interpolation moves both."""
    if attributes is None:
        return vertices
    try:
        array = np.asarray(attributes, dtype=np.float64)
    except (TypeError, ValueError):
        raise ClippingError(
            f"clip_polygon: attributes = {describe(attributes)} is not numeric; expected (N, C) numbers"
        ) from None
    if array.ndim not in (1, 2) or array.shape[0] != vertices.shape[0]:
        raise ClippingError(
            f"clip_polygon: attributes has shape {array.shape}; expected ({vertices.shape[0]}, C) or "
            f"({vertices.shape[0]},), one row per vertex"
        )
    bad = np.flatnonzero(~np.isfinite(array.reshape(array.shape[0], -1)).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise ClippingError(
            f"clip_polygon: attributes[{i}] = {describe(array[i])} is not finite; attributes must be finite"
        )
    return np.hstack([vertices, array.reshape(array.shape[0], -1)])


class ClippedTriangles(NamedTuple):
    """Result of ``clip_triangles``: an indexed triangle mesh in clip space, with where every piece came from.

    ``vertices`` starts with the V input vertices, unchanged and in order, followed by the K new vertices
    that clipping made. Triangles wholly inside keep their input indices; clipped ones are fanned out of
    their polygon, reusing the input index of every corner that survived.
    """

    vertices: Points
    """(V + K, 4) float64: the input vertices, then the new ones."""
    faces: NDArray[np.int64]
    """(F, 3) int64 output triangles, in input order (a clipped triangle's fan where the triangle was), same
    winding as their source."""
    face_sources: NDArray[np.int64]
    """(F,) int64: the input triangle each output triangle comes from (for per-face data)."""
    new_vertex_sources: NDArray[np.int64]
    """(K,) int64: the input triangle each new vertex ``vertices[V + k]`` lies in."""
    new_vertex_weights: NDArray[np.float64]
    """(K, 3) float64 barycentric weights of each new vertex w.r.t. its source triangle's corners (clip space:
    ``vertices[V + k] = Σ_j weights[k, j]·vertices[faces_in[source, j]]`` up to round-off)."""

    def interpolate(self, faces: ArrayLike, attributes: ArrayLike) -> NDArray[np.float64]:
        """Per-vertex `attributes` (V, ...) of the input mesh extended to all V + K output vertices.

        `faces` are the input faces given to ``clip_triangles``. New vertices get $Σ_j w_j·attribute_j$
        over their source triangle's corners (linear in clip space).
        """
        values = np.asarray(attributes, dtype=np.float64)
        corners = np.asarray(faces)[self.new_vertex_sources]  # (K, 3) input vertex indices
        new_values = np.einsum("kj,kj...->k...", self.new_vertex_weights, values[corners])
        return np.concatenate([values, new_values])


def clip_triangles(vertices_h: ArrayLike, faces: ArrayLike, planes: ArrayLike | None = None) -> ClippedTriangles:
    """Clip a triangle mesh in clip space against the cube (and any user planes): the renderer's batch clipper.

    Region codes per vertex give each triangle a trivial accept (``c0 | c1 | c2 == 0``: kept untouched, same
    indices), a trivial reject (``c0 & c1 & c2 != 0``: dropped at the cost of two integer operations) or a
    clip: Sutherland–Hodgman on that triangle (``raster.clip.clip_triangle``, a kernel other kernels call),
    whose convex polygon is fanned into triangles ``(0, i, i + 1)``. Polygons that degenerate to fewer than
    three vertices (a triangle touching a plane at a point or an edge) are dropped.

    Parameters
    ----------
    vertices_h : (V, 4) array_like
        Clip-space vertices, e.g. ``apply_homogeneous(clip_from_world, points_world)``.
    faces : (M, 3) array_like of int
        Vertex indices of each triangle.
    planes : (K, 4) array_like, optional
        Extra clip-space planes (a cutaway: ``transform_plane(clip_from_world, plane_world)``), at most
        $MAX_KERNEL_PLANES − 6$.

    Returns
    -------
    ClippedTriangles
        Output vertices, faces, each face's source triangle, and each new vertex's source triangle and
        barycentric weights (``ClippedTriangles.interpolate`` extends any per-vertex attribute).

    Raises
    ------
    ClippingError
        If a shape or dtype is wrong, a coordinate is not finite, an index is out of range, or a plane is bad.

    References
    ----------
    [HB 10] "Three-Dimensional Polygon Clipping", "Clipping in Three-Dimensional Homogeneous Coordinates";
    [seed] "Three-dimensional Region Codes", "3D Polygon clipping".
    """
    vertices = as_homogeneous_points(vertices_h, "vertices_h", where="clip_triangles", error=ClippingError)
    triangles = as_faces(faces, vertices.shape[0], where="clip_triangles", error=ClippingError)
    all_planes = kernel_planes(planes, "clip_triangles")
    # trivial accept / reject from the vertices' region codes
    status = np.empty(triangles.shape[0], dtype=np.int8)
    clip_kernels().classify_triangles(triangles, kernel_codes(vertices, all_planes), status)
    crossing = np.flatnonzero(status == clip_kernels().TRIANGLE_CROSSING)
    # Sutherland–Hodgman on the rest
    capacity = 3 + all_planes.shape[0]
    positions = np.empty((crossing.size, capacity, 4))
    weights = np.empty((crossing.size, capacity, 3))
    counts = np.empty(crossing.size, dtype=np.int64)
    clip_kernels().clip_crossing_triangles(vertices, triangles, crossing, all_planes, positions, weights, counts)
    counts[counts < 3] = 0  # points and slivers have no area
    return _assemble(vertices, triangles, status, crossing, positions, weights, counts)


def _assemble(
    vertices: NDArray, triangles: NDArray, status: NDArray, crossing: NDArray,
    positions: NDArray, weights: NDArray, counts: NDArray,
) -> ClippedTriangles:  # fmt: skip
    capacity = positions.shape[1]
    used = np.arange(capacity) < counts[:, None]  # (C, capacity) polygon slots in use
    # a surviving corner has its exact one-hot weights: reuse the input vertex index
    corner = used & (weights == 1.0).any(axis=2) & ((weights == 0.0).sum(axis=2) == 2)
    new = used & ~corner
    index = np.zeros((crossing.size, capacity), dtype=np.int64)
    corner_rows, corner_slots = np.nonzero(corner)
    index[corner_rows, corner_slots] = triangles[
        crossing[corner_rows], np.argmax(weights[corner_rows, corner_slots], axis=1)
    ]
    new_rows, new_slots = np.nonzero(new)
    index[new_rows, new_slots] = vertices.shape[0] + np.arange(new_rows.size)
    # fan (0, i, i + 1) of each polygon, placed where its source triangle was
    face_count = int(np.count_nonzero(status == clip_kernels().TRIANGLE_INSIDE) + np.maximum(counts - 2, 0).sum())
    out_faces = np.empty((face_count, 3), dtype=np.int64)
    face_sources = np.empty(face_count, dtype=np.int64)
    clip_kernels().assemble_faces(triangles, status, index, counts, out_faces, face_sources)
    return ClippedTriangles(
        vertices=np.concatenate([vertices, positions[new_rows, new_slots]]),
        faces=out_faces,
        face_sources=face_sources,
        new_vertex_sources=crossing[new_rows],
        new_vertex_weights=weights[new_rows, new_slots],
    )
