"""Dimensions of a sheet (ISO 129-1): overall extents per view or each part's sizes, diameters and radii, placed in
view-local paper millimetres with thin lines, closed filled arrowheads and 3.5 mm lettering; centre lines in the
long-dashed dotted narrow line (ISO 128-2 type 04)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum.output.sheet.layout import marks_clash
from frustum.output.sheet.model import (
    ARROW_LENGTH,
    DIMENSION_OFFSET,
    DIMENSION_SPACING,
    END_ON_ANGLE,
    EXTENSION_BEYOND,
    EXTENSION_GAP,
    LABEL_DROP,
    LEADER_RISE,
    LETTER,
    Mark,
    SheetView,
    marks_box,
    to_local,
)
from frustum.output.sheet.views import circle_key
from frustum.output.true_curves import Circle


def dimension_text(value: float) -> str:
    """A dimension value as a drafter writes it: four significant digits, at most six decimals, no trailing
    zeros (``40``, ``2.4``, ``0.16``, ``1235``)."""
    value = float(value)
    if value == 0.0:
        return "0"
    decimals = min(6, max(0, 3 - math.floor(math.log10(abs(value)))))
    text = f"{round(value, decimals):.{decimals}f}"
    return text.rstrip("0").rstrip(".") if "." in text else text


def view_marks(view: SheetView, scale: float, dimensions: str | None, plan: _Plan | None = None) -> list[Mark]:
    """Centre lines of end-on circles, dimensions (overall extents or each part's sizes, diameters) and the
    label of one view."""
    marks: list[Mark] = []
    paper = view.local * scale
    x0, y0 = paper.min(axis=0)
    x1, y1 = paper.max(axis=0)
    orthographic = view.name != "isometric"
    if orthographic and (view.circles or view.axes):
        centres = Mark("centre", "centre-lines")
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
        marks += _diameters(view, scale, min(y0, float(marks_box(marks)[1])), plan.leaders[view.name])
        marks += _radius_leaders(view, scale, plan.radii.get(view.name, []))
    elif dimensions == "overall" and orthographic:
        model = view.local.max(axis=0) - view.local.min(axis=0)
        tolerance = 1e-9 * max(x1 - x0, y1 - y0, 1e-300)
        # horizontal: below the view, extension lines from the lowest point on each extreme vertical
        # (a part seen edge-on, of no width or height, has nothing to dimension that way)
        if model[0] > 1e-12 * model.max():
            feet = [float(paper[np.abs(paper[:, 0] - x) <= tolerance, 1].max()) for x in (x0, x1)]
            marks.append(_linear("horizontal", float(model[0]), (x0, feet[0]), (x1, feet[1]), y1 + DIMENSION_OFFSET))
        # vertical: right of the view, extension lines from the rightmost point on each extreme horizontal
        if model[1] > 1e-12 * model.max():
            feet = [float(paper[np.abs(paper[:, 1] - y) <= tolerance, 0].max()) for y in (y0, y1)]
            marks.append(_linear("vertical", float(model[1]), (feet[0], y0), (feet[1], y1), x1 + DIMENSION_OFFSET))
        marks += _diameters(view, scale, y0)
    bottom = max(float(marks_box(marks)[3]), y1)
    label = Mark("label", "label")
    label.texts.append(((x0 + x1) / 2.0, bottom + LABEL_DROP, f"{view.name.upper()} VIEW", "middle", False))
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
    mark = Mark("dimension", mark_name or f"dimension-{name}", value)
    horizontal = name == "horizontal"
    axis = 0 if horizontal else 1
    low, high = a[axis], b[axis]
    mark.definition = ("linear", a, b, at, horizontal)
    for point in (a, b):
        foot = point[1 - axis]
        sign = 1.0 if at >= foot else -1.0
        start, end = foot + sign * EXTENSION_GAP, at + sign * EXTENSION_BEYOND
        mark.lines.append((point[0], start, point[0], end) if horizontal else (start, point[1], end, point[1]))
    inside = high - low >= 2 * ARROW_LENGTH + 1.0
    reach = 0.0 if inside else ARROW_LENGTH + 2.0
    mark.lines.append((low - reach, at, high + reach, at) if horizontal else (at, low - reach, at, high + reach))
    outward = -1.0 if inside else 1.0  # direction of travel of the low arrow: tips outward, or inward from outside
    for tip, sign in ((low, outward), (high, -outward)):
        mark.arrows.append((tip, at, sign, 0.0) if horizontal else (at, tip, 0.0, sign))
    middle = (low + high) / 2.0
    text = prefix + dimension_text(value)
    run = 0.6 * LETTER * len(text)
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


def _centre_lines(mark: Mark, centre: NDArray, radius: float) -> None:
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


def _diameter_groups(view: SheetView) -> list[tuple[float, list[NDArray]]]:
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
    view: SheetView, scale: float, top: float, groups: list[tuple[float, list[NDArray], str]] | None = None
) -> list[Mark]:
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
        mark = Mark("diameter", f"diameter-{index}", 2.0 * radius)
        tip = centres[-1] * scale + radius * scale * unit
        level = top - LEADER_RISE - 6.0 * index
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


@dataclass
class _Plan:
    """Which view states which size of which part: per view, linear dimensions (part, "horizontal" or
    "vertical", symbol before the value) and diameter leaders (radius, local centres, symbol)."""

    linear: dict[str, list[tuple[int, str, str]]]
    leaders: dict[str, list[tuple[float, list[NDArray], str]]]
    radii: dict[str, list[tuple[float, list[tuple[NDArray, NDArray]]]]] = field(default_factory=dict)


def plan_parts(
    views: list[SheetView], circles: list[Circle], parts_world: list[NDArray], meshes_ids: list[int], size: float
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
            key = circle_key(circle, size)
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


def _plan_radius(circle: Circle, ortho: list[SheetView], radii: dict, size: float) -> None:
    """An arc's radius goes to the first aligned view that sees it end-on: (local centre, local middle point),
    with the other arcs of its radius there ("n× R")."""
    for view in ortho:
        direction = np.asarray(view.camera.frame.direction)
        if abs(float(circle.normal @ direction)) < math.cos(END_ON_ANGLE) or circle.middle is None:
            continue
        ends = view.camera.project(np.stack([circle.centre, circle.middle]))[:, :2]
        local = to_local(ends, view.model_per_pixel)
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


def _radius_leaders(view: SheetView, scale: float, groups: list) -> list[Mark]:
    """One leader per radius of the view's arcs: arrowhead on the arc's middle, pointing at its centre, a line
    8 mm outward along the radius, a 3 mm shoulder and "R r" (or "n× R r")."""
    marks = []
    for index, (radius, arcs) in enumerate(sorted(groups, key=lambda group: -group[0])):
        centre, middle = (np.asarray(p) * scale for p in arcs[-1])
        outward = middle - centre
        outward = outward / max(float(np.linalg.norm(outward)), 1e-300)
        knee = middle + 8.0 * outward
        side = 1.0 if outward[0] >= 0.0 else -1.0
        mark = Mark("radius", f"radius-{index}", radius)
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


def _best_view(ortho: list[SheetView], part: int, axis: int, linear: dict) -> SheetView | None:
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


def _part_dimensions(view: SheetView, scale: float, specs: list[tuple[int, str, str]]) -> list[Mark]:
    """The linear dimensions `specs` of one view, stacked outward from the view at ``DIMENSION_SPACING``
    (horizontal ones below it, else above; vertical ones right of it, else left): shorter ones first, each on
    the nearest level where it clashes with no dimension placed before (``marks_clash``: no extension line across
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
    marks: list[Mark] = []
    deepest: dict[tuple[str, float], int] = {}  # deepest level used per orientation and side
    for value, orientation, part, symbol, points in items:
        axis = 0 if orientation == "horizontal" else 1
        # (sign away from the view, first level's position): below / right first, then above / left
        sides = [(1.0, (y1 if axis == 0 else x1) + DIMENSION_OFFSET),
                 (-1.0, (y0 if axis == 0 else x0) - DIMENSION_OFFSET)]  # fmt: skip
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
                at = base + sign * level * DIMENSION_SPACING
                for text_side in ("fit", "after", "before"):
                    mark = _linear(orientation, value, ends[0], ends[1], at, mark_name=name, prefix=symbol,
                                   text_side=text_side)  # fmt: skip
                    if mark is not None and not any(marks_clash(mark, other) for other in marks):
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
            chosen = _linear(orientation, value, ends[0], ends[1], sides[0][1] + level * DIMENSION_SPACING,
                             mark_name=name, prefix=symbol)  # fmt: skip
        marks.append(chosen)
    return marks
