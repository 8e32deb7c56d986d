"""Visible surfaces, step by step: back-face detection, the BSP tree (splits, then back to front), the depth buffer
(surface by surface).

Why one module: the three methods of the chapter, recorded on the same scene and figure helpers.

References: [HB 16] "Back-Face Detection", "BSP-Tree Method", "Depth-Buffer Method"; [seed] "Back-face
detection", "BSP trees", "Depth-buffer method".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_faces, as_points, as_vector3
from frustum.budgets import check_memory, check_operations
from frustum.camera import Camera
from frustum.errors import CameraError, FrustumError, GeometryError, OutputError
from frustum.scene import Scene
from frustum.steps._draw import bounds_of, oblique
from frustum.steps._record import Step, Steps, _Canvas, format_value
from frustum.steps.modeling import HOUSE_POINTS
from frustum.steps.viewing import _camera
from frustum.visibility import backface_mask
from frustum.visibility.bsp import BSPTree

__all__ = [
    "HOUSE_FACES",
    "a_buffer",
    "area_subdivision",
    "back_faces",
    "bsp_tree",
    "depth_buffer",
    "depth_sort",
    "scan_line",
]

# the house's faces (outward, counter-clockwise seen from outside) for back-face detection
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


# --- BSP tree ----------------------------------------------------------------------------------------------

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


# --- depth buffer ------------------------------------------------------------------------------------------


def default_scene() -> tuple[Scene, Camera]:
    """Three overlapping boxes and a sphere on a small image: the depth-buffer example of the chapter."""
    from frustum.geometry import box, uv_sphere
    from frustum.projection import Perspective
    from frustum.shading import AmbientLight, DirectionalLight, Material
    from frustum.transforms import translate

    scene = Scene(lights=[DirectionalLight((-0.4, -0.6, -1.0)), AmbientLight(intensity=0.25)])
    scene.add(box((2.0, 1.0, 0.4)), Material(color=(0.85, 0.3, 0.2)), translate(0.0, 0.0, -0.5), name="back slab")
    scene.add(uv_sphere(0.7, 16, 8), Material(color=(0.2, 0.5, 0.9)), translate(0.4, 0.2, 0.0), name="sphere")
    scene.add(box((0.8, 1.6, 0.8)), Material(color=(0.3, 0.75, 0.3)), translate(-0.6, 0.0, 0.3), name="pillar")
    camera = Camera.look_at((0.0, 0.8, 4.0), (0.0, 0.0, 0.0), projection=Perspective(math.radians(45), 0.1, 20.0),
                            width=64, height=48)  # fmt: skip
    return scene, camera


def depth_buffer(scene: Scene | None = None, camera: Camera | None = None, **options: Any) -> Steps:
    """The depth-buffer method surface by surface: the depth and frame buffers after each of the scene's top
    nodes (in order) has been drawn.

    Each step is ``render`` of the scene's first k surfaces (``options`` passed on): the depth buffer keeps, per
    pixel, the nearest depth seen so far, so drawing the first k surfaces is exactly the state after k of them.
    ``result`` is the last render, equal byte for byte to ``render(scene, camera, **options)``.

    Raises
    ------
    OutputError
        A recording over the memory or work budget (k renders of W×H), with the estimate.
    """
    from frustum.render import render

    where = "steps.depth_buffer"
    if scene is None:
        scene, default_camera = default_scene()
        camera = default_camera if camera is None else camera
    if not isinstance(scene, Scene):
        raise FrustumError(f"{where}: scene = {scene!r} is not a Scene")
    cam = _camera(camera, where)
    surfaces = list(scene.root.children)
    if not surfaces:
        raise GeometryError(f"{where}: the scene has no surfaces; add a mesh with Scene.add")
    pixels = cam.width * cam.height
    cause = f"a recording of {len(surfaces)} surfaces at {cam.width}x{cam.height}"
    # per surface and pixel: the kept frame's color and depth (8 bytes) and its two pictures in the figure (PNG
    # in base64, up to about 12 bytes for noisy buffers)
    check_memory(len(surfaces) * pixels * (8 + 12), where=where, cause=cause, error=OutputError)
    check_operations(len(surfaces) * pixels * 64, where=where, cause=cause, error=OutputError)
    frames = []
    for k in range(1, len(surfaces) + 1):
        partial = Scene(lights=scene.lights)
        for node in surfaces[:k]:
            partial.root.children.append(node)
        frames.append(render(partial, cam, **options))
    result = frames[-1]
    steps = [Step("Empty buffers",
                  "The depth buffer starts at 1 (the far plane) everywhere, the frame buffer at the background. "
                  "Each surface is then scan-converted; a pixel is overwritten only where the surface is nearer "
                  "than the depth stored there.",
                  {"size": f"{cam.width}x{cam.height}", "surfaces": len(surfaces)})]  # fmt: skip
    previous = np.ones((cam.height, cam.width), dtype=np.float32)
    for k, (node, frame) in enumerate(zip(surfaces, frames, strict=True), start=1):
        depth = np.asarray(frame.depth)
        changed = int(np.count_nonzero(depth != previous))
        steps.append(Step(f"Surface {k}: {node.name or 'unnamed'}",
                          "For each pixel (x, y) of the surface: if its depth z < depth(x, y), store z and the "
                          "surface's color there; otherwise the pixel keeps what a nearer surface left.",
                          {"pixels written": changed, "nearest depth": float(depth.min())}))  # fmt: skip
        previous = depth
    width, height = float(cam.width), float(cam.height)
    nearest = float(min(np.asarray(frame.depth).min() for frame in frames))

    def paint(index: int, canvas: _Canvas) -> None:
        if index == 0:
            depth = np.ones((cam.height, cam.width), dtype=np.float32)
            color = np.zeros((cam.height, cam.width, 3), dtype=np.uint8)
        else:
            depth, color = np.asarray(frames[index - 1].depth), np.asarray(frames[index - 1].color)[:, :, :3]
        # depths of the scene crowd near 1: stretch [nearest, 1] over the gray ramp (1 = far = white)
        shade = np.clip((depth - nearest) / max(1.0 - nearest, 1e-12), 0.0, 1.0)
        gray = (40 + shade * 215).astype(np.uint8)
        zoom = max(1, 256 // max(cam.width, 1))  # nearest-neighbour enlargement: buffer pixels stay sharp
        big = np.repeat(np.repeat(np.repeat(gray[:, :, None], 3, axis=2), zoom, axis=0), zoom, axis=1)
        canvas.image(big, (0.0, height), (width, 0.0))
        canvas.image(np.repeat(np.repeat(color, zoom, axis=0), zoom, axis=1), (width * 1.1, height), (width * 2.1, 0.0))
        canvas.label((0.0, height * 1.04), "depth buffer (white = far)", size=12)
        canvas.label((width * 1.1, height * 1.04), "frame buffer", size=12)

    return Steps("Depth buffer", steps, result, paint, (0.0, 0.0, width * 2.1, height * 1.1))


# --- area subdivision (Warnock) ----------------------------------------------------------------------------

_DECISION_COLORS = {0: "#dddddd", 1: "#2b8a3e", 2: "#1c63b7", 3: "#d9480f", 4: "#7048e8"}
_DECISION_TEXT = {
    0: "empty: no surface is left in the area, it keeps the background",
    1: "surrounding: a surrounding surface is nearer than every other one over the whole area and fills it",
    2: "single: one surface is left (inside, overlapping or surrounding) and is drawn into the area",
    3: "pixel: the area is one pixel, the nearest surface at its centre is drawn",
    4: "subdivided: no test decided, the area is cut into four",
}
_RELATIONS = ("outside", "surrounding", "inside", "overlapping")
# a logged area costs its row (9 int64) and, in each figure that draws it, one rectangle of about 170 characters
_BYTES_PER_AREA_ROW, _BYTES_PER_AREA_RECT = 72, 170


def area_subdivision(scene: Scene | None = None, camera: Camera | None = None, **options: Any) -> Steps:
    """Warnock's area subdivision level by level: every area of the quadtree and the test that decided it.

    Runs ``render(scene, camera, method="area-subdivision", **options)`` with the kernel's recording mode on
    (``visibility.warnock.recording``: the kernel logs each area it visits); ``result`` is that frame, byte for
    byte the frame of the same call without recording.

    Raises
    ------
    OutputError
        A recording over the memory budget (at most 2·W·H areas, drawn in every later figure), with the estimate:
        a 4K image is refused by default.
    """
    from frustum.raster.warnock import DECISIONS
    from frustum.render import render
    from frustum.visibility.warnock import recording

    where = "steps.area_subdivision"
    if scene is None:
        scene, default_camera = default_scene()
        camera = default_camera if camera is None else camera
    if not isinstance(scene, Scene):
        raise FrustumError(f"{where}: scene = {scene!r} is not a Scene")
    cam = _camera(camera, where)
    areas_bound = 2 * cam.width * cam.height + 1
    levels_bound = 2 * max(1, math.ceil(math.log2(max(cam.width, cam.height, 2)))) + 2
    check_memory(areas_bound * (_BYTES_PER_AREA_ROW + _BYTES_PER_AREA_RECT * levels_bound), where=where,
                 cause=f"a recording at {cam.width}x{cam.height} (up to {areas_bound} areas, {levels_bound} levels)",
                 error=OutputError)  # fmt: skip
    with recording() as logs:
        frame = render(scene, cam, method="area-subdivision", **options)
    log = logs[0] if logs else np.zeros((0, 9), dtype=np.int64)
    result = frame
    levels = int(log[:, 4].max()) + 1 if len(log) else 0
    steps = [Step("The whole image is the first area",
                  "Each area is tested against the surfaces its parent kept: each is surrounding, overlapping, "
                  "inside or outside it. The area is finished when a test decides (no surface, a surrounding "
                  "surface hides all others, a single surface, or one pixel); otherwise it is cut into four.",
                  {"size": f"{cam.width}x{cam.height}", "areas visited": len(log)})]  # fmt: skip
    for level in range(levels):
        rows = log[log[:, 4] == level]
        counts = {DECISIONS[d]: int(np.count_nonzero(rows[:, 5] == d)) for d in range(len(DECISIONS))}
        decided = [d for d in range(len(DECISIONS)) if counts[DECISIONS[d]]]
        relations = {}
        picked = rows[rows[:, 5] == 2]  # the single surface left: the relation it had to the area
        for r in range(4):
            n = int(np.count_nonzero(picked[:, 8] == r))
            if n:
                relations[f"single, {_RELATIONS[r]}"] = n
        steps.append(Step(f"Level {level}: {len(rows)} area{'s' if len(rows) != 1 else ''}",
                          "; ".join(_DECISION_TEXT[d] for d in decided) + ".",
                          {**{k: v for k, v in counts.items() if v}, **relations}))  # fmt: skip
    steps.append(Step("The finished image", "Every pixel belongs to exactly one finished area; the surfaces found "
                      "are shaded as the depth buffer's.", {"areas": len(log), "levels": levels}))  # fmt: skip
    color = np.asarray(frame.color)[:, :, :3]
    width, height = float(cam.width), float(cam.height)
    zoom = max(1, 256 // max(cam.width, 1))
    picture = np.repeat(np.repeat(color, zoom, axis=0), zoom, axis=1)

    def paint(index: int, canvas: _Canvas) -> None:
        canvas.image(picture, (0.0, height), (width, 0.0))
        canvas.rect((0.0, 0.0), (width, height), color="ink", fill="white", opacity=0.55)
        current = index - 1 if 0 < index <= levels else levels
        shown = log[log[:, 4] <= current]
        for row in shown:
            i0, j0, i1, j1, level, decision = (int(v) for v in row[:6])
            finished = decision != 4
            if level < current and not finished:
                continue
            paint_color = _DECISION_COLORS[decision]
            canvas.rect((i0, j0), (i1, j1), color=paint_color, fill=paint_color if finished else None,
                        opacity=0.45 if level == current else 0.2, width=1.5 if level == current else 0.5)  # fmt: skip
        for n, d in enumerate(DECISIONS):
            canvas.rect((width * 1.03, height - n * height / 9), (width * 1.07, height - (n + 0.6) * height / 9),
                        color=_DECISION_COLORS[n], fill=_DECISION_COLORS[n], opacity=0.6)  # fmt: skip
            canvas.label((width * 1.09, height - (n + 0.55) * height / 9), d, size=12)

    return Steps("Area subdivision (Warnock)", steps, result, paint, (0.0, 0.0, width * 1.35, height))


# --- scan line ---------------------------------------------------------------------------------------------

# each scan line's figure embeds the picture (about 12 bytes a pixel as PNG in base64, stretched) and its logs
_BYTES_PER_PIXEL_PER_FIGURE = 12


def _triangle_color(t: int) -> str:
    hue = (int(t) * 0.618034) % 1.0
    r, g, b = (int(200 * (0.5 + 0.5 * math.cos(2 * math.pi * (hue + k / 3)))) for k in range(3))
    return f"#{r:02x}{g:02x}{b:02x}"


def scan_line(scene: Scene | None = None, camera: Camera | None = None, **options: Any) -> Steps:
    """The scan-line method row by row: the edge table, then per scan line the active list (triangles crossing
    it, sorted by span start) and the spans walked, each with the surface that filled it.

    Runs ``render(scene, camera, method="scan-line", **options)`` with the kernel's recording mode on
    (``visibility.scanline.recording``); ``result`` is that frame, byte for byte the frame without recording.
    Rows are window rows (y up from the bottom); rows that no triangle crosses are left out.

    Raises
    ------
    OutputError
        A recording over the memory budget (one figure per row, each with the picture), with the estimate.
    """
    from frustum.render import render
    from frustum.visibility.scanline import recording

    where = "steps.scan_line"
    if scene is None:
        scene, default_camera = default_scene()
        camera = default_camera if camera is None else camera
    if not isinstance(scene, Scene):
        raise FrustumError(f"{where}: scene = {scene!r} is not a Scene")
    cam = _camera(camera, where)
    zoom = max(1, 256 // max(cam.width, 1))
    check_memory(cam.height * cam.width * cam.height * zoom * zoom * _BYTES_PER_PIXEL_PER_FIGURE, where=where,
                 cause=f"a recording of {cam.height} scan lines at {cam.width}x{cam.height}",
                 error=OutputError)  # fmt: skip
    with recording() as logs:
        frame = render(scene, cam, method="scan-line", **options)
    result = frame
    height, width = cam.height, cam.width
    if not logs:  # nothing drawn by the method (an empty scene)
        logs = [{"order": np.zeros(0, np.int64), "bucket": np.zeros(height + 1, np.int64),
                 "active": np.full((height, 0, 3), -1), "spans": np.full((height, 1, 4), -1),
                 "box": np.zeros((0, 4), np.int64), "code": np.zeros(0, np.int64)}]  # fmt: skip
    log = logs[0]
    bucket, order = log["bucket"], log["order"]
    table = {int(j): order[bucket[j] : bucket[j + 1]].tolist() for j in range(height) if bucket[j + 1] > bucket[j]}
    steps = [Step("The edge table",
                  "Every triangle is listed under the first scan line it crosses (its lowest row). Going up the "
                  "image row by row, triangles enter the active list from this table and leave after their last "
                  "row.", {f"row {j}": ts for j, ts in list(table.items())[:12]})]  # fmt: skip
    rows: list[int] = []
    for j in range(height):
        active = log["active"][j]
        active = active[active[:, 0] >= 0]
        if not len(active):
            continue
        spans = log["spans"][j]
        spans = spans[spans[:, 0] >= 0]
        described = []
        for x0, x1, t, inside in spans.tolist():
            who = f"triangle {t}" if t >= 0 else "per pixel"
            described.append(f"[{x0}, {x1 - 1}] {who}" + (f" ({inside} in)" if inside > 1 else ""))
        steps.append(Step(f"Scan line y = {j}: {len(active)} active, {len(spans)} spans",
                          "The active list holds the triangles crossing this row, sorted by the x where their "
                          "span starts (insertion sort: the order hardly changes from the row below). Walking the "
                          "row through span starts and ends: one surface in, it fills the span; several, the "
                          "nearest at both ends fills it; else the nearest is found pixel by pixel.",
                          {"active list (t, x from, x to)": [tuple(r) for r in active.tolist()],
                           "spans": described}))  # fmt: skip
        rows.append(j)
    steps.append(Step("The finished image", "Every row walked; the surfaces found are shaded as the depth "
                      "buffer's.", {"rows with surfaces": len(rows)}))  # fmt: skip
    color = np.asarray(frame.color)[:, :, :3]
    background = color[0, 0].copy() if np.asarray(frame.depth)[0, 0] >= 1.0 else np.zeros(3, np.uint8)

    def paint(index: int, canvas: _Canvas) -> None:
        done = height if index == len(steps) - 1 else (rows[index - 1] + 1 if index > 0 else 0)
        partial = np.empty_like(color)
        partial[:] = background
        if done:
            partial[height - done :] = color[height - done :]  # window rows 0 … done − 1 are the bottom ones
        canvas.image(np.repeat(np.repeat(partial, zoom, axis=0), zoom, axis=1), (0.0, height), (width, 0.0))
        canvas.rect((0.0, 0.0), (width, height), color="ink")
        if 0 < index < len(steps) - 1:
            j = rows[index - 1]
            canvas.line((0.0, j + 0.5), (width, j + 0.5), color="faint", width=0.8, dash=True)
            for x0, x1, t, _inside in log["spans"][j][log["spans"][j][:, 0] >= 0].tolist():
                canvas.rect((x0, j), (x1, j + 1), color="highlight", fill=_triangle_color(t) if t >= 0 else "white",
                            opacity=0.9, width=1.2)  # fmt: skip
            canvas.label((width + 1.0, j + 0.2), f"y = {j}", color="highlight", size=12)

    return Steps("Scan-line method", steps, result, paint, (0.0, 0.0, width * 1.15, float(height)))


# --- depth sort --------------------------------------------------------------------------------------------

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
    from frustum.visibility.bsp import depth_sort as production

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
    colors = {label: _triangle_color(label + 3) for label in set(labels.values())}

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


# --- A-buffer ----------------------------------------------------------------------------------------------


def default_transparent_scene() -> tuple[Scene, Camera]:
    """The depth-buffer scene with a half-transparent sphere and pillar: the A-buffer example of the chapter."""
    from frustum.shading import Material

    scene, camera = default_scene()
    for node, opacity in zip(scene.root.children, (1.0, 0.5, 0.6), strict=True):
        node.material = Material(color=node.material.color, opacity=opacity)
    return scene, camera


def _mask_cells(mask: int) -> list[tuple[int, int]]:
    """The covered subsamples (column a, row b from the bottom) of a 16-bit coverage mask (bit 4·b + a)."""
    return [(a, b) for b in range(4) for a in range(4) if mask >> (4 * b + a) & 1]


def a_buffer(
    scene: Scene | None = None, camera: Camera | None = None, pixel: tuple[int, int] | None = None, **options: Any
) -> Steps:
    """One pixel of the A-buffer: its fragment list (each fragment's 4×4 coverage mask, depth and color), then the
    resolved color.

    Runs ``render(scene, camera, method="a-buffer", **options)`` with the A-buffer's recording mode on
    (``visibility.abuffer.recording``: the fragment lists as resolved); ``result`` is that frame, byte for byte
    the frame without recording. `pixel` is ``(x, y)`` in window coordinates (y up from the bottom); by default
    the pixel with the most fragments.
    """
    from frustum.render import render
    from frustum.visibility.abuffer import recording

    where = "steps.a_buffer"
    if scene is None:
        scene, default_camera = default_transparent_scene()
        camera = default_camera if camera is None else camera
    if not isinstance(scene, Scene):
        raise FrustumError(f"{where}: scene = {scene!r} is not a Scene")
    cam = _camera(camera, where)
    with recording() as logs:
        frame = render(scene, cam, method="a-buffer", **options)
    result = frame
    if not logs:
        raise GeometryError(f"{where}: the A-buffer resolved no fragments; the scene shows no surface")
    fragments, premultiplied = logs[0]["fragments"], logs[0]["premultiplied"]
    starts = fragments.starts
    width, height = cam.width, cam.height
    if pixel is None:
        index = int(np.argmax(np.diff(starts)))
        x, y = index % width, height - 1 - index // width
    else:
        x, y = (int(v) for v in pixel)
        if not (0 <= x < width and 0 <= y < height):
            raise OutputError(f"{where}: pixel = {pixel!r} lies outside the {width}x{height} image; give 0 <= x < "
                              f"{width}, 0 <= y < {height}")  # fmt: skip
        index = (height - 1 - y) * width + x
    first, last = int(starts[index]), int(starts[index + 1])
    entries = []
    for k in range(first, last):
        rgba = premultiplied[k].astype(float) / 255.0
        alpha = float(rgba[3])
        entries.append({"triangle": int(fragments.triangle[k]), "mask": int(fragments.mask[k]),
                        "depth": float(fragments.depth[k, 0]), "alpha": alpha,
                        "color": rgba[:3] / alpha if alpha > 0 else rgba[:3]})  # fmt: skip
    steps = [Step(f"Pixel ({x}, {y}): {len(entries)} fragments",
                  "The A-buffer keeps, per pixel, a list of fragments: each surface touching the pixel leaves its "
                  "coverage of the pixel's 4×4 subsamples (a 16-bit mask), its depth and its color with opacity α.",
                  {"fragments": len(entries)})]  # fmt: skip
    for n, entry in enumerate(entries):
        bits = format(entry["mask"], "016b")
        steps.append(Step(f"Fragment {n + 1}: triangle {entry['triangle']}",
                          "Its coverage mask marks the subsamples the triangle covers (top-left rule at each); "
                          "shading was done once, at their centroid.",
                          {"mask (rows top to bottom)": " ".join(bits[i : i + 4][::-1] for i in range(0, 16, 4)),
                           "covered": bin(entry["mask"]).count("1"), "depth": entry["depth"],
                           "alpha": entry["alpha"]}))  # fmt: skip
    final = np.asarray(frame.color)[height - 1 - y, x]
    steps.append(Step("Resolved pixel",
                      "Per subsample, the fragments covering it are composited front to back by their plane's depth "
                      "there, C = Σ T_k·α_k·c_k + T·background with T_k = Π(1 − α_m) over the nearer ones; the "
                      "pixel is the mean of its 16 subsamples.", {"color (RGBA bytes)": final}))  # fmt: skip
    picture = np.asarray(frame.color)[:, :, :3]
    zoom = max(1, 160 // max(width, 1))
    big = np.repeat(np.repeat(picture, zoom, axis=0), zoom, axis=1)
    # the image on the left (width units), the pixel's 4×4 grid on the right, in a box of side `side`
    side = float(height)
    grid_x0 = width * 1.15

    def paint(index_: int, canvas: _Canvas) -> None:
        canvas.image(big, (0.0, height), (width, 0.0))
        canvas.rect((x, y), (x + 1, y + 1), color="highlight", width=2.0)
        cell = side / 4.0
        shown = entries if index_ == len(steps) - 1 else entries[max(0, index_ - 1) : index_]
        if index_ == len(steps) - 1:
            r, g, b = (int(v) for v in final[:3])
            canvas.rect((grid_x0, 0.0), (grid_x0 + side, side), color="ink", fill=f"#{r:02x}{g:02x}{b:02x}")
        for entry in shown[::-1]:  # the nearest last (on top)
            r, g, b = (int(np.clip(v, 0.0, 1.0) * 255) for v in entry["color"])
            for a, b_row in _mask_cells(entry["mask"]):
                canvas.rect((grid_x0 + a * cell, b_row * cell), (grid_x0 + (a + 1) * cell, (b_row + 1) * cell),
                            color="ink", fill=f"#{r:02x}{g:02x}{b:02x}",
                            opacity=0.5 if index_ == len(steps) - 1 else max(entry["alpha"], 0.25),
                            width=0.5)  # fmt: skip
        for k in range(5):
            canvas.line((grid_x0 + k * cell, 0.0), (grid_x0 + k * cell, side), color="faint", width=0.8)
            canvas.line((grid_x0, k * cell), (grid_x0 + side, k * cell), color="faint", width=0.8)
        canvas.label((grid_x0, side * 1.03), f"pixel ({x}, {y}): 4×4 subsamples", size=12)

    return Steps("A-buffer", steps, result, paint, (0.0, 0.0, grid_x0 + side, side * 1.08))


# --- ray casting ---------------------------------------------------------------------------------------------


def _pixel_ray(camera: Camera, x: int, y: int) -> tuple[float, ...]:
    """The ray of window pixel (x, y), with ``raster.rays.cast_pixels``' arithmetic: origin on the near plane,
    direction to the far plane (t in [0, 1))."""
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
    if scene is None:
        scene, default_camera = default_scene()
        camera = default_camera if camera is None else camera
    if not isinstance(scene, Scene):
        raise FrustumError(f"{where}: scene = {scene!r} is not a Scene")
    cam = _camera(camera, where)
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


# --- octree ------------------------------------------------------------------------------------------------

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
