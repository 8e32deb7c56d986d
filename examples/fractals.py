"""Render fractal scenes to PNG: a fractal landscape with a coastline, a 3D L-system tree, a quaternion Julia set,
a Menger sponge, a Sierpinski tetrahedron, and a Mandelbrot image.

    python examples/fractals.py [OUT_DIR] [--width W] [--height H]

Each mesh comes from ``frustum.geometry`` (fractals, lsystem, escape_time) and is drawn by ``frustum.render`` with
one directional light and Blinn-Phong shading. The landscape is a diamond-square fBm heightfield (H = 0.8) with a
water plane at sea level, so the coastline is where the mountains meet it, plus a midpoint-displaced fractal
outline of an islet drawn as a thin tube. Depth cueing is not used here (it is being added to the renderer).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from PIL import Image

import frustum as fr
from frustum.geometry.escape_time import escape_time_colors, mandelbrot, quaternion_julia_mesh
from frustum.geometry.fractals import (
    fbm_terrain,
    fractal_coastline,
    heightfield_mesh,
    menger_sponge,
    sierpinski_tetrahedron,
)
from frustum.geometry.lsystem import CLASSIC_LSYSTEMS, TurtlePath, tube_mesh


def camera(eye, target, width: int, height: int, fovy_degrees: float = 40.0, far: float = 100.0) -> fr.Camera:
    return fr.Camera.look_at(
        eye=eye, target=target, up=(0, 0, 1),
        projection=fr.Perspective(fovy=np.radians(fovy_degrees), near=0.05, far=far), width=width, height=height,
    )  # fmt: skip


def landscape() -> fr.Scene:
    heights = fbm_terrain(8, 0.8, seed=7, sigma=0.35)
    heights -= np.median(heights)  # about half the land under water
    terrain = heightfield_mesh(heights, size=4.0)
    water = heightfield_mesh(np.zeros((2, 2)), size=4.0)
    angle = np.linspace(0.0, 2 * np.pi, 9)
    row, column = np.unravel_index(np.argmin(heights), heights.shape)  # an islet's outline in the deepest water
    x, y = 4.0 * column / (heights.shape[1] - 1), 4.0 * row / (heights.shape[0] - 1)
    outline = np.column_stack([x + 0.3 * np.cos(angle), y + 0.2 * np.sin(angle), np.full(9, 0.01)])
    outline[-1] = outline[0]
    coast = fractal_coastline(outline, 6, seed=3, hurst=0.6, amplitude=0.25)
    shore = tube_mesh(TurtlePath(np.stack([coast[:-1], coast[1:]], axis=1), np.zeros(len(coast) - 1, np.int64)),
                      radius=0.012, sides=4)  # fmt: skip
    scene = fr.Scene(lights=[fr.DirectionalLight(direction=(-0.6, 0.4, -0.7))])
    scene.add(terrain, material=fr.Material(color=(0.45, 0.5, 0.3), specular=0.02))
    scene.add(water, material=fr.Material(color=(0.15, 0.3, 0.55), specular=0.4))
    scene.add(shore, material=fr.Material(color=(0.9, 0.85, 0.6)))
    return scene


def tree() -> tuple[fr.Scene, float]:
    """The 3D L-system bush on a ground plate, and its height."""
    path = CLASSIC_LSYSTEMS["tree_3d"].path(6, heading=(0, 0, 1), left=(0, 1, 0))
    scene = fr.Scene(lights=[fr.DirectionalLight(direction=(-0.5, 0.7, -0.8))])
    wood = tube_mesh(path, radius=0.25, taper=0.6, sides=6)
    scene.add(wood, material=fr.Material(color=(0.45, 0.3, 0.15)))
    scene.add(heightfield_mesh(np.zeros((2, 2)), size=20.0), material=fr.Material(color=(0.3, 0.5, 0.25)),
              transform=fr.translate(-10, -10, 0))  # fmt: skip
    return scene, float(wood.bounds[1, 2])


def single(mesh: fr.Mesh, color, transform=None) -> fr.Scene:
    scene = fr.Scene(lights=[fr.DirectionalLight(direction=(-0.5, 0.8, -1.0))])
    scene.add(mesh, material=fr.Material(color=color), transform=transform)
    return scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="fractals_out")
    parser.add_argument("--width", type=int, default=800)
    parser.add_argument("--height", type=int, default=600)
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    w, h = args.width, args.height
    background = (0.75, 0.82, 0.9, 1.0)

    tree_scene, top = tree()
    jobs = {
        "landscape.png": (landscape(), camera((-1.0, -1.6, 1.6), (2.2, 2.2, 0.0), w, h)),
        "tree.png": (tree_scene, camera((top * 1.3, -top * 1.3, top * 0.7), (0, 0, top * 0.45), w, h)),
        "quaternion_julia.png": (
            single(
                quaternion_julia_mesh((-0.291, -0.399, 0.339, 0.437), resolution=96, max_iter=10), (0.8, 0.45, 0.25)
            ),
            camera((2.4, -2.6, 1.8), (0, 0, 0), w, h),
        ),
        "menger_sponge.png": (
            single(menger_sponge(3, shared_vertices=False), (0.7, 0.7, 0.75), fr.translate(-0.5, -0.5, -0.5)),
            camera((1.5, -1.9, 1.3), (0, 0, 0), w, h),
        ),
        "sierpinski_tetrahedron.png": (
            single(sierpinski_tetrahedron(5), (0.3, 0.6, 0.8), fr.translate(-0.5, -0.3, -0.3)),
            camera((1.2, -1.6, 1.0), (0, 0, 0), w, h),
        ),
    }
    # the landscape fades into the haze with distance (the seed's depth cueing); the others render plain
    haze = {"landscape.png": fr.DepthCue(near=1.5, far=6.0, min_intensity=0.25)}
    for name, (scene, cam) in jobs.items():
        start = time.perf_counter()
        fr.render(scene, cam, background=background, depth_cue=haze.get(name)).save(out / name)
        print(f"wrote {out / name} in {time.perf_counter() - start:.2f} s")
    start = time.perf_counter()
    image = mandelbrot((-2.2, 0.8, -1.125, 1.125), w, h, max_iter=500)
    Image.fromarray(escape_time_colors(image, period=40.0)).save(out / "mandelbrot.png")
    print(f"wrote {out / 'mandelbrot.png'} in {time.perf_counter() - start:.2f} s")


if __name__ == "__main__":
    main()
