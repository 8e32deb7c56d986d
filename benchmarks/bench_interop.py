"""Benchmark: pyrender's own offscreen render (Mesa llvmpipe through EGL) against
``frustum.interop.pyrender.OffscreenRenderer`` on the same ``pyrender.Scene``, same size, same machine, same run.

    python benchmarks/bench_interop.py [--scenes bunny_like_100k objects_20] [--frames 10] [--warmup 2]
                                       [--runs 3] [--size 640x480] [--scene-dir DIR] [--json PATH]

Scenes: ``bunny_like_100k`` (the shared standard scene of 100,000 triangles, ``../shared/bench/scenes.py``, drawn
as a pyrender primitive with its normals, a metallic–roughness material of its base colour and its directional
light) and ``objects_20`` (20 mesh nodes: boxes, spheres, cylinders and capsules of ~200–1,300 triangles each on
a 5 x 4 grid, each its own material, one directional light). Both at 640 x 480, colour and depth
(``RenderFlags.NONE``).

Each (scene, renderer, run) is a fresh child process: it builds the scene, then times the first frame (pyrender:
creating the renderer with its EGL context and the first ``render``; frustum: creating the renderer and the first
``render``, with Numba's on-disk kernel cache already warm from earlier runs) and ``--frames`` warm frames after
``--warmup`` (the median). Reported: the median over ``--runs`` runs of each, and the ratio frustum / pyrender of
the warm frames against the target 0.7.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

# ../shared/bench beside the repository (the nearest ancestor that has one: a git worktree sits deeper)
_HERE = Path(__file__).resolve()
BENCH_DIR = next(
    (p / "shared" / "bench" for p in _HERE.parents if (p / "shared" / "bench").is_dir()),
    _HERE.parents[1].parent / "shared" / "bench",
)
SCENES = ("bunny_like_100k", "objects_20")
TARGET_RATIO = 0.7


def _look_at_pose(eye, target, up) -> np.ndarray:
    """Camera-to-world (OpenGL axes) of a camera at `eye` looking at `target`."""
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    back = eye - target
    back /= np.linalg.norm(back)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = right, np.cross(back, right), back, eye
    return pose


def _light_pose(to_light) -> np.ndarray:
    """A directional light's pose whose −z axis is the light's direction (away from `to_light`)."""
    z = np.asarray(to_light, dtype=np.float64)
    z /= np.linalg.norm(z)
    helper = np.array([0.0, 1.0, 0.0]) if abs(z[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2] = x, np.cross(z, x), z
    return pose


def build_scene(name: str, scene_dir: Path, width: int, height: int):
    import pyrender
    import trimesh

    if name == "bunny_like_100k":
        if str(BENCH_DIR) not in sys.path:
            sys.path.insert(0, str(BENCH_DIR))
        import scenes

        data = scenes.load_scene(str(scene_dir / f"{name}.npz"))
        scene = pyrender.Scene(ambient_light=[0.12] * 3, bg_color=np.asarray(data["background"], dtype=np.float64))
        material = pyrender.MetallicRoughnessMaterial(baseColorFactor=[*data["base_color"].tolist(), 1.0],
                                                      metallicFactor=0.0, roughnessFactor=0.6)  # fmt: skip
        primitive = pyrender.Primitive(positions=data["vertices"], normals=data["normals"], indices=data["faces"],
                                       material=material)  # fmt: skip
        scene.add(pyrender.Mesh([primitive]))
        scene.add(pyrender.DirectionalLight(intensity=3.0), pose=_light_pose(data["light_dir"]))
        camera = pyrender.PerspectiveCamera(yfov=np.radians(float(data["fovy_deg"])), znear=float(data["near"]),
                                            zfar=float(data["far"]))  # fmt: skip
        scene.add(camera, pose=_look_at_pose(data["eye"], data["target"], data["up"]))
        return scene
    scene = pyrender.Scene(ambient_light=[0.1] * 3, bg_color=[0.1, 0.1, 0.12, 1.0])
    makers = [
        lambda: trimesh.creation.box((0.8, 0.8, 0.8)),
        lambda: trimesh.creation.icosphere(3, 0.45),
        lambda: trimesh.creation.cylinder(0.35, 0.9, sections=64),
        lambda: trimesh.creation.capsule(0.6, 0.3, count=[24, 24]),
    ]
    for index in range(20):
        row, column = divmod(index, 5)
        mesh = makers[index % 4]()
        hue = index / 20.0
        rgba = [0.3 + 0.6 * hue, 0.8 - 0.5 * hue, 0.5, 1.0]
        material = pyrender.MetallicRoughnessMaterial(
            baseColorFactor=rgba, metallicFactor=0.1 * (index % 3), roughnessFactor=0.5
        )
        pose = trimesh.transformations.translation_matrix([1.3 * column - 2.6, 1.3 * row - 1.95, 0.0])
        scene.add(pyrender.Mesh.from_trimesh(mesh, material=material), pose=pose)
    scene.add(pyrender.DirectionalLight(intensity=3.0), pose=_light_pose([0.3, 0.8, 0.5]))
    camera = pyrender.PerspectiveCamera(yfov=np.radians(45.0), znear=0.5, zfar=30.0)
    scene.add(camera, pose=_look_at_pose([1.0, 1.5, 8.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]))
    return scene


def child(renderer: str, name: str, args: argparse.Namespace) -> dict:
    """One fresh process: build the scene, time the first frame and the warm frames."""
    width, height = args.width, args.height
    scene = build_scene(name, Path(args.scene_dir), width, height)
    start = time.perf_counter()
    if renderer == "pyrender":
        import pyrender

        offscreen = pyrender.OffscreenRenderer(width, height)
    else:
        from frustum.interop.pyrender import OffscreenRenderer

        offscreen = OffscreenRenderer(width, height)
    color, depth = offscreen.render(scene)
    first = time.perf_counter() - start
    for _ in range(args.warmup):
        offscreen.render(scene)
    times = []
    for _ in range(args.frames):
        start = time.perf_counter()
        color, depth = offscreen.render(scene)
        times.append(time.perf_counter() - start)
    offscreen.delete()
    return {"first_s": first, "frame_s": statistics.median(times), "covered": float((depth > 0).mean()),
            "shape": list(color.shape)}  # fmt: skip


def ensure_scene(scene_dir: Path) -> None:
    if not (scene_dir / "bunny_like_100k.npz").exists():
        sys.path.insert(0, str(BENCH_DIR))
        import scenes

        scenes.main(["--only", "bunny_like_100k", "--out", str(scene_dir)])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="*", default=list(SCENES), choices=SCENES)
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--warmup", type=int, default=2)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--size", default="640x480")
    parser.add_argument("--scene-dir", default="/tmp/frustum-bench/scenes")
    parser.add_argument("--json", default=None)
    parser.add_argument("--child", nargs=2, metavar=("RENDERER", "SCENE"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    args.width, args.height = (int(v) for v in args.size.split("x"))
    if args.child:
        print(json.dumps(child(args.child[0], args.child[1], args)))
        return 0
    ensure_scene(Path(args.scene_dir))
    environment = {**os.environ, "PYOPENGL_PLATFORM": "egl"}
    results: dict = {}
    for name in args.scenes:
        for renderer in ("pyrender", "frustum"):
            runs = []
            for _ in range(args.runs):
                command = [sys.executable, __file__, "--child", renderer, name, "--frames", str(args.frames),
                           "--warmup", str(args.warmup), "--size", args.size,
                           "--scene-dir", args.scene_dir]  # fmt: skip
                done = subprocess.run(command, capture_output=True, text=True, env=environment, check=False)
                if done.returncode != 0:
                    print(f"{name} {renderer}: failed\n{done.stderr[-2000:]}", file=sys.stderr)
                    break
                runs.append(json.loads(done.stdout.strip().splitlines()[-1]))
            if runs:
                results[(name, renderer)] = {
                    "frame_ms": statistics.median(r["frame_s"] for r in runs) * 1e3,
                    "first_ms": statistics.median(r["first_s"] for r in runs) * 1e3,
                    "covered": runs[0]["covered"],
                }
    print(f"{'scene':18} {'pyrender ms':>12} {'frustum ms':>11} {'ratio':>6} {'target':>7} "
          f"{'pyrender 1st ms':>16} {'frustum 1st ms':>15}")  # fmt: skip
    table = {}
    for name in args.scenes:
        ours, theirs = results.get((name, "frustum")), results.get((name, "pyrender"))
        if not ours or not theirs:
            continue
        ratio = ours["frame_ms"] / theirs["frame_ms"]
        verdict = "met" if ratio <= TARGET_RATIO else "missed"
        print(f"{name:18} {theirs['frame_ms']:12.1f} {ours['frame_ms']:11.1f} {ratio:6.2f} {verdict:>7} "
              f"{theirs['first_ms']:16.0f} {ours['first_ms']:15.0f}")  # fmt: skip
        table[name] = {"pyrender": theirs, "frustum": ours, "ratio": ratio}
    print(f"load: {os.getloadavg()}")
    if args.json:
        Path(args.json).write_text(json.dumps(table, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
