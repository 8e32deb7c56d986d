"""Exact shadow polygons (``render_svg(..., shadows=True)``): the issue-50 scene of several items with a sphere of
1,280 or 5,120 faces, and the Stanford bunny (69k faces) on a plane, under a directional light; hidden lines of the
same scene beside them for scale.

    python benchmarks/bench_svg_shadows.py [--scenes sphere_1280 sphere_5120 bunny] [--repeat 3]

Each scene: the median wall time of ``--repeat`` runs of ``frustum.shadow_polygons`` and of the whole
``render_svg(scene, camera, shadows=True)``, the number of merged polygons and their total area (pixels²).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from pathlib import Path

import numpy as np

import frustum as fr
from frustum.geometry import box, plane
from frustum.transforms import rotate_x, translate

ROOT = Path(__file__).resolve().parents[1]
CAMERA = fr.Camera.look_at((4.0, 5.0, 7.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), width=320, height=240)
LIGHT = fr.DirectionalLight((0.3, -1.0, -0.2))


def items_scene(subdivisions: int) -> fr.Scene:
    """A ground plane, five thin slats, a box and an icosphere of 20·4^k faces (issue 50's scene)."""
    scene = fr.Scene(lights=[fr.AmbientLight(intensity=0.2), LIGHT])
    scene.add(plane((10, 10), divisions=(4, 4)), fr.Material(), transform=rotate_x(-math.pi / 2))
    for k in range(5):
        scene.add(box((0.2, 0.05, 3.0), center=(-1.0 + 0.5 * k, 2.0, 0.0)), fr.Material(color=(0.4, 0.4, 0.4)))
    scene.add(box((1, 1, 1), center=(1.5, 0.5, 1.5)), fr.Material(color=(0.9, 0.3, 0.2)))
    scene.add(fr.icosphere(0.6, subdivisions), fr.Material(color=(0.2, 0.5, 0.9)), transform=translate(-1.8, 0.6, 1.2))
    return scene


def bunny_scene() -> tuple[fr.Scene, fr.Camera]:
    """The Stanford bunny (69,451 faces) standing on a plane."""
    bunny = fr.load(ROOT / "tests" / "data" / "bunny" / "bun_zipper.ply")
    low, high = bunny.bounds
    scale = 2.0 / float((high - low).max())
    scene = fr.Scene(lights=[fr.AmbientLight(intensity=0.2), LIGHT])
    scene.add(plane((6, 6), divisions=(2, 2)), fr.Material(), transform=rotate_x(-math.pi / 2))
    centre = 0.5 * (low + high)
    place = translate(-centre[0] * scale, -low[1] * scale, -centre[2] * scale) @ np.diag([scale, scale, scale, 1.0])
    scene.add(bunny, fr.Material(color=(0.8, 0.7, 0.6)), transform=place)
    return scene, fr.Camera.look_at((3.0, 3.0, 5.0), (0.0, 0.8, 0.0), (0.0, 1.0, 0.0), width=480, height=360)


SCENES = {"sphere_1280": lambda: (items_scene(3), CAMERA), "sphere_5120": lambda: (items_scene(4), CAMERA),
          "bunny": bunny_scene}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    for name in args.scenes:
        scene, camera = SCENES[name]()
        faces = sum(item.mesh.face_count for item in scene.items)
        polygons, shadow_times, svg_times, line_times = [], [], [], []
        for _ in range(args.repeat):
            start = time.perf_counter()
            polygons = fr.shadow_polygons(scene, camera)
            shadow_times.append(time.perf_counter() - start)
            start = time.perf_counter()
            fr.render_svg(scene, camera, shadows=True)
            svg_times.append(time.perf_counter() - start)
            start = time.perf_counter()
            fr.render_svg(scene, camera)
            line_times.append(time.perf_counter() - start)
        area = sum(p.area for p in polygons)
        print(f"{name} ({faces} faces): shadow_polygons {statistics.median(shadow_times):.2f} s, "
              f"render_svg(shadows=True) {statistics.median(svg_times):.2f} s, "
              f"render_svg without shadows {statistics.median(line_times):.2f} s "
              f"(medians of {args.repeat}); {len(polygons)} polygons, {area:.1f} px²", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
