"""The output transform of the physically based model: linear HDR radiance, times ``exposure``, through a tone map,
then the render's ``color_space`` (``"srgb"`` encodes) — the order of a glTF viewer.

Tone maps (``render(..., tone_map=...)``):

* ``"none"`` (the library's default): the radiance itself, clamped to [0, 1] when stored, as the classical
  model's results are; right for measuring, for comparing with other renderers, and for scenes lit within range.
* ``"aces"``: Narkowicz's fit of the ACES filmic curve,
  $T(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)$ per channel (highlights roll off, contrast rises).
* ``"khronos-neutral"``: the Khronos PBR Neutral operator (2024), which keeps base colours as authored up to
  0.76 and compresses above toward white (the glTF sample viewer's choice for product pictures;
  ``frustum render model.glb`` uses it).

``khronos_neutral`` per colour c: $x = min(c)$, offset $= x − 6.25x²$ if x < 0.08 else 0.04, $c −= offset$;
peak p = max(c); if p >= s (s = 0.76): with d = 0.24, $p' = 1 − d²/(p + d − s)$, $c ·= p'/p$, then
$g = 1 − 1/(0.15·(p − p') + 1)$ and $c = mix(c, (p', p', p'), g)$.

References
----------
K. Narkowicz, "ACES Filmic Tone Mapping Curve" (2016); Khronos Group, "PBR Neutral Specification" (2024);
glTF Sample Viewer (KhronosGroup/glTF-Sample-Viewer), tone mapping stage.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["TONE_MAPS", "aces_filmic", "khronos_neutral", "srgb_to_linear", "tone_map"]

TONE_MAPS = {"none": 0, "aces": 1, "khronos-neutral": 2}
"""``render(..., tone_map=)`` names and the kernel codes of ``raster/pbr.py``."""

NEUTRAL_START = 0.8 - 0.04
NEUTRAL_DESATURATION = 0.15


def aces_filmic(radiance: ArrayLike) -> NDArray[np.float64]:
    """Narkowicz's ACES fit per channel: $T(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)$, clamped to [0, 1]."""
    x = np.maximum(np.asarray(radiance, dtype=np.float64), 0.0)
    return np.clip((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)


def khronos_neutral(radiance: ArrayLike) -> NDArray[np.float64]:
    """Khronos PBR Neutral on (..., 3) colours (the module docstring's steps)."""
    color = np.maximum(np.asarray(radiance, dtype=np.float64), 0.0).copy()
    x = color.min(axis=-1, keepdims=True)
    offset = np.where(x < 0.08, x - 6.25 * x * x, 0.04)
    color -= offset
    peak = color.max(axis=-1, keepdims=True)
    d = 1.0 - NEUTRAL_START
    new_peak = 1.0 - d * d / (peak + d - NEUTRAL_START)
    compressed = color * (new_peak / np.where(peak > 0.0, peak, 1.0))
    g = 1.0 - 1.0 / (NEUTRAL_DESATURATION * (peak - new_peak) + 1.0)
    compressed = (1.0 - g) * compressed + g * new_peak
    return np.where(peak < NEUTRAL_START, color, compressed)


def tone_map(radiance: ArrayLike, name: str = "none", exposure: float = 1.0) -> NDArray[np.float64]:
    """(..., 3) display values in [0, 1] of linear radiance: exposure, then the tone map `name`, then clamped."""
    scaled = np.asarray(radiance, dtype=np.float64) * float(exposure)
    if name == "aces":
        return aces_filmic(scaled)
    if name == "khronos-neutral":
        return np.clip(khronos_neutral(scaled), 0.0, 1.0)
    return np.clip(scaled, 0.0, 1.0)


def srgb_to_linear(encoded: ArrayLike) -> NDArray[np.float32]:
    """The sRGB decoding curve: $c/12.92$ for c <= 0.04045, else $((c + 0.055)/1.055)^{2.4}$ (float32)."""
    c = np.asarray(encoded, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)
