"""pyrender's light model (its ``mesh.frag``, pyrender 0.1.45), evaluated per pixel on the buffers frustum drew.

pyrender shades every metallic–roughness material with a Cook–Torrance BRDF and gamma-encodes the sum. With
base colour C (``baseColorFactor`` × the sRGB-decoded ``baseColorTexture``), metallic m and roughness r clamped to
[0.04, 1], for a unit normal N, V toward the eye and L toward a light of colour × intensity E:

$$c = Σ_l vis_l·(N·L)·E_l·((1 − F)·c_diff/π + F·G·D/(4·(N·L)·(N·V) + 0.001)) + C·I_a + e²$$

with $c_diff = 0.96·(1 − m)·C$, $f0 = 0.04·(1 − m) + m·C$, Schlick $F = f0 + (1 − f0)·(1 − V·H)^5$,
Smith–Schlick $G = G_1(N·V)·G_1(N·L)$, $G_1(x) = x/(x·(1 − k) + k)$, $k = (r + 1)²/8$, GGX
$D = r⁴/(π·((N·H)²·(r⁴ − 1) + 1)²)$, N·L clamped to [0.001, 1], |N·V| to [0.001, 1]; $e$ the emissive factor
(pyrender multiplies it in twice); vertex colours multiply c afterwards; the pixel is $clamp(c^{1/2.2}, 0, 1)$.

Light units are pyrender's: a directional light's E is its colour × intensity (irradiance on a surface facing it),
a point light's is colour × intensity / d², a spot light's that times $clamp(cos α·s + o, 0, 1)²$ with
$s = 1/max(0.001, cos θ_inner − cos θ_outer)$, $o = −cos θ_outer·s$ (α the angle from the spot's axis); ``range``
is ignored, as pyrender ignores it. ``vis_l`` is frustum's shadow-map visibility where shadows are asked for.
A primitive without normals is shaded with N = V (pyrender's fallback).

References: pyrender ``shaders/mesh.frag`` and ``renderer.py`` (``_bind_lighting``); the glTF 2.0
metallic–roughness model; [HB 17] "Basic Illumination Models" for the terms' roles.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["LIGHT_DIRECTIONAL", "LIGHT_POINT", "LIGHT_SPOT", "shade"]

LIGHT_DIRECTIONAL, LIGHT_POINT, LIGHT_SPOT = 0, 1, 2
_MIN_ROUGHNESS = 0.04  # pyrender's min_roughness, also its dielectric f0


def _unit(vectors: NDArray[np.float64]) -> NDArray[np.float64]:
    length = np.sqrt(np.einsum("ij,ij->i", vectors, vectors))
    with np.errstate(invalid="ignore", divide="ignore"):
        return vectors / length[:, None]


def _dot(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.einsum("ij,ij->i", a, b)


def shade(
    base: NDArray[np.float64],
    multiplier: NDArray[np.float64],
    metallic: NDArray[np.float64],
    roughness: NDArray[np.float64],
    emissive: NDArray[np.float64],
    normal: NDArray[np.float64],
    point: NDArray[np.float64],
    eye: NDArray[np.float64],
    lights: list[tuple],
    ambient: NDArray[np.float64],
    visibility: NDArray[np.float64] | None,
) -> NDArray[np.float64]:
    """Gamma-encoded RGB in [0, 1] of K pixels by the model of this module's docstring.

    Parameters
    ----------
    base, multiplier, emissive : (K, 3) float64
        C, the vertex-colour multiplier (ones without vertex colours) and the emissive factor e.
    metallic, roughness : (K,) float64
    normal : (K, 3) float64
        Unit normals (rows of NaN where the primitive has none: N = V there).
    point : (K, 3) float64
        World points; `eye` (3,) the camera position.
    lights : list of (kind, E (3,), position (3,), direction (3,), scale s, offset o)
        ``direction`` is where the light shines (pyrender's −z of the light's pose).
    ambient : (3,) float64
        ``Scene.ambient_light``.
    visibility : (K, L) float64 or None
        The fraction of each light reaching each pixel (frustum's shadow maps), or None (all lit).
    """
    m = np.clip(metallic, 0.0, 1.0)[:, None]
    r = np.clip(roughness, _MIN_ROUGHNESS, 1.0)[:, None]
    c_diff = base * (1.0 - _MIN_ROUGHNESS) * (1.0 - m)
    f0 = _MIN_ROUGHNESS * (1.0 - m) + base * m
    view = _unit(eye[None, :] - point)
    n = np.where(np.isnan(normal[:, :1]), view, normal)
    nv = np.clip(np.abs(_dot(n, view)), 0.001, 1.0)[:, None]
    k = (r + 1.0) ** 2 / 8.0
    g_view = nv / (nv * (1.0 - k) + k)
    a2 = (r * r) ** 2
    color = np.zeros_like(base)
    for index, (kind, energy, position, direction, scale, offset) in enumerate(lights):
        if kind == LIGHT_DIRECTIONAL:
            to_light = np.broadcast_to(-np.asarray(direction), point.shape)
            radiance = np.broadcast_to(np.asarray(energy), point.shape)
        else:
            offset_to_light = np.asarray(position)[None, :] - point
            distance2 = _dot(offset_to_light, offset_to_light)[:, None]
            to_light = offset_to_light / np.sqrt(distance2)
            attenuation = 1.0 / distance2
            if kind == LIGHT_SPOT:
                cos_axis = np.clip(to_light @ -np.asarray(direction), 0.0, 1.0)[:, None]
                attenuation = attenuation * np.clip(cos_axis * scale + offset, 0.0, 1.0) ** 2
            radiance = attenuation * np.asarray(energy)[None, :]
        half = _unit(to_light + view)
        nl = np.clip(_dot(n, to_light), 0.001, 1.0)[:, None]
        nh = np.clip(_dot(n, half), 0.0, 1.0)[:, None]
        vh = np.clip(_dot(view, half), 0.0, 1.0)[:, None]
        fresnel = f0 + (1.0 - f0) * np.clip(1.0 - vh, 0.0, 1.0) ** 5
        geometry = g_view * (nl / (nl * (1.0 - k) + k))
        denominator = nh * nh * (a2 - 1.0) + 1.0
        distribution = a2 / (math.pi * denominator * denominator)
        diffuse = (1.0 - fresnel) * c_diff / math.pi
        specular = fresnel * geometry * distribution / (4.0 * nl * nv + 0.001)
        contribution = nl * radiance * (diffuse + specular)
        if visibility is not None:
            contribution = contribution * visibility[:, index : index + 1]
        color += contribution
    color += base * np.asarray(ambient)[None, :]
    color += emissive * emissive  # pyrender: emissive = emissive_factor; color += emissive * emissive_factor
    color *= multiplier
    with np.errstate(invalid="ignore"):
        return np.clip(np.power(np.maximum(color, 0.0), 1.0 / 2.2), 0.0, 1.0)
