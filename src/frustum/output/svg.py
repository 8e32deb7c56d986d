"""Exact vector drawings: hidden-line SVG (and PDF or PNG through cairosvg) of a scene seen by a camera.

``render_svg`` draws the edges that ``visibility.hidden_lines.remove_hidden_lines`` finds, visible solid and hidden
dashed (or dimmed), in window coordinates with **y down** as SVG wants it ($y_svg = height − y_window$), one
SVG user unit per pixel. With ``fill=True`` it first paints the faces as flat-shaded polygons back to front (a
BSP tree, ``frustum.visibility.bsp``, or a plain depth sort), so filled drawings are correct where a painter's algorithm
on whole faces is not. Curves: under a parallel projection the window image of a Bézier control polygon is
the control polygon of the image curve (an affine map commutes with de Casteljau), so ``svg_path_from_bezier``
writes it as an exact SVG Bézier path.

References
----------
[HB 16] "Wire-Frame Visibility Methods", "Depth-Sorting Method", "BSP-Tree Method"; [HB 10] "Orthogonal
Projections", "Oblique Parallel Projections" (affine maps); [HB 14] "Bézier Spline Curves"; [seed]
"Wire-frame visibility", "Depth cueing".
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from html import escape as _html_escape
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_scalar, describe
from frustum._files import atomic_path, os_reason
from frustum.camera import Camera
from frustum.clipping import clip_polygon
from frustum.errors import FrustumError, OutputError
from frustum.geometry import Mesh
from frustum.geometry.curves import BezierCurve, PiecewiseBezier
from frustum.scene import Scene, SceneItem
from frustum.shading import DirectionalLight
from frustum.visibility.bsp import BSPTree
from frustum.visibility.hidden_lines import DEFAULT_CREASE_ANGLE, EDGE_LINE, HiddenLines, remove_hidden_lines

__all__ = [
    "FILL_ORDERS",
    "HIDDEN_STYLES",
    "render_svg",
    "save_svg",
    "svg_document",
    "svg_path_from_bezier",
    "svg_path_from_polyline",
]


def _escape(text: str) -> str:
    """XML character data: ``&``, ``<`` and ``>`` escaped (``html.escape`` without quotes: ``xml.sax.saxutils``
    would import ``urllib.request``, 20 ms of ``import frustum``)."""
    return _html_escape(text, quote=False)


HIDDEN_STYLES = ("dashed", "dimmed", None)
"""How ``render_svg`` draws hidden lines: dashed (engineering drawings), light gray, or not at all."""
FILL_ORDERS = ("bsp", "depth")
"""Back-to-front orders for ``fill=True``: a BSP tree (splits cyclic overlaps) or a depth sort by the farthest
corner (the painter's first step, no splitting)."""

_SVG_NAMESPACE = "http://www.w3.org/2000/svg"
_HIDDEN_GRAY = "#9a9a9a"
# depth cueing: the nearest visible piece is drawn black at full width, the farthest at this gray and width
_FAR_GRAY = 0.75
_FAR_WIDTH = 0.4


class _Pieces(NamedTuple):
    """The part of a ``HiddenLines`` that one group draws."""

    visible: NDArray[np.float64]
    visible_depth: NDArray[np.float64]
    hidden: NDArray[np.float64]


def _split_pieces(lines: HiddenLines) -> tuple[_Pieces, dict[int, _Pieces]]:
    """Mesh edges, and polyline pieces per placed item (drawn in the item's material color)."""
    visible_line = (lines.edge_kinds[lines.visible_edges] & EDGE_LINE) != 0
    hidden_line = (lines.edge_kinds[lines.hidden_edges] & EDGE_LINE) != 0
    edges = _Pieces(lines.visible[~visible_line], lines.visible_depth[~visible_line], lines.hidden[~hidden_line])
    items = {}
    visible_item = lines.edge_meshes[lines.visible_edges]
    hidden_item = lines.edge_meshes[lines.hidden_edges]
    for item in np.unique(np.concatenate([visible_item[visible_line], hidden_item[hidden_line]])).tolist():
        v = visible_line & (visible_item == item)
        h = hidden_line & (hidden_item == item)
        items[int(item)] = _Pieces(lines.visible[v], lines.visible_depth[v], lines.hidden[h])
    return edges, items


def _placed_meshes(scene: Scene) -> list[SceneItem]:
    """Every placed mesh, then every polyline, with inherited materials, in the order ``render`` draws them."""
    return scene.items + scene.polylines


def _lights(scene: Any) -> list[DirectionalLight]:
    lights = scene.world_lights() if callable(getattr(scene, "world_lights", None)) else getattr(scene, "lights", [])
    return [light for light in lights if isinstance(light, DirectionalLight)]


# --- numbers and paths ------------------------------------------------------------------------------------


def _number(value: float) -> str:
    """Shortest text that reads back as the same float64 (``repr``), without a trailing ``.0``: exact, stable."""
    value = float(value)
    if value == 0.0:
        return "0"
    text = repr(value)
    return text[:-2] if text.endswith(".0") else text


def _point(x: float, y: float) -> str:
    return f"{_number(x)} {_number(y)}"


def svg_path_from_polyline(points_window: ArrayLike, height: float, closed: bool = False) -> str:
    """SVG path data ``M x0 y0 L x1 y1 …`` of window points (y up), flipped to SVG's y down: $y = height − y_w$.

    Parameters
    ----------
    points_window : (N, 2) or (N, 3) array_like
        Window coordinates (extra columns, e.g. depth, are ignored), N >= 2.
    height : float
        The window height in the same units.
    closed : bool
        Append ``Z``.

    Raises
    ------
    OutputError
        For fewer than two points, a wrong shape or non-finite values.
    """
    points = _window_points(points_window, "points_window", "svg_path_from_polyline", 2)
    flip = as_scalar(height, "height", where="svg_path_from_polyline", error=OutputError)
    parts = [f"M{_point(points[0, 0], flip - points[0, 1])}"]
    parts += [f"L{_point(x, flip - y)}" for x, y in points[1:, :2]]
    return " ".join(parts) + (" Z" if closed else "")


def svg_path_from_bezier(control_points_window: ArrayLike, height: float | None = None) -> str:
    """SVG path data of a Bézier curve from its window control points: exact under a parallel projection.

    An affine map (any parallel projection and the viewport) sends the control points of a Bézier curve to
    the control points of the image curve, $A·Σ B_k,n(u) P_k = Σ B_k,n(u) A·P_k$ (the Bernstein weights sum
    to 1), so the projected curve is exactly the SVG curve with the projected controls. Degree 1 gives ``L``,
    2 a quadratic ``Q``, 3 a cubic ``C``; 3k + 1 points are read as k cubic pieces joined end to start (a
    composite Bézier spline). A perspective projection is not affine: draw a polyline of curve points instead.

    Parameters
    ----------
    control_points_window : (n + 1, 2) or (n + 1, 3) array_like
        Window coordinates, y up; 2 (line), 3 (quadratic), 4 (cubic) or 3k + 1 (k cubics) points.
    height : float, optional
        Window height: y is flipped to SVG's y down as $height − y$; None keeps y as given.

    Returns
    -------
    str
        Path data such as ``"M x0 y0 C x1 y1 x2 y2 x3 y3"``.

    Raises
    ------
    OutputError
        For a point count that is none of the above, a wrong shape or non-finite values.

    References
    ----------
    [HB 14] "Bézier Spline Curves" (affine invariance of the control points); [seed] "Bezier curves".
    """
    where = "svg_path_from_bezier"
    points = _window_points(control_points_window, "control_points_window", where, 2)
    if height is not None:
        flip = as_scalar(height, "height", where=where, error=OutputError)
        points = np.column_stack([points[:, 0], flip - points[:, 1]])
    count = points.shape[0]
    start = f"M{_point(*points[0, :2])}"
    if count == 2:
        return f"{start} L{_point(*points[1, :2])}"
    if count == 3:
        return f"{start} Q{_point(*points[1, :2])} {_point(*points[2, :2])}"
    if (count - 1) % 3 == 0:
        pieces = ["C" + " ".join(_point(*points[i + k, :2]) for k in (1, 2, 3)) for i in range(0, count - 1, 3)]
        return " ".join([start, *pieces])
    raise OutputError(
        f"{where}: control_points_window has {count} points; expected 2 (line), 3 (quadratic), 4 (cubic) or "
        "3k + 1 (k joined cubic pieces)"
    )


def _window_points(value: ArrayLike, name: str, where: str, minimum: int) -> NDArray[np.float64]:
    try:
        points = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise OutputError(f"{where}: {name} = {describe(value)} is not numeric; expected (N, 2) points") from None
    if points.ndim != 2 or points.shape[1] not in (2, 3) or points.shape[0] < minimum:
        raise OutputError(
            f"{where}: {name} has shape {points.shape}; expected (N, 2) or (N, 3) window points with N >= {minimum}"
        )
    if not np.isfinite(points).all():
        raise OutputError(f"{where}: {name} = {describe(points)} is not finite; coordinates must be finite")
    return points


# --- drawing ----------------------------------------------------------------------------------------------


def _segments_path(segments: NDArray, transform: Any) -> str:
    """One path of ``M a L b`` subpaths for (K, 2, 2) window segments mapped by `transform` to paper."""
    paper = transform(segments.reshape(-1, 2)).reshape(-1, 2, 2)
    return " ".join(f"M{_point(*a)} L{_point(*b)}" for a, b in paper)


def hidden_style(hidden: str, stroke_width: float, stroke: str = "#000000") -> str:
    """The SVG stroke attributes of hidden lines: thinner (0.7 of `stroke_width`), and dashed (4 on, 2.5 off, in
    stroke widths) in `stroke` or solid gray."""
    thin = _number(0.7 * stroke_width)
    if hidden == "dashed":
        dash = f"{_number(4 * stroke_width)} {_number(2.5 * stroke_width)}"
        return f'stroke="{stroke}" stroke-width="{thin}" stroke-dasharray="{dash}"'
    return f'stroke="{_HIDDEN_GRAY}" stroke-width="{thin}"'


def _line_groups(
    lines: HiddenLines | _Pieces, transform: Any, stroke_width: float, hidden: str | None, depth_cue: bool,
    stroke: str = "#000000",
    prefix: str = "",
) -> list[str]:  # fmt: skip
    """SVG ``<g>`` elements for the hidden pieces (drawn first) and the visible pieces of `lines`."""
    groups = []
    width = _number(stroke_width)
    if hidden is not None and lines.hidden.shape[0]:
        style = hidden_style(hidden, stroke_width, stroke)
        groups.append(
            f'<g id="{prefix}hidden" fill="none" {style} stroke-linecap="butt">'
            f'<path d="{_segments_path(lines.hidden, transform)}"/></g>'
        )
    if lines.visible.shape[0] == 0:
        return groups
    common = 'fill="none" stroke-linecap="round" stroke-linejoin="round"'
    if not depth_cue:
        groups.append(
            f'<g id="{prefix}visible" {common} stroke="{stroke}" stroke-width="{width}">'
            f'<path d="{_segments_path(lines.visible, transform)}"/></g>'
        )
        return groups
    # depth cueing: gray and width interpolated linearly in window depth between the nearest and farthest piece
    depth = lines.visible_depth.mean(axis=1)
    near, far = float(depth.min()), float(depth.max())
    weight = (depth - near) / (far - near) if far > near else np.zeros_like(depth)
    paper = transform(lines.visible.reshape(-1, 2)).reshape(-1, 2, 2)
    parts = []
    for (a, b), f in zip(paper, weight, strict=True):
        level = round(255 * _FAR_GRAY * float(f))
        line_width = stroke_width * (1.0 - (1.0 - _FAR_WIDTH) * float(f))
        parts.append(
            f'<path d="M{_point(*a)} L{_point(*b)}" stroke="#{level:02x}{level:02x}{level:02x}" '
            f'stroke-width="{_number(line_width)}"/>'
        )
    groups.append(f'<g id="{prefix}visible" {common}>{"".join(parts)}</g>')
    return groups


def _drawing_groups(
    lines: HiddenLines, placed: Sequence[SceneItem], transform: Any, stroke_width: float, hidden: str | None,
    depth_cue: bool, prefix: str = "", camera: Camera | None = None,
) -> list[str]:  # fmt: skip
    """Mesh edges in black (groups ``hidden``, ``visible``), then each polyline in its material color.

    With a parallel-projection `camera`, a polyline flattened from a Bézier-convertible curve of degree <= 3
    that is wholly visible is drawn as the exact SVG Bézier path of its projected control points.
    """
    edges, items = _split_pieces(lines)
    groups = _line_groups(edges, transform, stroke_width, hidden, depth_cue, prefix=prefix)
    for item, pieces in items.items():
        color = _hex_color(np.asarray(placed[item].material.color))
        exact = _exact_curve_path(placed[item], pieces, camera, transform) if not depth_cue else None
        if exact is not None:
            groups.append(
                f'<g id="{prefix}line{item}-visible" fill="none" stroke-linecap="round" stroke-linejoin="round" '
                f'stroke="{color}" stroke-width="{_number(stroke_width)}"><path class="bezier" d="{exact}"/></g>'
            )
            continue
        groups += _line_groups(pieces, transform, stroke_width, hidden, depth_cue, color, prefix=f"{prefix}line{item}-")
    return groups


def _exact_curve_path(item: SceneItem, pieces: _Pieces, camera: Camera | None, transform: Any) -> str | None:
    """SVG path data of the item's source curve from its projected control points, or None where that is not
    exact: a perspective camera, no source curve, degree > 3, hidden or clipped parts."""
    line = item.mesh
    curve = getattr(line, "curve", None)
    if camera is None or curve is None or not camera.projection.parallel or pieces.hidden.shape[0]:
        return None
    if hasattr(curve, "to_bezier") and not isinstance(curve, BezierCurve):
        curve = curve.to_bezier()
    if isinstance(curve, BezierCurve):
        controls = [curve.control_points]
    elif isinstance(curve, PiecewiseBezier):
        controls = list(curve.control_points)
    else:
        return None
    if any(c.shape[0] > 4 for c in controls):
        return None
    drawn = float(np.linalg.norm(pieces.visible[:, 1] - pieces.visible[:, 0], axis=1).sum())
    window_line = camera.project(line.points @ item.world_from_model[:3, :3].T + item.world_from_model[:3, 3])
    full = float(np.linalg.norm(np.diff(window_line[:, :2], axis=0), axis=1).sum())
    if not full > 0.0 or abs(drawn - full) > 1e-6 * full:  # clipped by the window or split: keep the pieces
        return None
    parts = []
    for points in controls:
        world = _padded(points) @ item.world_from_model[:3, :3].T + item.world_from_model[:3, 3]
        window = camera.project(world)[:, :2]
        paper = transform(window)
        parts.append(svg_path_from_bezier(paper))
    return " ".join(parts)


def _padded(points: NDArray) -> NDArray:
    """2D control points get z = 0, as ``Polyline`` does for the flattened curve."""
    points = np.asarray(points, dtype=np.float64)
    return np.column_stack([points, np.zeros(len(points))]) if points.shape[1] == 2 else points


def _hex_color(rgb: NDArray) -> str:
    r, g, b = (round(255 * min(max(float(c), 0.0), 1.0)) for c in rgb)
    return f"#{r:02x}{g:02x}{b:02x}"


def _centre_of_projection(camera: Camera) -> tuple[NDArray | None, NDArray | None]:
    """(eye, None) for a perspective camera, (None, view direction) for a parallel one."""
    rows = np.asarray(camera.clip_from_world)[[0, 1, 3]]
    centre = np.linalg.svd(rows)[2][-1]
    if abs(centre[3]) > 1e-12 * np.abs(centre).max():
        return np.asarray(camera.frame.eye, dtype=np.float64), None
    if camera.clip_from_world[2] @ centre > 0.0:  # make (d, 0) point toward the viewer
        centre = -centre
    return None, -centre[:3]


def _fill_polygons(
    placed: Sequence[SceneItem], lights: Sequence[DirectionalLight], camera: Camera, order: str
) -> tuple[list[str], str]:
    """``<polygon>`` elements of all faces, flat-shaded, back to front; and the name of the order used."""
    corners_parts, colors_parts, hatch_parts = [], [], []
    eye, direction = _centre_of_projection(camera)
    for mesh, material, world_from_model in placed:
        if not isinstance(mesh, Mesh) or mesh.face_count == 0:
            continue
        points = mesh.vertices @ world_from_model[:3, :3].T + world_from_model[:3, 3]
        corners = points[mesh.faces]  # (M, 3, 3)
        normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        lengths = np.linalg.norm(normals, axis=1)
        good = lengths > 0.0
        normals = normals[good] / lengths[good, None]
        corners = corners[good]
        # flat Lambert shading: k_a + k_d·max(0, N·L), N turned toward the viewer (two-sided)
        toward_viewer = (eye - corners.mean(axis=1)) if eye is not None else -direction[None, :]
        facing = np.sign((normals * toward_viewer).sum(axis=1))
        normals = normals * np.where(facing < 0, -1.0, 1.0)[:, None]
        if lights:
            lambert = sum(np.maximum(0.0, normals @ (light.to_light * light.intensity)) for light in lights)
        else:  # a headlight
            to_viewer = toward_viewer / np.linalg.norm(toward_viewer, axis=-1, keepdims=True)
            lambert = np.maximum(0.0, (normals * to_viewer).sum(axis=1))
        shade = np.clip(material.ambient + material.diffuse * lambert, 0.0, 1.0)
        corners_parts.append(corners)
        colors_parts.append(shade[:, None] * np.asarray(material.color)[None, :])
        hatch_parts.append(np.full(corners.shape[0], 0.0 if material.hatch is None else material.hatch))
    if not corners_parts:
        return [], order
    corners = np.concatenate(corners_parts)
    colors = np.concatenate(colors_parts)
    hatches = np.concatenate(hatch_parts)
    patterns: dict[float, str] = {}
    fragments, used = _back_to_front(corners, eye, direction, camera, order)
    clip_from_world = np.asarray(camera.clip_from_world)
    elements = []
    for polygon, index in fragments:
        polygon_clip = polygon @ clip_from_world[:, :3].T + clip_from_world[:, 3]
        if not (polygon_clip[:, 3] > 0).all() or np.any(np.abs(polygon_clip[:, :3]) > polygon_clip[:, 3:]):
            polygon_clip = clip_polygon(polygon_clip).vertices
            if polygon_clip.shape[0] < 3:
                continue
        ndc = polygon_clip[:, :2] / polygon_clip[:, 3:]
        x = (ndc[:, 0] + 1.0) * (camera.width / 2.0)
        y = camera.height - (ndc[:, 1] + 1.0) * (camera.height / 2.0)
        color = _hex_color(colors[index])
        points = " ".join(f"{_number(a)},{_number(b)}" for a, b in zip(x, y, strict=True))
        # a thin outline in the fill color closes the anti-aliasing seams between neighbouring polygons
        elements.append(f'<polygon points="{points}" fill="{color}" stroke="{color}" stroke-width="0.5"/>')
        spacing = float(hatches[index])
        if spacing > 0.0:  # a section cap: 45° hatching over the fill
            name = patterns.setdefault(spacing, f"hatch-{len(patterns)}")
            elements.append(f'<polygon points="{points}" fill="url(#{name})" stroke="none" class="section"/>')
    if patterns:
        definitions = "".join(
            f'<pattern id="{name}" patternUnits="userSpaceOnUse" width="{_number(spacing)}" '
            f'height="{_number(spacing)}" patternTransform="rotate(45)"><line x1="0" y1="0" x2="0" '
            f'y2="{_number(spacing)}" stroke="#000000" stroke-width="{_number(spacing / 8)}"/></pattern>'
            for spacing, name in patterns.items()
        )
        elements.insert(0, f"<defs>{definitions}</defs>")
    return elements, used


def _back_to_front(
    corners: NDArray, eye: NDArray | None, direction: NDArray | None, camera: Camera, order: str
) -> tuple[list[tuple[NDArray, int]], str]:
    if order == "bsp":  # the camera gives the true projection direction, oblique projections included
        tree = BSPTree(corners, np.arange(corners.shape[0]))
        return tree.back_to_front(camera=camera), "bsp"
    # painter's first step: farthest corner first (view-space distance along the line of sight)
    view = corners @ np.asarray(camera.view_matrix)[:3, :3].T + np.asarray(camera.view_matrix)[:3, 3]
    farthest = (-view[:, :, 2]).max(axis=1)
    ordering = np.argsort(-farthest, kind="stable")
    return [(corners[i], int(i)) for i in ordering], "depth"


def _check_common(scene: Any, stroke_width: Any, hidden: Any, where: str) -> float:
    if not isinstance(scene, Scene):
        raise FrustumError(f"{where}: scene = {describe(scene)} is not a Scene; build one with Scene() and add meshes")
    width = as_scalar(stroke_width, "stroke_width", where=where, error=OutputError)
    if not width > 0.0:
        raise OutputError(f"{where}: stroke_width = {width!r} must be > 0; give a line width in drawing units")
    if hidden not in HIDDEN_STYLES:
        raise OutputError(
            f"{where}: hidden = {describe(hidden)} is unknown; expected one of 'dashed', 'dimmed' or None"
        )
    return width


def render_svg(
    scene: Scene,
    camera: Camera,
    *,
    edges: str | Sequence[str] = "feature",
    crease_angle: float = DEFAULT_CREASE_ANGLE,
    hidden: str | None = "dashed",
    fill: bool = False,
    fill_order: str = "bsp",
    stroke_width: float = 1.0,
    depth_cue: bool = False,
    background: str | None = "#ffffff",
    shadows: bool = False,
) -> str:
    """An SVG line drawing of `scene` seen by `camera`, hidden lines removed exactly (object space).

    Mesh edges are drawn black; ``Polyline`` geometry (curves, control polygons) in its material's color,
    hidden by faces like any edge (groups ``line<k>-visible`` / ``line<k>-hidden`` for the k-th placed item).
    The SVG has ``width`` × ``height`` = the camera's image size, one user unit per pixel, y down:
    a window point (x, y_w) is drawn at (x, height − y_w). Visible pieces are solid, hidden pieces dashed or
    gray (``hidden``); with ``depth_cue`` each visible piece gets a gray level and a width that fall off
    linearly with window depth, $f = (z − z_near)/(z_far − z_near)$: gray = 0.75·f, width ·(1 − 0.6·f).
    Placed volumes (``Scene.add_volume``) have no vector form: their ray-cast picture (``render``'s kernels)
    is embedded as one PNG ``<image>`` in the group ``volumes`` over the faces and lines, each ray stopped at the
    nearest face or visible line (``frustum.output.svg_volumes``).

    Parameters
    ----------
    scene : Scene
    camera : Camera
    edges : {"feature", "silhouette", "crease", "boundary", "all"} or a sequence of them
        Which mesh edges to draw (``remove_hidden_lines``).
    crease_angle : float
        Radians: the dihedral angle above which an edge is a crease.
    hidden : {"dashed", "dimmed"} or None
        Style of the hidden pieces, or None to leave them out.
    fill : bool
        Paint every face as a flat-shaded polygon (Lambert with the scene's directional lights, or a headlight),
        back to front, under the lines.
    fill_order : {"bsp", "depth"}
        ``"bsp"``: ``frustum.visibility.bsp.BSPTree`` order, splitting faces where no order exists (exact; cost grows
        faster than linearly, fine to some ten thousand faces). ``"depth"``: sort faces by their farthest
        corner (fast; may be wrong where faces overlap cyclically or interpenetrate).
    stroke_width : float
        Visible line width in pixels (> 0); hidden lines are 0.7 of it.
    depth_cue : bool
        Fade and thin distant visible lines.
    background : str or None
        A CSS color for a full-size background rectangle, or None for transparent.
    shadows : bool
        Add the exact shadow regions of every directional and point light that casts shadows on the visible
        faces (``frustum.output.svg_shadows``: the object-space method from the light, then the visible parts
        from the camera) as the group ``<g id="shadows">`` of ``<path>`` elements (absolute M/L/Z): translucent
        gray over the faces with `fill`, hatched at 45° otherwise; under the lines. ``sun_45()`` is the
        sciagraphy light.

    Returns
    -------
    str
        The SVG document (UTF-8 text, starting with the XML declaration).

    Raises
    ------
    FrustumError
        If `scene` is not a Scene or `camera` not a Camera, or edges / crease_angle are invalid.
    OutputError
        For a bad stroke width, hidden style or fill order.

    References
    ----------
    [HB 16] "Wire-Frame Visibility Methods", "BSP-Tree Method", "Depth-Sorting Method"; [seed] "Depth cueing".
    """
    where = "render_svg"
    width = _check_common(scene, stroke_width, hidden, where)
    if not isinstance(camera, Camera):
        raise FrustumError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at")
    if fill_order not in FILL_ORDERS:
        raise OutputError(f"{where}: fill_order = {describe(fill_order)} is unknown; expected 'bsp' or 'depth'")
    placed = _placed_meshes(scene)
    lines = remove_hidden_lines(
        [(item.mesh, item.world_from_model) for item in placed], camera, edges=edges, crease_angle=crease_angle
    )
    height = float(camera.height)

    def to_paper(points: NDArray) -> NDArray:
        return np.column_stack([points[:, 0], height - points[:, 1]])

    body = []
    if background is not None:
        body.append(f'<rect width="{camera.width}" height="{camera.height}" fill="{_escape(str(background))}"/>')
    if fill:
        polygons, used = _fill_polygons(placed, _lights(scene), camera, fill_order)
        body.append(f'<g id="faces" data-order="{used}">{"".join(polygons)}</g>')
    if not isinstance(shadows, bool | np.bool_):
        raise OutputError(f"{where}: shadows = {describe(shadows)} is not a bool; give True or False")
    if shadows:
        from frustum.output.svg_shadows import shadow_group

        body.append(shadow_group(scene, camera, fill=bool(fill)))
    body += _drawing_groups(lines, placed, to_paper, width, hidden, bool(depth_cue), camera=camera)
    if scene.volumes:  # a raster layer over faces and lines, its rays stopped by both (output/svg_volumes.py)
        from frustum.output.svg_volumes import volume_image_element

        body.append(volume_image_element(scene, camera, lines.visible, lines.visible_depth, width))
    if getattr(scene, "particle_layers", None):  # dots and segments over the drawing (output/svg_particles.py)
        from frustum.output.svg_particles import particle_elements

        body += particle_elements(scene, camera)
    return svg_document(camera.width, camera.height, body)


def svg_document(width: float, height: float, body: Sequence[str], units: str = "") -> str:
    """The SVG text around `body` elements: ``width``/``height`` (with `units`, e.g. "mm") and a viewBox."""
    w, h = _number(width), _number(height)
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<svg xmlns="{_SVG_NAMESPACE}" version="1.1" width="{w}{units}" height="{h}{units}" '
        f'viewBox="0 0 {w} {h}">\n' + "\n".join(body) + "\n</svg>\n"
    )


def save_svg(svg_text: str, path: str | os.PathLike) -> Path:
    """Write an SVG document to `path`: ``.svg`` as text, ``.pdf`` (vector) or ``.png`` through cairosvg.

    Raises
    ------
    OutputError
        If `svg_text` is not a string, the suffix is none of the three, or the file cannot be written.
    """
    where = "save_svg"
    if not isinstance(svg_text, str):
        raise OutputError(f"{where}: svg_text = {describe(svg_text)} is not a string; pass what render_svg returns")
    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in (".svg", ".pdf", ".png"):
        raise OutputError(f"{where}: path = {str(target)!r} has suffix {suffix!r}; expected '.svg', '.pdf' or '.png'")
    convert = None
    if suffix != ".svg":
        try:
            import cairosvg
        except ImportError:
            raise OutputError(
                f"{where}: path = {str(target)!r} asks for {suffix[1:].upper()}, which needs the cairosvg package "
                "(pip install cairosvg); or write a '.svg'"
            ) from None
        convert = cairosvg.svg2pdf if suffix == ".pdf" else cairosvg.svg2png
    with atomic_path(target, where=where) as temporary:  # the old file survives a failed or interrupted write
        try:
            if convert is None:
                temporary.write_text(svg_text, encoding="utf-8")
            else:
                convert(bytestring=svg_text.encode("utf-8"), write_to=str(temporary))
        except (OSError, MemoryError) as error:
            raise OutputError(
                f"{where}: path = {str(target)!r} cannot be written ({os_reason(error)}); choose a writable "
                "location with free space"
            ) from None
        except Exception as error:  # cairo reports a failed write as its own error with a status number
            raise OutputError(
                f"{where}: path = {str(target)!r} cannot be written: cairo failed ({_cairo_reason(error)}); choose "
                "a writable location with free space"
            ) from None
    return target


def _cairo_reason(error: Exception) -> str:
    """cairo's status as words: ``(11)`` is CAIRO_STATUS_WRITE_ERROR, a full disk or a lost file."""
    status = getattr(error, "status", None)
    if status is None and error.args and isinstance(error.args[-1], int):
        status = error.args[-1]
    words = {1: "out of memory", 11: "write error: the disk is full or the file cannot be written",
             13: "invalid size: the drawing is too large"}  # fmt: skip
    if isinstance(status, int) and status in words:
        return words[status]
    text = " ".join(str(error).split())
    return text[:120] if text else type(error).__name__
