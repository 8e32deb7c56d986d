"""Recording mode of the visible-surface methods (``frustum.steps``): a block inside which a method appends what
it did (its log) to a list, held in a context variable so that a method run outside the block records nothing."""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Iterator
from typing import Any

__all__ = ["recording_into"]


@contextlib.contextmanager
def recording_into(variable: contextvars.ContextVar[Any]) -> Iterator[list[Any]]:
    """Set `variable` to a new list for the block and yield the list; reset the variable after it."""
    logs: list[Any] = []
    token = variable.set(logs)
    try:
        yield logs
    finally:
        variable.reset(token)
