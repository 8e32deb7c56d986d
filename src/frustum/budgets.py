"""The work budget: memory and inner iterations estimated before any work starts.

Every loader, generator and renderer estimates what a request will cost *before* allocating or looping and
calls :func:`check_memory` / :func:`check_operations`. Over budget, the area's ``FrustumError`` subclass is
raised with the estimate, the budget and how to raise it, instead of a ``MemoryError`` after gigabytes are
taken or a kernel that runs for hours.

One setting governs all of it:

- ``frustum.set_budget(bytes=..., operations=...)`` in Python (returns the previous budget; also usable as a
  context manager through :func:`budget`),
- the environment variables ``FRUSTUM_MAX_BYTES`` and ``FRUSTUM_MAX_OPERATIONS`` (read at import; numbers such
  as ``8e9`` or with a suffix ``16G``, ``512M``),
- the CLI option ``--max-bytes`` / ``--max-operations``.

Defaults: ``DEFAULT_BYTES`` (8 GiB) for one request's memory, ``DEFAULT_OPERATIONS`` (5·10¹⁰ inner
iterations, minutes of work at most) for iterative work such as escape-time fractals, ray marching or
simulation steps.
"""

from __future__ import annotations

import contextlib
import math
import os
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from frustum.errors import FrustumError

__all__ = [
    "DEFAULT_BYTES",
    "DEFAULT_OPERATIONS",
    "Budget",
    "budget",
    "check_memory",
    "check_operations",
    "format_bytes",
    "get_budget",
    "set_budget",
]

DEFAULT_BYTES = 8 * 2**30
"""Default memory budget of one request (8 GiB)."""
DEFAULT_OPERATIONS = 5 * 10**10
"""Default budget of inner iterations of one request (5·10¹⁰)."""

_SUFFIXES = {"k": 2**10, "m": 2**20, "g": 2**30, "t": 2**40}


@dataclass(frozen=True)
class Budget:
    """The limits in force: `bytes` of memory and `operations` (inner iterations) per request."""

    bytes: int
    operations: int


def _parse(name: str, value: Any) -> int:
    """A positive integer from an int, a float such as 8e9, or a string such as "16G" / "512M" / "2e10"."""
    text = str(value).strip()
    number: float
    try:
        if isinstance(value, bool):
            raise ValueError
        if isinstance(value, str) and text and text[-1].lower() in _SUFFIXES:
            number = float(text[:-1]) * _SUFFIXES[text[-1].lower()]
        else:
            number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number) or number < 1:
        raise FrustumError(f"set_budget: {name} = {value!r} is not a positive number; give e.g. {name}=8e9 or '8G'")
    return int(number)


def _from_environment() -> Budget:
    limits = {}
    for key, variable, default in (("bytes", "FRUSTUM_MAX_BYTES", DEFAULT_BYTES),
                                   ("operations", "FRUSTUM_MAX_OPERATIONS", DEFAULT_OPERATIONS)):  # fmt: skip
        raw = os.environ.get(variable)
        limits[key] = default if raw in (None, "") else _parse(variable, raw)
    return Budget(**limits)


_lock = threading.Lock()
_current = _from_environment()


def get_budget() -> Budget:
    """The budget in force (set by :func:`set_budget`, the environment, or the defaults)."""
    return _current


def set_budget(bytes: Any = None, operations: Any = None) -> Budget:
    """Set the memory (`bytes`) and work (`operations`) budget for every later request; return the previous one.

    ``None`` leaves a limit unchanged. Values may be numbers (``8e9``) or strings with a suffix (``"16G"``).
    """
    global _current
    with _lock:
        previous = _current
        _current = Budget(
            bytes=previous.bytes if bytes is None else _parse("bytes", bytes),
            operations=previous.operations if operations is None else _parse("operations", operations),
        )
    return previous


@contextlib.contextmanager
def budget(bytes: Any = None, operations: Any = None) -> Iterator[Budget]:
    """Context manager: ``with frustum.budget(bytes="32G"): ...`` raises the limits inside the block only."""
    previous = set_budget(bytes, operations)
    try:
        yield _current
    finally:
        set_budget(previous.bytes, previous.operations)


def format_bytes(nbytes: float) -> str:
    """Bytes as a short human text: ``'1.5 GiB'``."""
    size = float(nbytes)
    if size >= 2.0**60:  # an estimate made in log space can be astronomically large
        return f"{size / 2.0**50:.3g} PiB"
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if size < 1024.0 or unit == "PiB":
            return f"{int(size)} B" if unit == "B" else f"{size:.1f} {unit}"
        size /= 1024.0
    raise AssertionError("unreachable")  # pragma: no cover


def check_memory(nbytes: float, *, where: str, cause: str, error: type[FrustumError] = FrustumError,
                 limit: int | None = None) -> None:  # fmt: skip
    """Raise `error` if a request estimated at `nbytes` bytes exceeds the memory budget.

    `where` names the function (``"uv_sphere"``), `cause` the parameters that drive the estimate
    (``"segments = 100000, rings = 1000"``); the message gives the estimate, the budget and how to raise it.
    `limit` overrides the global budget (a per-call ``max_bytes=`` argument).
    """
    budget_bytes = _current.bytes if limit is None else int(limit)
    if nbytes > budget_bytes:
        raise error(f"{where}: {cause} needs about {format_bytes(nbytes)}, over the memory budget of "
                    f"{format_bytes(budget_bytes)}; reduce it, or raise the budget with "
                    f"frustum.set_budget(bytes=...), FRUSTUM_MAX_BYTES or --max-bytes")  # fmt: skip


def check_operations(count: float, *, where: str, cause: str, error: type[FrustumError] = FrustumError,
                     limit: int | None = None) -> None:  # fmt: skip
    """Raise `error` if a request estimated at `count` inner iterations exceeds the work budget."""
    budget_ops = _current.operations if limit is None else int(limit)
    if count > budget_ops:
        raise error(f"{where}: {cause} needs about {count:.3g} operations, over the work budget of "
                    f"{budget_ops:.3g}; reduce it, or raise the budget with frustum.set_budget(operations=...), "
                    f"FRUSTUM_MAX_OPERATIONS or --max-operations")  # fmt: skip
