"""Fractals, step by step: the Koch curve and midpoint displacement iteration by iteration, the box-counting fit.

References: [HB 15] "Fractal-Geometry Methods"; [seed] "Fractals".
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum.geometry.dimension import box_counting_dimension
from frustum.geometry.fractals import fractal_coastline, koch_curve
from frustum.steps._draw import bounds_of
from frustum.steps._record import Step, Steps, _Canvas, check_recording, log_geometric_sum

__all__ = ["box_counting", "koch", "midpoint_displacement"]

_BYTES_PER_KOCH_VERTEX = 180.0
"""Peak memory of ``koch(level)`` and its sheet per recorded vertex (Σ_k 4^k + 1 of them): 175–178 B measured at
levels 7 and 8 (tracemalloc; tests/hostile/test_hostile_round_three.py checks the estimate within 2×)."""
_BYTES_PER_DISPLACED_VERTEX = 220.0
"""The same for ``midpoint_displacement`` per recorded vertex (Σ_k segments·2^k + 1): 209–222 B at levels 12, 14."""


def koch(level: int = 4, start: ArrayLike = (0.0, 0.0), end: ArrayLike = (1.0, 0.0)) -> Steps:
    """The Koch curve, iteration by iteration (``koch_curve(..., record=...)``); ``result`` is its polyline.

    Raises ``OutputError`` when the recording (every level's polyline and its figures) is over the memory
    budget (``frustum.set_budget``), with the estimate.
    """
    if isinstance(level, int) and level >= 0:
        check_recording(log_geometric_sum(4.0, level + 1), _BYTES_PER_KOCH_VERTEX, "steps.koch",
                        f"a recording of level = {level}")  # fmt: skip
    levels: list[NDArray] = []
    result = koch_curve(level, start, end, record=lambda k, points: levels.append(points.copy()))
    first = np.array([np.asarray(start, float)[:2], np.asarray(end, float)[:2]])
    shown = [first, *levels]
    steps = [Step("Initiator: one segment", "Each iteration replaces every segment by four copies a third as long, "
                  "the middle third raised into an equilateral bump (the generator).", {"segments": 1})]  # fmt: skip
    for k, points in enumerate(levels, start=1):
        length = float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
        steps.append(Step(
            f"Iteration {k}: {len(points) - 1} segments",
            "N = 4^k segments of length (1/3)^k: the length grows by 4/3 each time; the similarity dimension is "
            "D = log 4 / log 3 ≈ 1.2619.",
            {"segments": len(points) - 1, "length": length, "D": math.log(4) / math.log(3)},
        ))  # fmt: skip

    def paint(index: int, canvas: _Canvas) -> None:
        if index > 0:
            canvas.polyline(shown[index - 1], color="faint", width=1.0)
        canvas.polyline(shown[index], color="blue", width=1.8)

    everything = np.vstack(shown)
    x0, y0, x1, y1 = bounds_of(everything)
    return Steps("Koch curve", steps, result, paint, (x0, y0 - 0.3 * (x1 - x0), x1, y1 + 0.1 * (x1 - x0)))


def midpoint_displacement(
    polyline: ArrayLike = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)), level: int = 6, *, seed: int = 1, hurst: float = 0.5,
    amplitude: float = 0.3,
) -> Steps:  # fmt: skip
    """Random midpoint displacement of a polyline (``fractal_coastline(..., record=...)``), step by step;
    ``result`` is the production polyline. Over the memory budget: ``OutputError`` with the estimate."""
    if isinstance(level, int) and level >= 0:
        segments = max(len(polyline) - 1, 1) if hasattr(polyline, "__len__") else 1
        check_recording(math.log(segments) + log_geometric_sum(2.0, level + 1), _BYTES_PER_DISPLACED_VERTEX,
                        "steps.midpoint_displacement", f"a recording of level = {level}")  # fmt: skip
    levels: list[tuple[NDArray, float]] = []

    def record(k: int, points: NDArray, sigma: float) -> None:
        levels.append((points.copy(), float(sigma)))

    result = fractal_coastline(polyline, level, seed=seed, hurst=hurst, amplitude=amplitude, record=record)
    first = np.asarray(polyline, dtype=float)
    shown = [first, *(p for p, _ in levels)]
    steps = [Step("The initial polyline", "Each step moves the midpoint of every segment along the segment's normal "
                  "by a Gaussian amount g·σ_k, with σ_k = amplitude·L̄·2^(−k·H) shrinking step by step (H the "
                  "Hurst exponent).", {"segments": len(first) - 1, "H": hurst})]  # fmt: skip
    for k, (points, sigma) in enumerate(levels, start=1):
        steps.append(Step(f"Step {k}: {len(points) - 1} segments",
                          "New midpoints (p + q)/2 + g·σ_k·n̂; the end points stay fixed. Dimension about 2 − H.",
                          {"sigma_k": sigma, "segments": len(points) - 1}))  # fmt: skip

    def paint(index: int, canvas: _Canvas) -> None:
        if index > 0:
            canvas.polyline(shown[index - 1][:, :2], color="faint", width=1.0)
        canvas.polyline(shown[index][:, :2], color="blue", width=1.8)
        if index > 0 and len(shown[index]) <= 65:
            for p in shown[index][1::2]:
                canvas.dot(p[:2], color="highlight", radius=2.5)

    return Steps("Midpoint displacement", steps, result, paint, bounds_of(np.vstack(shown)[:, :2], pad=0.15))


def box_counting(points: ArrayLike | None = None, sizes: ArrayLike | None = None) -> Steps:
    """Box counting on 2D points (default: a level-6 Koch curve): N(ε) per box size, then the log-log fit.

    ``result`` is ``box_counting_dimension(points, sizes)`` (a ``BoxCounting``); the steps show each of its
    box sizes with its count and the fitted line.
    """
    data = koch_curve(6)[:, :2] if points is None else np.asarray(points, dtype=float)
    result = box_counting_dimension(data, sizes)
    low = data.min(axis=0)
    steps = [Step("The point set", "Cover the set with a grid of boxes of side ε and count the occupied ones, "
                  "N(ε); for a fractal N(ε) ∝ ε^(−D).", {"points": len(data)})]  # fmt: skip
    for size, count in zip(result.sizes, result.counts, strict=True):
        steps.append(Step(f"Boxes of side ε = {size:.4g}: N = {int(count)}",
                          "The grid starts at the set's lower corner; a box counts when it holds a point.",
                          {"epsilon": float(size), "N": int(count), "log(1/ε)": -math.log(size),
                           "log N": math.log(count)}))  # fmt: skip
    steps.append(Step("Least-squares fit of log N against log(1/ε)",
                      "The slope of the line is the box-counting dimension D.",
                      {"D": result.dimension, "interval": result.interval, "stderr": result.stderr}))  # fmt: skip
    x0, y0, x1, y1 = bounds_of(data)
    logs_x, logs_y = -np.log(result.sizes), np.log(result.counts.astype(float))

    def paint(index: int, canvas: _Canvas) -> None:
        if index == len(steps) - 1:
            # the fit, drawn in the same box: log(1/ε) across, log N up, scaled into the data's bounds
            def fit_xy(lx: NDArray, ly: NDArray) -> NDArray:
                sx = (lx - logs_x.min()) / max(np.ptp(logs_x), 1e-12)
                sy = (ly - logs_y.min()) / max(np.ptp(logs_y), 1e-12)
                return np.column_stack([x0 + sx * (x1 - x0), y0 + sy * (y1 - y0)])

            intercept = float(np.mean(logs_y - result.dimension * logs_x))
            line_x = np.array([logs_x.min(), logs_x.max()])
            canvas.polyline(fit_xy(line_x, result.dimension * line_x + intercept), color="highlight", width=2.0)
            for p in fit_xy(logs_x, logs_y):
                canvas.dot(p, color="blue")
            canvas.label((x0, y1), f"log N vs log(1/ε): slope D = {result.dimension:.4f}", size=12)
            return
        if points is None:
            canvas.polyline(data, color="ink", width=1.0)
        for p in data[:: max(1, len(data) // 2000)]:
            canvas.dot(p, color="ink", radius=0.8)
        if index > 0:
            size = float(result.sizes[index - 1])
            nx, ny = math.ceil((x1 - low[0]) / size), math.ceil((y1 - low[1]) / size)
            if nx * ny <= 4096:
                for i in range(nx + 1):
                    canvas.line((low[0] + i * size, low[1]), (low[0] + i * size, low[1] + ny * size), color="faint",
                                width=0.6)  # fmt: skip
                for j in range(ny + 1):
                    canvas.line((low[0], low[1] + j * size), (low[0] + nx * size, low[1] + j * size), color="faint",
                                width=0.6)  # fmt: skip

    return Steps("Box-counting dimension", steps, result, paint, (x0, y0, x1, y1))
