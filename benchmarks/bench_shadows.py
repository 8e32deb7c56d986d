"""Benchmark: shadows in ``frustum.render`` against shadows off, Mesa llvmpipe's shadow mapping and Embree's rays.

    python benchmarks/bench_shadows.py [--scenes bunny_like_100k ...] [--frames 5] [--warmup 1] [--scene-dir DIR]
                                       [--views 8] [--json PATH]

On issue 50's scene of several items (``items_8``: a ground plane, five slats, a box and a sphere, eight meshes
with their own materials, 1024², written by ``_write_items_scene``) and the standard scenes of ``../shared/bench``
(``bunny_like_100k``, ``bunny_like_100k_4k`` at 4096², ``sphere_1m``, ``terrain_2m``; each with its own size and
directional light), in one run per scene, medians of ``--frames`` frames after ``--warmup``, each variant in its
own block of frames:

- frustum with the scene's directional light: shadows off; shadow maps (``shadows=True``, 2048² map, 2×2 bilinear
  PCF) **redrawn every frame** (``shadow_pass.set_map_reuse(False)``: fit, bin and fill the map, then the frame);
  shadow maps **reused** (the same scene, light and view: the map drawn for an earlier frame is taken as it is,
  ``shadow_pass.kept_maps``); ratios shadowed / unshadowed for both (target: <= 1.5, directional);
- a turntable: ``--views`` cameras orbiting the scene's target at the scene camera's height and at least the
  distance at which the whole model is in view (the map is fitted to what the camera sees: only a view that
  sees all of the model can reuse it), each round of frames turned on by a fraction of a step (no view comes
  twice), frames with shadows off and with maps reused; ratio and how many of the frames drew their map;
- the scene with one point light (shadows off and on: a cube of six maps drawn every frame, the stage-by-stage
  path);
- llvmpipe (``benchmarks/anchor_moderngl_shadows.py``, a child process): the same scene (one draw call per
  item) without and with a 2048² depth-texture shadow map drawn every frame, ``sampler2DShadow`` with 2×2 PCF
  taps; ratio frustum shadowed (map redrawn: like for like) / llvmpipe shadowed (target: <= 0.6);
- the first scene only (``--scenes`` order): the shadow-ray pass alone, the rays from every drawn pixel toward
  the light through frustum's any-hit query (``shadow_pass.occluded``) and through Embree (``embreex`` OCCLUDED
  query, same
  origins, directions and distances); ratio frustum / Embree (target: <= 3). Index builds are reported apart.

Timings on a shared machine are noisy: read the ratios, measured in the same run.
"""

from __future__ import annotations

import argparse
import json
import math
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
ITEMS_SCENE = "items_8"
"""Issue 50's scene of several items at 1024²: a ground plane, five thin slats above it, a box and a sphere (48 × 24)
on it, each its own mesh and material, under a directional light (``_write_items_scene``)."""
DEFAULT_SCENES = [ITEMS_SCENE, "bunny_like_100k", "bunny_like_100k_4k", "sphere_1m", "terrain_2m"]


def _write_items_scene(path: Path) -> None:
    """The ``ITEMS_SCENE`` as a bench scene file: the items' world vertices, faces and normals concatenated, with
    ``item_vertex_starts``, ``item_face_starts`` (I + 1 each) and ``item_colors`` (I, 3) to split them again
    (``_items``; the llvmpipe anchor draws one call per item)."""
    import frustum
    from frustum.geometry.primitives import box, plane, uv_sphere
    from frustum.transforms import rotate_x, translate

    placed = [(plane((10, 10), divisions=(4, 4)), (0.8, 0.8, 0.8), rotate_x(-math.pi / 2))]
    placed += [(box((0.2, 0.05, 3.0), center=(-1.0 + 0.5 * k, 2.0, 0.0)), (0.4, 0.4, 0.4), np.eye(4))
               for k in range(5)]  # fmt: skip
    placed += [(box((1, 1, 1), center=(1.5, 0.5, 1.5)), (0.9, 0.3, 0.2), np.eye(4)),
               (uv_sphere(0.6, segments=48, rings=24), (0.2, 0.5, 0.9), translate(-1.8, 0.6, 1.2))]  # fmt: skip
    vertices, normals, faces, v_starts, f_starts = [], [], [], [0], [0]
    for mesh, _, m in placed:
        m = np.asarray(m, dtype=np.float64)
        vertices.append(mesh.vertices @ m[:3, :3].T + m[:3, 3])
        turned = mesh.vertex_normals @ np.linalg.inv(m[:3, :3])
        normals.append(turned / np.linalg.norm(turned, axis=1, keepdims=True))
        faces.append(np.asarray(mesh.faces) + v_starts[-1])
        v_starts.append(v_starts[-1] + mesh.vertex_count)
        f_starts.append(f_starts[-1] + mesh.face_count)
    material = frustum.Material()
    light = np.array([0.3, -1.0, -0.2])
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez(
        path, vertices=np.concatenate(vertices).astype(np.float32), normals=np.concatenate(normals).astype(np.float32),
        faces=np.concatenate(faces).astype(np.uint32), item_vertex_starts=np.array(v_starts),
        item_face_starts=np.array(f_starts), item_colors=np.array([c for _, c, _ in placed]),
        eye=np.array([4.0, 5.0, 7.0]), target=np.zeros(3), up=np.array([0.0, 1.0, 0.0]), fovy_deg=np.float64(45.0),
        near=np.float64(0.1), far=np.float64(100.0), width=np.int64(1024), height=np.int64(1024),
        base_color=np.array(material.color), ambient=np.float64(material.ambient),
        diffuse=np.float64(material.diffuse), specular=np.float64(material.specular),
        shininess=np.float64(material.shininess), light_dir=-light / np.linalg.norm(light),
        background=np.array([0.0, 0.0, 0.0, 1.0]),
    )  # fmt: skip


def _items(frustum, sc) -> list:
    """The scene file's items as ``(Mesh, Material)`` pairs: one for a standard scene, several for one with
    ``item_face_starts`` (``_write_items_scene``)."""
    material = dict(ambient=float(sc["ambient"]), diffuse=float(sc["diffuse"]), specular=float(sc["specular"]),
                    shininess=float(sc["shininess"]))  # fmt: skip
    if "item_face_starts" not in sc:
        mesh = frustum.Mesh(sc["vertices"], sc["faces"], vertex_normals=sc["normals"], copy=False)
        return [(mesh, frustum.Material(color=tuple(float(c) for c in sc["base_color"]), **material))]
    v, f = sc["item_vertex_starts"], sc["item_face_starts"]
    items = []
    for k in range(len(f) - 1):
        faces = sc["faces"][f[k] : f[k + 1]].astype(np.int64) - v[k]
        mesh = frustum.Mesh(sc["vertices"][v[k] : v[k + 1]], faces, vertex_normals=sc["normals"][v[k] : v[k + 1]])
        items.append((mesh, frustum.Material(color=tuple(float(c) for c in sc["item_colors"][k]), **material)))
    return items


def _median_ms(work, frames: int, warmup: int) -> float:
    for _ in range(warmup):
        work()
    times = []
    for _ in range(frames):
        t0 = time.perf_counter()
        work()
        times.append((time.perf_counter() - t0) * 1e3)
    return statistics.median(times)


def _blocks_ms(variants: dict, frames: int, warmup: int) -> dict[str, float]:
    """Median ms of each variant (a callable), each timed in its own block of frames after its own warmup (a
    variant's frame does not follow another's: a shadowed frame's map would leave the caches cold for an
    unshadowed one)."""
    return {name: _median_ms(work, frames, warmup) for name, work in variants.items()}


def _turntable(frustum, sc, views: int, turn: float = 0.0) -> list:
    """`views` cameras around the scene's target (the first `turn` of a step past the scene camera's side), at the
    scene camera's height above it and a distance at least that at which the model's bounding sphere fits the
    field of view."""
    eye, target = np.asarray(sc["eye"], dtype=np.float64), np.asarray(sc["target"], dtype=np.float64)
    up = np.asarray(sc["up"], dtype=np.float64)
    up = up / np.linalg.norm(up)
    vertices = np.asarray(sc["vertices"], dtype=np.float64)
    centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    radius = float(np.linalg.norm(vertices - centre, axis=1).max())
    width, height = int(sc["width"]), int(sc["height"])
    fovy = math.radians(float(sc["fovy_deg"]))
    half = min(fovy, 2.0 * math.atan(math.tan(fovy / 2.0) * width / height)) / 2.0
    offset = eye - target
    rise = float(offset @ up)
    across = offset - rise * up
    reach = radius + float(np.linalg.norm(centre - target))  # the model's sphere around the target
    distance = max(float(np.linalg.norm(offset)), 1.1 * reach / math.sin(half))
    scale = distance / float(np.linalg.norm(offset))
    side = np.cross(up, across)
    cameras = []
    for k in range(views):
        angle = 2.0 * math.pi * (k + turn) / views
        turned = math.cos(angle) * across + math.sin(angle) * side
        position = target + scale * (turned + rise * up)
        far = max(float(sc["far"]), 2.0 * (distance + radius))
        cameras.append(frustum.Camera.look_at(
            position, target, up, projection=frustum.Perspective(fovy, float(sc["near"]), far),
            width=width, height=height,
        ))  # fmt: skip
    return cameras


def bench_scene(name: str, args, first_scene: bool) -> dict:
    """One standard scene's rows (see the module docstring)."""
    sys.path.insert(0, str(BENCH_DIR))
    import scenes

    path = Path(args.scene_dir) / f"{name}.npz"
    if name == ITEMS_SCENE and not path.exists():
        _write_items_scene(path)
    elif not path.exists():
        scenes.main(["--only", name, "--out", str(args.scene_dir)])
    sc = scenes.load_scene(str(path))

    import frustum
    from frustum.raster import shadow
    from frustum.render.shadows import fractions as shadow_pass

    width, height = int(sc["width"]), int(sc["height"])
    items = _items(frustum, sc)
    camera = frustum.Camera.look_at(
        sc["eye"], sc["target"], sc["up"],
        projection=frustum.Perspective(np.radians(float(sc["fovy_deg"])), float(sc["near"]), float(sc["far"])),
        width=width, height=height,
    )  # fmt: skip
    to_light = np.asarray(sc["light_dir"], dtype=np.float64)
    centre = 0.5 * (sc["vertices"].min(axis=0) + sc["vertices"].max(axis=0)).astype(np.float64)
    radius = float(np.linalg.norm(sc["vertices"] - centre, axis=1).max())
    lights = {
        "directional": frustum.DirectionalLight(direction=-to_light),
        "point": frustum.PointLight(position=centre + 2.5 * radius * to_light),
    }
    background = tuple(float(c) for c in sc["background"])
    results: dict = {"scene": name, "width": width, "height": height, "triangles": int(sc["faces"].shape[0]),
                     "items": len(items)}  # fmt: skip
    scene = frustum.Scene(lights=[lights["directional"]])
    for mesh, material in items:
        scene.add(mesh, material=material)

    def frame(camera=camera, reuse=True, **extra):
        shadow_pass.set_map_reuse(reuse)
        try:
            frustum.render(scene, camera, background=background, **extra)
        finally:
            shadow_pass.set_map_reuse(True)

    first = {}
    for variant, extra in (("off", {}), ("redrawn", {"shadows": True, "reuse": False})):
        t0 = time.perf_counter()
        frame(**extra)
        first[variant] = time.perf_counter() - t0
    results["directional_first_call_s"] = first
    fills = []
    fill = shadow.fill_depth_tiles

    def counted(*arguments):
        fills.append(1)
        return fill(*arguments)

    shadow.fill_depth_tiles = counted
    try:
        timed = _blocks_ms({
            "off": lambda: frame(),
            "redrawn": lambda: frame(shadows=True, reuse=False),
            "reused": lambda: frame(shadows=True),
        }, args.frames, args.warmup)  # fmt: skip
        frames_drawn = args.frames + args.warmup
        results["directional_maps_drawn_when_reused"] = len(fills) - frames_drawn  # the redrawn variant's excluded
        for variant, ms in timed.items():
            results[f"directional_{variant}_ms"] = ms
        # the turntable: every view sees the whole model, so one map serves all
        rounds = args.warmup + args.frames  # every frame a view not seen before (nothing of its fit kept)
        orbits = [_turntable(frustum, sc, args.views, turn / rounds) for turn in range(rounds)]
        cameras = orbits[0]
        shadow_pass.release_memory()
        fills.clear()
        spins = {"off": [], "reused": []}
        for variant, extra in (("off", {}), ("reused", {"shadows": True})):
            for round_ in range(rounds):
                t0 = time.perf_counter()
                for view in orbits[round_]:
                    frame(view, **extra)
                if round_ >= args.warmup:
                    spins[variant].append((time.perf_counter() - t0) * 1e3 / len(cameras))
        results["turntable_views"] = len(cameras)
        results["turntable_maps_drawn"] = len(fills)
        results["turntable_frames"] = len(cameras) * (args.warmup + args.frames)
        for variant, values in spins.items():
            results[f"turntable_{variant}_ms"] = statistics.median(values)
    finally:
        shadow.fill_depth_tiles = fill
    print(f"{name} directional: " + ", ".join(f"{v} {results[f'directional_{v}_ms']:.1f} ms" for v in timed)
          + f"; turntable of {len(cameras)} views: off {results['turntable_off_ms']:.1f}, reused "
          f"{results['turntable_reused_ms']:.1f} ms ({results['turntable_maps_drawn']} maps drawn in "
          f"{results['turntable_frames']} frames)", flush=True)  # fmt: skip
    point = frustum.Scene(lights=[lights["point"]])
    for mesh, material in items:
        point.add(mesh, material=material)
    timed = _blocks_ms({
        "off": lambda: frustum.render(point, camera, background=background),
        "maps": lambda: frustum.render(point, camera, background=background, shadows=True),
    }, args.frames, args.warmup)  # fmt: skip
    results["point_off_ms"], results["point_maps_ms"] = timed["off"], timed["maps"]
    print(f"{name} point: off {timed['off']:.1f} ms, maps {timed['maps']:.1f} ms", flush=True)
    if first_scene:
        results.update(_rays(frustum, shadow_pass, sc, scene, camera, to_light, args))
    # llvmpipe's shadow mapping (a child process: its own GL context)
    anchor = subprocess.run(
        [sys.executable, str(HERE / "anchor_moderngl_shadows.py"), "--scene", str(path), "--frames",
         str(args.frames), "--warmup", str(args.warmup)], capture_output=True, text=True, timeout=1800,
    )  # fmt: skip
    if anchor.returncode == 0:
        gl = json.loads(anchor.stdout.strip().splitlines()[-1])
        results["llvmpipe"] = gl
        results["ratio_vs_llvmpipe_shadowed"] = results["directional_redrawn_ms"] / gl["frame_shadowed_ms"]
    else:
        print(f"llvmpipe skipped: {anchor.stderr.strip().splitlines()[-1:]}")
    off = results["directional_off_ms"]
    results["ratio_redrawn_vs_unshadowed"] = results["directional_redrawn_ms"] / off
    results["ratio_reused_vs_unshadowed"] = results["directional_reused_ms"] / off
    results["ratio_turntable_reused_vs_unshadowed"] = results["turntable_reused_ms"] / results["turntable_off_ms"]
    results["ratio_point_vs_unshadowed"] = results["point_maps_ms"] / results["point_off_ms"]
    return results


def _rays(frustum, shadow_pass, sc, scene, camera, to_light, args) -> dict:
    """The shadow-ray pass alone, frustum's any-hit query against Embree's on the same rays."""
    results: dict = {}
    results["directional_ray_ms"] = _median_ms(
        lambda: frustum.render(scene, camera, shadows="ray"), args.frames, args.warmup
    )
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
    return results


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", nargs="+", default=DEFAULT_SCENES)
    parser.add_argument("--scene", help="one scene (the --scenes of earlier versions)")
    parser.add_argument("--frames", type=int, default=5)
    parser.add_argument("--warmup", type=int, default=1)
    parser.add_argument("--views", type=int, default=8, help="cameras of the turntable")
    parser.add_argument("--scene-dir", default="/tmp/frustum-bench/scenes")
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)
    names = [args.scene] if args.scene else args.scenes
    rows = [bench_scene(name, args, number == 0) for number, name in enumerate(names)]
    print(json.dumps(rows, indent=1, default=float))
    print("scene | off ms | redrawn ms (/off) | reused ms (/off) | turntable off / reused ms (/off, maps drawn) | "
          "point off / maps ms (/off) | llvmpipe off / shadowed ms | frustum redrawn / llvmpipe shadowed")
    for r in rows:
        gl = r.get("llvmpipe", {})
        vs = f"{r['ratio_vs_llvmpipe_shadowed']:.2f}" if "ratio_vs_llvmpipe_shadowed" in r else "-"
        print(f"{r['scene']} | {r['directional_off_ms']:.1f} | {r['directional_redrawn_ms']:.1f} "
              f"({r['ratio_redrawn_vs_unshadowed']:.2f}) | {r['directional_reused_ms']:.1f} "
              f"({r['ratio_reused_vs_unshadowed']:.2f}) | {r['turntable_off_ms']:.1f} / {r['turntable_reused_ms']:.1f} "
              f"({r['ratio_turntable_reused_vs_unshadowed']:.2f}, {r['turntable_maps_drawn']} of "
              f"{r['turntable_frames']}) | {r['point_off_ms']:.1f} / {r['point_maps_ms']:.1f} "
              f"({r['ratio_point_vs_unshadowed']:.2f}) | {gl.get('frame_ms', float('nan')):.1f} / "
              f"{gl.get('frame_shadowed_ms', float('nan')):.1f} | {vs}")  # fmt: skip
    for r in rows:  # the issue's two targets, scene by scene
        vs = f"{r['ratio_vs_llvmpipe_shadowed']:.2f}" if "ratio_vs_llvmpipe_shadowed" in r else "- (no llvmpipe)"
        print(f"{r['scene']} ({r['items']} item(s), {r['width']}x{r['height']}): shadowed with a reused map / "
              f"unshadowed = {r['ratio_reused_vs_unshadowed']:.2f} (target <= 1.5; turntable "
              f"{r['ratio_turntable_reused_vs_unshadowed']:.2f}); map redrawn every frame / llvmpipe shadowed frame "
              f"= {vs} (target <= 0.6)")  # fmt: skip
    first = rows[0]
    if "ray_ratio_vs_embree" in first:
        print(f"shadow rays frustum / Embree = {first['ray_ratio_vs_embree']:.2f} (target <= 3), "
              f"agreement {first['rays_agree']:.5f}")  # fmt: skip
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
