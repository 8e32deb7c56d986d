"""Benchmark: ``render_dataset`` / ``render_many`` on every executor against a bare ``render`` loop.

    python benchmarks/bench_batch.py [--views 200] [--size 512] [--runs serial,process1,process2,ray2]
                                     [--mesh PATH] [--out DIR] [--json PATH]

The Stanford bunny (69,451 triangles) at ``--size``² with every buffer (color PNG, metric depth .npy, normals
.npy, object ids and mask PNGs), ``--views`` views on an orbit, format "files". For each run it prints:

- views per second (wall clock of the whole ``render_dataset`` call: pool or cluster start included);
- worker seconds per view spent rendering and writing (``ViewResult.render_seconds`` / ``write_seconds``, as
  logged in the manifest);
- overhead per view: ``(wall × workers − Σ render − Σ write) / views``, worker time not spent on a view
  (start-up, loading the kernels, receiving the scene, passing jobs and results, idle at the end);
- first result: seconds from the call to the first finished view (start-up cost);
- peak resident memory per worker (psutil, sampled every 50 ms; serial: this process);
- the 1-minute load average after the run (the machine may be shared: read the numbers with it).

The baseline is a bare loop in this process, ``render(...)`` then the same files written with the same encoders,
after a warm-up (the first call, kernel compile or cache load, is printed separately). Output bytes per view
are summed from the files. Ray runs start a local cluster of ``num_cpus = workers`` (its start is included).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

import psutil

SCENE = """
title = "bench_batch: the Stanford bunny"
[render]
size = [{size}, {size}]
[camera]
eye = [-0.05, 0.25, 0.32]
target = [-0.017, 0.11, 0.0]
fovy_deg = 35
near = 0.05
far = 2.0
[[lights]]
type = "ambient"
intensity = 0.3
[[lights]]
type = "directional"
direction = [-0.5, -1.0, -0.6]
[[nodes]]
name = "bunny"
geometry = {{ type = "mesh", path = "{mesh}" }}
"""


class PeakMemory:
    """Peak RSS of matching processes, sampled every 50 ms in a thread."""

    def __init__(self, kind: str) -> None:
        self.kind, self.peak, self._stop = kind, {}, threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _processes(self) -> list[psutil.Process]:
        me = psutil.Process()
        if self.kind == "serial":
            return [me]
        found = []
        candidates = me.children(recursive=True) if self.kind == "process" else psutil.process_iter()
        for process in candidates:
            try:
                line = " ".join(process.cmdline())
            except psutil.Error:  # gone, or a zombie at the pool's shutdown
                continue
            if ("resource_tracker" not in line) if self.kind == "process" else ("_RayRenderer" in line):
                found.append(process)
        return found

    def _run(self) -> None:
        while not self._stop.is_set():
            for process in self._processes():
                try:
                    rss = process.memory_info().rss
                except psutil.Error:
                    continue
                self.peak[process.pid] = max(self.peak.get(process.pid, 0), rss)
            self._stop.wait(0.05)

    def __enter__(self) -> PeakMemory:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()


def bare_loop(scene_file, cameras, out: Path) -> dict:
    """render + the same encoders, in this process, one view after another."""
    from frustum.batch.jobs import RenderJob, render_view

    kinds = {"color": "images/{}.png", "depth": "depth/{}.npy", "normals": "normals/{}.npy",
             "object_id": "object_id/{}.png", "mask": "masks/{}.png"}  # fmt: skip

    def job(key, camera):
        return RenderJob(key, scene_file.scene, camera, {k: out / v.format(key) for k, v in kinds.items()})

    start = time.perf_counter()
    first = render_view(scene_file.scene, job("warmup", cameras[0][1]), scene_file.options)
    first_seconds = time.perf_counter() - start
    assert first.ok, first.error
    renders, writes = [], []
    start = time.perf_counter()
    for key, camera in cameras:
        result = render_view(scene_file.scene, job(key, camera), scene_file.options)
        assert result.ok, result.error
        renders.append(result.render_seconds)
        writes.append(result.write_seconds)
    wall = time.perf_counter() - start
    return {
        "first_call_s": first_seconds,
        "wall_s": wall,
        "views_per_s": len(cameras) / wall,
        "render_ms_median": 1e3 * statistics.median(renders),
        "write_ms_median": 1e3 * statistics.median(writes),
        "render_s_total": sum(renders),
        "write_s_total": sum(writes),
    }


def dataset_run(scene_path: Path, out: Path, views: int, executor: str, workers: int) -> dict:
    import frustum.batch.progress as progress_module
    from frustum.batch import render_dataset

    first: list[float] = []
    start = time.perf_counter()
    original = progress_module.ViewProgress.advance

    def advance(self, result):  # the first finished view marks the end of start-up
        if not first:
            first.append(time.perf_counter() - start)
        return original(self, result)

    progress_module.ViewProgress.advance = advance
    started_ray = False
    try:
        if executor == "ray":
            import ray

            ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False, configure_logging=False)
            started_ray = True
        kind = "serial" if executor == "serial" else executor
        with PeakMemory(kind) as memory:
            result = render_dataset(scene_path, out, views=views, layout="orbit", format="files", executor=executor,
                                    workers=workers, progress=False)  # fmt: skip
        wall = time.perf_counter() - start
    finally:
        progress_module.ViewProgress.advance = original
        if started_ray:
            import ray

            ray.shutdown()
    assert result.ok, result.failed
    entries = [json.loads(line) for line in (out / "manifest.jsonl").read_text().splitlines()[1:]]
    render_total = sum(e["render_seconds"] for e in entries)
    write_total = sum(e["write_seconds"] for e in entries)
    count = 1 if executor == "serial" else workers
    peaks = sorted(memory.peak.values())
    return {
        "wall_s": wall,
        "views_per_s": views / wall,
        "render_ms_per_view": 1e3 * render_total / views,
        "write_ms_per_view": 1e3 * write_total / views,
        "overhead_ms_per_view": 1e3 * (wall * count - render_total - write_total) / views,
        "first_result_s": first[0] if first else float("nan"),
        "workers_seen": len({e["worker"] for e in entries}),
        "peak_rss_mib_per_worker": [round(p / 2**20, 1) for p in peaks],
        "load_average_1min_after": os.getloadavg()[0],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--views", type=int, default=200)
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--runs", default="serial,process1,process2,ray2")
    bunny = Path(__file__).resolve().parents[1] / "tests" / "data" / "bunny" / "bun_zipper.ply"
    parser.add_argument("--mesh", default=str(bunny))
    parser.add_argument("--out", default=None, help="folder for the datasets (default: a temporary one, removed)")
    parser.add_argument("--json", default=None)
    args = parser.parse_args()

    from frustum.batch import dataset_cameras
    from frustum.scenefile import load_scene_file

    work = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="bench_batch_"))
    work.mkdir(parents=True, exist_ok=True)
    scene_path = work / "bunny.toml"
    scene_path.write_text(SCENE.format(size=args.size, mesh=Path(args.mesh).resolve()))
    scene_file = load_scene_file(scene_path)
    cameras = dataset_cameras(scene_file.cameras[0], args.views, "orbit")
    print(f"bench_batch: {args.views} views of {Path(args.mesh).name} "
          f"({scene_file.scene.items[0].mesh.face_count} triangles) at {args.size}x{args.size}, all buffers; "
          f"{os.cpu_count()} cores, python {sys.version.split()[0]}")  # fmt: skip
    report: dict = {"views": args.views, "size": args.size, "cores": os.cpu_count()}
    bare = bare_loop(scene_file, cameras, work / "bare")
    bare["load_average_1min_after"] = os.getloadavg()[0]
    sizes = {}
    for path in (work / "bare").rglob("*"):
        if path.is_file() and "warmup" not in path.name:
            sizes[path.parent.name] = sizes.get(path.parent.name, 0) + path.stat().st_size
    per_view = {kind: total / args.views for kind, total in sizes.items()}
    report["bare"], report["bytes_per_view"] = bare, per_view
    print(f"  bare loop        {bare['views_per_s']:6.2f} views/s   render {bare['render_ms_median']:6.1f} ms  "
          f"write {bare['write_ms_median']:6.1f} ms (medians)   first call {bare['first_call_s']:.1f} s   "
          f"load {bare['load_average_1min_after']:.1f}")  # fmt: skip
    print("  output per view: " + ", ".join(f"{k} {v / 1024:.0f} KiB" for k, v in sorted(per_view.items()))
          + f"; total {sum(per_view.values()) / 2**20:.2f} MiB")  # fmt: skip
    shutil.rmtree(work / "bare")
    for run in args.runs.split(","):
        executor = run.rstrip("0123456789")
        workers = int(run[len(executor) :] or 1)
        out = work / run
        shutil.rmtree(out, ignore_errors=True)
        result = dataset_run(scene_path, out, args.views, executor, workers)
        report[run] = result
        print(f"  {run:<16} {result['views_per_s']:6.2f} views/s   render {result['render_ms_per_view']:6.1f} ms  "
              f"write {result['write_ms_per_view']:6.1f} ms  overhead {result['overhead_ms_per_view']:6.1f} ms "
              f"(worker time per view)   first result {result['first_result_s']:.1f} s   "
              f"peak RSS/worker {result['peak_rss_mib_per_worker']} MiB   "
              f"load {result['load_average_1min_after']:.1f}")  # fmt: skip
        shutil.rmtree(out, ignore_errors=True)
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    if not args.out:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
