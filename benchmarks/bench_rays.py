"""Benchmark: ray queries through the public API (``Scene.intersect``, ``Scene.occluded``) against Embree.

    python benchmarks/bench_rays.py [--rows bunny/camera bunny/random sphere/camera sphere/random]
                                    [--rays 262144] [--repeats 3] [--fields t item face]

Four rows, as a user calls them: the Stanford bunny (69,451 triangles, ``../shared/data/bunny/bun_zipper.ply``,
else the decimated copy in ``tests/data``) and a 1,308,672-triangle ``frustum.uv_sphere(segments=1024,
rings=640)``, each with camera rays (a pinhole camera looking at the object, √N × √N pixels) and random rays
(origins uniform in the object's bounding box grown twice about its centre, directions uniform on the sphere;
seed 0). First hits: ``Scene.intersect`` (every field; ``--fields`` also times that subset) against Embree 4
through ``embreex`` (``rtcIntersect1`` per ray, one thread: its ``run(..., output=1)``, which returns t, u, v,
the geometric normal and the face). Occlusion: ``Scene.occluded`` of shadow rays from each first hit (or from a
point 3 units along a ray that missed) toward a point light, t_max 1, against Embree's ``rtcOccluded1``.

Reported per row: **wall** time with frustum's default threads against Embree's one thread, and **CPU** time
(``time.process_time``: every thread of the process) with ``frustum.set_threads(1)`` against Embree's one
thread, each the median of `--repeats` runs, as ratios frustum / Embree (the project's rule: a ratio against the
anchor measured in the same run on the same machine; on a loaded host the CPU ratios are the reliable ones), and
the share of rays where both give the same face and the same occlusion. The load average is printed with them.

The faces that differ (camera rows: 4 of 262,144 rays on the bunny, 6 on the sphere) are not ties: each such ray
passes within a barycentric weight of 1e-6 … 1e-4 of an edge, and Embree's float32 test gives the neighbour
across it, which the float64 Möller–Trumbore test misses (that weight negative); frustum's face is the float64
answer (``t`` exact in float64; a true tie, the same t on two faces, goes to the lower face number).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

import numpy as np

import frustum as f

ROOT = Path(__file__).resolve().parents[1]
SHARED = next((p / "shared" for p in ROOT.parents if (p / "shared" / "data").is_dir()), ROOT.parent / "shared")
"""The project's shared folder (``../shared`` of the checkout, or of a folder above a git worktree)."""
ROWS = ("bunny/camera", "bunny/random", "sphere/camera", "sphere/random")


def load_mesh(name: str) -> f.Mesh:
    """The row's mesh, its vertices rounded to float32 (Embree's input) so both index the same triangles."""
    if name == "bunny":
        path = SHARED / "data" / "bunny" / "bun_zipper.ply"
        mesh = f.load(path if path.is_file() else ROOT / "tests" / "data" / "bunny" / "bun_zipper_res2.ply")
    else:
        mesh = f.uv_sphere(segments=1024, rings=640)
    return f.Mesh(mesh.vertices.astype(np.float32).astype(np.float64), mesh.faces)


def make_rays(mesh: f.Mesh, kind: str, count: int) -> tuple[np.ndarray, np.ndarray]:
    """(origins, directions), float32-representable float64 (N, 3)."""
    low, high = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    centre, extent = 0.5 * (low + high), float((high - low).max())
    if kind == "camera":
        size = round(float(np.sqrt(count)))
        eye = centre + np.array([0.1, 0.2, 1.4]) * extent
        forward = (centre - eye) / np.linalg.norm(centre - eye)
        right = np.cross(forward, [0.0, 1.0, 0.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        half = np.tan(np.radians(40.0) / 2.0)
        s = (np.arange(size) + 0.5) / size * 2.0 - 1.0
        x, y = np.meshgrid(s * half, -s * half)
        directions = forward + x.reshape(-1, 1) * right + y.reshape(-1, 1) * up
        origins = np.broadcast_to(eye, directions.shape)
    else:
        rng = np.random.default_rng(0)
        origins = centre + (rng.random((count, 3)) - 0.5) * 2.0 * (high - low)
        directions = rng.normal(size=(count, 3))
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    return (np.ascontiguousarray(origins, dtype=np.float32).astype(np.float64),
            np.ascontiguousarray(directions, dtype=np.float32).astype(np.float64))  # fmt: skip


def shadow_rays(mesh: f.Mesh, origins: np.ndarray, directions: np.ndarray, t: np.ndarray):
    """Rays from each first hit (3 units along a miss) toward a point light above the object, t_max 1."""
    low, high = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    light = 0.5 * (low + high) + np.array([2.0, 3.0, 2.5]) * float((high - low).max())
    points = origins + np.where(np.isfinite(t), t, 3.0)[:, None] * directions
    to_light = light - points
    start = points + 1e-4 * to_light / np.linalg.norm(to_light, axis=1, keepdims=True)
    return start.astype(np.float32).astype(np.float64), (light - start).astype(np.float32).astype(np.float64)


def measure(function, repeats: int) -> tuple[float, float, object]:
    """(median wall s, median CPU s of the process, the last result) over `repeats` runs."""
    walls, cpus, result = [], [], None
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        result = function()
        cpus.append(time.process_time() - cpu)
        walls.append(time.perf_counter() - wall)
    return statistics.median(walls), statistics.median(cpus), result


def bench_row(row: str, count: int, repeats: int, fields: tuple[str, ...] | None) -> dict:
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh

    name, kind = row.split("/")
    mesh = load_mesh(name)
    scene = f.Scene()
    scene.add(mesh)
    origins, directions = make_rays(mesh, kind, count)
    embree = rtcore_scene.EmbreeScene()
    TriangleMesh(embree, mesh.vertices[mesh.faces].astype(np.float32))
    o32, d32 = origins.astype(np.float32), directions.astype(np.float32)
    embree.run(o32[:1], d32[:1])  # the commit (Embree's BVH build) happens at the first query
    scene.intersect(origins[:1000], directions[:1000])  # the index build (and any compilation) outside the timings
    scene.occluded(origins[:1000], directions[:1000], 1.0)
    result: dict = {"row": row, "triangles": mesh.face_count, "rays": origins.shape[0]}
    hit_e = measure(lambda: embree.run(o32, d32, output=1), repeats)
    hit_wall = measure(lambda: scene.intersect(origins, directions), repeats)
    subset = None
    f.set_threads(1)
    try:
        hit_cpu = measure(lambda: scene.intersect(origins, directions), repeats)
        if fields:
            subset = measure(lambda: scene.intersect(origins, directions, fields=fields), repeats)
    finally:
        f.set_threads(None)
    hits, embree_hits = hit_wall[2], hit_e[2]
    s_o, s_d = shadow_rays(mesh, origins, directions, hits.t)
    s32, l32, ones = s_o.astype(np.float32), s_d.astype(np.float32), np.ones(s_o.shape[0], dtype=np.float32)
    occ_e = measure(lambda: embree.run(s32, l32, dists=ones, query="OCCLUDED"), repeats)
    occ_wall = measure(lambda: scene.occluded(s_o, s_d, 1.0), repeats)
    f.set_threads(1)
    try:
        occ_cpu = measure(lambda: scene.occluded(s_o, s_d, 1.0), repeats)
    finally:
        f.set_threads(None)
    result.update(
        hit=(hit_wall[0] / hit_e[0], hit_cpu[1] / hit_e[1]), occluded=(occ_wall[0] / occ_e[0], occ_cpu[1] / occ_e[1]),
        subset=None if subset is None else subset[1] / hit_e[1], embree=(hit_e[1], occ_e[1]),
        same_face=float((hits.face == embree_hits["primID"]).mean()),
        same_occlusion=float((occ_wall[2] == (occ_e[2] != -1)).mean()),
        hit_fraction=float((hits.face >= 0).mean()), occluded_fraction=float(occ_wall[2].mean()),
    )  # fmt: skip
    return result


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", nargs="+", default=list(ROWS), choices=ROWS)
    parser.add_argument("--rays", type=int, default=262_144)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--fields", nargs="*", default=["t", "item", "face"])
    args = parser.parse_args(argv)
    fields = tuple(args.fields) or None
    from frustum.raster._jit import threads
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}, {os.cpu_count()} cores, "
          f"frustum default threads {threads()}; ratios frustum / Embree (1 thread), medians of {args.repeats}")
    subset_head = f"{'hit CPU ' + ','.join(fields) if fields else ''}"
    print(f"{'row':<15}{'triangles':>10}  {'hit wall':>9}{'hit CPU':>9}  {subset_head:>18}  {'occ wall':>9}"
          f"{'occ CPU':>9}  {'Embree hit/occ CPU s':>21}  same face/occlusion")  # fmt: skip
    for row in args.rows:
        r = bench_row(row, args.rays, args.repeats, fields)
        subset = f"{r['subset']:>18.2f}" if r["subset"] is not None else f"{'':>18}"
        print(f"{row:<15}{r['triangles']:>10}  {r['hit'][0]:>9.2f}{r['hit'][1]:>9.2f}  {subset}  "
              f"{r['occluded'][0]:>9.2f}{r['occluded'][1]:>9.2f}  {r['embree'][0]:>10.3f}/{r['embree'][1]:<10.3f}"
              f"  {r['same_face']:.5f}/{r['same_occlusion']:.5f}", flush=True)  # fmt: skip
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
