"""Numba's start-up as a short-lived command needs it: imported without the optional packages its import only
probes, the kernels loaded from its on-disk cache without its whole-target refresh first, and its runtime loaded
compiled instead of compiled anew.

**The import** (``import_numba``). ``import numba`` imports PyYAML (to read a ``.numba_config.yaml`` in the working
folder), colorama (for coloured error messages under ``NUMBA_COLOR_SCHEME``) and SciPy (to check its version):
about 0.02 s of CPU of a warm render. Where there is no such file and no colour scheme, they are hidden while Numba
imports, so Numba takes the path it takes without them (no file read, messages uncoloured, SciPy not checked), and
shown again at once: anything that imports them later gets them as usual.

**The kernels** (``load_kernels_lean``). Numba's ``Cache.load_overload`` calls ``target_context.refresh()`` before
it loads a cached kernel: the refresh imports and installs every implementation registry of the CPU target (about
60 modules: typed containers, the random generators, jitclass, datetime, the CFFI parser, the third-party entry
points) and initialises Numba's runtime (NRT). Loading machine code from the cache needs only the runtime; the
registries are for compiling. On a warm command that refresh was most of the "kernel loading" stage (about 0.08 s
of the 0.11 s of four kernels). And before a kernel's first call Numba initialises its third-party extensions: it
reads the entry points of every installed distribution (about 0.01 s in an environment of 240 packages).
``load_kernels_lean`` makes the cache load initialise the runtime alone, and leaves the extensions to that refresh.
Nothing else changes: a kernel missing from the cache still compiles, and Numba's compiler refreshes the whole
target, extensions included, before it compiles (``CompilerBase.__init__``), so a compile sees every registry as
before. The machine code loaded is the same bytes, so every output is the same.

**The runtime** (``_initialize_runtime``): Numba compiles its runtime's LLVM module on every start; here its object
code is kept beside the kernels and loaded, as a cached kernel is.

All three are the program's choice (``frustum.app.work.render_files``, ``frustum.app.timing``): a library user's
process keeps Numba's own order.
"""

from __future__ import annotations

import os
import sys
from typing import Any

__all__ = ["import_numba", "load_kernels_lean"]

PROBED = ("yaml", "colorama", "scipy")
"""The optional packages ``import numba`` imports only to probe (``import_numba`` hides them)."""


def import_numba() -> None:
    """Import Numba with the ``PROBED`` packages it would import only to probe hidden (not those already imported,
    PyYAML where ``.numba_config.yaml`` exists, colorama under ``NUMBA_COLOR_SCHEME``)."""
    if "numba" in sys.modules:
        return
    hidden = [name for name in PROBED if name not in sys.modules]
    if os.path.exists(".numba_config.yaml") and "yaml" in hidden:
        hidden.remove("yaml")
    if os.environ.get("NUMBA_COLOR_SCHEME", "no_color") != "no_color" and "colorama" in hidden:
        hidden.remove("colorama")
    for name in hidden:
        sys.modules[name] = None  # type: ignore[assignment] - "import name" raises ImportError meanwhile
    try:
        import numba  # noqa: F401
    finally:
        for name in hidden:
            if name in sys.modules and sys.modules[name] is None:
                del sys.modules[name]


_STATE = {"installed": False}


def load_kernels_lean() -> None:
    """Load cached kernels with Numba's runtime initialised instead of the whole target refreshed (once per
    process; nothing under ``NUMBA_DISABLE_JIT=1`` or on a Numba without these names)."""
    if _STATE["installed"]:
        return
    _STATE["installed"] = True
    import_numba()
    import numba

    if numba.config.DISABLE_JIT:
        return
    try:
        from numba.core import caching
        from numba.core.runtime import nrt
    except ImportError:  # pragma: no cover - a Numba laid out differently: keep its own order
        return
    cache_class = getattr(caching, "Cache", None)
    if cache_class is None or not hasattr(cache_class, "_load_overload") or not hasattr(nrt, "rtsys"):
        return  # pragma: no cover

    def load_overload(cache: Any, signature: Any, target_context: Any) -> Any:
        _initialize_runtime(target_context, getattr(cache, "_cache_path", None))  # what the machine code calls
        with cache._guard_against_spurious_io_errors():
            return cache._load_overload(signature, target_context)
        return None  # pragma: no cover - the guard swallowed an I/O error: compile instead, as Numba does

    load_overload.__doc__ = cache_class.load_overload.__doc__
    cache_class.load_overload = load_overload
    from numba.core import dispatcher

    base = getattr(dispatcher, "_DispatcherBase", None)
    if base is not None and hasattr(base, "_compilation_chain_init_hook"):
        base._compilation_chain_init_hook = _extensions_with_the_refresh


def _extensions_with_the_refresh(dispatcher: Any) -> None:
    """A kernel's first call: Numba's third-party extensions (entry points ``numba_extensions``) are initialised by
    the target refresh before a compile (``numba.core.entrypoints.init_all`` in the CPU target's registries), not
    here before the arguments' typing: frustum passes NumPy arrays and numbers, which no extension types."""


def _runtime_key(target_context: Any) -> tuple:
    """What the runtime's machine code depends on: Numba, llvmlite, Python, and the codegen's target (triple, CPU
    name and features: ``magic_tuple``, as Numba keys its cache)."""
    import llvmlite
    import numba

    return (numba.__version__, llvmlite.__version__, sys.version, target_context.codegen().magic_tuple())


def _initialize_runtime(target_context: Any, folder: str | None) -> None:
    """Initialise Numba's runtime as ``nrt.rtsys.initialize`` does, with its machine code from `folder` (the loading
    kernel's cache folder) where an earlier command left it, else compiled and left there.

    ``rtsys.initialize`` registers the runtime's C helpers and compiles its LLVM module (reference counting, memory
    information) on every start: about 0.02 s of CPU. Here the compiled object code is kept in
    ``numba-runtime-<key>.nrt`` (keyed by ``_runtime_key``, written atomically) and loaded as Numba loads a cached
    kernel (``unserialize_library``); a missing, unreadable or foreign file means compiling, as Numba does."""
    import pickle
    import zlib

    from llvmlite import binding
    from numba.core import config
    from numba.core.compiler_lock import global_compiler_lock
    from numba.core.runtime import _nrt_python, nrt, nrtdynmod

    runtime = nrt.rtsys
    with global_compiler_lock:
        if runtime._init:
            return
        if folder is None or not hasattr(nrtdynmod, "create_nrt_module"):  # pragma: no cover - another Numba
            runtime.initialize(target_context)
            return
        key = _runtime_key(target_context)
        path = os.path.join(folder, f"numba-runtime-{zlib.crc32(repr(key).encode()):08x}.nrt")
        try:
            with open(path, "rb") as file:
                stored_key, state = pickle.load(file)
        except Exception:  # missing, unreadable, truncated: compiled below
            stored_key, state = None, None
        if config.NRT_STATS:
            _nrt_python.memsys_enable_stats()
        for name, address in _nrt_python.c_helpers.items():
            binding.add_symbol(name if name.startswith("_") else f"NRT_{name}", address)
        if stored_key == key:
            runtime._library = target_context.codegen().unserialize_library(state)
        else:
            module, library = nrtdynmod.create_nrt_module(target_context)
            library.add_ir_module(module)
            library.enable_object_caching()
            library.finalize()
            _keep(path, (key, library.serialize_using_object_code()))
            runtime._library = library
        runtime._init = True


def _keep(path: str, value: Any) -> None:
    """Write `value` pickled to `path` atomically (a temporary renamed); nothing when the folder cannot be
    written."""
    import contextlib
    import pickle
    import tempfile

    with contextlib.suppress(OSError):
        handle, temporary = tempfile.mkstemp(dir=os.path.dirname(path), suffix=".part")
        try:
            with os.fdopen(handle, "wb") as file:
                pickle.dump(value, file, protocol=pickle.HIGHEST_PROTOCOL)
            os.replace(temporary, path)
        finally:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
