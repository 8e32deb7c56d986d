"""Benchmark: ``frustum.render`` against Mesa llvmpipe (moderngl, EGL) on the standard scenes, in one run.

    python benchmarks/bench_render.py [--scenes NAME ...] [--frames 10] [--warmup 2] [--threads N]
                                      [--scene-dir DIR] [--skip-llvmpipe] [--save DIR] [--json PATH] [--pbr]

``--pbr`` (issue 46) also renders each scene with ``shading="pbr"`` (the scene's base colour as a metallic 0.6,
roughness 0.45 material, its light as 3 lux, a sky environment map as image-based light) against llvmpipe running a
standard glTF PBR fragment shader with the same BRDF, a prefiltered cube map and the split-sum table
(``anchor_moderngl_pbr.py``), and prints the ratio and the PBR frame over frustum's own Phong frame.

Each scene and each renderer runs in its own child process, so peak RSS (``ru_maxrss`` read in the child) is per
scene and renderer and includes loading the scene. llvmpipe runs through the shared anchor
``../shared/bench/anchor_moderngl.py`` (its own command line, ``--save-reference`` into a temporary folder);
frustum runs in a child of this script. A frame is timed with ``time.perf_counter`` from the ``render(...)`` call
to ``frame.color`` and ``frame.depth`` in hand (llvmpipe: clear + draw + glFinish + readback of colour and
depth), over ``--frames`` frames after ``--warmup``; the median is reported. The first call of a fresh process
(Numba compilation, or loading its on-disk cache, plus one frame) is reported separately.

Per scene it prints: median frame ms of both renderers, the ratio frustum / llvmpipe against the issue's target,
frustum's first call, peak RSS of both, coverage agreement (pixel covered vs background, from the depth buffers)
and the share of pixels whose RGB channels are all within ±1 level of llvmpipe's. Where moderngl or EGL/Mesa is
missing, llvmpipe is skipped with one line saying why; where ``frustum.render`` is not importable yet, frustum is
skipped the same way and llvmpipe still runs.

Scenes live in ``--scene-dir`` (default ``/tmp/frustum-bench/scenes``); missing ones are built there with
``../shared/bench/scenes.py --out`` (about 15 s for all five; that folder may be read-only, nothing is written
beside it).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import zlib
from pathlib import Path

import numpy as np

BENCH_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "bench"
ANCHOR = BENCH_DIR / "anchor_moderngl.py"
DEFAULT_SCENES = ["bunny_like_100k", "bunny_like_100k_4k", "sphere_1m", "terrain_2m", "many_small_10m"]
HEAVY_SCENES = {"many_small_10m"}
# Issue 16 (the second round; issue 5's were 0.7, 1.0, 0.4, 0.4, 0.35): frustum frame / llvmpipe frame, medians.
TARGET_RATIO = {
    "bunny_like_100k": 0.5,
    "bunny_like_100k_4k": 0.7,
    "sphere_1m": 0.3,
    "terrain_2m": 0.3,
    "many_small_10m": 0.25,
}
FRUSTUM_API = ("render", "Mesh", "Camera", "Perspective", "Material", "DirectionalLight", "Scene")


def _bench_modules():
    """The shared ``scenes`` module and the anchor (imported lazily: moderngl is only imported by its children)."""
    if str(BENCH_DIR) not in sys.path:
        sys.path.insert(0, str(BENCH_DIR))
    import anchor_moderngl
    import scenes

    return scenes, anchor_moderngl


def peak_rss_mib() -> float:
    """Peak resident set size of this process in MiB.

    Linux: ``VmHWM`` from /proc/self/status, which starts afresh at exec. Not ``ru_maxrss``: Linux keeps that
    across fork and exec, so a child started by a large parent reports at least the parent's peak.
    """
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


# --- frustum child -------------------------------------------------------------------------------------------


def _parse_variant(text: str | None) -> dict:
    """``"shading=flat,samples=4"`` → ``{"shading": "flat", "samples": 4}`` (ints where they parse)."""
    options: dict = {}
    for pair in filter(None, (text or "").split(",")):
        key, _, value = pair.partition("=")
        options[key] = int(value) if value.isdigit() else value
    return options


def frustum_child(name: str, args: argparse.Namespace) -> dict:
    """Render one scene with frustum in this (fresh) process; save color/depth as .npy into ``args.out``."""
    t0 = time.perf_counter()
    import frustum

    import_s = time.perf_counter() - t0
    scenes, _ = _bench_modules()
    sc = scenes.load_scene(str(Path(args.scene_dir) / f"{name}.npz"))
    width, height = int(sc["width"]), int(sc["height"])

    t0 = time.perf_counter()
    # copy=False: the Mesh renders from the scene's own vertex and face buffers (validated, read-only views) where
    # the anchor's GL driver copies them into its buffers; both processes also hold the loaded scene arrays
    mesh = frustum.Mesh(sc["vertices"], sc["faces"], vertex_normals=sc["normals"], copy=False)
    camera = frustum.Camera.look_at(
        sc["eye"],
        sc["target"],
        sc["up"],
        projection=frustum.Perspective(np.radians(float(sc["fovy_deg"])), float(sc["near"]), float(sc["far"])),
        width=width,
        height=height,
    )
    material = frustum.Material(
        color=tuple(float(c) for c in sc["base_color"]),
        ambient=float(sc["ambient"]),
        diffuse=float(sc["diffuse"]),
        specular=float(sc["specular"]),
        shininess=float(sc["shininess"]),
    )
    # The bench's light_dir points toward the light; frustum's direction is the way the light travels.
    light = frustum.DirectionalLight(direction=-np.asarray(sc["light_dir"], dtype=np.float64))
    scene = frustum.Scene(lights=[light])
    scene.add(mesh, material=material)
    background = tuple(float(c) for c in sc["background"])
    setup_s = time.perf_counter() - t0

    options = dict(shading="phong", background=background, cull_back_faces=True)
    options.update(_parse_variant(args.child_variant))
    if options["shading"] == "pbr":  # --pbr: the PBR anchor's material, light (lux) and environment
        from anchor_moderngl_pbr import LIGHT_LUX, PBR_MATERIAL, bench_environment

        scene = frustum.Scene(lights=[frustum.DirectionalLight(light.direction, intensity=LIGHT_LUX)],
                              environment=bench_environment())  # fmt: skip
        scene.add(mesh, material=material.with_(model="pbr", **PBR_MATERIAL))

    def frame_once():
        frame = frustum.render(scene, camera, **options)
        return frame.color, frame.depth

    t0 = time.perf_counter()
    frame_once()
    first_call_s = time.perf_counter() - t0
    for _ in range(args.warmup):
        frame_once()
    times = []
    color = depth = None
    for _ in range(args.frames):
        # the last frame's arrays go before the next call (the anchor reads into one color and one depth buffer):
        # holding them through it would count two frames in the peak RSS (2 × 128 MiB at 4096²)
        color = depth = None
        t0 = time.perf_counter()
        color, depth = frame_once()
        times.append((time.perf_counter() - t0) * 1e3)

    out_dir = Path(args.out)
    np.save(out_dir / f"{name}_frustum_color.npy", np.asarray(color))
    if depth is not None:
        np.save(out_dir / f"{name}_frustum_depth.npy", np.asarray(depth))
    return dict(
        scene=name,
        triangles=int(sc["faces"].shape[0]),
        width=width,
        height=height,
        import_s=import_s,
        setup_s=setup_s,
        first_call_s=first_call_s,
        frame_ms=statistics.median(times),
        frame_min_ms=min(times),
        frame_max_ms=max(times),
        frame_ms_all=times,
        frames=args.frames,
        warmup=args.warmup,
        numba_num_threads=os.environ.get("NUMBA_NUM_THREADS", f"default({os.cpu_count()})"),
        peak_rss_mb=peak_rss_mib(),
    )


# --- parent: availability checks -----------------------------------------------------------------------------


def _child_env(threads: int | None) -> dict:
    env = dict(os.environ)
    if threads:
        env["NUMBA_NUM_THREADS"] = str(threads)
        env["LP_NUM_THREADS"] = str(threads)
    return env


def check_llvmpipe(env: dict) -> tuple[bool, str]:
    """(available, GL_RENDERER or the reason it is not): moderngl importable and an EGL context created."""
    code = (
        "import moderngl\n"
        "ctx = moderngl.create_standalone_context(require=330, backend='egl')\n"
        "print(ctx.info['GL_RENDERER'], '|', ctx.info['GL_VERSION'])\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        lines = [ln for ln in proc.stderr.strip().splitlines() if ln.strip()]
        return False, lines[-1] if lines else f"exit code {proc.returncode}"
    return True, proc.stdout.strip()


def check_frustum(env: dict) -> tuple[bool, str]:
    """(available, reason): ``frustum`` imports and has every name the benchmark uses."""
    # ``frustum.render`` must be the function: a bare ``import frustum.render`` would bind the submodule there.
    code = (
        "import frustum\n"
        f"missing = [n for n in {FRUSTUM_API!r} if not callable(getattr(frustum, n, None))]\n"
        "print(missing)\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        lines = [ln for ln in proc.stderr.strip().splitlines() if ln.strip()]
        return False, "import frustum failed: " + (lines[-1] if lines else f"exit code {proc.returncode}")
    missing = proc.stdout.strip()
    if missing != "[]":
        return False, f"frustum has no {missing} yet"
    return True, ""


def ensure_scenes(scene_dir: Path, names: list[str]) -> None:
    missing = [n for n in names if not (scene_dir / f"{n}.npz").exists()]
    if missing:
        print(f"building {', '.join(missing)} in {scene_dir} with {BENCH_DIR / 'scenes.py'}", flush=True)
        scenes, _ = _bench_modules()
        t0 = time.perf_counter()
        scenes.main(["--only", *missing, "--out", str(scene_dir)])
        print(f"  scenes built in {time.perf_counter() - t0:.1f} s", flush=True)


# --- parent: running the children ----------------------------------------------------------------------------


def read_rgba_png(path: Path) -> np.ndarray:
    """Decode the anchor's own PNGs (RGBA8, filter 0 on every row, as ``anchor_moderngl.write_png`` writes)."""
    data = Path(path).read_bytes()
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        length = int.from_bytes(data[pos : pos + 4], "big")
        tag, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + length]
        if tag == b"IHDR":
            width, height = int.from_bytes(body[:4], "big"), int.from_bytes(body[4:8], "big")
        elif tag == b"IDAT":
            idat += body
        pos += 12 + length
    rows = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, 1 + 4 * width)
    if rows[:, 0].any():  # another writer's PNG: fall back to Pillow
        from PIL import Image

        return np.asarray(Image.open(path).convert("RGBA"))
    return rows[:, 1:].reshape(height, width, 4)


def run_llvmpipe(name: str, frames: int, args: argparse.Namespace, env: dict, work: Path) -> dict:
    """One scene through the shared anchor (its own child process); returns its JSON plus the saved images."""
    ref_dir = work / f"llvmpipe_{name}"
    cmd = [
        sys.executable, str(ANCHOR), "--scenes", name, "--frames", str(frames), "--warmup", str(args.warmup),
        "--scene-dir", str(args.scene_dir), "--reference-dir", str(ref_dir), "--results-dir", str(ref_dir),
        "--save-reference", "--tag", "bench",
    ]  # fmt: skip
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=args.timeout)
    wall_s = time.perf_counter() - t0
    result_path = ref_dir / "moderngl_bench.json"
    if proc.returncode != 0 or not result_path.exists():
        raise RuntimeError(f"anchor failed (rc={proc.returncode}): {(proc.stdout + proc.stderr)[-1500:]}")
    result = json.loads(result_path.read_text())["results"][0]
    if "error" in result:
        raise RuntimeError(f"anchor failed: {result['error'][-1500:]}")
    result["child_wall_s"] = wall_s
    result["color"] = read_rgba_png(ref_dir / f"{name}.png")
    result["depth"] = np.load(ref_dir / f"{name}_depth.npy")
    return result


PBR_ANCHOR = Path(__file__).resolve().parent / "anchor_moderngl_pbr.py"
PBR_TARGET = 0.7
"""Issue 46: frustum's shading="pbr" frame (one directional light + IBL) / llvmpipe's glTF PBR shader frame."""


def run_pbr(name: str, frames: int, args: argparse.Namespace, env: dict, work: Path, both: bool,
            phong: dict | None) -> dict:  # fmt: skip
    """frustum with ``shading="pbr"`` and the PBR anchor on one scene; prints both medians and the ratios."""
    result: dict = {}
    try:
        result["frustum_ms"] = run_frustum(name, frames, args, env, work, "shading=pbr")["frame_ms"]
        if both:
            proc = subprocess.run(
                [sys.executable, str(PBR_ANCHOR), "--scene", str(Path(args.scene_dir) / f"{name}.npz"),
                 "--frames", str(frames), "--warmup", str(args.warmup)],
                capture_output=True, text=True, env=env, timeout=args.timeout,
            )  # fmt: skip
            if proc.returncode != 0:
                raise RuntimeError(f"PBR anchor failed: {(proc.stdout + proc.stderr)[-1500:]}")
            result["llvmpipe_ms"] = json.loads(proc.stdout.strip().splitlines()[-1])["frame_ms"]
    except (RuntimeError, subprocess.TimeoutExpired) as exc:
        print(f"{name}: pbr failed: {exc}", flush=True)
        return result
    line = f"{name:20s} pbr       frame {result['frustum_ms']:8.1f} ms"
    if "llvmpipe_ms" in result:
        result["ratio"] = result["frustum_ms"] / result["llvmpipe_ms"]
        line += (f"  llvmpipe glTF PBR {result['llvmpipe_ms']:8.1f} ms  ratio {result['ratio']:.2f} "
                 f"(target <= {PBR_TARGET})")  # fmt: skip
    if phong:
        result["over_phong"] = result["frustum_ms"] / phong["frame_ms"]
        line += f"  {result['over_phong']:.2f}x frustum phong (target <= 1.5)"
    print(line, flush=True)
    return result


def run_frustum(name: str, frames: int, args: argparse.Namespace, env: dict, work: Path, variant: str = "") -> dict:
    cmd = [
        sys.executable, os.path.abspath(__file__), "--child-frustum", name, "--frames", str(frames),
        "--warmup", str(args.warmup), "--scene-dir", str(args.scene_dir), "--child-out", str(work),
        "--child-variant", variant,
    ]  # fmt: skip
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=args.timeout)
    wall_s = time.perf_counter() - t0
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")]
    if proc.returncode != 0 or not lines:
        raise RuntimeError(f"frustum child failed (rc={proc.returncode}): {(proc.stdout + proc.stderr)[-1500:]}")
    result = json.loads(lines[-1][len("RESULT ") :])
    result["child_wall_s"] = wall_s
    result["color"] = np.load(work / f"{name}_frustum_color.npy")
    depth_path = work / f"{name}_frustum_depth.npy"
    result["depth"] = np.load(depth_path) if depth_path.exists() else None
    return result


# --- parent: comparing images --------------------------------------------------------------------------------


def as_rgb8(color: np.ndarray) -> np.ndarray:
    """(H, W, 3) int16 levels from an (H, W, 3|4) image, uint8 or float in [0, 1]."""
    color = np.asarray(color)
    if color.dtype != np.uint8:
        color = np.clip(np.rint(color.astype(np.float64) * 255.0), 0, 255)
    return color[..., :3].astype(np.int16)


def coverage(color: np.ndarray, depth: np.ndarray | None, background: np.ndarray) -> np.ndarray:
    """Covered pixels: depth < 1 (the cleared far value) where there is a depth map, else colour != background."""
    if depth is not None:
        d = np.asarray(depth, dtype=np.float64)
        return np.isfinite(d) & (d < 1.0)
    bg = np.rint(np.asarray(background[:3], dtype=np.float64) * 255.0).astype(np.int16)
    return np.any(color != bg, axis=-1)


def compare(frustum_result: dict, llvmpipe_result: dict, background: np.ndarray) -> dict:
    """Coverage agreement and ±1-level colour agreement, both images top row first."""
    f_rgb, l_rgb = as_rgb8(frustum_result["color"]), as_rgb8(llvmpipe_result["color"])
    if f_rgb.shape != l_rgb.shape:
        return dict(error=f"image shapes differ: frustum {f_rgb.shape}, llvmpipe {l_rgb.shape}")
    f_depth = frustum_result["depth"]
    if f_depth is not None and np.shape(f_depth)[:2] != f_rgb.shape[:2]:
        f_depth = None
    f_cov = coverage(f_rgb, f_depth, background)
    l_cov = coverage(l_rgb, llvmpipe_result["depth"], background)
    diff = np.abs(f_rgb - l_rgb).max(axis=-1)
    both = f_cov & l_cov
    out = dict(
        coverage_agree_pct=100.0 * float(np.mean(f_cov == l_cov)),
        coverage_only_frustum=int(np.count_nonzero(f_cov & ~l_cov)),
        coverage_only_llvmpipe=int(np.count_nonzero(~f_cov & l_cov)),
        within1_pct=100.0 * float(np.mean(diff <= 1)),
        within1_covered_pct=100.0 * float(np.mean(diff[both] <= 1)) if both.any() else None,
        max_level_diff=int(diff.max()),
        covered_fraction_frustum=float(f_cov.mean()),
        covered_fraction_llvmpipe=float(l_cov.mean()),
    )
    if f_depth is not None and both.any():
        dd = np.abs(np.asarray(f_depth, np.float64) - np.asarray(llvmpipe_result["depth"], np.float64))[both]
        out["depth_max_abs_diff"] = float(dd.max())
        out["depth_median_abs_diff"] = float(np.median(dd))
    # A renderer storing bottom row first would agree far better flipped: say so rather than report noise.
    flipped = 100.0 * float(np.mean(f_cov[::-1] == l_cov))
    if flipped > out["coverage_agree_pct"] + 1.0:
        out["warning"] = f"frustum image looks bottom-row-first (coverage agreement {flipped:.2f} % when flipped)"
    return out


# --- parent: table -------------------------------------------------------------------------------------------


def _fmt(value, spec: str, width: int) -> str:
    return f"{'-':>{width}}" if value is None else f"{value:>{width}{spec}}"


def print_table(rows: list[dict]) -> None:
    header = (
        f"{'scene':20s} {'size':>9s} {'frustum ms':>10s} {'llvmpipe ms':>11s} {'ratio':>6s} {'target':>6s} "
        f"{'first s':>7s} {'RSS fr MiB':>10s} {'RSS lp MiB':>10s} {'cov agree %':>11s} {'±1 lvl %':>9s}"
    )
    print(header)
    print("-" * len(header))
    for r in rows:
        f, lp, cmp_ = r.get("frustum") or {}, r.get("llvmpipe") or {}, r.get("compare") or {}
        print(
            f"{r['scene']:20s} {r['size']:>9s} {_fmt(f.get('frame_ms'), '.1f', 10)} "
            f"{_fmt(lp.get('frame_ms'), '.1f', 11)} {_fmt(r.get('ratio'), '.2f', 6)} "
            f"{_fmt(TARGET_RATIO.get(r['scene']), '.2f', 6)} {_fmt(f.get('first_call_s'), '.2f', 7)} "
            f"{_fmt(f.get('peak_rss_mb'), '.0f', 10)} {_fmt(lp.get('peak_rss_mb'), '.0f', 10)} "
            f"{_fmt(cmp_.get('coverage_agree_pct'), '.3f', 11)} {_fmt(cmp_.get('within1_pct'), '.3f', 9)}"
        )


# --- main ----------------------------------------------------------------------------------------------------


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=DEFAULT_SCENES, choices=DEFAULT_SCENES)
    parser.add_argument("--frames", type=int, default=10, help="timed frames per scene (median reported)")
    parser.add_argument("--heavy-frames", type=int, default=3, help=f"timed frames for {', '.join(HEAVY_SCENES)}")
    parser.add_argument("--warmup", type=int, default=2, help="untimed frames after the first call")
    parser.add_argument("--scene-dir", default="/tmp/frustum-bench/scenes")
    parser.add_argument("--skip-llvmpipe", action="store_true")
    parser.add_argument("--skip-frustum", action="store_true")
    parser.add_argument("--threads", type=int, default=None, help="NUMBA_NUM_THREADS and LP_NUM_THREADS")
    parser.add_argument("--save", default=None, help="write <scene>_frustum.png and <scene>_llvmpipe.png here")
    parser.add_argument("--json", default=None, help="write all results here")
    parser.add_argument("--no-cache-check", action="store_true", help="skip the warm-cache first-call process")
    parser.add_argument("--timeout", type=float, default=1800.0, help="seconds per child process")
    parser.add_argument("--child-frustum", default=None, help=argparse.SUPPRESS)
    parser.add_argument("--child-out", default=None, help=argparse.SUPPRESS)
    parser.add_argument("--child-variant", default="", help=argparse.SUPPRESS)
    parser.add_argument("--pbr", action="store_true",
                        help="also shading=pbr (one light + image-based light) against the PBR anchor (issue 46)")
    parser.add_argument(
        "--variants", nargs="*", default=[],
        help="extra frustum runs per scene, e.g. shading=gouraud mode=hidden-line samples=4 (timed only)",
    )  # fmt: skip
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    if args.child_frustum:
        args.out = args.child_out
        print("RESULT " + json.dumps(frustum_child(args.child_frustum, args)), flush=True)
        return 0

    env = _child_env(args.threads)
    scene_dir = Path(args.scene_dir)
    ensure_scenes(scene_dir, args.scenes)
    _, anchor = _bench_modules()

    do_llvmpipe, do_frustum = not args.skip_llvmpipe, not args.skip_frustum
    gl_renderer = None
    if args.skip_llvmpipe:
        print("llvmpipe: skipped (--skip-llvmpipe)")
    else:
        do_llvmpipe, gl_renderer = check_llvmpipe(env)
        if do_llvmpipe:
            print(f"llvmpipe: {gl_renderer}")
            if "llvmpipe" not in gl_renderer:
                print(f"  warning: GL_RENDERER is not llvmpipe, ratios are against {gl_renderer.split('|')[0]}")
        else:
            print(f"llvmpipe: skipped, moderngl/EGL/Mesa not usable: {gl_renderer}")
            gl_renderer = None
    if args.skip_frustum:
        print("frustum: skipped (--skip-frustum)")
    else:
        do_frustum, why = check_frustum(env)
        print("frustum: ready" if do_frustum else f"frustum: skipped, {why}")
    threads = args.threads or f"default ({os.cpu_count()} CPUs)"
    print(f"threads: {threads}; frames {args.frames} (heavy scenes {args.heavy_frames}) after {args.warmup} warm-up")
    print(flush=True)

    if args.save:
        os.makedirs(args.save, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory(prefix="frustum-bench-") as tmp:
        work = Path(tmp)
        for name in args.scenes:
            frames = args.heavy_frames if name in HEAVY_SCENES else args.frames
            with np.load(scene_dir / f"{name}.npz") as npz:
                background = np.asarray(npz["background"])
                size = f"{int(npz['width'])}x{int(npz['height'])}"
            row: dict = dict(scene=name, size=size, frames=frames)
            runners = (("llvmpipe", do_llvmpipe, run_llvmpipe), ("frustum", do_frustum, run_frustum))
            for label, enabled, runner in runners:
                if not enabled:
                    continue
                try:
                    row[label] = runner(name, frames, args, env, work)
                except (RuntimeError, subprocess.TimeoutExpired) as exc:
                    row[label + "_error"] = str(exc)
                    print(f"{name}: {label} failed: {exc}", flush=True)
            f, lp = row.get("frustum"), row.get("llvmpipe")
            if f and lp:
                row["ratio"] = f["frame_ms"] / lp["frame_ms"]
                row["compare"] = compare(f, lp, background)
                if "warning" in row["compare"]:
                    print(f"{name}: {row['compare']['warning']}")
            if lp:
                print(
                    f"{name:20s} llvmpipe  frame {lp['frame_ms']:8.1f} ms (min {lp['frame_min_ms']:.1f}, "
                    f"max {lp['frame_max_ms']:.1f})  first {lp['first_frame_ms']:8.1f} ms  "
                    f"setup {lp['setup_ms']:7.1f} ms  peak {lp['peak_rss_mb']:6.0f} MiB",
                    flush=True,
                )
            if f:
                print(
                    f"{name:20s} frustum   frame {f['frame_ms']:8.1f} ms (min {f['frame_min_ms']:.1f}, "
                    f"max {f['frame_max_ms']:.1f})  first call {f['first_call_s']:.2f} s  "
                    f"setup {f['setup_s'] * 1e3:.1f} ms  peak {f['peak_rss_mb']:6.0f} MiB",
                    flush=True,
                )
            for variant in args.variants if do_frustum else ():
                try:
                    v = run_frustum(name, frames, args, env, work, variant)
                except (RuntimeError, subprocess.TimeoutExpired) as exc:
                    print(f"{name}: frustum {variant} failed: {exc}", flush=True)
                    continue
                ratio = f" ratio {v['frame_ms'] / lp['frame_ms']:.2f}" if lp else ""
                slower = f" ({v['frame_ms'] / f['frame_ms']:.2f}x phong)" if f else ""
                print(f"{name:20s} {variant:24s} frame {v['frame_ms']:8.1f} ms{ratio}{slower}", flush=True)
                row.setdefault("variants", {})[variant] = {k: v[k] for k in ("frame_ms", "peak_rss_mb")}
            if args.pbr:
                row["pbr"] = run_pbr(name, frames, args, env, work, do_llvmpipe and do_frustum, f)
            if args.save:
                for label in ("frustum", "llvmpipe"):
                    if row.get(label):
                        rgb = np.asarray(row[label]["color"])
                        rgba = np.dstack([as_rgb8(rgb).astype(np.uint8), np.full(rgb.shape[:2], 255, np.uint8)])
                        anchor.write_png(os.path.join(args.save, f"{name}_{label}.png"), rgba)
                if row.get("llvmpipe"):
                    np.save(os.path.join(args.save, f"{name}_llvmpipe_depth.npy"), row["llvmpipe"]["depth"])
                if row.get("frustum") and row["frustum"]["depth"] is not None:
                    np.save(os.path.join(args.save, f"{name}_frustum_depth.npy"), row["frustum"]["depth"])
            for label in ("frustum", "llvmpipe"):
                if row.get(label):
                    row[label].pop("color")
                    row[label].pop("depth")
            rows.append(row)
            shutil.rmtree(work / f"llvmpipe_{name}", ignore_errors=True)

        cache = None
        if do_frustum and any(r.get("frustum") for r in rows) and not args.no_cache_check:
            # Kernels are compiled and cached by now: a fresh process measures loading them (plus one frame).
            name = next(r["scene"] for r in rows if r.get("frustum"))
            args_warmup, args.warmup = args.warmup, 0
            try:
                cache = run_frustum(name, 1, args, env, work)
                cache = dict(scene=name, first_call_s=cache["first_call_s"], import_s=cache["import_s"])
            except (RuntimeError, subprocess.TimeoutExpired) as exc:
                print(f"cache check failed: {exc}")
            args.warmup = args_warmup

    print()
    print_table(rows)
    if cache:
        frame_s = next(r["frustum"]["frame_ms"] for r in rows if r["scene"] == cache["scene"]) / 1e3
        print(
            f"frustum first call in a fresh process with the kernel cache warm ({cache['scene']}): "
            f"{cache['first_call_s']:.3f} s, of which about {cache['first_call_s'] - frame_s:.3f} s beyond one "
            f"frame (cache load); import frustum {cache['import_s']:.2f} s"
        )
    if args.json:
        meta = dict(
            python=sys.version.split()[0],
            machine=platform.machine(),
            cpus=os.cpu_count(),
            numpy=np.__version__,
            argv=sys.argv[1:],
            threads=args.threads,
            gl_renderer=gl_renderer,
            frustum_cache_load=cache,
            env={k: os.environ[k] for k in os.environ if k.startswith(("LP_", "NUMBA_", "GALLIUM", "MESA", "EGL"))},
        )
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps(dict(meta=meta, results=rows), indent=1, default=str))
        print(f"wrote {args.json}")
    failed = any(k.endswith("_error") for r in rows for k in r)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
