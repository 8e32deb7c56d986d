"""The indexed triangle mesh: vertices, faces and per-vertex normals in model coordinates."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import Points, as_faces, as_points, read_only
from frustum.errors import GeometryError

__all__ = ["Mesh"]


@dataclass(frozen=True, eq=False)
class Mesh:
    """An indexed triangle mesh: ``vertices`` (N, 3), ``faces`` (M, 3), unit ``vertex_normals`` (N, 3).

    Faces list vertex indices **counter-clockwise seen from the front** (the side the normals point to), so
    the face normal is ``(v1 − v0) × (v2 − v0)``. Without given normals, each vertex normal is the
    area-weighted average of the normals of the faces around it: the sum of the unnormalized cross products
    ``(v1 − v0) × (v2 − v0)`` (whose length is twice the face area), normalized. A vertex that no face uses, or
    whose faces cancel, gets the normal (0, 0, 1), so shading stays finite.

    Parameters
    ----------
    vertices : (N, 3) array_like
        Finite model coordinates (stored float64).
    faces : (M, 3) array_like of int
        Vertex indices in [0, N). An empty mesh (M = 0) is valid.
    vertex_normals : (N, 3) array_like, optional
        Finite, nonzero per-vertex normals; normalized on construction.

    Raises
    ------
    GeometryError
        Wrong shapes, non-finite coordinates, indices out of range, or zero-length normals.

    The arrays are read-only; operations return new meshes.
    """

    vertices: Points
    faces: NDArray[np.int64]
    vertex_normals: Points | None = None

    def __post_init__(self) -> None:
        where = "Mesh"
        vertices = as_points(self.vertices, "vertices", where=where)
        faces = as_faces(self.faces, vertices.shape[0], "faces", where=where)
        object.__setattr__(self, "vertices", read_only(vertices))
        object.__setattr__(self, "faces", read_only(faces))
        if self.vertex_normals is None:
            normals = _area_weighted_normals(vertices, faces)
        else:
            normals = as_points(self.vertex_normals, "vertex_normals", where=where)
            if normals.shape[0] != vertices.shape[0]:
                raise GeometryError(
                    f"{where}: vertex_normals has {normals.shape[0]} rows for {vertices.shape[0]} vertices; "
                    "give one normal per vertex"
                )
            lengths = np.sqrt((normals * normals).sum(axis=1))
            zero = np.flatnonzero(lengths == 0.0)
            if zero.size:
                i = int(zero[0])
                raise GeometryError(
                    f"{where}: vertex_normals[{i}] = {normals[i].tolist()} has zero length; normals must be nonzero"
                )
            normals = normals / lengths[:, None]
        object.__setattr__(self, "vertex_normals", read_only(np.ascontiguousarray(normals)))

    @property
    def vertex_count(self) -> int:
        """N, the number of vertices."""
        return int(self.vertices.shape[0])

    @property
    def face_count(self) -> int:
        """M, the number of triangles."""
        return int(self.faces.shape[0])

    @cached_property
    def face_normals(self) -> Points:
        """(M, 3) unit face normals ``(v1 − v0) × (v2 − v0)`` normalized; (0, 0, 0) for a zero-area face."""
        cross = _face_cross_products(self.vertices, self.faces)
        lengths = np.sqrt((cross * cross).sum(axis=1))
        with np.errstate(invalid="ignore", divide="ignore"):
            normals = np.where(lengths[:, None] > 0.0, cross / lengths[:, None], 0.0)
        return read_only(normals)

    @cached_property
    def bounds(self) -> Points:
        """(2, 3): the minimum and maximum corner of the axis-aligned bounding box (NaN for no vertices)."""
        if self.vertex_count == 0:
            return read_only(np.full((2, 3), np.nan))
        return read_only(np.stack([self.vertices.min(axis=0), self.vertices.max(axis=0)]))


def _face_cross_products(vertices: Points, faces: NDArray[np.int64]) -> Points:
    v0, v1, v2 = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    return np.cross(v1 - v0, v2 - v0)


def _area_weighted_normals(vertices: Points, faces: NDArray[np.int64]) -> Points:
    # sum of each face's (v1 − v0) × (v2 − v0) (length 2·area) over the faces at a vertex, then normalize
    cross = _face_cross_products(vertices, faces)
    sums = np.zeros_like(vertices)
    for corner in range(3):
        np.add.at(sums, faces[:, corner], cross)
    lengths = np.sqrt((sums * sums).sum(axis=1))
    normals = np.empty_like(vertices)
    ok = lengths > 0.0
    normals[ok] = sums[ok] / lengths[ok, None]
    normals[~ok] = (0.0, 0.0, 1.0)
    return normals
