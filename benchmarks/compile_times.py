"""Cold-start cost of the README's main job: per-kernel Numba compile seconds with an empty cache.

    python benchmarks/compile_times.py [scene.toml] [--json]

Runs the scene file's render in a fresh subprocess with ``NUMBA_CACHE_DIR`` set to an empty temporary directory
(so nothing is loaded from a previous run's cache), records Numba's ``numba:compile`` events, and prints the
compile seconds (CPU time of the compiling thread, steadier than wall time on a busy
machine) of every kernel (outermost compilations only: a kernel's callees compiled on its behalf are counted
inside it), the total, and the wall time of the whole render. A second run in a new
process with the same cache directory gives the warm time.

``frustum render`` starts a second compiler on a cold cache (``frustum.app.warmup.FIRST_PICTURE``, compiled by
``frustum.raster._background`` in a child process): the table lists what the render compiled itself; the child's
CPU seconds, its reports and how long the render waited for it are printed below the table. On a quiet machine
the cold wall time is about the render's own CPU time plus that wait. ``FRUSTUM_BACKGROUND_COMPILE=0`` measures
the single-compiler start.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

_CHILD = r"""
import json, sys, time
start = time.perf_counter()
from numba.core import event
records = []
stack = []

class Listener(event.Listener):
    def on_start(self, ev):
        stack.append((ev.data["dispatcher"].py_func.__module__ + "." + ev.data["dispatcher"].py_func.__qualname__,
                      time.process_time()))
    def on_end(self, ev):
        name, t0 = stack.pop()
        records.append({"kernel": name, "seconds": time.process_time() - t0, "depth": len(stack),
                        "signature": str(ev.data["args"])[:200]})

event.register("numba:compile", Listener())


def report():
    wall = time.perf_counter() - start
    import resource
    try:
        from frustum.raster import _background
        helper = _background._started  # the second compiler (frustum.raster._background), if one was started
    except ImportError:  # a frustum without one
        helper = None
    if helper is not None:
        helper.process.wait()  # it has ended by now (its last kernel is one the render waited for), or ends at once
    helper_cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
    print("@@" + json.dumps({"records": records, "wall": wall, "cpu": time.process_time(),
                             "helper": helper is not None and {"reported": helper.reported, "waited": helper.waited,
                                                               "cpu": helper_cpu.ru_utime + helper_cpu.ru_stime}}))


import atexit
atexit.register(report)  # the program ends its process itself, after the exit handlers (runtime.end_program)
from frustum.app.cli import main
sys.argv[0] = "frustum"
try:
    main()  # as the console script runs it (the program's garbage-collector settings apply)
except SystemExit as stop:
    if stop.code:
        raise
"""


def measure(scene: str, cache: str, out: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    proc = subprocess.run([sys.executable, "-c", _CHILD, "render", scene, "-o", out], env=env, capture_output=True,
                          text=True, cwd=ROOT)  # fmt: skip
    if proc.returncode:
        raise SystemExit(proc.stdout + proc.stderr)
    line = next(x for x in proc.stdout.splitlines() if x.startswith("@@"))
    return {**json.loads(line[2:]), "stderr": proc.stderr}


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    scene = args[0] if args else "examples/teapot.toml"
    with tempfile.TemporaryDirectory() as cache:
        out = os.path.join(cache, "out.png")
        t0 = time.perf_counter()
        cold = measure(scene, cache, out)
        cold_wall = time.perf_counter() - t0
        t0 = time.perf_counter()
        warm = measure(scene, cache, out)
        warm_wall = time.perf_counter() - t0
    if "--json" in sys.argv:
        print(json.dumps({"cold": cold, "warm": warm, "cold_process": cold_wall, "warm_process": warm_wall}))
        return
    top = sorted((r for r in cold["records"] if r["depth"] == 0), key=lambda r: -r["seconds"])
    print(f"{'kernel':60s} {'compile s':>9s}  (CPU)")
    for r in top:
        print(f"{r['kernel']:60s} {r['seconds']:9.2f}")
    total = sum(r["seconds"] for r in top)
    print(f"{'total (outermost compilations)':60s} {total:9.2f}")
    print(f"cold process {cold_wall:.2f} s (render {cold['wall']:.2f} s, process CPU {cold['cpu']:.2f} s)")
    if cold["helper"]:
        helper = cold["helper"]
        print(f"background compiler: {helper['cpu']:.2f} s CPU, reported {helper['reported']}; the render waited "
              f"{helper['waited']:.2f} s for it")
    else:
        print("background compiler: not started")
    print(f"warm process {warm_wall:.2f} s (render {warm['wall']:.2f} s, process CPU {warm['cpu']:.2f} s, "
          f"{len(warm['records'])} compilations)")


if __name__ == "__main__":
    main()
