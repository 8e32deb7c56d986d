"""Visible surfaces step by step, ray casting: a ray per pixel through the scene's BVH, node by node.

References: [HB 16] "Ray-Casting Method".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum.camera import Camera
from frustum.errors import GeometryError, OutputError
from frustum.scene import Scene
from frustum.steps._record import Step, Steps, _Canvas
from frustum.steps.visible_surfaces.image_space import scene_and_camera

__all__ = ["ray_casting", "traced_closest"]


def _pixel_ray(camera: Camera, x: int, y: int) -> tuple[float, ...]:
    """The ray of window pixel (x, y), with ``raster.rays.cast_pixels``' arithmetic: origin on the near plane,
    direction to the far plane (t in [0, 1))."""
    # kept twice on purpose: the arithmetic of raster/rays.py:cast_pixels (a kernel's inner loop), for one pixel
    m = np.ascontiguousarray(camera.world_from_window, dtype=np.float64)
    px, py = x + 0.5, y + 0.5
    nw = m[3, 0] * px + m[3, 1] * py + m[3, 3]
    ox = (m[0, 0] * px + m[0, 1] * py + m[0, 3]) / nw
    oy = (m[1, 0] * px + m[1, 1] * py + m[1, 3]) / nw
    oz = (m[2, 0] * px + m[2, 1] * py + m[2, 3]) / nw
    fw = nw + m[3, 2]
    dx = (m[0, 0] * px + m[0, 1] * py + m[0, 2] + m[0, 3]) / fw - ox
    dy = (m[1, 0] * px + m[1, 1] * py + m[1, 2] + m[1, 3]) / fw - oy
    dz = (m[2, 0] * px + m[2, 1] * py + m[2, 2] + m[2, 3]) / fw - oz
    return ox, oy, oz, dx, dy, dz


def traced_closest(index: Any, skip: NDArray, ray: tuple[float, ...], cull: int) -> tuple[tuple, list[tuple]]:
    """Run the ray kernel's Python twin (``raster.rays._closest``'s own source, uncompiled) on one ray under a
    line tracer: its return value (equal to the compiled kernel's) and the traversal's events in order —
    ``("node", node, t_left, t_right)`` (an inner node entered and its children's box entries, inf for a miss),
    ``("leaf", first_row, count)``, ``("test", row, face)``, ``("hit", row, face, t)`` (a new nearest hit)."""
    import inspect
    import sys

    from frustum.raster import rays

    function = getattr(rays._closest, "py_func", rays._closest)
    code = function.__code__
    lines, first = inspect.getsourcelines(function)
    children_line = first + next(n for n, text in enumerate(lines) if "left, right = links[node, 0]" in text)
    leaf_line = first + next(n for n, text in enumerate(lines) if "first = code >> 3" in text)
    events: list[tuple] = []
    seen = {"tests": 0, "best_row": -1}

    def local(frame: Any, event: str, arg: Any) -> Any:
        if event != "line":
            return local
        values = frame.f_locals
        if frame.f_lineno == children_line:
            events.append(("node", int(values["node"]), float(values["t_near0"]), float(values["t_near1"])))
        elif frame.f_lineno == leaf_line:
            events.append(("leaf", int(values["code"]) >> 3, int(values["code"]) & 7))
        tests = values.get("tests", 0)
        if tests > seen["tests"]:
            seen["tests"] = tests
            events.append(("test", int(values["row"]), int(values["face"])))
        best_row = values.get("best_row", -1)
        if best_row != seen["best_row"]:
            seen["best_row"] = best_row
            events.append(("hit", int(best_row), int(values["best_face"]), float(values["best"])))
        return local

    def tracer(frame: Any, event: str, arg: Any) -> Any:
        return local if frame.f_code is code else None

    stack = np.empty(index.depth + 2, dtype=np.int64)
    entry = np.empty(index.depth + 2)
    previous = sys.gettrace()
    sys.settrace(tracer)
    try:
        result = function(index.boxes, index.links, index.triangles, index.order, skip, *ray, 0.0, 1.0, cull, stack,
                          entry)  # fmt: skip
    finally:
        sys.settrace(previous)
    return result, events


def ray_casting(
    scene: Scene | None = None, camera: Camera | None = None, pixel: tuple[int, int] | None = None, **options: Any
) -> Steps:
    """One pixel's ray through the scene's bounding-volume hierarchy: each node entered (nearer child first, a
    child whose box the ray misses left out), each leaf's ray–triangle tests, each new nearest hit.

    The frame is ``render(scene, camera, method="ray-casting", **options)`` (``result``); the pixel's traversal is
    the ray kernel's Python twin (``raster.rays._closest``, the same source uncompiled) run on that pixel's ray
    under a line tracer (``traced_closest``), whose hit equals the kernel's (a test holds the depth it gives to
    the frame's). `pixel` is ``(x, y)`` in window coordinates (y up); by default the image centre.
    """
    from frustum.render import render

    where = "steps.ray_casting"
    scene, cam = scene_and_camera(scene, camera, where)
    width, height = cam.width, cam.height
    x, y = (width // 2, height // 2) if pixel is None else (int(v) for v in pixel)
    if not (0 <= x < width and 0 <= y < height):
        raise OutputError(f"{where}: pixel = {pixel!r} lies outside the {width}x{height} image; give 0 <= x < "
                          f"{width}, 0 <= y < {height}")  # fmt: skip
    frame = render(scene, cam, method="ray-casting", **options)
    result = frame
    found = scene._triangle_index(where=where)
    if found is None:
        raise GeometryError(f"{where}: the scene has no triangles to cast rays at")
    items, index, starts = found
    clear = np.array([item.material.opacity < 1.0 for item in items])
    skip = np.repeat(clear, np.diff(starts)).astype(np.uint8) if clear.any() else np.empty(0, dtype=np.uint8)
    ray = _pixel_ray(cam, x, y)
    cull = int(options.get("cull_back_faces", True))
    hit, events = traced_closest(index, skip, ray, cull)
    steps = [Step(f"The ray through pixel ({x}, {y})",
                  "From the pixel centre on the near plane toward the far plane. Instead of testing every surface, "
                  "the ray descends the bounding-volume hierarchy: a box it misses hides nothing, and the nearer "
                  "child is entered first so that a hit found early lets farther boxes be skipped.",
                  {"origin": ray[:3], "direction": ray[3:], "inner nodes": index.nodes})]  # fmt: skip
    shown: list[tuple] = [("start",)]
    for event in events:
        if event[0] == "node":
            _, node, t_left, t_right = event
            entries = {"left entry t": t_left, "right entry t": t_right}
            order = "left first" if t_left <= t_right else "right first"
            missed = [side for side, t in (("left", t_left), ("right", t_right)) if not math.isfinite(t)]
            steps.append(Step(f"Node {node}: test both children's boxes",
                              "Slab test of each child box: the entry parameter t where the ray enters it. "
                              + (f"The ray misses the {' and '.join(missed)} box." if missed else
                                 f"Both are hit: the nearer is entered first ({order}), the other pushed."),
                              entries))  # fmt: skip
        elif event[0] == "leaf":
            steps.append(Step(f"Leaf: triangles {event[1]}…{event[1] + event[2] - 1}",
                              "A leaf holds a few triangles; each is tested against the ray (Möller–Trumbore).",
                              {"triangles": event[2]}))  # fmt: skip
        elif event[0] == "test":
            steps.append(Step(f"Test face {event[2]}", "Ray–triangle test: a hit nearer than the best so far "
                              "replaces it.", {"face": event[2]}))  # fmt: skip
        else:
            steps.append(Step(f"Nearest hit so far: face {event[2]}", "Boxes entered beyond it will be skipped.",
                              {"t": event[3]}))  # fmt: skip
        shown.append(event)
    row = height - 1 - y
    steps.append(Step("The pixel's surface", "The nearest hit is the visible surface: its depth, face and "
                      "barycentrics are shaded as the depth buffer's." if hit[1] >= 0 else "The ray meets no "
                      "surface: the pixel keeps the background.",
                      {"t": hit[0], "depth": float(frame.depth[row, x])}))  # fmt: skip
    shown.append(("end",))
    # draw the boxes of the nodes entered, projected onto the image (their 8 corners' bounding rectangles)
    corners = np.array([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)], dtype=float)

    def child_rect(node: int, side: int) -> NDArray | None:
        box = np.asarray(index.boxes[node, 6 * side : 6 * side + 6], dtype=float)
        lo, hi = box[:3], box[3:]
        if (lo > hi).any():
            return None
        window = np.asarray(cam.project(lo + corners * (hi - lo)))[:, :2]
        return None if not np.isfinite(window).all() else np.array([window.min(axis=0), window.max(axis=0)])

    picture = np.asarray(frame.color)[:, :, :3]
    zoom = max(1, 256 // max(width, 1))
    big = np.repeat(np.repeat(picture, zoom, axis=0), zoom, axis=1)

    def paint(index_: int, canvas: _Canvas) -> None:
        canvas.image(big, (0.0, height), (width, 0.0))
        event = shown[index_]
        if event[0] == "node":
            for side, t in ((0, event[2]), (1, event[3])):
                rect = child_rect(event[1], side)
                if rect is not None:
                    canvas.rect(rect[0], rect[1], color="accept" if math.isfinite(t) else "reject",
                                width=2.0 if math.isfinite(t) else 1.0)  # fmt: skip
        canvas.rect((x, y), (x + 1, y + 1), color="blue", fill="blue", width=1.0)

    return Steps("Ray casting through a BVH", steps, result, paint, (0.0, 0.0, float(width), float(height)))
