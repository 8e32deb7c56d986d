"""``[materials]``, material references and ``[[lights]]`` (and a node's lights)."""

from __future__ import annotations

from typing import Any

from frustum.scenefile.checks import _call, _choice, _table, _table_list
from frustum.scenefile.report import _BAD, _Report
from frustum.shading import AmbientLight, DirectionalLight, Material, PointLight, SpotLight

_LIGHT_TYPES = {"ambient": AmbientLight, "directional": DirectionalLight, "point": PointLight, "spot": SpotLight}


def _material(report: _Report, path: tuple, value: Any) -> Any:
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    if "texture" in params:
        report.add((*path, "texture"), params.pop("texture"), "is not supported in scene files",
                   "textures come with mesh files (OBJ/glTF) or from the Python API")  # fmt: skip
        return _BAD
    return _call(report, path, Material, params, label="Material")


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
