"""The mechanical part the drawing-sheet tests draw: a plate with a post, a block and a ball (each test module adds
its own further parts)."""

from __future__ import annotations

import math

from frustum import Scene, rotate_x, translate
from frustum.geometry import box, cylinder, uv_sphere


def plate() -> Scene:
    """A 80 × 6 × 50 plate, a vertical post (cylinder r = 8), a block on the plate and a ball on the block."""
    scene = Scene()
    scene.add(box((80.0, 6.0, 50.0)))
    scene.add(cylinder(8.0, 30.0, 48), transform=translate(-20.0, 18.0, 5.0) @ rotate_x(-math.pi / 2))
    scene.add(box((20.0, 12.0, 14.0)), transform=translate(22.0, 9.0, -10.0))
    scene.add(uv_sphere(5.0, 32, 16), transform=translate(22.0, 20.0, -10.0))
    return scene
