"""Light and material types, and the Blinn-Phong illumination model the renderer evaluates per pixel.

For a surface point P with unit normal N, seen from the eye E and lit by a directional light:

    L     = −direction / |direction|          (toward the light; ``direction`` is where the light travels)
    V     = (E − P) / |E − P|                  (toward the viewer)
    H     = (L + V) / |L + V|                  (the halfway vector)
    ndl   = max(N·L, 0)
    spec  = ndl > 0 ? max(N·H, 0)^shininess : 0
    rgb   = clamp(color · (ambient + diffuse · ndl) + specular · spec, 0, 1)
    pixel = round(rgb · 255)                   (linear RGB, no sRGB encoding; round half up)

This is the formula of ``../shared/bench/README.md`` (white light of intensity 1); the light's ``color`` and
``intensity`` fields exist for the shading issue and must be white and 1 here. The arithmetic itself runs in
``raster/shade.py``; ``blinn_phong`` below is the readable one-point version of the same formula.

References
----------
[HB 17] "Basic Illumination Models": ambient, diffuse (Lambert) and specular (Phong, halfway vector H).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from frustum._arrays import Vector3, as_direction, as_scalar, as_vector3, describe, read_only
from frustum.errors import ShadingError

__all__ = ["DirectionalLight", "Material", "blinn_phong"]


def _unit_color(value: ArrayLike, name: str, where: str) -> Vector3:
    color = as_vector3(value, name, where=where, error=ShadingError)
    if (color < 0.0).any() or (color > 1.0).any():
        raise ShadingError(f"{where}: {name} = {describe(color)} is outside [0, 1]; give linear RGB in [0, 1]")
    return read_only(color)


def _nonnegative(value: Any, name: str, where: str) -> float:
    number = as_scalar(value, name, where=where, error=ShadingError)
    if number < 0.0:
        raise ShadingError(f"{where}: {name} = {number!r} is negative; expected a finite number >= 0")
    return number


@dataclass(frozen=True, eq=False)
class Material:
    """Blinn-Phong surface: base ``color`` (linear RGB in [0, 1]) and the coefficients of the formula above.

    Raises ``ShadingError`` for a non-finite or negative coefficient or a color outside [0, 1].
    """

    color: Vector3 = (0.8, 0.8, 0.8)  # type: ignore[assignment]
    ambient: float = 0.12
    diffuse: float = 0.85
    specular: float = 0.35
    shininess: float = 32.0

    def __post_init__(self) -> None:
        where = "Material"
        object.__setattr__(self, "color", _unit_color(self.color, "color", where))
        for name in ("ambient", "diffuse", "specular", "shininess"):
            object.__setattr__(self, name, _nonnegative(getattr(self, name), name, where))


@dataclass(frozen=True, eq=False)
class DirectionalLight:
    """A light at infinity whose rays travel along ``direction`` (glTF convention); ``to_light = −direction``.

    ``color`` (linear RGB in [0, 1]) and ``intensity`` (>= 0) are white and 1 by default; ``render`` in this
    version supports only that white light of intensity 1 (the benchmark formula).
    """

    direction: Vector3
    color: Vector3 = (1.0, 1.0, 1.0)  # type: ignore[assignment]
    intensity: float = 1.0

    def __post_init__(self) -> None:
        where = "DirectionalLight"
        object.__setattr__(
            self, "direction", read_only(as_direction(self.direction, "direction", where=where, error=ShadingError))
        )
        object.__setattr__(self, "color", _unit_color(self.color, "color", where))
        object.__setattr__(self, "intensity", _nonnegative(self.intensity, "intensity", where))

    @property
    def to_light(self) -> Vector3:
        """L, the unit vector from a surface toward the light: ``−direction``."""
        return -self.direction


def blinn_phong(
    material: Material, light: DirectionalLight, normal: ArrayLike, point: ArrayLike, eye: ArrayLike
) -> tuple[int, int, int]:
    """8-bit RGB of one surface point by the formula of this module's docstring (readable, slow, float64).

    `normal` need not be unit length; it is normalized first.
    """
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.sqrt(n @ n)
    to_light = light.to_light
    view = np.asarray(eye, dtype=np.float64) - np.asarray(point, dtype=np.float64)
    view = view / np.sqrt(view @ view)
    half = to_light + view
    half = half / np.sqrt(half @ half)
    ndl = max(float(n @ to_light), 0.0)
    spec = max(float(n @ half), 0.0) ** material.shininess if ndl > 0.0 else 0.0
    rgb = np.clip(material.color * (material.ambient + material.diffuse * ndl) + material.specular * spec, 0, 1)
    r, g, b = np.floor(rgb * 255.0 + 0.5).astype(int).tolist()
    return r, g, b
