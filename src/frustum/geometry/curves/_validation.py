"""Validation shared by every curve family (the curve-specific part; shapes of (N, 3) points live in
``frustum._arrays``): control points, parameters inside a domain, degrees."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import describe
from frustum.errors import GeometryError

FloatArray = NDArray[np.float64]


_DOMAIN_SLACK = 1e-12  # parameters this far (relative) outside a domain are clamped, not refused


def _as_control_points(
    value: ArrayLike,
    name: str,
    *,
    where: str,
    min_count: int = 1,
    dimensions: tuple[int, ...] = (2, 3),
    reason: str = "",
) -> FloatArray:
    """Return `value` as a finite, C-contiguous (N, d) float64 array with d in `dimensions` and N >= min_count."""
    shape_text = " or ".join(f"(N, {d})" for d in dimensions)
    try:
        points = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(
            f"{where}: {name} = {describe(value)} is not numeric; expected an {shape_text} array of points"
        ) from None
    if points.ndim != 2 or points.shape[1] not in dimensions:
        raise GeometryError(f"{where}: {name} has shape {points.shape}; expected {shape_text} points, one per row")
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise GeometryError(
            f"{where}: {name}[{i}] = {describe(points[i])} is not finite; coordinates must be finite numbers"
        )
    if points.shape[0] < min_count:
        raise GeometryError(
            f"{where}: len({name}) = {points.shape[0]} is below {min_count}; give at least {min_count} points"
            + (f" {reason}" if reason else "")
        )
    return np.ascontiguousarray(points)


def _as_parameters(value: ArrayLike, name: str, low: float, high: float, *, where: str) -> tuple[FloatArray, bool]:
    """Return (1-D float64 parameters inside [low, high], whether `value` was a scalar); refuse others."""
    try:
        t = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(
            f"{where}: {name} = {describe(value)} is not numeric; expected numbers in [{low!r}, {high!r}]"
        ) from None
    scalar = t.ndim == 0
    if t.ndim > 1:
        raise GeometryError(f"{where}: {name} has shape {t.shape}; expected a number or a 1-D array of numbers")
    t = np.atleast_1d(t)
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise GeometryError(
            f"{where}: {name} = {float(t[bad[0]])!r} is not finite; expected numbers in [{low!r}, {high!r}]"
        )
    slack = _DOMAIN_SLACK * max(1.0, high - low, abs(low), abs(high))
    outside = np.flatnonzero((t < low - slack) | (t > high + slack))
    if outside.size:
        raise GeometryError(
            f"{where}: {name} = {float(t[outside[0]])!r} lies outside the domain [{low!r}, {high!r}]; "
            "give parameters inside the domain (curves do not extrapolate)"
        )
    return np.ascontiguousarray(np.clip(t, low, high)), scalar


def _as_degree(value: Any, *, where: str, name: str = "degree") -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not an integer; give an integer {name} >= 1")
    if value < 1:
        raise GeometryError(f"{where}: {name} = {int(value)} is below 1; give an integer {name} >= 1")
    return int(value)


def _shape_result(values: FloatArray, scalar: bool) -> FloatArray:
    return values[0] if scalar else values


def _as_knot_vector(value: ArrayLike, name: str, *, where: str) -> FloatArray:
    try:
        knots = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not numeric; give a 1-D array of knots") from None
    if knots.ndim != 1:
        raise GeometryError(f"{where}: {name} has shape {knots.shape}; expected a 1-D array of knots")
    bad = np.flatnonzero(~np.isfinite(knots))
    if bad.size:
        i = int(bad[0])
        raise GeometryError(f"{where}: {name}[{i}] = {float(knots[i])!r} is not finite; knots must be finite numbers")
    return np.ascontiguousarray(knots)
