"""Clip-space clipping kernels: region codes, Liang–Barsky segments, Sutherland–Hodgman triangles.

Every kernel works on homogeneous clip-space points ``(x, y, z, w)`` and on planes given as 4-vectors
``(a, b, c, d)``: a point is inside a plane when $a·x + b·y + c·z + d·w >= 0$ (exactly; no tolerance). The
symmetric view volume $−w <= x, y, z <= w$ is the six planes $w + x >= 0$ (left), $w − x >= 0$ (right),
``w + y`` (bottom), $w − y$ (top), ``w + z`` (near), $w − z$ (far); ``clipping.py`` builds that array and
appends any user planes. Plane ``k`` owns bit ``k`` (value ``1 << k``) of a region code, so at most 63 planes.

Contracts (kernels never validate): arrays are C-contiguous float64 (int64 for faces and codes), faces index
into the vertex array, scratch buffers have room for ``3 + len(planes)`` vertices (clipping a convex polygon by
one plane adds at most one vertex).
"""

from __future__ import annotations

import numpy as np

from frustum.raster._jit import kernel

__all__ = [
    "TRIANGLE_CROSSING",
    "TRIANGLE_INSIDE",
    "TRIANGLE_OUTSIDE",
    "assemble_faces",
    "classify_triangles",
    "clip_against_plane",
    "clip_convex_polygon",
    "clip_crossing_triangles",
    "clip_segment",
    "clip_segments",
    "clip_triangle",
    "plane_distance",
    "region_codes",
]

TRIANGLE_INSIDE = 0
"""Every vertex inside every plane: the triangle passes unchanged (trivial accept)."""
TRIANGLE_OUTSIDE = 1
"""All three vertices outside one same plane: nothing of the triangle is visible (trivial reject)."""
TRIANGLE_CROSSING = 2
"""Neither: the triangle has to be clipped."""


@kernel
def plane_distance(plane: np.ndarray, point: np.ndarray) -> float:
    """Signed plane value $a·x + b·y + c·z + d·w$ of one (4,) point: ``>= 0`` is inside."""
    return plane[0] * point[0] + plane[1] * point[1] + plane[2] * point[2] + plane[3] * point[3]


@kernel
def region_codes(points: np.ndarray, planes: np.ndarray, codes: np.ndarray) -> None:
    """Write into ``codes[i]`` the region code of ``points[i]``: bit k set when the point is outside plane k.

    points (N, 4) float64, planes (P, 4) float64 with P <= 63, codes (N,) int64 (written).
    """
    for i in range(points.shape[0]):
        code = 0
        for k in range(planes.shape[0]):
            if plane_distance(planes[k], points[i]) < 0.0:
                code |= 1 << k
        codes[i] = code


@kernel
def classify_triangles(faces: np.ndarray, codes: np.ndarray, status: np.ndarray) -> None:
    """Trivial accept / reject of every triangle from its vertices' region codes.

    ``c0 | c1 | c2 == 0`` → ``TRIANGLE_INSIDE``; ``c0 & c1 & c2 != 0`` → ``TRIANGLE_OUTSIDE``; otherwise
    ``TRIANGLE_CROSSING``. faces (M, 3) int64, codes (N,) int64, status (M,) int8 (written).
    """
    for t in range(faces.shape[0]):
        c0, c1, c2 = codes[faces[t, 0]], codes[faces[t, 1]], codes[faces[t, 2]]
        if (c0 | c1 | c2) == 0:
            status[t] = TRIANGLE_INSIDE
        elif (c0 & c1 & c2) != 0:
            status[t] = TRIANGLE_OUTSIDE
        else:
            status[t] = TRIANGLE_CROSSING


@kernel
def clip_segment(start: np.ndarray, end: np.ndarray, planes: np.ndarray) -> tuple[float, float]:
    """Liang–Barsky: the parameter interval ``[u0, u1]`` of $P = P1 + (P2 − P1)u$ inside every plane.

    For each plane, $p_k = d(P1) − d(P2)$ and $q_k = d(P1)$; the inside part satisfies $p_k·u <= q_k$.
    $p_k < 0$ (entering) raises u0 to ``q_k/p_k``, $p_k > 0$ (leaving) lowers u1, $p_k = 0$ (parallel)
    rejects when $q_k < 0$. Returns ``(u0, u1)``; $u0 > u1$ means nothing is inside (``(1.0, 0.0)``).
    """
    u0, u1 = 0.0, 1.0
    for k in range(planes.shape[0]):
        q = plane_distance(planes[k], start)
        p = q - plane_distance(planes[k], end)
        if p == 0.0:
            if q < 0.0:
                return 1.0, 0.0
        elif p < 0.0:
            u0 = max(u0, q / p)
        else:
            u1 = min(u1, q / p)
        if u0 > u1:
            return 1.0, 0.0
    return u0, u1


@kernel
def clip_segments(
    starts: np.ndarray,
    ends: np.ndarray,
    planes: np.ndarray,
    clipped_starts: np.ndarray,
    clipped_ends: np.ndarray,
    parameters: np.ndarray,
) -> None:
    """Liang–Barsky on every segment; rows of a fully clipped segment get NaN and $parameters = (1, 0)$.

    starts, ends (N, 4) float64; clipped_starts, clipped_ends (N, 4) and parameters (N, 2) written. An end
    that is not moved (u0 = 0 or u1 = 1) is copied bit for bit.
    """
    for i in range(starts.shape[0]):
        u0, u1 = clip_segment(starts[i], ends[i], planes)
        parameters[i, 0], parameters[i, 1] = u0, u1
        for j in range(4):
            if u0 > u1:
                clipped_starts[i, j] = np.nan
                clipped_ends[i, j] = np.nan
                continue
            delta = ends[i, j] - starts[i, j]
            clipped_starts[i, j] = starts[i, j] if u0 == 0.0 else starts[i, j] + delta * u0
            clipped_ends[i, j] = ends[i, j] if u1 == 1.0 else starts[i, j] + delta * u1


@kernel
def _write_intersection(
    inside: int, outside: int, u: float, positions: np.ndarray, weights: np.ndarray, out: int,
    out_positions: np.ndarray, out_weights: np.ndarray,
) -> None:  # fmt: skip
    """$P = P_in + (P_out − P_in)u$ for the position and the barycentric weights alike."""
    for j in range(4):
        out_positions[out, j] = positions[inside, j] + (positions[outside, j] - positions[inside, j]) * u
    for j in range(3):
        out_weights[out, j] = weights[inside, j] + (weights[outside, j] - weights[inside, j]) * u


@kernel
def _copy_vertex(
    source: int, positions: np.ndarray, weights: np.ndarray, out: int, out_positions: np.ndarray,
    out_weights: np.ndarray,
) -> None:  # fmt: skip
    """Copy one polygon vertex (position and weights) from slot `source` to slot `out`."""
    for j in range(4):
        out_positions[out, j] = positions[source, j]
    for j in range(3):
        out_weights[out, j] = weights[source, j]


@kernel
def clip_against_plane(
    plane: np.ndarray, count: int, positions: np.ndarray, weights: np.ndarray,
    out_positions: np.ndarray, out_weights: np.ndarray,
) -> int:  # fmt: skip
    """One Sutherland–Hodgman pass: the polygon ``positions[:count]`` cut by one plane; returns the new count.

    For each edge S → E: E inside and S outside → intersection, E; both inside → E; S inside, E outside →
    intersection; both outside → nothing. The intersection is always computed from the inside end toward the
    outside end, so two triangles sharing an edge get bit-identical points, and it is skipped when the inside
    end lies exactly on the plane (it would repeat that end).
    """
    n = 0
    s = count - 1
    ds = plane_distance(plane, positions[s])
    for e in range(count):
        de = plane_distance(plane, positions[e])
        if de >= 0.0:
            if ds < 0.0 and de > 0.0:
                _write_intersection(e, s, de / (de - ds), positions, weights, n, out_positions, out_weights)
                n += 1
            _copy_vertex(e, positions, weights, n, out_positions, out_weights)
            n += 1
        elif ds > 0.0:
            _write_intersection(s, e, ds / (ds - de), positions, weights, n, out_positions, out_weights)
            n += 1
        s, ds = e, de
    return n


@kernel
def clip_convex_polygon(count: int, planes: np.ndarray, positions: np.ndarray, weights: np.ndarray) -> int:
    """Sutherland–Hodgman against every plane, ping-ponging between two scratch halves; returns the count.

    positions (2, capacity, 4) and weights (2, capacity, 3) float64: the polygon is read from
    ``positions[0, :count]`` and the clipped one is left there (weights alike). Planes that every vertex is
    inside are skipped; a plane that every vertex is outside ends the clip with 0.
    """
    source = 0
    for k in range(planes.shape[0]):
        outside = 0
        for i in range(count):
            if plane_distance(planes[k], positions[source, i]) < 0.0:
                outside += 1
        if outside == 0:
            continue
        if outside == count:
            return 0
        target = 1 - source
        count = clip_against_plane(
            planes[k], count, positions[source], weights[source], positions[target], weights[target]
        )
        source = target
    if source == 1:
        for i in range(count):
            _copy_vertex(i, positions[1], weights[1], i, positions[0], weights[0])
    return count


@kernel
def clip_triangle(
    p0: np.ndarray, p1: np.ndarray, p2: np.ndarray, planes: np.ndarray, positions: np.ndarray, weights: np.ndarray
) -> int:
    """Clip one triangle (three (4,) clip-space vertices) against every plane; returns the vertex count.

    The clipped convex polygon is written to ``positions[0, :count]`` with, in ``weights[0, :count]``, each
    vertex's barycentric weights with respect to (p0, p1, p2): any per-vertex attribute interpolates as
    $Σ weights[j]·attribute_j$. An unclipped corner keeps the exact one-hot weights of its corner. Scratch:
    positions (2, 3 + P, 4), weights (2, 3 + P, 3) float64, owned by the caller.
    """
    for j in range(4):
        positions[0, 0, j], positions[0, 1, j], positions[0, 2, j] = p0[j], p1[j], p2[j]
    for i in range(3):
        for j in range(3):
            weights[0, i, j] = 1.0 if i == j else 0.0
    return clip_convex_polygon(3, planes, positions, weights)


@kernel
def clip_crossing_triangles(
    vertices: np.ndarray, faces: np.ndarray, crossing: np.ndarray, planes: np.ndarray,
    positions: np.ndarray, weights: np.ndarray, counts: np.ndarray,
) -> None:  # fmt: skip
    """Clip the triangles ``faces[crossing[i]]``; polygon i goes to ``positions[i, :counts[i]]`` (weights alike).

    vertices (N, 4) float64, faces (M, 3) int64, crossing (C,) int64, planes (P, 4) float64; written:
    positions (C, 3 + P, 4), weights (C, 3 + P, 3) float64, counts (C,) int64.
    """
    capacity = 3 + planes.shape[0]
    scratch_positions = np.empty((2, capacity, 4))
    scratch_weights = np.empty((2, capacity, 3))
    for i in range(crossing.shape[0]):
        face = faces[crossing[i]]
        count = clip_triangle(
            vertices[face[0]], vertices[face[1]], vertices[face[2]], planes, scratch_positions, scratch_weights
        )
        for v in range(count):
            _copy_vertex(v, scratch_positions[0], scratch_weights[0], v, positions[i], weights[i])
        counts[i] = count


@kernel
def assemble_faces(
    faces: np.ndarray, status: np.ndarray, polygons: np.ndarray, counts: np.ndarray,
    out_faces: np.ndarray, face_sources: np.ndarray,
) -> None:  # fmt: skip
    """Write the output mesh in input order: inside triangles as they are, each clipped one as its fan.

    faces (M, 3) int64, status (M,) int8; polygons (C, capacity) int64 holds the output vertex index of each
    clipped triangle's polygon vertices (the C crossing triangles in increasing order), counts (C,) int64 their
    sizes (< 3: dropped). Written: out_faces (F, 3) int64 with the fan ``(0, i, i + 1)``, face_sources (F,).
    """
    n = 0
    polygon = 0
    for t in range(faces.shape[0]):
        if status[t] == TRIANGLE_INSIDE:
            out_faces[n, 0], out_faces[n, 1], out_faces[n, 2] = faces[t, 0], faces[t, 1], faces[t, 2]
            face_sources[n] = t
            n += 1
        elif status[t] == TRIANGLE_CROSSING:
            for i in range(1, counts[polygon] - 1):
                out_faces[n, 0] = polygons[polygon, 0]
                out_faces[n, 1] = polygons[polygon, i]
                out_faces[n, 2] = polygons[polygon, i + 1]
                face_sources[n] = t
                n += 1
            polygon += 1
