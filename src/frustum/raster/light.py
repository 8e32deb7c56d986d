"""The light model's one Numba function: the light of one light at one point, which every shading kernel inlines.

For light k (a row of ``frustum.shading.pack_lights``: kind 0 directional, 1 point, 2 spot; I_l; position;
direction; attenuation a0, a1, a2; cos θ_inner, cos θ_outer) at point P with unit normal N and unit vector V
toward the eye:

- L: toward the light (the row's direction for a directional light, $(P_l − P)/|P_l − P|$ otherwise);
- $f = v / (a_0 + a_1·d + a_2·d²)$ for point and spot lights at distance d (v for a directional light), where v
  is the visibility of the light at P (1 unshadowed; the shadow pass's fraction otherwise), times the spot cone
  factor $clamp((cos α − cos θ_outer)/(cos θ_inner − cos θ_outer), 0, 1)$ (a hard cone where the two are equal);
- Lambert $max(N·L, 0)$ and the specular term: Phong $(R·V)^n$ with $R = 2(N·L)N − L$, or Blinn $(N·H)^n$ with
  $H = (L + V)/|L + V|$, the power by ``raster.power.textbook_power``.

``light_terms`` returns $(f·(N·L), f·spec)$ and whether the light adds anything (N·L > 0 and f ≠ 0); a kernel
adds $k_d·(f·(N·L))·I_l$ and $k_s·(f·spec)·I_l$. ``frustum.shading.light`` is the same model in NumPy for the ray
tracer, radiosity and ``shading.illuminate``; ``tests/test_light_model.py`` renders one lit scene by the depth
buffer, ray casting and ray tracing and holds their colours equal.

References: [HB 17] "Light Sources", "Basic Illumination Models" (radial attenuation, spotlights, Phong model).
"""

from __future__ import annotations

import math

import numpy as np

from frustum.raster._jit import kernel
from frustum.raster.power import textbook_power

__all__ = ["SPECULAR_BLINN", "SPECULAR_PHONG", "light_terms", "power"]

SPECULAR_BLINN, SPECULAR_PHONG = 0, 1

power = kernel(textbook_power)
"""``textbook_power`` compiled, for the shading kernels (``shading.illuminate`` calls the plain function: the
same operations, so the same bytes)."""


@kernel
def light_terms(
    lights: np.ndarray, k: int, specular_model: int, shininess: float, visible: float,
    px: float, py: float, pz: float, nx: float, ny: float, nz: float, vx: float, vy: float, vz: float,
) -> tuple[bool, float, float]:  # fmt: skip
    """(lit, f·(N·L), f·spec) of light k at P (unit normal N, unit V toward the eye): the module docstring's."""
    kind = lights[k, 0]
    falloff = visible
    if kind == 0.0:
        lx, ly, lz = lights[k, 7], lights[k, 8], lights[k, 9]
    else:
        lx, ly, lz = lights[k, 4] - px, lights[k, 5] - py, lights[k, 6] - pz
        distance = math.sqrt((lx * lx + ly * ly) + lz * lz)
        lx, ly, lz = lx / distance, ly / distance, lz / distance
        falloff /= (lights[k, 10] + lights[k, 11] * distance) + lights[k, 12] * distance * distance
        if kind == 2.0:
            cos_alpha = -((lx * lights[k, 7] + ly * lights[k, 8]) + lz * lights[k, 9])
            cos_inner, cos_outer = lights[k, 13], lights[k, 14]
            if cos_inner > cos_outer:
                falloff *= min(max((cos_alpha - cos_outer) / (cos_inner - cos_outer), 0.0), 1.0)
            elif cos_alpha < cos_outer:
                falloff = 0.0
    ndl = (nx * lx + ny * ly) + nz * lz
    if ndl <= 0.0 or falloff == 0.0:
        return False, 0.0, 0.0
    if specular_model == SPECULAR_PHONG:
        rx, ry, rz = 2.0 * ndl * nx - lx, 2.0 * ndl * ny - ly, 2.0 * ndl * nz - lz
        spec = power(max((rx * vx + ry * vy) + rz * vz, 0.0), shininess)
    else:
        hx, hy, hz = lx + vx, ly + vy, lz + vz
        length = math.sqrt((hx * hx + hy * hy) + hz * hz)
        if length > 0.0:
            hx, hy, hz = hx / length, hy / length, hz / length
        spec = power(max((nx * hx + ny * hy) + nz * hz, 0.0), shininess)
    return True, falloff * ndl, falloff * spec
