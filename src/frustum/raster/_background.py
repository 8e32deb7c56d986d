"""Compile some kernels in a second process while this one compiles the others: two cores, two compilers.

Numba compiles under one process-wide lock (``global_compiler_lock``), so threads cannot compile two kernels at
once; a child process can. ``start(plan)`` launches ``python -m frustum.raster._background`` with a plan — kernels
and the exact argument types they will be called with — and the child compiles each into Numba's on-disk cache
(the same ``NUMBA_CACHE_DIR`` and cache stamps: ``_jit._cached``) in order, reporting each one on its stdout. Meanwhile
this process runs as usual. When it first calls a planned kernel with the planned types and the child has not yet
reported that kernel, it waits for the report, and the call then loads the child's machine code from the cache,
as a warm start would. The machine code is the one this process would have compiled (same function, same types,
same options), so every output byte is the same.

Nothing depends on the child: if it cannot start, fails on a kernel, dies or hangs (no report within
``WAIT_LIMIT_S`` of waiting), the waiting call goes on and compiles the kernel itself. The child is started only
when at least two cores are usable and some planned kernel is missing from the cache (a warm start starts
nothing), never with ``NUMBA_DISABLE_JIT=1`` or ``FRUSTUM_BACKGROUND_COMPILE=0``, and it ends when this process
exits (killed at exit; it also ends itself within 0.2 s of finding its parent gone).
"""

from __future__ import annotations

import atexit
import importlib
import json
import os
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from functools import cache
from typing import Any

__all__ = ["BackgroundCompile", "start"]

WAIT_LIMIT_S = 120.0
"""Longest a kernel call waits for the child's report before compiling the kernel itself."""

# Numba is imported on first use, not with this module: the child starts watching for its parent's end first


@cache
def _type_names() -> dict[str, Any]:
    from numba.core import types

    return {name: getattr(types, name) for name in dir(types) if not name.startswith("_")}


def parse_signature(text: str) -> tuple:
    """Argument types from their ``repr`` (``"(Array(float64, 2, 'C', True, aligned=True), int64)"``)."""
    value = eval(text, {"__builtins__": {}}, _type_names())  # only numba.types names, from frustum's own plan
    return tuple(value) if isinstance(value, tuple) else (value,)


def dispatcher(module: str, name: str) -> Any:
    """The Numba dispatcher of a kernel: the function itself, or a ``parallel_kernel`` driver's ``.kernel``."""
    found = getattr(importlib.import_module(module), name)
    return getattr(found, "kernel", found)


def _cached(kernel: Any, signature: tuple) -> bool:
    """Whether Numba's on-disk cache holds `kernel` for `signature` (the index only: nothing is loaded)."""
    cache = kernel._cache
    key = cache._index_key(signature, kernel.targetctx.codegen())
    return key in cache._cache_file._load_index()


def _usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


class BackgroundCompile:
    """A running child compiler: ``planned`` (dispatcher id → (dispatcher, signature, index)), ``reported``
    (index → "done" or "failed"), ``waited`` (seconds spent waiting for it), ``process`` (the ``subprocess.Popen``).
    """

    def __init__(self, entries: list[tuple[Any, tuple, tuple[str, str, str]]]) -> None:
        self.planned = {id(kernel): (kernel, signature, i) for i, (kernel, signature, _) in enumerate(entries)}
        self.reported: dict[int, str] = {}
        self.waited = 0.0  # seconds this process's kernel calls spent waiting for the child
        self.finished = threading.Event()  # the child's stdout closed: it exited, crashed or was killed
        self._condition = threading.Condition()
        plan = json.dumps([list(spec) for _, _, spec in entries])
        # the child imports this very frustum (its folder first on the path), so its cache entries are this one's
        package_root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        path = os.pathsep.join(p for p in (package_root, os.environ.get("PYTHONPATH", "")) if p)
        self.process = subprocess.Popen(
            [sys.executable, "-m", "frustum.raster._background", plan, str(os.getpid())], stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env={**os.environ, "PYTHONPATH": path},
        )  # fmt: skip
        atexit.register(self.stop)
        threading.Thread(target=self._read, name="frustum-background-compile", daemon=True).start()
        for kernel, _, _ in self.planned.values():
            self._wrap(kernel)

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            status, _, index = line.strip().partition(" ")
            if status in ("done", "failed") and index.isdigit():
                with self._condition:
                    self.reported[int(index)] = status
                    self._condition.notify_all()
        with self._condition:
            self.finished.set()
            self._condition.notify_all()

    def wait(self, index: int, limit: float | None = None) -> str:
        """Wait until the child reports entry `index` (or ends, or `limit` seconds, default ``WAIT_LIMIT_S``, pass);
        return "done", "failed" or "gone" (no report)."""
        limit = WAIT_LIMIT_S if limit is None else limit
        with self._condition:
            self._condition.wait_for(lambda: index in self.reported or self.finished.is_set(), limit)
            return self.reported.get(index, "gone")

    def _wrap(self, kernel: Any) -> None:
        """Make `kernel`'s first call with the planned types wait for the child (Numba looks ``_compile_for_args``
        up on the instance, so this replaces it for this one dispatcher)."""
        compile_for_args = kernel._compile_for_args
        _, signature, index = self.planned[id(kernel)]

        def waiting(*args: Any, **kws: Any) -> Any:
            if not kws and tuple(kernel.typeof_pyval(a) for a in args) == signature:
                started = time.perf_counter()
                self.wait(index)
                self.waited += time.perf_counter() - started
            return compile_for_args(*args, **kws)

        kernel._compile_for_args = waiting

    def stop(self) -> None:
        """End the child (at exit: its unfinished kernels are not needed any more)."""
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


_started: BackgroundCompile | None = None
_start_lock = threading.Lock()


def start(plan: Sequence[tuple[str, str, str]]) -> BackgroundCompile | None:
    """Compile the `plan`'s kernels ``(module, name, argument types' repr)`` in a child process, in order.

    Returns the running child, or None where nothing was started (see the module docstring). Once per process:
    a second call returns the first call's child.
    """
    global _started
    with _start_lock:
        if _started is not None:
            return _started
        import numba

        if numba.config.DISABLE_JIT or os.environ.get("FRUSTUM_BACKGROUND_COMPILE", "1") == "0":
            return None
        if _usable_cores() < 2:
            return None
        try:
            entries = [(dispatcher(module, name), parse_signature(text), (module, name, text))
                       for module, name, text in plan]  # fmt: skip
            missing = [entry for entry in entries if not _cached(entry[0], entry[1])]
        except Exception:  # a Numba whose cache internals differ: compile here, as before
            return None
        if not missing:
            return None
        try:
            _started = BackgroundCompile(missing)
        except OSError:
            return None
        return _started


def _orphan_watch(parent: int) -> None:
    """End the child once its parent is gone (killed, or ``os._exit`` on Ctrl-C, where ``atexit`` does not run)."""
    while os.getppid() == parent:
        time.sleep(0.2)
    os._exit(0)


def _child(plan: list[list[str]], parent: int | None = None) -> None:
    """The child: compile each planned kernel for its types (into the cache); one report line each. `parent`: the
    process that started it (when given, the child ends once that process is gone)."""
    if parent is not None:
        threading.Thread(target=_orphan_watch, args=(parent,), daemon=True).start()
    for index, (module, name, text) in enumerate(plan):
        try:
            dispatcher(module, name).compile(parse_signature(text))
            status = "done"
        except Exception:  # the parent compiles this one itself
            status = "failed"
        print(status, index, flush=True)


if __name__ == "__main__":
    _child(json.loads(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else None)
