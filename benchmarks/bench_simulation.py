"""Benchmark: particle and mass–spring simulation, and drawing particles.

    python benchmarks/bench_simulation.py [--repeat 5] [--particles 1000000] [--frames 200] [--gif-size 320x240]

1. One ``ParticleSystem.step`` of 10⁶ particles with gravity, drag and a plane collision (no births or deaths:
   the lifetime is long and the rate zero, so the step is the dynamics alone; the fused compiled pass of
   ``raster.particle_step``).
2. ``render`` of 10⁶ additive soft sprites at 1920×1080 over a ground plane (the whole render, surfaces included;
   the plane alone is timed too, so the particle pass is the difference).
3. One ``"implicit-euler"`` step of a 100×100 cloth (9,801 cells, 58,808 springs: assembly + sparse CG).
4. A 200-frame fountain GIF end to end (``simulate(..., path=...)``: stepping, rendering, palette, writing).

Each line gives the first call (including Numba compilation or its cache load) and the median of `repeat` runs
after it, with the thread count. ``--compile`` measures the particle kernels' cold compile time in a fresh
process with an empty ``NUMBA_CACHE_DIR``.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numba
import numpy as np

import frustum as fr


def _time(fn, repeat: int) -> tuple[float, float]:
    start = time.perf_counter()
    fn()
    first = time.perf_counter() - start
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - start)
    return first, statistics.median(runs)


def million_particles(count: int) -> fr.ParticleSystem:
    system = fr.ParticleSystem(
        emitter=fr.DiskEmitter((0, 1.0, 0), radius=2.0, spread=0.6, speed=3.0, speed_variance=1.0), rate=0.0,
        lifetime=1e9, forces=[fr.Gravity(), fr.Drag(0.1)], colliders=[fr.PlaneCollider((0, 0, 0), (0, 1, 0))],
        seed=0, size=0.01, color=(1.0, 0.5, 0.1), opacity=0.3,
    )  # fmt: skip
    system.emit(count)
    return system


def bench_step(count: int, repeat: int) -> None:
    system = million_particles(count)
    first, median = _time(lambda: system.step(1 / 120), repeat)
    print(f"particle step, {count} particles (gravity, drag, plane): first {first:.3f} s, median {median:.3f} s "
          f"({count / median / 1e6:.1f} M particles/s)")  # fmt: skip


def bench_sprites(count: int, repeat: int) -> None:
    system = million_particles(count)
    for _ in range(30):
        system.step(1 / 60)
    ground = fr.Mesh([[-6, 0, -6], [6, 0, -6], [6, 0, 6], [-6, 0, 6]], [[0, 2, 1], [0, 3, 2]])
    scene = fr.Scene(lights=[fr.DirectionalLight((-1, -2, -1))])
    scene.add(ground, fr.Material(color=(0.3, 0.3, 0.3)))
    camera = fr.Camera.look_at((0, 3, 8), (0, 1, 0), (0, 1, 0), fr.Perspective(math.radians(45), 0.1, 100), 1920,
                               1080)  # fmt: skip
    _, plain = _time(lambda: fr.render(scene, camera), repeat)
    scene.add_particles(system, style="sprites", blending="additive")
    first, median = _time(lambda: fr.render(scene, camera), repeat)
    print(f"render {count} sprites at 1920x1080 (additive, over a plane): first {first:.3f} s, median {median:.3f} s"
          f" (plane alone {plain:.3f} s: particle pass {median - plain:.3f} s)")  # fmt: skip


def bench_cloth(repeat: int) -> None:
    sheet = fr.cloth(2.0, 2.0, 100, 100, pinned=[0, 99], gravity=(0, -9.81, 0), integrator="implicit-euler")
    for _ in range(3):
        sheet.step(1 / 60)
    first, median = _time(lambda: sheet.step(1 / 60), repeat)
    print(f"implicit-euler step, 100x100 cloth ({sheet.springs.shape[0]} springs): first {first:.3f} s, "
          f"median {median:.3f} s")  # fmt: skip


def bench_gif(frames: int, size: tuple[int, int]) -> None:
    fountain = fr.ParticleSystem(
        emitter=fr.PointEmitter((0, 0, 0), direction=(0, 1, 0), spread=0.25, speed=6.0, speed_variance=0.5),
        rate=3000.0, lifetime=2.0, forces=[fr.Gravity(), fr.Drag(0.05)], colliders=[fr.PlaneCollider()], seed=1,
        size=0.03, color=[(0.0, (0.6, 0.8, 1.0)), (1.0, (0.1, 0.3, 0.9))], opacity=[(0.0, 0.9), (1.0, 0.0)],
    )  # fmt: skip
    scene = fr.Scene(lights=[fr.DirectionalLight((-1, -2, -1))])
    scene.add_particles(fountain)
    camera = fr.Camera.look_at((0, 2, 7), (0, 1.5, 0), (0, 1, 0), None, *size)
    with tempfile.TemporaryDirectory() as folder:
        start = time.perf_counter()
        fr.simulate(scene, camera, frames, fps=30, substeps=2, path=os.path.join(folder, "fountain.gif"),
                    progress=False)  # fmt: skip
        elapsed = time.perf_counter() - start
        size_bytes = os.path.getsize(os.path.join(folder, "fountain.gif"))
    print(f"fountain GIF, {frames} frames at {size[0]}x{size[1]} (≈{fountain.count} particles): {elapsed:.2f} s "
          f"end to end ({elapsed / frames * 1000:.1f} ms/frame, {size_bytes / 1024:.0f} KiB)")  # fmt: skip


_COMPILE = """
import time, numpy as np
import frustum as fr
system = fr.ParticleSystem(emitter=fr.PointEmitter((0, 0, 0), spread=1.0), rate=0, lifetime=1, seed=0)
system.emit(100)
camera = fr.Camera.look_at((0, 0, 5), (0, 0, 0), (0, 1, 0), None, 64, 48)
scene = fr.Scene()
scene.add_particles(system)
scene.add_particles(system, style="streaks")
from frustum.render.particles import draw_particles
depth = np.ones((48, 64), np.float32); color = np.zeros((48, 64, 4), np.uint8)
start = time.perf_counter()
draw_particles(scene.particle_layers, camera, depth, color)
drawing = time.perf_counter() - start
import frustum.simulation.particles as module
module.FUSED_STEP_MINIMUM = 0
start = time.perf_counter()
system.step(0.01)
print(f"{drawing:.2f} s (drawing: 7 kernels), {time.perf_counter() - start:.2f} s (fused step)")
"""


def bench_compile() -> None:
    with tempfile.TemporaryDirectory() as cache:
        environment = {**os.environ, "NUMBA_CACHE_DIR": cache}
        # the first draw compiles project_sprites, project_streaks, count_bands, fill_bands, draw_sprites (with
        # _blend) and draw_streaks; the first fused step compiles step_linear
        result = subprocess.run([sys.executable, "-c", _COMPILE], env=environment, capture_output=True, text=True,
                                check=True)  # fmt: skip
    print(f"particle kernels, cold compile (empty NUMBA_CACHE_DIR): {result.stdout.strip()}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--particles", type=int, default=1_000_000)
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--gif-size", default="320x240")
    parser.add_argument("--compile", action="store_true", help="also measure the cold compile of the kernels")
    parser.add_argument("--only", choices=("step", "sprites", "cloth", "gif"), default=None)
    args = parser.parse_args()
    print(f"numba threads: {numba.get_num_threads()}, numpy {np.__version__}")
    width, height = (int(v) for v in args.gif_size.split("x"))
    if args.compile:
        bench_compile()
    if args.only in (None, "step"):
        bench_step(args.particles, args.repeat)
    if args.only in (None, "sprites"):
        bench_sprites(args.particles, args.repeat)
    if args.only in (None, "cloth"):
        bench_cloth(args.repeat)
    if args.only in (None, "gif"):
        bench_gif(args.frames, (width, height))


if __name__ == "__main__":
    main()
