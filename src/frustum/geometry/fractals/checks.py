"""What the fractal builders share: the kernels, the memory budget of a level, and the checks of levels, seeds,
points and Hurst exponents."""

from __future__ import annotations

import math
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_scalar, describe
from frustum.budgets import DEFAULT_BYTES, check_memory
from frustum.errors import GeometryError

__all__ = [
    "DEFAULT_MAX_BYTES",
    "MAX_LEVEL",
    "SQRT3",
    "as_point2",
    "byte_budget",
    "check_fractal_memory",
    "check_hurst",
    "check_level",
    "check_positive_int",
    "check_seed",
    "human_bytes",
    "kernels",
    "with_z",
]


def kernels() -> ModuleType:
    """The compiled kernels of this module (``raster/fractals.py``), imported on first use: ``import frustum``
    never loads Numba."""
    from frustum.raster import fractals

    return fractals


DEFAULT_MAX_BYTES = DEFAULT_BYTES
"""Default memory budget (8 GiB, ``frustum.budgets.DEFAULT_BYTES``); ``max_bytes=None`` (every generator's
default) follows the global budget in force, ``max_bytes=n`` overrides it for one call."""


SQRT3 = math.sqrt(3.0)


MAX_LEVEL = 1000


def check_level(value: Any, where: str, name: str = "level") -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not an integer; give an integer {name} >= 0")
    if value < 0:
        raise GeometryError(f"{where}: {name} = {int(value)} is negative; give an integer {name} >= 0")
    if value > MAX_LEVEL:
        # checked before any size arithmetic: base**level with a huge level is itself a huge integer
        raise GeometryError(
            f"{where}: {name} = {int(value)} is above {MAX_LEVEL}; its output (at least 2^{MAX_LEVEL} bytes for "
            "any branching fractal) exceeds every memory budget; give a smaller level"
        )
    return int(value)


def check_positive_int(value: Any, where: str, name: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise GeometryError(f"{where}: {name} = {describe(value)} is not an integer >= {minimum}; give one")
    return int(value)


def byte_budget(max_bytes: Any, where: str) -> int | None:
    """The per-call override `max_bytes` as an int, or None (the global budget, ``frustum.budgets``)."""
    if max_bytes is None:
        return None
    if isinstance(max_bytes, bool) or not isinstance(max_bytes, int | np.integer) or max_bytes <= 0:
        raise GeometryError(f"{where}: max_bytes = {describe(max_bytes)} is not a positive integer; give bytes > 0")
    return int(max_bytes)


def human_bytes(nbytes: int) -> str:
    size = float(nbytes)
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"):
        if size < 1024.0 or unit == "EiB":
            return f"{size:.1f} {unit}" if unit != "B" else f"{nbytes} B"
        size /= 1024.0
    return f"{nbytes} B"  # pragma: no cover


def check_fractal_memory(nbytes: int, max_bytes: int | None, *, where: str, name: str, value: Any) -> None:
    """Raise ``GeometryError`` if an output of `nbytes` bytes would exceed the budget.

    `max_bytes` None: the global budget (``frustum.budgets.check_memory``); an int: the per-call override. The
    message states the bytes needed, the budget and how to raise it, so a too-deep level fails at once instead
    of running out of memory.
    """
    if max_bytes is None:
        check_memory(nbytes, where=where, cause=f"{name} = {describe(value)}", error=GeometryError)
    elif nbytes > max_bytes:
        raise GeometryError(
            f"{where}: {name} = {describe(value)} would need {nbytes} bytes ({human_bytes(nbytes)}), over the memory "
            f"budget max_bytes = {max_bytes} ({human_bytes(max_bytes)}); lower {name} or raise max_bytes"
        )


def as_point2(value: ArrayLike, name: str, where: str) -> NDArray[np.float64]:
    try:
        point = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not numeric; give (x, y)") from None
    if point.shape != (2,) or not np.isfinite(point).all():
        raise GeometryError(f"{where}: {name} = {describe(value)} is not two finite numbers; give (x, y)")
    return point


def with_z(points2: NDArray[np.float64]) -> Points:
    out = np.zeros((points2.shape[0], 3))
    out[:, :2] = points2
    return out


def check_seed(seed: Any, where: str) -> int:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise GeometryError(f"{where}: seed = {describe(seed)} is not an integer >= 0; give a seed like 0 or 42")
    return int(seed)


def check_hurst(value: Any, where: str) -> float:
    h = as_scalar(value, "hurst", where=where, error=GeometryError)
    if not 0.0 < h < 1.0:
        raise GeometryError(f"{where}: hurst = {h!r} is outside (0, 1); give a Hurst exponent H with 0 < H < 1")
    return h
