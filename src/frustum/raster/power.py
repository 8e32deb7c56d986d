"""x^n as every shading path computes it, in plain Python: no Numba here, so ``frustum.shading`` imports it
without loading the compiler, and ``raster.shade`` compiles the same function for its kernels."""

from __future__ import annotations

import math

__all__ = ["SQUARING_MAX", "textbook_power"]

SQUARING_MAX = 1024.0


def textbook_power(x: float, n: float) -> float:
    """Textbook x^n; integral n in [0, SQUARING_MAX] by repeated squaring (exact same bytes in every path).

    Squaring: r = 1; per bit of n from the lowest, r·x if the bit is set, then x·x. Other n: libm ``x ** n``.
    """
    # kept twice on purpose: tests/reference_raster.py:_power is the same loop, as the byte-exact tests' reference
    # shares no code with the renderer
    if not (n == math.floor(n) and 0.0 <= n <= SQUARING_MAX):
        return x**n
    e, r = int(n), 1.0
    while e > 0:
        if e & 1:
            r *= x
        x *= x
        e >>= 1
    return r
