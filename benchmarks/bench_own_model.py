"""Your own model in one command (issues 36, 49): `frustum render <mesh file> -o out.png` on six real files, cold (an
empty Numba cache) and warm, beside F3D's headless render of the same files, in the same run, three ways:

(a) one command per file, each in its own process (the default: no resident process);
(b) all six files in one command, ``frustum render f1 ... f6 -o {index}-{name}.png`` (per-file time = the
    command's time / 6; every file with ``--up y``, the teapot lying on its side: the timing is what counts);
(c) one command per file handed to a resident render process started on purpose (``frustum resident start``).

Each timing is a whole process, as a user runs it, against a Python one-liner that opens F3D offscreen
(``f3d.Engine.create(True)``), adds the file, renders 480x360 and saves the PNG. Warm timings are medians of
`--repeat` runs; cold is one run of the first file with an empty ``NUMBA_CACHE_DIR``. F3D is the anchor: the
ratio frustum / F3D per file is what this reports (targets: (a) <= 1.3, (b) <= 0.5), in wall time and in CPU time
(user + system of the whole process, and for (c) of the resident's request children too: steadier than wall time
on a shared machine). Warm means the kernel cache and Python's bytecode cache are filled
(``PYTHONDONTWRITEBYTECODE`` is dropped for the runs: a source checkout under that setting compiles frustum's
modules from source on every run, ~0.1 s).

    python benchmarks/bench_own_model.py [--repeat 3] [--no-cold]

Needs ``pip install f3d`` (the bench extra; otherwise only frustum's times are printed) and trimesh (for the GLB,
STL and OFF made from the reference files).
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"

F3D_SCRIPT = """
import sys, f3d
engine = f3d.Engine.create(True)
engine.window.size = (480, 360)
engine.scene.add(sys.argv[1])
engine.window.render_to_image().save(sys.argv[2])
"""


def make_files(folder: Path) -> dict[str, tuple[Path, str]]:
    """The six files: bunny PLY, Spot OBJ + MTL + PNG, Spot GLB (texture embedded), teapot OBJ, bunny STL, OFF."""
    import trimesh
    from PIL import Image

    bunny = trimesh.load(DATA / "bunny" / "bun_zipper_res2.ply", process=False)
    bunny.export(folder / "bunny.stl")
    bunny.export(folder / "bunny.off")
    spot_obj = DATA / "spot" / "spot_triangulated.obj"
    (folder / "spot.mtl").write_text("newmtl cow\nKd 1 1 1\nmap_Kd spot_texture.png\n")
    (folder / "spot.obj").write_text("mtllib spot.mtl\nusemtl cow\n" + spot_obj.read_text())
    shutil.copy(DATA / "spot" / "spot_texture.png", folder / "spot_texture.png")
    mesh = trimesh.load(spot_obj, process=False)
    material = trimesh.visual.material.PBRMaterial(
        baseColorTexture=Image.open(DATA / "spot" / "spot_texture.png"), baseColorFactor=[255, 255, 255, 255]
    )
    mesh.visual = trimesh.visual.TextureVisuals(uv=mesh.visual.uv, material=material)
    mesh.export(folder / "spot.glb")
    return {
        "bunny.ply": (DATA / "bunny" / "bun_zipper_res2.ply", "y"),
        "spot.obj+mtl": (folder / "spot.obj", "y"),
        "spot.glb": (folder / "spot.glb", "y"),
        "teapot.obj": (DATA / "teapot_n10.obj", "z"),
        "bunny.stl": (folder / "bunny.stl", "y"),
        "bunny.off": (folder / "bunny.off", "y"),
    }


def timed(command: list[str], env: dict[str, str] | None = None) -> float:
    return timed_cpu(command, env)[0]


def timed_cpu(command: list[str], env: dict[str, str] | None = None) -> tuple[float, float]:
    """Wall seconds and CPU seconds (user + system) of one whole process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, check=True, env=env, capture_output=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _medians(runs: list[tuple[float, float]]) -> tuple[float, float]:
    return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)


def _resident_cpu(env: dict[str, str]) -> float:
    """CPU seconds (user + system, its own and its reaped request children's) the resident render processes of
    `env`'s runtime folder have used so far."""
    script = "from frustum.app import resident; print(' '.join(str(e['pid']) for e in resident.status()))"
    pids = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True).stdout.split()
    total = 0.0
    for pid in pids:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        total += sum(int(value) for value in fields[11:15]) / os.sysconf("SC_CLK_TCK")
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-cold", action="store_true")
    args = parser.parse_args()
    frustum_cli = [sys.executable, "-m", "frustum"]
    with tempfile.TemporaryDirectory(prefix="fr-bench-") as temp:
        folder = Path(temp)
        (folder / "run").mkdir(mode=0o700)
        env = {**os.environ, "PYTHONPATH": str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""),
               "XDG_RUNTIME_DIR": str(folder / "run")}  # fmt: skip
        env.pop("PYTHONDONTWRITEBYTECODE", None)  # warm = bytecode cached too, as pip install leaves a package
        env.pop("FRUSTUM_RESIDENT", None)  # the default: (a) and (b) start no resident process
        own_env = {**env, "FRUSTUM_RESIDENT": "0"}
        try:
            import f3d  # noqa: F401

            have_f3d = True
        except ImportError:
            have_f3d = False
            print("f3d is not installed (pip install f3d): frustum's times only")
        try:
            _compare(args, frustum_cli, folder, env, own_env, have_f3d)
        finally:
            subprocess.run([*frustum_cli, "resident", "stop"], env=env, capture_output=True)


def _compare(args: argparse.Namespace, frustum_cli: list[str], folder: Path, env: dict[str, str],
             own_env: dict[str, str], have_f3d: bool) -> None:  # fmt: skip
    files = make_files(folder)
    print(f"load average at the start: {' '.join(f'{v:.2f}' for v in os.getloadavg())} ({os.cpu_count()} cores)")
    first_name, (first, up) = next(iter(files.items()))
    if not args.no_cold:
        cold_env = {**own_env, "NUMBA_CACHE_DIR": str(folder / "empty_cache")}
        cold = timed([*frustum_cli, "render", str(first), "-o", str(folder / "cold.png"), "--up", up], cold_env)
        print(f"cold (empty NUMBA_CACHE_DIR), {first_name}: {cold:.2f} s")
    for path, up in files.values():  # every kernel the six files use is in the cache before timing
        timed([*frustum_cli, "render", str(path), "-o", str(folder / "warm.png"), "--up", up], own_env)
    f3d_runs: dict[str, tuple[float, float]] = {}
    own_runs: dict[str, tuple[float, float]] = {}
    for name, (path, up) in files.items():  # (a) and F3D
        command = [*frustum_cli, "render", str(path), "-o", str(folder / "ours.png"), "--up", up]
        own_runs[name] = _medians([timed_cpu(command, env) for _ in range(args.repeat)])
        if have_f3d:
            f3d_runs[name] = _medians([timed_cpu([sys.executable, "-c", F3D_SCRIPT, str(path), str(folder / "f3d.png")],
                                                 env) for _ in range(args.repeat)])  # fmt: skip
    batch = [*frustum_cli, "render", *(str(path) for path, _ in files.values()), "-o",
             str(folder / "batch" / "{index}-{name}.png"), "--up", "y"]  # fmt: skip
    batch_wall, batch_cpu = _medians([timed_cpu(batch, env) for _ in range(args.repeat)])  # (b)
    subprocess.run([*frustum_cli, "resident", "start"], env=env, capture_output=True, check=True)  # (c)
    resident_runs: dict[str, tuple[float, float]] = {}
    for name, (path, up) in files.items():
        command = [*frustum_cli, "render", str(path), "-o", str(folder / "ours.png"), "--up", up]
        handed = []
        for _ in range(args.repeat):
            before = _resident_cpu(env)
            wall, cpu = timed_cpu(command, env)
            handed.append((wall, cpu + _resident_cpu(env) - before))
        resident_runs[name] = _medians(handed)
    print("(a) own: one command per file in its own process (no resident); (c) resident: handed to a resident "
          "started on purpose (CPU: client + the resident's request child)")
    print(f"{'file':<14} {'own s':>7} {'F3D s':>7} {'own/F3D':>8} {'resident s':>10} {'res/F3D':>8}   "
          f"{'CPU s: own':>10} {'F3D':>6} {'own/F3D':>8} {'resident':>8}")  # fmt: skip
    for name in files:
        own, own_cpu = own_runs[name]
        handed_wall, handed_cpu = resident_runs[name]
        theirs, theirs_cpu = f3d_runs.get(name, (float("nan"), float("nan")))
        print(f"{name:<14} {own:>7.2f} {theirs:>7.2f} {own / theirs:>8.2f} {handed_wall:>10.2f} "
              f"{handed_wall / theirs:>8.2f}   {own_cpu:>10.2f} {theirs_cpu:>6.2f} {own_cpu / theirs_cpu:>8.2f} "
              f"{handed_cpu:>8.2f}", flush=True)  # fmt: skip
    f3d_wall = statistics.median(wall for wall, _ in f3d_runs.values()) if f3d_runs else float("nan")
    f3d_cpu = statistics.median(cpu for _, cpu in f3d_runs.values()) if f3d_runs else float("nan")
    print(f"(b) six files in one command: {batch_wall:.2f} s ({batch_cpu:.2f} s CPU), per file {batch_wall / 6:.3f} s "
          f"= {batch_wall / 6 / f3d_wall:.2f}x F3D's median per file ({f3d_wall:.2f} s); CPU per file "
          f"{batch_cpu / 6:.3f} s = {batch_cpu / 6 / f3d_cpu:.2f}x F3D's ({f3d_cpu:.2f} s)")  # fmt: skip
    print(f"load average at the end: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
