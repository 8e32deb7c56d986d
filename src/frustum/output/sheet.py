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
isometric                 upper right                  upper right
========================  ===========================  ===========================

References
----------
[HB 10] "Orthogonal Projections" (front, side and rear elevations; plan view), "Axonometric and Isometric
Orthogonal Projections"; [seed] "Elevation and Plan View", "engineering and architectural drawings".
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any
from xml.sax.saxutils import escape

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import as_scalar, describe
from frustum.camera import Camera, ViewFrame
from frustum.errors import OutputError
from frustum.geometry import Mesh, Polyline
from frustum.hidden_lines import DEFAULT_CREASE_ANGLE, remove_hidden_lines
from frustum.output.svg import _check_common, _drawing_groups, _number, _placed_meshes, svg_document
from frustum.projection import ISOMETRIC_ROTATION_X, MULTIVIEWS, Axonometric, Orthographic, multiview
from frustum.scene import Scene

__all__ = ["PAPER_SIZES", "SHEET_VIEWS", "STANDARD_SCALES", "drawing_sheet", "scale_label"]

PAPER_SIZES: dict[str, tuple[float, float]] = {
    "A0": (1189.0, 841.0),
    "A1": (841.0, 594.0),
    "A2": (594.0, 420.0),
    "A3": (420.0, 297.0),
    "A4": (297.0, 210.0),
    "letter": (279.4, 215.9),
    "tabloid": (431.8, 279.4),
}
"""Paper sizes in millimetres, landscape (width, height)."""
STANDARD_SCALES = (10.0, 5.0, 2.0, 1.0, 1 / 2, 1 / 5, 1 / 10, 1 / 20, 1 / 50, 1 / 100, 1 / 200, 1 / 500, 1 / 1000)
"""Drawing scales (paper length / model length) that ``scale=None`` chooses from, largest first (ISO 5455)."""
SHEET_VIEWS = (*MULTIVIEWS, "isometric")
"""View names ``drawing_sheet`` accepts."""

# grid cell of each view relative to the front view, (column, row), row grows downward
_THIRD_ANGLE = {"front": (0, 0), "top": (0, -1), "bottom": (0, 1), "right": (1, 0), "left": (-1, 0),
                "rear": (2, 0), "isometric": (1, -1)}  # fmt: skip
_FIRST_ANGLE = {"front": (0, 0), "top": (0, 1), "bottom": (0, -1), "right": (-1, 0), "left": (1, 0),
                "rear": (2, 0), "isometric": (1, -1)}  # fmt: skip
_MARGIN = 10.0  # border to paper edge, mm
_TITLE_HEIGHT = 36.0  # title block strip at the bottom of the frame, mm
_TITLE_WIDTH = 170.0
_GAP = 20.0  # between views, mm
_LABEL_SPACE = 9.0  # below each view for its label, mm
_PIXELS = 1000  # window size of the view cameras; window → paper is x_p = scale · (h / _PIXELS) · x_w + ...


@dataclass
class _View:
    name: str
    camera: Camera
    model_per_pixel: float  # model length (mm) per window pixel
    extents: NDArray[np.float64]  # (left, right, up, down) of the projected model around the target, model mm


def scale_label(scale: float) -> str:
    """Drawing-scale text: ``"1:1"``, ``"2:1"``, ``"1:5"``, or ``"1:<1/scale>"`` for other values."""
    if scale >= 1.0 and float(scale).is_integer():
        return f"{int(scale)}:1"
    inverse = 1.0 / scale
    if abs(inverse - round(inverse)) <= 1e-9 * inverse:
        return f"1:{round(inverse)}"
    return f"1:{_number(round(inverse, 6))}"


def _view_camera(name: str, target: NDArray, radius: float) -> Camera:
    """Orthographic (or isometric) camera of `name` looking at `target`, view window 2.2·radius tall."""
    distance = 4.0 * radius
    height = 2.2 * radius
    near, far = distance - 1.5 * radius, distance + 1.5 * radius
    if name == "isometric":
        frame = ViewFrame(target + distance * np.array([0.0, 0.0, 1.0]), target=target, up=(0.0, 1.0, 0.0))
        # isometric angles, turned −45° about y so that the front, top and right faces show (as the right view)
        isometric = Axonometric(-math.pi / 4, ISOMETRIC_ROTATION_X, height, near, far)
        return Camera(frame, isometric, _PIXELS, _PIXELS)
    return Camera.multiview(name, Orthographic(height, near, far), target, distance, _PIXELS, _PIXELS)


def _sheet_views(names: Sequence[str], points_world: NDArray) -> list[_View]:
    low, high = points_world.min(axis=0), points_world.max(axis=0)
    target = (low + high) / 2.0
    radius = max(float(np.linalg.norm(high - low)) / 2.0, 1e-9)
    views = []
    for name in names:
        camera = _view_camera(name, target, radius)
        mm_per_pixel = 2.2 * radius / _PIXELS
        window = camera.project(points_world)[:, :2] - _PIXELS / 2.0
        extents = np.array([-window[:, 0].min(), window[:, 0].max(), window[:, 1].max(), -window[:, 1].min()])
        views.append(_View(name, camera, mm_per_pixel, np.maximum(extents, 0.0) * mm_per_pixel))
    return views


def _layout(views: list[_View], cells: dict[str, tuple[int, int]]) -> tuple[dict, dict, NDArray, NDArray]:
    """Column and row extents at scale 1: (left, right) per column, (up, down) per row, fixed gaps."""
    columns: dict[int, list[float]] = {}
    rows: dict[int, list[float]] = {}
    for view in views:
        column, row = cells[view.name]
        left, right, up, down = view.extents
        c = columns.setdefault(column, [0.0, 0.0])
        c[0], c[1] = max(c[0], left), max(c[1], right)
        r = rows.setdefault(row, [0.0, 0.0])
        r[0], r[1] = max(r[0], up), max(r[1], down)
    column_keys = np.array(sorted(columns))
    row_keys = np.array(sorted(rows))
    return columns, rows, column_keys, row_keys


def drawing_sheet(
    scene: Scene,
    views: Sequence[str] = ("front", "top", "right", "isometric"),
    *,
    scale: float | None = None,
    projection_angle: str = "third",
    paper: str | tuple[float, float] = "A3",
    title: str = "",
    edges: str | Sequence[str] = "feature",
    crease_angle: float = DEFAULT_CREASE_ANGLE,
    hidden: str | None = "dashed",
    stroke_width: float = 0.5,
) -> str:
    """An SVG engineering drawing of `scene`: multiview orthographic views, title block, view labels, scale bar.

    Model units are millimetres; the SVG's user unit is one millimetre of paper (``width="420mm"`` with a
    matching viewBox), so a model length L parallel to a view plane measures exactly ``L · scale`` in that
    orthographic view: paper ``x = x0 + scale·x_view``, ``y = y0 − scale·y_view``. The isometric view is the
    isometric *projection* (every axis foreshortened by √(2/3)), drawn at the same scale.

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
        A name from ``PAPER_SIZES`` or a size in millimetres.
    title : str
        Drawing title for the title block.
    edges, crease_angle, hidden, stroke_width
        As in ``render_svg``; `stroke_width` in paper millimetres.

    Returns
    -------
    str
        The SVG document.

    Raises
    ------
    FrustumError
        If `scene` is not a Scene.
    OutputError
        For an empty scene, an unknown or repeated view, a bad scale, paper or projection angle, or views that
        do not fit on the paper at the given scale (the message says the largest scale that fits).

    References
    ----------
    [HB 10] "Orthogonal Projections", "Axonometric and Isometric Orthogonal Projections"; [seed] "Elevation
    and Plan View".
    """
    where = "drawing_sheet"
    width_line = _check_common(scene, stroke_width, hidden, where)
    names = _view_names(views, where)
    if projection_angle not in ("third", "first"):
        raise OutputError(
            f"{where}: projection_angle = {describe(projection_angle)} is unknown; expected 'third' or 'first'"
        )
    paper_width, paper_height = _paper(paper, where)
    placed = _placed_meshes(scene)
    if not any(isinstance(item.mesh, Mesh) and item.mesh.face_count > 0 for item in placed):
        raise OutputError(f"{where}: scene has no faces to draw; add a mesh with at least one triangle")
    points_world = np.concatenate(
        [_points(item.mesh) @ item.world_from_model[:3, :3].T + item.world_from_model[:3, 3] for item in placed]
    )
    meshes = [(item.mesh, item.world_from_model) for item in placed]
    sheet_views = _sheet_views(names, points_world)
    cells = _THIRD_ANGLE if projection_angle == "third" else _FIRST_ANGLE
    columns, rows, column_keys, row_keys = _layout(sheet_views, cells)
    # the drawing area: inside the border, above the title strip
    area_x0, area_y0 = _MARGIN, _MARGIN
    area_width = paper_width - 2 * _MARGIN
    area_height = paper_height - 2 * _MARGIN - _TITLE_HEIGHT
    model_width = sum(sum(columns[k]) for k in column_keys)
    model_height = sum(sum(rows[k]) for k in row_keys)
    fixed_width = _GAP * (len(column_keys) + 1)
    fixed_height = (_GAP + _LABEL_SPACE) * len(row_keys) + _GAP
    fits = min(
        (area_width - fixed_width) / model_width if model_width > 0 else math.inf,
        (area_height - fixed_height) / model_height if model_height > 0 else math.inf,
    )
    if scale is None:
        choices = [s for s in STANDARD_SCALES if s <= fits]
        if not choices:
            raise OutputError(
                f"{where}: scale = None found no standard scale down to 1:1000 that fits {_paper_text(paper)}; "
                "give a smaller scale or larger paper"
            )
        drawing_scale = choices[0]
    else:
        drawing_scale = as_scalar(scale, "scale", where=where, error=OutputError)
        if not drawing_scale > 0.0:
            raise OutputError(f"{where}: scale = {drawing_scale!r} must be > 0; paper length / model length")
        if drawing_scale > fits:
            raise OutputError(
                f"{where}: scale = {drawing_scale!r} does not fit {len(names)} views on {_paper_text(paper)} "
                f"(at most {fits:.4g}); give a smaller scale, fewer views or larger paper"
            )
    # place the views: the projected target of each view on its column's and row's centre lines
    used_width = drawing_scale * model_width + fixed_width
    used_height = drawing_scale * model_height + fixed_height
    x = area_x0 + (area_width - used_width) / 2.0 + _GAP
    centre_x = {}
    for key in column_keys:
        left, right = columns[key]
        centre_x[int(key)] = x + drawing_scale * left
        x += drawing_scale * (left + right) + _GAP
    y = area_y0 + (area_height - used_height) / 2.0 + _GAP
    centre_y, label_y = {}, {}
    for key in row_keys:
        up, down = rows[key]
        centre_y[int(key)] = y + drawing_scale * up
        label_y[int(key)] = y + drawing_scale * (up + down) + 6.0
        y += drawing_scale * (up + down) + _LABEL_SPACE + _GAP
    body = [
        f'<rect id="border" x="{_number(_MARGIN)}" y="{_number(_MARGIN)}" '
        f'width="{_number(paper_width - 2 * _MARGIN)}" height="{_number(paper_height - 2 * _MARGIN)}" '
        'fill="none" stroke="#000000" stroke-width="0.7"/>'
    ]
    for view in sheet_views:
        column, row = cells[view.name]
        body.append(
            _view_group(
                view,
                placed,
                meshes,
                centre_x[column],
                centre_y[row],
                drawing_scale,
                edges,
                crease_angle,
                hidden,
                width_line,
            )
        )
        body.append(
            f'<text x="{_number(centre_x[column])}" y="{_number(label_y[row])}" font-family="sans-serif" '
            f'font-size="3.5" text-anchor="middle">{view.name.upper()} VIEW</text>'
        )
    body.append(_title_block(paper_width, paper_height, title, drawing_scale, projection_angle))
    body.append(_scale_bar(drawing_scale, paper_height))
    return svg_document(paper_width, paper_height, body, units="mm")


def _points(geometry: Mesh | Polyline) -> NDArray[np.float64]:
    return geometry.vertices if isinstance(geometry, Mesh) else geometry.points


def _view_group(
    view: _View, placed: list, meshes: list, centre_x: float, centre_y: float, scale: float, edges: Any,
    crease_angle: float, hidden: str | None, stroke_width: float,
) -> str:  # fmt: skip
    lines = remove_hidden_lines(meshes, view.camera, edges=edges, crease_angle=crease_angle)
    factor = scale * view.model_per_pixel
    half = _PIXELS / 2.0

    def to_paper(points: NDArray) -> NDArray:
        # window (y up) → paper mm (y down): x_p = c_x + scale·x_view, y_p = c_y − scale·y_view
        return np.column_stack([centre_x + (points[:, 0] - half) * factor, centre_y - (points[:, 1] - half) * factor])

    groups = _drawing_groups(lines, placed, to_paper, stroke_width, hidden, False, prefix=f"{view.name}-")
    return f'<g id="view-{view.name}" data-scale="{_number(scale)}">{"".join(groups)}</g>'


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


def _paper(paper: Any, where: str) -> tuple[float, float]:
    if isinstance(paper, str):
        if paper not in PAPER_SIZES:
            raise OutputError(f"{where}: paper = {paper!r} is unknown; expected one of {sorted(PAPER_SIZES)}")
        return PAPER_SIZES[paper]
    try:
        size = np.asarray(paper, dtype=np.float64)
    except (TypeError, ValueError):
        size = np.zeros(0)
    if size.shape != (2,) or not np.isfinite(size).all() or not (size > 2 * _MARGIN + _TITLE_HEIGHT).all():
        raise OutputError(
            f"{where}: paper = {describe(paper)} is not a paper name or a (width, height) in mm larger than "
            f"{_number(2 * _MARGIN + _TITLE_HEIGHT)}; use e.g. 'A3' or (420, 297)"
        )
    return float(size[0]), float(size[1])


def _paper_text(paper: Any) -> str:
    return paper if isinstance(paper, str) else f"{describe(paper)} mm paper"


def _text(x: float, y: float, text: str, size: float, anchor: str = "start") -> str:
    return (
        f'<text x="{_number(x)}" y="{_number(y)}" font-family="sans-serif" font-size="{_number(size)}" '
        f'text-anchor="{anchor}">{escape(text)}</text>'
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
