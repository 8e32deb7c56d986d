"""DXF output of engineering sheets (``drawing_sheet(..., path="sheet.dxf")``) through ezdxf, for CAD.

The DXF holds what the SVG sheet draws, in **model units at full size**: one drawing unit is one model unit
(``$INSUNITS``), the sheet drawn at 1 / scale (a CAD user measures the model's lengths directly), y up:
$x_dxf = x_paper / scale$, $y_dxf = (paper height − y_paper) / scale$. So a CIRCLE's radius and a DIMENSION's
measurement are the model's values; lettering and arrowheads keep their paper size through ``DIMSCALE`` and
text heights divided by the scale.

============  =======================================================  ==========================================
layer         entities                                                 linetype, lineweight
============  =======================================================  ==========================================
VISIBLE       LINE (straight edges), CIRCLE / ARC / ELLIPSE (true       continuous, 0.50 mm
              curves, ``output/true_curves.py``)
HIDDEN        the same for hidden parts                                DASHED (the SVG's dash), 0.35 mm
CENTER        LINE: the dashes of the centre lines (as drawn)          continuous, 0.25 mm
DIMENSIONS    DIMENSION (linear: horizontal / vertical, with the        continuous, 0.25 mm
              measured value and "⌀" / "S⌀" / "n×" prefixes;
              diameter; radius "R"), rendered into their blocks by
              ezdxf
TITLE         LINE, CIRCLE, TEXT: border, title block, projection       continuous, 0.25–0.7 mm
              symbol, scale bar, view labels
============  =======================================================  ==========================================

ezdxf is an optional dependency (the ``dxf`` extra): ``pip install 'frustum[dxf]'``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum._files import atomic_path, os_reason
from frustum.errors import OutputError
from frustum.output.sheet.model import to_local
from frustum.output.true_curves import EllipseArc

__all__ = ["DXF_LAYERS", "save_sheet_dxf"]

DXF_LAYERS = {"VISIBLE": 50, "HIDDEN": 35, "CENTER": 25, "DIMENSIONS": 25, "TITLE": 25}
"""Layer names and their lineweights (1/100 mm)."""
# model units → DXF $INSUNITS codes
_INSUNITS = {"in": 1, "ft": 2, "mi": 3, "mm": 4, "cm": 5, "m": 6, "km": 7, "µm": 13, "um": 13, "nm": 12, "yd": 10}
_ROUND = 1e-9  # an ellipse whose axes differ by less than this fraction is a circle


def _ezdxf() -> Any:
    try:
        import ezdxf
    except ImportError:
        raise OutputError(
            "drawing_sheet: path = '*.dxf' needs the ezdxf package, the 'dxf' extra: pip install 'frustum[dxf]'; "
            "or write '.svg' / '.pdf'"
        ) from None
    return ezdxf


def save_sheet_dxf(drawing: Any, path: str | os.PathLike) -> Path:
    """Write the sheet `drawing` (``model.SheetDrawing``) to `path` as DXF R2010 (see the module); the same
    sheet gives the same bytes (ezdxf's fixed meta data: no time stamps or random GUIDs)."""
    ezdxf = _ezdxf()
    previous = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        return _save(ezdxf, drawing, path)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = previous


def _save(ezdxf: Any, drawing: Any, path: str | os.PathLike) -> Path:
    where = "drawing_sheet"
    scale, height = drawing.scale, drawing.height
    document = ezdxf.new("R2010")
    document.units = _INSUNITS.get(drawing.units, 0)
    document.header["$INSUNITS"] = _INSUNITS.get(drawing.units, 0)
    document.header["$MEASUREMENT"] = 0 if drawing.units in ("in", "ft", "mi", "yd") else 1
    document.header["$LUNITS"] = 2  # decimal
    # the SVG's hidden-line dash (4 and 2.5 line widths of the 0.5 mm pen), in drawing units
    dash, gap = 2.0 / scale, 1.25 / scale
    document.linetypes.add("DASHED", pattern=[dash + gap, dash, -gap], description="Dashed __ __ __")
    for name, weight in DXF_LAYERS.items():
        attributes = {"lineweight": weight, "linetype": "DASHED" if name == "HIDDEN" else "Continuous"}
        document.layers.add(name, **attributes)
    style = document.dimstyles.new("FRUSTUM")
    for key, value in {"dimscale": 1.0 / scale, "dimtxt": 3.5, "dimasz": 3.0, "dimexe": 2.0, "dimexo": 1.0,
                       "dimgap": 1.0, "dimtad": 1, "dimtzin": 8, "dimdsep": ord("."), "dimtih": 0,
                       "dimtoh": 0, "dimlwd": 25, "dimlwe": 25}.items():  # fmt: skip
        style.dxf.set(key, value)
    space = document.modelspace()

    def to_dxf(points: NDArray) -> NDArray:
        points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        return np.column_stack([points[:, 0] / scale, (height - points[:, 1]) / scale])

    for view in drawing.views:
        cx, cy = drawing.places[view.name]
        factor = scale * view.model_per_pixel

        def window_to_dxf(points: NDArray, cx: float = cx, cy: float = cy, factor: float = factor) -> NDArray:
            local = to_local(np.asarray(points).reshape(-1, 2), factor)
            return to_dxf(np.column_stack([cx + local[:, 0], cy + local[:, 1]]))

        # a pictorial view shows visible edges only, as in the SVG; polylines are drawn with the mesh edges
        hidden = None if view.name == "isometric" else drawing.hidden
        lines = view.lines
        for layer, segments, arcs in (
            ("HIDDEN", lines.hidden if hidden else np.zeros((0, 2, 2)), view.hidden_arcs if hidden else []),
            ("VISIBLE", lines.visible, view.visible_arcs),
        ):
            for a, b in window_to_dxf(segments.reshape(-1, 2)).reshape(-1, 2, 2):
                space.add_line(tuple(a), tuple(b), dxfattribs={"layer": layer})
            for arc in arcs:
                _add_arc(space, arc.mapped(window_to_dxf), layer)
        for mark in drawing.marks[view.name]:
            _add_mark(space, mark, cx, cy, to_dxf, scale)
    for mark in drawing.title_marks:
        _add_mark(space, mark, 0.0, 0.0, to_dxf, scale)
    border = to_dxf(np.array([[10.0, 10.0], [drawing.width - 10.0, 10.0], [drawing.width - 10.0, height - 10.0],
                              [10.0, height - 10.0]]))  # fmt: skip
    for k in range(4):
        space.add_line(tuple(border[k]), tuple(border[(k + 1) % 4]), dxfattribs={"layer": "TITLE", "lineweight": 70})
    target = Path(path)
    with atomic_path(target, where=where) as temporary:
        try:
            document.saveas(temporary)
        except OSError as error:
            raise OutputError(
                f"{where}: path = {str(target)!r} cannot be written ({os_reason(error)}); choose a writable "
                "location with free space"
            ) from None
    return target


def _add_arc(space: Any, arc: EllipseArc, layer: str) -> None:
    """CIRCLE, ARC or ELLIPSE of an arc in DXF coordinates (y up; DXF angles counter-clockwise)."""
    u, s, vt = np.linalg.svd(arc.axes)
    attributes = {"layer": layer}
    centre = (float(arc.centre[0]), float(arc.centre[1]))
    counter_clockwise = np.linalg.det(arc.axes) > 0.0  # increasing θ turns counter-clockwise
    if s[0] - s[1] <= _ROUND * s[0]:
        radius = float(s[0])
        if arc.full:
            space.add_circle(centre, radius, dxfattribs=attributes)
            return
        a, b = arc.point(arc.start) - arc.centre, arc.point(arc.end) - arc.centre
        start, end = (math.degrees(math.atan2(p[1], p[0])) for p in ((a, b) if counter_clockwise else (b, a)))
        space.add_arc(centre, radius, start % 360.0, end % 360.0, dxfattribs=attributes)
        return
    if np.linalg.det(u) < 0.0:  # a right-handed ellipse frame: minor axis = major axis turned +90°
        u[:, 1] *= -1.0
        vt[1] *= -1.0
    major = u[:, 0] * s[0]
    ratio = float(s[1] / s[0])
    if arc.full:
        start, end = 0.0, 2.0 * math.pi
    else:
        # ellipse parameter φ of a point: [cos φ, sin φ] = Vᵀ·[cos θ, sin θ]
        phis = [math.atan2(*(vt @ [math.cos(t), math.sin(t)])[::-1]) for t in (arc.start, arc.end)]
        start, end = phis if np.linalg.det(vt) > 0.0 else phis[::-1]
    space.add_ellipse(centre, (float(major[0]), float(major[1])), ratio, start, end, dxfattribs=attributes)


def _add_mark(space: Any, mark: Any, dx: float, dy: float, to_dxf: Any, scale: float) -> None:
    """A sheet mark: DIMENSION for dimensions and diameters, LINE / CIRCLE / TEXT for the rest."""
    layer = {"dimension": "DIMENSIONS", "diameter": "DIMENSIONS", "radius": "DIMENSIONS", "centre": "CENTER"}.get(
        mark.kind, "TITLE"
    )
    attributes = {"layer": layer}
    definition = mark.definition
    if mark.kind == "dimension" and definition is not None:
        _, a, b, at, horizontal = definition
        p1, p2 = to_dxf(np.array([[a[0] + dx, a[1] + dy], [b[0] + dx, b[1] + dy]]))
        base = to_dxf(np.array([[a[0] + dx, at + dy] if horizontal else [at + dx, a[1] + dy]]))[0]
        prefix = _prefix(mark.texts[0][2])
        dimension = space.add_linear_dim(
            base=tuple(base), p1=tuple(p1), p2=tuple(p2), angle=0.0 if horizontal else 90.0,
            text=f"{prefix}<>", dimstyle="FRUSTUM", override={"dimdec": _decimals(mark.value)},
            dxfattribs=attributes,
        )  # fmt: skip
        dimension.render()
        return
    if mark.kind in ("diameter", "radius") and definition is not None:
        # a diameter (radius) dimension writes its own ⌀ (R) before the measurement: the mark's text drops it
        add, symbol = (space.add_diameter_dim, "%%c") if mark.kind == "diameter" else (space.add_radius_dim, "R")
        _, centre, radius, tip = definition
        centre_dxf = to_dxf(np.array([[centre[0] + dx, centre[1] + dy]]))[0]
        angle = math.degrees(math.atan2(-(tip[1] - centre[1]), tip[0] - centre[0]))
        knee = mark.lines[0][2:]
        location = to_dxf(np.array([[knee[0] + dx, knee[1] + dy]]))[0]
        dimension = add(
            center=tuple(centre_dxf),
            radius=radius / scale,
            angle=angle,
            location=tuple(location),
            text=f"{_prefix(mark.texts[0][2]).removesuffix(symbol)}<>",
            dimstyle="FRUSTUM",
            override={"dimdec": _decimals(mark.value), "dimtmove": 0, "dimtih": 1, "dimtoh": 1},
            dxfattribs=attributes,
        )
        dimension.render()
        return
    weight = {"lineweight": round(mark.line_width * 100)} if layer == "TITLE" else {}
    for x0, y0, x1, y1 in mark.lines:
        a, b = to_dxf(np.array([[x0 + dx, y0 + dy], [x1 + dx, y1 + dy]]))
        space.add_line(tuple(a), tuple(b), dxfattribs={**attributes, **weight})
    for x, y, r in mark.circles:
        space.add_circle(tuple(to_dxf(np.array([[x + dx, y + dy]]))[0]), r / scale, dxfattribs={**attributes, **weight})
    for x, y, text, anchor, vertical in mark.texts:
        insert = tuple(to_dxf(np.array([[x + dx, y + dy]]))[0])
        entity = space.add_text(
            text, height=mark.text_size / scale, rotation=90.0 if vertical else 0.0, dxfattribs=attributes
        )
        entity.set_placement(insert, align=_ALIGN[anchor])


def _prefix(text: str) -> str:
    """What a dimension's text carries before its number ("⌀", "S⌀", "2× ⌀"), in DXF control codes (%%c: ⌀)."""
    digits = next((k for k, c in enumerate(text) if c.isdigit() and text[k + 1 : k + 2] != "×"), len(text))
    return text[:digits].replace("⌀", "%%c")


def _decimals(value: float) -> int:
    """Decimal places ``dimension_text`` shows for `value` (four significant digits, at most six)."""
    if not value:
        return 0
    return min(6, max(0, 3 - math.floor(math.log10(abs(value)))))


def _alignments() -> dict[str, Any]:
    from ezdxf.enums import TextEntityAlignment

    return {"start": TextEntityAlignment.LEFT, "middle": TextEntityAlignment.CENTER, "end": TextEntityAlignment.RIGHT}


class _Align(dict):
    def __missing__(self, key: str) -> Any:
        self.update(_alignments())
        return self[key]


_ALIGN = _Align()
