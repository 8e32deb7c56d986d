"""``drawing_sheet``: a dimensioned engineering sheet of a scene as SVG (and PDF, PNG through ``save_svg``, DXF
through ``output.sheet.dxf``), at the largest standard scale at which its views fit the paper."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from html import escape as _html_escape
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import as_scalar, describe
from frustum.errors import OutputError
from frustum.geometry import Mesh
from frustum.output.sheet.dimensions import plan_parts, view_marks
from frustum.output.sheet.layout import layout_views, paper_size, paper_text, view_names
from frustum.output.sheet.model import (
    ARROW_HALF_WIDTH,
    ARROW_LENGTH,
    DIMENSION_MODES,
    FIRST_ANGLE,
    MARGIN,
    ORIENTATIONS,
    PARTS_TRIES,
    STANDARD_SCALES,
    THIRD_ANGLE,
    TITLE_HEIGHT,
    Mark,
    SheetDrawing,
    SheetView,
    geometry_points,
    to_local,
)
from frustum.output.sheet.title_block import draw_title_block, scale_bar, scale_label, title_fields
from frustum.output.sheet.views import make_views
from frustum.output.svg import (
    _check_common,
    _drawing_groups,
    _escape,
    _number,
    _placed_meshes,
    hidden_style,
    save_svg,
    svg_document,
)
from frustum.output.true_curves import svg_arc_elements
from frustum.scene import Scene
from frustum.visibility.hidden_lines import (
    DEFAULT_CREASE_ANGLE,
)


def _mark_svg(mark: Mark, prefix: str, dx: float, dy: float) -> str:
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
            bx, by = x + dx - ARROW_LENGTH * ux, y + dy - ARROW_LENGTH * uy
            px, py = -uy * ARROW_HALF_WIDTH, ux * ARROW_HALF_WIDTH
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
        stated once in the view that shows it best (``plan_parts``): a diameter leader (``⌀d``, ``S⌀d`` for a
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
        Also write the sheet: ``.svg``, ``.pdf``, ``.png`` (``save_svg``) or ``.dxf`` (``output/sheet/dxf.py``:
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
    names = view_names(views, where)
    mode, given_scale = _checked_options(projection_angle, orientation, dimensions, scale, where)
    paper_width, paper_height = paper_size(paper, orientation, where)
    fields = title_fields(title_block, title, where)
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
        [geometry_points(item.mesh) @ item.world_from_model[:3, :3].T + item.world_from_model[:3, 3] for item in placed]
    )
    meshes = [(item.mesh, item.world_from_model) for item in placed]
    sheet_views, circles = make_views(names, points_world, meshes, {"edges": edges, "crease_angle": crease_angle})
    size = max(float(np.linalg.norm(points_world.max(axis=0) - points_world.min(axis=0))), 1e-300)
    parts_world = [geometry_points(mesh) @ m[:3, :3].T + m[:3, 3] for mesh, m in meshes]
    ids = [hash((geometry_points(mesh).tobytes(), getattr(mesh, "faces", np.empty(0)).tobytes())) for mesh, _ in meshes]
    plan = plan_parts(sheet_views, circles, parts_world, ids, size) if mode == "parts" else None
    cells = THIRD_ANGLE if projection_angle == "third" else FIRST_ANGLE
    # the drawing area: inside the border, above the title strip
    area = (MARGIN, MARGIN, paper_width - 2 * MARGIN, paper_height - 2 * MARGIN - TITLE_HEIGHT)

    drawing_scale, used, marks, places = _fit(sheet_views, cells, area, plan, mode, given_scale, len(names), paper,
                                              where)  # fmt: skip
    body = [
        f'<rect id="border" x="{_number(MARGIN)}" y="{_number(MARGIN)}" '
        f'width="{_number(paper_width - 2 * MARGIN)}" height="{_number(paper_height - 2 * MARGIN)}" '
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
    title_marks = draw_title_block(paper_width, paper_height, fields, drawing_scale, projection_angle, paper_name)
    data = {**fields, "scale": scale_label(drawing_scale), "projection": projection_angle, "size": paper_name,
            "dimensions": str(used).lower()}  # fmt: skip
    attributes = "".join(f' data-{key.replace("_", "-")}="{_html_escape(value)}"' for key, value in data.items())
    body.append(f'<g id="title-block"{attributes}>{"".join(_mark_svg(mark, "", 0.0, 0.0) for mark in title_marks)}</g>')
    length, bar = scale_bar(drawing_scale, paper_height)
    body.append(f'<g id="scale-bar" data-length="{_number(length)}">{_mark_svg(bar, "", 0.0, 0.0)}</g>')
    title_marks.append(bar)
    text = svg_document(paper_width, paper_height, body, units="mm")
    if path is not None:
        if str(path).lower().endswith(".dxf"):
            from frustum.output.sheet.dxf import save_sheet_dxf

            save_sheet_dxf(
                SheetDrawing(paper_width, paper_height, drawing_scale, sheet_views, places, marks, title_marks,
                              hidden, fields["units"], placed),
                path,
            )  # fmt: skip
        else:
            save_svg(text, path)
    return text


def _checked_options(projection_angle: Any, orientation: Any, dimensions: Any, scale: Any,
                     where: str) -> tuple[str | None, float | None]:  # fmt: skip
    """``drawing_sheet``'s projection angle, orientation, dimensions and scale checked: (dimension mode or None, the
    given scale or None)."""
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
    given_scale = None
    if scale is not None:
        given_scale = as_scalar(scale, "scale", where=where, error=OutputError)
        if not given_scale > 0.0:
            raise OutputError(f"{where}: scale = {given_scale!r} must be > 0; paper length / model length")
    return mode, given_scale


def _fit(
    sheet_views: list[SheetView], cells: dict, area: tuple, plan: Any, mode: str | None, given_scale: float | None,
    view_count: int, paper: Any, where: str,
) -> tuple[float, str | None, dict, dict]:  # fmt: skip
    """(scale, dimension mode used, marks, places): the views and their dimensions laid out at the given scale, or
    at the largest standard scale at which they fit (``mode="parts"`` falls back to "overall" where each part's
    dimensions crowd the paper)."""
    empty: dict[str, list[Mark]] = {view.name: [] for view in sheet_views}

    def attempt(candidate: float, use: str | None) -> tuple[dict, dict] | None:
        if layout_views(sheet_views, empty, cells, candidate, area) is None:  # the views alone do not fit
            return None
        marks = {view.name: view_marks(view, candidate, use, plan) for view in sheet_views}
        places = layout_views(sheet_views, marks, cells, candidate, area)
        return None if places is None else (marks, places)

    def search(use: str | None, tries: int | None) -> tuple[float, tuple[dict, dict]] | None:
        """The largest standard scale that fits with `use` dimensions (giving up after `tries` scales at which
        the views alone fit)."""
        for candidate in STANDARD_SCALES:
            if layout_views(sheet_views, empty, cells, candidate, area) is None:
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
        largest = search(mode, PARTS_TRIES if mode == "parts" else None)
        if largest is None and mode == "parts":
            used, largest = "overall", search("overall", None)
        if largest is None:
            raise OutputError(
                f"{where}: scale = None found no standard scale down to {scale_label(STANDARD_SCALES[-1])} that "
                f"fits {paper_text(paper)}; give a smaller scale or larger paper"
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
                f"{where}: scale = {drawing_scale!r} does not fit {view_count} views on {paper_text(paper)} "
                f"({hint}); give a smaller scale, fewer views or larger paper"
            )
        marks, places = fitted
    return drawing_scale, used, marks, places


def _view_group(
    view: SheetView, placed: list, centre_x: float, centre_y: float, scale: float, hidden: str | None,
    stroke_width: float,
) -> str:  # fmt: skip
    factor = scale * view.model_per_pixel

    def to_paper(points: NDArray) -> NDArray:
        # window (y up) → paper mm (y down): x_p = c_x + scale·x_view, y_p = c_y − scale·y_view
        local = to_local(points, factor)
        return np.column_stack([centre_x + local[:, 0], centre_y + local[:, 1]])

    groups = _drawing_groups(view.lines, placed, to_paper, stroke_width, hidden, False, prefix=f"{view.name}-")
    groups += _curve_groups(view, to_paper, stroke_width, hidden)
    return (
        f'<g id="view-{view.name}" data-scale="{_number(scale)}" '
        f'data-centre="{_number(centre_x)} {_number(centre_y)}">{"".join(groups)}</g>'
    )


def _view_shadows(scene: Scene, view: SheetView, centre_x: float, centre_y: float, scale: float) -> str:
    """The view's ``<g id="<view>-shadows">``: hatched shadow paths (``svg_shadows.shadow_polygons``) on paper."""
    from frustum.output.svg_shadows import shadow_polygons

    factor = scale * view.model_per_pixel
    paths = []
    for polygon in shadow_polygons(scene, view.camera):
        loops = []
        for loop in polygon.loops:
            local = to_local(loop, factor)
            loops.append("M " + " L ".join(f"{_number(centre_x + x)} {_number(centre_y + y)}" for x, y in local) + " Z")
        paths.append(f'<path d="{" ".join(loops)}" class="{polygon.kind}"/>')
    return (
        f'<g id="{view.name}-shadows" fill="url(#shadow-hatch)" fill-rule="evenodd" stroke="#000000" '
        f'stroke-width="0.18"><defs><pattern id="shadow-hatch" patternUnits="userSpaceOnUse" width="1.5" '
        'height="1.5" patternTransform="rotate(45)"><line x1="0" y1="0" x2="0" y2="1.5" stroke="#000000" '
        f'stroke-width="0.18"/></pattern></defs>{"".join(paths)}</g>'
    )


def _curve_groups(view: SheetView, to_paper: Any, stroke_width: float, hidden: str | None) -> list[str]:
    """The view's true curves: groups ``<view>-hidden-curves`` (styled as the hidden lines) and
    ``<view>-visible-curves`` of ``<circle>``, ``<ellipse>`` and elliptical-arc ``<path>`` elements."""
    groups = []
    if hidden is not None and view.hidden_arcs:
        style = hidden_style(hidden, stroke_width)
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
