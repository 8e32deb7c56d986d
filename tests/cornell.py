"""The Cornell box for the radiosity tests and benchmark: a unit box open toward the camera (+z), walls facing in,
a square ceiling emitter just below the ceiling, red left wall, green right wall, white floor, ceiling and back."""

from __future__ import annotations

import numpy as np

import frustum as fr

WALLS = ("floor", "ceiling", "back", "left", "right", "light")
RED, GREEN, WHITE = (0.63, 0.065, 0.05), (0.14, 0.45, 0.091), (0.725, 0.71, 0.68)
EMISSION = 8.0  # radiance of the ceiling light (emissive (1, 1, 1) × emission)


def quad(corner, edge_u, edge_v) -> fr.Mesh:
    """A rectangle corner, corner + u, corner + u + v, corner + v; its front (normal u × v) counter-clockwise."""
    c, u, v = (np.asarray(x, dtype=np.float64) for x in (corner, edge_u, edge_v))
    return fr.Mesh(np.array([c, c + u, c + u + v, c + v]), np.array([[0, 1, 2], [0, 2, 3]]))


def cornell_box() -> fr.Scene:
    """The box [0, 1]³ without its front wall (z = 1), each wall one node named as in ``WALLS``."""
    scene = fr.Scene()
    white = fr.Material(color=WHITE, diffuse=1.0)
    parts = {
        "floor": (quad((0, 0, 0), (0, 0, 1), (1, 0, 0)), white),  # normal +y
        "ceiling": (quad((0, 1, 0), (1, 0, 0), (0, 0, 1)), white),  # normal −y
        "back": (quad((0, 0, 0), (1, 0, 0), (0, 1, 0)), white),  # normal +z
        "left": (quad((0, 0, 0), (0, 1, 0), (0, 0, 1)), fr.Material(color=RED, diffuse=1.0)),  # normal +x
        "right": (quad((1, 0, 0), (0, 0, 1), (0, 1, 0)), fr.Material(color=GREEN, diffuse=1.0)),  # normal −x
        "light": (quad((0.35, 0.999, 0.35), (0.3, 0, 0), (0, 0, 0.3)),
                  fr.Material(color=(0.0, 0.0, 0.0), diffuse=0.0, emissive=(1.0, 1.0, 1.0), emission=EMISSION)),
    }  # fmt: skip
    for name, (mesh, material) in parts.items():
        scene.add(mesh, material, name=name)
    return scene


def camera(size: int = 64) -> fr.Camera:
    projection = fr.Perspective(np.radians(39.0), 0.1, 10.0)
    return fr.Camera.look_at((0.5, 0.5, 2.4), (0.5, 0.5, 0.0), (0, 1, 0), projection, size, size)
