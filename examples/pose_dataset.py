"""A synthetic 6-DoF pose dataset: five objects of ``tests/data`` dropped on a plane, 100 views, written as BOP and
COCO (docs/how-to/pose-estimation-data.md).

    python examples/pose_dataset.py out/ [--views 100 --size 640x480 --seed 0 --executor process]

writes ``out/bop/`` (a BOP scenewise dataset: models/, train/000000/{rgb,depth,mask,mask_visib}, scene_camera.json,
scene_gt.json, scene_gt_info.json) and ``out/coco/`` (images/ and annotations.json). The same seed gives the same
bytes; rerunning the command resumes an interrupted run.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import frustum
from frustum.batch.randomize import cameras_on_shell, drop_on_plane, jitter_lights, jitter_materials
from frustum.geometry import Mesh, load, primitives
from frustum.geometry.teapot import teacup, teaspoon

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"
SIZE = 0.1
"""Largest extent of each object: 100 mm (scene units are metres)."""


def _sized(mesh: Mesh) -> Mesh:
    """The mesh centred on its bounding box and scaled to a largest extent of `SIZE`."""
    low, high = mesh.bounds
    scale = SIZE / float((high - low).max())
    centre = (low + high) / 2
    return mesh.transformed(frustum.scale(scale, scale, scale) @ frustum.translate(*-centre))


def objects() -> list[frustum.Node]:
    """The five objects, each with its label (its BOP obj_id and COCO category in this order)."""
    upright = frustum.rotate_x(-math.pi / 2)  # the teapot's OBJ is z up
    meshes = {
        "bunny": load(DATA / "bunny" / "bun_zipper_res3.ply"),
        "spot": load(DATA / "spot" / "spot_triangulated.obj"),
        "teapot": load(DATA / "teapot_n10.obj").transformed(upright),
        "teacup": teacup().tessellate(8),
        "teaspoon": teaspoon().tessellate(8).transformed(frustum.rotate_x(math.pi / 2)),  # lying on its back
    }
    colors = [(0.8, 0.75, 0.7), (0.9, 0.9, 0.85), (0.8, 0.3, 0.2), (0.3, 0.5, 0.8), (0.7, 0.7, 0.75)]
    return [frustum.Node(name, geometry=_sized(mesh), material=frustum.Material(color=color), label=name)
            for (name, mesh), color in zip(meshes.items(), colors, strict=True)]  # fmt: skip


def build(seed: int, views: int, width: int, height: int) -> tuple[frustum.Scene, list[frustum.Camera]]:
    """The scene (a grey floor, the objects dropped on it, jittered lights and colors) and the cameras, all drawn
    from one generator seeded with `seed`."""
    rng = np.random.default_rng(seed)
    lights = [frustum.AmbientLight(intensity=0.3), frustum.DirectionalLight((-0.4, -1.0, -0.5)),
              frustum.DirectionalLight((0.6, -0.5, 0.4), intensity=0.4)]  # fmt: skip
    scene = frustum.Scene(lights=jitter_lights(lights, rng))
    floor = primitives.plane((0.8, 0.8))
    scene.add(floor, frustum.Material(color=(0.45, 0.45, 0.45)), frustum.rotate_x(-math.pi / 2), name="floor")
    drop_on_plane(scene, objects(), rng, area=((-0.15, -0.15), (0.15, 0.15)))
    jitter_materials(scene, rng, color=0.05)
    cameras = cameras_on_shell(rng, views, (0.0, 0.03, 0.0), radius=(0.4, 0.6), elevation=(0.35, 1.2),
                               width=width, height=height)  # fmt: skip
    return scene, cameras


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--views", type=int, default=100)
    parser.add_argument("--size", default="640x480")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--executor", default="process")
    arguments = parser.parse_args()
    width, height = (int(v) for v in arguments.size.lower().split("x"))
    scene, cameras = build(arguments.seed, arguments.views, width, height)
    for format in ("bop", "coco"):
        result = frustum.render_dataset(scene, arguments.out / format, cameras=cameras, format=format,
                                        seed=arguments.seed, executor=arguments.executor)  # fmt: skip
        print(f"{format}: {len(result.rendered)} views rendered, {len(result.skipped)} skipped, "
              f"{len(result.failed)} failed -> {arguments.out / format}")  # fmt: skip


if __name__ == "__main__":
    main()
