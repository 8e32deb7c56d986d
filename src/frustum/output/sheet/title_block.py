"""The title block (ISO 7200), the projection symbol (ISO 128-1: first or third angle) and the scale bar of a
sheet."""

from __future__ import annotations

import math
from typing import Any

from frustum._arrays import describe
from frustum.errors import OutputError
from frustum.output.sheet.model import MARGIN, TITLE_WIDTH, Mark
from frustum.output.svg import (
    _number,
)


def scale_label(scale: float) -> str:
    """Drawing-scale text: ``"1:1"``, ``"2:1"``, ``"1:5"``, or ``"1:<1/scale>"`` for other values."""
    if scale >= 1.0 and float(scale).is_integer():
        return f"{int(scale)}:1"
    inverse = 1.0 / scale
    if abs(inverse - round(inverse)) <= 1e-9 * inverse:
        return f"1:{round(inverse)}"
    return f"1:{_number(round(inverse, 6))}"


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


def title_fields(title_block: Any, title: str, where: str) -> dict[str, str]:
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


def draw_title_block(paper_width: float, paper_height: float, fields: dict[str, str], scale: float, angle: str,
                 paper: str) -> list[Mark]:  # fmt: skip
    """The ISO 7200 title block at the lower right corner of the frame, as marks (sheet coordinates): frame and
    cell lines, each cell's label (small) and value, and the projection symbol of `angle` with its name."""
    x1, y1 = paper_width - MARGIN, paper_height - MARGIN
    x0, y0 = x1 - TITLE_WIDTH, y1 - 32.0
    frame = Mark("title", "title-block-lines", line_width=0.5)
    frame.lines += [(x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)]
    labels = Mark("title", "title-block-labels", text_size=_TITLE_LABEL)
    values = Mark("title", "title-block-values")
    title = Mark("title", "title-block-title", text_size=5.0)
    cells = Mark("title", "title-block-cells", line_width=0.35)
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


def _projection_symbol(x: float, y: float, angle: str) -> Mark:
    """ISO 5456-2's symbol of the projection method, 7 mm tall, its top left at (x, y): a truncated cone with
    its small end to the left (front view: a trapezoid) and its view from the left (two circles, both rims
    seen). First angle puts that view on the far side, right of the trapezoid (next to the large end); third
    angle where it was seen from, left of it (next to the small end). Centre lines through both."""
    mark = Mark("symbol", f"projection-symbol-{angle}", line_width=0.35)
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


def scale_bar(scale: float, paper_height: float) -> tuple[float, Mark]:
    """A bar of a round model length (1, 2 or 5 × 10^k mm) between 20 and 50 mm of paper, with ticks: the
    length and the bar as a mark (sheet coordinates)."""
    target = 40.0 / scale  # model mm that make about 40 mm of paper
    exponent = math.floor(math.log10(target))
    length = max(
        (m * 10.0**exponent for m in (1.0, 2.0, 5.0, 10.0) if m * 10.0**exponent * scale <= 50.0),
        default=10.0**exponent,
    )
    x0, y = MARGIN + 8.0, paper_height - MARGIN - 12.0
    bar = length * scale
    mark = Mark("title", "scale-bar-line", line_width=0.35, text_size=3.0)
    mark.lines.append((x0, y, x0 + bar, y))
    mark.lines += [(x0 + bar * k / 4, y - 2.0, x0 + bar * k / 4, y + 2.0) for k in range(5)]
    mark.texts += [(x0, y + 6.0, "0", "middle", False), (x0 + bar, y + 6.0, f"{_number(length)} mm", "middle", False)]
    return length, mark
