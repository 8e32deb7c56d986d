"""Benchmark: shadows in ``frustum.render`` against shadows off, Mesa llvmpipe's shadow mapping and Embree's rays.

    python benchmarks/bench_shadows.py [--scene bunny_like_100k] [--frames 5] [--warmup 1] [--scene-dir DIR]

On a standard scene of ``../shared/bench`` (default ``bunny_like_100k``, 1024², its directional light; the torus
knot shadows itself), in one run, medians of ``--frames`` frames after ``--warmup``:

- frustum: shadows off, shadow maps (``shadows=True``, 2048² map, 2×2 bilinear PCF), shadow rays (``shadows="ray"``),
  with the scene's directional light and with one point light (shadows off and on); ratio shadowed / unshadowed
  (target: <= 1.5 for the directional light);
- llvmpipe (``benchmarks/anchor_moderngl_shadows.py``, a child process): the same scene without and with a
  2048² depth-texture shadow map, ``sampler2DShadow`` with 2×2 PCF taps; ratio frustum shadowed / llvmpipe
  shadowed (target: <= 0.6);
- the shadow-ray pass alone: the rays from every drawn pixel toward the light through frustum's any-hit query
  (``shadow_pass.occluded``) and through Embree (``embreex`` OCCLUDED query, same origins, directions and
  distances); ratio frustum / Embree (target: <= 3). Index builds are reported apart.

Timings on a shared machine are noisy: read the ratios, measured in the same run.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
BENCH_DIR = HERE.parents[0].parent / "shared" / "bench"
if not BENCH_DIR.is_dir():
    BENCH_DIR = Path("/work/shared/bench")


def _median_ms(work, frames: int, warmup: int) -> float:
    for _ in range(warmup):
        work()
    times = []
    for _ in range(frames):
        t0 = time.perf_counter()
        work()
        times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scene", default="bunny_like_100k")
    parser.add_argument("--frames", type=int, default=5)
    parser.add_argument("--warmup", type=int, default=1)
    parser.add_argument("--scene-dir", default="/tmp/frustum-bench/scenes")
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)

    sys.path.insert(0, str(BENCH_DIR))
    import scenes

    path = Path(args.scene_dir) / f"{args.scene}.npz"
    if not path.exists():
        scenes.main(["--only", args.scene, "--out", str(args.scene_dir)])
    sc = scenes.load_scene(str(path))

    import frustum
    from frustum import shadow_pass

    width, height = int(sc["width"]), int(sc["height"])
    mesh = frustum.Mesh(sc["vertices"], sc["faces"], vertex_normals=sc["normals"], copy=False)
    camera = frustum.Camera.look_at(
        sc["eye"], sc["target"], sc["up"],
        projection=frustum.Perspective(np.radians(float(sc["fovy_deg"])), float(sc["near"]), float(sc["far"])),
        width=width, height=height,
    )  # fmt: skip
    material = frustum.Material(color=tuple(float(c) for c in sc["base_color"]), ambient=float(sc["ambient"]),
                                diffuse=float(sc["diffuse"]), specular=float(sc["specular"]),
                                shininess=float(sc["shininess"]))  # fmt: skip
    to_light = np.asarray(sc["light_dir"], dtype=np.float64)
    centre = 0.5 * (sc["vertices"].min(axis=0) + sc["vertices"].max(axis=0)).astype(np.float64)
    radius = float(np.linalg.norm(sc["vertices"] - centre, axis=1).max())
    lights = {
        "directional": frustum.DirectionalLight(direction=-to_light),
        "point": frustum.PointLight(position=centre + 2.5 * radius * to_light),
    }
    background = tuple(float(c) for c in sc["background"])
    results: dict = {"scene": args.scene, "width": width, "height": height}
    for name, light in lights.items():
        scene = frustum.Scene(lights=[light])
        scene.add(mesh, material=material)
        variants = {"off": {}, "maps": {"shadows": True}}
        if name == "directional":
            variants["ray"] = {"shadows": "ray"}
        first = {}
        for variant, extra in variants.items():
            t0 = time.perf_counter()
            frustum.render(scene, camera, background=background, **extra)
            first[variant] = time.perf_counter() - t0
            results[f"{name}_{variant}_ms"] = _median_ms(
                lambda extra=extra, scene=scene: frustum.render(scene, camera, background=background, **extra),
                args.frames, args.warmup,
            )  # fmt: skip
        results[f"{name}_first_call_s"] = first
        print(f"frustum {name}: " + ", ".join(f"{v} {results[f'{name}_{v}_ms']:.1f} ms" for v in variants), flush=True)

    # the shadow-ray pass alone, against Embree on the same rays
    scene = frustum.Scene(lights=[lights["directional"]])
    scene.add(mesh, material=material)
    frame = frustum.render(scene, camera, buffers=("position", "normals"))
    drawn = np.isfinite(frame.position[..., 0])
    span = float(np.ptp(sc["vertices"], axis=0).max())
    origins = frame.position[drawn].astype(np.float64) + 1e-5 * span * frame.normals[drawn].astype(np.float64)
    directions = np.ascontiguousarray(np.broadcast_to(to_light, origins.shape))
    t_max = np.full(origins.shape[0], np.inf)
    t0 = time.perf_counter()
    ours = shadow_pass.occluded(scene, origins, directions, t_max)
    results["frustum_index_and_first_rays_s"] = time.perf_counter() - t0
    results["frustum_rays_ms"] = _median_ms(
        lambda: shadow_pass.occluded(scene, origins, directions, t_max), args.frames, args.warmup
    )
    results["rays"] = int(origins.shape[0])
    try:
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        t0 = time.perf_counter()
        embree = rtcore_scene.EmbreeScene()
        TriangleMesh(embree, sc["vertices"][sc["faces"]].astype(np.float32))
        o32, d32 = origins.astype(np.float32), directions.astype(np.float32)
        dists = np.full(origins.shape[0], np.finfo(np.float32).max, dtype=np.float32)
        hits = embree.run(o32, d32, dists=dists, query="OCCLUDED")
        results["embree_build_and_first_rays_s"] = time.perf_counter() - t0
        results["embree_rays_ms"] = _median_ms(
            lambda: embree.run(o32, d32, dists=dists, query="OCCLUDED"), args.frames, args.warmup
        )
        results["rays_agree"] = float((ours == (np.asarray(hits) >= 0)).mean())
        results["ray_ratio_vs_embree"] = results["frustum_rays_ms"] / results["embree_rays_ms"]
    except ImportError as error:
        print(f"embree skipped: {error}")

    # llvmpipe's shadow mapping (a child process: its own GL context)
    anchor = subprocess.run(
        [sys.executable, str(HERE / "anchor_moderngl_shadows.py"), "--scene", str(path), "--frames",
         str(args.frames), "--warmup", str(args.warmup)], capture_output=True, text=True, timeout=900,
    )  # fmt: skip
    if anchor.returncode == 0:
        gl = json.loads(anchor.stdout.strip().splitlines()[-1])
        results["llvmpipe"] = gl
        results["ratio_vs_llvmpipe_shadowed"] = results["directional_maps_ms"] / gl["frame_shadowed_ms"]
    else:
        print(f"llvmpipe skipped: {anchor.stderr.strip().splitlines()[-1:]}")
    results["ratio_shadowed_vs_unshadowed_directional"] = results["directional_maps_ms"] / results["directional_off_ms"]
    results["ratio_shadowed_vs_unshadowed_point"] = results["point_maps_ms"] / results["point_off_ms"]
    print(json.dumps(results, indent=1, default=float))
    print(
        f"directional shadow maps / no shadows = {results['ratio_shadowed_vs_unshadowed_directional']:.2f} "
        f"(target <= 1.5); point: {results['ratio_shadowed_vs_unshadowed_point']:.2f}"
    )
    if "ratio_vs_llvmpipe_shadowed" in results:
        print(f"frustum shadowed / llvmpipe shadowed = {results['ratio_vs_llvmpipe_shadowed']:.2f} (target <= 0.6)")
    if "ray_ratio_vs_embree" in results:
        print(f"shadow rays frustum / Embree = {results['ray_ratio_vs_embree']:.2f} (target <= 3), "
              f"agreement {results['rays_agree']:.5f}")  # fmt: skip
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
