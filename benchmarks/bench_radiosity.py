"""Radiosity of the Cornell box at about 1k and 10k patches (50k with `--patches`) beside Mitsuba 3's path tracer.

    python benchmarks/bench_radiosity.py [--patches 1000 10000] [--repeat 3] [--form-factors ray] [--json PATH]

For each size: ``frustum.radiosity`` to a residual of 1e-3 (median wall and CPU time of ``--repeat`` runs (target:
10k patches <= 15 s wall on a quiet machine), shots, the
residual; ``--form-factors ray`` (default) or ``hemicube``), the mean radiance of each wall, and its relative
difference from Mitsuba's (``path`` integrator,
``scalar_rgb``, an orthographic sensor covering each wall face-on, as ``tests/test_radiosity.py`` does). Mitsuba's
own time is the time to a per-wall standard error of 1 % (samples per pixel doubled until every wall's standard
error of the mean, from the pixel variance, is at most 1 % of its mean), for scale: the two methods answer
different questions (a view-independent solution for every patch vs. one picture's pixels).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import frustum as fr  # noqa: E402
from cornell import WALLS, cornell_box  # noqa: E402

CELLS_PER_PATCH_SIZE = 26.2
"""The Cornell box makes about 26.2 / patch_size² patches (measured: 0.1 → 2624, 0.05 → 10496)."""


def wall_means(result: fr.RadiosityResult) -> np.ndarray:
    patches = result.patch_mesh
    return np.array([(result.radiosity[patches.item == i] * patches.area[patches.item == i, None]).sum(axis=0)
                     / patches.area[patches.item == i].sum() for i in range(5)])  # fmt: skip


def mitsuba_walls(scene: fr.Scene, target: float = 0.01, size: int = 64) -> tuple[np.ndarray, float, int]:
    """Mitsuba's per-wall means, the seconds it took to reach a standard error of `target`, and the spp used."""
    from test_radiosity import _mitsuba_wall_means_and_errors

    spp, elapsed = 4, 0.0
    while True:
        start = time.perf_counter()
        means, errors = _mitsuba_wall_means_and_errors(scene, spp=spp, size=size)
        elapsed = time.perf_counter() - start
        if (errors / np.maximum(means, 1e-12)).max() <= target or spp >= 4096:
            return means, elapsed, spp
        spp *= 2


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--patches", type=int, nargs="+", default=[1000, 10000])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--form-factors", default="ray", choices=["ray", "hemicube"])
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    scene = cornell_box()
    fr.radiosity(scene, patch_size=0.3, hemicube=32, form_factors=args.form_factors)  # compile (or load) kernels
    reference, mitsuba_seconds, spp = mitsuba_walls(scene)
    print(f"Mitsuba 3 (path, scalar_rgb): per-wall standard error <= 1 % at {spp} spp on 64² per wall: "
          f"{mitsuba_seconds:.2f} s")  # fmt: skip
    rows = []
    for target in args.patches:
        size = float(np.sqrt(CELLS_PER_PATCH_SIZE / target))
        times, cpu = [], []
        try:
            for _ in range(args.repeat):
                start, start_cpu = time.perf_counter(), time.process_time()
                result = fr.radiosity(scene, patch_size=size, form_factors=args.form_factors)
                times.append(time.perf_counter() - start)
                cpu.append(time.process_time() - start_cpu)
        except fr.FrustumError as error:  # over the work budget (50k patches with ray form factors)
            print(f"about {target} patches: {error}")
            continue
        difference = np.abs(wall_means(result) / reference - 1.0).max(axis=1)
        row = {"patches": result.patches, "patch_size": size, "seconds": statistics.median(times), "runs": times,
               "cpu_seconds": statistics.median(cpu),
               "shots": result.iterations, "residual": result.residual,
               "wall_difference": dict(zip(WALLS[:5], difference.round(4).tolist(), strict=True))}  # fmt: skip
        rows.append(row)
        walls = ", ".join(f"{k} {v:.1%}" for k, v in row["wall_difference"].items())
        target_note = " (target <= 15 s at 10k patches)" if 5000 <= result.patches <= 20000 else ""
        print(f"{result.patches:6d} patches: {row['seconds']:6.2f} s wall{target_note}, {row['cpu_seconds']:.2f} s "
              f"CPU (medians of {args.repeat}), {result.iterations} shots, residual {result.residual:.1e}; "
              f"|frustum/Mitsuba − 1| per wall: {walls}")  # fmt: skip
    if args.json:
        args.json.write_text(json.dumps({"mitsuba_seconds": mitsuba_seconds, "mitsuba_spp": spp, "rows": rows},
                                        indent=2))  # fmt: skip


if __name__ == "__main__":
    main()
