"""Visible surfaces step by step, the image-space methods: the depth buffer (surface by surface), area subdivision
(Warnock, window by window), the scan line (span by span) and the A-buffer (fragment lists per pixel).

References: [HB 16] "Depth-Buffer Method", "Area-Subdivision Method", "Scan-Line Method", "A-Buffer Method";
[seed] "Depth-buffer method".
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from frustum.budgets import check_memory, check_operations
from frustum.camera import Camera
from frustum.errors import FrustumError, GeometryError, OutputError
from frustum.scene import Scene
from frustum.steps._record import Step, Steps, _Canvas
from frustum.steps.viewing import _camera

__all__ = [
    "a_buffer",
    "area_subdivision",
    "default_scene",
    "default_transparent_scene",
    "depth_buffer",
    "scan_line",
    "triangle_color",
]


def triangle_color(t: int) -> str:
    """A distinct color for triangle `t` of a figure (hues spaced by the golden ratio)."""
    hue = (int(t) * 0.618034) % 1.0
    r, g, b = (int(200 * (0.5 + 0.5 * math.cos(2 * math.pi * (hue + k / 3)))) for k in range(3))
    return f"#{r:02x}{g:02x}{b:02x}"


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


def scene_and_camera(scene: Scene | None, camera: Camera | None, where: str,
                     default: Callable[[], tuple[Scene, Camera]] = default_scene) -> tuple[Scene, Camera]:  # fmt: skip
    """The scene and checked camera a visible-surface step works on: `default`'s scene and camera where none is
    given (a given camera wins over the default's)."""
    if scene is None:
        scene, default_camera = default()
        camera = default_camera if camera is None else camera
    if not isinstance(scene, Scene):
        raise FrustumError(f"{where}: scene = {scene!r} is not a Scene")
    return scene, _camera(camera, where)


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
    scene, cam = scene_and_camera(scene, camera, where)
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
    scene, cam = scene_and_camera(scene, camera, where)
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


# each scan line's figure embeds the picture (about 12 bytes a pixel as PNG in base64, stretched) and its logs
_BYTES_PER_PIXEL_PER_FIGURE = 12


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
    scene, cam = scene_and_camera(scene, camera, where)
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
                canvas.rect((x0, j), (x1, j + 1), color="highlight", fill=triangle_color(t) if t >= 0 else "white",
                            opacity=0.9, width=1.2)  # fmt: skip
            canvas.label((width + 1.0, j + 0.2), f"y = {j}", color="highlight", size=12)

    return Steps("Scan-line method", steps, result, paint, (0.0, 0.0, width * 1.15, float(height)))


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
    scene, cam = scene_and_camera(scene, camera, where, default_transparent_scene)
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
