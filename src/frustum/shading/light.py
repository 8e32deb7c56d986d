"""The light model in NumPy: the light of one light at many points, for the ray tracer, radiosity and ``illuminate``.

The same formulas, in the same order of operations, as ``raster.light.light_terms`` (the Numba function every
shading kernel inlines):

- ``toward_light``: L, the unit vector toward the light, and its falloff
  $f = spot(α) / (a_0 + a_1·d + a_2·d²)$ (1 for a directional light), with the spot cone factor
  $clamp((cos α − cos θ_outer)/(cos θ_inner − cos θ_outer), 0, 1)$ (a hard cone where the two are equal);
- Lambert $max(N·L, 0)$;
- ``specular_terms``: Phong $(R·V)^n$, $R = 2(N·L)N − L$, or Blinn $(N·H)^n$, $H = (L + V)/|L + V|$, the power
  by ``textbook_power`` (repeated squaring for integral n), where the light reaches the point.

``illuminate`` is the whole model at one point (slow, readable: the reference the kernels are tested against).
``light_terms`` puts them together with a visibility (the fraction of the light reaching each point: shadow rays,
shadow maps) as an argument: $(v·f·max(N·L, 0), v·f·spec)$.

References: [HB 17] "Light Sources", "Basic Illumination Models".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum.errors import ShadingError
from frustum.raster.power import SQUARING_MAX, textbook_power
from frustum.shading.model import (
    SPECULAR_MODELS,
    AmbientLight,
    DirectionalLight,
    Light,
    Material,
    SpotLight,
    pack_lights,
)

__all__ = ["blinn_phong", "illuminate", "light_terms", "power", "specular_terms", "toward_light"]


def toward_light(light: Any, points: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(L (N, 3), f (N,)): unit vectors from `points` (N, 3) toward a directional, point or spot `light`, and the
    light's falloff there (attenuation and spot cone; the module docstring)."""
    if isinstance(light, DirectionalLight):
        to_light = np.broadcast_to(-np.asarray(light.direction, dtype=np.float64), points.shape)
        return to_light, np.ones(points.shape[0])
    offset = np.asarray(light.position, dtype=np.float64) - points
    distance = np.sqrt(np.einsum("ij,ij->i", offset, offset))
    to_light = offset / np.maximum(distance, 1e-300)[:, None]
    a0, a1, a2 = light.attenuation
    falloff = 1.0 / (a0 + a1 * distance + a2 * distance * distance)
    if isinstance(light, SpotLight):
        cos_inner, cos_outer = math.cos(light.inner_angle), math.cos(light.outer_angle)
        cos_alpha = -(to_light @ np.asarray(light.direction, dtype=np.float64))
        if cos_inner > cos_outer:
            falloff = falloff * np.clip((cos_alpha - cos_outer) / (cos_inner - cos_outer), 0.0, 1.0)
        else:
            falloff = falloff * (cos_alpha >= cos_outer)
    return to_light, falloff


def specular_terms(
    to_light: NDArray[np.float64], cosine: NDArray[np.float64], normals: NDArray[np.float64],
    views: NDArray[np.float64], shininess: ArrayLike, phong: bool, lit: NDArray[np.bool_],
) -> NDArray[np.float64]:  # fmt: skip
    """(N,) the specular term at the points where `lit` (0 elsewhere): $(R·V)^n$ (`phong`) or $(N·H)^n$, with
    `cosine` = N·L and unit `views` toward the eye; `shininess` one exponent or one per point."""
    spec = np.zeros(normals.shape[0])
    if not lit.any():
        return spec
    exponents = np.broadcast_to(np.asarray(shininess, dtype=np.float64), spec.shape)[lit]
    if phong:
        reflected = 2.0 * cosine[lit, None] * normals[lit] - to_light[lit]
        x = np.maximum(np.einsum("ij,ij->i", reflected, views[lit]), 0.0)
    else:
        half = to_light[lit] + views[lit]
        half = half / np.sqrt(np.einsum("ij,ij->i", half, half))[:, None]
        x = np.maximum(np.einsum("ij,ij->i", normals[lit], half), 0.0)
    spec[lit] = [textbook_power(float(a), float(b)) for a, b in zip(x, exponents, strict=True)] \
        if x.shape[0] < 64 else power(x, exponents)  # fmt: skip
    return spec


def light_terms(
    light: Any, points: NDArray[np.float64], normals: NDArray[np.float64], views: NDArray[np.float64],
    shininess: ArrayLike, phong: bool, visible: NDArray[np.float64] | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:  # fmt: skip
    """(v·f·max(N·L, 0), v·f·spec), each (N,), of one light at `points` with unit `normals` and unit `views`
    toward the eye; `visible` (N,) the fraction of the light reaching each point (None: all of it)."""
    to_light, falloff = toward_light(light, points)
    if visible is not None:
        falloff = visible * falloff
    cosine = np.einsum("ij,ij->i", normals, to_light)
    lit = (cosine > 0.0) & (falloff != 0.0)
    spec = specular_terms(to_light, cosine, normals, views, shininess, phong, lit)
    return np.where(lit, falloff * np.maximum(cosine, 0.0), 0.0), falloff * spec


def power(x: NDArray[np.float64], n: NDArray[np.float64]) -> NDArray[np.float64]:
    """``textbook_power`` over arrays: repeated squaring for integral exponents in its range, else ``x**n``."""
    out = np.empty_like(x)
    integral = (n == np.floor(n)) & (n >= 0.0) & (n <= SQUARING_MAX)
    out[~integral] = x[~integral] ** n[~integral]
    for value in np.unique(n[integral]):
        chosen = integral & (n == value)
        base, result, e = x[chosen].copy(), np.ones(int(chosen.sum())), int(value)
        while e > 0:
            if e & 1:
                result = result * base
            base = base * base
            e >>= 1
        out[chosen] = result
    return out


def illuminate(
    material: Material,
    lights: list[Light],
    point: ArrayLike,
    normal: ArrayLike,
    eye: ArrayLike,
    *,
    base_color: ArrayLike | None = None,
    specular: str = "blinn-phong",
) -> NDArray[np.float64]:
    """Linear RGB (3,) in [0, 1] of one surface point by the formula of this module's docstring (slow, readable).

    `normal` need not be unit length. `base_color` replaces the material color (for vertex colors or a
    texture sample already multiplied in).
    """
    if specular not in SPECULAR_MODELS:
        raise ShadingError(f"illuminate: specular = {specular!r} is unknown; expected one of {SPECULAR_MODELS}")
    n = np.asarray(normal, dtype=np.float64)
    n = n / math.sqrt(float(n @ n))
    p = np.asarray(point, dtype=np.float64)
    view = np.asarray(eye, dtype=np.float64) - p
    view = view / math.sqrt(float(view @ view))
    color = material.color if base_color is None else np.asarray(base_color, dtype=np.float64)
    ambient, _ = pack_lights(lights)
    diffuse_sum = material.ambient * ambient
    specular_sum = np.zeros(3)
    for light in lights:
        if isinstance(light, AmbientLight):
            continue
        lambert, spec = light_terms(light, p[None], n[None], view[None], material.shininess, specular == "phong")
        intensity = light.color * light.intensity
        diffuse_sum = diffuse_sum + material.diffuse * float(lambert[0]) * intensity
        specular_sum = specular_sum + material.specular * float(spec[0]) * intensity
    return np.clip(color * diffuse_sum + specular_sum + material.emissive, 0.0, 1.0)


def blinn_phong(
    material: Material, light: DirectionalLight, normal: ArrayLike, point: ArrayLike, eye: ArrayLike
) -> tuple[int, int, int]:
    """8-bit RGB of one point lit by one directional light: $floor(illuminate(...)·255 + 0.5)$ (the bench formula)."""
    rgb = illuminate(material, [light], point, normal, eye)
    r, g, b = np.floor(rgb * 255.0 + 0.5).astype(int).tolist()
    return r, g, b
