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

from typing import Any

import numpy as np

__all__ = ["LIGHT_DIRECTIONAL", "LIGHT_POINT", "LIGHT_SPOT", "MODE_CONSTANT", "MODE_TEXTURED", "MODE_VERTEX", "shade"]

LIGHT_DIRECTIONAL, LIGHT_POINT, LIGHT_SPOT = 0, 1, 2
MODE_CONSTANT, MODE_TEXTURED, MODE_VERTEX = 0, 1, 2
"""Where an item's base colour comes from: its factor alone, the factor times the texture frustum drew (its sRGB
bytes), or the factor with the vertex colours frustum drew multiplying the lit colour."""


def shade(frame: Any, camera: Any, items: np.ndarray, lights: list[tuple], ambient: Any,
          lit: bool) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """(color (H, W, 4) uint8, metric depth (H, W) float32) of a frame frustum drew unlit (``shading="none"``).

    Colour: where `lit`, pyrender's model of the module docstring at every covered pixel, else the frame's own
    bytes. Depth: $−z_view$ from the window depth through clip_from_view's z rows, 0 where nothing was drawn
    (``camera_conventions.metric_depth``'s formula, in the same pass).

    Parameters
    ----------
    items : (I, 10) float64
        Per item of ``Scene.items``: base colour factor (3), metallic, roughness, emissive factor (3), mode
        (``MODE_*``), whether the primitive has normals (0 or 1).
    lights : list of (kind, E (3,), position (3,), direction (3,), scale s, offset o, shadow column)
        ``direction`` is where the light shines; the column indexes the frame's ``shadow`` buffer, −1 for none.
    """
    from frustum.raster.pyrender_shade import CAMERA_FIELDS, shade_pixels

    clip_from_view = camera.projection.matrix(camera.aspect)
    packed = np.zeros(CAMERA_FIELDS)
    packed[:16] = np.asarray(camera.world_from_window, dtype=np.float64).ravel()
    packed[16:19] = camera.frame.eye
    packed[19:22] = np.asarray(ambient, dtype=np.float64)[:3]
    packed[22:26] = clip_from_view[2, 2], clip_from_view[2, 3], clip_from_view[3, 2], clip_from_view[3, 3]
    packed[26] = 1.0 if lit else 0.0
    rows = np.zeros((max(len(lights), 0), 13))
    for index, (kind, energy, position, direction, scale, offset, column) in enumerate(lights):
        rows[index] = (kind, *energy, *position, *direction, scale, offset, column)
    color = np.array(frame.color)  # writable (the kernel writes the lit bytes into it)
    normals = frame.normals if frame.normals is not None else np.zeros((1, 1, 3), np.float32)
    ids = frame.object_id if frame.object_id is not None else np.zeros((1, 1), np.int32)
    visibility = frame.shadow if frame.shadow is not None else np.ones((1, 1, 1), np.float32)
    metric = np.empty(frame.depth.shape, dtype=np.float32)
    shade_pixels(frame.depth, color, normals, ids, np.ascontiguousarray(items, dtype=np.float64).reshape(-1, 10),
                 rows, np.ascontiguousarray(visibility), packed, metric)  # fmt: skip
    return color, metric
