"""The views of a sheet: one orthographic (or isometric) camera per view name, the hidden-line drawing of the
parts from it, and the circles each view shows end on (true circles) or side on (cylinder axes)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from frustum.camera import Camera, ViewFrame
from frustum.output.sheet.model import CIRCLE_TOLERANCE, END_ON_ANGLE, PIXELS, SheetView, geometry_points, to_local
from frustum.output.true_curves import Circle, circle_arcs, find_circles
from frustum.projection import ISOMETRIC_ROTATION_X, Axonometric, Orthographic
from frustum.visibility.hidden_lines import (
    EDGE_SILHOUETTE,
    HiddenLines,
    remove_hidden_lines,
)


def _view_camera(name: str, target: NDArray, radius: float) -> Camera:
    """Orthographic (or isometric) camera of `name` looking at `target`, view window 2.2·radius tall."""
    distance = 4.0 * radius
    height = 2.2 * radius
    near, far = distance - 1.5 * radius, distance + 1.5 * radius
    if name == "isometric":
        frame = ViewFrame(target + distance * np.array([0.0, 0.0, 1.0]), target, (0.0, 1.0, 0.0))
        # isometric angles, turned −45° about y so that the front, top and right faces show (as the right view)
        isometric = Axonometric(-math.pi / 4, ISOMETRIC_ROTATION_X, height, near, far)
        return Camera(frame, isometric, PIXELS, PIXELS)
    return Camera.multiview(name, Orthographic(height, near, far), target, distance, PIXELS, PIXELS)


def make_views(
    names: Sequence[str], points_world: NDArray, meshes: list, options: dict
) -> tuple[list[SheetView], list[Circle]]:
    low, high = points_world.min(axis=0), points_world.max(axis=0)
    target = (low + high) / 2.0
    radius = max(float(np.linalg.norm(high - low)) / 2.0, 1e-9)
    circles = find_circles(meshes, options["crease_angle"])
    parts_world = [geometry_points(mesh) @ m[:3, :3].T + m[:3, 3] for mesh, m in meshes]
    views = []
    for name in names:
        camera = _view_camera(name, target, radius)
        mm_per_pixel = 2.2 * radius / PIXELS
        lines = remove_hidden_lines(meshes, camera, **options)
        local = to_local(camera.project(points_world)[:, :2], mm_per_pixel)
        end_on = [] if name == "isometric" else _end_on(circles, camera, lines, mm_per_pixel)
        axes = [] if name == "isometric" else _side_on_axes(circles, camera, mm_per_pixel)
        shown = [_shown(lines, index) for index in range(len(meshes))]
        lines, visible_arcs, hidden_arcs = circle_arcs(lines, circles, camera)
        view = SheetView(name, camera, mm_per_pixel, lines, local, end_on, axes, visible_arcs, hidden_arcs)
        view.parts = [to_local(camera.project(points)[:, :2], mm_per_pixel) for points in parts_world]
        view.shown = shown
        if name != "isometric":
            u, v = np.asarray(camera.frame.u), np.asarray(camera.frame.v)
            view.across, view.down = int(np.argmax(np.abs(u))), int(np.argmax(np.abs(v)))
            view.circle_keys = _circle_keys(end_on, circles, camera, mm_per_pixel, 2.0 * radius)
        views.append(view)
    return views, circles


def _shown(lines: HiddenLines, mesh: int) -> float:
    """Visible share of the drawn edges of placed mesh `mesh` (window length), 0 where none is drawn."""
    lengths = []
    for window, owners in ((lines.visible, lines.visible_edges), (lines.hidden, lines.hidden_edges)):
        mine = lines.edge_meshes[owners] == mesh
        lengths.append(float(np.linalg.norm(window[mine, 1] - window[mine, 0], axis=1).sum()))
    total = lengths[0] + lengths[1]
    return lengths[0] / total if total > 0.0 else 0.0


def circle_key(circle: Circle, size: float) -> tuple:
    """One key for the circles a part's diameter states: (part, radius, axis); a sphere's axis is -1."""
    axis = -1 if circle.kind == "sphere" else int(np.argmax(np.abs(circle.normal)))
    return (circle.mesh, round(circle.radius / size, 9), axis)


def _circle_keys(end_on: list, circles: list[Circle], camera: Camera, mm_per_pixel: float, size: float) -> list:
    """For each end-on circle entry (projected centre, radius): the keys of the circles drawn there."""
    direction = np.asarray(camera.frame.direction)
    keys: list[set] = [set() for _ in end_on]
    for circle in circles:
        if circle.kind == "arc":
            continue
        if circle.kind != "sphere" and abs(float(circle.normal @ direction)) < math.cos(END_ON_ANGLE):
            continue
        centre = to_local(camera.project(circle.centre[None, :])[:, :2], mm_per_pixel)[0]
        tolerance = 1e-6 * circle.radius
        for k, (c, r, _) in enumerate(end_on):
            if np.abs(c - centre).max() <= tolerance and abs(r - circle.radius) <= tolerance:
                keys[k].add(circle_key(circle, size))
    return keys


def _side_on_axes(circles: list[Circle], camera: Camera, mm_per_pixel: float) -> list:
    """Axes of the cylinders `camera` sees from the side, as view-local segments, collinear overlaps merged.

    A cylinder (or a coaxial hole) shows as two circles of equal radius whose centres lie on their common normal;
    its axis is drawn where it is perpendicular to the line of sight (within 1e-6 rad).
    """
    direction = np.asarray(camera.frame.direction)
    found: list[tuple[NDArray, NDArray]] = []
    circles = [circle for circle in circles if circle.kind == "loop"]
    for i, first in enumerate(circles):
        if abs(float(first.normal @ direction)) > math.sin(END_ON_ANGLE):
            continue
        for second in circles[i + 1 :]:
            tolerance = CIRCLE_TOLERANCE * first.radius
            offset = second.centre - first.centre
            if (
                abs(second.radius - first.radius) > tolerance
                or abs(abs(float(first.normal @ second.normal)) - 1.0) > CIRCLE_TOLERANCE
                or np.linalg.norm(np.cross(offset, first.normal)) > tolerance
                or np.linalg.norm(offset) <= tolerance
            ):
                continue
            ends = to_local(camera.project(np.stack([first.centre, second.centre]))[:, :2], mm_per_pixel)
            found.append((ends[0], ends[1]))
    # merge collinear, overlapping segments (a lid on its housing): one chain line per run
    merged: list[tuple[NDArray, NDArray]] = []
    for a, b in sorted(found, key=lambda ends: (round(float(ends[0][0]), 9), round(float(ends[0][1]), 9))):
        unit = (b - a) / np.linalg.norm(b - a)
        for k, (c, d) in enumerate(merged):
            along = (d - c) / np.linalg.norm(d - c)
            gap = 1e-6 * max(float(np.linalg.norm(d - c)), float(np.linalg.norm(b - a)))
            offset = a - c
            if (
                abs(float(unit[0] * along[1] - unit[1] * along[0])) > 1e-9  # 2D cross products: not parallel,
                or abs(float(offset[0] * along[1] - offset[1] * along[0])) > gap
            ):  # or not on one line
                continue
            t = [float((p - c) @ along) for p in (a, b)]
            span = float(np.linalg.norm(d - c))
            if min(t) > span + gap or max(t) < -gap:
                continue
            low, high = min(0.0, *t), max(span, *t)
            merged[k] = (c + low * along, c + high * along)
            break
        else:
            merged.append((a, b))
    return merged


def _end_on(circles: list[Circle], camera: Camera, lines: HiddenLines, mm_per_pixel: float) -> list:
    """The circles seen end-on by `camera`, once per projected centre and radius: (local centre, radius,
    visible fraction of the drawn circle)."""
    direction = np.asarray(camera.frame.direction)
    seen: list[tuple[NDArray, float, float]] = []
    for circle in circles:
        if circle.kind == "arc":  # arcs get radius leaders (plan_parts), not centre lines
            continue
        if circle.kind == "sphere":  # seen as its silhouette circle from every side
            circle = Circle(circle.centre, direction, circle.radius, 0, circle.mesh, "sphere")
        elif abs(float(circle.normal @ direction)) < math.cos(END_ON_ANGLE):
            continue
        centre = to_local(camera.project(circle.centre[None, :])[:, :2], mm_per_pixel)[0]
        if circle.kind in ("sphere", "torus"):  # outlines: the share of the mesh's silhouette that is visible
            visible = _silhouette_visible(lines, circle.mesh)
            _add_seen(seen, centre, circle.radius, visible)
            continue
        # drawn pieces of this circle: ends in its plane, between the chord midpoints' and the vertices' radius
        inner = circle.radius * math.cos(math.pi / circle.sides) * (1.0 - 1e-6)
        outer = circle.radius * (1.0 + 1e-6)
        lengths = []
        for world in (lines.visible_world, lines.hidden_world):
            offsets = world - circle.centre
            planar = (np.abs(offsets @ circle.normal) <= 1e-6 * circle.radius).all(axis=1)
            distance = np.linalg.norm(offsets, axis=2)
            on = planar & ((distance >= inner) & (distance <= outer)).all(axis=1)
            lengths.append(float(np.linalg.norm(world[on, 1] - world[on, 0], axis=1).sum()))
        drawn = lengths[0] + lengths[1]
        _add_seen(seen, centre, circle.radius, lengths[0] / drawn if drawn > 0.0 else 0.0)
    return seen


def _add_seen(seen: list, centre: NDArray, radius: float, visible: float) -> None:
    """Add an end-on circle once per projected centre and radius, keeping the larger visible fraction."""
    tolerance = 1e-6 * radius
    same = next(
        (
            k
            for k, (c, r, _) in enumerate(seen)
            if np.abs(c - centre).max() <= tolerance and abs(r - radius) <= tolerance
        ),
        None,
    )
    if same is None:
        seen.append((centre, radius, visible))
    elif visible > seen[same][2]:
        seen[same] = (centre, radius, visible)


def _silhouette_visible(lines: HiddenLines, mesh: int) -> float:
    """Visible fraction of the drawn silhouette of placed mesh `mesh` (a sphere's outline)."""
    lengths = []
    for window, owners in ((lines.visible, lines.visible_edges), (lines.hidden, lines.hidden_edges)):
        mine = (lines.edge_meshes[owners] == mesh) & ((lines.edge_kinds[owners] & EDGE_SILHOUETTE) != 0)
        lengths.append(float(np.linalg.norm(window[mine, 1] - window[mine, 0], axis=1).sum()))
    total = lengths[0] + lengths[1]
    return lengths[0] / total if total > 0.0 else 0.0
