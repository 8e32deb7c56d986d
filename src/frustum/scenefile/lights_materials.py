"""``[materials]``, material references, ``[[lights]]`` (and a node's lights) and ``[environment]``."""

from __future__ import annotations

from typing import Any

import numpy as np

from frustum.errors import FrustumError, SceneFileError
from frustum.scenefile.checks import _call, _choice, _input_file, _table, _table_list, _unknown_keys
from frustum.scenefile.report import _BAD, _Report
from frustum.shading import AmbientLight, DirectionalLight, Material, PointLight, SpotLight
from frustum.shading.environment import ENVIRONMENT_KINDS, EnvironmentMap

IMAGE_KEYS = ("texture", "bump", "normal_map", "base_color_texture", "metallic_roughness_texture", "occlusion_texture",
              "emissive_texture")
"""Material keys that name an image file (relative to the scene file's folder): PNG, JPEG, anything Pillow reads."""

_LIGHT_TYPES = {"ambient": AmbientLight, "directional": DirectionalLight, "point": PointLight, "spot": SpotLight}


def _material(report: _Report, path: tuple, value: Any) -> Any:
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    for key in IMAGE_KEYS:
        if key in params:
            image = _image(report, (*path, key), params[key])
            if image is _BAD:
                return _BAD
            params[key] = image
    return _call(report, path, Material, params, label="Material")


def _image(report: _Report, path: tuple, value: Any) -> Any:
    """The image file `value` names (relative to the scene file's folder) as an (H, W, 3|4) uint8 array."""

    file = _input_file(report, path, value, what="a PNG or JPEG image")
    if file is _BAD:
        return _BAD
    from frustum._images import decode, open_image

    try:
        with open_image(file, where="image", name=repr(value), error=SceneFileError) as image:
            return np.asarray(decode(image).convert("RGBA" if "A" in image.mode else "RGB"), dtype=np.uint8)
    except SceneFileError as error:  # over the memory budget, said before decoding
        report.add(path, value, "is an image over the memory budget", str(error).split("needs ", 1)[-1])
        return _BAD
    except Exception as error:  # Pillow raises many types for unreadable or hostile files
        report.add(path, value, f"could not be read as an image ({type(error).__name__})",
                   "give a PNG or JPEG image")  # fmt: skip
        return _BAD


def _environment(report: _Report, path: tuple, value: Any) -> Any:
    """``[environment]``: ``image`` (an equirect PNG/JPEG/.hdr, or six cube faces side by side), ``kind``,
    ``intensity``."""
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    _unknown_keys(report, path, params, ("image", "kind", "intensity"))
    if "image" not in params:
        report.missing((*path, "image"), "give the image file of the surroundings (equirect 2:1, or .hdr)")
        return _BAD
    kind = _choice(report, (*path, "kind"), params.get("kind", "equirect"), ENVIRONMENT_KINDS)
    image = params["image"]
    file = _input_file(report, (*path, "image"), image, what="an image of the surroundings")
    if file is _BAD:
        return _BAD
    if kind is _BAD:
        return _BAD
    try:
        return EnvironmentMap.load(file, kind=kind, intensity=params.get("intensity", 1.0))
    except FrustumError as error:
        report.refused(path, params, error)
        return _BAD


def _material_reference(report: _Report, path: tuple, value: Any, materials: dict) -> Any:
    if isinstance(value, str):
        if value not in materials:
            names = ", ".join(repr(name) for name in sorted(materials)) or "none defined"
            report.add(path, value, "names no material", f"define it under [materials.{value}]; known: {names}")
            return _BAD
        return materials[value]
    return _material(report, path, value)


def _light(report: _Report, path: tuple, value: Any) -> Any:
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    if "type" not in params:
        report.missing((*path, "type"), f"give type, one of {', '.join(_LIGHT_TYPES)}")
        return _BAD
    kind = _choice(report, (*path, "type"), params.pop("type"), tuple(_LIGHT_TYPES))
    if kind is _BAD:
        return _BAD
    return _call(report, path, _LIGHT_TYPES[kind], params, label=f"{kind} light")


def _lights(report: _Report, path: tuple, value: Any) -> list:
    return [light for i, item in enumerate(_table_list(report, path, value))
            if (light := _light(report, (*path, i), item)) is not _BAD]  # fmt: skip
