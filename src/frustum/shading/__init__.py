"""Lights, materials, depth cueing, and the illumination model the renderer evaluates.

For a surface point P with unit normal N, seen from the eye E, with base color C (material color × vertex
color × texture), the intensity of each channel is [HB 17]:

$$I = C·(k_a·I_a + Σ_l f_l·k_d·I_l·max(N·L_l, 0)) + Σ_l f_l·k_s·I_l·spec_l + emissive$$

with

- $L_l$ the unit vector from P toward light l ($−direction$ for a directional light);
- $V = (E − P)/|E − P|$, toward the viewer;
- $spec_l$ for Blinn-Phong $max(N·H, 0)^n$ with $H = (L + V)/|L + V|$, for Phong $max(R·V, 0)^n$ with
  $R = 2(N·L)N − L$; 0 where $N·L <= 0$ (no highlight on the unlit side);
- $I_a$ the ambient illumination: the sum of the scene's ``AmbientLight``s, or white of intensity 1 if it has
  none (so ``k_a`` alone sets the "background illumination", as in the benchmark formula);
- $I_l$ the light's color × intensity;
- $f_l$ the radial attenuation $1/(a_0 + a_1·d + a_2·d²)$ of point and spot lights (1 for directional lights),
  times the spot cone factor $clamp((cos α − cos θ_outer)/(cos θ_inner − cos θ_outer), 0, 1)$.

Colors are linear RGB in [0, 1]; the result is clamped to [0, 1] and stored as $floor(I·255 + 0.5)$.
With one white directional light of intensity 1 and no ambient light this is exactly the formula of
``../shared/bench/README.md``, bit for bit. ``shading.light.illuminate`` is the readable one-point version; the
kernels are in ``raster/shade.py``.

Depth cueing [HB 10] "Depth Cueing" blends each color toward a cue color by its distance d from the viewing
plane: $f(d) = f_min + (f_max − f_min)·(d_far − d)/(d_far − d_near)$ clamped to [f_min, f_max], then
$color' = f·color + (1 − f)·cue_color$.

References
----------
[HB 17] "Basic Illumination Models" (ambient, diffuse, specular, the halfway vector, multiple light sources),
"Light Sources" (radial intensity attenuation, directional light sources and spotlight effects).
[HB 10] "Depth Cueing"; [seed] "we set the lighting conditions by specifying the colour and location of the
light sources", depth cueing "by choosing a maximum and a minimum intensity value and a range of distances".

The package: the lights, materials and depth cueing (``model``), the light of one light at many points in NumPy
(``light``; the kernels' twin is ``raster.light``), environment maps (``environment``), bump and normal maps
(``surface_detail``), and the glTF metallic–roughness model (``pbr``, ``ibl``, ``tone``). ``frustum.shading``
re-exports the classical model's names, as the single module of that name did (``docs/architecture.md``).
"""

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
