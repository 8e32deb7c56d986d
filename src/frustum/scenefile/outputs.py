"""``[render]`` (the keyword arguments of ``frustum.render``, the image size and the sheet's columns), the image
memory budget at load time, and ``[output]``, ``[animation]`` and ``[svg]`` (files kept inside the scene
file's folder)."""

from __future__ import annotations

import importlib
import inspect
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from frustum.budgets import check_memory
from frustum.errors import SceneFileError
from frustum.render import RENDER_METHODS, RENDER_MODES, SHADING_MODES, TRANSPARENCY_MODES
from frustum.render.options import COLOR_SPACES, EDGE_SETS, FILTERS, HIDDEN_STYLES
from frustum.scenefile.checks import (
    _ANGLE_PARAMETERS,
    _boolean,
    _call,
    _check_plain_value,
    _choice,
    _color,
    _number,
    _table,
    _unknown_keys,
    _vector,
)
from frustum.scenefile.report import _BAD, _Report
from frustum.shading import SPECULAR_MODELS, DepthCue
from frustum.shading.tone import TONE_MAPS

OUTPUT_SUFFIXES = (".png", ".svg", ".pdf", ".gif", ".mp4")
"""What ``render_scene_file`` writes, chosen by the output's suffix."""


_MAX_PIXELS = 8192
"""Largest image width or height a scene file may ask for."""


_RENDER_KEYS = (
    "size", "shading", "specular", "background", "cull_back_faces", "mode", "edges", "crease_angle_deg", "edge_color",
    "hidden", "hidden_color", "line_width", "depth_cue", "samples", "filter", "color_space", "columns", "method",
    "transparency", "max_depth", "shadows", "shadow_map_size", "shadow_softness", "tone_map", "exposure", "eye_dome",
    "eye_dome_strength",
)  # fmt: skip


_DEPTH_CUE_KEYS = ("near", "far", "min_intensity", "max_intensity", "color")


_DEFAULT_SIZE = (480, 360)


def _shadows(report: _Report, path: tuple, value: Any) -> Any:
    """``[render] shadows``: true (shadow maps), false, or "ray" (shadow rays)."""
    if isinstance(value, bool) or value == "ray":
        return value
    report.add(path, value, "is not a shadow method", 'give true (shadow maps), false or "ray" (shadow rays)')
    return _BAD


def _render_options(report: _Report, path: tuple, value: Any) -> tuple[dict, tuple[int, int], int]:
    params = _table(report, path, value)
    if params is _BAD:
        return {}, _DEFAULT_SIZE, 0
    _unknown_keys(report, path, params, _RENDER_KEYS)
    options: dict[str, Any] = {}
    size = _DEFAULT_SIZE
    if "size" in params:
        checked = _vector(report, (*path, "size"), params["size"], 2, "width, height")
        if checked is not _BAD and all(c.is_integer() and c >= 1 for c in checked) and max(checked) > _MAX_PIXELS:
            report.add((*path, "size"), params["size"], f"is over the limit of {_MAX_PIXELS} pixels a side",
                       f"give [width, height], integers in [1, {_MAX_PIXELS}]")  # fmt: skip
        elif checked is not _BAD and not all(c.is_integer() and 1 <= c <= _MAX_PIXELS for c in checked):
            report.add((*path, "size"), params["size"], "is not two positive integer pixel counts",
                       f"give [width, height], integers in [1, {_MAX_PIXELS}]")  # fmt: skip
        elif checked is not _BAD:
            size = (int(checked[0]), int(checked[1]))
    simple: dict[str, Callable[[tuple, Any], Any]] = {
        "shading": lambda p, v: _choice(report, p, v, tuple(SHADING_MODES)),
        "specular": lambda p, v: _choice(report, p, v, SPECULAR_MODELS),
        "background": lambda p, v: _color(report, p, v, alpha=True),
        "cull_back_faces": lambda p, v: _boolean(report, p, v),
        "mode": lambda p, v: _choice(report, p, v, RENDER_MODES),
        "edges": lambda p, v: _choice(report, p, v, EDGE_SETS),
        "edge_color": lambda p, v: _color(report, p, v, alpha=True),
        "hidden": lambda p, v: _choice(report, p, v, HIDDEN_STYLES[1:]),  # (None: leave the key out)
        "hidden_color": lambda p, v: _color(report, p, v, alpha=True),
        "line_width": lambda p, v: _number(report, p, v, low=1.0, high=64.0),
        "samples": lambda p, v: _number(report, p, v, low=1, high=64, integer=True),
        "filter": lambda p, v: _choice(report, p, v, FILTERS),
        "color_space": lambda p, v: _choice(report, p, v, COLOR_SPACES),
        "method": lambda p, v: _choice(report, p, v, tuple(RENDER_METHODS)),
        "transparency": lambda p, v: _choice(report, p, v, TRANSPARENCY_MODES),
        "max_depth": lambda p, v: _number(report, p, v, low=0, high=64, integer=True),
        "shadows": lambda p, v: _shadows(report, p, v),
        "shadow_map_size": lambda p, v: _number(report, p, v, low=64, high=16384, integer=True),
        "shadow_softness": lambda p, v: _number(report, p, v, low=0.0, high=16.0),
        "eye_dome": lambda p, v: _boolean(report, p, v),
        "eye_dome_strength": lambda p, v: _number(report, p, v, low=0.0, low_open=True),
        "tone_map": lambda p, v: _choice(report, p, v, tuple(TONE_MAPS)),
        "exposure": lambda p, v: _number(report, p, v, low=1e-6, high=1e6),
    }
    for key, check in simple.items():
        if key in params:
            checked = check((*path, key), params[key])
            if checked is not _BAD:
                options[key] = checked
    if "samples" in options and math.isqrt(options["samples"]) ** 2 != options["samples"]:
        report.add((*path, "samples"), options.pop("samples"), "is not a square", "give 1, 4, 9, 16, ...")
    if "crease_angle_deg" in params:
        angle = _number(report, (*path, "crease_angle_deg"), params["crease_angle_deg"], low=0.0, high=180.0)
        if angle is not _BAD:
            options["crease_angle"] = math.radians(angle)
    if "depth_cue" in params:
        cue = _table(report, (*path, "depth_cue"), params["depth_cue"])
        if cue is not _BAD:
            _unknown_keys(report, (*path, "depth_cue"), cue, _DEPTH_CUE_KEYS)
            if all(key in _DEPTH_CUE_KEYS for key in cue):
                built = _call(report, (*path, "depth_cue"), DepthCue, cue, label="depth_cue")
                if built is not _BAD:
                    options["depth_cue"] = built
    columns = 0
    if "columns" in params:
        checked = _number(report, (*path, "columns"), params["columns"], low=1, high=64, integer=True)
        columns = 0 if checked is _BAD else checked
    return options, size, columns


def _check_image_memory(report: _Report, options: dict, size: tuple[int, int], cameras: int) -> None:
    """The image budget (``render.options.check_image_budget``'s estimate) at load time, so the error has file:line:
    one camera's supersampled buffers (12 bytes a rendered pixel, more for extra buffers and filters) plus
    every camera's finished 8-byte pixels (a contact sheet keeps them all)."""
    width, height = size
    samples = int(options.get("samples", 1))
    buffers = options.get("buffers", ())
    per_pixel = 12 + 12 * ("normals" in buffers) + 4 * ("object_id" in buffers)
    if options.get("filter", "box") != "box" or options.get("color_space", "linear") != "linear":
        per_pixel += 64
    needed = width * height * (samples * per_pixel + 8 * cameras)
    key = "samples" if "samples" in options else "size"
    try:
        check_memory(needed, where="render", cause=f"{width} x {height} pixels x samples = {samples} x {cameras} "
                     f"camera{'s' if cameras > 1 else ''}", error=SceneFileError)  # fmt: skip
    except SceneFileError as error:
        report.add(("render", key), options.get(key, list(size)), "is over the memory budget",
                   str(error).split(": ", 1)[1])  # fmt: skip


def _inside(base: Path, name: str) -> bool:
    """Whether output `name` of a scene file in folder `base` resolves inside `base` (symlinks followed)."""
    relative = Path(name)
    if relative.is_absolute() or relative.drive or ".." in relative.parts or "\0" in name:
        return False
    try:
        folder = base.resolve()
        target = (folder / relative).resolve()
    except (OSError, RuntimeError, ValueError):  # a symlink loop
        return False
    return target != folder and target.is_relative_to(folder)


def _outputs(report: _Report, data: dict, base: Path, check: bool = True) -> tuple[tuple[Path, ...], dict, dict]:
    outputs: list[Path] = []
    if "output" in data:
        params = _table(report, ("output",), data["output"])
        if params is not _BAD:
            _unknown_keys(report, ("output",), params, ("files",))
            files = params.get("files", [])
            if not isinstance(files, list) or not all(isinstance(f, str) and f for f in files):
                report.add(("output", "files"), files, "is not a list of file names", "give files = ['out/a.png']")
            else:
                for i, name in enumerate(files):
                    if Path(name).suffix.lower() not in OUTPUT_SUFFIXES:
                        report.add(("output", "files", i), name, "has an unknown suffix",
                                   f"expected one of {', '.join(OUTPUT_SUFFIXES)}")  # fmt: skip
                    elif not _inside(base, name):
                        if not check:  # not written (the caller writes elsewhere: -o), so not refused either
                            continue
                        report.add(("output", "files", i), name, "is outside the scene file's folder",
                                   "outputs named in a scene file must stay in its folder (no '..', no absolute "
                                   "path, no symlink pointing out); give a relative path, or use -o on the "
                                   "command line")  # fmt: skip
                    else:
                        outputs.append(base / name)
    animation: dict[str, Any] = {}
    if "animation" in data:
        path = ("animation",)
        params = _table(report, path, data["animation"])
        if params is not _BAD:
            _unknown_keys(report, path, params, ("frames", "fps", "axis", "substeps", "warmup"))
            if "substeps" in params:
                animation["substeps"] = _number(report, (*path, "substeps"), params["substeps"], low=1, high=1000,
                                                integer=True)  # fmt: skip
            if "warmup" in params:
                animation["warmup"] = _number(report, (*path, "warmup"), params["warmup"], low=0.0, high=3600.0)
            if "frames" in params:
                animation["frames"] = _number(report, (*path, "frames"), params["frames"], low=1, high=3600,
                                              integer=True)  # fmt: skip
            if "fps" in params:
                animation["fps"] = _number(report, (*path, "fps"), params["fps"], low=0.0, high=100.0, low_open=True)
            if "axis" in params:
                axis = params["axis"]
                animation["axis"] = (_choice(report, (*path, "axis"), axis, ("x", "y", "z")) if isinstance(axis, str)
                                     else _vector(report, (*path, "axis"), axis))  # fmt: skip
            animation = {k: v for k, v in animation.items() if v is not _BAD}
    svg: dict[str, Any] = {}
    if "svg" in data:
        params = _table(report, ("svg",), data["svg"])
        if params is not _BAD:
            svg = _svg_options(report, ("svg",), params)
    return tuple(outputs), animation, svg


def _svg_options(report: _Report, path: tuple, params: dict) -> dict:
    try:
        render_svg = importlib.import_module("frustum.output.svg").render_svg
    except (ImportError, AttributeError):
        report.add(path, params, "is not available in this version", "frustum.output.svg.render_svg is missing")
        return {}
    parameters = inspect.signature(render_svg).parameters
    allowed = [name for name in parameters if name not in ("scene", "camera")]
    shown = [f"{name}_deg" if name in _ANGLE_PARAMETERS else name for name in allowed]
    options: dict[str, Any] = {}
    for key, value in params.items():
        name = key[:-4] if key.endswith("_deg") else key
        if name not in allowed or (name in _ANGLE_PARAMETERS) != key.endswith("_deg"):
            report.add((*path, key), value, "is not an svg option", f"expected one of {', '.join(shown)}")
        elif _check_plain_value(report, (*path, key), value):
            if key.endswith("_deg"):
                if _number(report, (*path, key), value) is _BAD:
                    continue
                value = math.radians(value)
            options[name] = value
    return options
