"""Per-kernel time of one frame of a standard scene: where the renderer spends it.

    python benchmarks/profile_stages.py bunny_like_100k_4k [--frames 5] [--scene-dir /tmp/frustum-bench/scenes]

Each kernel the pipeline calls (vertex projection, setup and binning of the faces, clipping, tile rasterization,
shading) is wrapped with a timer; one line per frame prints the milliseconds per kernel and the whole frame.
Timing wrappers add a little Python overhead, so use it to compare stages, and `bench_render.py` for frame times.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import time
from pathlib import Path

import numpy as np

import frustum
from frustum.raster import shade, tiled, tiles, triangles

SHARED_BENCH = Path(__file__).resolve().parents[2] / "shared" / "bench"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--frames", type=int, default=5)
    parser.add_argument("--scene-dir", default="/tmp/frustum-bench/scenes")
    args = parser.parse_args()
    sys.path.insert(0, str(SHARED_BENCH))
    import scenes  # the shared benchmark's scene loader

    sc = scenes.load_scene(str(Path(args.scene_dir) / f"{args.scene}.npz"))
    mesh = frustum.Mesh(sc["vertices"], sc["faces"], vertex_normals=sc["normals"])
    projection = frustum.Perspective(np.radians(float(sc["fovy_deg"])), float(sc["near"]), float(sc["far"]))
    camera = frustum.Camera.look_at(sc["eye"], sc["target"], sc["up"], projection=projection,
                                    width=int(sc["width"]), height=int(sc["height"]))  # fmt: skip
    material = frustum.Material(color=tuple(float(c) for c in sc["base_color"]), ambient=float(sc["ambient"]),
                                diffuse=float(sc["diffuse"]), specular=float(sc["specular"]),
                                shininess=float(sc["shininess"]))  # fmt: skip
    scene = frustum.Scene(lights=[frustum.DirectionalLight(direction=-np.asarray(sc["light_dir"]))])
    scene.add(mesh, material)
    background = tuple(float(c) for c in sc["background"])

    timings: dict[str, float] = {}
    stages = importlib.import_module("frustum.render.stages")  # the per-item stages (vertex, binning)
    surfaces = importlib.import_module("frustum.render.surfaces")  # the surface pass (clears the buffers)

    def timed(module, name: str) -> None:
        function = getattr(module, name)

        def wrapper(*arguments):
            start = time.perf_counter()
            result = function(*arguments)
            timings[name] = timings.get(name, 0.0) + (time.perf_counter() - start) * 1e3
            return result

        setattr(module, name, wrapper)

    for name in ("project_vertices", "world_points", "transform_normals", "tile_offsets"):
        timed(stages, name)
    timed(surfaces, "clear_buffers")
    for name in ("count_tiles", "add_record_tiles", "fill_tiles"):
        timed(tiles, name)
    for name in ("clip_faces", "rasterize_tiles"):
        timed(triangles, name)
    for name in ("shade_pixels", "shade_pixels_directional"):
        timed(shade, name)
    timed(tiled, "draw_tiles_directional")  # one opaque mesh: clear, fill and shade per tile
    frustum.render(scene, camera, background=background)  # compile or load the kernels
    rows: list[dict[str, float]] = []
    for _ in range(args.frames):
        timings.clear()
        start = time.perf_counter()
        frustum.render(scene, camera, background=background)
        total = (time.perf_counter() - start) * 1e3
        print("  ".join(f"{k} {v:.1f}" for k, v in timings.items()) + f"  | frame {total:.1f} ms")
        rows.append({**timings, "frame": total})
    print("min   " + "  ".join(f"{k} {min(r.get(k, 0.0) for r in rows):.1f}" for k in rows[0]))


if __name__ == "__main__":
    main()
