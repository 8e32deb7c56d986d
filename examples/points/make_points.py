"""Write the point files of the point-cloud and splat examples (run from the repository root:
``python examples/points/make_points.py``; the bytes are the same on every run).

- ``bunny_scan.ply``: 8,000 points sampled uniformly (by area, seed 0) from the Stanford bunny
  (``tests/data/bunny/bun_zipper_res2.ply``, see ``tests/data/README.md`` for its licence), coloured like a scan by
  height (a blue-to-sand ramp) with a little per-point noise; no normals (a scan's raw points).
- ``torus_splats.ply``: the 3DGS file of ``tests/data/splats/make_splats.py`` (the same bytes).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import trimesh

HERE = Path(__file__).parent
ROOT = HERE.parent.parent


def bunny_points() -> tuple[np.ndarray, np.ndarray]:
    bunny = trimesh.load(ROOT / "tests" / "data" / "bunny" / "bun_zipper_res2.ply", process=False)
    points, _ = trimesh.sample.sample_surface(bunny, 8_000, seed=0)
    height = (points[:, 1] - points[:, 1].min()) / np.ptp(points[:, 1])
    low, high = np.array([0.25, 0.35, 0.75]), np.array([0.95, 0.8, 0.55])
    rng = np.random.default_rng(0)
    colors = (low + height[:, None] * (high - low)) * rng.uniform(0.85, 1.0, size=(len(points), 1))
    return points, np.round(colors * 255).astype(np.uint8)


def write_ply(path: Path, points: np.ndarray, colors: np.ndarray, normals: np.ndarray | None = None) -> None:
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    if normals is not None:
        fields += [("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4")]
    fields += [("red", "u1"), ("green", "u1"), ("blue", "u1")]
    table = np.zeros(len(points), dtype=fields)
    for i, axis in enumerate("xyz"):
        table[axis] = points[:, i]
        if normals is not None:
            table["n" + axis] = normals[:, i]
    for i, channel in enumerate(("red", "green", "blue")):
        table[channel] = colors[:, i]
    types = {"<f4": "float", "u1": "uchar"}
    header = "ply\nformat binary_little_endian 1.0\n" + f"element vertex {len(points)}\n"
    header += "".join(f"property {types[kind]} {name}\n" for name, kind in fields) + "end_header\n"
    path.write_bytes(header.encode("ascii") + table.tobytes())


if __name__ == "__main__":
    points, colors = bunny_points()
    write_ply(HERE / "bunny_scan.ply", points, colors)
    spec = importlib.util.spec_from_file_location("make_splats", ROOT / "tests" / "data" / "splats" / "make_splats.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.torus_splats().save(HERE / "torus_splats.ply")
    assert (HERE / "torus_splats.ply").read_bytes() == (ROOT / "tests/data/splats/torus.ply").read_bytes()
