"""Large but legitimate scenes: what 10⁴ placed meshes and 10³ point lights add to a frame.

    python benchmarks/bench_many_items.py [--nodes 10000] [--lights 1000] [--size 128] [--repeat 5]

Renders a scene of `--nodes` small spheres (one node each, its own material and transform) lit by `--lights` point
lights, and the same camera on one sphere, and prints the minimum and median wall time and the minimum process CPU
time (all threads) per frame. On a busy machine the CPU time is the steadier figure; on a quiet one the wall time
is about the same (the per-item work is mostly one thread of Python).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import frustum as fr


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=10_000)
    parser.add_argument("--lights", type=int, default=1_000)
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    angles = np.linspace(0.0, 2.0 * np.pi, args.lights, endpoint=False)
    lights = [fr.PointLight((5 * np.cos(a), 3.0, 5 * np.sin(a)), intensity=1.0 / args.lights) for a in angles]
    sphere = fr.uv_sphere(0.05, 8, 4)
    rng = np.random.default_rng(0)
    many = fr.Scene(lights=lights)
    for _ in range(args.nodes):
        many.add(sphere, fr.Material(color=(0.8, 0.5, 0.2)), fr.translate(*rng.uniform(-2.0, 2.0, 3)))
    one = fr.Scene(lights=lights)
    one.add(sphere, fr.Material(color=(0.8, 0.5, 0.2)))
    camera = fr.Camera.look_at((0, 1, 8), (0, 0, 0), (0, 1, 0), projection=fr.Perspective(fovy=0.8, near=0.1, far=30),
                               width=args.size, height=args.size)  # fmt: skip
    for label, scene in ((f"{args.nodes} nodes, {args.lights} lights", many), (f"1 node, {args.lights} lights", one)):
        fr.render(scene, camera)  # compile or load the kernels
        walls, cpus = [], []
        for _ in range(args.repeat):
            wall, cpu = time.perf_counter(), time.process_time()
            fr.render(scene, camera)
            walls.append(time.perf_counter() - wall)
            cpus.append(time.process_time() - cpu)
        print(f"{label:32s} wall min {min(walls):.3f} s, median {statistics.median(walls):.3f} s; "
              f"CPU min {min(cpus):.3f} s")  # fmt: skip


if __name__ == "__main__":
    main()
