"""Layout of a sheet: the paper, the view names asked for, and the grid of views around the front view (first- or
third-angle), each view's cell sized by its drawing and its annotations, with no two annotations clashing."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import describe
from frustum.errors import OutputError
from frustum.output.sheet.model import (
    ARROW_HALF_WIDTH,
    MARGIN,
    MIN_GAP,
    PAPER_SIZES,
    SHEET_VIEWS,
    TITLE_HEIGHT,
    TITLE_WIDTH,
    Mark,
    SheetView,
    marks_box,
)
from frustum.output.svg import (
    _number,
)
from frustum.projection import multiview


def _body(mark: Mark) -> list[NDArray]:
    """Rectangles (x0, y0, x1, y1) around a linear dimension's line with its arrowheads, and its text (computed
    once per mark)."""
    if mark.body is None:
        mark.body = _body_of(mark)
    return mark.body


def _body_of(mark: Mark) -> list[NDArray]:
    x0, y0, x1, y1 = mark.lines[-1]
    line = np.array([min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1)])
    line += np.array([-1.0, -1.0, 1.0, 1.0]) * ARROW_HALF_WIDTH
    return [line, marks_box([Mark("text", "", texts=mark.texts)])]


def marks_clash(mark: Mark, other: Mark) -> bool:
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


def layout_views(
    views: list[SheetView], marks: dict[str, list[Mark]], cells: dict[str, tuple[int, int]], scale: float,
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
        box = marks_box(marks[view.name])
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
    if gap_x < MIN_GAP or gap_y < MIN_GAP:
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


def view_names(views: Any, where: str) -> list[str]:
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


def paper_size(paper: Any, orientation: str, where: str) -> tuple[float, float]:
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
        or not size[0] > 2 * MARGIN + TITLE_WIDTH
        or not size[1] > 2 * MARGIN + TITLE_HEIGHT
    ):
        raise OutputError(
            f"{where}: paper = {describe(paper)} is not a paper name or a (width, height) in mm larger than "
            f"({_number(2 * MARGIN + TITLE_WIDTH)}, {_number(2 * MARGIN + TITLE_HEIGHT)}); use e.g. 'A3' or "
            "(420, 297)"
        )
    return float(size[0]), float(size[1])


def paper_text(paper: Any) -> str:
    return paper if isinstance(paper, str) else f"{describe(paper)} mm paper"
