"""Visible surfaces step by step, the object-space methods: back-face detection, the BSP tree (splits, then back
to front) and the painter's depth sort (Newell–Newell–Sancha, test by test).

References: [HB 16] "Back-Face Detection", "BSP-Tree Method", "Depth-Sorting Method"; [seed] "Back-face
detection", "BSP trees".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_faces, as_points, as_vector3
from frustum.camera import Camera
from frustum.errors import CameraError, GeometryError
from frustum.steps._draw import bounds_of, oblique
from frustum.steps._record import Step, Steps, _Canvas, format_value
from frustum.steps.modeling import HOUSE_POINTS
from frustum.steps.viewing import _camera
from frustum.steps.visible_surfaces.image_space import triangle_color
from frustum.visibility import backface_mask
from frustum.visibility.bsp import BSPTree

__all__ = ["HOUSE_FACES", "back_faces", "bsp_tree", "default_depth_sort_scene", "default_walls", "depth_sort"]


HOUSE_FACES = np.array(
    [[0, 3, 2], [0, 2, 1], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [3, 0, 4], [3, 4, 7],
     [2, 3, 8], [6, 9, 7], [2, 8, 9], [2, 9, 6], [3, 7, 9], [3, 9, 8]], dtype=np.int64,
)  # fmt: skip


def back_faces(
    vertices: ArrayLike | None = None, faces: ArrayLike | None = None, camera: Camera | None = None
) -> Steps:
    """Back-face detection by the plane equation, face by face: $A·x + B·y + C·z + D·w < 0$ at the viewer.

    Runs ``backface_mask(vertices, faces, camera, record=...)``; ``result`` is its (M,) bool mask (True = back
    face). Default: the house of ``viewing_pipeline`` and its camera.
    """
    where = "steps.back_faces"
    cam = _camera(camera, where)
    if vertices is None:
        points, triangles = HOUSE_POINTS, HOUSE_FACES
    else:
        points = as_points(vertices, "vertices", where=where)
        triangles = as_faces(faces, points.shape[0], where=where, error=GeometryError)
    events: list[dict[str, Any]] = []
    result = backface_mask(points, triangles, cam, record=lambda event, **values: events.append(values))
    tests = events[0]
    position = tests["position"]
    steps = [Step(
        "The viewing position",
        "Each face's plane A·x + B·y + C·z + D = 0 comes from its corners, N = (P1 − P0) × (P2 − P0) pointing "
        "out of the object. A face is a back face when the viewing position (x, y, z, w) lies behind its plane.",
        {"viewer (x, y, z, w)": position, "faces": len(triangles)},
    )]  # fmt: skip
    for f, (plane, value) in enumerate(zip(tests["planes"], tests["values"], strict=True)):
        back = bool(value < 0.0)
        steps.append(Step(
            f"Face {f}: {'back face, culled' if back else 'front face, kept'}",
            "Plane test at the viewing position: A·x + B·y + C·z + D·w "
            + ("< 0, the viewer is behind the plane." if back else ">= 0, the viewer is in front of it."),
            {"A, B, C, D": plane, "A·x + B·y + C·z + D·w": value, "back": back},
        ))  # fmt: skip
    steps.append(Step(
        "All faces tested",
        "The back faces (grey) are removed before any depth test; for a closed convex object the rest is the "
        "visible surface.",
        {"back faces": int(result.sum()), "front faces": int((~result).sum())},
    ))  # fmt: skip
    window = np.asarray(cam.project(points))[:, :2]

    def paint(index: int, canvas: _Canvas) -> None:
        done = index - 1  # faces decided so far (step 0 none, the last step all)
        final = index == len(steps) - 1
        order = np.argsort(~result, kind="stable") if final else range(len(triangles))  # back faces first
        for f in order:
            corners = window[triangles[f]]
            if not np.isfinite(corners).all():
                continue
            if f < done or final:
                fill = "faint" if result[f] else "accept"
                canvas.polyline(corners, color="ink", closed=True, fill=fill, opacity=0.35, width=0.8)
            elif f == done:
                fill = "reject" if result[f] else "accept"
                canvas.polyline(corners, color="highlight", closed=True, fill=fill, opacity=0.6, width=2.5)
            else:
                canvas.polyline(corners, color="faint", closed=True, width=0.6)
        if 0 <= done < len(triangles):
            centre = window[triangles[done]].mean(axis=0)
            if np.isfinite(centre).all():
                canvas.label(centre, format_value(float(tests["values"][done])), color="highlight", size=11)

    finite = window[np.isfinite(window).all(axis=1)]
    bounds = bounds_of(finite) if finite.size else (0.0, 0.0, cam.width, cam.height)
    return Steps("Back-face detection", steps, result, paint, bounds)


# four walls seen from above (x right, z toward the viewer), two of them crossing: the building splits one
_WALLS = [((-2.0, 0.0), (2.0, 0.0)), ((-1.0, -2.0), (-1.0, 1.5)), ((0.5, -1.5), (2.5, 1.0)), ((-2.5, 2.0), (1.5, 2.5))]


def default_walls() -> NDArray[np.float64]:
    """(4, 4, 3) vertical rectangles (walls) standing on the xz plane, the BSP example of the chapter."""
    walls = []
    for (x0, z0), (x1, z1) in _WALLS:
        walls.append([(x0, 0.0, z0), (x1, 0.0, z1), (x1, 1.0, z1), (x0, 1.0, z0)])
    return np.array(walls)


def _top_view(points: Any) -> NDArray[np.float64]:
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    return np.column_stack([p[:, 0], -p[:, 2]])


def bsp_tree(polygons: ArrayLike | None = None, eye: ArrayLike = (0.3, 0.5, 4.0)) -> Steps:
    """A BSP tree built node by node (partitioning plane, polygons in front and behind, splits), then read back
    to front from `eye`, fragment by fragment.

    Runs ``BSPTree(polygons, record=...)`` and ``back_to_front_indices(eye=eye, record=...)``; ``result`` is that
    painting order (indices into the tree's ``fragments``). Walls standing on the xz plane (the default) are
    drawn from above, as the textbook does; other polygons in an oblique view.
    """
    where = "steps.bsp_tree"
    polys = default_walls() if polygons is None else polygons
    viewer = as_vector3(eye, "eye", where=where, error=CameraError)
    nodes: list[dict[str, Any]] = []
    tree = BSPTree(polys, record=lambda event, **values: nodes.append(values))
    emitted: list[dict[str, Any]] = []
    result = tree.back_to_front_indices(eye=viewer, record=lambda event, **values: emitted.append(values))
    fragments = tree.fragments
    sources = [np.asarray(p, dtype=float) for p in polys]
    vertical = all(abs(float(np.cross(p[1] - p[0], p[2] - p[0])[1])) < 1e-9 for p in sources)
    view = _top_view if vertical else oblique
    steps = [Step("The polygons and the viewer",
                  "A BSP tree splits space by the plane of one polygon at each node: polygons in front go to one "
                  "subtree, those behind to the other, and a polygon crossing the plane is split in two.",
                  {"polygons": len(sources), "eye": viewer})]  # fmt: skip
    shown: list[tuple[str, Any]] = [("scene", None)]
    for node in nodes:
        kind = "convex cell" if node["cell"] else "partitioning plane"
        steps.append(Step(f"Node {node['node']}: {kind}",
                          "The node keeps the polygons lying in its plane; the rest go in front (N·P + D > 0) or "
                          "behind." + (" Crossing polygons are split at the plane." if node["splits"] else ""),
                          {"plane (A, B, C, D)": node["plane"], "on the plane": len(node["on"]),
                           "in front": node["in_front"], "behind": node["behind"],
                           "splits": len(node["splits"])}))  # fmt: skip
        shown.append(("node", node))
    painted: list[int] = []
    for emit in emitted:
        ids = [int(i) for i in np.asarray(emit["fragments"]).tolist()]
        if not ids:
            continue
        side = emit["viewer_in_front"]
        rule = ("the viewer is in front of this node's plane: its back subtree was painted first"
                if side else "the viewer is behind this node's plane: its front subtree was painted first"
                if side is not None else "a convex cell: faces turned away first")  # fmt: skip
        painted = painted + ids
        steps.append(Step(f"Paint node {emit['node']}'s fragments {ids}", rule[0].upper() + rule[1:] + ".",
                          {"painted so far": list(painted)}))  # fmt: skip
        shown.append(("paint", list(painted)))
    everything = np.vstack([view(p) for p in sources] + [view(viewer)])
    box = bounds_of(everything, pad=0.15)

    def plane_line(canvas: _Canvas, plane: NDArray) -> None:
        if not vertical:
            return
        a, c, d = plane[0], -plane[2], plane[3]  # in top-view coordinates (x, −z)
        norm = a * a + c * c
        if norm == 0:
            return
        base = -d * np.array([a, c]) / norm
        along = np.array([-c, a]) / math.sqrt(norm) * 2 * (box[2] - box[0] + box[3] - box[1])
        canvas.line(base - along, base + along, color="highlight", dash=True)

    def paint(index: int, canvas: _Canvas) -> None:
        kind, data = shown[index]
        canvas.dot(view(viewer)[0], color="ink", label="eye")
        if kind == "paint":
            for n, i in enumerate(data):
                outline = view(fragments[i])
                canvas.polyline(outline, color="blue", closed=True, fill="blue", opacity=0.25, width=3.0)
                canvas.label(outline.mean(axis=0), str(n + 1), color="highlight", size=14)
            return
        for p in sources:
            canvas.polyline(view(p), color="faint" if kind == "node" else "ink", closed=True, width=2.0)
        if kind == "node":
            plane_line(canvas, data["plane"])
            for p in data["on"]:
                canvas.polyline(view(p), color="highlight", closed=True, width=4.0)
            for _, front, back in data["splits"]:
                if front is not None:
                    canvas.polyline(view(front), color="accept", closed=True, width=3.0)
                if back is not None:
                    canvas.polyline(view(back), color="purple", closed=True, width=3.0)

    return Steps("BSP tree", steps, result, paint, box)


_TESTS = {
    1: "test 1: their bounding rectangles do not overlap (or Q is wholly nearer)",
    2: "test 2: P lies wholly behind Q's plane",
    3: "test 3: Q lies wholly in front of P's plane",
    4: "test 4: their projections do not overlap, or P is behind Q where they do",
}


def default_depth_sort_scene() -> tuple[NDArray[np.float64], Camera]:
    """Three long triangles that overlap cyclically (each over the next) and a camera looking down at them."""
    from frustum.projection import Orthographic

    length, half_width, height = 2.0 * math.sqrt(3.0), 0.45, 0.6
    base = np.array([[-length, -1.0 - half_width, -height], [-length, -1.0 + half_width, -height],
                     [length, -1.0, height]])  # fmt: skip
    turns = []
    for k in range(3):
        angle = 2 * math.pi * k / 3
        rotation = np.array([[math.cos(angle), -math.sin(angle), 0], [math.sin(angle), math.cos(angle), 0], [0, 0, 1]])
        turns.append(base @ rotation.T)
    camera = Camera.look_at((0.0, 0.0, 6.0), (0.0, 0.0, 0.0), projection=Orthographic(4.0, 0.1, 20.0), width=64,
                            height=64)  # fmt: skip
    return np.array(turns) * 0.6, camera


def depth_sort(polygons: ArrayLike | None = None, camera: Camera | None = None) -> Steps:
    """The depth-sorting (painter's) method: the list by greatest depth, the overlap tests 1–4 of each P against
    the Q it might hide, moves to the head of the list, splits of cyclic overlaps, then each polygon painted.

    Runs ``visibility.bsp.depth_sort(polygons, camera, record=...)``; ``result`` is its ``DepthOrder``. Default: three
    triangles that overlap cyclically, which only a split can order.
    """
    from frustum.visibility.depth_sort import depth_sort as production

    where = "steps.depth_sort"
    if polygons is None:
        polygons, default_camera = default_depth_sort_scene()
        camera = default_camera if camera is None else camera
    cam = _camera(camera, where)
    events: list[tuple[str, dict[str, Any]]] = []
    result = production(polygons, cam, record=lambda event, **values: events.append((event, values)))
    shapes: dict[int, NDArray] = {}
    labels: dict[int, int] = {}
    steps: list[Step] = []
    shown: list[tuple[list[int], int | None, int | None]] = []  # painted so far, P, Q
    painted: list[int] = []
    tests: list[str] = []
    for event, values in events:
        if event == "sorted":
            shapes.update(enumerate(values["polygons"]))
            labels.update(enumerate(values["labels"]))
            steps.append(Step("Sorted by greatest depth",
                              "The polygons are listed by their farthest point z_max, farthest first. The farthest, "
                              "P, may be painted unless it hides part of a polygon Q whose depth range overlaps "
                              "its own: tests 1–4, in order of cost, each show that P cannot hide Q.",
                              {"list (farthest first)": values["order"]}))  # fmt: skip
            shown.append(([], None, None))
        elif event == "test":
            tests.append(f"P{values['p']}/Q{values['q']}: {values['passed']}")
        elif event == "hides":
            p, q = values["p"], values["q"]
            kind = "their depths cross inside the overlap (they pierce)" if values["pierce"] else "P is behind Q"
            steps.append(Step(f"P = {p} hides part of Q = {q}",
                              f"Tests 1–4 all fail for Q = {q}: where their projections overlap, {kind}.",
                              {"tests passed (P/Q: test)": list(tests)}))  # fmt: skip
            tests = []
            shown.append((list(painted), p, q))
        elif event == "move":
            steps.append(Step(f"Q = {values['q']} moved to the head of the list",
                              "Q must be painted before P. Q is marked: meeting it again means a cycle.",
                              {"P": values["p"], "Q": values["q"]}))  # fmt: skip
            shown.append((list(painted), values["p"], values["q"]))
        elif event == "split":
            for index, polygon in zip(values["parts"], values["polygons"], strict=True):
                shapes[index] = polygon
                labels[index] = labels[values["victim"]]
            steps.append(Step(f"Split {values['victim']} by the plane of {values['by']}",
                              "A cycle (or two polygons piercing each other) cannot be ordered whole: the polygon is "
                              "cut by the other's plane and its parts take its place in the list.",
                              {"new parts": values["parts"]}))  # fmt: skip
            shown.append((list(painted), values["by"], values["victim"]))
        elif event in ("paint", "unresolved"):
            item = values["item"]
            if event == "paint":
                painted.append(item)
            steps.append(Step(f"Paint {item} (polygon {labels.get(item, item)})" if event == "paint"
                              else f"Unresolved: paint {item} as it is",
                              "No polygon it could hide is left unpainted before it, so it is painted over what is "
                              "there (back to front).", {"tests passed (P/Q: test)": list(tests),
                                                          "painted so far": list(painted)}))  # fmt: skip
            tests = []
            shown.append((list(painted), item, None))
    window = {i: np.asarray(cam.project(np.asarray(poly)))[:, :2] for i, poly in shapes.items()}
    everything = np.vstack(list(window.values())) if window else np.zeros((1, 2))
    colors = {label: triangle_color(label + 3) for label in set(labels.values())}

    def paint(index: int, canvas: _Canvas) -> None:
        done, p, q = shown[index]
        for i in shapes:
            if i in window:
                canvas.polyline(window[i], color="faint", closed=True, width=0.8)
        for n, i in enumerate(done):
            canvas.polyline(window[i], color="ink", closed=True, fill=colors[labels[i]], opacity=1.0, width=0.8)
            canvas.label(window[i].mean(axis=0), str(n + 1), color="ink", size=11)
        if p is not None:
            canvas.polyline(window[p], color="highlight", closed=True, width=3.0)
            canvas.label(window[p][0], f"P {p}", color="highlight", size=12)
        if q is not None:
            canvas.polyline(window[q], color="blue", closed=True, width=3.0, dash=True)
            canvas.label(window[q][-1], f"Q {q}", color="blue", size=12)

    return Steps("Depth sort (painter's algorithm)", steps, result, paint, bounds_of(everything, pad=0.1))
