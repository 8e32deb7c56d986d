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

References
----------
[HB 10] "Orthogonal Projections" (front, side and rear elevations; plan view), "Axonometric and Isometric
Orthogonal Projections"; [seed] "Elevation and Plan View", "engineering and architectural drawings".
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import as_scalar, describe
from frustum.camera import Camera, ViewFrame
from frustum.errors import OutputError
from frustum.geometry import Mesh, Polyline
from frustum.hidden_lines import (
    DEFAULT_CREASE_ANGLE,
    EDGE_BOUNDARY,
    EDGE_CREASE,
    HiddenLines,
    classify_edges,
    remove_hidden_lines,
    welded_adjacency,
)
from frustum.output.svg import _check_common, _drawing_groups, _escape, _number, _placed_meshes, svg_document
from frustum.projection import ISOMETRIC_ROTATION_X, MULTIVIEWS, Axonometric, Orthographic, multiview
from frustum.scene import Scene

__all__ = [
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
SHEET_VIEWS = (*MULTIVIEWS, "isometric")
"""View names ``drawing_sheet`` accepts."""

# grid cell of each view relative to the front view, (column, row), row grows downward
_THIRD_ANGLE = {"front": (0, 0), "top": (0, -1), "bottom": (0, 1), "right": (1, 0), "left": (-1, 0),
                "rear": (2, 0), "isometric": (1, -1)}  # fmt: skip
_FIRST_ANGLE = {"front": (0, 0), "top": (0, 1), "bottom": (0, -1), "right": (-1, 0), "left": (1, 0),
                "rear": (2, 0), "isometric": (1, 1)}  # fmt: skip
_MARGIN = 10.0  # border to paper edge, mm
_TITLE_HEIGHT = 36.0  # title block strip at the bottom of the frame, mm
_TITLE_WIDTH = 170.0
_MIN_GAP = 8.0  # least space between views (and between views and the border), mm
_PIXELS = 1000  # window size of the view cameras; window → paper is x_p = scale · (h / _PIXELS) · x_w + ...
# dimensioning (ISO 129-1): thin lines, closed filled arrowheads, 3.5 mm lettering above the dimension line
_THIN = 0.25  # dimension, extension, leader and centre lines, mm
_DIMENSION_OFFSET = 10.0  # view outline to dimension line, mm
_EXTENSION_GAP = 1.0  # extension lines start this far from the feature ...
_EXTENSION_BEYOND = 2.0  # ... and end this far past the dimension line, mm
_ARROW_LENGTH, _ARROW_HALF_WIDTH = 3.0, 0.55  # arrowhead, mm (about 20 degrees included)
_LETTER = 3.5  # dimension and label text height, mm
_LEADER_RISE = 5.0  # a diameter leader's shoulder sits this far above the view, mm; more leaders stack 6 mm apart
_LABEL_DROP = 7.0  # view label baseline below everything else of the view, mm
# circles: closed loops of creases / boundaries with at least this many vertices, planar and round within
# these fractions of the radius (a tessellated circle's vertices lie on it, up to round-off)
_CIRCLE_MIN_VERTICES = 10
_CIRCLE_TOLERANCE = 1e-6
# an end-on circle's plane normal lies within this angle (radians) of the line of sight
_END_ON_ANGLE = 1e-6


@dataclass(frozen=True)
class _Circle:
    centre: NDArray[np.float64]  # world
    normal: NDArray[np.float64]  # unit, world
    radius: float
    sides: int  # vertices of the polygon


@dataclass
class _View:
    name: str
    camera: Camera
    model_per_pixel: float  # model length (mm) per window pixel
    lines: HiddenLines
    local: NDArray[np.float64]  # (N, 2) every model vertex in view-local model mm: x right, y down, origin = target
    circles: list[tuple[NDArray[np.float64], float, float]]  # end-on circles: local centre, radius, visible part
    axes: list[tuple[NDArray[np.float64], NDArray[np.float64]]]  # cylinder axes seen side-on: local ends


@dataclass
class _Mark:
    """One annotation in view-local paper mm (x right, y down, origin = the view's projected target)."""

    kind: str  # "dimension", "diameter", "centre" (centre lines), "label"
    name: str  # id suffix
    value: float = math.nan  # the model length a dimension states
    lines: list[tuple[float, float, float, float]] = field(default_factory=list)
    arrows: list[tuple[float, float, float, float]] = field(default_factory=list)  # tip x, y, unit direction
    texts: list[tuple[float, float, str, str, bool]] = field(default_factory=list)  # x, y, text, anchor, vertical


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


def _circles(meshes: list[tuple[Mesh | Polyline, NDArray]]) -> list[_Circle]:
    """Circular edge loops of the meshes (world): closed chains of creases and boundaries, planar and round.

    A loop is a connected set of feature edges in which every vertex has two edges; it is a circle when it has
    at least ``_CIRCLE_MIN_VERTICES`` vertices, all within ``_CIRCLE_TOLERANCE``·r of one plane and of one
    distance r from their centroid (a regular polygon's centroid is the circle's centre).
    """
    found = []
    for mesh, world_from_model in meshes:
        if not isinstance(mesh, Mesh) or mesh.face_count == 0:
            continue
        points = mesh.vertices @ world_from_model[:3, :3].T + world_from_model[:3, 3]
        adjacency = welded_adjacency(mesh)
        kinds = classify_edges(adjacency, points, np.asarray(mesh.faces), None, DEFAULT_CREASE_ANGLE)
        edges = adjacency.edges[(kinds & (EDGE_BOUNDARY | EDGE_CREASE)) != 0]
        if edges.shape[0] < _CIRCLE_MIN_VERTICES:
            continue
        # connected components of the edge graph (union–find on the few feature vertices)
        vertices, local = np.unique(edges, return_inverse=True)
        local = local.reshape(-1, 2)
        parent = np.arange(vertices.size)
        changed = True
        while changed:
            low = np.minimum(parent[local[:, 0]], parent[local[:, 1]])
            changed = bool((parent[local[:, 0]] != low).any() or (parent[local[:, 1]] != low).any())
            np.minimum.at(parent, local[:, 0], low)
            np.minimum.at(parent, local[:, 1], low)
            parent = parent[parent]
        degree = np.bincount(local.reshape(-1), minlength=vertices.size)
        for root in np.unique(parent):
            members = np.flatnonzero(parent == root)
            if members.size < _CIRCLE_MIN_VERTICES or (degree[members] != 2).any():
                continue
            ring = points[vertices[members]]
            centre = ring.mean(axis=0)
            offsets = ring - centre
            normal = np.linalg.svd(offsets)[2][2]
            radii = np.linalg.norm(offsets, axis=1)
            radius = float(radii.mean())
            if not radius > 0.0:
                continue
            if np.abs(offsets @ normal).max() > _CIRCLE_TOLERANCE * radius:
                continue
            if np.abs(radii - radius).max() > _CIRCLE_TOLERANCE * radius:
                continue
            found.append(_Circle(centre, normal, radius, int(members.size)))
    return found


def _sheet_views(names: Sequence[str], points_world: NDArray, meshes: list, options: dict) -> list[_View]:
    low, high = points_world.min(axis=0), points_world.max(axis=0)
    target = (low + high) / 2.0
    radius = max(float(np.linalg.norm(high - low)) / 2.0, 1e-9)
    circles = _circles(meshes)
    views = []
    for name in names:
        camera = _view_camera(name, target, radius)
        mm_per_pixel = 2.2 * radius / _PIXELS
        lines = remove_hidden_lines(meshes, camera, **options)
        local = _to_local(camera.project(points_world)[:, :2], mm_per_pixel)
        end_on = [] if name == "isometric" else _end_on(circles, camera, lines, mm_per_pixel)
        axes = [] if name == "isometric" else _side_on_axes(circles, camera, mm_per_pixel)
        views.append(_View(name, camera, mm_per_pixel, lines, local, end_on, axes))
    return views


def _to_local(window: NDArray, factor: float) -> NDArray:
    """Window (x, y up) → view-local (x right, y down) around the window centre, times `factor`."""
    half = _PIXELS / 2.0
    return np.column_stack([(window[:, 0] - half) * factor, -(window[:, 1] - half) * factor])


def _side_on_axes(circles: list[_Circle], camera: Camera, mm_per_pixel: float) -> list:
    """Axes of the cylinders `camera` sees from the side, as view-local segments, collinear overlaps merged.

    A cylinder (or a coaxial hole) shows as two circles of equal radius whose centres lie on their common normal;
    its axis is drawn where it is perpendicular to the line of sight (within 1e-6 rad).
    """
    direction = np.asarray(camera.frame.direction)
    found: list[tuple[NDArray, NDArray]] = []
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
            if (abs(float(unit[0] * along[1] - unit[1] * along[0])) > 1e-9  # 2D cross products: not parallel,
                    or abs(float(offset[0] * along[1] - offset[1] * along[0])) > gap):  # or not on one line
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


def _end_on(circles: list[_Circle], camera: Camera, lines: HiddenLines, mm_per_pixel: float) -> list:
    """The circles seen end-on by `camera`, once per projected centre and radius: (local centre, radius,
    visible fraction of the drawn circle)."""
    direction = np.asarray(camera.frame.direction)
    seen: list[tuple[NDArray, float, float]] = []
    for circle in circles:
        if abs(float(circle.normal @ direction)) < math.cos(_END_ON_ANGLE):
            continue
        centre = _to_local(camera.project(circle.centre[None, :])[:, :2], mm_per_pixel)[0]
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
        visible = lengths[0] / drawn if drawn > 0.0 else 0.0
        tolerance = 1e-6 * circle.radius
        same = next(
            (k for k, (c, r, _) in enumerate(seen)
             if np.abs(c - centre).max() <= tolerance and abs(r - circle.radius) <= tolerance),
            None,
        )  # fmt: skip
        if same is None:
            seen.append((centre, circle.radius, visible))
        elif visible > seen[same][2]:
            seen[same] = (centre, circle.radius, visible)
    return seen


# --- annotations in view-local paper millimetres ----------------------------------------------------------


def _marks(view: _View, scale: float, dimensions: bool) -> list[_Mark]:
    """Centre lines of end-on circles, dimensions (overall extents, diameters) and the label of one view."""
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
            centres.lines.append((float(start[0]), float(start[1]), float(end[0]), float(end[1])))
        marks.append(centres)
    if dimensions and orthographic:
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


def _linear(name: str, value: float, a: tuple[float, float], b: tuple[float, float], at: float) -> _Mark:
    """A linear dimension of model length `value` between feature points `a` and `b` (paper): extension lines
    to a dimension line at `at` (y for "horizontal", x for "vertical"), arrowheads at both ends (outside,
    pointing in, when they do not fit between), the value above the line (vertical: reading from the right)."""
    mark = _Mark("dimension", f"dimension-{name}", value)
    horizontal = name == "horizontal"
    axis = 0 if horizontal else 1
    low, high = a[axis], b[axis]
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
    text = dimension_text(value)
    mark.texts.append(
        (middle, at - 1.0, text, "middle", False) if horizontal else (at - 1.0, middle, text, "middle", True)
    )
    return mark


def _centre_lines(mark: _Mark, centre: NDArray, radius: float) -> None:
    reach = radius + 2.0
    cx, cy = float(centre[0]), float(centre[1])
    mark.lines.append((cx - reach, cy, cx + reach, cy))
    mark.lines.append((cx, cy - reach, cx, cy + reach))


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


def _diameters(view: _View, scale: float, top: float) -> list[_Mark]:
    """One leader per diameter: from the circle at 45° up and right (arrowhead on the circle, pointing at the
    centre) to a shoulder above the view, with "⌀d" (or "n× ⌀d" for n equal circles)."""
    marks = []
    unit = np.array([math.sqrt(0.5), -math.sqrt(0.5)])
    for index, (radius, centres) in enumerate(_diameter_groups(view)):
        mark = _Mark("diameter", f"diameter-{index}", 2.0 * radius)
        tip = centres[-1] * scale + radius * scale * unit
        level = top - _LEADER_RISE - 6.0 * index
        knee = tip + (float(tip[1]) - level) * np.array([1.0, -1.0])
        mark.lines.append((float(tip[0]), float(tip[1]), float(knee[0]), level))
        mark.lines.append((float(knee[0]), level, float(knee[0]) + 3.0, level))
        mark.arrows.append((float(tip[0]), float(tip[1]), -float(unit[0]), -float(unit[1])))
        count = f"{len(centres)}× " if len(centres) > 1 else ""
        text = f"{count}⌀{dimension_text(2.0 * radius)}"
        mark.texts.append((float(knee[0]) + 4.0, level + 1.2, text, "start", False))
        marks.append(mark)
    return marks


def _mark_svg(mark: _Mark, prefix: str, dx: float, dy: float) -> str:
    """A mark's ``<g>``: thin lines, filled arrowheads, text; shifted by (dx, dy) onto the sheet."""
    parts = []
    if mark.lines:
        d = " ".join(
            f"M{_number(x0 + dx)} {_number(y0 + dy)} L{_number(x1 + dx)} {_number(y1 + dy)}"
            for x0, y0, x1, y1 in mark.lines
        )
        dash = ' stroke-dasharray="6 1 1 1"' if mark.kind == "centre" else ""
        parts.append(
            f'<path class="lines" d="{d}" fill="none" stroke="#000000" stroke-width="{_number(_THIN)}"{dash}/>'
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
            f'<text x="{X}" y="{Y}" font-family="sans-serif" font-size="{_number(_LETTER)}" '
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
    dimensions: bool = True,
    edges: str | Sequence[str] = "feature",
    crease_angle: float = DEFAULT_CREASE_ANGLE,
    hidden: str | None = "dashed",
    stroke_width: float = 0.5,
    shadows: bool = False,
) -> str:
    """An SVG engineering drawing of `scene`: multiview orthographic views, dimensions, title block, scale bar.

    Model units are millimetres; the SVG's user unit is one millimetre of paper (``width="420mm"`` with a
    matching viewBox), so a model length L parallel to a view plane measures exactly ``L · scale`` in that
    orthographic view: paper ``x = x0 + scale·x_view``, ``y = y0 − scale·y_view``. The isometric view is the
    isometric *projection* (every axis foreshortened by √(2/3)), drawn at the same scale.

    Only what a drawing shows is drawn: boundaries, creases and silhouettes of the solids (faces adjacent by
    shared vertex positions; never an edge between coplanar triangles, see ``hidden_lines.COPLANAR_ANGLE``),
    visible solid, hidden dashed (thinner; the isometric view shows visible edges only). Each orthographic
    view carries its overall horizontal and vertical dimension (extension lines, dimension line, arrowheads,
    the model length in mm), centre lines through the circles it sees end-on and along the axes of the
    cylinders it sees from the side, and a leader with the diameter of each visible end-on circle (``n× ⌀d``
    for n equal circles). Circles are closed loops of creases (over the default 30°) or boundaries with at
    least 10 vertices, planar and round within 1e-6 of their radius.

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
    dimensions : bool
        False: no dimensions or diameter leaders (centre lines stay).
    edges, crease_angle, hidden, stroke_width
        As in ``render_svg``; `stroke_width` (visible outlines) in paper millimetres.

    Returns
    -------
    str
        The SVG document.

    Raises
    ------
    FrustumError
        If `scene` is not a Scene.
    OutputError
        For a scene with volumes (a drawing sheet shows meshes only), an empty scene, an unknown or repeated view,
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
    if not isinstance(dimensions, bool | np.bool_):
        raise OutputError(f"{where}: dimensions = {describe(dimensions)} is not a bool; give True or False")
    paper_width, paper_height = _paper(paper, orientation, where)
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
    sheet_views = _sheet_views(names, points_world, meshes, {"edges": edges, "crease_angle": crease_angle})
    cells = _THIRD_ANGLE if projection_angle == "third" else _FIRST_ANGLE
    # the drawing area: inside the border, above the title strip
    area = (_MARGIN, _MARGIN, paper_width - 2 * _MARGIN, paper_height - 2 * _MARGIN - _TITLE_HEIGHT)

    def attempt(candidate: float) -> tuple[dict, dict] | None:
        marks = {view.name: _marks(view, candidate, dimensions) for view in sheet_views}
        places = _layout(sheet_views, marks, cells, candidate, area)
        return None if places is None else (marks, places)

    largest = next(((s, fitted) for s in STANDARD_SCALES if (fitted := attempt(s)) is not None), None)
    if given_scale is None:
        if largest is None:
            raise OutputError(
                f"{where}: scale = None found no standard scale down to {scale_label(STANDARD_SCALES[-1])} that "
                f"fits {_paper_text(paper)}; give a smaller scale or larger paper"
            )
        drawing_scale, (marks, places) = largest
    else:
        drawing_scale = given_scale
        fitted = attempt(drawing_scale)
        if fitted is None:
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
    body.append(_title_block(paper_width, paper_height, title, drawing_scale, projection_angle))
    body.append(_scale_bar(drawing_scale, paper_height))
    return svg_document(paper_width, paper_height, body, units="mm")


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


def _title_block(paper_width: float, paper_height: float, title: str, scale: float, angle: str) -> str:
    x1, y1 = paper_width - _MARGIN, paper_height - _MARGIN
    x0, y0 = x1 - _TITLE_WIDTH, y1 - _TITLE_HEIGHT + 4.0
    middle = (y0 + y1) / 2.0
    column = x0 + 110.0
    parts = [
        f'<rect x="{_number(x0)}" y="{_number(y0)}" width="{_number(_TITLE_WIDTH)}" '
        f'height="{_number(y1 - y0)}" fill="none" stroke="#000000" stroke-width="0.5"/>',
        f'<path d="M{_number(x0)} {_number(middle)} L{_number(x1)} {_number(middle)} '
        f'M{_number(column)} {_number(middle)} L{_number(column)} {_number(y1)}" '
        'fill="none" stroke="#000000" stroke-width="0.35"/>',
        _text(x0 + 3.0, middle - 5.0, title or "UNTITLED", 6.0),
        _text(x0 + 3.0, y1 - 5.0, f"{angle.upper()} ANGLE PROJECTION   UNITS: mm", 3.5),
        _text(column + 3.0, y1 - 5.0, f"SCALE {scale_label(scale)}", 3.5),
    ]
    return f'<g id="title-block">{"".join(parts)}</g>'


def _scale_bar(scale: float, paper_height: float) -> str:
    """A bar of a round model length (1, 2 or 5 × 10^k mm) between 20 and 50 mm of paper, with ticks."""
    target = 40.0 / scale  # model mm that make about 40 mm of paper
    exponent = math.floor(math.log10(target))
    length = max(
        (m * 10.0**exponent for m in (1.0, 2.0, 5.0, 10.0) if m * 10.0**exponent * scale <= 50.0),
        default=10.0**exponent,
    )
    x0, y = _MARGIN + 8.0, paper_height - _MARGIN - 12.0
    bar = length * scale
    ticks = " ".join(
        f"M{_number(x0 + bar * k / 4)} {_number(y - 2.0)} L{_number(x0 + bar * k / 4)} {_number(y + 2.0)}"
        for k in range(5)
    )
    parts = [
        f'<path id="scale-bar-line" d="M{_number(x0)} {_number(y)} L{_number(x0 + bar)} {_number(y)} {ticks}" '
        'fill="none" stroke="#000000" stroke-width="0.35"/>',
        _text(x0, y + 6.0, "0", 3.0, "middle"),
        _text(x0 + bar, y + 6.0, f"{_number(length)} mm", 3.0, "middle"),
    ]
    return f'<g id="scale-bar" data-length="{_number(length)}">{"".join(parts)}</g>'
