"""Clipping, step by step: Cohen–Sutherland region codes, Liang–Barsky parameters, Sutherland–Hodgman planes.

Each function runs the production clipper (``frustum.clipping.clip_line`` / ``clip_polygon``) with its
``record=`` hook and turns the events into ``Step`` records; ``Steps.result`` is what the production call
returned. Points are clip-space ``(x, y, z, w)``; a Cartesian ``(x, y, z)`` is taken with $w = 1$ (a point of
the normalized view volume $[−1, 1]³$).

References: [HB 10] "Three-Dimensional Point and Line Clipping", "Three-Dimensional Polygon Clipping";
[seed] "Three-dimensional Region Codes", "3D Point and Line Clipping", "3D Polygon clipping".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum import clipping
from frustum.clipping.codes import point4
from frustum.errors import ClippingError
from frustum.steps._draw import PLANE_NAMES, bounds_of, cartesian, draw_cube, oblique
from frustum.steps._record import Step, Steps, _Canvas, check_recording, format_value

__all__ = ["cohen_sutherland", "liang_barsky", "sutherland_hodgman"]

_BYTES_PER_CLIPPED_VERTEX = 5500.0
"""Peak memory of ``sutherland_hodgman`` and its sheet per input vertex: 5.3–5.5 KB measured with 1,000 and 5,000
vertices (tracemalloc): seven figures, each with every vertex's polyline point, dot and label."""


def _homogeneous(value: ArrayLike, name: str, where: str) -> NDArray[np.float64]:
    array = np.asarray(value, dtype=float) if np.ndim(value) else None
    if array is not None and array.shape == (3,):
        return np.append(array, 1.0)
    return point4(value, name, where)


def _polygon(value: ArrayLike, where: str) -> NDArray[np.float64]:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ClippingError(f"{where}: vertices = {value!r} is not numeric; give (N, 3) or (N, 4) points") from None
    if array.ndim == 2 and array.shape[1] == 3:
        array = np.column_stack([array, np.ones(array.shape[0])])
    return array


def _recorder() -> tuple[list[tuple[str, dict[str, Any]]], Any]:
    events: list[tuple[str, dict[str, Any]]] = []

    def record(event: str, **values: Any) -> None:
        events.append((event, values))

    return events, record


def _plane_name(k: int) -> str:
    return PLANE_NAMES[k] if k < len(PLANE_NAMES) else f"user plane {k - len(PLANE_NAMES) + 1}"


def _code(code: int, bits: int) -> str:
    return format(int(code), f"0{bits}b")


def _segment_bounds(points_h: list[NDArray]) -> tuple[float, float, float, float]:
    from frustum.steps._draw import CUBE_CORNERS

    return bounds_of(np.vstack([oblique(CUBE_CORNERS), oblique(cartesian(np.array(points_h)))]))


# --- Cohen–Sutherland --------------------------------------------------------------------------------------


def cohen_sutherland(p0: ArrayLike, p1: ArrayLike, planes: ArrayLike | None = None) -> Steps:
    """Cohen–Sutherland 3D, step by step: both region codes, each trivial test, each intersection.

    Runs ``clip_line(p0, p1, method="cohen-sutherland", planes=planes, record=...)``; ``result`` is its
    ``ClippedSegment`` (or None).

    Parameters
    ----------
    p0, p1 : (4,) or (3,) array_like
        Clip-space ends (``(x, y, z)`` means w = 1).
    planes : (K, 4) array_like, optional
        Extra clip-space planes, as in ``clip_line``.
    """
    start = _homogeneous(p0, "p0", "steps.cohen_sutherland")
    end = _homogeneous(p1, "p1", "steps.cohen_sutherland")
    events, record = _recorder()
    result = clipping.clip_line(start, end, method="cohen-sutherland", planes=planes, record=record)
    bits = 6 + (0 if planes is None else np.atleast_2d(np.asarray(planes)).shape[0])
    steps: list[Step] = []
    frames: list[dict[str, Any]] = []  # what each step's figure shows
    ends = [start, end]
    first = events[0][1]
    codes = first["codes"]
    steps.append(
        Step(
            "Region codes of both endpoints",
            "Each end gets a 6-bit region code, one bit per plane of the view volume (bit 1 left, 2 right, 3 bottom, "
            "4 top, 5 near, 6 far, written right to left): a bit is 1 when the end lies outside that plane "
            "(w + x < 0 for left, w − x < 0 for right, ...).",
            {"P1": start, "P2": end, "code P1": _code(codes[0], bits), "code P2": _code(codes[1], bits)},
        )
    )
    frames.append({"ends": list(ends), "codes": codes})
    for event, values in events[1:] if events[0][0] == "codes" else events:
        if event == "intersect":
            i, k = values["end"], values["plane"]
            ends[i] = values["point"]
            steps.append(Step(
                f"Move P{i + 1} onto the {_plane_name(k)} plane",
                f"Neither trivially accepted nor rejected: P{i + 1} is outside, and its lowest set bit names the "
                f"{_plane_name(k)} plane. The intersection is at t = d_out / (d_out − d_in) along the segment "
                "from the outside end; the moved end's code is recomputed.",
                {"plane": _plane_name(k), "d_out": values["d_out"], "d_in": values["d_in"], "t": values["t"],
                 "u": values["u"], f"new P{i + 1}": values["point"]},
            ))  # fmt: skip
            frames.append({"ends": list(ends), "highlight_end": i, "face": k})
        elif event == "codes":
            codes = values["codes"]
            steps[-1] = Step(
                steps[-1].title,
                steps[-1].text,
                {**steps[-1].values, "code P1": _code(codes[0], bits), "code P2": _code(codes[1], bits)},
            )
            frames[-1]["codes"] = codes
        elif event == "accept":
            c = values["codes"]
            steps.append(Step(
                "Trivially accepted",
                "Both codes are 000000 (c1 OR c2 = 0): the whole remaining segment lies inside the view volume "
                "and is kept.",
                {"c1 | c2": _code(c[0] | c[1], bits), "start": result.start, "end": result.end,
                 "u": (result.u_start, result.u_end)},
            ))  # fmt: skip
            frames.append({"ends": list(ends), "codes": c, "kept": True})
        elif event == "reject":
            c = values["codes"]
            steps.append(
                Step(
                    "Trivially rejected",
                    "c1 AND c2 is not 0: both ends lie outside the same plane, so the segment is invisible and is "
                    "discarded without computing any intersection.",
                    {"c1": _code(c[0], bits), "c2": _code(c[1], bits), "c1 & c2": _code(values["common"], bits)},
                )
            )
            frames.append({"ends": list(ends), "codes": c, "kept": False})
        elif event == "parallel":
            steps.append(
                Step(
                    "Rejected: parallel to a plane it is outside of",
                    f"P{values['end'] + 1} is outside the {_plane_name(values['plane'])} plane and the segment runs "
                    "parallel to it, so no part of it can be inside.",
                    {"plane": _plane_name(values["plane"])},
                )
            )
            frames.append({"ends": list(ends), "kept": False})
    original = [start, end]

    def paint(index: int, canvas: _Canvas) -> None:
        frame = frames[index]
        draw_cube(canvas, face=frame.get("face"))
        a, b = oblique(cartesian(np.array(original)))
        canvas.line(a, b, color="faint", dash=True)
        p, q = oblique(cartesian(np.array(frame["ends"])))
        color = {True: "accept", False: "reject"}.get(frame.get("kept"), "blue")
        canvas.line(p, q, color=color, width=3.0)
        codes = frame.get("codes")
        for j, point in enumerate((p, q)):
            label = f"P{j + 1}" + (f" {_code(codes[j], bits)}" if codes is not None else "")
            canvas.dot(point, color="highlight" if frame.get("highlight_end") == j else "ink", label=label)

    return Steps("Cohen–Sutherland line clipping", steps, result, paint, _segment_bounds(original))


# --- Liang–Barsky -------------------------------------------------------------------------------------------


def liang_barsky(p0: ArrayLike, p1: ArrayLike, planes: ArrayLike | None = None) -> Steps:
    """Liang–Barsky, step by step: ``p_k``, ``q_k`` and the interval ``[u1, u2]`` after each boundary.

    Runs ``clip_line(p0, p1, method="liang-barsky", planes=planes, record=...)`` (the Python twin of the
    kernel, equal to it bit for bit); ``result`` is its ``ClippedSegment`` (or None). The notes' ``u1, u2`` are
    the segment's ``u_start, u_end``.
    """
    start = _homogeneous(p0, "p0", "steps.liang_barsky")
    end = _homogeneous(p1, "p1", "steps.liang_barsky")
    events, record = _recorder()
    result = clipping.clip_line(start, end, method="liang-barsky", planes=planes, record=record)
    direction = end - start
    steps = [
        Step(
            "Parametric segment P = P1 + (P2 − P1)u",
            "The visible part is an interval of u. For each boundary k, p_k = d_k(P1) − d_k(P2) and q_k = d_k(P1), "
            "with d_k the plane's inside-positive value; the inside satisfies p_k·u <= q_k. Start with u1 = 0, u2 = 1.",
            {"P1": start, "P2": end, "u1": 0.0, "u2": 1.0},
        )
    ]
    intervals: list[tuple[float, float, int | None]] = [(0.0, 1.0, None)]
    for event, values in events:
        if event == "plane":
            k, p, q, case = values["plane"], values["p"], values["q"], values["case"]
            rule = {
                "entering": "p_k < 0, the segment enters here: u1 = max(u1, q_k/p_k)",
                "leaving": "p_k > 0, the segment leaves here: u2 = min(u2, q_k/p_k)",
                "parallel, inside": "p_k = 0, parallel to the boundary and q_k >= 0 (inside): no change",
                "parallel, outside": "p_k = 0 and q_k < 0: parallel and outside, rejected",
            }[case]
            row = {"k": k + 1, "boundary": _plane_name(k), "p_k": p, "q_k": q}
            if p != 0.0:
                row["r_k = q_k/p_k"] = q / p
            row.update({"u1": values["u0"], "u2": values["u1"]})
            steps.append(Step(f"Boundary {k + 1} ({_plane_name(k)}): {case}", rule + ".", row))
            intervals.append((values["u0"], values["u1"], k))
        elif event == "reject":
            steps.append(Step(
                "Rejected: u1 > u2", "The interval is empty (or the segment is parallel and outside): nothing "
                "of it is inside the view volume.", {"u1": intervals[-1][0], "u2": intervals[-1][1]},
            ))  # fmt: skip
            intervals.append((intervals[-1][0], intervals[-1][1], None))
        elif event == "accept":
            steps.append(
                Step(
                    "Visible part: P(u1) to P(u2)",
                    "After every boundary u1 <= u2: the clipped segment runs from P1 + (P2 − P1)·u1 to "
                    "P1 + (P2 − P1)·u2 (an end with u1 = 0 or u2 = 1 is kept as it was).",
                    {"u1": values["u0"], "u2": values["u1"], "start": result.start, "end": result.end},
                )
            )
            intervals.append((values["u0"], values["u1"], None))

    def paint(index: int, canvas: _Canvas) -> None:
        u_low, u_high, face = intervals[index]
        draw_cube(canvas, face=face)
        a, b = oblique(cartesian(np.array([start, end])))
        canvas.line(a, b, color="faint", dash=True)
        final = index == len(steps) - 1
        if u_low <= u_high:
            p, q = oblique(cartesian(np.array([start + direction * u_low, start + direction * u_high])))
            canvas.line(p, q, color="accept" if final else "blue", width=3.0)
            canvas.dot(p, color="highlight", label=f"u1 = {format_value(u_low)}")
            canvas.dot(q, color="highlight", label=f"u2 = {format_value(u_high)}")
        elif final:
            canvas.line(a, b, color="reject", width=2.0)
        canvas.dot(a, label="P1")
        canvas.dot(b, label="P2")

    return Steps("Liang–Barsky line clipping", steps, result, paint, _segment_bounds([start, end]))


# --- Sutherland–Hodgman ------------------------------------------------------------------------------------


def sutherland_hodgman(vertices_h: ArrayLike, planes: ArrayLike | None = None) -> Steps:
    """Sutherland–Hodgman, step by step: the polygon after each clipping plane.

    Runs ``clip_polygon(vertices_h, planes=planes, record=...)``; ``result`` is its ``ClippedPolygon``.
    Vertices are (N, 4) clip-space points, or (N, 3) taken with w = 1.
    """
    vertices = _polygon(vertices_h, "steps.sutherland_hodgman")
    if vertices.ndim == 2:  # a figure per plane, each drawing the polygon (at most N + 6 vertices) and its labels
        check_recording(math.log(max(len(vertices), 1)), _BYTES_PER_CLIPPED_VERTEX, "steps.sutherland_hodgman",
                        f"a recording of a polygon of {len(vertices)} vertices")  # fmt: skip
    events, record = _recorder()
    result = clipping.clip_polygon(vertices, planes=planes, record=record)
    steps: list[Step] = []
    shown: list[tuple[NDArray, NDArray | None, int | None]] = []
    for event, values in events:
        if event == "start":
            steps.append(
                Step(
                    "The polygon before clipping",
                    "Sutherland–Hodgman clips the whole polygon against one plane at a time: each edge S → E adds "
                    "E (both in), the intersection (leaving), the intersection then E (entering), or nothing.",
                    {"vertices": len(values["polygon"])},
                )
            )
            shown.append((values["polygon"], None, None))
        elif event == "plane":
            k, d = values["plane"], values["distances"]
            inside = int(np.count_nonzero(d >= 0))
            steps.append(Step(
                f"After the {_plane_name(k)} plane",
                f"Vertices inside the {_plane_name(k)} plane (d >= 0) are kept; each edge crossing it contributes "
                "its intersection P = P_in + (P_out − P_in)·u with u = d_in / (d_in − d_out).",
                {"inside before": f"{inside} of {len(d)}", "vertices after": len(values["polygon"]),
                 "d": np.round(d, 6)},
            ))  # fmt: skip
            shown.append((values["polygon"], values["before"], k))
    steps.append(
        Step(
            "Clipped polygon",
            "The polygon left after every plane; fewer than 3 vertices (or none with w > 0) means nothing is visible.",
            {"vertices": len(result.vertices)},
        )
    )
    shown.append((result.vertices, None, None))
    everything = np.vstack([vertices] + [s[0] for s in shown if len(s[0])])

    def paint(index: int, canvas: _Canvas) -> None:
        polygon, before, face = shown[index]
        draw_cube(canvas, face=face)
        canvas.polyline(oblique(cartesian(vertices)), color="faint", closed=True, dash=True)
        if before is not None and len(before):
            canvas.polyline(oblique(cartesian(before)), color="faint", closed=True)
        if len(polygon):
            final = index == len(shown) - 1
            canvas.polyline(oblique(cartesian(polygon)), color="accept" if final else "blue", closed=True,
                            fill="accept" if final else "blue", opacity=0.2, width=2.5)  # fmt: skip
            for j, point in enumerate(oblique(cartesian(polygon))):
                canvas.dot(point, color="highlight", radius=3.0, label=str(j + 1))

    from frustum.steps._draw import CUBE_CORNERS

    bounds = bounds_of(np.vstack([oblique(CUBE_CORNERS), oblique(cartesian(everything))]))
    return Steps("Sutherland–Hodgman polygon clipping", steps, result, paint, bounds)
