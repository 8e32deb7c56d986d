"""Numba kernels: plain contiguous arrays and integers in, caller-owned buffers out; no frustum objects.

This package imports only numpy and numba (an import-linter contract). Validation happens in the public
modules that call these kernels (``clipping.py``, later ``render.py``); a kernel trusts its inputs and states
its contract in its docstring.
"""
