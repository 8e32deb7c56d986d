"""Engineering drawing sheets: multiview orthographic projections laid out in first- or third-angle projection.

A multiview drawing shows an object by orthogonal projections along its principal axes, "that show accurate
dimensions": the front, side and rear *elevations* and the *plan* (top) view, here with an isometric view
beside them. The sheet is an SVG whose user unit is one millimetre of paper; model units are millimetres and
a model length L is drawn L × scale long in every orthographic view (an edge parallel to the view plane keeps
its length under an orthogonal projection). Hidden edges are dashed, as engineering drawings use.

Layout (the views stay aligned: the top view shares the front view's x axis, the side views its y axis):

========================  ===========================  ===========================
view                      third angle (ISO E, US)      first angle (ISO, Europe)
========================  ===========================  ===========================
top (plan)                above the front view         below the front view
bottom                    below                        above
right                     right of the front view      left of the front view
left                      left                         right
rear                      far right                    far right
isometric                 upper right (top's row)      lower right (top's row)
========================  ===========================  ===========================

Why one module: layout, views, dimensions and the title block of one sheet share its scale and paper geometry.

References
----------
[HB 10] "Orthogonal Projections" (front, side and rear elevations; plan view), "Axonometric and Isometric
Orthogonal Projections"; [seed] "Elevation and Plan View", "engineering and architectural drawings".
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from html import escape as _html_escape
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import as_scalar, describe
from frustum.camera import Camera, ViewFrame
from frustum.errors import OutputError
from frustum.geometry import Mesh, Polyline
from frustum.output.svg import (
    _HIDDEN_GRAY,
    _check_common,
    _drawing_groups,
    _escape,
    _number,
    _placed_meshes,
    save_svg,
    svg_document,
)
from frustum.output.true_curves import Circle, EllipseArc, circle_arcs, find_circles, svg_arc_elements
from frustum.projection import ISOMETRIC_ROTATION_X, MULTIVIEWS, Axonometric, Orthographic, multiview
from frustum.scene import Scene
from frustum.visibility.hidden_lines import (
    DEFAULT_CREASE_ANGLE,
    EDGE_SILHOUETTE,
    HiddenLines,
    remove_hidden_lines,
)

__all__ = [
    "DIMENSION_MODES",
    "ORIENTATIONS",
    "PAPER_SIZES",
    "SHEET_VIEWS",
    "STANDARD_SCALES",
    "dimension_text",
    "drawing_sheet",
    "scale_label",
]

PAPER_SIZES: dict[str, tuple[float, float]] = {
    "A0": (1189.0, 841.0),
    "A1": (841.0, 594.0),
    "A2": (594.0, 420.0),
    "A3": (420.0, 297.0),
    "A4": (297.0, 210.0),
    "letter": (279.4, 215.9),
    "tabloid": (431.8, 279.4),
}
"""Paper sizes in millimetres, landscape (width, height); names are matched without regard to case."""
ORIENTATIONS = ("landscape", "portrait")
"""Sheet orientations: landscape puts the long side of a named paper size horizontal."""
STANDARD_SCALES = tuple(m * 10.0**k if k >= 0 else m / 10.0**-k for k in range(2, -5, -1) for m in (5.0, 2.0, 1.0))
"""Drawing scales (paper length / model length) ``scale=None`` chooses from, largest first: ISO 5455's
1, 2, 5 series (500:1 … 1:10000; the standard's table extended by powers of ten, as it allows)."""
DIMENSION_MODES = ("parts", "overall")
"""What ``drawing_sheet(dimensions=...)`` dimensions besides False: each part's sizes, or each view's overall extent."""
SHEET_VIEWS = (*MULTIVIEWS, "isometric")
"""View names ``drawing_sheet`` accepts."""

# grid cell of each view relative to the front view, (column, row), row grows downward
_THIRD_ANGLE = {"front": (0, 0), "top": (0, -1), "bottom": (0, 1), "right": (1, 0), "left": (-1, 0),
                "rear": (2, 0), "isometric": (1, -1)}  # fmt: skip
_FIRST_ANGLE = {"front": (0, 0), "top": (0, 1), "bottom": (0, -1), "right": (-1, 0), "left": (1, 0),
                "rear": (2, 0), "isometric": (1, 1)}  # fmt: skip
_MARGIN = 10.0  # border to paper edge, mm
_TITLE_HEIGHT = 36.0  # title block strip at the bottom of the frame, mm
_TITLE_WIDTH = 180.0  # ISO 7200: at most 180 mm wide
_MIN_GAP = 8.0  # least space between views (and between views and the border), mm
_PIXELS = 1000  # window size of the view cameras; window → paper is x_p = scale · (h / _PIXELS) · x_w + ...
# dimensioning (ISO 129-1): thin lines, closed filled arrowheads, 3.5 mm lettering above the dimension line
_THIN = 0.25  # dimension, extension, leader and centre lines, mm
_DIMENSION_OFFSET = 10.0  # view outline to dimension line, mm
_DIMENSION_SPACING = 7.0  # between stacked parallel dimension lines, mm
_PARTS_TRIES = 4  # scales at which the views fit that dimensions="parts" tries before falling back to "overall"
_EXTENSION_GAP = 1.0  # extension lines start this far from the feature ...
_EXTENSION_BEYOND = 2.0  # ... and end this far past the dimension line, mm
_ARROW_LENGTH, _ARROW_HALF_WIDTH = 3.0, 0.55  # arrowhead, mm (about 20 degrees included)
_LETTER = 3.5  # dimension and label text height, mm
_LEADER_RISE = 5.0  # a diameter leader's shoulder sits this far above the view, mm; more leaders stack 6 mm apart
_LABEL_DROP = 7.0  # view label baseline below everything else of the view, mm
# circles (output/true_curves.py): two circles are one cylinder's when radii and axes agree within this fraction
_CIRCLE_TOLERANCE = 1e-6
# an end-on circle's plane normal lies within this angle (radians) of the line of sight
_END_ON_ANGLE = 1e-6


@dataclass
class _View:
    name: str
    camera: Camera
    model_per_pixel: float  # model length (mm) per window pixel
    lines: HiddenLines
    local: NDArray[np.float64]  # (N, 2) every model vertex in view-local model mm: x right, y down, origin = target
    circles: list[tuple[NDArray[np.float64], float, float]]  # end-on circles: local centre, radius, visible part
    axes: list[tuple[NDArray[np.float64], NDArray[np.float64]]]  # cylinder axes seen side-on: local ends
    visible_arcs: list[EllipseArc] = field(default_factory=list)  # true curves, window coordinates
    hidden_arcs: list[EllipseArc] = field(default_factory=list)
    parts: list[NDArray[np.float64]] = field(default_factory=list)  # (N_p, 2) view-local points of each part
    # world axis (0, 1, 2) running across / down the view; -1 for a view not aligned with the axes (isometric)
    across: int = -1
    down: int = -1
    # per part: visible share of its drawn edges in this view (how well the view shows it)
    shown: list[float] = field(default_factory=list)
    # per end-on circle entry of `circles`: the keys (part, radius, axis) of the circles drawn there
    circle_keys: list[set] = field(default_factory=list)


@dataclass
class _Mark:
    """One annotation in view-local paper mm (x right, y down, origin = the view's projected target)."""

    kind: str  # "dimension", "diameter", "centre" (centre lines), "label"
    name: str  # id suffix
    value: float = math.nan  # the model length a dimension states
    lines: list[tuple[float, float, float, float]] = field(default_factory=list)
    arrows: list[tuple[float, float, float, float]] = field(default_factory=list)  # tip x, y, unit direction
    texts: list[tuple[float, float, str, str, bool]] = field(default_factory=list)  # x, y, text, anchor, vertical
    # what the mark measures, for CAD (DXF DIMENSION entities): ("linear", a, b, at, horizontal) or
    # ("diameter", centre, radius, tip) in the same coordinates, or None
    definition: tuple | None = None
    circles: list[tuple[float, float, float]] = field(default_factory=list)  # x, y, radius (projection symbol)
    text_size: float = _LETTER
    line_width: float = _THIN
    body: list | None = field(default=None, repr=False, compare=False)  # cached by _body


def _box(marks: list[_Mark]) -> NDArray[np.float64]:
    """(x0, y0, x1, y1) around every shape of `marks` (text as 0.6 · height per character)."""
    xs: list[float] = []
    ys: list[float] = []
    for mark in marks:
        for x0, y0, x1, y1 in mark.lines:
            xs += [x0, x1]
            ys += [y0, y1]
        for x, y, _, _ in mark.arrows:
            xs.append(x)
            ys.append(y)
        for x, y, text, anchor, vertical in mark.texts:
            run = 0.6 * _LETTER * len(text)
            along = {"start": (0.0, run), "middle": (-run / 2, run / 2), "end": (-run, 0.0)}[anchor]
            if vertical:  # rotated −90°: reads upward, the run along −y
                xs += [x - _LETTER, x]
                ys += [y - along[1], y - along[0]]
            else:
                xs += [x + along[0], x + along[1]]
                ys += [y - _LETTER, y]
    if not xs:
        return np.array([np.inf, np.inf, -np.inf, -np.inf])
    return np.array([min(xs), min(ys), max(xs), max(ys)])


def scale_label(scale: float) -> str:
    """Drawing-scale text: ``"1:1"``, ``"2:1"``, ``"1:5"``, or ``"1:<1/scale>"`` for other values."""
    if scale >= 1.0 and float(scale).is_integer():
        return f"{int(scale)}:1"
    inverse = 1.0 / scale
    if abs(inverse - round(inverse)) <= 1e-9 * inverse:
        return f"1:{round(inverse)}"
    return f"1:{_number(round(inverse, 6))}"


def dimension_text(value: float) -> str:
    """A dimension value as a drafter writes it: four significant digits, at most six decimals, no trailing
    zeros (``40``, ``2.4``, ``0.16``, ``1235``)."""
    value = float(value)
    if value == 0.0:
        return "0"
    decimals = min(6, max(0, 3 - math.floor(math.log10(abs(value)))))
    text = f"{round(value, decimals):.{decimals}f}"
    return text.rstrip("0").rstrip(".") if "." in text else text


def _view_camera(name: str, target: NDArray, radius: float) -> Camera:
    """Orthographic (or isometric) camera of `name` looking at `target`, view window 2.2·radius tall."""
    distance = 4.0 * radius
    height = 2.2 * radius
    near, far = distance - 1.5 * radius, distance + 1.5 * radius
    if name == "isometric":
        frame = ViewFrame(target + distance * np.array([0.0, 0.0, 1.0]), target, (0.0, 1.0, 0.0))
        # isometric angles, turned −45° about y so that the front, top and right faces show (as the right view)
        isometric = Axonometric(-math.pi / 4, ISOMETRIC_ROTATION_X, height, near, far)
        return Camera(frame, isometric, _PIXELS, _PIXELS)
    return Camera.multiview(name, Orthographic(height, near, far), target, distance, _PIXELS, _PIXELS)


def _sheet_views(
    names: Sequence[str], points_world: NDArray, meshes: list, options: dict
) -> tuple[list[_View], list[Circle]]:
    low, high = points_world.min(axis=0), points_world.max(axis=0)
    target = (low + high) / 2.0
    radius = max(float(np.linalg.norm(high - low)) / 2.0, 1e-9)
    circles = find_circles(meshes, options["crease_angle"])
    parts_world = [_points(mesh) @ m[:3, :3].T + m[:3, 3] for mesh, m in meshes]
    views = []
    for name in names:
        camera = _view_camera(name, target, radius)
        mm_per_pixel = 2.2 * radius / _PIXELS
        lines = remove_hidden_lines(meshes, camera, **options)
        local = _to_local(camera.project(points_world)[:, :2], mm_per_pixel)
        end_on = [] if name == "isometric" else _end_on(circles, camera, lines, mm_per_pixel)
        axes = [] if name == "isometric" else _side_on_axes(circles, camera, mm_per_pixel)
        shown = [_shown(lines, index) for index in range(len(meshes))]
        lines, visible_arcs, hidden_arcs = circle_arcs(lines, circles, camera)
        view = _View(name, camera, mm_per_pixel, lines, local, end_on, axes, visible_arcs, hidden_arcs)
        view.parts = [_to_local(camera.project(points)[:, :2], mm_per_pixel) for points in parts_world]
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


def _circle_key(circle: Circle, size: float) -> tuple:
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
        if circle.kind != "sphere" and abs(float(circle.normal @ direction)) < math.cos(_END_ON_ANGLE):
            continue
        centre = _to_local(camera.project(circle.centre[None, :])[:, :2], mm_per_pixel)[0]
        tolerance = 1e-6 * circle.radius
        for k, (c, r, _) in enumerate(end_on):
            if np.abs(c - centre).max() <= tolerance and abs(r - circle.radius) <= tolerance:
                keys[k].add(_circle_key(circle, size))
    return keys


def _to_local(window: NDArray, factor: float) -> NDArray:
    """Window (x, y up) → view-local (x right, y down) around the window centre, times `factor`."""
    half = _PIXELS / 2.0
    return np.column_stack([(window[:, 0] - half) * factor, -(window[:, 1] - half) * factor])


def _side_on_axes(circles: list[Circle], camera: Camera, mm_per_pixel: float) -> list:
    """Axes of the cylinders `camera` sees from the side, as view-local segments, collinear overlaps merged.

    A cylinder (or a coaxial hole) shows as two circles of equal radius whose centres lie on their common normal;
    its axis is drawn where it is perpendicular to the line of sight (within 1e-6 rad).
    """
    direction = np.asarray(camera.frame.direction)
    found: list[tuple[NDArray, NDArray]] = []
    circles = [circle for circle in circles if circle.kind == "loop"]
    for i, first in enumerate(circles):
        if abs(float(first.normal @ direction)) > math.sin(_END_ON_ANGLE):
            continue
        for second in circles[i + 1 :]:
            tolerance = _CIRCLE_TOLERANCE * first.radius
            offset = second.centre - first.centre
            if (
                abs(second.radius - first.radius) > tolerance
                or abs(abs(float(first.normal @ second.normal)) - 1.0) > _CIRCLE_TOLERANCE
                or np.linalg.norm(np.cross(offset, first.normal)) > tolerance
                or np.linalg.norm(offset) <= tolerance
            ):
                continue
            ends = _to_local(camera.project(np.stack([first.centre, second.centre]))[:, :2], mm_per_pixel)
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
        if circle.kind == "arc":  # arcs get radius leaders (_plan_parts), not centre lines
            continue
        if circle.kind == "sphere":  # seen as its silhouette circle from every side
            circle = Circle(circle.centre, direction, circle.radius, 0, circle.mesh, "sphere")
        elif abs(float(circle.normal @ direction)) < math.cos(_END_ON_ANGLE):
            continue
        centre = _to_local(camera.project(circle.centre[None, :])[:, :2], mm_per_pixel)[0]
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


# --- annotations in view-local paper millimetres ----------------------------------------------------------


def _marks(view: _View, scale: float, dimensions: str | None, plan: _Plan | None = None) -> list[_Mark]:
    """Centre lines of end-on circles, dimensions (overall extents or each part's sizes, diameters) and the
    label of one view."""
    marks: list[_Mark] = []
    paper = view.local * scale
    x0, y0 = paper.min(axis=0)
    x1, y1 = paper.max(axis=0)
    orthographic = view.name != "isometric"
    if orthographic and (view.circles or view.axes):
        centres = _Mark("centre", "centre-lines")
        for centre, radius, _ in view.circles:
            _centre_lines(centres, centre * scale, radius * scale)
        for a, b in view.axes:
            # the axis, 2 mm past the ends of the cylinder
            along = (b - a) / np.linalg.norm(b - a)
            start, end = a * scale - 2.0 * along, b * scale + 2.0 * along
            centres.lines += _chain_line((float(start[0]), float(start[1])), (float(end[0]), float(end[1])))
        marks.append(centres)
    if dimensions == "parts" and orthographic and plan is not None:
        marks += _part_dimensions(view, scale, plan.linear[view.name])
        marks += _diameters(view, scale, min(y0, float(_box(marks)[1])), plan.leaders[view.name])
        marks += _radius_leaders(view, scale, plan.radii.get(view.name, []))
    elif dimensions == "overall" and orthographic:
        model = view.local.max(axis=0) - view.local.min(axis=0)
        tolerance = 1e-9 * max(x1 - x0, y1 - y0, 1e-300)
        # horizontal: below the view, extension lines from the lowest point on each extreme vertical
        # (a part seen edge-on, of no width or height, has nothing to dimension that way)
        if model[0] > 1e-12 * model.max():
            feet = [float(paper[np.abs(paper[:, 0] - x) <= tolerance, 1].max()) for x in (x0, x1)]
            marks.append(_linear("horizontal", float(model[0]), (x0, feet[0]), (x1, feet[1]), y1 + _DIMENSION_OFFSET))
        # vertical: right of the view, extension lines from the rightmost point on each extreme horizontal
        if model[1] > 1e-12 * model.max():
            feet = [float(paper[np.abs(paper[:, 1] - y) <= tolerance, 0].max()) for y in (y0, y1)]
            marks.append(_linear("vertical", float(model[1]), (feet[0], y0), (feet[1], y1), x1 + _DIMENSION_OFFSET))
        marks += _diameters(view, scale, y0)
    bottom = max(float(_box(marks)[3]), y1)
    label = _Mark("label", "label")
    label.texts.append(((x0 + x1) / 2.0, bottom + _LABEL_DROP, f"{view.name.upper()} VIEW", "middle", False))
    marks.append(label)
    return marks


def _linear(
    name: str, value: float, a: tuple[float, float], b: tuple[float, float], at: float, *, mark_name: str = "",
    prefix: str = "", text_side: str = "",
) -> Any:  # fmt: skip
    """A linear dimension of model length `value` between feature points `a` and `b` (paper): extension lines
    to a dimension line at `at` (y for "horizontal", x for "vertical"), arrowheads at both ends (outside,
    pointing in, when they do not fit between), the value above the line (vertical: reading from the right),
    or past the end of the line when it does not fit between the extension lines (ISO 129-1). `text_side`
    "fit", "after" (past the high end) or "before" asks for one placement: None when "fit" does not fit;
    "" chooses (between, else after)."""
    mark = _Mark("dimension", mark_name or f"dimension-{name}", value)
    horizontal = name == "horizontal"
    axis = 0 if horizontal else 1
    low, high = a[axis], b[axis]
    mark.definition = ("linear", a, b, at, horizontal)
    for point in (a, b):
        foot = point[1 - axis]
        sign = 1.0 if at >= foot else -1.0
        start, end = foot + sign * _EXTENSION_GAP, at + sign * _EXTENSION_BEYOND
        mark.lines.append((point[0], start, point[0], end) if horizontal else (start, point[1], end, point[1]))
    inside = high - low >= 2 * _ARROW_LENGTH + 1.0
    reach = 0.0 if inside else _ARROW_LENGTH + 2.0
    mark.lines.append((low - reach, at, high + reach, at) if horizontal else (at, low - reach, at, high + reach))
    outward = -1.0 if inside else 1.0  # direction of travel of the low arrow: tips outward, or inward from outside
    for tip, sign in ((low, outward), (high, -outward)):
        mark.arrows.append((tip, at, sign, 0.0) if horizontal else (at, tip, 0.0, sign))
    middle = (low + high) / 2.0
    text = prefix + dimension_text(value)
    run = 0.6 * _LETTER * len(text)
    fits = run + 2.0 <= high - low
    if text_side == "fit" and not fits:
        return None
    offset = -1.0  # the text 1 mm above the line (left of a vertical one, reading from the right)
    if fits and text_side in ("", "fit"):
        mark.texts.append(
            (middle, at + offset, text, "middle", False) if horizontal else (at + offset, middle, text, "middle", True)
        )
    elif text_side in ("", "after"):  # past the high end (right; for a vertical dimension: below, reading up)
        position = high + reach + 1.5
        mark.texts.append(
            (position, at + offset, text, "start", False)
            if horizontal
            else (at + offset, position + run, text, "start", True)
        )
    else:  # past the low end (left; above)
        position = low - reach - 1.5
        mark.texts.append(
            (position, at + offset, text, "end", False) if horizontal else (at + offset, position, text, "start", True)
        )
    return mark


def _centre_lines(mark: _Mark, centre: NDArray, radius: float) -> None:
    """Two centre lines crossing at the centre on their long dashes, 2 mm past the circle (a centre mark)."""
    reach = radius + 2.0
    cx, cy = float(centre[0]), float(centre[1])
    mark.lines += _chain_line((cx - reach, cy), (cx + reach, cy))
    mark.lines += _chain_line((cx, cy - reach), (cx, cy + reach))


_CHAIN_LONG, _CHAIN_GAP, _CHAIN_SHORT = 8.0, 1.0, 1.0  # long-dashed dotted narrow line (ISO 128-2 type 04), mm


def _chain_line(a: tuple[float, float], b: tuple[float, float]) -> list[tuple[float, float, float, float]]:
    """A centre line from `a` to `b` as its dashes, symmetric about the middle: a long dash across the middle,
    then short dash and long dash in turn, and a long dash (never a gap or a short dash) at each end. A line
    too short for one short dash each side is drawn solid (ISO 128-2: small circles get continuous centre
    lines)."""
    ax, ay = a
    bx, by = b
    half = math.hypot(bx - ax, by - ay) / 2.0
    if half <= 0.0:
        return []
    ux, uy = (bx - ax) / (2 * half), (by - ay) / (2 * half)
    mx, my = (ax + bx) / 2.0, (ay + by) / 2.0
    # pieces along one half, from the middle: [0, L/2] long, then (gap, short, gap, long) repeated
    pieces: list[list[float]] = [[0.0, _CHAIN_LONG / 2]]
    position = _CHAIN_LONG / 2
    while position < half:
        short = [position + _CHAIN_GAP, position + _CHAIN_GAP + _CHAIN_SHORT]
        long = [short[1] + _CHAIN_GAP, short[1] + _CHAIN_GAP + _CHAIN_LONG]
        pieces += [short, long]
        position = long[1]
    # cut at the end; an end that is not a long dash of at least 2 mm: extend the last long dash instead
    kept = [piece for piece in pieces if piece[0] < half]
    while len(kept) > 1 and (len(kept) % 2 == 0 or half - kept[-1][0] < 2.0):
        kept.pop()
    kept[-1][1] = half
    segments = []
    for start, end in kept:
        for sign in (1.0, -1.0):
            if start == 0.0 and sign < 0.0:  # the middle dash: once, across the middle
                segments.append((mx - end * ux, my - end * uy, mx + end * ux, my + end * uy))
            elif start > 0.0:
                p, q = start * sign, end * sign
                segments.append((mx + p * ux, my + p * uy, mx + q * ux, my + q * uy))
    return segments


def _diameter_groups(view: _View) -> list[tuple[float, list[NDArray]]]:
    """Visible end-on circles grouped by diameter (within 1e-6): (radius, local centres sorted by x, y)."""
    groups: list[tuple[float, list[NDArray]]] = []
    for centre, radius, visible in view.circles:
        if visible < 0.5:
            continue
        for k, (r, centres) in enumerate(groups):
            if abs(r - radius) <= 1e-6 * radius:
                groups[k] = (r, [*centres, centre])
                break
        else:
            groups.append((radius, [centre]))
    ordered = sorted(groups, key=lambda group: -group[0])
    return [(r, sorted(c, key=lambda p: (float(p[0]), float(p[1])))) for r, c in ordered]


def _diameters(
    view: _View, scale: float, top: float, groups: list[tuple[float, list[NDArray], str]] | None = None
) -> list[_Mark]:
    """One leader per diameter: from the circle at 45° (57°, 69°, ...) up and right (arrowhead on the circle,
    pointing at the centre) to a shoulder above the view, with "⌀d" (or "n× ⌀d" for n equal circles; "S⌀d"
    for a sphere). `groups` (radius, local centres, symbol) default to every visible end-on circle of the view."""
    marks = []
    if groups is None:
        groups = [(radius, centres, "⌀") for radius, centres in _diameter_groups(view)]
    for index, (radius, centres, symbol) in enumerate(groups):
        # each further leader 12° steeper (concentric circles' leaders are rays from one centre: never cross)
        angle = math.radians(min(45.0 + 12.0 * index, 81.0))
        unit = np.array([math.cos(angle), -math.sin(angle)])
        mark = _Mark("diameter", f"diameter-{index}", 2.0 * radius)
        tip = centres[-1] * scale + radius * scale * unit
        level = top - _LEADER_RISE - 6.0 * index
        knee = (
            tip
            + (float(tip[1]) - level) / math.tan(angle) * np.array([1.0, 0.0])
            + np.array([0.0, level - float(tip[1])])
        )
        mark.lines.append((float(tip[0]), float(tip[1]), float(knee[0]), level))
        mark.lines.append((float(knee[0]), level, float(knee[0]) + 3.0, level))
        mark.arrows.append((float(tip[0]), float(tip[1]), -float(unit[0]), -float(unit[1])))
        count = f"{len(centres)}× " if len(centres) > 1 else ""
        text = f"{count}{symbol}{dimension_text(2.0 * radius)}"
        mark.texts.append((float(knee[0]) + 4.0, level + 1.2, text, "start", False))
        mark.definition = ("diameter", centres[-1] * scale, radius * scale, tip)
        marks.append(mark)
    return marks


# --- dimensions per part (ISO 129-1) ----------------------------------------------------------------------


@dataclass
class _Plan:
    """Which view states which size of which part: per view, linear dimensions (part, "horizontal" or
    "vertical", symbol before the value) and diameter leaders (radius, local centres, symbol)."""

    linear: dict[str, list[tuple[int, str, str]]]
    leaders: dict[str, list[tuple[float, list[NDArray], str]]]
    radii: dict[str, list[tuple[float, list[tuple[NDArray, NDArray]]]]] = field(default_factory=dict)


def _plan_parts(
    views: list[_View], circles: list[Circle], parts_world: list[NDArray], meshes_ids: list[int], size: float
) -> _Plan:
    """Each part's sizes, each stated once on the sheet, in the view that shows it best.

    A part's sizes are its extents along the world axes. A circle of the part (a rim or a hole, or a sphere)
    gets a diameter leader in the end-on view where it is most visible; a diameter equal to the part's extents
    across its axis states those extents (a sphere's: all three). Extents left get a linear dimension in the
    aligned view that shows them, preferring the view where the most of the part's edges are visible and a
    view already dimensioning the part. Without an end-on view, a rim's diameter is a linear dimension "⌀d".
    """
    ortho = [view for view in views if view.across >= 0]
    linear: dict[str, list[tuple[int, str, str]]] = {view.name: [] for view in views}
    leader_groups: dict[str, list[tuple[float, list[NDArray], str]]] = {view.name: [] for view in views}
    radii: dict[str, list[tuple[float, list[tuple[NDArray, NDArray]]]]] = {view.name: [] for view in views}
    tolerance = 1e-6 * size
    done: list[tuple[int, NDArray]] = []  # (mesh id, extent) of the parts dimensioned
    for part, points in enumerate(parts_world):
        if points.shape[0] == 0:
            continue
        extent = points.max(axis=0) - points.min(axis=0)
        # a copy of a part already dimensioned (equal model geometry, placed alike): its diameters count in the "n×"
        # of the leaders, its sizes are the first copy's
        copy = any(m == meshes_ids[part] and np.abs(e - extent).max() <= 1e-9 * size for m, e in done)
        done.append((meshes_ids[part], extent))
        needed = {k for k in range(3) if extent[k] > 1e-9 * size}
        stated: set[tuple] = set()
        for circle in sorted((c for c in circles if c.mesh == part), key=lambda c: -c.radius):
            if circle.kind == "arc":
                _plan_radius(circle, ortho, radii, size)
                continue
            key = _circle_key(circle, size)
            if key in stated:
                continue
            stated.add(key)
            axis = key[2]
            across = {0, 1, 2} - {axis}
            covers = across if all(abs(2.0 * circle.radius - extent[k]) <= tolerance for k in across) else set()
            best = None  # (visible fraction, -order, view, entry)
            for order, view in enumerate(ortho):
                for entry, keys in enumerate(view.circle_keys):
                    if key in keys:
                        candidate = (view.circles[entry][2], -order, view, entry)
                        if best is None or candidate[:2] > best[:2]:
                            best = candidate
            symbol = "S⌀" if circle.kind == "sphere" else "⌀"
            if best is not None:
                view, entry = best[2], best[3]
                centre = view.circles[entry][0]
                groups = leader_groups[view.name]
                for k, (radius, centres, other) in enumerate(groups):
                    if other == symbol and abs(radius - circle.radius) <= 1e-6 * circle.radius:
                        groups[k] = (radius, [*centres, centre], other)
                        break
                else:
                    groups.append((circle.radius, [centre], symbol))
                needed -= covers
            elif covers and axis >= 0:  # no end-on view: the rim's diameter as a linear dimension
                k = min(covers & needed, default=None)
                view = _best_view(ortho, part, k, linear) if k is not None else None
                if view is not None:
                    linear[view.name].append((part, "horizontal" if view.across == k else "vertical", "⌀"))
                    needed -= covers
        for k in sorted(needed) if not copy else ():
            view = _best_view(ortho, part, k, linear)
            if view is not None:
                linear[view.name].append((part, "horizontal" if view.across == k else "vertical", ""))
    leaders = {}
    for name, groups in leader_groups.items():
        ordered = sorted(groups, key=lambda group: -group[0])
        leaders[name] = [(r, sorted(c, key=lambda p: (float(p[0]), float(p[1]))), sym) for r, c, sym in ordered]
    return _Plan(linear, leaders, radii)


def _plan_radius(circle: Circle, ortho: list[_View], radii: dict, size: float) -> None:
    """An arc's radius goes to the first aligned view that sees it end-on: (local centre, local middle point),
    with the other arcs of its radius there ("n× R")."""
    for view in ortho:
        direction = np.asarray(view.camera.frame.direction)
        if abs(float(circle.normal @ direction)) < math.cos(_END_ON_ANGLE) or circle.middle is None:
            continue
        ends = view.camera.project(np.stack([circle.centre, circle.middle]))[:, :2]
        local = _to_local(ends, view.model_per_pixel)
        groups = radii[view.name]
        for k, (radius, arcs) in enumerate(groups):
            if abs(radius - circle.radius) <= 1e-6 * max(radius, size * 1e-9):
                tolerance = 1e-6 * max(radius, size * 1e-9)
                if not any(np.abs(c - local[0]).max() <= tolerance for c, _ in arcs):  # one arc behind another
                    groups[k] = (radius, [*arcs, (local[0], local[1])])
                break
        else:
            groups.append((circle.radius, [(local[0], local[1])]))
        return


def _radius_leaders(view: _View, scale: float, groups: list) -> list[_Mark]:
    """One leader per radius of the view's arcs: arrowhead on the arc's middle, pointing at its centre, a line
    8 mm outward along the radius, a 3 mm shoulder and "R r" (or "n× R r")."""
    marks = []
    for index, (radius, arcs) in enumerate(sorted(groups, key=lambda group: -group[0])):
        centre, middle = (np.asarray(p) * scale for p in arcs[-1])
        outward = middle - centre
        outward = outward / max(float(np.linalg.norm(outward)), 1e-300)
        knee = middle + 8.0 * outward
        side = 1.0 if outward[0] >= 0.0 else -1.0
        mark = _Mark("radius", f"radius-{index}", radius)
        mark.lines.append((float(middle[0]), float(middle[1]), float(knee[0]), float(knee[1])))
        mark.lines.append((float(knee[0]), float(knee[1]), float(knee[0]) + 3.0 * side, float(knee[1])))
        mark.arrows.append((float(middle[0]), float(middle[1]), -float(outward[0]), -float(outward[1])))
        count = f"{len(arcs)}× " if len(arcs) > 1 else ""
        text = f"{count}R{dimension_text(radius)}"
        anchor = "start" if side > 0 else "end"
        mark.texts.append((float(knee[0]) + 4.0 * side, float(knee[1]) + 1.2, text, anchor, False))
        mark.definition = ("radius", centre, radius * scale, middle)
        marks.append(mark)
    return marks


def _best_view(ortho: list[_View], part: int, axis: int, linear: dict) -> _View | None:
    """The aligned view showing world `axis` where the part is most visible (a view that already dimensions
    the part counts half a view more; earlier views win ties)."""
    best, best_score = None, -math.inf
    for view in ortho:
        if axis not in (view.across, view.down) or view.parts[part].shape[0] == 0:
            continue
        score = view.shown[part] + (0.5 if any(entry[0] == part for entry in linear[view.name]) else 0.0)
        if score > best_score + 1e-12:
            best, best_score = view, score
    return best


def _part_dimensions(view: _View, scale: float, specs: list[tuple[int, str, str]]) -> list[_Mark]:
    """The linear dimensions `specs` of one view, stacked outward from the view at ``_DIMENSION_SPACING``
    (horizontal ones below it, else above; vertical ones right of it, else left): shorter ones first, each on
    the nearest level where it clashes with no dimension placed before (``_clash``: no extension line across
    another's dimension line, arrowheads or text, no overlap of those); a value that does not fit between its
    extension lines goes past one end of the line."""
    paper = view.local * scale
    (x0, y0), (x1, y1) = paper.min(axis=0), paper.max(axis=0)
    items = []
    for part, orientation, symbol in specs:
        axis = 0 if orientation == "horizontal" else 1
        local = view.parts[part]
        value = float(local[:, axis].max() - local[:, axis].min())
        items.append((value, orientation, part, symbol, local * scale))
    items.sort(key=lambda item: (item[0], item[1], item[2]))
    marks: list[_Mark] = []
    deepest: dict[tuple[str, float], int] = {}  # deepest level used per orientation and side
    for value, orientation, part, symbol, points in items:
        axis = 0 if orientation == "horizontal" else 1
        # (sign away from the view, first level's position): below / right first, then above / left
        sides = [(1.0, (y1 if axis == 0 else x1) + _DIMENSION_OFFSET),
                 (-1.0, (y0 if axis == 0 else x0) - _DIMENSION_OFFSET)]  # fmt: skip
        low, high = float(points[:, axis].min()), float(points[:, axis].max())
        tolerance = 1e-9 * max(abs(low), abs(high), 1.0)
        name = f"dimension-part{part}-{orientation}"
        chosen = None
        for level in range(len(items) + 1):
            for sign, base in sides:
                ends = []
                for end in (low, high):  # the foot: the part's outermost point toward that side, at the end
                    across = points[np.abs(points[:, axis] - end) <= tolerance, 1 - axis]
                    foot = float(across.max() if sign > 0 else across.min())
                    ends.append((end, foot) if axis == 0 else (foot, end))
                at = base + sign * level * _DIMENSION_SPACING
                for text_side in ("fit", "after", "before"):
                    mark = _linear(orientation, value, ends[0], ends[1], at, mark_name=name, prefix=symbol,
                                   text_side=text_side)  # fmt: skip
                    if mark is not None and not any(_clash(mark, other) for other in marks):
                        chosen = mark
                        deepest[(orientation, sign)] = max(deepest.get((orientation, sign), -1), level)
                        break
                if chosen is not None:
                    break
            if chosen is not None:
                break
        if chosen is None:  # crowded beyond resolving: the level past the deepest below / right (may clash)
            level = deepest.get((orientation, 1.0), -1) + 1
            deepest[(orientation, 1.0)] = level
            ends = []
            for end in (low, high):
                across = points[np.abs(points[:, axis] - end) <= tolerance, 1 - axis]
                ends.append((end, float(across.max())) if axis == 0 else (float(across.max()), end))
            chosen = _linear(orientation, value, ends[0], ends[1], sides[0][1] + level * _DIMENSION_SPACING,
                             mark_name=name, prefix=symbol)  # fmt: skip
        marks.append(chosen)
    return marks


def _body(mark: _Mark) -> list[NDArray]:
    """Rectangles (x0, y0, x1, y1) around a linear dimension's line with its arrowheads, and its text (computed
    once per mark)."""
    if mark.body is None:
        mark.body = _body_of(mark)
    return mark.body


def _body_of(mark: _Mark) -> list[NDArray]:
    x0, y0, x1, y1 = mark.lines[-1]
    line = np.array([min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1)])
    line += np.array([-1.0, -1.0, 1.0, 1.0]) * _ARROW_HALF_WIDTH
    return [line, _box([_Mark("text", "", texts=mark.texts)])]


def _clash(mark: _Mark, other: _Mark) -> bool:
    """Whether two linear dimensions clash: an extension line of one meets the other's dimension line,
    arrowheads or text, or those of both overlap (0.5 mm clearance)."""
    clear = 0.5
    for a, b in ((mark, other), (other, mark)):
        line, text = _body(b)
        for segment in a.lines[:-1]:
            # an extension line on the line of one of b's own (a shared extension line, as in chain
            # dimensioning) may run through b's arrowhead there, not through its text
            shared = any(_collinear(segment, own) for own in b.lines[:-1])
            for rectangle in (text,) if shared else (line, text):
                if _segment_meets(segment, rectangle + np.array([-clear, -clear, clear, clear])):
                    return True
    return any(_overlap(r + np.array([-clear, -clear, clear, clear]), q) for r in _body(mark) for q in _body(other))


def _collinear(a: tuple[float, float, float, float], b: tuple[float, float, float, float]) -> bool:
    """Whether two axis-parallel extension lines lie on one line (within 1e-9 mm)."""
    if a[0] == a[2] and b[0] == b[2]:
        return abs(a[0] - b[0]) <= 1e-9
    return a[1] == a[3] and b[1] == b[3] and abs(a[1] - b[1]) <= 1e-9


def _overlap(a: NDArray, b: NDArray) -> bool:
    return bool(a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3])


def _segment_meets(segment: tuple[float, float, float, float], box: NDArray) -> bool:
    """Whether the segment meets the open box (x0, y0, x1, y1): Liang–Barsky clipping."""
    x0, y0, x1, y1 = segment
    dx, dy = x1 - x0, y1 - y0
    t0, t1 = 0.0, 1.0
    for p, q in ((-dx, x0 - box[0]), (dx, box[2] - x0), (-dy, y0 - box[1]), (dy, box[3] - y0)):
        if p == 0.0:
            if q <= 0.0:
                return False
        else:
            t = q / p
            if p < 0.0:
                t0 = max(t0, t)
            else:
                t1 = min(t1, t)
    return t0 < t1


def _mark_svg(mark: _Mark, prefix: str, dx: float, dy: float) -> str:
    """A mark's ``<g>``: thin lines, filled arrowheads, text; shifted by (dx, dy) onto the sheet."""
    parts = []
    if mark.lines:
        d = " ".join(
            f"M{_number(x0 + dx)} {_number(y0 + dy)} L{_number(x1 + dx)} {_number(y1 + dy)}"
            for x0, y0, x1, y1 in mark.lines
        )
        parts.append(
            f'<path class="lines" d="{d}" fill="none" stroke="#000000" stroke-width="{_number(mark.line_width)}"/>'
        )
    for x, y, r in mark.circles:
        parts.append(
            f'<circle cx="{_number(x + dx)}" cy="{_number(y + dy)}" r="{_number(r)}" fill="none" stroke="#000000" '
            f'stroke-width="{_number(mark.line_width)}"/>'
        )
    if mark.arrows:
        heads = []
        for x, y, ux, uy in mark.arrows:
            # tip at (x, y), pointing along (ux, uy): base corners one arrow length back, ± half width across
            bx, by = x + dx - _ARROW_LENGTH * ux, y + dy - _ARROW_LENGTH * uy
            px, py = -uy * _ARROW_HALF_WIDTH, ux * _ARROW_HALF_WIDTH
            heads.append(
                f"M{_number(x + dx)} {_number(y + dy)} L{_number(bx + px)} {_number(by + py)} "
                f"L{_number(bx - px)} {_number(by - py)} Z"
            )
        parts.append(f'<path class="arrowheads" d="{" ".join(heads)}" fill="#000000" stroke="none"/>')
    for x, y, text, anchor, vertical in mark.texts:
        X, Y = _number(x + dx), _number(y + dy)
        turn = f' transform="rotate(-90 {X} {Y})"' if vertical else ""
        parts.append(
            f'<text x="{X}" y="{Y}" font-family="sans-serif" font-size="{_number(mark.text_size)}" '
            f'text-anchor="{anchor}"{turn}>{_escape(text)}</text>'
        )
    value = "" if math.isnan(mark.value) else f' data-value="{_number(mark.value)}"'
    return f'<g id="{prefix}{mark.name}" class="{mark.kind}"{value}>{"".join(parts)}</g>'


def _layout(
    views: list[_View], marks: dict[str, list[_Mark]], cells: dict[str, tuple[int, int]], scale: float,
    area: tuple[float, float, float, float],
) -> dict[str, tuple[float, float]] | None:  # fmt: skip
    """Sheet position of each view's projected target at `scale`, or None when the views do not fit `area`.

    Each column is as wide as its widest view (geometry, dimensions and label), each row as tall as its tallest;
    the space left over is shared evenly between the gaps (before, between and after the columns and rows).
    """
    columns: dict[int, list[float]] = {}
    rows: dict[int, list[float]] = {}
    for view in views:
        column, row = cells[view.name]
        paper = view.local * scale
        box = _box(marks[view.name])
        left = -min(float(paper[:, 0].min()), float(box[0]))
        right = max(float(paper[:, 0].max()), float(box[2]))
        up = -min(float(paper[:, 1].min()), float(box[1]))
        down = max(float(paper[:, 1].max()), float(box[3]))
        c = columns.setdefault(column, [0.0, 0.0])
        c[0], c[1] = max(c[0], left), max(c[1], right)
        r = rows.setdefault(row, [0.0, 0.0])
        r[0], r[1] = max(r[0], up), max(r[1], down)
    x0, y0, width, height = area
    used_width = sum(sum(columns[k]) for k in columns)
    used_height = sum(sum(rows[k]) for k in rows)
    gap_x = (width - used_width) / (len(columns) + 1)
    gap_y = (height - used_height) / (len(rows) + 1)
    if gap_x < _MIN_GAP or gap_y < _MIN_GAP:
        return None
    centre_x, centre_y = {}, {}
    x = x0 + gap_x
    for key in sorted(columns):
        left, right = columns[key]
        centre_x[key] = x + left
        x += left + right + gap_x
    y = y0 + gap_y
    for key in sorted(rows):
        up, down = rows[key]
        centre_y[key] = y + up
        y += up + down + gap_y
    return {view.name: (centre_x[cells[view.name][0]], centre_y[cells[view.name][1]]) for view in views}


def drawing_sheet(
    scene: Scene,
    views: Sequence[str] = ("front", "top", "right", "isometric"),
    *,
    scale: float | None = None,
    projection_angle: str = "third",
    paper: str | tuple[float, float] = "A3",
    orientation: str = "landscape",
    title: str = "",
    dimensions: str | bool = "parts",
    edges: str | Sequence[str] = "feature",
    crease_angle: float = DEFAULT_CREASE_ANGLE,
    hidden: str | None = "dashed",
    stroke_width: float = 0.5,
    shadows: bool = False,
    title_block: dict[str, Any] | None = None,
    path: str | os.PathLike | None = None,
) -> str:
    """An SVG engineering drawing of `scene`: multiview orthographic views, dimensions, title block, scale bar.

    Model units are millimetres; the SVG's user unit is one millimetre of paper (``width="420mm"`` with a
    matching viewBox), so a model length L parallel to a view plane measures exactly $L · scale$ in that
    orthographic view: paper $x = x0 + scale·x_view$, $y = y0 − scale·y_view$. The isometric view is the
    isometric *projection* (every axis foreshortened by √(2/3)), drawn at the same scale.

    Only what a drawing shows is drawn: boundaries, creases and silhouettes of the solids (faces adjacent by
    shared vertex positions; never an edge between coplanar triangles, see ``hidden_lines.COPLANAR_ANGLE``),
    visible solid, hidden dashed (thinner; the isometric view shows visible edges only). Circular features
    (``output/true_curves.py``: closed loops of creases or boundaries with at least 10 vertices, planar and
    round within 1e-6 of radius + model size, and spheres) are drawn as true curves, ``<circle>``,
    ``<ellipse>`` or elliptical-arc ``<path>`` in groups ``<view>-visible-curves`` / ``<view>-hidden-curves``,
    instead of their polygons. Each orthographic view carries centre lines (dashes, long ones at the ends)
    through the circles it sees end-on (a sphere's outline too) and along the axes of the cylinders it sees
    from the side, and the dimensions `dimensions` asks for (extension lines, dimension line, arrowheads, the
    model length in model units; leaders with ``⌀d``). The title block (ISO 7200) has the title, drawing number,
    sheet n/N, scale, the projection symbol of `projection_angle` (ISO 5456-2), units, date, author, general
    tolerances and paper size; a scale bar sits at the lower left.

    Parameters
    ----------
    scene : Scene
        At least one mesh with a face.
    views : sequence of str
        Names from ``SHEET_VIEWS``: "front", "rear", "right", "left", "top", "bottom", "isometric"; each once.
    scale : float, optional
        Paper length / model length (> 0). None: the largest of ``STANDARD_SCALES`` whose layout fits.
    projection_angle : {"third", "first"}
        Where the views go around the front view (see the module's table).
    paper : str or (width, height)
        A name from ``PAPER_SIZES`` (any case: "A4" … "A0", "Letter", "Tabloid") or a size in millimetres.
    orientation : {"landscape", "portrait"}
        For a named paper: long side horizontal or vertical. A (width, height) is used as given.
    title : str
        Drawing title for the title block.
    dimensions : {"parts", "overall"} or False
        "parts" (default): each part (placed mesh, a scene-graph node with geometry) gets its sizes, each
        stated once in the view that shows it best (``_plan_parts``): a diameter leader (``⌀d``, ``S⌀d`` for a
        sphere, $n× ⌀d$ for equal circles in one view) on each of its circles, linear dimensions for the
        extents the diameters do not state, stacked outward 7 mm apart so that no extension line crosses a
        dimension line or its text (radii "R r" on arcs). When the parts' dimensions crowd the paper at the
        four largest standard scales at which the views fit (or at the given `scale`), the sheet falls back to
        "overall" (the title block's ``data-dimensions`` says which). "overall": each view's overall width and
        height and a leader for every visible end-on diameter. False: none (centre lines stay). True is
        "overall".
    edges, crease_angle, hidden, stroke_width
        As in ``render_svg``; `stroke_width` (visible outlines) in paper millimetres.
    shadows : bool
        Sciagraphy: each view gets the exact shadow regions of the scene's directional and point lights
        (``svg_shadows.shadow_polygons``) as a hatched group ``<view>-shadows`` (``sun_45()`` is the convention).
    title_block : dict, optional
        Title block fields, keys from ``TITLE_BLOCK_FIELDS``: "title" (else `title`), "drawing_number", "sheet"
        ("n/N" or (n, N)), "date", "author", "tolerance" (default "ISO 2768-m"), "units" (default "mm"); text.
    path : str or PathLike, optional
        Also write the sheet: ``.svg``, ``.pdf``, ``.png`` (``save_svg``) or ``.dxf`` (``output/sheet_dxf.py``:
        layers, true CIRCLE / ARC / ELLIPSE, DIMENSION entities, in model units at full size; the ``dxf`` extra).

    Returns
    -------
    str
        The SVG document.

    Raises
    ------
    FrustumError
        If `scene` is not a Scene.
    OutputError
        For a bad title block field, a ``.dxf`` path without ezdxf (the message names the extra), a file that
        cannot be written,
        a scene with volumes (a drawing sheet shows meshes only), an empty scene, an unknown or repeated view,
        a bad scale, paper, orientation or projection angle, or views that do not fit on the paper at the given
        scale (the message says the largest scale that fits).

    References
    ----------
    [HB 10] "Orthogonal Projections", "Axonometric and Isometric Orthogonal Projections"; [seed] "Elevation
    and Plan View"; ISO 5455 (scales), ISO 128 (lines), ISO 129-1 (dimensions), ISO 5456-2 (first and third
    angle).
    """
    where = "drawing_sheet"
    width_line = _check_common(scene, stroke_width, hidden, where)
    names = _view_names(views, where)
    if projection_angle not in ("third", "first"):
        raise OutputError(
            f"{where}: projection_angle = {describe(projection_angle)} is unknown; expected 'third' or 'first'"
        )
    if orientation not in ORIENTATIONS:
        raise OutputError(
            f"{where}: orientation = {describe(orientation)} is unknown; expected 'landscape' or 'portrait'"
        )
    if dimensions is True or dimensions is False or isinstance(dimensions, np.bool_):
        mode = "overall" if dimensions else None
    elif isinstance(dimensions, str) and dimensions in DIMENSION_MODES:
        mode = dimensions
    else:
        raise OutputError(
            f"{where}: dimensions = {describe(dimensions)} is unknown; expected 'overall', 'parts' or False"
        )
    paper_width, paper_height = _paper(paper, orientation, where)
    fields = _title_fields(title_block, title, where)
    given_scale = None
    if scale is not None:
        given_scale = as_scalar(scale, "scale", where=where, error=OutputError)
        if not given_scale > 0.0:
            raise OutputError(f"{where}: scale = {given_scale!r} must be > 0; paper length / model length")
    if scene.volumes:  # a dimensioned line drawing has no form for a scalar field: say so rather than drop it
        count = len(scene.volumes)
        raise OutputError(
            f"{where}: scene has {count} volume{'s' * (count != 1)} (Scene.add_volume), which an engineering drawing "
            "cannot show; draw volumes with render_svg (an embedded image) or render, place volume.isosurface(level) "
            "as a mesh, or remove them from scene.volumes for a drawing of the meshes"
        )
    placed = _placed_meshes(scene)
    if not any(isinstance(item.mesh, Mesh) and item.mesh.face_count > 0 for item in placed):
        raise OutputError(f"{where}: scene has no faces to draw; add a mesh with at least one triangle")
    points_world = np.concatenate(
        [_points(item.mesh) @ item.world_from_model[:3, :3].T + item.world_from_model[:3, 3] for item in placed]
    )
    meshes = [(item.mesh, item.world_from_model) for item in placed]
    sheet_views, circles = _sheet_views(names, points_world, meshes, {"edges": edges, "crease_angle": crease_angle})
    size = max(float(np.linalg.norm(points_world.max(axis=0) - points_world.min(axis=0))), 1e-300)
    parts_world = [_points(mesh) @ m[:3, :3].T + m[:3, 3] for mesh, m in meshes]
    ids = [hash((_points(mesh).tobytes(), getattr(mesh, "faces", np.empty(0)).tobytes())) for mesh, _ in meshes]
    plan = _plan_parts(sheet_views, circles, parts_world, ids, size) if mode == "parts" else None
    cells = _THIRD_ANGLE if projection_angle == "third" else _FIRST_ANGLE
    # the drawing area: inside the border, above the title strip
    area = (_MARGIN, _MARGIN, paper_width - 2 * _MARGIN, paper_height - 2 * _MARGIN - _TITLE_HEIGHT)

    empty: dict[str, list[_Mark]] = {view.name: [] for view in sheet_views}

    def attempt(candidate: float, use: str | None) -> tuple[dict, dict] | None:
        if _layout(sheet_views, empty, cells, candidate, area) is None:  # the views alone do not fit
            return None
        marks = {view.name: _marks(view, candidate, use, plan) for view in sheet_views}
        places = _layout(sheet_views, marks, cells, candidate, area)
        return None if places is None else (marks, places)

    def search(use: str | None, tries: int | None) -> tuple[float, tuple[dict, dict]] | None:
        """The largest standard scale that fits with `use` dimensions (giving up after `tries` scales at which
        the views alone fit)."""
        for candidate in STANDARD_SCALES:
            if _layout(sheet_views, empty, cells, candidate, area) is None:
                continue
            fitted = attempt(candidate, use)
            if fitted is not None:
                return candidate, fitted
            if tries is not None:
                tries -= 1
                if tries == 0:
                    return None
        return None

    # each part's dimensions stack outward at a constant paper spacing: when they crowd the paper at every
    # scale that fits the views (many parts), the sheet falls back to each view's overall dimensions
    used = mode
    if given_scale is None:
        largest = search(mode, _PARTS_TRIES if mode == "parts" else None)
        if largest is None and mode == "parts":
            used, largest = "overall", search("overall", None)
        if largest is None:
            raise OutputError(
                f"{where}: scale = None found no standard scale down to {scale_label(STANDARD_SCALES[-1])} that "
                f"fits {_paper_text(paper)}; give a smaller scale or larger paper"
            )
        drawing_scale, (marks, places) = largest
    else:
        drawing_scale = given_scale
        fitted = attempt(drawing_scale, mode)
        if fitted is None and mode == "parts":
            used, fitted = "overall", attempt(drawing_scale, "overall")
        if fitted is None:
            largest = search(used, None)
            hint = f"the largest standard scale that fits is {scale_label(largest[0])}" if largest else "none fits"
            raise OutputError(
                f"{where}: scale = {drawing_scale!r} does not fit {len(names)} views on {_paper_text(paper)} "
                f"({hint}); give a smaller scale, fewer views or larger paper"
            )
        marks, places = fitted
    body = [
        f'<rect id="border" x="{_number(_MARGIN)}" y="{_number(_MARGIN)}" '
        f'width="{_number(paper_width - 2 * _MARGIN)}" height="{_number(paper_height - 2 * _MARGIN)}" '
        'fill="none" stroke="#000000" stroke-width="0.7"/>'
    ]
    for view in sheet_views:
        centre_x, centre_y = places[view.name]
        # a pictorial view shows visible edges only (hidden lines are for the orthographic views)
        view_hidden = None if view.name == "isometric" else hidden
        body.append(_view_group(view, placed, centre_x, centre_y, drawing_scale, view_hidden, width_line))
        if shadows:  # sciagraphy: the exact shadow polygons of the scene's lights in each view, hatched
            body.append(_view_shadows(scene, view, centre_x, centre_y, drawing_scale))
        body += [_mark_svg(mark, f"{view.name}-", centre_x, centre_y) for mark in marks[view.name]]
    paper_name = (
        paper.upper()
        if isinstance(paper, str) and paper.lower() != "letter" and paper.lower() != "tabloid"
        else (paper.capitalize() if isinstance(paper, str) else f"{_number(paper_width)} x {_number(paper_height)}")
    )
    title_marks = _title_block(paper_width, paper_height, fields, drawing_scale, projection_angle, paper_name)
    data = {**fields, "scale": scale_label(drawing_scale), "projection": projection_angle, "size": paper_name,
            "dimensions": str(used).lower()}  # fmt: skip
    attributes = "".join(f' data-{key.replace("_", "-")}="{_html_escape(value)}"' for key, value in data.items())
    body.append(f'<g id="title-block"{attributes}>{"".join(_mark_svg(mark, "", 0.0, 0.0) for mark in title_marks)}</g>')
    length, bar = _scale_bar(drawing_scale, paper_height)
    body.append(f'<g id="scale-bar" data-length="{_number(length)}">{_mark_svg(bar, "", 0.0, 0.0)}</g>')
    title_marks.append(bar)
    text = svg_document(paper_width, paper_height, body, units="mm")
    if path is not None:
        if str(path).lower().endswith(".dxf"):
            from frustum.output.sheet_dxf import save_sheet_dxf

            save_sheet_dxf(
                _SheetDrawing(paper_width, paper_height, drawing_scale, sheet_views, places, marks, title_marks,
                              hidden, fields["units"], placed),
                path,
            )  # fmt: skip
        else:
            save_svg(text, path)
    return text


@dataclass
class _SheetDrawing:
    """Everything a sheet draws, for writers other than SVG (``output/sheet_dxf.py``): paper size (mm), scale,
    the views and their sheet positions, their marks (view-local paper mm), the title block's marks (sheet mm),
    the hidden-line style, the model units and the placed meshes."""

    width: float
    height: float
    scale: float
    views: list[_View]
    places: dict[str, tuple[float, float]]
    marks: dict[str, list[_Mark]]
    title_marks: list[_Mark]
    hidden: str | None
    units: str
    placed: list


def _points(geometry: Mesh | Polyline) -> NDArray[np.float64]:
    return geometry.vertices if isinstance(geometry, Mesh) else geometry.points


def _view_group(
    view: _View, placed: list, centre_x: float, centre_y: float, scale: float, hidden: str | None,
    stroke_width: float,
) -> str:  # fmt: skip
    factor = scale * view.model_per_pixel

    def to_paper(points: NDArray) -> NDArray:
        # window (y up) → paper mm (y down): x_p = c_x + scale·x_view, y_p = c_y − scale·y_view
        local = _to_local(points, factor)
        return np.column_stack([centre_x + local[:, 0], centre_y + local[:, 1]])

    groups = _drawing_groups(view.lines, placed, to_paper, stroke_width, hidden, False, prefix=f"{view.name}-")
    groups += _curve_groups(view, to_paper, stroke_width, hidden)
    return (
        f'<g id="view-{view.name}" data-scale="{_number(scale)}" '
        f'data-centre="{_number(centre_x)} {_number(centre_y)}">{"".join(groups)}</g>'
    )


def _view_shadows(scene: Scene, view: _View, centre_x: float, centre_y: float, scale: float) -> str:
    """The view's ``<g id="<view>-shadows">``: hatched shadow paths (``svg_shadows.shadow_polygons``) on paper."""
    from frustum.output.svg_shadows import shadow_polygons

    factor = scale * view.model_per_pixel
    paths = []
    for polygon in shadow_polygons(scene, view.camera):
        loops = []
        for loop in polygon.loops:
            local = _to_local(loop, factor)
            loops.append("M " + " L ".join(f"{_number(centre_x + x)} {_number(centre_y + y)}" for x, y in local) + " Z")
        paths.append(f'<path d="{" ".join(loops)}" class="{polygon.kind}"/>')
    return (
        f'<g id="{view.name}-shadows" fill="url(#shadow-hatch)" fill-rule="evenodd" stroke="#000000" '
        f'stroke-width="0.18"><defs><pattern id="shadow-hatch" patternUnits="userSpaceOnUse" width="1.5" '
        'height="1.5" patternTransform="rotate(45)"><line x1="0" y1="0" x2="0" y2="1.5" stroke="#000000" '
        f'stroke-width="0.18"/></pattern></defs>{"".join(paths)}</g>'
    )


def _curve_groups(view: _View, to_paper: Any, stroke_width: float, hidden: str | None) -> list[str]:
    """The view's true curves: groups ``<view>-hidden-curves`` (styled as the hidden lines) and
    ``<view>-visible-curves`` of ``<circle>``, ``<ellipse>`` and elliptical-arc ``<path>`` elements."""
    groups = []
    if hidden is not None and view.hidden_arcs:
        thin = _number(0.7 * stroke_width)
        if hidden == "dashed":
            dash = f"{_number(4 * stroke_width)} {_number(2.5 * stroke_width)}"
            style = f'stroke="#000000" stroke-width="{thin}" stroke-dasharray="{dash}"'
        else:
            style = f'stroke="{_HIDDEN_GRAY}" stroke-width="{thin}"'
        elements = svg_arc_elements([arc.mapped(to_paper) for arc in view.hidden_arcs])
        groups.append(
            f'<g id="{view.name}-hidden-curves" fill="none" {style} stroke-linecap="butt">{"".join(elements)}</g>'
        )
    if view.visible_arcs:
        elements = svg_arc_elements([arc.mapped(to_paper) for arc in view.visible_arcs])
        groups.append(
            f'<g id="{view.name}-visible-curves" fill="none" stroke-linecap="round" stroke-linejoin="round" '
            f'stroke="#000000" stroke-width="{_number(stroke_width)}">{"".join(elements)}</g>'
        )
    return groups


def _view_names(views: Any, where: str) -> list[str]:
    names = [views] if isinstance(views, str) else list(views) if isinstance(views, Sequence) else None
    if not names:
        raise OutputError(f"{where}: views = {describe(views)} is empty or not a sequence; name at least one view")
    for name in names:
        if name not in SHEET_VIEWS:
            raise OutputError(f"{where}: views has {describe(name)}, which is unknown; expected some of {SHEET_VIEWS}")
        if name != "isometric":
            multiview(name)
    if len(set(names)) != len(names):
        raise OutputError(f"{where}: views = {describe(names)} names a view twice; give each view once")
    return names


def _paper(paper: Any, orientation: str, where: str) -> tuple[float, float]:
    if isinstance(paper, str):
        sizes = {name.lower(): size for name, size in PAPER_SIZES.items()}
        if paper.lower() not in sizes:
            raise OutputError(f"{where}: paper = {paper!r} is unknown; expected one of {sorted(PAPER_SIZES)}")
        long, short = sizes[paper.lower()]
        return (long, short) if orientation == "landscape" else (short, long)
    try:
        size = np.asarray(paper, dtype=np.float64)
    except (TypeError, ValueError):
        size = np.zeros(0)
    if (
        size.shape != (2,)
        or not np.isfinite(size).all()
        or not size[0] > 2 * _MARGIN + _TITLE_WIDTH
        or not size[1] > 2 * _MARGIN + _TITLE_HEIGHT
    ):
        raise OutputError(
            f"{where}: paper = {describe(paper)} is not a paper name or a (width, height) in mm larger than "
            f"({_number(2 * _MARGIN + _TITLE_WIDTH)}, {_number(2 * _MARGIN + _TITLE_HEIGHT)}); use e.g. 'A3' or "
            "(420, 297)"
        )
    return float(size[0]), float(size[1])


def _paper_text(paper: Any) -> str:
    return paper if isinstance(paper, str) else f"{describe(paper)} mm paper"


def _text(x: float, y: float, text: str, size: float, anchor: str = "start") -> str:
    return (
        f'<text x="{_number(x)}" y="{_number(y)}" font-family="sans-serif" font-size="{_number(size)}" '
        f'text-anchor="{anchor}">{_escape(text)}</text>'
    )


TITLE_BLOCK_FIELDS = ("title", "drawing_number", "sheet", "date", "author", "tolerance", "units")
"""Keys of ``drawing_sheet(title_block=...)`` (ISO 7200 data fields): the drawing's title, its identification
number, sheet "n/N", date of issue, creator, general tolerance note and model units."""
_TITLE_DEFAULTS = {"drawing_number": "", "sheet": "1/1", "date": "", "author": "", "tolerance": "ISO 2768-m",
                   "units": "mm"}  # fmt: skip
# title block cells: (key, label, x, y, width, height) in mm from the block's top left corner; 180 x 32 mm
_TITLE_CELLS = (
    ("title", "TITLE", 0.0, 0.0, 120.0, 12.0), ("drawing_number", "DRAWING NO.", 120.0, 0.0, 60.0, 12.0),
    ("author", "DRAWN BY", 0.0, 12.0, 50.0, 10.0), ("date", "DATE", 50.0, 12.0, 35.0, 10.0),
    ("scale", "SCALE", 85.0, 12.0, 35.0, 10.0), ("sheet", "SHEET", 120.0, 12.0, 30.0, 10.0),
    ("units", "UNITS", 150.0, 12.0, 30.0, 10.0), ("tolerance", "GENERAL TOLERANCES", 0.0, 22.0, 85.0, 10.0),
    ("projection", "", 85.0, 22.0, 65.0, 10.0), ("size", "SIZE", 150.0, 22.0, 30.0, 10.0),
)  # fmt: skip
_TITLE_LABEL = 1.8  # label lettering, mm


def _title_fields(title_block: Any, title: str, where: str) -> dict[str, str]:
    """The title block's field texts from ``title_block`` (a mapping of ``TITLE_BLOCK_FIELDS``) and `title`."""
    if title_block is None:
        title_block = {}
    if not isinstance(title_block, dict):
        raise OutputError(
            f"{where}: title_block = {describe(title_block)} is not a mapping; give a dict of {TITLE_BLOCK_FIELDS}"
        )
    unknown = sorted(str(key) for key in title_block if key not in TITLE_BLOCK_FIELDS)
    if unknown:
        raise OutputError(
            f"{where}: title_block has {', '.join(map(repr, unknown))}, which is unknown; expected keys from "
            f"{TITLE_BLOCK_FIELDS}"
        )
    fields = {**_TITLE_DEFAULTS, "title": title, **title_block}
    sheet = fields["sheet"]
    if isinstance(sheet, tuple | list):
        if len(sheet) != 2 or not all(isinstance(k, int) and not isinstance(k, bool) for k in sheet):
            raise OutputError(
                f"{where}: title_block sheet = {describe(sheet)} is not (n, N); give e.g. (1, 2) or '1/2'"
            )
        number, count = sheet
        if not 1 <= number <= count:
            raise OutputError(f"{where}: title_block sheet = ({number}, {count}) needs 1 <= n <= N; give e.g. (1, 2)")
        fields["sheet"] = f"{number}/{count}"
    for key, value in fields.items():
        if not isinstance(value, str):
            raise OutputError(f"{where}: title_block {key} = {describe(value)} is not text; give a string")
    return fields


def _title_block(paper_width: float, paper_height: float, fields: dict[str, str], scale: float, angle: str,
                 paper: str) -> list[_Mark]:  # fmt: skip
    """The ISO 7200 title block at the lower right corner of the frame, as marks (sheet coordinates): frame and
    cell lines, each cell's label (small) and value, and the projection symbol of `angle` with its name."""
    x1, y1 = paper_width - _MARGIN, paper_height - _MARGIN
    x0, y0 = x1 - _TITLE_WIDTH, y1 - 32.0
    frame = _Mark("title", "title-block-lines", line_width=0.5)
    frame.lines += [(x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)]
    labels = _Mark("title", "title-block-labels", text_size=_TITLE_LABEL)
    values = _Mark("title", "title-block-values")
    title = _Mark("title", "title-block-title", text_size=5.0)
    cells = _Mark("title", "title-block-cells", line_width=0.35)
    texts = {**fields, "scale": scale_label(scale), "size": paper}
    for key, label, dx, dy, _width, height in _TITLE_CELLS:
        cx, cy = x0 + dx, y0 + dy
        if dx > 0.0:  # the cell's left side
            cells.lines.append((cx, cy, cx, cy + height))
        if label:
            labels.texts.append((cx + 1.5, cy + 1.5 + _TITLE_LABEL, label, "start", False))
        if key == "projection":
            continue
        text = texts[key]
        target = title if key == "title" else values
        target.texts.append((cx + 1.5, cy + height - 2.0, text or "—", "start", False))
    for row in (12.0, 22.0):  # rows between the cells
        cells.lines.append((x0, y0 + row, x1, y0 + row))
    symbol = _projection_symbol(x0 + 85.0 + 2.0, y0 + 22.0 + 1.5, angle)
    symbol.texts.append((x0 + 85.0 + 27.0, y0 + 22.0 + 6.2, f"{angle.upper()} ANGLE PROJECTION", "start", False))
    symbol.text_size = 2.5
    return [frame, cells, labels, values, title, symbol]


def _projection_symbol(x: float, y: float, angle: str) -> _Mark:
    """ISO 5456-2's symbol of the projection method, 7 mm tall, its top left at (x, y): a truncated cone with
    its small end to the left (front view: a trapezoid) and its view from the left (two circles, both rims
    seen). First angle puts that view on the far side, right of the trapezoid (next to the large end); third
    angle where it was seen from, left of it (next to the small end). Centre lines through both."""
    mark = _Mark("symbol", f"projection-symbol-{angle}", line_width=0.35)
    big, small, length, gap = 3.5, 1.75, 7.0, 4.0  # radii, the cone's length, space between the views, mm
    circles_x = x + big if angle == "third" else x + length + gap + big
    cone_x = x + 2 * big + gap if angle == "third" else x
    cy = y + big
    mark.lines += [
        (cone_x, cy - small, cone_x + length, cy - big), (cone_x + length, cy - big, cone_x + length, cy + big),
        (cone_x + length, cy + big, cone_x, cy + small), (cone_x, cy + small, cone_x, cy - small),
    ]  # fmt: skip
    mark.circles += [(circles_x, cy, big), (circles_x, cy, small)]
    mark.definition = ("symbol", circles_x, cone_x)
    return mark


def _scale_bar(scale: float, paper_height: float) -> tuple[float, _Mark]:
    """A bar of a round model length (1, 2 or 5 × 10^k mm) between 20 and 50 mm of paper, with ticks: the
    length and the bar as a mark (sheet coordinates)."""
    target = 40.0 / scale  # model mm that make about 40 mm of paper
    exponent = math.floor(math.log10(target))
    length = max(
        (m * 10.0**exponent for m in (1.0, 2.0, 5.0, 10.0) if m * 10.0**exponent * scale <= 50.0),
        default=10.0**exponent,
    )
    x0, y = _MARGIN + 8.0, paper_height - _MARGIN - 12.0
    bar = length * scale
    mark = _Mark("title", "scale-bar-line", line_width=0.35, text_size=3.0)
    mark.lines.append((x0, y, x0 + bar, y))
    mark.lines += [(x0 + bar * k / 4, y - 2.0, x0 + bar * k / 4, y + 2.0) for k in range(5)]
    mark.texts += [(x0, y + 6.0, "0", "middle", False), (x0 + bar, y + 6.0, f"{_number(length)} mm", "middle", False)]
    return length, mark
