"""``FRUSTUM_PROFILE=1``: where the time of a plain ``frustum render FILE -o OUT`` goes, stage by stage, in one line
on stderr at the end.

Stages: Python's own start-up (from the process's start to the program's first line), the imports of NumPy and
Numba, Numba's compiler target setup, the imports of frustum's renderer, reading the file (mesh or scene file,
the scene built), loading the kernels from Numba's cache (and compiling those it lacks: a first run), the render
itself (without the kernels' loading and compiling), and encoding and writing the PNG. ``python -X importtime`` tells
the imports apart further.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Callable, Iterator
from typing import Any

__all__ = ["Profile", "enabled"]


def enabled() -> bool:
    """Whether ``FRUSTUM_PROFILE`` asks for the per-stage timer (1, on, yes, true)."""
    return os.environ.get("FRUSTUM_PROFILE", "").strip().lower() in ("1", "on", "yes", "true")


def _since_process_start() -> float | None:
    """Seconds since this process started (Linux's /proc), or None."""
    from pathlib import Path

    try:
        ticks = int(Path("/proc/self/stat").read_text().rsplit(")", 1)[1].split()[19])
        uptime = float(Path("/proc/uptime").read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return None
    return max(0.0, uptime - ticks / os.sysconf("SC_CLK_TCK"))


class Profile:
    """The seconds of each stage of one command, in the order first seen."""

    def __init__(self) -> None:
        self.start = time.perf_counter()
        self.stages: dict[str, float] = {}
        self.kernels = 0
        startup = _since_process_start()
        if startup is not None:
            self.stages["python start-up"] = startup

    def add(self, name: str, seconds: float) -> None:
        self.stages[name] = self.stages.get(name, 0.0) + seconds

    @contextlib.contextmanager
    def stage(self, name: str) -> Iterator[None]:
        start = time.perf_counter()
        try:
            yield
        finally:
            self.add(name, time.perf_counter() - start)

    def wrap(self, owner: Any, attribute: str, name: str) -> None:
        """Time every call of ``owner.attribute`` as stage `name` (for this process: it is a short-lived one)."""
        function = getattr(owner, attribute)

        def timed(*arguments: Any, **keywords: Any) -> Any:
            with self.stage(name):
                return function(*arguments, **keywords)

        setattr(owner, attribute, timed)

    def watch_kernels(self) -> None:
        """Time Numba's loads of kernels from its cache ("kernel loading") and its compilations, outermost only
        ("kernel compiling": a first run in a new environment)."""
        from numba.core import caching, event

        from frustum.app.numba_start import load_kernels_lean

        load_kernels_lean()  # the program's way of loading, timed (not replaced by it afterwards)
        profile = self
        load = caching.Cache.load_overload

        def timed_load(cache: Any, *arguments: Any, **keywords: Any) -> Any:
            with profile.stage("kernel loading"):
                loaded = load(cache, *arguments, **keywords)
            profile.kernels += loaded is not None
            return loaded

        caching.Cache.load_overload = timed_load

        class Listener(event.Listener):
            depth = 0
            started = 0.0

            def on_start(self, ev: event.Event) -> None:
                if self.depth == 0:
                    self.started = time.perf_counter()
                self.depth += 1

            def on_end(self, ev: event.Event) -> None:
                self.depth -= 1
                if self.depth == 0:
                    profile.add("kernel compiling", time.perf_counter() - self.started)

        event.register("numba:compile", Listener())

    def line(self) -> str:
        total = time.perf_counter() - self.start + self.stages.get("python start-up", 0.0)
        for inner in ("kernel loading", "kernel compiling"):  # inside the render
            if "render" in self.stages and inner in self.stages:
                self.stages["render"] -= self.stages[inner]
        parts = [f"{name} {seconds:.3f} s" + (f" ({self.kernels} kernels)" if name == "kernel loading" else "")
                 for name, seconds in self.stages.items()]  # fmt: skip
        return "profile: " + ", ".join(parts) + f"; total {total:.3f} s"


def profiled(work: Callable[[], Any], profile: Profile) -> Any:
    """Run a plain render's `work` with its stages timed (``frustum.app.work.run_render``)."""
    with profile.stage("import numpy and numba"):
        from frustum.app.numba_start import import_numba

        import_numba()  # as the render imports it (``numba_start``): a stage of its own
    with profile.stage("numba target setup"):
        from numba.core.registry import cpu_target

        cpu_target.target_context  # noqa: B018 - the first access sets the compiler's target up
    with profile.stage("import frustum"):
        import frustum.frame
        import frustum.scenefile.commands
        import frustum.scenefile.loader
    profile.watch_kernels()
    profile.wrap(frustum.scenefile.commands, "_load_scene_file", "file reading")
    profile.wrap(frustum.scenefile.loader.SceneFile, "render", "render")
    profile.wrap(frustum.frame.Frame, "save", "png write")
    try:
        return work()
    finally:
        sys.stderr.write(profile.line() + "\n")
