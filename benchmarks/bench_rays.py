"""Benchmark: frustum's ray index (``raster.rays``) against Embree (``embreex``) in the same run.

    python benchmarks/bench_rays.py [--scenes bunny bunny_like_100k sphere_1m] [--size 512] [--repeats 3]
                                    [--threads N] [--classic]

Per scene: the index build (frustum: ``raster.rays.build`` over float64 world triangles; Embree: a new scene,
its triangle mesh from float32 arrays, and the commit its first query triggers), first-hit tracing of size²
primary rays (a camera looking at the object, as the shared bench scenes place it), and the same number of
shadow rays (occlusion: from every primary hit, or from a point of the view ray where it missed, toward a point
light, t_max 1). Each timing is the median of `--repeats` runs, and the ratio frustum / Embree is printed
(the project's rule: a ratio against the anchor measured in the same run on the same machine). Embree's
``run`` calls ``rtcIntersect1``/``rtcOccluded1`` per ray on one thread; frustum traces in parallel on
``--threads`` (default all cores), as ``Scene.intersect`` does.

Scenes: ``bunny`` (the Stanford bunny, 69,451 triangles, from ``../shared/data/bunny/bun_zipper.ply``, else the
decimated copy in ``tests/data``), and ``bunny_like_100k`` and ``sphere_1m`` built by
``../shared/bench/scenes.py``'s functions. ``--classic`` also renders ``examples/ray_tracing.toml`` at 1024²
with max_depth 5 (time and rays per second). The host is shared: read the ratios, not the absolute times.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SHARED = next((p / "shared" for p in ROOT.parents if (p / "shared" / "bench" / "scenes.py").is_file()),
              ROOT.parent / "shared")  # fmt: skip
"""The project's shared folder (``../shared`` of the checkout, or of a folder above a git worktree)."""


def _scenes_module():
    sys.path.insert(0, str(SHARED / "bench"))
    import scenes

    return scenes


def load_scene(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """(triangles (F, 3, 3) float64 exactly float32-representable, eye, target, fovy in degrees)."""
    if name == "bunny":
        from frustum.geometry.io import load

        path = SHARED / "data" / "bunny" / "bun_zipper.ply"
        mesh = load(path if path.is_file() else ROOT / "tests" / "data" / "bunny" / "bun_zipper_res2.ply")
        tri = mesh.vertices[mesh.faces]
        centre = 0.5 * (tri.reshape(-1, 3).min(axis=0) + tri.reshape(-1, 3).max(axis=0))
        eye, target, fovy = centre + np.array([0.0, 0.02, 0.26]), centre, 40.0
    else:
        scenes = _scenes_module()
        builder, kwargs, _ = scenes.SCENES[name]
        scene = builder(**kwargs)
        tri = scene["vertices"][scene["faces"]]
        eye, target, fovy = np.array(scene["eye"]), np.array(scene["target"]), float(scene["fovy_deg"])
    return tri.astype(np.float32).astype(np.float64), eye, target, fovy


def camera_rays(eye: np.ndarray, target: np.ndarray, fovy_deg: float, size: int) -> tuple[np.ndarray, np.ndarray]:
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    half = np.tan(np.radians(fovy_deg) / 2.0)
    s = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    x, y = np.meshgrid(s * half, -s * half)
    directions = forward + x.reshape(-1, 1) * right + y.reshape(-1, 1) * up
    origins = np.broadcast_to(eye, directions.shape)
    return np.ascontiguousarray(origins, dtype=np.float32).astype(np.float64), \
        np.ascontiguousarray(directions, dtype=np.float32).astype(np.float64)  # fmt: skip


def median_time(function, repeats: int) -> tuple[float, object]:
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def bench_scene(name: str, size: int, repeats: int) -> dict:
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    from frustum.raster import rays

    tri, eye, target, fovy = load_scene(name)
    tri32 = tri.astype(np.float32)
    origins, directions = camera_rays(eye, target, fovy, size)
    o32, d32 = origins.astype(np.float32), directions.astype(np.float32)

    def embree_build():
        scene = rtcore_scene.EmbreeScene()
        TriangleMesh(scene, tri32)
        scene.run(o32[:1], d32[:1])  # the commit (the BVH build) happens at the first query
        return scene

    rays.build(tri[:1000])  # compile outside the timings (cached on disk after the first run)
    frustum_build, index = median_time(lambda: rays.build(tri), repeats)
    embree_build_time, scene = median_time(embree_build, repeats)
    frustum_trace, hits = median_time(lambda: rays.closest_hits(index, origins, directions), repeats)
    embree_trace, embree_hits = median_time(lambda: scene.run(o32, d32, output=1), repeats)
    # shadow rays: from the hit (or from 3 units along the ray where it missed) toward a point light
    reach = np.where(np.isfinite(hits.t), hits.t, 3.0)
    points = origins + reach[:, None] * directions
    corners = tri.reshape(-1, 3)
    light = corners.mean(axis=0) + np.array([2.0, 3.0, 2.5]) * np.abs(corners - corners.mean(axis=0)).max()
    to_light = light - points
    start = points + 1e-4 * to_light / np.linalg.norm(to_light, axis=1, keepdims=True)
    start, to_light = start.astype(np.float32).astype(np.float64), (light - start).astype(np.float32).astype(np.float64)
    ones = np.ones(start.shape[0], dtype=np.float32)
    s32, l32 = start.astype(np.float32), to_light.astype(np.float32)
    frustum_occ, blocked = median_time(lambda: rays.any_hits(index, start, to_light, 0.0, 1.0), repeats)
    embree_occ, embree_blocked = median_time(lambda: scene.run(s32, l32, dists=ones, query="OCCLUDED"), repeats)
    same_face = float((hits.face == embree_hits["primID"]).mean())
    same_occlusion = float((blocked == (embree_blocked != -1)).mean())
    return {
        "scene": name, "triangles": tri.shape[0], "rays": origins.shape[0],
        "build": (frustum_build, embree_build_time), "trace": (frustum_trace, embree_trace),
        "occlusion": (frustum_occ, embree_occ), "same_first_hit": same_face, "same_occlusion": same_occlusion,
        "hit_fraction": float((hits.face >= 0).mean()), "occluded_fraction": float(blocked.mean()),
    }  # fmt: skip


def bench_classic(size: int) -> dict:
    from frustum import render
    from frustum.scenefile import load_scene_file

    loaded = load_scene_file(ROOT / "examples" / "ray_tracing.toml")
    camera = loaded.cameras[0] if hasattr(loaded, "cameras") else loaded.camera
    import dataclasses

    camera = dataclasses.replace(camera, width=size, height=size)
    options = {**loaded.options, "samples": 1, "max_depth": 5, "stats": True}
    options.pop("size", None)
    render(loaded.scene, dataclasses.replace(camera, width=32, height=32), **options)  # compile
    start = time.perf_counter()
    frame = render(loaded.scene, camera, **options)
    seconds = time.perf_counter() - start
    stats = frame.stats
    total = sum(stats[k] for k in ("primary_rays", "shadow_rays", "reflected_rays", "refracted_rays"))
    return {"seconds": seconds, "rays": total, "rays_per_second": total / seconds, **stats}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=["bunny", "bunny_like_100k", "sphere_1m"])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--classic", action="store_true")
    args = parser.parse_args(argv)
    if args.threads is not None:
        from frustum.raster._jit import set_threads

        set_threads(args.threads)
    print(f"{'scene':<17}{'triangles':>10}  {'what':<10}{'frustum s':>10}{'embree s':>10}{'ratio':>7}")
    for name in args.scenes:
        result = bench_scene(name, args.size, args.repeats)
        for what in ("build", "trace", "occlusion"):
            ours, theirs = result[what]
            print(f"{name:<17}{result['triangles']:>10}  {what:<10}{ours:>10.4f}{theirs:>10.4f}{ours / theirs:>7.2f}")
        print(f"{'':<29}same first hit {result['same_first_hit']:.5f}, same occlusion {result['same_occlusion']:.5f}"
              f", hits {result['hit_fraction']:.3f}, occluded {result['occluded_fraction']:.3f}", flush=True)
    if args.classic:
        classic = bench_classic(1024)
        print(f"classic mirror/glass 1024² max_depth 5: {classic['seconds']:.2f} s, {classic['rays']} rays, "
              f"{classic['rays_per_second'] / 1e6:.2f} M rays/s (depth reached {classic['depth_reached']})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
