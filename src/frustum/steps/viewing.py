"""Viewing, step by step: the pipeline world → view → projection → normalization → viewport, and back faces.

``viewing_pipeline`` is ``frustum.trace`` (the renderer's stages, recorded) drawn stage by stage, with the view
volume's eight corners traced along so that the frustum visibly becomes the canonical cube.

References: [HB 10] "The Three-Dimensional Viewing Pipeline"; [seed] "Three-Dimensional Viewing Pipeline".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_points
from frustum.camera import Camera
from frustum.errors import FrustumError, GeometryError
from frustum.projection import Perspective
from frustum.steps._draw import CUBE_CORNERS, CUBE_EDGES, cartesian, oblique
from frustum.steps._record import Step, Steps, _Canvas
from frustum.steps.modeling import HOUSE_EDGES, HOUSE_POINTS
from frustum.trace import trace

__all__ = ["default_camera", "viewing_pipeline"]


def default_camera() -> Camera:
    """The camera of the chapter's examples: looking at the house from front right above, near 1, far 8."""
    return Camera.look_at((3.0, 2.5, 4.0), (0.5, 0.6, 0.5), projection=Perspective(math.radians(50), 1.0, 8.0),
                          width=64, height=48)  # fmt: skip


def _camera(camera: Any, where: str) -> Camera:
    if camera is None:
        return default_camera()
    if not isinstance(camera, Camera):
        raise FrustumError(f"{where}: camera = {camera!r} is not a Camera; build one with Camera.look_at")
    return camera


def _fit(points2: NDArray) -> NDArray:
    """Map (N, 2) into [0, 1]² keeping the aspect (each stage's own scale: the stages differ by orders)."""
    finite = points2[np.isfinite(points2).all(axis=1)]
    if finite.size == 0:
        return points2
    low, high = finite.min(axis=0), finite.max(axis=0)
    size = max(float((high - low).max()), 1e-12)
    return (points2 - low) / size + (1.0 - (high - low) / size) / 2.0


def viewing_pipeline(points: ArrayLike | None = None, camera: Camera | None = None, edges: Any = None) -> Steps:
    """The viewing pipeline stage by stage, for `points` (default a small house) seen by `camera`.

    Every stage of ``trace(points, camera)`` is one step (its matrix and the coordinates of the first
    points); the figure shows the object and the view volume (its corners traced with the points) in that
    stage's coordinates, so the frustum becomes the canonical cube. ``result`` is the window coordinates of
    `points` (``trace(...).window``, equal to ``camera.project(points)``).
    """
    where = "steps.viewing_pipeline"
    cam = _camera(camera, where)
    if points is None:
        object_points, lines = HOUSE_POINTS, HOUSE_EDGES
    else:
        object_points = as_points(points, "points", where=where, error=GeometryError)
        lines = edges if edges is not None else [(i, i + 1) for i in range(len(object_points) - 1)]
    inverse = np.linalg.inv(np.asarray(cam.clip_from_world))
    corners_h = np.column_stack([CUBE_CORNERS, np.ones(8)]) @ inverse.T
    corners_world = corners_h[:, :3] / corners_h[:, 3:]
    count = len(object_points)
    traced = trace(np.vstack([object_points, corners_world]), cam)
    result = np.asarray(traced.window)[:count]
    steps: list[Step] = []
    drawn: list[NDArray] = []
    for stage in traced.stages:
        values: dict[str, Any] = {}
        if stage.matrix is not None:
            values["matrix"] = np.round(stage.matrix, 4)
        values["first point"] = stage.points[0]
        if stage.codes is not None:
            values["region codes"] = [format(int(c), "06b") for c in stage.codes[:count]]
        steps.append(Step(stage.title, stage.description[:1].upper() + stage.description[1:] + ".", values))
        coordinates = np.asarray(stage.points)
        drawn.append(cartesian(coordinates) if coordinates.shape[1] == 4 else coordinates[:, :3])

    def paint(index: int, canvas: _Canvas) -> None:
        points2 = _fit(oblique(drawn[index]))
        box = points2[count:]
        for a, b in CUBE_EDGES:
            canvas.line(box[a], box[b], color="highlight", width=1.0, dash=True)
        for a, b in lines:
            canvas.line(points2[a], points2[b], color="blue", width=2.0)
        canvas.label((0.0, 1.02), f"view volume (dashed), object (blue): {traced.stages[index].name}", color="ink",
                     size=12)  # fmt: skip

    return Steps("The viewing pipeline", steps, result, paint, (0.0, 0.0, 1.0, 1.05))
