"""The glTF 2.0 metallic–roughness model: the BRDF of the specification's Appendix B, its light units, and the
mapping of a classical (Phong) material onto it. NumPy, vectorised over points; the kernels in ``raster/pbr.py``
evaluate the same terms in the same order.

For a surface point with unit normal n, unit direction to the viewer v, unit direction to the light l and the
half vector h = (l + v)/|l + v|, the material's base colour ``base``, ``metallic`` and ``roughness`` (α =
roughness²) give [glTF 2.0, Appendix B "BRDF Implementation"]

$$f(l, v) = mix(f_dielectric, f_metal, metallic)$$
$$f_dielectric = mix(base/π, V·D, F(0.04)),  f_metal = V·D·F(base)$$

with D the Trowbridge–Reitz (GGX) distribution, V the height-correlated Smith visibility (G/(4|n·l||n·v|) folded
in) and F(f0) = f0 + (1 − f0)(1 − |v·h|)⁵ the Schlick Fresnel term; $mix(a, b, t) = (1 − t)·a + t·b$.

Lights (KHR_lights_punctual units) add, per light, $f(l, v)·E·(n·l)$ to the outgoing linear radiance, where E is
the illuminance at the point: a directional light's ``intensity`` in lux (lm/m²); a point or spot light's in
candela divided by d² (inverse-square falloff), windowed by ``range`` as $clamp(1 − (d/range)⁴, 0, 1)²$ when a
range is given, and for a spot light times $t²$, $t = clamp((cos α − cos θ_outer)/(cos θ_inner − cos θ_outer),
0, 1)$. The classical ``attenuation`` coefficients are not used by this model. An ``AmbientLight`` is light of
uniform radiance $I_a$ from every direction (a constant environment): it adds what image-based lighting adds
for a constant map (``frustum.shading.ibl``).

A classical material (``Material(model="phong")``) shaded by this model uses base = ``color``, metallic =
``Material.metallic`` (0 unless given) and the roughness whose GGX lobe matches the Blinn-Phong exponent n,
$α² = 2/(n + 2)$ (Walter et al. 2007), i.e. $roughness = (2/(n + 2))^{1/4}$ (n = 32 → 0.49).

References
----------
glTF 2.0 Specification, Appendix B "BRDF Implementation" (Khronos, 2021); KHR_lights_punctual; B. Walter,
S. Marschner, H. Li, K. Torrance, "Microfacet Models for Refraction through Rough Surfaces", EGSR 2007;
E. Heitz, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 3(2), 2014;
C. Schlick, "An Inexpensive BRDF Model for Physically-based Rendering", 1994.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "DIELECTRIC_F0",
    "brdf",
    "conductor_fresnel",
    "diffuse_lambert",
    "distribution_ggx",
    "fresnel_mix",
    "fresnel_schlick",
    "phong_roughness",
    "range_window",
    "spot_cone",
    "visibility_smith_ggx",
]

DIELECTRIC_F0 = 0.04
"""Reflectance at normal incidence of every dielectric in the glTF model (an index of refraction of 1.5)."""


def distribution_ggx(n_dot_h: ArrayLike, alpha: ArrayLike) -> NDArray[np.float64]:
    """Trowbridge–Reitz (GGX) normal distribution: $D = α²·χ⁺(n·h) / (π·((n·h)²(α² − 1) + 1)²)$."""
    nh = np.asarray(n_dot_h, dtype=np.float64)
    a2 = np.asarray(alpha, dtype=np.float64) ** 2
    denominator = nh * nh * (a2 - 1.0) + 1.0
    lobe = (nh > 0.0) & (a2 > 0.0)  # α = 0: a mirror's delta lobe, which no single direction hits
    return np.where(lobe, a2 / (math.pi * np.where(lobe, denominator * denominator, 1.0)), 0.0)


def visibility_smith_ggx(n_dot_l: ArrayLike, n_dot_v: ArrayLike, alpha: ArrayLike) -> NDArray[np.float64]:
    """Height-correlated Smith visibility: $V = 0.5 / (|n·l|·√((n·v)²(1 − α²) + α²) + |n·v|·√((n·l)²(1 − α²) + α²))$."""
    nl = np.abs(np.asarray(n_dot_l, dtype=np.float64))
    nv = np.abs(np.asarray(n_dot_v, dtype=np.float64))
    a2 = np.asarray(alpha, dtype=np.float64) ** 2
    total = nl * np.sqrt(nv * nv * (1.0 - a2) + a2) + nv * np.sqrt(nl * nl * (1.0 - a2) + a2)
    return np.where(total > 0.0, 0.5 / np.where(total > 0.0, total, 1.0), 0.0)


def fresnel_schlick(f0: ArrayLike, v_dot_h: ArrayLike) -> NDArray[np.float64]:
    """Schlick's Fresnel approximation: $F = f0 + (1 − f0)·(1 − |v·h|)⁵$."""
    f0 = np.asarray(f0, dtype=np.float64)
    weight = (1.0 - np.abs(np.asarray(v_dot_h, dtype=np.float64))) ** 5
    return f0 + (1.0 - f0) * weight


def diffuse_lambert(base: ArrayLike) -> NDArray[np.float64]:
    """Lambertian diffuse: $f_diffuse = base / π$."""
    return np.asarray(base, dtype=np.float64) / math.pi


def fresnel_mix(base_layer: ArrayLike, layer: ArrayLike, v_dot_h: ArrayLike) -> NDArray[np.float64]:
    """A dielectric coat over a base: $mix(base_layer, layer, F) = (1 − F)·base_layer + F·layer$, F = F(0.04)."""
    f = fresnel_schlick(DIELECTRIC_F0, v_dot_h)
    return (1.0 - f) * np.asarray(base_layer, dtype=np.float64) + f * np.asarray(layer, dtype=np.float64)


def conductor_fresnel(base: ArrayLike, specular: ArrayLike, v_dot_h: ArrayLike) -> NDArray[np.float64]:
    """A metal tinted by its colour: $specular·(base + (1 − base)·(1 − |v·h|)⁵)$ (Schlick with f0 = base)."""
    return np.asarray(specular, dtype=np.float64) * fresnel_schlick(base, v_dot_h)


def brdf(
    normal: ArrayLike, to_light: ArrayLike, to_viewer: ArrayLike, base: ArrayLike, metallic: ArrayLike,
    roughness: ArrayLike,
) -> NDArray[np.float64]:  # fmt: skip
    """(N, 3) BRDF f(l, v) of the module docstring for unit n, l, v (N, 3), base (N, 3) or (3,), metallic and
    roughness (N,) or scalars; 0 where n·l <= 0 (light from below the surface)."""
    n = np.atleast_2d(np.asarray(normal, dtype=np.float64))
    l = np.atleast_2d(np.asarray(to_light, dtype=np.float64))  # noqa: E741
    v = np.atleast_2d(np.asarray(to_viewer, dtype=np.float64))
    base = np.asarray(base, dtype=np.float64)
    metallic = np.asarray(metallic, dtype=np.float64)[..., None]
    alpha = np.asarray(roughness, dtype=np.float64) ** 2
    h = l + v
    h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    nl = (n * l).sum(axis=-1)
    nv = (n * v).sum(axis=-1)
    nh = (n * h).sum(axis=-1)
    vh = (v * h).sum(axis=-1)[..., None]
    specular = (visibility_smith_ggx(nl, nv, alpha) * distribution_ggx(nh, alpha))[..., None]
    dielectric = fresnel_mix(diffuse_lambert(base), specular, vh)
    metal = conductor_fresnel(base, specular, vh)
    f = (1.0 - metallic) * dielectric + metallic * metal
    return np.where((nl > 0.0)[..., None], f, 0.0)


def range_window(distance: ArrayLike, light_range: float) -> NDArray[np.float64]:
    """KHR_lights_punctual's smooth cut-off: $clamp(1 − (d/range)⁴, 0, 1)²$ (1 everywhere when range is 0: none)."""
    d = np.asarray(distance, dtype=np.float64)
    if light_range <= 0.0:
        return np.ones_like(d)
    return np.clip(1.0 - (d / light_range) ** 4, 0.0, 1.0) ** 2


def spot_cone(cos_alpha: ArrayLike, cos_inner: float, cos_outer: float) -> NDArray[np.float64]:
    """KHR_lights_punctual's spot cone: $t²$, $t = clamp((cos α − cos θ_outer)/(cos θ_inner − cos θ_outer), 0, 1)$."""
    c = np.asarray(cos_alpha, dtype=np.float64)
    scale = 1.0 / max(1e-3, cos_inner - cos_outer)
    t = np.clip((c - cos_outer) * scale, 0.0, 1.0)
    return t * t


def phong_roughness(shininess: float) -> float:
    """The roughness of a Blinn-Phong exponent n: $α² = 2/(n + 2)$, $roughness = √α = (2/(n + 2))^{1/4}$."""
    return (2.0 / (float(shininess) + 2.0)) ** 0.25
