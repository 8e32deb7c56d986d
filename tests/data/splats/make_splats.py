"""Write ``torus.ply``: a small 3DGS file of 512 analytic Gaussians (run from the repository root:
``python tests/data/splats/make_splats.py``; the bytes are the same on every run).

The Gaussians sit on a torus (major radius 1, minor radius 0.35, axis z): 32 rings of 16, each elongated along
the torus's circle through it (scales 0.12 × 0.05 × 0.05, rotated by the quaternion of the angle about z),
opacity 0.8, base colour a hue wheel around the ring (f_dc = (colour − 0.5)/0.28209479) and a degree-1
spherical-harmonic term that brightens red toward +x viewers (f_rest of red: 0, 0, 0.3 for the y, z, x basis
functions; green and blue 0). Written with ``frustum.GaussianSplats.save`` in the standard layout (log-scales,
logit opacity, channel-major f_rest).
"""

from __future__ import annotations

import colorsys
import math
from pathlib import Path

import numpy as np

from frustum import GaussianSplats
from frustum.geometry.splats import SH_C0

RINGS, AROUND = 32, 16


def torus_splats() -> GaussianSplats:
    positions, rotations, colors = [], [], []
    for i in range(RINGS):
        phi = 2 * math.pi * i / RINGS
        for j in range(AROUND):
            theta = 2 * math.pi * j / AROUND
            radial = 1.0 + 0.35 * math.cos(theta)
            positions.append((radial * math.cos(phi), radial * math.sin(phi), 0.35 * math.sin(theta)))
            # the Gaussian's x axis along the ring's tangent (the direction of growing phi): a turn of phi + 90°
            half = (phi + math.pi / 2) / 2
            rotations.append((math.cos(half), 0.0, 0.0, math.sin(half)))
            colors.append(colorsys.hsv_to_rgb(i / RINGS, 0.7, 0.9))
    count = len(positions)
    sh = np.zeros((count, 4, 3), dtype=np.float32)
    sh[:, 0, :] = (np.array(colors) - 0.5) / SH_C0
    sh[:, 3, 0] = 0.3  # red, the x basis function (coefficient 3 of degree 1)
    return GaussianSplats(np.array(positions), np.tile([0.12, 0.05, 0.05], (count, 1)), np.array(rotations),
                          np.full(count, 0.8), sh)  # fmt: skip


if __name__ == "__main__":
    torus_splats().save(Path(__file__).with_name("torus.ply"))
