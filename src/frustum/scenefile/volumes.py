"""``[[volumes]]``: a volume source, its transfer function, mode and options, placed by ``Scene.add_volume``."""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

from frustum.errors import FrustumError
from frustum.scene import Scene
from frustum.scenefile.checks import (
    _boolean,
    _call,
    _choice,
    _number,
    _plain,
    _table,
    _table_list,
    _unknown_keys,
    _vector,
)
from frustum.scenefile.geometry import _mesh_file
from frustum.scenefile.lights_materials import _material_reference
from frustum.scenefile.report import _BAD, _bad, _Report
from frustum.scenefile.transforms import _transform

_VOLUME_KEYS = ("source", "transfer_function", "mode", "transform", "step", "level", "shade", "material",
                "clip_planes", "sampling")  # fmt: skip


_VOLUME_SOURCES = {"file": "load", "fbm_cloud": "fbm_cloud", "quaternion_julia": "quaternion_julia_volume",
                   "blobby": "blobby_volume", "head_phantom": "head_phantom"}  # fmt: skip


_TRANSFER_KEYS = ("preset", "colormap", "range", "opacity", "values", "colors", "opacities")


def _volume(report: _Report, path: tuple, value: dict, base: Path, materials: dict, scene: Scene) -> None:
    """One ``[[volumes]]`` table: $source = { type = ..., ... }$, a transfer function, the mode and options,
    placed by ``Scene.add_volume``."""
    module = importlib.import_module("frustum.geometry.volume")
    _unknown_keys(report, path, value, _VOLUME_KEYS)
    if "source" not in value:
        report.missing((*path, "source"), f"give source = {{ type = ... }}, type one of {', '.join(_VOLUME_SOURCES)}")
        return
    params = _table(report, (*path, "source"), value["source"])
    if params is _BAD:
        return
    if "type" not in params:
        report.missing((*path, "source", "type"), f"give source.type, one of {', '.join(_VOLUME_SOURCES)}")
        return
    kind = _choice(report, (*path, "source", "type"), params.pop("type"), tuple(_VOLUME_SOURCES))
    if kind is _BAD:
        return
    if kind == "file":
        volume = _mesh_file(report, (*path, "source"), params, base, module.Volume.load)
    else:
        volume = _call(report, (*path, "source"), getattr(module, _VOLUME_SOURCES[kind]), params, label=kind)
    options: dict[str, Any] = {}
    if "mode" in value:
        options["mode"] = _choice(report, (*path, "mode"), value["mode"], module.VOLUME_MODES)
    if "sampling" in value:
        options["sampling"] = _choice(report, (*path, "sampling"), value["sampling"], module.VOLUME_SAMPLINGS)
    for key in ("step", "level"):
        if key in value:
            options[key] = _number(report, (*path, key), value[key], low=0.0 if key == "step" else None,
                                   low_open=key == "step")  # fmt: skip
    if "shade" in value:
        options["shade"] = _boolean(report, (*path, "shade"), value["shade"])
    if "transform" in value:
        options["transform"] = _transform(report, (*path, "transform"), value["transform"])
    if "material" in value:
        options["material"] = _material_reference(report, (*path, "material"), value["material"], materials)
    if "clip_planes" in value:
        planes = []
        for j, plane in enumerate(_table_list(report, (*path, "clip_planes"), value["clip_planes"])):
            _unknown_keys(report, (*path, "clip_planes", j), plane, ("point", "normal"))
            for key in ("point", "normal"):
                if key not in plane:
                    report.missing((*path, "clip_planes", j, key), "give point and normal; the normal's side is cut")
            if "point" in plane and "normal" in plane:
                planes.append((_vector(report, (*path, "clip_planes", j, "point"), plane["point"]),
                               _vector(report, (*path, "clip_planes", j, "normal"), plane["normal"])))  # fmt: skip
            else:
                planes.append((_BAD, _BAD))
        options["clip_planes"] = _BAD if any(_bad(*p) for p in planes) else planes
    transfer = None
    if "transfer_function" in value:
        transfer = _transfer_function(report, (*path, "transfer_function"), value["transfer_function"], module)
    if _bad(volume, transfer, *options.values()):
        return
    try:
        scene.add_volume(volume, transfer, **options)
    except FrustumError as error:
        report.refused(path, value, error)


def _transfer_function(report: _Report, path: tuple, value: Any, module: Any) -> Any:
    """``{ preset = "bone", range = [lo, hi], opacity = ... }``, ``{ colormap = "viridis", ... }`` or
    ${ values = [...], colors = [[r, g, b], ...], opacities = [...] }$ (range optional)."""
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    _unknown_keys(report, path, params, _TRANSFER_KEYS)
    kinds = [key for key in ("preset", "colormap", "values") if key in params]
    if len(kinds) != 1:
        report.add(path, params, "needs exactly one of preset, colormap or values",
                   "give preset = 'bone' (or colormap = 'viridis') with range, or values, colors and "
                   "opacities")  # fmt: skip
        return _BAD
    transfer = module.TransferFunction
    if kinds[0] == "values":
        arguments = {key: params[key] for key in ("values", "colors", "opacities", "range") if key in params}
        return _call(report, path, transfer, arguments, label="TransferFunction")
    builder = transfer.preset if kinds[0] == "preset" else transfer.colormap
    if "range" not in params:
        report.missing((*path, "range"), f"give range = [low, high] with the {kinds[0]}")
        return _BAD
    try:
        return builder(params[kinds[0]], **{key: _plain(params[key]) for key in ("range", "opacity") if key in params})
    except FrustumError as error:
        report.refused((*path, kinds[0]), params[kinds[0]], error)
        return _BAD
