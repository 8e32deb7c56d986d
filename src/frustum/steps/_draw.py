"""Drawing helpers shared by the chapters: a fixed oblique view of 3D points, the canonical cube, bounds."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum.steps._record import _Canvas

# cabinet-like oblique view: depth z (into the screen in NDC) drawn up and to the right at half length
_DEPTH_X, _DEPTH_Y = 0.5 * np.cos(np.radians(35.0)), 0.5 * np.sin(np.radians(35.0))

CUBE_CORNERS = np.array([[x, y, z] for z in (-1.0, 1.0) for y in (-1.0, 1.0) for x in (-1.0, 1.0)])
CUBE_EDGES = [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)]
# the faces of the cube in region-code order: left, right, bottom, top, near, far (corner indices, in a loop)
CUBE_FACES = [(0, 2, 6, 4), (1, 3, 7, 5), (0, 1, 5, 4), (2, 3, 7, 6), (0, 1, 3, 2), (4, 5, 7, 6)]
PLANE_NAMES = ("left", "right", "bottom", "top", "near", "far")


def oblique(points: Any) -> NDArray[np.float64]:
    """(N, 3) → (N, 2): x + a·z, y + b·z (a fixed oblique view; NDC z grows away from the viewer)."""
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    return np.column_stack([p[:, 0] + _DEPTH_X * p[:, 2], p[:, 1] + _DEPTH_Y * p[:, 2]])


def cartesian(points_h: Any) -> NDArray[np.float64]:
    """(N, 4) clip-space points → (N, 3) for drawing: divided by w where w > 0, else x, y, z as they are."""
    p = np.asarray(points_h, dtype=float).reshape(-1, 4)
    w = np.where(p[:, 3] > 0, p[:, 3], 1.0)
    return p[:, :3] / w[:, None]


def bounds_of(points2: Any, pad: float = 0.08) -> tuple[float, float, float, float]:
    p = np.asarray(points2, dtype=float).reshape(-1, 2)
    p = p[np.isfinite(p).all(axis=1)]
    x0, y0 = p.min(axis=0)
    x1, y1 = p.max(axis=0)
    margin = pad * max(x1 - x0, y1 - y0, 1e-9)
    return x0 - margin, y0 - margin, x1 + margin, y1 + margin


def draw_cube(canvas: _Canvas, project: Callable[[Any], NDArray] = oblique, face: int | None = None) -> None:
    """The canonical view volume [−1, 1]³ as a wireframe; `face` (region-code order) shaded."""
    corners = project(CUBE_CORNERS)
    if face is not None and face < len(CUBE_FACES):
        canvas.polyline(corners[list(CUBE_FACES[face])], color="highlight", closed=True, fill="highlight",
                        opacity=0.15, width=1.0)  # fmt: skip
    for a, b in CUBE_EDGES:
        canvas.line(corners[a], corners[b], color="faint", width=1.0)
