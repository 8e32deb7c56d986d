"""Visible-surface detection: back-face detection by the plane equation and by the signed window area.

Two ways to find the back faces of a polyhedron, as the seed gives them:

* **Object space, the plane equation.** A face with corners P0, P1, P2 (counter-clockwise seen from the front)
  lies in the plane $Ax + By + Cz + D = 0$ with $(A, B, C) = (P1 − P0) × (P2 − P0)$ (pointing to the front)
  and $D = −(A, B, C)·P0$. A point is behind the face when $Ax + By + Cz + D < 0$; the face is a back face
  when the viewing position is behind it. For a parallel projection the viewing position is the point at
  infinity ``(d, 0)`` toward the viewer, and the test $A·dx + B·dy + C·dz < 0$ is the same formula with w = 0.
  ``viewing_position`` finds that homogeneous point for any camera.
* **Window space, the signed area.** After projection, a front face is counter-clockwise in window
  coordinates (y up): twice its signed area $(x1 − x0)(y2 − y0) − (x2 − x0)(y1 − y0)$ is positive; a
  back face has a negative (and an edge-on face a zero) area.

For faces in front of the eye both agree (the renderer uses the window test, on its snapped coordinates,
after clipping); the plane test needs no projection and also works for faces behind the eye.

References
----------
[HB 16] "Back-Face Detection"; [seed] "Back-face detection".
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_faces, as_points, describe
from frustum.camera import Camera
from frustum.errors import FrustumError, GeometryError

__all__ = ["backface_mask", "plane_equations", "signed_window_areas", "viewing_position"]


def plane_equations(vertices: ArrayLike, faces: ArrayLike) -> NDArray[np.float64]:
    """(M, 4) plane coefficients ``(A, B, C, D)`` of each face: normal $(P1 − P0) × (P2 − P0)$, $D = −N·P0$.

    Not normalized (the normal's length is twice the face area); a zero-area face gives (0, 0, 0, 0).
    """
    points = as_points(vertices, "vertices", where="plane_equations")
    triangles = as_faces(faces, points.shape[0], where="plane_equations")
    p0, p1, p2 = points[triangles[:, 0]], points[triangles[:, 1]], points[triangles[:, 2]]
    normal = np.cross(p1 - p0, p2 - p0)
    return np.concatenate([normal, -(normal * p0).sum(axis=1, keepdims=True)], axis=1)


def viewing_position(camera: Camera) -> NDArray[np.float64]:
    """(4,) homogeneous world point of the viewing position: ``(eye, 1)``, or ``(d, 0)`` for a parallel projection.

    It is the centre of projection, the point that clip_from_world sends to x = y = w = 0 (its null vector),
    scaled so that its clip z is negative (it lies on the viewer's side of the near plane).
    """
    rows = np.asarray(camera.clip_from_world)[[0, 1, 3]]
    centre = np.linalg.svd(rows)[2][-1]
    if abs(centre[3]) > 1e-12 * np.abs(centre).max():  # a finite eye: make w exactly 1
        centre = centre / centre[3]
        centre[:3] = np.asarray(camera.frame.eye, dtype=np.float64)
    elif camera.clip_from_world[2] @ centre > 0.0:
        centre = -centre
    return centre


def signed_window_areas(window: ArrayLike, faces: ArrayLike) -> NDArray[np.float64]:
    """(M,) twice the signed area of each face in window coordinates: positive = counter-clockwise (y up)."""
    points = np.asarray(window, dtype=np.float64)
    triangles = as_faces(faces, points.shape[0], where="signed_window_areas")
    x, y = points[:, 0], points[:, 1]
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    return (x[b] - x[a]) * (y[c] - y[a]) - (x[c] - x[a]) * (y[b] - y[a])


def backface_mask(
    vertices: ArrayLike,
    faces: ArrayLike,
    camera: Camera,
    method: Literal["plane", "window"] = "plane",
    *,
    record: Callable[..., Any] | None = None,
) -> NDArray[np.bool_]:
    """(M,) bool: True for the back faces of a mesh (world coordinates) seen by `camera`.

    ``method="plane"``: $A·x + B·y + C·z + D·w < 0$ for the viewing position ``(x, y, z, w)``
    (``viewing_position``), in object (world) space. ``method="window"``: signed window area <= 0 after
    ``camera.project`` (clockwise or edge-on); a face with a corner on or behind the eye plane has no window
    image and is reported by the plane test instead. ``record``, if given, is called as
    ``record("planes", planes=..., position=..., values=...)`` with every face's plane test (``frustum.steps``).

    Raises
    ------
    GeometryError
        Bad vertices or faces.
    FrustumError
        An unknown method, or a camera that is not a Camera.
    """
    where = "backface_mask"
    if not isinstance(camera, Camera):
        raise FrustumError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at")
    points = as_points(vertices, "vertices", where=where)
    triangles = as_faces(faces, points.shape[0], where=where, error=GeometryError)
    planes = plane_equations(points, triangles)
    position = viewing_position(camera)
    values = planes @ position
    by_plane = values < 0.0
    if record is not None:  # frustum.steps: each face's plane test
        record("planes", planes=planes, position=position, values=values)
    if method == "plane":
        return by_plane
    if method == "window":
        window = camera.project(points)
        areas = signed_window_areas(window, triangles)
        behind = ~np.isfinite(window[triangles].reshape(len(triangles), -1)).all(axis=1)
        return np.where(behind, by_plane, areas <= 0.0)
    raise FrustumError(f"{where}: method = {describe(method)} is unknown; expected 'plane' or 'window'")
