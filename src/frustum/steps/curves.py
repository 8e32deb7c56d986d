"""Curves, step by step: de Casteljau's construction and subdivision, Cox–de Boor level by level, Hermite blending.

References: [HB 14] "Bézier Curves", "B-Spline Curves", "Hermite Interpolation"; [seed] "Bezier Curve",
"B-Spline Curve", "Hermite Spline".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_scalar
from frustum.errors import GeometryError
from frustum.geometry import curves
from frustum.geometry.curves import _validation, bezier
from frustum.steps._draw import bounds_of
from frustum.steps._record import Step, Steps, _Canvas, check_recording, format_value

__all__ = ["b_spline_basis", "de_casteljau", "hermite"]

_LEVEL_COLORS = ("ink", "blue", "purple", "accept", "highlight", "reject")
_BYTES_PER_DRAWN_CONTROL_POINT = 650.0
"""Peak memory of ``de_casteljau`` and its sheet per drawn point (a dot and a polyline vertex in a figure): 609–695 B
measured with 30 and 60 control points (tracemalloc)."""


def de_casteljau(control_points: ArrayLike, t: float = 0.5) -> Steps:
    """de Casteljau's construction at `t`, level by level, then the subdivision into two halves.

    Runs the production split (``BezierCurve.split``'s ``_split_batch`` with its ``record`` hook): level j holds
    $P_i^j = (1 − t)·P_i^{j−1} + t·P_{i+1}^{j−1}$; the last level is the point ``C(t)``. ``result`` is
    ``(C(t), (left, right))`` — the point (equal to ``BezierCurve.evaluate(t)``) and the two halves' control
    points (equal to ``BezierCurve.split(t)``). 2D or 3D control points (drawn in x, y).
    """
    where = "steps.de_casteljau"
    curve = curves.BezierCurve(control_points)
    s = as_scalar(t, "t", where=where, error=GeometryError)
    if not 0.0 <= s <= 1.0:
        raise GeometryError(f"{where}: t = {s!r} lies outside [0.0, 1.0]; give 0 <= t <= 1")
    points = curve.control_points
    n = len(points)
    # figure j draws levels 0…j, level i holding n − i points: Σ_m m² = n(n+1)(2n+1)/6 drawn points in all
    check_recording(math.log(n * (n + 1) * (2 * n + 1) / 6), _BYTES_PER_DRAWN_CONTROL_POINT, where,
                    f"a recording of {n} control points (cubic in their number)")  # fmt: skip
    levels: list[NDArray] = [points]
    left, right = bezier._split_batch(points[None], s, record=lambda level: levels.append(level[0].copy()))
    point = levels[-1][0]
    result = (point, (left[0], right[0]))
    steps = [Step(
        f"Control polygon (degree {curve.degree}), t = {format_value(s)}",
        "The Bézier curve C(t) = Σ P_k·BEZ_k,n(t). de Casteljau evaluates it by repeated linear interpolation "
        "of the control polygon's edges at the same ratio t : (1 − t).",
        {"P": points},
    )]  # fmt: skip
    for j, level in enumerate(levels[1:], start=1):
        steps.append(Step(
            f"Level {j}: {len(level)} point{'s' if len(level) > 1 else ''}",
            f"P_i^{j} = (1 − t)·P_i^{j - 1} + t·P_(i+1)^{j - 1}: each new point divides an edge of the previous "
            "level's polygon at t." + (" One point is left: it is C(t)." if len(level) == 1 else ""),
            {f"P^{j}": level},
        ))  # fmt: skip
    steps.append(Step(
        "Subdivision at t",
        "The first points of every level (P_0^0, P_0^1, …) are the control points of the curve on [0, t]; the last "
        "points (…, P_(n−1)^1, P_n^0) those on [t, 1]. Each half is again a Bézier curve.",
        {"left": left[0], "right": right[0]},
    ))  # fmt: skip
    samples = curve.evaluate(np.linspace(0.0, 1.0, 101))

    def paint(index: int, canvas: _Canvas) -> None:
        canvas.polyline(samples[:, :2], color="faint", width=2.0)
        if index == len(steps) - 1:
            canvas.polyline(curves.BezierCurve(left[0]).evaluate(np.linspace(0, 1, 51))[:, :2], color="blue",
                            width=3.0)  # fmt: skip
            canvas.polyline(curves.BezierCurve(right[0]).evaluate(np.linspace(0, 1, 51))[:, :2], color="accept",
                            width=3.0)  # fmt: skip
            canvas.polyline(left[0][:, :2], color="blue", dash=True)
            canvas.polyline(right[0][:, :2], color="accept", dash=True)
            canvas.dot(point[:2], color="highlight", radius=5.0, label="C(t)")
            return
        for j, level in enumerate(levels[: index + 1]):
            color = _LEVEL_COLORS[j % len(_LEVEL_COLORS)] if j == index else "faint"
            canvas.polyline(level[:, :2], color=color, width=1.5)
            for i, p in enumerate(level):
                canvas.dot(p[:2], color=color, radius=3.5 if j == index else 2.5,
                           label=f"P{i}^{j}" if j == index and len(level) < 8 else "")  # fmt: skip
        if index == len(levels) - 1:
            canvas.dot(point[:2], color="highlight", radius=5.0, label="C(t)")

    return Steps("de Casteljau's algorithm", steps, result, paint, bounds_of(points[:, :2]))


def b_spline_basis(knots: ArrayLike, order: int, u: float | None = None, samples: int = 201) -> Steps:
    """The B-spline basis functions N_{i,k} by the Cox–de Boor recursion, level k = 1 … `order` by level.

    Runs ``cox_de_boor(knots, i, order, grid, record=...)`` for every i (the production recursion; it computes
    the lower levels on the way up). ``result`` is the (count, samples) array of the ``order`` basis functions on
    the sample grid, equal to ``cox_de_boor`` row by row. With `u`, the knot span $x_s <= u < x_{s+1}$ and the
    `order` functions non-zero there are shown.
    """
    where = "steps.b_spline_basis"
    x = _validation._as_knot_vector(knots, "knots", where=where)
    k_max = _validation._as_degree(order, where=where, name="order")
    count = x.size - k_max
    if count < 1:
        raise GeometryError(f"{where}: {x.size} knots leave no basis function of order {k_max}; give at least "
                            f"{k_max + 1} knots")  # fmt: skip
    grid = np.linspace(float(x[0]), float(x[-1]), int(samples))
    table: dict[tuple[int, int], NDArray] = {}

    def record(i: int, k: int, values: NDArray) -> None:
        table[(i, k)] = values.copy()

    result = np.array([curves.cox_de_boor(x, i, k_max, grid, record=record) for i in range(count)])
    span = None
    if u is not None:
        value = as_scalar(u, "u", where=where, error=GeometryError)
        if not x[0] <= value <= x[-1]:
            raise GeometryError(f"{where}: u = {value!r} lies outside [{x[0]}, {x[-1]}]; give a parameter in the "
                                "knot range")  # fmt: skip
        nonempty = np.flatnonzero(x[:-1] < x[1:])
        span = int(min(max(np.searchsorted(x, value, side="right") - 1, nonempty[0]), nonempty[-1]))
    steps = [Step(
        f"Knot vector, order k = {k_max} (degree {k_max - 1})",
        "N_i,1(u) = 1 on [x_i, x_(i+1)), else 0; then N_i,k(u) = (u − x_i)/(x_(i+k−1) − x_i)·N_i,k−1(u) + "
        "(x_(i+k) − u)/(x_(i+k) − x_(i+1))·N_(i+1),k−1(u), a term with a zero denominator taken as 0.",
        {"knots": x, "basis functions": count} | ({"u": u, "knot span s": span} if span is not None else {}),
    )]  # fmt: skip
    for k in range(1, k_max + 1):
        indices = sorted(i for (i, level) in table if level == k)
        values: dict[str, Any] = {"functions": [f"N{i},{k}" for i in indices]}
        if span is not None:
            nonzero = [i for i in indices if i <= span <= i + k - 1]
            values["non-zero on the span"] = [f"N{i},{k}" for i in nonzero]
        steps.append(Step(
            f"Level k = {k}: {len(indices)} functions of degree {k - 1}",
            "Each N_i,k blends two functions of the level below with linear weights; it is non-zero only on "
            f"[x_i, x_(i+k)) (k = {k} knot intervals)."
            + (" On the span of u exactly k of them are non-zero." if span is not None else ""),
            values,
        ))  # fmt: skip

    def paint(index: int, canvas: _Canvas) -> None:
        height = 1.0
        for value in x:
            canvas.line((value, 0.0), (value, -0.04), color="ink")
        canvas.line((x[0], 0.0), (x[-1], 0.0), color="faint")
        canvas.line((x[0], height), (x[-1], height), color="faint", dash=True)
        if span is not None:
            canvas.rect((x[span], 0.0), (x[span + 1], height), color="highlight", fill="highlight", opacity=0.1)
        if index == 0:
            return
        level = index
        for n, i in enumerate(sorted(i for (i, kk) in table if kk == level)):
            color = _LEVEL_COLORS[n % len(_LEVEL_COLORS)]
            canvas.polyline(np.column_stack([grid, table[(i, level)]]), color=color, width=2.0)

    span_x = float(x[-1] - x[0]) or 1.0
    return Steps("B-spline basis (Cox–de Boor)", steps, result, paint,
                 (float(x[0]) - 0.02 * span_x, -0.1, float(x[-1]) + 0.02 * span_x, 1.08))  # fmt: skip


def hermite(p0: ArrayLike, p1: ArrayLike, r0: ArrayLike, r1: ArrayLike, t: float = 0.5) -> Steps:
    """Hermite interpolation: the four blending functions, their weights at `t`, and the curve.

    $P(t) = P0·H1(t) + P1·H2(t) + R0·H3(t) + R1·H4(t)$ with $[H1 H2 H3 H4] = hermite_blending(t)$.
    ``result`` is ``HermiteCurve(p0, p1, r0, r1).evaluate(t)``; the last step's point is the blend of the four
    weighted vectors (equal up to round-off).
    """
    where = "steps.hermite"
    curve = curves.HermiteCurve(p0, p1, r0, r1)
    s = as_scalar(t, "t", where=where, error=GeometryError)
    weights = curves.hermite_blending(s)
    result = curve.evaluate(s)
    grid = np.linspace(0.0, 1.0, 101)
    blending = curves.hermite_blending(grid)
    names = ("H1 = 2t³ − 3t² + 1 (weight of P0)", "H2 = −2t³ + 3t² (weight of P1)", "H3 = t³ − 2t² + t (weight of R0)",
             "H4 = t³ − t² (weight of R1)")  # fmt: skip
    steps = [Step(
        "Hermite blending functions",
        "P(t) = [t³ t² t 1]·M_H·[P0 P1 R0 R1]ᵀ: the rows of M_H give four cubic blending functions, each "
        "weighting one end point or end tangent.",
        {"M_H": curves.M_H},
    )]  # fmt: skip
    for j, name in enumerate(names):
        steps.append(Step(name, f"At t = {format_value(s)} this weight is {format_value(float(weights[j]))}.",
                          {f"H{j + 1}(t)": float(weights[j])}))  # fmt: skip
    steps.append(Step(
        "The curve point P(t)",
        "The weighted sum of the end points and tangents; P(0) = P0, P(1) = P1, P'(0) = R0, P'(1) = R1.",
        {"weights": weights, "P(t)": result},
    ))  # fmt: skip
    samples = curve.evaluate(grid)
    ends = np.vstack([curve.evaluate(0.0), curve.evaluate(1.0)])[:, :2]
    box = bounds_of(
        np.vstack([samples[:, :2], ends + np.vstack([np.asarray(r0, float)[:2], np.asarray(r1, float)[:2]]) / 3])
    )
    # the blending functions are drawn into the lower band of the same canvas: map [0,1]x[-0.2,1] into it
    x0, y0, x1, y1 = box
    band = (y1 - y0) * 0.45

    def to_band(tt: NDArray, h: NDArray) -> NDArray:
        return np.column_stack([x0 + (x1 - x0) * tt, y0 - band * 1.1 + band * (h + 0.2) / 1.2])

    def paint(index: int, canvas: _Canvas) -> None:
        canvas.polyline(samples[:, :2], color="blue" if index == len(steps) - 1 else "faint", width=2.5)
        canvas.dot(ends[0], label="P0")
        canvas.dot(ends[1], label="P1")
        canvas.line(ends[0], ends[0] + np.asarray(r0, float)[:2] / 3, color="purple")
        canvas.line(ends[1], ends[1] + np.asarray(r1, float)[:2] / 3, color="purple")
        for j in range(4):
            color = _LEVEL_COLORS[j + 1] if index in (0, j + 1, len(steps) - 1) else "faint"
            canvas.polyline(to_band(grid, blending[:, j]), color=color, width=2.0 if index == j + 1 else 1.2)
        canvas.line(to_band(np.array([s]), np.array([-0.2]))[0], to_band(np.array([s]), np.array([1.0]))[0],
                    color="highlight", dash=True)  # fmt: skip
        if index == len(steps) - 1:
            canvas.dot(np.asarray(result)[:2], color="highlight", radius=5.0, label="P(t)")

    return Steps("Hermite interpolation", steps, result, paint, (x0, y0 - band * 1.15, x1, y1))
