"""The ``[sheet]`` table: ``drawing_sheet`` keywords for ``frustum view`` and the title block's fields."""

from __future__ import annotations

from typing import Any

from frustum.scenefile.checks import _number, _table, _unknown_keys
from frustum.scenefile.report import _BAD, _Report

_SHEET_KEYS = ("views", "paper", "orientation", "angle", "scale", "dimensions", "title", "drawing_number", "sheet",
               "date", "author", "tolerance", "units")  # fmt: skip
_SHEET_TEXT = ("paper", "orientation", "angle", "title", "drawing_number", "sheet", "date", "author", "tolerance",
               "units")  # fmt: skip


def _sheet_options(report: _Report, value: Any) -> dict:
    """``[sheet]``: ``drawing_sheet`` keywords for ``frustum view`` (views, paper, orientation, angle, scale,
    dimensions) and the title block's fields (title, drawing_number, sheet, date, author, tolerance, units)."""
    path = ("sheet",)
    params = _table(report, path, value)
    if params is _BAD:
        return {}
    _unknown_keys(report, path, params, _SHEET_KEYS)
    options: dict[str, Any] = {}
    fields: dict[str, str] = {}
    for key in _SHEET_TEXT:
        if key in params:
            if not isinstance(params[key], str):
                report.add((*path, key), params[key], "is not a string", "give text in quotes")
            elif key in ("paper", "orientation", "angle"):
                options["projection_angle" if key == "angle" else key] = params[key]
            else:
                fields[key] = params[key]
    if "views" in params:
        views = params["views"]
        if not isinstance(views, list) or not views or not all(isinstance(v, str) for v in views):
            report.add((*path, "views"), views, "is not a list of view names",
                       "give e.g. [\"front\", \"top\", \"right\", \"iso\"]")  # fmt: skip
        else:
            options["views"] = ["isometric" if v == "iso" else v for v in views]
    if "scale" in params:
        scale = _number(report, (*path, "scale"), params["scale"], low=0.0, low_open=True)
        if scale is not _BAD:
            options["scale"] = float(scale)
    if "dimensions" in params:
        dimensions = params["dimensions"]
        if dimensions not in ("parts", "overall", False):
            report.add((*path, "dimensions"), dimensions, "is unknown", 'give "parts", "overall" or false')
        else:
            options["dimensions"] = dimensions
    if fields:
        options["title_block"] = fields
    return options
