"""Numba kernels: plain contiguous arrays and integers in, caller-owned buffers out; no frustum objects.

This package imports only numpy and numba (an import-linter contract). Validation happens in the public
modules that call these kernels (``clipping.py``, later ``render/``); a kernel trusts its inputs and states
its contract in its docstring.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable

COMPILE_NOTICE_ENV = "FRUSTUM_COMPILE_NOTICE"
"""Environment variable: ``0`` (or ``false``, ``no``, ``off``) silences the library's compile notice."""

_NOTICE_TEXT = (
    "frustum: compiling render kernels, first run only (frustum.warmup() or `frustum warmup` does it ahead of "
    "time; frustum.set_compile_notice(False) silences this) ..."
)
_noticed = [False]


def _library_notice() -> None:
    """The library's notice: one line on stderr, once per process, unless silenced by `COMPILE_NOTICE_ENV`."""
    if _noticed[0] or os.environ.get(COMPILE_NOTICE_ENV, "1").strip().lower() in ("0", "false", "no", "off"):
        return
    _noticed[0] = True
    print(_NOTICE_TEXT, file=sys.stderr, flush=True)


compile_notice: Callable[[], None] | None = _library_notice
"""Called once per process when kernels have been compiling for more than a second: by default one line on
stderr (the CLI sets its own). This module imports no Numba: setting it is free."""


def set_compile_notice(enabled: bool | Callable[[], None] = True) -> None:
    """Turn the one-line "compiling render kernels" notice on stderr on or off, or give a function to call instead.

    The notice comes once per process, only when kernel compilation (a first run in a new environment) has taken
    over a second. The environment variable ``FRUSTUM_COMPILE_NOTICE=0`` silences it too.
    """
    global compile_notice
    compile_notice = enabled if callable(enabled) else (_library_notice if enabled else None)
