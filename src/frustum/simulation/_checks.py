"""Checkers shared by the simulation modules: time steps, non-negative coefficients, ramps over a life."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import as_scalar, describe
from frustum.errors import SimulationError

__all__ = ["as_nonnegative", "as_positive", "as_ramp", "as_time_step", "evaluate_ramp", "per_item", "state_not_finite"]


def as_time_step(dt: Any, where: str) -> float:
    """A finite time step > 0 in seconds, or a SimulationError."""
    value = as_scalar(dt, "dt", where=where, error=SimulationError)
    if not value > 0.0:
        raise SimulationError(f"{where}: dt = {value!r} is not positive; give a time step in seconds > 0")
    return value


def as_nonnegative(value: Any, name: str, where: str) -> float:
    """A finite float >= 0 (a coefficient: drag, damping, friction)."""
    number = as_scalar(value, name, where=where, error=SimulationError)
    if number < 0.0:
        raise SimulationError(f"{where}: {name} = {number!r} is negative; give a number >= 0")
    return number


def as_positive(value: Any, name: str, where: str) -> float:
    """A finite float > 0 (a radius, a lifetime)."""
    number = as_scalar(value, name, where=where, error=SimulationError)
    if not number > 0.0:
        raise SimulationError(f"{where}: {name} = {number!r} is not positive; give a number > 0")
    return number


def per_item(value: Any, count: int, name: str, where: str, *, positive: bool = False) -> NDArray[np.float64]:
    """A scalar or a (count,) array of finite numbers >= 0 (> 0 with `positive`) as a (count,) float64 array."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise SimulationError(
            f"{where}: {name} = {describe(value)} is not numeric; give a number or {count} numbers"
        ) from None
    if array.ndim == 0:
        array = np.full(count, float(array))
    if array.shape != (count,):
        raise SimulationError(f"{where}: {name} has shape {array.shape}; give one number or ({count},) numbers")
    bad = np.flatnonzero(~np.isfinite(array) | ((array <= 0.0) if positive else (array < 0.0)))
    if bad.size:
        i = int(bad[0])
        problem = "is not finite" if not np.isfinite(array[i]) else "is not positive" if positive else "is negative"
        valid = "> 0" if positive else ">= 0"
        label = name if np.ndim(value) == 0 else f"{name}[{i}]"
        raise SimulationError(f"{where}: {label} = {float(array[i])!r} {problem}; give finite numbers {valid}")
    return np.ascontiguousarray(array)


def as_ramp(value: Any, width: int, name: str, where: str, *, low: float = 0.0, high: float = np.inf) -> NDArray:
    """A constant or a ramp over normalized age as a (K, 1 + width) float64 table of rows ``(t, value...)``.

    A constant (a number, or `width` numbers) gives one row at t = 0. A ramp is a sequence of ``(t, value)``
    pairs with t in [0, 1] increasing; values between the knots are linear in t, constant beyond them.
    """
    try:
        array = np.asarray(value, dtype=np.float64)
        ramp = None
    except (TypeError, ValueError):
        array = None
        ramp = value
    if array is not None and array.ndim <= 1 and array.size == width:
        table = np.concatenate([[0.0], array.reshape(width)])[None, :]
    else:
        try:
            rows = [np.concatenate([[float(t)], np.atleast_1d(np.asarray(v, dtype=np.float64))]) for t, v in
                    (ramp if ramp is not None else array.tolist())]  # fmt: skip
            table = np.array(rows, dtype=np.float64)
        except (TypeError, ValueError):
            table = None
        if table is None or table.ndim != 2 or table.shape[1] != 1 + width or table.shape[0] == 0:
            shape = "a number" if width == 1 else f"{width} numbers"
            raise SimulationError(
                f"{where}: {name} = {describe(value)} is not {shape} or a ramp; give {shape} or pairs "
                f"(t, value) with t in [0, 1] increasing"
            ) from None
    if not np.isfinite(table).all():
        raise SimulationError(f"{where}: {name} = {describe(value)} is not finite; give finite numbers")
    t = table[:, 0]
    if (t < 0.0).any() or (t > 1.0).any() or (np.diff(t) <= 0.0).any():
        raise SimulationError(
            f"{where}: {name} ramp times {describe(t)} are not increasing in [0, 1]; give (t, value) pairs with "
            "0 <= t <= 1, each t larger than the one before"
        )
    values = table[:, 1:]
    if (values < low).any() or (values > high).any():
        raise SimulationError(
            f"{where}: {name} = {describe(value)} has values outside [{low:g}, {high:g}]; give values in that range"
        )
    return np.ascontiguousarray(table)


def evaluate_ramp(table: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    """(N, width) values of a ramp table at normalized ages `t` (N,): linear between knots (``np.interp``)."""
    if table.shape[0] == 1:
        return np.broadcast_to(table[0, 1:], (t.shape[0], table.shape[1] - 1)).copy()
    return np.stack([np.interp(t, table[:, 0], table[:, 1 + c]) for c in range(table.shape[1] - 1)], axis=1)


def state_not_finite(where: str, step: int, time: float, dt: float, integrator: str) -> SimulationError:
    """The blow-up error: which step, and what to do about it."""
    return SimulationError(
        f"{where}: the state is not finite (NaN or infinite) after step {step} (t = {time:.6g} s) with "
        f"dt = {dt!r} and integrator = {integrator!r}; the integration diverged: give a smaller dt (or more "
        "substeps), or use integrator='implicit-euler', which stays stable for stiff springs"
    )
