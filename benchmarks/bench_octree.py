"""Benchmark: octrees from the bunny, octree set operations, the octree visible-surface method and picking.

    python benchmarks/bench_octree.py [--repeat 3] [--depths 8 10] [--trimesh-depth 8] [--picks 1000]

Measured in one run:

* ``Octree.from_mesh`` of the Stanford bunny (``bun_zipper.ply``, 69,451 triangles, its 5 bottom holes closed by
  fans) at each of `--depths`; the anchor is ``trimesh.voxel.creation.voxelize(mesh, pitch).fill()`` at the
  same cell size for `--trimesh-depth` (its subdivision method takes about a minute at 256³ on 2 busy cores, so
  the depth-10 anchor is left out by default);
* ``a | b`` of two depth-9 octrees (the bunny and the bunny moved by (37, 11, 5) cells);
* ``render_octree`` of the depth-10 bunny at 1024² (median of `repeat`; first call includes compilation);
* ``Scene.pick`` of `--picks` window positions on the 1M-triangle sphere of ``../shared/bench/scenes.py``
  (``sphere_1m``: 1000×501 UV sphere, 1920×1080), after the index is built (index build timed separately).

First calls (Numba compilation or its on-disk cache) are printed apart from the steady-state medians.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numba
import numpy as np
import trimesh

from frustum import Camera, Mesh, Octree, Perspective, Scene, render_octree

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the closed bunny: tests/testdata.py
from testdata import closed_bunny

BENCH_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "bench"  # the shared standard scenes
if not BENCH_DIR.exists():
    BENCH_DIR = Path("/work/shared/bench")


def timed(fn, repeat: int = 1):
    start = time.perf_counter()
    result = fn()
    first = time.perf_counter() - start
    runs = []
    for _ in range(repeat - 1):
        start = time.perf_counter()
        result = fn()
        runs.append(time.perf_counter() - start)
    return first, (statistics.median(runs) if runs else first), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--depths", type=int, nargs="+", default=[8, 10])
    parser.add_argument("--trimesh-depth", type=int, nargs="*", default=[8])
    parser.add_argument("--picks", type=int, default=1000)
    args = parser.parse_args()
    print(f"numba threads: {numba.get_num_threads()}")

    bunny = closed_bunny()
    extent = float((bunny.bounds[1] - bunny.bounds[0]).max())
    trees = {}
    Octree.from_mesh(bunny, 3)  # compile (or load) the pair kernel outside the timings
    for depth in args.depths:
        _, seconds, tree = timed(lambda d=depth: Octree.from_mesh(bunny, d))
        trees[depth] = tree
        print(
            f"from_mesh bunny depth {depth} ({2**depth}^3): {seconds:.2f} s, {tree.node_count} nodes, "
            f"{tree.nbytes / 2**20:.1f} MiB, volume {tree.volume:.4e} (bounds {tree.volume_bounds[0]:.4e} .. "
            f"{tree.volume_bounds[1]:.4e})"
        )
    for depth in args.trimesh_depth:
        mesh = trimesh.Trimesh(bunny.vertices, bunny.faces, process=False)
        _, seconds, grid = timed(lambda d=depth, m=mesh: trimesh.voxel.creation.voxelize(m, extent / 2**d).fill())
        print(f"trimesh voxelize+fill bunny pitch extent/{2**depth}: {seconds:.2f} s, {int(grid.filled_count)} cells")

    nine = trees.get(9) or Octree.from_mesh(bunny, 9)
    moved = nine.shifted((37, 11, 5))
    first, median, union = timed(lambda: nine | moved, args.repeat)
    print(f"union of two depth-9 octrees ({nine.node_count} and {moved.node_count} nodes): median {median:.3f} s "
          f"(first {first:.3f} s), {union.node_count} nodes")  # fmt: skip

    solid = trees.get(10) or trees[max(trees)]
    center = solid.bounds.mean(axis=0)
    camera = Camera.look_at(center + np.array([0.1, 0.08, 0.22]), center, projection=Perspective(0.9, 0.01, 10.0),
                            width=1024, height=1024)  # fmt: skip
    first, median, frame = timed(lambda: render_octree(solid, camera), args.repeat)
    print(f"render_octree depth {solid.depth} at 1024^2: median {median * 1e3:.1f} ms (first call {first:.2f} s), "
          f"{(frame.depth < 1).mean():.1%} of pixels covered")  # fmt: skip

    sys.path.insert(0, str(BENCH_DIR))
    import scenes  # the shared standard scenes

    data = scenes.sphere_scene(n_lat=501, n_lon=1000, width=1920, height=1080)
    scene = Scene()
    scene.add(Mesh(data["vertices"], data["faces"].astype(np.int64)))
    sphere_camera = Camera.look_at(data["eye"], data["target"], data["up"],
                                   Perspective(np.radians(data["fovy_deg"]), data["near"], data["far"]),
                                   data["width"], data["height"])  # fmt: skip
    rng = np.random.default_rng(0)
    pixels = rng.uniform([0, 0], [1920, 1080], size=(args.picks, 2))
    build, _, _ = timed(lambda: scene.pick(sphere_camera, 960.5, 540.5))
    start = time.perf_counter()
    hits = sum(scene.pick(sphere_camera, x, y) is not None for x, y in pixels)
    per_pick = (time.perf_counter() - start) / args.picks
    print(f"pick on the 1M-triangle sphere: index build + first pick {build:.2f} s, then {per_pick * 1e3:.3f} ms per "
          f"pick ({args.picks} picks, {hits} hits)")  # fmt: skip


if __name__ == "__main__":
    main()
