"""The Numba options of every frustum kernel, chosen once (datashader's ``ngjit`` habit), and the one way kernels
run in parallel.

``kernel`` compiles a single-thread function: machine code cached on disk (``cache=True``), the GIL released
(``nogil=True``), no ``fastmath`` (results must be the bytes the textbook path gives), no forced inlining (it
multiplied compile time: the generalized shading kernel took 15 s to compile with every helper inlined).

``parallel_kernel(items)`` makes the three tiers of a kernel from one function: the decorated function is a
single-thread kernel over a slice ``[start, stop)`` of independent items (its last two parameters); the name it
is bound to is a Python driver taking the same arguments without the slice, which splits ``items(*args)`` items
into pieces and runs them on the calling thread and ``threads() − 1`` pool threads (kernels release the GIL). Each piece
owns its slice of the outputs, so results are the same bytes on any number of threads. This replaces Numba's
``parallel=True``/``prange``: a parfor costs 0.25–0.5 s more to compile per kernel (and compiled every helper it
calls twice, for an int64 and a uint64 index), and a pool of Python threads lets the main thread take Ctrl-C
between pieces. Pieces are taken dynamically (``pieces_per_thread`` per thread), so a picture whose surfaces crowd
one part of the image keeps every thread busy.

With ``NUMBA_DISABLE_JIT=1`` ``kernel`` returns the plain Python function, so the test suite can run (and
measure coverage of) every kernel line as Python.
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numba


def _load_numba_array_math_without_scipy() -> None:
    """Import ``numba.np.arraymath`` without the SciPy import it does only to ask whether SciPy is installed.

    Numba loads its array-math implementations before it runs any kernel (cached or not), and that module's first
    line of work, ``_HAVE_BLAS = _check_blas()``, imports ``scipy.linalg.cython_blas`` — 0.17 s of a 1.1 s warm
    render, for a flag that only picks ``np.correlate``'s inner loop. SciPy is one of frustum's dependencies, so the
    answer is yes: here the check asks ``find_spec("scipy")`` (no import) instead, while the module is imported, and
    the real ``ensure_blas`` is put back at once (``np.dot`` and ``np.linalg`` in any kernel still import SciPy
    when they compile, as before). On a Numba without these names nothing is changed."""
    import importlib.util
    import sys

    if "numba.np.arraymath" in sys.modules or "scipy.linalg" in sys.modules:
        return
    try:
        from numba.np import linalg
    except ImportError:  # pragma: no cover - a Numba laid out differently: keep its own import order
        return
    real = getattr(linalg, "ensure_blas", None)
    if real is None:  # pragma: no cover
        return

    def scipy_installed() -> None:
        if importlib.util.find_spec("scipy") is None:
            raise ImportError("scipy is required for linear algebra")

    linalg.ensure_blas = scipy_installed
    try:
        from numba.np import arraymath
    finally:
        linalg.ensure_blas = real
    if getattr(arraymath, "ensure_blas", None) is scipy_installed:
        arraymath.ensure_blas = real


_load_numba_array_math_without_scipy()

from llvmlite import ir  # noqa: E402
from numba.core import cgutils, event, types  # noqa: E402
from numba.extending import intrinsic  # noqa: E402
from numba.np.ufunc import parallel as _numba_parallel  # noqa: E402

import frustum.raster  # noqa: E402

__all__ = [
    "fence", "kernel", "parallel_for", "parallel_kernel", "prange", "prefetch", "set_threads", "stream", "threads",
]



def package_digest(folder: Path) -> str:
    """SHA-1 of the names and contents of the modules in `folder`: for ``frustum.raster``, part of each kernel's
    cache stamp (``_cached``)."""
    digest = hashlib.sha1()
    for path in sorted(folder.glob("*.py")):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


_DIGEST = package_digest(Path(frustum.raster.__file__).parent)


def _cached(options: dict[str, Any]) -> Callable[[Callable], Any]:
    """``numba.njit(cache=True, **options)`` whose on-disk cache is also invalidated when any other module of
    ``frustum.raster`` changes. Numba stamps a cache with its function's own source file only, so a kernel that
    calls (and inlines) a helper from another module kept running the helper's old code after an edit there
    (a ``git pull`` into an editable install does just that)."""
    jit = numba.njit(cache=True, **options)

    def decorate(function: Callable) -> Any:
        dispatcher = jit(function)
        cache_file = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
        if cache_file is not None and hasattr(cache_file, "_source_stamp"):
            cache_file._source_stamp = (cache_file._source_stamp, _DIGEST)
        return dispatcher

    return decorate


kernel = _cached({"nogil": True})
_parfor_kernel = _cached({"nogil": True, "parallel": True})
prange = numba.prange



@intrinsic
def _prefetch(typingctx, array, i, j):
    """LLVM's ``llvm.prefetch`` (read, high locality) of the cache line holding ``array[i, j]``."""

    def codegen(context, builder, signature, args):
        kind = signature.args[0]
        data = context.make_array(kind)(context, builder, args[0])
        # indices as intp: an int32 index (a Mesh's int32 faces) beside an int64 one is not one LLVM type
        index = [context.cast(builder, v, t, types.intp) for v, t in zip(args[1:], signature.args[1:], strict=True)]
        pointer = cgutils.get_item_pointer(context, builder, kind, data, index, wraparound=False)
        byte = ir.IntType(8).as_pointer()
        int32 = ir.IntType(32)
        function = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(ir.VoidType(), [byte, int32, int32, int32]), "llvm.prefetch.p0i8"
        )
        builder.call(function, [builder.bitcast(pointer, byte), int32(0), int32(3), int32(1)])
        return context.get_dummy_value()

    return types.void(array, i, j), codegen


def _no_prefetch(array: Any, i: int, j: int) -> None:
    """``prefetch`` as plain Python (``NUMBA_DISABLE_JIT=1``): nothing to do."""


prefetch = _no_prefetch if numba.config.DISABLE_JIT else _prefetch
"""``prefetch(array, i, j)`` in a kernel: start loading the cache line of the 2-D ``array[i, j]`` (no effect on
results). For loops that gather rows by index (tile entry → face → its vertices), issued some iterations ahead,
so the loads of many iterations are in flight at once instead of each waiting in turn."""



@intrinsic
def _stream(typingctx, array, i, j, value):
    """$array[i, j] = value$ as a non-temporal store (LLVM ``!nontemporal``)."""

    def codegen(context, builder, signature, args):
        kind = signature.args[0]
        data = context.make_array(kind)(context, builder, args[0])
        index = [context.cast(builder, v, t, types.intp) for v, t in zip(args[1:3], signature.args[1:3], strict=True)]
        pointer = cgutils.get_item_pointer(context, builder, kind, data, index, wraparound=False)
        stored = builder.store(context.cast(builder, args[3], signature.args[3], kind.dtype), pointer)
        stored.set_metadata("nontemporal", builder.module.add_metadata([ir.IntType(32)(1)]))
        return context.get_dummy_value()

    return types.void(array, i, j, value), codegen


@intrinsic
def _fence(typingctx):
    """A sequentially consistent memory fence (``mfence`` on x86: it orders non-temporal stores too)."""

    def codegen(context, builder, signature, args):
        builder.fence("seq_cst")
        return context.get_dummy_value()

    return types.void(), codegen


def _store(array: Any, i: int, j: int, value: Any) -> None:
    """``stream`` as plain Python (``NUMBA_DISABLE_JIT=1``): an ordinary store."""
    array[i, j] = value


def _no_fence() -> None:
    """``fence`` as plain Python: nothing to order."""


stream = _store if numba.config.DISABLE_JIT else _stream
"""``stream(array, i, j, value)`` in a kernel: ``array[i, j] = value`` bypassing the caches (a non-temporal
store: the line is not read first and does not evict what the kernel still uses), for output written once and not
read again by the kernel; ``fence()`` after the last one."""
fence = _no_fence if numba.config.DISABLE_JIT else _fence
"""``fence()`` in a kernel: a full memory fence (after ``stream`` stores, before the piece returns)."""

NOTICE_AFTER = 1.0
"""Seconds of kernel compilation after which ``frustum.raster.compile_notice`` is called (once per process)."""


class _CompileWatch(event.Listener):
    """Calls ``frustum.raster.compile_notice`` once, when compilation has gone on for ``NOTICE_AFTER`` seconds."""

    def __init__(self) -> None:
        self.depth = 0
        self.spent = 0.0
        self.started = 0.0
        self.done = False

    def _notice(self) -> None:
        if not self.done and (self.depth > 0 or self.spent >= NOTICE_AFTER):
            self.done = True
            notice = frustum.raster.compile_notice
            if notice is not None:
                notice()

    def on_start(self, ev: event.Event) -> None:
        self.depth += 1
        if self.depth > 1 or self.done:
            return
        self.started = time.perf_counter()
        if self.spent >= NOTICE_AFTER:
            self._notice()
        else:
            timer = threading.Timer(NOTICE_AFTER - self.spent, self._notice)
            timer.daemon = True
            timer.start()

    def on_end(self, ev: event.Event) -> None:
        self.depth -= 1
        if self.depth == 0:
            self.spent += time.perf_counter() - self.started


event.register("numba:compile", _CompileWatch())

_lock = threading.Lock()
_threads: int | None = None
_pool: ThreadPoolExecutor | None = None
_pool_size = 0


def threads() -> int:
    """Threads the parallel kernels use: ``set_threads(n)`` if called, else Numba's own setting
    (``numba.set_num_threads``, ``NUMBA_NUM_THREADS``, default the number of cores)."""
    if _threads is not None:
        return _threads
    return numba.get_num_threads() if _numba_parallel._is_initialized else int(numba.config.NUMBA_NUM_THREADS)


def set_threads(count: int | None) -> None:
    """Use `count` threads for the parallel kernels (None: back to Numba's setting)."""
    global _threads
    _threads = None if count is None else max(1, int(count))


def _executor(size: int) -> ThreadPoolExecutor:
    global _pool, _pool_size
    with _lock:
        if _pool is None or _pool_size != size:
            if _pool is not None:
                _pool.shutdown(wait=False)
            _pool, _pool_size = ThreadPoolExecutor(size, thread_name_prefix="frustum-kernel"), size
        return _pool


def parallel_for(compiled: Callable[..., None], count: int, args: tuple, *, pieces_per_thread: int = 4,
                 work: int | None = None, grain: int = 1) -> None:  # fmt: skip
    """Run ``compiled(*args, start, stop)`` over ``[0, count)`` split into pieces, on ``threads()`` threads.

    `work` (default `count`) estimates the whole job in any unit and `grain` is the least of it worth a piece of
    its own: a small job runs on the calling thread (handing a piece to a thread costs tens of microseconds, which
    a scene of 10⁴ small meshes pays per kernel and item). Otherwise the calling thread and ``threads() − 1`` pool
    threads take pieces in order from a shared counter until none are left (the caller works instead of waiting:
    one thread fewer to wake per kernel). Ctrl-C reaches the caller between its pieces; on it, or on any error in
    a piece, the pieces not yet taken are skipped, the running ones finish (each is short: they write into the
    caller's arrays), and the exception propagates.
    """
    size = threads()
    pieces = min(count, size * pieces_per_thread, (count if work is None else work) // max(grain, 1))
    if size <= 1 or pieces <= 1:
        compiled(*args, 0, count)
        return
    bounds = [count * i // pieces for i in range(pieces + 1)]
    taken = itertools.count()  # next() on it is atomic: each piece is taken once
    stop = threading.Event()

    def take() -> None:
        for piece in taken:
            if piece >= pieces or stop.is_set():
                return
            compiled(*args, bounds[piece], bounds[piece + 1])

    pool = _executor(size - 1)
    helpers: list[Future] = [pool.submit(take) for _ in range(min(size, pieces) - 1)]
    try:
        take()
        for future in helpers:
            future.result()
    except BaseException:
        stop.set()
        for future in helpers:
            future.cancel()
        for future in helpers:
            if not future.cancelled():
                future.exception()  # wait for the running pieces: they write into the caller's arrays
        raise


def parallel_kernel(items: Callable[..., int], *, work: Callable[..., int] | None = None, grain: int = 1,
                    pieces_per_thread: int = 4) -> Callable[[Callable], Callable]:  # fmt: skip
    """Decorator: a kernel over ``[start, stop)`` of ``items(*args)`` independent items, run by ``parallel_for``
    (``work(*args)`` and `grain`: below two grains of work it runs on the calling thread).

    The returned driver takes the kernel's arguments without ``start, stop``; ``driver.kernel`` is the compiled
    single-thread kernel (call it with a slice to run part of the work on the calling thread).

    Applied directly to a function that loops with ``prange`` (the older form), it compiles that function with
    Numba's ``parallel=True`` instead; prefer the slice form for new kernels.
    """
    if "prange" in getattr(getattr(items, "__code__", None), "co_names", ()):
        return _parfor_kernel(items)  # type: ignore[return-value]

    def decorate(function: Callable[..., None]) -> Callable[..., None]:
        compiled = kernel(function)

        @functools.wraps(function)
        def driver(*args: Any) -> None:
            parallel_for(compiled, int(items(*args)), args, pieces_per_thread=pieces_per_thread,
                         work=None if work is None else int(work(*args)), grain=grain)  # fmt: skip

        driver.kernel = compiled  # type: ignore[attr-defined]
        return driver

    return decorate
