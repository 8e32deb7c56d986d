"""The Numba options of every frustum kernel, chosen once (datashader's ``ngjit`` habit).

``kernel`` compiles a single-thread function; ``inline_kernel`` is for small per-pixel helpers that take many
arguments and return tuples (Numba inlines them into the caller's IR: the shading pass ran 2–3x faster than
with calls); ``parallel_kernel`` is for the few drivers whose loop over independent items pays for
``numba.prange``. All cache the machine code on disk (``cache=True``) and release
the GIL (``nogil=True``). No ``fastmath``: results must be the bytes the textbook path gives. With
``NUMBA_DISABLE_JIT=1`` both decorators return the plain Python function and ``prange`` is ``range``, so the
test suite can run (and measure coverage of) every kernel line as Python.
"""

from __future__ import annotations

import numba

__all__ = ["inline_kernel", "kernel", "parallel_kernel", "prange"]

kernel = numba.njit(cache=True, nogil=True)
inline_kernel = numba.njit(cache=True, nogil=True, inline="always")
parallel_kernel = numba.njit(cache=True, nogil=True, parallel=True)
prange = numba.prange
