"""Make the example images: an equirect sky (2:1, y up: sky gradient, a sun, a checkered ground) and a brick-wall
height map (mortar low, bricks high with bevelled edges). Deterministic; run from the repository root:

    python examples/images/make_images.py
"""

from pathlib import Path

import numpy as np
from PIL import Image

HERE = Path(__file__).parent


def sky(height: int = 256) -> np.ndarray:
    rows = (np.arange(height) + 0.5) / height * np.pi  # polar angle from +y
    cols = ((np.arange(2 * height) + 0.5) / (2 * height) - 0.5) * 2 * np.pi
    theta, phi = np.meshgrid(rows, cols, indexing="ij")
    d = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], axis=-1)
    up = d[..., 1]
    horizon = np.array([0.85, 0.9, 1.0])
    zenith = np.array([0.15, 0.35, 0.8])
    t = np.clip(up, 0, 1)[..., None] ** 0.6
    image = (1 - t) * horizon + t * zenith
    sun = np.array([0.5, 0.6, -0.62])
    sun /= np.linalg.norm(sun)
    image += 2.0 * np.clip((d @ sun - 0.995) / 0.005, 0, 1)[..., None]
    ground = up < 0
    hit = d[ground] / np.minimum(d[ground][:, 1:2], -1e-3) * -1.0  # the ground plane y = −1
    checks = ((np.floor(hit[:, 0]) + np.floor(hit[:, 2])) % 2)[:, None]
    fade = np.exp(-np.linalg.norm(hit[:, [0, 2]], axis=1) / 30.0)[:, None]
    image[ground] = fade * (0.25 + 0.45 * checks) * np.array([0.9, 0.85, 0.75]) + (1 - fade) * horizon * 0.7
    return np.clip(image, 0, 1)


def bricks(width: int = 256, height: int = 256, rows: int = 8, columns: int = 4) -> np.ndarray:
    y, x = np.mgrid[0:height, 0:width] + 0.5
    row = np.floor(y / (height / rows))
    shift = (row % 2) * 0.5 * (width / columns)
    u = ((x + shift) % (width / columns)) / (width / columns)  # 0..1 across a brick
    v = (y % (height / rows)) / (height / rows)
    edge = np.minimum(np.minimum(u, 1 - u) * (width / columns), np.minimum(v, 1 - v) * (height / rows))
    mortar = 2.0
    return np.clip((edge - mortar) / 4.0, 0.0, 1.0)  # 0 in the mortar, rising over 4 pixels to 1 on the brick


if __name__ == "__main__":
    Image.fromarray(np.round(sky() * 255).astype(np.uint8)).save(HERE / "sky.png", optimize=True)
    Image.fromarray(np.round(bricks() * 255).astype(np.uint8)).save(HERE / "bricks_height.png", optimize=True)
