"""Numba kernels: plain contiguous arrays and integers in, caller-owned buffers out; no frustum objects.

This package imports only numpy and numba (an import-linter contract). Validation happens in the public
modules that call these kernels (``clipping.py``, later ``render/``); a kernel trusts its inputs and states
its contract in its docstring.
"""

from __future__ import annotations

from collections.abc import Callable

compile_notice: Callable[[], None] | None = None
"""Called once per process when kernels have been compiling for more than a second (the CLI sets it to print
"compiling render kernels, first run only" on stderr). This module imports no Numba: setting it is free."""
