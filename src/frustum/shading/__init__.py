"""Shading: the classical illumination model with its lights and materials (``model``), environment maps
(``environment``) and surface detail — bump and normal maps (``surface_detail``).

``frustum.shading`` re-exports the classical model's names, as the single module of that name did before it became
a package; the formulas live in the submodules (``docs/architecture.md``)."""

from frustum.shading.light import blinn_phong, illuminate
from frustum.shading.model import (
    LIGHT_FIELDS,
    LIGHT_TYPES,
    SPECULAR_MODELS,
    AmbientLight,
    DepthCue,
    DirectionalLight,
    Light,
    Material,
    PointLight,
    SpotLight,
    pack_lights,
    sun_45,
)

__all__ = [
    "LIGHT_FIELDS",
    "LIGHT_TYPES",
    "SPECULAR_MODELS",
    "AmbientLight",
    "DepthCue",
    "DirectionalLight",
    "Light",
    "Material",
    "PointLight",
    "SpotLight",
    "blinn_phong",
    "illuminate",
    "pack_lights",
    "sun_45",
]
