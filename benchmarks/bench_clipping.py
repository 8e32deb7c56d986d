"""Micro-benchmark: ``clip_triangles`` on the standard terrain scene (2M triangles, off-screen sides).

    python benchmarks/bench_clipping.py [--scenes DIR] [--repeat 7]

Loads ``terrain_2m.npz`` from DIR (default ``$FRUSTUM_BENCH_SCENES`` or ``/tmp/frustum-scenes``), building it
there with ``../shared/bench/scenes.py`` when missing (about 6 s). Vertices go to clip space once, outside the
timing, with the scene's glm-compatible camera. Prints the first call's time (compilation, or loading Numba's
on-disk cache) separately from the steady state: the median of `repeat` runs, as triangles per second.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from frustum.clipping import VIEW_VOLUME_PLANES, clip_triangles
from frustum.raster import clip as kernels
from frustum.transforms import apply_homogeneous

BENCH_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "bench"


def load_terrain(scene_dir: Path) -> dict:
    """The terrain scene dict plus ``clip_from_world`` (glm's projection @ view), building the .npz if missing."""
    sys.path.insert(0, str(BENCH_DIR))
    import scenes  # the shared benchmark module, found at run time

    path = scene_dir / "terrain_2m.npz"
    if not path.exists():
        scenes.main(["--only", "terrain_2m", "--out", str(scene_dir)])
    scene = scenes.load_scene(str(path))
    view, projection = scenes.scene_matrices(scene)
    scene["clip_from_world"] = projection @ view
    return scene


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default=os.environ.get("FRUSTUM_BENCH_SCENES", "/tmp/frustum-scenes"))
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args(argv)

    scene = load_terrain(Path(args.scenes))
    vertices_clip = apply_homogeneous(scene["clip_from_world"], scene["vertices"].astype(np.float64))
    faces = scene["faces"]

    start = time.perf_counter()
    clip_triangles(vertices_clip[:3], np.array([[0, 1, 2]]))
    first_call = time.perf_counter() - start

    times = []
    for _ in range(args.repeat):
        start = time.perf_counter()
        result = clip_triangles(vertices_clip, faces)
        times.append(time.perf_counter() - start)
    median = statistics.median(times)

    codes = np.empty(len(vertices_clip), dtype=np.int64)
    kernels.region_codes(vertices_clip, np.array(VIEW_VOLUME_PLANES), codes)
    status = np.empty(len(faces), dtype=np.int8)
    kernels.classify_triangles(faces.astype(np.int64), codes, status)
    counts = np.bincount(status, minlength=3)
    print(f"terrain_2m: {len(faces):,} triangles, {len(vertices_clip):,} vertices")
    print(
        f"  trivially accepted {counts[kernels.TRIANGLE_INSIDE]:,}, rejected {counts[kernels.TRIANGLE_OUTSIDE]:,}, "
        f"clipped {counts[kernels.TRIANGLE_CROSSING]:,}; output {len(result.faces):,} triangles, "
        f"{len(result.vertices) - len(vertices_clip):,} new vertices"
    )
    print(f"  first call (compile or cache load): {first_call:.3f} s")
    print(f"  clip_triangles: median {median * 1e3:.1f} ms of {args.repeat} (min {min(times) * 1e3:.1f} ms)")
    print(f"  throughput: {len(faces) / median / 1e6:.1f} M triangles/s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
