"""Render the example scene to a PNG: a torus over a ground plate, lit by one directional light.

    python examples/render_example.py [OUT.png] [--width W] [--height H]

The geometry is built here with NumPy (a parametric torus and a grid), so the example needs no data files.
Each mesh is placed by its own modeling transform (``world_from_model``), the camera is the seed's uvw frame
with a perspective projection, and the renderer runs the whole pipeline: clip, cull, rasterize with a depth
buffer, Blinn-Phong.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import frustum as fr


def torus(ring_radius: float, tube_radius: float, rings: int, sides: int) -> fr.Mesh:
    """Parametric torus around the z axis, (R + r cos v) (cos u, sin u) + r sin v z, with analytic normals."""
    around = np.linspace(0, 2 * np.pi, rings, endpoint=False)
    u, v = np.meshgrid(around, np.linspace(0, 2 * np.pi, sides, endpoint=False))
    u, v = u.ravel(), v.ravel()
    normals = np.column_stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)])
    centers = ring_radius * np.column_stack([np.cos(u), np.sin(u), np.zeros_like(u)])
    i, j = np.meshgrid(np.arange(rings), np.arange(sides))
    a = j * rings + i
    b = j * rings + (i + 1) % rings
    c = ((j + 1) % sides) * rings + (i + 1) % rings
    d = ((j + 1) % sides) * rings + i
    a, b, c, d = a.ravel(), b.ravel(), c.ravel(), d.ravel()
    faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return fr.Mesh(centers + tube_radius * normals, faces, vertex_normals=normals)


def plate(size: float, cells: int) -> fr.Mesh:
    """A square grid in the xy plane, facing +z, split into 2·cells² triangles."""
    ticks = np.linspace(-size / 2, size / 2, cells + 1)
    x, y = np.meshgrid(ticks, ticks)
    vertices = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    i, j = np.meshgrid(np.arange(cells), np.arange(cells))
    a = (j * (cells + 1) + i).ravel()
    above = a + cells + 1
    faces = np.concatenate([np.column_stack([a, a + 1, above + 1]), np.column_stack([a, above + 1, above])])
    return fr.Mesh(vertices, faces)


def example_scene() -> fr.Scene:
    scene = fr.Scene(lights=[fr.DirectionalLight(direction=(-0.5, 0.8, -1.0))])
    scene.add(plate(8.0, 16), material=fr.Material(color=(0.55, 0.57, 0.6), specular=0.05))
    world_from_torus = fr.compose(fr.rotate_x(np.radians(60)), fr.rotate_z(np.radians(25)), fr.translate(0, 0, 1.4))
    scene.add(torus(1.2, 0.45, 96, 48), material=fr.Material(color=(0.85, 0.35, 0.2)), transform=world_from_torus)
    return scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="example.png")
    parser.add_argument("--width", type=int, default=960)
    parser.add_argument("--height", type=int, default=640)
    args = parser.parse_args()
    camera = fr.Camera.look_at(
        eye=(5.5, -6.5, 4.5), target=(0, 0, 1.0), up=(0, 0, 1),
        projection=fr.Perspective(fovy=np.radians(38), near=0.5, far=50), width=args.width, height=args.height,
    )  # fmt: skip
    start = time.perf_counter()
    frame = fr.render(example_scene(), camera, background=(0.10, 0.11, 0.13, 1.0))
    seconds = time.perf_counter() - start
    frame.save(args.out)
    print(f"wrote {args.out} ({args.width}x{args.height}) in {seconds:.2f} s (includes compile or cache load)")


if __name__ == "__main__":
    main()
