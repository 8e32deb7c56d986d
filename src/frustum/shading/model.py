"""Lights, materials and depth cueing: the types of the classical illumination model, whose formulas the package
docstring (``frustum.shading``) states once."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Matrix4, Vector3, as_direction, as_scalar, as_vector3, describe, read_only
from frustum.errors import ShadingError
from frustum.shading.tone import srgb_to_linear
from frustum.transforms import apply, apply_to_directions

__all__ = [
    "SPECULAR_MODELS",
    "AmbientLight",
    "DepthCue",
    "DirectionalLight",
    "Light",
    "Material",
    "PointLight",
    "SpotLight",
    "pack_lights",
]

SPECULAR_MODELS = ("blinn-phong", "phong")
"""Specular terms ``illuminate`` and ``render`` accept: Blinn-Phong (N·H)^n (default) or Phong (R·V)^n."""

MATERIAL_MODELS = ("phong", "pbr")
"""``Material(model=)``: the classical illumination model or glTF's metallic–roughness model."""

LIGHT_FIELDS = 16
"""Row length of ``pack_lights``: kind, I_l (3), position (3), to-light or axis direction (3), attenuation (3),
cos θ_inner, cos θ_outer, range."""
LIGHT_DIRECTIONAL, LIGHT_POINT, LIGHT_SPOT = 0, 1, 2


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


def _attenuation(value: ArrayLike, where: str) -> Vector3:
    coefficients = as_vector3(value, "attenuation", where=where, error=ShadingError)
    if (coefficients < 0.0).any() or coefficients.sum() <= 0.0:
        raise ShadingError(
            f"{where}: attenuation = {describe(coefficients)} is not (constant, linear, quadratic) >= 0 with a "
            "positive sum; e.g. (1, 0, 0) for no falloff or (1, 0.09, 0.032)"
        )
    return read_only(coefficients)


def _check_cast_shadows(value: Any, where: str) -> None:
    """``cast_shadows`` (whether surfaces shadow this light where a method draws shadows) must be a bool."""
    if not isinstance(value, bool | np.bool_):
        raise ShadingError(f"{where}: cast_shadows = {describe(value)} is not a bool; give True or False")


def _check_range(light: Any, where: str) -> None:
    """A point or spot light's ``range``: None or a finite distance > 0."""
    if light.range is None:
        return
    reach = as_scalar(light.range, "range", where=where, error=ShadingError)
    if not reach > 0.0:
        raise ShadingError(f"{where}: range = {reach!r} is not a distance > 0; give one, or None for no limit")
    object.__setattr__(light, "range", reach)


def _texture(value: Any, where: str) -> NDArray[np.float32] | None:
    if value is None:
        return None
    array = np.asarray(value)
    if array.ndim == 2:
        array = np.repeat(array[:, :, None], 3, axis=2)
    if array.ndim != 3 or array.shape[2] not in (3, 4) or array.shape[0] < 1 or array.shape[1] < 1:
        raise ShadingError(
            f"{where}: texture has shape {array.shape}; expected an (H, W), (H, W, 3) or (H, W, 4) image"
        )
    if array.dtype == np.uint8:
        texels = array.astype(np.float32) / np.float32(255.0)
    elif np.issubdtype(array.dtype, np.floating):
        texels = array.astype(np.float32)
        if not np.isfinite(texels).all() or (texels < 0).any() or (texels > 1).any():
            raise ShadingError(f"{where}: texture has values outside [0, 1] or non-finite; give floats in [0, 1]")
    else:
        raise ShadingError(f"{where}: texture has dtype {array.dtype}; expected uint8 or floats in [0, 1]")
    if texels.shape[2] == 3:
        texels = np.concatenate([texels, np.ones((*texels.shape[:2], 1), dtype=np.float32)], axis=2)
    return read_only(np.ascontiguousarray(texels))


@dataclass(frozen=True, eq=False)
class Material:
    """Surface reflectance: base ``color`` (linear RGB in [0, 1]) and the coefficients of the formula above.

    ``emissive`` (linear RGB added after lighting), ``opacity`` in [0, 1] (below 1 the surface is blended
    over what lies behind it, drawn back to front after the opaque surfaces: the "ghosted" parts of a cutaway),
    ``texture`` an (H, W[, 3|4]) image sampled bilinearly at the mesh's UV coordinates (v up: v = 0 is the
    image's bottom row; uint8 bytes are taken as linear values / 255), multiplied into the base color.
    ``emission`` (>= 0, default 1) scales ``emissive`` for ``radiosity``: an emitter's radiance is
    $emissive · emission$, which may exceed 1 (the local illumination model adds ``emissive`` alone).
    ``reflectivity`` in [0, 1]: the share of the color that is the mirror reflection of the surroundings (the
    scene's environment map in the depth-buffer pipeline: $(1 − r)·I + r·env(R)$).
    ``bump`` an (H, W[, 3|4]) height image (gray, in [0, 1], times ``bump_scale`` world units) and ``normal_map``
    an (H, W, 3|4) tangent-space normal image (OpenGL convention, +y up): both perturb the shading normal per pixel
    in Phong shading, from the mesh's UVs (``frustum.shading.surface_detail``; flat and Gouraud shading ignore them).
    ``model`` the illumination model the material is written for: ``"phong"`` (the classical coefficients above)
    or ``"pbr"``, glTF's metallic–roughness model (``frustum.shading.pbr``): ``color`` is the base colour,
    ``metallic`` and ``roughness`` in [0, 1] its factors, ``metallic_roughness_texture`` an image whose B channel
    scales metallic and G roughness, ``occlusion_texture`` one whose R channel r darkens image-based and ambient
    light by $1 + occlusion_strength·(r − 1)$; ``base_color_texture`` an sRGB-encoded image (as glTF stores it),
    decoded to linear values into ``texture`` (give one of the two); ``emissive_texture`` an sRGB-encoded image
    (glTF's ``emissiveTexture``) sampled at the same UVs, decoded, times ``emissive``: the emission the model adds
    to the linear radiance (the classical shading modes leave it unused). ``render(shading="phong")`` shades a
    ``"pbr"`` material per pixel by that model, ``shading="pbr"`` every material (a ``"phong"`` one with
    ``shading.pbr.phong_roughness(shininess)``); docs/materials.md.
    ``hatch`` (vector output only): the spacing of 45° section lines drawn over the faces in filled SVG/PDF,
    in drawing units, as engineering drawings mark cut surfaces (``cutaway`` sets it on section caps).
    With ``render(..., method="ray-tracing")`` ``reflectivity`` is the weight of the traced mirror-reflected ray
    (the same $(1 − r)·I + r·reflected$), and ``ior`` (index of refraction, > 0; 1 bends nothing, glass 1.5;
    read by that method only) bends the ray transmitted through a surface of opacity < 1 (Snell's law;
    docs/ray-tracing.md).
    Raises ``ShadingError`` for a non-finite or negative coefficient, a color outside [0, 1] or a bad texture.
    """

    color: Vector3 = (0.8, 0.8, 0.8)  # type: ignore[assignment]
    ambient: float = 0.12
    diffuse: float = 0.85
    specular: float = 0.35
    shininess: float = 32.0
    emissive: Vector3 = (0.0, 0.0, 0.0)  # type: ignore[assignment]
    opacity: float = 1.0
    texture: NDArray[np.float32] | None = None
    hatch: float | None = None
    emission: float = 1.0
    reflectivity: float = 0.0
    bump: NDArray[np.float32] | None = None
    bump_scale: float = 1.0
    normal_map: NDArray[np.float32] | None = None
    ior: float = 1.0
    metallic: float = 0.0
    roughness: float = 0.5
    model: str = "phong"
    base_color_texture: NDArray[np.float32] | None = None
    metallic_roughness_texture: NDArray[np.float32] | None = None
    occlusion_texture: NDArray[np.float32] | None = None
    occlusion_strength: float = 1.0
    emissive_texture: NDArray[np.float32] | None = None

    def __post_init__(self) -> None:
        where = "Material"
        ior = as_scalar(self.ior, "ior", where=where, error=ShadingError)
        if not (math.isfinite(ior) and ior > 0.0):
            raise ShadingError(f"{where}: ior = {ior!r} is not a finite index of refraction > 0 (glass: 1.5)")
        object.__setattr__(self, "ior", ior)
        if self.hatch is not None:
            spacing = as_scalar(self.hatch, "hatch", where=where, error=ShadingError)
            if not spacing > 0.0:
                raise ShadingError(f"{where}: hatch = {spacing!r} is not a positive spacing; give a number > 0 or None")
            object.__setattr__(self, "hatch", spacing)
        object.__setattr__(self, "color", _unit_color(self.color, "color", where))
        object.__setattr__(self, "emissive", _unit_color(self.emissive, "emissive", where))
        for name in ("ambient", "diffuse", "specular", "shininess"):
            object.__setattr__(self, name, _nonnegative(getattr(self, name), name, where))
        opacity = _nonnegative(self.opacity, "opacity", where)
        if opacity > 1.0:
            raise ShadingError(f"{where}: opacity = {opacity!r} is above 1; expected 0 <= opacity <= 1")
        object.__setattr__(self, "opacity", opacity)
        object.__setattr__(self, "texture", _texture(self.texture, where))
        object.__setattr__(self, "emission", _nonnegative(self.emission, "emission", where))
        reflectivity = _nonnegative(self.reflectivity, "reflectivity", where)
        if reflectivity > 1.0:
            raise ShadingError(f"{where}: reflectivity = {reflectivity!r} is above 1; expected 0 <= reflectivity <= 1")
        object.__setattr__(self, "reflectivity", reflectivity)
        object.__setattr__(self, "bump", _texture(self.bump, f"{where} bump"))
        bump_scale = as_scalar(self.bump_scale, "bump_scale", where=where, error=ShadingError)
        object.__setattr__(self, "bump_scale", bump_scale)
        object.__setattr__(self, "normal_map", _texture(self.normal_map, f"{where} normal_map"))
        self._check_physical(where)

    def _check_physical(self, where: str) -> None:
        """The metallic–roughness fields: factors in [0, 1], a known model, the glTF textures (the base colour
        one decoded from sRGB into ``texture``)."""
        if self.model not in MATERIAL_MODELS:
            raise ShadingError(f"{where}: model = {describe(self.model)} is unknown; expected one of {MATERIAL_MODELS}")
        for name in ("metallic", "roughness", "occlusion_strength"):
            value = _nonnegative(getattr(self, name), name, where)
            if value > 1.0:
                raise ShadingError(f"{where}: {name} = {value!r} is above 1; expected a number in [0, 1]")
            object.__setattr__(self, name, value)
        if self.base_color_texture is not None:
            if self.texture is not None:
                raise ShadingError(
                    f"{where}: both texture and base_color_texture are given; give one (texture: linear values, "
                    "base_color_texture: an sRGB-encoded image as glTF stores it)"
                )
            encoded = np.asarray(self.base_color_texture)
            texels = _texture(encoded, f"{where} base_color_texture")
            linear = np.array(texels)
            if encoded.dtype == np.uint8:  # 8-bit values (a PNG's, a JPEG's): the curve at the 256 of them, looked up
                channels = np.repeat(encoded[:, :, None], 3, axis=2) if encoded.ndim == 2 else encoded[..., :3]
                linear[..., :3] = srgb_to_linear(np.arange(256, dtype=np.float32) / np.float32(255.0))[channels]
            else:
                linear[..., :3] = srgb_to_linear(linear[..., :3])
            object.__setattr__(self, "texture", read_only(linear))
            object.__setattr__(self, "base_color_texture", None)
        for name in ("metallic_roughness_texture", "occlusion_texture", "emissive_texture"):
            object.__setattr__(self, name, _texture(getattr(self, name), f"{where} {name}"))

    def with_(self, **changes: Any) -> Material:
        """A copy with some fields changed, e.g. ``material.with_(opacity=0.3)``."""
        return replace(self, **changes)

    def __repr__(self) -> str:
        """Short: images appear as their shapes (``<1024x1024x3 image>``), not their pixels; absent glTF maps not
        at all."""
        shown = []
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if value is None and name.endswith("_texture"):  # the metallic–roughness maps, when there are none
                continue
            if isinstance(value, np.ndarray) and value.ndim >= 2:
                shown.append(f"{name}=<{'x'.join(map(str, value.shape))} image>")
            elif isinstance(value, np.ndarray):
                shown.append(f"{name}=({', '.join(f'{float(v):g}' for v in value)})")
            else:
                shown.append(f"{name}={value!r}")
        return f"Material({', '.join(shown)})"


@dataclass(frozen=True, eq=False)
class AmbientLight:
    """Background illumination $I_a = color · intensity$ reaching every surface equally (the k_a term)."""

    color: Vector3 = (1.0, 1.0, 1.0)  # type: ignore[assignment]
    intensity: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "color", _unit_color(self.color, "color", "AmbientLight"))
        object.__setattr__(self, "intensity", _nonnegative(self.intensity, "intensity", "AmbientLight"))

    def transformed(self, world_from_model: Matrix4) -> AmbientLight:
        """Ambient light has no position or direction: itself."""
        return self


@dataclass(frozen=True, eq=False)
class DirectionalLight:
    """A light at infinity whose rays travel along ``direction`` (glTF convention); $to_light = −direction$."""

    direction: Vector3
    color: Vector3 = (1.0, 1.0, 1.0)  # type: ignore[assignment]
    intensity: float = 1.0
    cast_shadows: bool = True

    def __post_init__(self) -> None:
        where = "DirectionalLight"
        _check_cast_shadows(self.cast_shadows, where)
        object.__setattr__(
            self, "direction", read_only(as_direction(self.direction, "direction", where=where, error=ShadingError))
        )
        object.__setattr__(self, "color", _unit_color(self.color, "color", where))
        object.__setattr__(self, "intensity", _nonnegative(self.intensity, "intensity", where))

    @property
    def to_light(self) -> Vector3:
        """L, the unit vector from a surface toward the light: $−direction$."""
        return -self.direction

    def transformed(self, world_from_model: Matrix4) -> DirectionalLight:
        """The light riding a node: its direction mapped by the node's world transform."""
        direction = apply_to_directions(world_from_model, self.direction[None, :])[0]
        return replace(self, direction=direction)


@dataclass(frozen=True, eq=False)
class PointLight:
    """A light at ``position`` shining equally in all directions, dimmed by $1/(a0 + a1·d + a2·d²)$.

    With the metallic–roughness model (``frustum.shading.pbr``) ``intensity`` is in candela, the falloff is the
    inverse square $1/d²$ and ``range`` (None: unlimited; else > 0) fades it to zero as KHR_lights_punctual does.
    """

    position: Vector3
    color: Vector3 = (1.0, 1.0, 1.0)  # type: ignore[assignment]
    intensity: float = 1.0
    attenuation: Vector3 = (1.0, 0.0, 0.0)  # type: ignore[assignment]
    cast_shadows: bool = True
    range: float | None = None

    def __post_init__(self) -> None:
        where = type(self).__name__
        _check_cast_shadows(self.cast_shadows, where)
        object.__setattr__(
            self, "position", read_only(as_vector3(self.position, "position", where=where, error=ShadingError))
        )
        object.__setattr__(self, "color", _unit_color(self.color, "color", where))
        object.__setattr__(self, "intensity", _nonnegative(self.intensity, "intensity", where))
        object.__setattr__(self, "attenuation", _attenuation(self.attenuation, where))
        _check_range(self, where)

    def transformed(self, world_from_model: Matrix4) -> PointLight:
        """The light riding a node: its position mapped by the node's world transform."""
        return replace(self, position=apply(world_from_model, self.position[None, :])[0])


@dataclass(frozen=True, eq=False)
class SpotLight:
    """A point light limited to a cone around ``direction`` (where it shines), full inside ``inner_angle``
    and fading linearly in cos α to zero at ``outer_angle`` (half-angles in radians, 0 <= inner <= outer < π/2).

    With the metallic–roughness model: candela, $1/d²$, ``range`` as ``PointLight``'s, and the cone factor
    squared (KHR_lights_punctual's smooth cone).
    """

    position: Vector3
    direction: Vector3
    color: Vector3 = (1.0, 1.0, 1.0)  # type: ignore[assignment]
    intensity: float = 1.0
    inner_angle: float = math.radians(20.0)
    outer_angle: float = math.radians(30.0)
    attenuation: Vector3 = (1.0, 0.0, 0.0)  # type: ignore[assignment]
    cast_shadows: bool = True
    range: float | None = None

    def __post_init__(self) -> None:
        where = "SpotLight"
        _check_cast_shadows(self.cast_shadows, where)
        object.__setattr__(
            self, "position", read_only(as_vector3(self.position, "position", where=where, error=ShadingError))
        )
        object.__setattr__(
            self, "direction", read_only(as_direction(self.direction, "direction", where=where, error=ShadingError))
        )
        object.__setattr__(self, "color", _unit_color(self.color, "color", where))
        object.__setattr__(self, "intensity", _nonnegative(self.intensity, "intensity", where))
        object.__setattr__(self, "attenuation", _attenuation(self.attenuation, where))
        inner = as_scalar(self.inner_angle, "inner_angle", where=where, error=ShadingError)
        outer = as_scalar(self.outer_angle, "outer_angle", where=where, error=ShadingError)
        if not 0.0 <= inner <= outer < math.pi / 2:
            raise ShadingError(
                f"{where}: inner_angle, outer_angle = {inner!r}, {outer!r} radians; expected "
                "0 <= inner_angle <= outer_angle < pi/2"
            )
        object.__setattr__(self, "inner_angle", inner)
        object.__setattr__(self, "outer_angle", outer)
        _check_range(self, where)

    def transformed(self, world_from_model: Matrix4) -> SpotLight:
        """The light riding a node: position and direction mapped by the node's world transform."""
        position = apply(world_from_model, self.position[None, :])[0]
        direction = apply_to_directions(world_from_model, self.direction[None, :])[0]
        return replace(self, position=position, direction=direction)


def sun_45(intensity: float = 1.0, color: Any = (1.0, 1.0, 1.0), cast_shadows: bool = True) -> DirectionalLight:
    """The sciagraphy sun: rays along the diagonal of a cube from the upper left front, $direction ∝ (1, −1, −1)$
    (y up, the front elevation seen along −z), so in the front elevation and in the plan every ray and every
    shadow edge runs at 45°, and a shadow's width equals the depth of what casts it (architects' convention)."""
    return DirectionalLight((1.0, -1.0, -1.0), color=color, intensity=intensity, cast_shadows=cast_shadows)


Light = AmbientLight | DirectionalLight | PointLight | SpotLight
"""Any light a scene holds."""
LIGHT_TYPES = (AmbientLight, DirectionalLight, PointLight, SpotLight)


@dataclass(frozen=True, eq=False)
class DepthCue:
    """Depth cueing: $f(d) = f_min + (f_max − f_min)·(far − d)/(far − near)$, clamped; $c' = f·c + (1 − f)·cue$.

    ``d`` is the distance in front of the viewing plane (−z_view); ``color=None`` cues toward the render's
    background color. Raises ``ShadingError`` unless 0 <= near < far and 0 <= min <= max <= 1.
    """

    near: float
    far: float
    min_intensity: float = 0.0
    max_intensity: float = 1.0
    color: Vector3 | None = None

    def __post_init__(self) -> None:
        where = "DepthCue"
        near = _nonnegative(self.near, "near", where)
        far = as_scalar(self.far, "far", where=where, error=ShadingError)
        if not far > near:
            raise ShadingError(f"{where}: far = {far!r} is not beyond near = {near!r}; expected 0 <= near < far")
        low = _nonnegative(self.min_intensity, "min_intensity", where)
        high = _nonnegative(self.max_intensity, "max_intensity", where)
        if not low <= high <= 1.0:
            raise ShadingError(
                f"{where}: min_intensity, max_intensity = {low!r}, {high!r}; expected 0 <= min <= max <= 1"
            )
        object.__setattr__(self, "near", near)
        object.__setattr__(self, "far", far)
        object.__setattr__(self, "min_intensity", low)
        object.__setattr__(self, "max_intensity", high)
        if self.color is not None:
            object.__setattr__(self, "color", _unit_color(self.color, "color", where))

    def factor(self, distance: ArrayLike) -> NDArray[np.float64]:
        """f(d), the fraction of the surface's own color kept at view distance d."""
        d = np.asarray(distance, dtype=np.float64)
        f = self.min_intensity + (self.max_intensity - self.min_intensity) * (self.far - d) / (self.far - self.near)
        return np.clip(f, self.min_intensity, self.max_intensity)


def pack_lights(lights: list[Light]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Kernel form of world-space lights: the ambient I_a (3,) and an (K, 16) row per other light.

    Row: kind (0 directional, 1 point, 2 spot), I_l = color·intensity (3), position (3), direction (3:
    toward the light for a directional light, the cone axis (where it shines) for a spot), attenuation
    (a0, a1, a2), cos θ_inner, cos θ_outer, range (0: none; read by the metallic–roughness model only).
    """
    ambient_lights = [light for light in lights if isinstance(light, AmbientLight)]
    if ambient_lights:
        ambient = np.zeros(3)
        for light in ambient_lights:
            ambient = ambient + light.color * light.intensity
    else:
        ambient = np.ones(3)
    rows = []
    for light in lights:
        if isinstance(light, AmbientLight):
            continue
        row = np.zeros(LIGHT_FIELDS)
        row[1:4] = light.color * light.intensity
        if isinstance(light, DirectionalLight):
            row[0] = LIGHT_DIRECTIONAL
            row[7:10] = light.to_light
            row[10] = 1.0
        else:
            row[0] = LIGHT_POINT if isinstance(light, PointLight) else LIGHT_SPOT
            row[4:7] = light.position
            row[10:13] = light.attenuation
            row[15] = 0.0 if light.range is None else light.range
            if isinstance(light, SpotLight):
                row[7:10] = light.direction
                row[13] = math.cos(light.inner_angle)
                row[14] = math.cos(light.outer_angle)
        rows.append(row)
    return ambient, np.array(rows, dtype=np.float64).reshape(-1, LIGHT_FIELDS)


