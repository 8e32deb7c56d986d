"""The parts of an engineering sheet and the paper they go on: paper sizes, scales and the fixed distances of the
drawing standards (mm), a view (``SheetView``), an annotation (``Mark``: dimension, leader, centre line or label in
view-local paper millimetres) and the finished drawing for writers other than SVG (``SheetDrawing``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from frustum.camera import Camera
from frustum.geometry import Mesh, Polyline
from frustum.output.true_curves import EllipseArc
from frustum.projection import MULTIVIEWS
from frustum.visibility.hidden_lines import (
    HiddenLines,
)

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
THIRD_ANGLE = {"front": (0, 0), "top": (0, -1), "bottom": (0, 1), "right": (1, 0), "left": (-1, 0),
                "rear": (2, 0), "isometric": (1, -1)}  # fmt: skip


FIRST_ANGLE = {"front": (0, 0), "top": (0, 1), "bottom": (0, -1), "right": (-1, 0), "left": (1, 0),
                "rear": (2, 0), "isometric": (1, 1)}  # fmt: skip


MARGIN = 10.0  # border to paper edge, mm


TITLE_HEIGHT = 36.0  # title block strip at the bottom of the frame, mm


TITLE_WIDTH = 180.0  # ISO 7200: at most 180 mm wide


MIN_GAP = 8.0  # least space between views (and between views and the border), mm


PIXELS = 1000  # window size of the view cameras; window → paper is x_p = scale · (h / PIXELS) · x_w + ...


# dimensioning (ISO 129-1): thin lines, closed filled arrowheads, 3.5 mm lettering above the dimension line
_THIN = 0.25  # dimension, extension, leader and centre lines, mm


DIMENSION_OFFSET = 10.0  # view outline to dimension line, mm


DIMENSION_SPACING = 7.0  # between stacked parallel dimension lines, mm


PARTS_TRIES = 4  # scales at which the views fit that dimensions="parts" tries before falling back to "overall"


EXTENSION_GAP = 1.0  # extension lines start this far from the feature ...


EXTENSION_BEYOND = 2.0  # ... and end this far past the dimension line, mm


ARROW_LENGTH, ARROW_HALF_WIDTH = 3.0, 0.55  # arrowhead, mm (about 20 degrees included)


LETTER = 3.5  # dimension and label text height, mm


LEADER_RISE = 5.0  # a diameter leader's shoulder sits this far above the view, mm; more leaders stack 6 mm apart


LABEL_DROP = 7.0  # view label baseline below everything else of the view, mm


# circles (output/true_curves.py): two circles are one cylinder's when radii and axes agree within this fraction
CIRCLE_TOLERANCE = 1e-6


# an end-on circle's plane normal lies within this angle (radians) of the line of sight
END_ON_ANGLE = 1e-6


@dataclass
class SheetView:
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
class Mark:
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
    text_size: float = LETTER
    line_width: float = _THIN
    body: list | None = field(default=None, repr=False, compare=False)  # cached by _body


def marks_box(marks: list[Mark]) -> NDArray[np.float64]:
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
            run = 0.6 * LETTER * len(text)
            along = {"start": (0.0, run), "middle": (-run / 2, run / 2), "end": (-run, 0.0)}[anchor]
            if vertical:  # rotated −90°: reads upward, the run along −y
                xs += [x - LETTER, x]
                ys += [y - along[1], y - along[0]]
            else:
                xs += [x + along[0], x + along[1]]
                ys += [y - LETTER, y]
    if not xs:
        return np.array([np.inf, np.inf, -np.inf, -np.inf])
    return np.array([min(xs), min(ys), max(xs), max(ys)])


def to_local(window: NDArray, factor: float) -> NDArray:
    """Window (x, y up) → view-local (x right, y down) around the window centre, times `factor`."""
    half = PIXELS / 2.0
    return np.column_stack([(window[:, 0] - half) * factor, -(window[:, 1] - half) * factor])


@dataclass
class SheetDrawing:
    """Everything a sheet draws, for writers other than SVG (``output/sheet/dxf.py``): paper size (mm), scale,
    the views and their sheet positions, their marks (view-local paper mm), the title block's marks (sheet mm),
    the hidden-line style, the model units and the placed meshes."""

    width: float
    height: float
    scale: float
    views: list[SheetView]
    places: dict[str, tuple[float, float]]
    marks: dict[str, list[Mark]]
    title_marks: list[Mark]
    hidden: str | None
    units: str
    placed: list


def geometry_points(geometry: Mesh | Polyline) -> NDArray[np.float64]:
    return geometry.vertices if isinstance(geometry, Mesh) else geometry.points
