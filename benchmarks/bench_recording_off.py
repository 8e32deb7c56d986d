"""The recording hooks of ``frustum.steps`` cost nothing when off: the instrumented production functions, timed
against another checkout of frustum (the anchor, e.g. ``main`` before the hooks) in the same run.

    python benchmarks/bench_recording_off.py --against /path/to/other/checkout/src [--rounds 3]

Each round runs this file's timing part once per tree (tree order alternating, fresh interpreters, kernels
compiled before timing); printed: per function the median over rounds for each tree and the ratio
this / anchor. On a shared machine ratios within about ±30 % are noise (compare a function whose code is the same
in both trees).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve()
OWN_SRC = HERE.parents[1] / "src"


def timings() -> dict[str, float]:
    import time

    import numpy as np

    import frustum
    from frustum.clipping import clip_line, clip_polygon

    rng = np.random.default_rng(0)
    segments = [(np.append(rng.uniform(-3, 3, 3), 1.0), np.append(rng.uniform(-3, 3, 3), 1.0)) for _ in range(2000)]
    polygons = [np.column_stack([rng.uniform(-2, 2, (6, 3)), np.ones(6)]) for _ in range(500)]
    soup = list(np.random.default_rng(1).uniform(-1, 1, (40, 3, 3)))

    def best_of_three(function) -> float:
        times = []
        for _ in range(3):
            start = time.perf_counter()
            function()
            times.append(time.perf_counter() - start)
        return statistics.median(times)

    scene = frustum.Scene(lights=[frustum.DirectionalLight((-0.4, -0.6, -1.0))])
    scene.add(frustum.uv_sphere(1.0, 64, 32), frustum.Material())
    camera = frustum.Camera.look_at((0, 0.5, 4), (0, 0, 0), width=256, height=192)
    methods = ("scan-line", "area-subdivision", "a-buffer", "ray-casting")
    for method in methods:
        frustum.render(scene, camera, method=method)  # compile (or load the cache) before timing
    results = {
        "clip_line cohen-sutherland x2000": best_of_three(
            lambda: [clip_line(a, b, method="cohen-sutherland") for a, b in segments]
        ),
        "clip_line liang-barsky x2000": best_of_three(lambda: [clip_line(a, b) for a, b in segments]),
        "clip_polygon x500": best_of_three(lambda: [clip_polygon(p) for p in polygons]),
        "koch_curve(9)": best_of_three(lambda: frustum.koch_curve(9)),
        "depth_sort 40 triangles": best_of_three(lambda: frustum.depth_sort(soup, camera)),
        "BSPTree 40 triangles": best_of_three(lambda: frustum.BSPTree(soup).back_to_front_indices(eye=(0, 0, 5))),
    }
    for method in methods:
        results[f"render {method} 256x192"] = best_of_three(lambda m=method: frustum.render(scene, camera, method=m))
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", type=Path, required=True, help="the anchor checkout's src folder")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    trees = {"this": OWN_SRC, "anchor": args.against.resolve()}
    runs: dict[str, list[dict[str, float]]] = {"this": [], "anchor": []}
    for round_ in range(args.rounds):
        for name in ("this", "anchor") if round_ % 2 == 0 else ("anchor", "this"):
            env = dict(os.environ, PYTHONPATH=str(trees[name]))
            out = subprocess.run([sys.executable, str(HERE), "--child"], env=env, capture_output=True, text=True,
                                 check=True)  # fmt: skip
            runs[name].append(json.loads(out.stdout.strip().splitlines()[-1]))
    print(f"{'function':<36} {'this (s)':>10} {'anchor (s)':>11} {'ratio':>6}")
    for key in runs["this"][0]:
        this = statistics.median(run[key] for run in runs["this"])
        anchor = statistics.median(run[key] for run in runs["anchor"])
        print(f"{key:<36} {this:>10.4f} {anchor:>11.4f} {this / anchor:>6.2f}")


if __name__ == "__main__":
    if "--child" in sys.argv:
        print(json.dumps(timings()))
    else:
        main()
