"""Visible surfaces step by step, the octree method: the subdivision of a solid level by level, then the
front-to-back traversal, each pixel written once.

References: [HB 16] "Octree Methods".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum.camera import Camera
from frustum.errors import FrustumError
from frustum.steps._record import Step, Steps, _Canvas
from frustum.steps.viewing import _camera

__all__ = ["default_octree", "octree"]


_OCTREE_OUTCOMES = ("outside the view volume", "on no pixel centre", "hidden: every pixel under it is written",
                    "drawn", "children visited, nearest octant first", "crossing the near plane")  # fmt: skip


def default_octree() -> tuple[Any, Camera]:
    """A ball as a depth-3 octree and a camera looking at it from above and in front."""
    from frustum.geometry.octree import Octree
    from frustum.projection import Perspective

    ball = Octree.from_function(lambda x, y, z: x * x + y * y + z * z - 0.8, ((-1, -1, -1), (1, 1, 1)), 3)
    camera = Camera.look_at((2.2, 1.8, 3.0), (0.0, 0.0, 0.0), projection=Perspective(math.radians(40), 0.1, 20.0),
                            width=64, height=48)  # fmt: skip
    return ball, camera


def _morton_ijk(code: int, level: int) -> tuple[int, int, int]:
    i = j = k = 0
    for bit in range(level):
        i |= ((code >> (3 * bit)) & 1) << bit
        j |= ((code >> (3 * bit + 1)) & 1) << bit
        k |= ((code >> (3 * bit + 2)) & 1) << bit
    return i, j, k


def octree(tree: Any = None, camera: Camera | None = None, **options: Any) -> Steps:
    """The octree method: the subdivision level by level (full and partial cells), then the front-to-back
    traversal, node by node: octants nearer the eye first, a node skipped when every pixel under it is written.

    Runs ``render_octree(tree, camera, **options)`` with the kernel's recording mode on
    (``visibility.octree.recording``); ``result`` is that frame, byte for byte the frame without recording.
    """
    from frustum.geometry.octree import Octree
    from frustum.visibility.octree import recording, render_octree

    where = "steps.octree"
    if tree is None:
        tree, default_camera = default_octree()
        camera = default_camera if camera is None else camera
    if not isinstance(tree, Octree):
        raise FrustumError(f"{where}: tree = {tree!r} is not an Octree; build one with Octree.from_mesh")
    cam = _camera(camera, where)
    with recording() as logs:
        frame = render_octree(tree, cam, **options)
    result = frame
    log = logs[0]
    steps: list[Step] = []
    shown: list[tuple[str, Any]] = []
    partial = tree.partial
    for level in range(tree.depth + 1):
        full = len(tree.full[level])
        split = len(partial[level]) if level < len(partial) else 0
        steps.append(Step(f"Subdivision, level {level}",
                          "A cell wholly inside the solid is full (a leaf); one the surface crosses is partial and "
                          "is cut into eight octants at the next level.",
                          {"full cells": full, "partial cells": split}))  # fmt: skip
        shown.append(("level", level))
    drawn_total = 0
    for n, (level, code, outcome, pixels) in enumerate(log.tolist()):
        drawn_total += pixels
        i, j, k = _morton_ijk(code, level)
        steps.append(Step(f"Visit {n + 1}: level {level} cell ({i}, {j}, {k}), {_OCTREE_OUTCOMES[outcome]}",
                          "Front to back: at each node the child on the eye's side of all three mid-planes comes "
                          "first, then those across one, two and three planes; a pixel is written once.",
                          {"pixels written": pixels, "written so far": drawn_total}))  # fmt: skip
        shown.append(("visit", n))
    corners = np.array([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)], dtype=float)
    origin, size = tree.bounds[0], float(tree.size)

    def cell_rect(level: int, code: int) -> NDArray | None:
        ijk = np.array(_morton_ijk(code, level), dtype=float)
        side = size / (1 << level)
        window = np.asarray(cam.project(origin + (ijk + corners) * side))[:, :2]
        if not np.isfinite(window).all():
            return None
        return np.array([window.min(axis=0), window.max(axis=0)])

    picture = np.asarray(frame.color)[:, :, :3]
    zoom = max(1, 256 // max(cam.width, 1))
    big = np.repeat(np.repeat(picture, zoom, axis=0), zoom, axis=1)
    width, height = float(cam.width), float(cam.height)

    def paint(index: int, canvas: _Canvas) -> None:
        kind, value = shown[index]
        canvas.image(big, (0.0, height), (width, 0.0))
        canvas.rect((0.0, 0.0), (width, height), color="ink", fill="white", opacity=0.6 if kind == "level" else 0.35)
        if kind == "level":
            for codes, color in (
                (tree.full[value], "accept"),
                (partial[value] if value < len(partial) else [], "blue"),
            ):
                for code in np.asarray(codes).tolist():
                    rect = cell_rect(value, int(code))
                    if rect is not None:
                        canvas.rect(rect[0], rect[1], color=color, width=1.0)
            return
        for n in range(value + 1):
            level, code, outcome, _pixels = (int(v) for v in log[n])
            if outcome != 3 and n != value:
                continue
            rect = cell_rect(level, code)
            if rect is None:
                continue
            current = n == value
            canvas.rect(rect[0], rect[1], color="highlight" if current else "accept",
                        fill="accept" if outcome == 3 else None, opacity=0.15,
                        width=2.0 if current else 0.5)  # fmt: skip

    return Steps("Octree method", steps, result, paint, (0.0, 0.0, width, height))
