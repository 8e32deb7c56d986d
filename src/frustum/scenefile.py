"""TOML scene files: a camera, lights, materials and a node hierarchy, validated with every error reported at once.

A scene file is read with the standard library's ``tomllib`` and checked completely before anything is
rendered: each problem becomes one line ``file:line: key = value problem; what is valid`` and all of them are
raised together as one ``SceneFileError`` (its ``problems`` attribute lists the lines). ``tomllib`` reports no
positions for keys, so ``_key_lines`` scans the TOML text once and maps every key path (``nodes[1].transform[0]
.rotate_y_deg``) to the line it is written on.

Conventions of the format (``docs/topics.md`` has a tour, ``scene.schema.json`` the JSON Schema):

- Angles are degrees, in keys ending ``_deg`` (``fovy_deg = 45``, ``rotate_y_deg = 30``); the Python API they
  feed takes radians. Lengths are world units; colors are linear RGB(A) in [0, 1].
- A node's ``transform`` is a list of named steps applied first to last (``world_from_model = compose(*steps)``,
  column vectors): ``translate``, ``rotate_x_deg`` / ``rotate_y_deg`` / ``rotate_z_deg``, ``rotate_deg`` about
  ``axis`` through ``point``, ``scale`` (one factor or three) about ``fixed``, ``reflect`` (``"xy"``, ``"yz"``,
  ``"zx"`` or a normal) through ``point``, ``shear`` (axis with ``a``, ``b``, ``ref``), ``quaternion`` ``[w, x, y,
  z]`` and ``matrix`` (4x4 rows).
- Geometry parameters are checked against the building function's own signature (``inspect.signature``), so a
  keyword argument that a geometry function gains later works in scene files at once.
- Paths (mesh files, outputs) are relative to the scene file's folder. Output files named in ``[output]
  files`` must stay inside that folder (no ``..`` escape, no absolute path, no symlink pointing out): rendering
  an untrusted scene file cannot write anywhere else. The command line's ``-o`` goes wherever the user says.
- Hostile input is refused early, with ``file:line``: files over ``MAX_SCENE_FILE_BYTES`` (16 MiB), arrays or
  tables nested deeper than ``_MAX_NESTING`` (64), dotted keys of more than 64 parts; keys and values are quoted
  in messages with control characters escaped.

References
----------
[HB 9] "Composite Three-Dimensional Transformations"; [HB 10] "The Three-Dimensional Viewing Pipeline";
[seed] "3D Viewing parameter (how 3D object displays at 2D)".
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import importlib
import inspect
import math
import re
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from frustum._arrays import describe, escape_control
from frustum.budgets import check_memory
from frustum.camera import Camera
from frustum.errors import FrustumError, OutputError, SceneFileError
from frustum.frame import Frame
from frustum.geometry import Mesh
from frustum.projection import MULTIVIEWS, Axonometric, Frustum, Oblique, Orthographic, Perspective
from frustum.quaternion import Quaternion
from frustum.render import RENDER_METHODS, RENDER_MODES, SHADING_MODES, TRANSPARENCY_MODES, render
from frustum.scene import Node, Scene, cutaway, exploded
from frustum.shading import AmbientLight, DepthCue, DirectionalLight, Material, PointLight, SpotLight
from frustum.transforms import compose, reflect, rotate, rotate_x, rotate_y, rotate_z, scale, shear, translate

__all__ = [
    "EXAMPLES_DIR",
    "GEOMETRY_TYPES",
    "OUTPUT_SUFFIXES",
    "PROJECTIONS",
    "SCHEMA_PATH",
    "TRANSFORM_STEPS",
    "SceneFile",
    "explain_scene_file",
    "load_scene",
    "load_scene_file",
    "render_examples",
    "render_scene_file",
    "render_view_sheet",
]

SCHEMA_PATH = Path(__file__).with_name("scene.schema.json")
"""The JSON Schema (draft 2020-12) of the scene-file format (the loader checks more: see the module docstring)."""

EXAMPLES_DIR = Path(__file__).resolve().parents[2] / "examples"
"""The gallery of example scene files in a source checkout (``render_examples`` renders them)."""

OUTPUT_SUFFIXES = (".png", ".svg", ".pdf", ".gif", ".mp4")
"""What ``render_scene_file`` writes, chosen by the output's suffix."""

PROJECTIONS = (
    "perspective", "frustum", "orthographic", "oblique", "cavalier", "cabinet", "isometric", "dimetric", "trimetric",
)  # fmt: skip
"""``camera.projection`` values."""

TRANSFORM_STEPS = (
    "translate", "rotate_x_deg", "rotate_y_deg", "rotate_z_deg", "rotate_deg", "scale", "reflect", "shear",
    "quaternion", "matrix",
)  # fmt: skip
"""The named steps a node's ``transform`` list may hold (each step is a table with one of these keys)."""

_MAX_PIXELS = 8192
MAX_SCENE_FILE_BYTES = 16 * 2**20
"""Largest scene file read (16 MiB): ``frustum render /dev/zero`` stops there instead of reading gigabytes."""
_MAX_NESTING = 64
"""Deepest nesting of arrays / inline tables, and most parts of a dotted key, a scene file may use."""
"""Largest image width or height a scene file may ask for."""
_MAX_INTEGER_PARAMETER = 100_000
"""Largest integer geometry parameter (segments, resolution, ...): guards against runaway tessellation."""
_ANGLE_PARAMETERS = frozenset(
    {"angle", "fovy", "alpha", "phi", "rotation_x", "rotation_y", "crease_angle", "inner_angle", "outer_angle",
     "azimuth", "elevation", "start", "end", "spread"}
)  # fmt: skip
"""Radian parameters of the Python API: scene files must give them in degrees, as ``<name>_deg``."""
_DEGREE_PARAMETERS = frozenset({"LSystem.angle", "union.sharp_angle", "difference.sharp_angle",
                                "intersection.sharp_angle"})  # fmt: skip
"""Parameters the Python API itself takes in degrees: ``<name>_deg`` passes through unconverted."""

_TOP_LEVEL = (
    "title", "description", "camera", "cameras", "lights", "materials", "nodes", "render", "exploded", "cutaway",
    "output", "animation", "svg", "particles", "cloth", "volumes",
)  # fmt: skip
_NODE_KEYS = ("name", "geometry", "material", "transform", "children", "lights")
_CAMERA_KEYS = (
    "eye", "target", "up", "projection", "fovy_deg", "near", "far", "height", "left", "right", "bottom", "top",
    "alpha_deg", "phi_deg", "ratio", "rotation_y_deg", "rotation_x_deg", "pivot", "z_vp", "view", "distance",
    "azimuth_deg", "elevation_deg", "stereo",
)  # fmt: skip
_STEREO_KEYS = ("eye_separation", "convergence_distance", "layout", "anaglyph_method", "cross_eyed")
_RENDER_KEYS = (
    "size", "shading", "specular", "background", "cull_back_faces", "mode", "edges", "crease_angle_deg", "edge_color",
    "hidden", "hidden_color", "line_width", "depth_cue", "samples", "filter", "color_space", "columns", "method",
    "transparency",
)  # fmt: skip
_DEPTH_CUE_KEYS = ("near", "far", "min_intensity", "max_intensity", "color")
_LIGHT_TYPES = {"ambient": AmbientLight, "directional": DirectionalLight, "point": PointLight, "spot": SpotLight}
_CURVE_KEYS = ("samples", "radius", "sides", "style", "closed", "control_polygon", "control_markers",
               "control_radius", "control_material")  # fmt: skip
_CURVE_STYLES = ("tube", "line")
_DEFAULT_SIZE = (480, 360)


# --- geometry registry ------------------------------------------------------------------------------------
# type name -> (kind, module, attribute). kind: "mesh" (a function returning a Mesh), "patches" (a function
# returning a BezierPatchSet to tessellate), "surface" (a class to tessellate), "curve" (a class or function
# whose result has .evaluate and .domain), "points" (a function returning (N, 2|3) polyline points), or one
# of the special kinds handled by name.

GEOMETRY_TYPES: dict[str, tuple[str, str, str]] = {
    "mesh": ("file", "frustum.geometry.io", "load"),
    # primitives
    "box": ("mesh", "frustum.geometry.primitives", "box"),
    "plane": ("mesh", "frustum.geometry.primitives", "plane"),
    "grid": ("mesh", "frustum.geometry.primitives", "grid"),
    "uv_sphere": ("mesh", "frustum.geometry.primitives", "uv_sphere"),
    "icosphere": ("mesh", "frustum.geometry.primitives", "icosphere"),
    "cylinder": ("mesh", "frustum.geometry.primitives", "cylinder"),
    "cone": ("mesh", "frustum.geometry.primitives", "cone"),
    "torus": ("mesh", "frustum.geometry.primitives", "torus"),
    "disk": ("mesh", "frustum.geometry.primitives", "disk"),
    "arrow": ("mesh", "frustum.geometry.primitives", "arrow"),
    "axes": ("mesh", "frustum.geometry.primitives", "axes"),
    # quadrics and superquadrics
    "sphere": ("mesh", "frustum.geometry.quadrics", "sphere"),
    "ellipsoid": ("mesh", "frustum.geometry.quadrics", "ellipsoid"),
    "superellipsoid": ("mesh", "frustum.geometry.quadrics", "superellipsoid"),
    "supertoroid": ("mesh", "frustum.geometry.quadrics", "supertoroid"),
    # Bézier patch models
    "teapot": ("patches", "frustum.geometry.teapot", "teapot"),
    "teacup": ("patches", "frustum.geometry.teapot", "teacup"),
    "teaspoon": ("patches", "frustum.geometry.teapot", "teaspoon"),
    # surfaces
    "bezier_surface": ("surface", "frustum.geometry.surfaces", "BezierSurface"),
    "bspline_surface": ("surface", "frustum.geometry.surfaces", "BSplineSurface"),
    "nurbs_surface": ("surface", "frustum.geometry.surfaces", "NURBSSurface"),
    # curves
    "bezier_curve": ("curve", "frustum.geometry.curves", "BezierCurve"),
    "bspline_curve": ("curve", "frustum.geometry.curves", "BSpline"),
    "nurbs_curve": ("curve", "frustum.geometry.curves", "NURBSCurve"),
    "cubic_spline": ("curve", "frustum.geometry.curves", "CubicSpline"),
    "catmull_rom": ("curve", "frustum.geometry.curves", "catmull_rom"),
    "cardinal_spline": ("curve", "frustum.geometry.curves", "cardinal_spline"),
    # fractals
    "terrain": ("terrain", "frustum.geometry.fractals", "fbm_terrain"),
    "menger_sponge": ("mesh", "frustum.geometry.fractals", "menger_sponge"),
    "sierpinski_tetrahedron": ("mesh", "frustum.geometry.fractals", "sierpinski_tetrahedron"),
    "koch_snowflake": ("points", "frustum.geometry.fractals", "koch_snowflake"),
    "hilbert_curve_3d": ("points", "frustum.geometry.fractals", "hilbert_curve_3d"),
    "quaternion_julia": ("mesh", "frustum.geometry.escape_time", "quaternion_julia_mesh"),
    "lsystem": ("lsystem", "frustum.geometry.lsystem", "LSystem"),
    # constructive solid geometry over other geometry tables
    "union": ("csg", "frustum.geometry.csg", "union"),
    "difference": ("csg", "frustum.geometry.csg", "difference"),
    "intersection": ("csg", "frustum.geometry.csg", "intersection"),
    # a solid as an octree of the cells of another geometry table (drawn by [render] method = "octree")
    "octree": ("octree", "frustum.geometry.octree", "Octree"),
}
"""``geometry.type`` values: (kind, module, attribute) of the function or class that builds each one."""


# --- key lines: where each key path is written in the TOML text --------------------------------------------


_SPACES = re.compile(r"[ \t\r]*")
_BARE_KEY = re.compile(r"[\w-]*")  # letters, digits, "_" and "-"
_BARE_VALUE = re.compile(r"[^,\]}\n#]*")
_BASIC_STRING = re.compile(r'"((?:[^"\\\n]|\\.)*)"')
_LITERAL_STRING = re.compile(r"'([^'\n]*)'")


class _Scanner:
    """Map every key path (and array element) of valid TOML text to its 1-based line number."""

    def __init__(self, text: str) -> None:
        self.text, self.pos, self.line = text, 0, 1
        self.lines: dict[tuple, int] = {}
        self.array_tables: dict[tuple, int] = {}

    def _char(self) -> str:
        return self.text[self.pos] if self.pos < len(self.text) else ""

    def _advance(self, count: int = 1) -> None:
        self.line += self.text.count("\n", self.pos, self.pos + count)
        self.pos += count

    def _skip_spaces(self) -> None:
        self.pos = _SPACES.match(self.text, self.pos).end()  # type: ignore[union-attr]

    def _skip_blank(self) -> None:
        """Spaces, newlines and comments (inside arrays)."""
        while self._char():
            char = self._char()
            if char in " \t\r\n":
                self._advance()
            elif char == "#":
                end = self.text.find("\n", self.pos)
                self.pos = len(self.text) if end < 0 else end
            else:
                return

    def _record(self, path: tuple) -> None:
        self.lines.setdefault(path, self.line)

    def _string(self) -> str:
        quote = self._char()
        triple = self.text.startswith(quote * 3, self.pos)
        if not triple:  # one-line strings (nearly all of them) in one regular-expression step
            found = (_BASIC_STRING if quote == '"' else _LITERAL_STRING).match(self.text, self.pos)
            if found:
                self.pos = found.end()
                body = found.group(1)
                return _unescape(body) if quote == '"' and "\\" in body else body
        start = self.pos + (3 if triple else 1)
        self._advance(start - self.pos)
        chars = []
        while self._char():
            if quote == '"' and self._char() == "\\":
                chars.append(self.text[self.pos : self.pos + 2])
                self._advance(2)
                continue
            if triple and self.text.startswith(quote * 3, self.pos):
                while self.text.startswith(quote * 4, self.pos):  # up to two quotes may end the content
                    chars.append(quote)
                    self._advance()
                self._advance(3)
                return "".join(chars)
            if not triple and self._char() == quote:
                self._advance()
                return _unescape("".join(chars)) if quote == '"' else "".join(chars)
            chars.append(self._char())
            self._advance()
        return "".join(chars)

    def _key(self) -> list[str]:
        parts = []
        while True:
            self._skip_spaces()
            if self._char() in ('"', "'"):
                parts.append(self._string())
            else:
                start = self.pos
                self.pos = _BARE_KEY.match(self.text, self.pos).end()  # type: ignore[union-attr]
                parts.append(self.text[start : self.pos])
            self._skip_spaces()
            if self._char() != ".":
                return parts
            self.pos += 1

    def _value(self, path: tuple) -> None:
        char = self._char()
        if char == "[":
            self._advance()
            index = 0
            while self._char():
                self._skip_blank()
                if self._char() == "]":
                    self._advance()
                    return
                self._record((*path, index))
                self._value((*path, index))
                index += 1
                self._skip_blank()
                if self._char() == ",":
                    self._advance()
            return
        if char == "{":
            self._advance()
            while self._char():
                self._skip_blank()
                if self._char() == "}":
                    self._advance()
                    return
                if self._char() == ",":
                    self._advance()
                    continue
                self._pair(path)
            return
        if char in ('"', "'"):
            self._string()
            return
        self.pos = _BARE_VALUE.match(self.text, self.pos).end()  # type: ignore[union-attr]

    def _pair(self, table: tuple) -> None:
        keys = self._key()
        for depth in range(1, len(keys) + 1):
            self._record((*table, *keys[:depth]))
        self._skip_spaces()
        if self._char() == "=":
            self.pos += 1
        self._skip_spaces()
        self._value((*table, *keys))

    def _resolve(self, parts: list[str], array: bool) -> tuple:
        path: tuple = ()
        for k, part in enumerate(parts):
            path = (*path, part)
            if array and k == len(parts) - 1:
                index = self.array_tables.get(path, 0)
                self.array_tables[path] = index + 1
                self._record(path)
                path = (*path, index)
            elif path in self.array_tables:
                path = (*path, self.array_tables[path] - 1)
        return path

    def scan(self) -> dict[tuple, int]:
        table: tuple = ()
        while self._char():
            self._skip_spaces()
            char = self._char()
            if char == "\n":
                self._advance()
            elif char == "#":
                end = self.text.find("\n", self.pos)
                self.pos = len(self.text) if end < 0 else end
            elif char == "[":
                array = self.text.startswith("[[", self.pos)
                self.pos += 2 if array else 1
                table = self._resolve(self._key(), array)
                self._record(table)
                end = self.text.find("\n", self.pos)
                self.pos = len(self.text) if end < 0 else end
            elif char:
                self._pair(table)
        return self.lines


def _unescape(raw: str) -> str:
    """The value of a TOML basic string's body (escapes such as \\u00e9 decoded), or `raw` if it is not one."""
    try:
        return tomllib.loads(f'v = "{raw}"')["v"]
    except tomllib.TOMLDecodeError:
        return raw


def _key_lines(text: str) -> dict[tuple, int]:
    """{key path: line} for valid TOML `text`; a path holds table keys and array indices, e.g. ("nodes", 0, "name")."""
    scanner = _Scanner(text)
    try:
        return scanner.scan()
    except (IndexError, ValueError):  # defensive: a scanner gap costs line numbers, never the validation
        return scanner.lines


# --- the error report ------------------------------------------------------------------------------------


def _path_text(path: Sequence) -> str:
    text = ""
    for part in path:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            bare = part.replace("_", "").replace("-", "").isalnum()
            shown = part if bare else f'"{escape_control(part)}"'
            text += ("." if text else "") + shown
    return text or "(file)"


def _problem_text(error: Exception) -> str:
    return escape_control(str(error).splitlines()[0]) if str(error) else type(error).__name__


class _Report:
    """Collects every problem as ``file:line: key = value problem; what is valid``."""

    def __init__(self, source: str, lines: dict[tuple, int] | str | None) -> None:
        self.source = source
        self._lines = lines  # TOML text: scanned for key lines only when a problem needs one
        self.problems: list[str] = []
        self.built: dict[tuple, Any] = {}  # (builder, arguments) -> result, for deterministic builders

    @property
    def lines(self) -> dict[tuple, int] | None:
        if isinstance(self._lines, str):
            self._lines = _key_lines(self._lines)
        return self._lines

    def line(self, path: Sequence) -> int | None:
        if self.lines is None:
            return None
        path = tuple(path)
        while path:
            if path in self.lines:
                return self.lines[path]
            path = path[:-1]
        return 1

    def _where(self, path: Sequence) -> str:
        line = self.line(path)
        source = escape_control(self.source)
        return f"{source}:{line}" if line is not None else source

    def add(self, path: Sequence, value: Any, problem: str, valid: str) -> None:
        """``key = value problem; valid``."""
        self.problems.append(f"{self._where(path)}: {_path_text(path)} = {describe(value)} {problem}; {valid}")

    def missing(self, path: Sequence, valid: str) -> None:
        self.problems.append(f"{self._where(path)}: {_path_text(path)} is missing; {valid}")

    def refused(self, path: Sequence, value: Any, error: Exception) -> None:
        """A value the building function refused: its own message says what is valid.

        When the message names one of the table's keys (``where: name = ...``), the problem points at that key.
        """
        message = _problem_text(error)
        named = re.match(r"[^:]*: (\w+)", message)
        if named and isinstance(value, Mapping):
            for key in (named.group(1), named.group(1) + "_deg"):
                if key in value:
                    path, value = (*path, key), value[key]
                    break
        self.problems.append(f"{self._where(path)}: {_path_text(path)} = {describe(value)} is not accepted: {message}")

    def raise_if_any(self) -> None:
        if self.problems:
            self.problems.sort(key=_line_of)
            count = len(self.problems)
            error = SceneFileError("\n".join(self.problems) + (f"\n({count} errors)" if count > 1 else ""))
            error.problems = list(self.problems)  # type: ignore[attr-defined]
            raise error


def _line_of(problem: str) -> int:
    """The line number a problem starts with (0 when it has none), for sorting the report."""
    found = re.match(r".*?:(\d+): ", problem)
    return int(found.group(1)) if found else 0


_BAD = object()
"""Marks a value that failed validation (its problem is already in the report)."""


def _bad(*values: Any) -> bool:
    """True if any value is ``_BAD`` (by identity: values may be numpy arrays)."""
    return any(value is _BAD for value in values)


def _unknown_keys(report: _Report, path: tuple, table: Mapping, allowed: Sequence[str]) -> None:
    for key in table:
        if key not in allowed:
            close = difflib.get_close_matches(str(key), allowed, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            report.add(
                (*path, key), table[key], "is not a known key", f"{hint}expected one of {', '.join(sorted(allowed))}"
            )


def _table(report: _Report, path: tuple, value: Any, what: str = "a table") -> dict | Any:
    if not isinstance(value, Mapping):
        report.add(path, value, f"is not {what}", f"write it as a TOML table ([{_path_text(path)}] or {{ ... }})")
        return _BAD
    return dict(value)


def _table_list(report: _Report, path: tuple, value: Any) -> list:
    if not isinstance(value, list) or not all(isinstance(item, Mapping) for item in value):
        report.add(path, value, "is not a list of tables", f"write each entry as [[{_path_text(path)}]]")
        return []
    return value


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _number(
    report: _Report,
    path: tuple,
    value: Any,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    integer: bool = False,
) -> Any:
    """A finite number (an integer when asked) in [low, high] ((low, high] when `low_open`)."""
    kind = "an integer" if integer else "a number"
    if (integer and (not isinstance(value, int) or isinstance(value, bool))) or not _is_number(value):
        report.add(path, value, f"is not {kind}", f"give {kind}")
        return _BAD
    if not math.isfinite(value):
        report.add(path, value, "is not finite", f"give a finite {kind[2:] if integer else 'number'}")
        return _BAD
    below = low is not None and (value <= low if low_open else value < low)
    if below or (high is not None and value > high):
        left = "(" if low_open else "["
        lower = "-inf" if low is None else f"{low:g}"
        upper = "inf" if high is None else f"{high:g}"
        bounds = f"{left}{lower}, {upper}]"
        report.add(path, value, "is out of range", f"expected {kind} in {bounds}")
        return _BAD
    return value


def _vector(report: _Report, path: tuple, value: Any, count: int = 3, what: str = "x, y, z") -> Any:
    if not isinstance(value, list) or len(value) != count or not all(_is_number(v) for v in value):
        report.add(path, value, f"is not {count} numbers", f"give [{what}]")
        return _BAD
    if not all(math.isfinite(v) for v in value):
        report.add(path, value, "is not finite", f"give {count} finite numbers [{what}]")
        return _BAD
    return [float(v) for v in value]


def _color(report: _Report, path: tuple, value: Any, alpha: bool = False) -> Any:
    counts = (3, 4) if alpha else (3,)
    shape = "[r, g, b] or [r, g, b, a]" if alpha else "[r, g, b]"
    if not isinstance(value, list) or len(value) not in counts or not all(_is_number(v) for v in value):
        report.add(path, value, "is not a color", f"give {shape} with components in [0, 1]")
        return _BAD
    if not all(math.isfinite(v) and 0.0 <= v <= 1.0 for v in value):
        report.add(path, value, "has components outside [0, 1]", f"give {shape} with components in [0, 1]")
        return _BAD
    return [float(v) for v in value]


def _choice(report: _Report, path: tuple, value: Any, choices: Sequence[str]) -> Any:
    if not isinstance(value, str) or value not in choices:
        close = difflib.get_close_matches(str(value), choices, n=1) if isinstance(value, str) else []
        hint = f"did you mean {close[0]!r}? " if close else ""
        report.add(path, value, "is unknown", f"{hint}expected one of {', '.join(repr(c) for c in choices)}")
        return _BAD
    return value


def _boolean(report: _Report, path: tuple, value: Any) -> Any:
    if not isinstance(value, bool):
        report.add(path, value, "is not a boolean", "give true or false")
        return _BAD
    return value


def _plain(value: Any) -> Any:
    """TOML values as the Python API wants them (lists of numbers stay lists; numpy converts them)."""
    return value


def _check_plain_value(report: _Report, path: tuple, value: Any) -> bool:
    """Reject NaN/inf anywhere in a parameter, and integers large enough to make tessellation run away."""
    if isinstance(value, bool | str):
        return True
    if isinstance(value, float) and not math.isfinite(value):
        report.add(path, value, "is not finite", "give a finite number")
        return False
    if isinstance(value, int) and abs(value) > _MAX_INTEGER_PARAMETER:
        report.add(path, value, "is too large", f"give an integer of magnitude <= {_MAX_INTEGER_PARAMETER}")
        return False
    if isinstance(value, list):
        return all(_check_plain_value(report, (*path, i), v) for i, v in enumerate(value))
    if isinstance(value, Mapping):
        report.add(path, value, "is a table", "give a number, a string, a boolean or a list of numbers")
        return False
    return True


_SIGNATURES: dict[Any, inspect.Signature | None] = {}


def _signature(function: Callable) -> inspect.Signature | None:
    """``inspect.signature``, cached (it is slow, and a large scene file calls the same builders 10⁴ times)."""
    key = getattr(function, "__func__", function)  # bound methods: one entry per function
    if isinstance(key, functools.partial):  # made per call: not worth a cache entry
        try:
            return inspect.signature(key)
        except (TypeError, ValueError):  # pragma: no cover
            return None
    if key not in _SIGNATURES:
        try:
            _SIGNATURES[key] = inspect.signature(key)
        except (TypeError, ValueError):  # pragma: no cover - builtins without signatures
            _SIGNATURES[key] = None
    signature = _SIGNATURES[key]
    if signature is not None and key is not function:  # a bound method: drop `self`
        signature = signature.replace(parameters=list(signature.parameters.values())[1:])
    return signature


def _call(
    report: _Report,
    path: tuple,
    function: Callable,
    params: Mapping[str, Any],
    *,
    label: str,
    skip: Sequence[str] = (),
) -> Any:
    """``function(**params)`` with keys checked against its signature; `_deg` keys converted to radians."""
    signature = _signature(function)
    accepted = {
        name: p
        for name, p in (signature.parameters.items() if signature else ())
        if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and name not in ("self", "cls", "max_bytes")
    }
    valid_keys = sorted(f"{n}_deg" if n in _ANGLE_PARAMETERS and f"{label}.{n}" not in _DEGREE_PARAMETERS else n
                        for n in accepted)  # fmt: skip
    kwargs: dict[str, Any] = {}
    ok = True
    for key, value in params.items():
        if key in skip:
            continue
        key_text = str(key)
        name = key_text[:-4] if key_text.endswith("_deg") else key_text
        native_degrees = f"{label}.{name}" in _DEGREE_PARAMETERS
        if name not in accepted or (name in _ANGLE_PARAMETERS and not native_degrees and name == key_text):
            if name in accepted:
                report.add((*path, key), value, "is an angle in radians", f"scene files take degrees: write {name}_deg")
            else:
                close = difflib.get_close_matches(key_text, valid_keys, n=1)
                hint = f"did you mean {close[0]!r}? " if close else ""
                report.add(
                    (*path, key), value, f"is not a parameter of {label}",
                    f"{hint}expected {', '.join(valid_keys) or 'no parameters'}",
                )  # fmt: skip
            ok = False
            continue
        if key_text.endswith("_deg") and not (name in _ANGLE_PARAMETERS or native_degrees):
            report.add((*path, key), value, "is not an angle", f"write {name} without _deg")
            ok = False
            continue
        if not _check_plain_value(report, (*path, key), value):
            ok = False
            continue
        if key_text.endswith("_deg") and not native_degrees:
            if not _is_number(value):
                report.add((*path, key), value, "is not a number", "give an angle in degrees")
                ok = False
                continue
            value = math.radians(value)
        kwargs[name] = _plain(value)
    missing = False
    for name, parameter in accepted.items():
        if parameter.default is parameter.empty and name not in kwargs and name not in params:
            key = f"{name}_deg" if name in _ANGLE_PARAMETERS and f"{label}.{name}" not in _DEGREE_PARAMETERS else name
            if key not in params:
                report.missing((*path, key), f"{label} needs {key}")
            missing = True
    if missing:
        return _BAD
    cacheable = ok and getattr(function, "__module__", "") in _DETERMINISTIC_MODULES
    key = (function, repr(sorted(kwargs.items()))) if cacheable else None
    if key is not None and key in report.built:  # the same primitive again: share the immutable result
        return report.built[key]
    try:  # even after a bad key: the function's own checks may find more problems in the other values
        built = function(**kwargs)
    except FrustumError as error:
        report.refused(path, dict(params), error)
        return _BAD
    except (TypeError, ValueError, ArithmeticError, IndexError, MemoryError) as error:
        report.refused(path, dict(params), error)
        return _BAD
    if key is not None:
        report.built[key] = built
    return built if ok else _BAD


_DETERMINISTIC_MODULES = frozenset({"frustum.geometry.primitives", "frustum.geometry.quadrics", "frustum.shading"})
"""Builders whose results depend only on their arguments and are immutable: a scene file of 10⁴ equal spheres
builds one Mesh and shares it (``_call``)."""


def _resolve(report: _Report, path: tuple, kind: str, module: str, attribute: str) -> Any:
    try:
        return getattr(importlib.import_module(module), attribute)
    except (ImportError, AttributeError):
        report.add(path, kind, "is not available in this version", f"{module}.{attribute} is missing")
        return _BAD


# --- transforms ------------------------------------------------------------------------------------------

_STEP_MODIFIERS = {
    "translate": (),
    "rotate_x_deg": (),
    "rotate_y_deg": (),
    "rotate_z_deg": (),
    "rotate_deg": ("axis", "point"),
    "scale": ("fixed",),
    "reflect": ("point",),
    "shear": ("a", "b", "ref"),
    "quaternion": (),
    "matrix": (),
}


def _transform(report: _Report, path: tuple, value: Any) -> Any:
    """A list of named steps → ``compose(*steps)`` (first listed, first applied)."""
    if not isinstance(value, list):
        report.add(path, value, "is not a list of steps", "write transform = [{ translate = [x, y, z] }, ...]")
        return _BAD
    matrices = []
    for index, step in enumerate(value):
        where = (*path, index)
        if not isinstance(step, Mapping):
            report.add(where, step, "is not a step table", f"write {{ name = value }} with name one of "
                       f"{', '.join(TRANSFORM_STEPS)}")  # fmt: skip
            continue
        names = [key for key in step if key in _STEP_MODIFIERS]
        if not names:
            _unknown_keys(report, where, step, TRANSFORM_STEPS)
            if step:
                continue
        if len(names) != 1:
            report.add(where, dict(step), f"names {len(names)} operations",
                       f"give exactly one of {', '.join(TRANSFORM_STEPS)} per step")  # fmt: skip
            continue
        name = names[0]
        allowed = (name, *_STEP_MODIFIERS[name])
        _unknown_keys(report, where, step, allowed)
        if any(key not in allowed for key in step):
            continue
        matrix = _step_matrix(report, where, name, step)
        if matrix is not _BAD:
            matrices.append(matrix)
    if len(matrices) != len(value):
        return _BAD
    return compose(*matrices) if matrices else np.eye(4)


def _step_matrix(report: _Report, where: tuple, name: str, step: Mapping) -> Any:
    value = step[name]
    at = (*where, name)
    if name == "translate":
        v = _vector(report, at, value)
        return _BAD if v is _BAD else translate(*v)
    if name in ("rotate_x_deg", "rotate_y_deg", "rotate_z_deg"):
        angle = _number(report, at, value)
        builder = {"rotate_x_deg": rotate_x, "rotate_y_deg": rotate_y, "rotate_z_deg": rotate_z}[name]
        return _BAD if angle is _BAD else builder(math.radians(angle))
    if name == "rotate_deg":
        angle = _number(report, at, value)
        if "axis" not in step:
            report.missing((*where, "axis"), "rotate_deg needs axis = [ax, ay, az] (and optionally point)")
            return _BAD
        axis = _vector(report, (*where, "axis"), step["axis"], what="ax, ay, az")
        point = _vector(report, (*where, "point"), step.get("point", [0.0, 0.0, 0.0]))
        if _bad(angle, axis, point):
            return _BAD
        if not any(axis):
            report.add((*where, "axis"), axis, "has zero length", "give a nonzero rotation axis")
            return _BAD
        return rotate(axis, math.radians(angle), point)
    if name == "scale":
        if _is_number(value):
            factors = _number(report, at, value)
            factors = _BAD if factors is _BAD else [factors] * 3
        else:
            factors = _vector(report, at, value, what="sx, sy, sz")
        fixed = _vector(report, (*where, "fixed"), step.get("fixed", [0.0, 0.0, 0.0]))
        if _bad(factors, fixed):
            return _BAD
        if 0.0 in factors:
            report.add(at, value, "has a zero factor", "give nonzero scale factors (a zero flattens the object)")
            return _BAD
        return scale(*factors, fixed=fixed)
    if name == "reflect":
        point = _vector(report, (*where, "point"), step.get("point", [0.0, 0.0, 0.0]))
        if isinstance(value, str):
            normal = _choice(report, at, value, ("xy", "yz", "zx", "xz"))
        else:
            normal = _vector(report, at, value, what="nx, ny, nz")
            if normal is not _BAD and not any(normal):
                report.add(at, value, "has zero length", "give a nonzero plane normal or 'xy', 'yz', 'zx'")
                normal = _BAD
        return _BAD if _bad(normal, point) else reflect(normal, point)
    if name == "shear":
        axis = _choice(report, at, value, ("x", "y", "z"))
        numbers = [_number(report, (*where, key), step.get(key, 0.0)) for key in ("a", "b", "ref")]
        return _BAD if axis is _BAD or _bad(*numbers) else shear(axis, *numbers)
    if name == "quaternion":
        q = _vector(report, at, value, 4, "w, x, y, z")
        if q is not _BAD and not any(q):
            report.add(at, value, "is the zero quaternion", "give [w, x, y, z] with a nonzero norm (a rotation)")
            return _BAD
        return _BAD if q is _BAD else Quaternion(*q).to_matrix()
    rows = value if isinstance(value, list) and len(value) == 4 else None
    checked = [_vector(report, (*at, i), row, 4, "m0, m1, m2, m3") for i, row in enumerate(rows or [])]
    if rows is None:
        report.add(at, value, "is not 4 rows", "give a 4x4 matrix as four rows of four numbers")
        return _BAD
    if _bad(*checked):
        return _BAD
    matrix = np.array(checked)
    if not np.array_equal(matrix[3], [0.0, 0.0, 0.0, 1.0]):
        report.add(at, value, "is not affine", "a modeling matrix has the bottom row [0, 0, 0, 1]")
        return _BAD
    return matrix


# --- geometry --------------------------------------------------------------------------------------------


def _tube(points: np.ndarray, radius: float, sides: int, closed: bool) -> Mesh:
    """A thin polygonal tube along a polyline: one prism per segment plus an octahedron at every joint.

    Each segment gets its own frame (the tangent and the coordinate axis least parallel to it), so no frame has
    to be carried along the curve; the joint octahedra hide the small gaps at bends.
    """
    if closed:
        points = np.concatenate([points, points[:1]])
    start, end = points[:-1], points[1:]
    keep = np.linalg.norm(end - start, axis=1) > 0.0
    start, end = start[keep], end[keep]
    tangent = end - start
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    helper = np.eye(3)[np.argmin(np.abs(tangent), axis=1)]
    u = np.cross(tangent, helper)
    u /= np.linalg.norm(u, axis=1)[:, None]
    w = np.cross(tangent, u)
    angles = 2.0 * math.pi * np.arange(sides) / sides
    ring = np.cos(angles)[None, :, None] * u[:, None, :] + np.sin(angles)[None, :, None] * w[:, None, :]
    bottom = start[:, None, :] + radius * ring
    top = end[:, None, :] + radius * ring
    segments = start.shape[0]
    vertices = np.concatenate([bottom, top], axis=1).reshape(-1, 3)
    base = (2 * sides * np.arange(segments))[:, None]
    j = np.arange(sides)[None, :]
    a, b = base + j, base + (j + 1) % sides
    c, d = b + sides, a + sides
    faces = np.concatenate([np.stack([a, b, c], -1), np.stack([a, c, d], -1)], axis=1).reshape(-1, 3)
    # octahedra at the joints (every polyline point)
    joints = np.unique(np.concatenate([start, end]), axis=0)
    offsets = radius * np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
    octa_faces = np.array(
        [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]], dtype=np.int64
    )
    octa_vertices = (joints[:, None, :] + offsets[None]).reshape(-1, 3)
    octa = (octa_faces[None] + 6 * np.arange(joints.shape[0])[:, None, None]).reshape(-1, 3) + vertices.shape[0]
    return Mesh(np.concatenate([vertices, octa_vertices]), np.concatenate([faces.astype(np.int64), octa]))


def _as_points3(points: Any) -> np.ndarray:
    array = np.asarray(points, dtype=np.float64)
    if array.ndim == 2 and array.shape[1] == 2:
        array = np.column_stack([array, np.zeros(array.shape[0])])
    return array


def _polyline_type() -> Any:
    """``frustum.geometry.polyline.Polyline``, or None where this version has no polylines."""
    try:
        return importlib.import_module("frustum.geometry.polyline").Polyline
    except (ImportError, AttributeError):
        return None


def _line_geometry(report: _Report, path: tuple, points: np.ndarray, options: dict, closed: bool) -> Any:
    """A polyline as a depth-tested line (``Polyline``) or as a thin tube mesh (``style = "tube"``, or a ``radius``).

    Without ``style``, a curve with a ``radius`` is a tube and one without is a line (a tube where this version
    has no ``Polyline``).
    """
    polyline = _polyline_type()
    default = "tube" if "radius" in options or polyline is None else "line"
    if options.get("style", default) == "line":
        if polyline is None:
            report.add((*path, "style"), "line", "is not available in this version",
                       "frustum.geometry.polyline.Polyline is missing; use style = 'tube'")  # fmt: skip
            return _BAD
        return polyline(points, closed=closed, markers=bool(options.get("markers", False)))
    if points.shape[0] < 2:
        report.add(path, points.tolist(), "has fewer than 2 points", "a curve needs at least two points")
        return _BAD
    return _tube(points, options.get("radius", 0.02), options.get("sides", 8), closed)


def _control_node(report: _Report, path: tuple, geometry: Any, options: dict, materials: dict, name: str) -> Any:
    """A child node drawing control points or a control net, in ``control_material`` (default gray)."""
    material = None
    if "control_material" in options:
        material = _material_reference(report, (*path, "control_material"), options["control_material"], materials)
    if _bad(geometry, material):
        return _BAD
    return Node(name, None, geometry, material or Material((0.45, 0.45, 0.45)))


def _curve_options(report: _Report, path: tuple, params: dict) -> dict:
    options: dict[str, Any] = {}
    checks: dict[str, Callable[[tuple, Any], Any]] = {
        "samples": lambda p, v: _number(report, p, v, low=2, high=_MAX_INTEGER_PARAMETER, integer=True),
        "radius": lambda p, v: _number(report, p, v, low=0.0, low_open=True),
        "control_radius": lambda p, v: _number(report, p, v, low=0.0, low_open=True),
        "sides": lambda p, v: _number(report, p, v, low=3, high=64, integer=True),
        "style": lambda p, v: _choice(report, p, v, _CURVE_STYLES),
        "closed": lambda p, v: _boolean(report, p, v),
        "control_polygon": lambda p, v: _boolean(report, p, v),
        "control_markers": lambda p, v: _boolean(report, p, v),
        "control_material": lambda p, v: v,
    }
    for key in _CURVE_KEYS:
        if key in params:
            value = checks[key]((*path, key), params[key])
            if value is _BAD:
                options["bad"] = True
            options[key] = value
    return options


def _geometry(report: _Report, path: tuple, value: Any, base: Path, materials: dict) -> tuple[Any, list[Node]]:
    """The node's geometry and any extra child nodes (a curve's control polygon)."""
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD, []
    if "type" not in params:
        report.missing((*path, "type"), f"give geometry.type, one of {', '.join(sorted(GEOMETRY_TYPES))}")
        return _BAD, []
    kind_name = _choice(report, (*path, "type"), params.pop("type"), sorted(GEOMETRY_TYPES))
    if kind_name is _BAD:
        return _BAD, []
    kind, module, attribute = GEOMETRY_TYPES[kind_name]
    builder = _resolve(report, (*path, "type"), kind_name, module, attribute)
    if builder is _BAD:
        return _BAD, []
    if kind == "file":
        return _mesh_file(report, path, params, base, builder), []
    if kind == "mesh":
        return _as_mesh(report, path, _call(report, path, builder, params, label=kind_name), kind_name), []
    if kind == "patches":
        return _patches(report, path, params, builder, materials)
    if kind == "surface":
        resolution = params.pop("resolution", [16, 16])
        counts = _vector(report, (*path, "resolution"), resolution, 2, "nu, nv")
        if counts is not _BAD and not all(float(c).is_integer() and 1 <= c <= 512 for c in counts):
            report.add((*path, "resolution"), resolution, "is out of range", "give [nu, nv], integers in [1, 512]")
            counts = _BAD
        surface = _call(report, path, builder, params, label=kind_name)
        if _bad(surface, counts):
            return _BAD, []
        return _call(report, path, surface.tessellate, {"nu": int(counts[0]), "nv": int(counts[1])},
                     label=kind_name), []  # fmt: skip
    if kind == "terrain":
        return _terrain(report, path, params, builder), []
    if kind == "csg":
        return _csg(report, path, params, builder, base, materials), []
    if kind == "lsystem":
        return _lsystem(report, path, params, builder), []
    if kind == "octree":
        return _octree(report, path, params, builder, base, materials), []
    # curves and point fractals: sampled into a polyline, drawn as a tube or line
    options = _curve_options(report, path, params)
    rest = {k: v for k, v in params.items() if k not in _CURVE_KEYS}
    built = _call(report, path, builder, rest, label=kind_name)
    if built is _BAD or options.get("bad"):
        return _BAD, []
    if kind == "points":
        points = _as_points3(built)
        control = None
        closed = bool(options.get("closed", kind_name == "koch_snowflake"))
    else:
        low, high = built.domain
        samples = options.get("samples", 64)
        points = _as_points3(built.evaluate(np.linspace(low, high, samples)))
        # interpolating splines show the points they pass through; approximating ones their control points
        control = rest["points"] if "points" in rest else getattr(built, "control_points", None)
        closed = bool(options.get("closed", False))
    geometry = _line_geometry(report, path, points, options, closed)
    extras: list[Node] = []
    if control is None:
        return geometry, extras
    polygon = _as_points3(control).reshape(-1, 3)
    if options.get("control_polygon"):
        control_options = {k: v for k, v in options.items() if k != "radius"}
        if "control_radius" in options or ("radius" in options and "style" not in options):
            control_options["radius"] = options.get("control_radius", 0.5 * options.get("radius", 0.02))
        drawn = _line_geometry(report, path, polygon, control_options, False)
        extras.append(_control_node(report, path, drawn, options, materials, "control polygon"))
    if options.get("control_markers"):
        drawn = _line_geometry(report, (*path, "control_markers"), polygon, {"style": "line", "markers": True}, False)
        extras.append(_control_node(report, path, drawn, options, materials, "control points"))
    return (_BAD, []) if _bad(*extras) else (geometry, extras)


def _patches(report: _Report, path: tuple, params: dict, builder: Callable, materials: dict) -> tuple[Any, list]:
    """A Bézier patch model tessellated ``resolution`` × ``resolution`` per patch, with its control net if asked."""
    _unknown_keys(report, path, params, ("resolution", "control_net", "control_material"))
    resolution = _number(report, (*path, "resolution"), params.get("resolution", 8), low=1, high=64, integer=True)
    net = _boolean(report, (*path, "control_net"), params.get("control_net", False))
    if _bad(resolution, net) or any(key not in ("resolution", "control_net", "control_material") for key in params):
        return _BAD, []
    patches = builder()
    mesh = _call(report, path, patches.tessellate, {"resolution": resolution}, label="tessellate")
    extras = []
    if net:
        polyline = _polyline_type()
        if polyline is None:
            report.add((*path, "control_net"), True, "is not available in this version", "Polyline is missing")
            return _BAD, []
        extras.append(_control_node(report, path, polyline.from_segments(patches.control_net()), params, materials,
                                    "control net"))  # fmt: skip
    return (_BAD, []) if _bad(mesh, *extras) else (mesh, extras)


def _csg(report: _Report, path: tuple, params: dict, boolean: Callable, base: Path, materials: dict) -> Any:
    """``union`` / ``difference`` / ``intersection`` of the solids in ``operands`` (each a geometry table that may
    carry its own ``transform`` list), with ``sharp_angle_deg`` for the result's normals."""
    _unknown_keys(report, path, params, ("operands", "sharp_angle_deg"))
    operands = params.get("operands")
    if not isinstance(operands, list) or len(operands) < 2 or not all(isinstance(o, Mapping) for o in operands):
        report.add((*path, "operands"), operands, "is not a list of two or more geometry tables",
                   "write operands = [{ type = 'box' }, { type = 'sphere', transform = [...] }]")  # fmt: skip
        return _BAD
    angle = _number(report, (*path, "sharp_angle_deg"), params.get("sharp_angle_deg", 60.0), low=0.0, high=180.0)
    meshes = []
    for i, operand in enumerate(operands):
        where = (*path, "operands", i)
        table = dict(operand)
        steps = table.pop("transform", None)
        mesh, _ = _geometry(report, where, table, base, materials)
        if mesh is not _BAD and not isinstance(mesh, Mesh):
            report.add((*where, "type"), table.get("type"), "is not a solid", "CSG operands are closed meshes")
            mesh = _BAD
        matrix = None if steps is None else _transform(report, (*where, "transform"), steps)
        if matrix is _BAD:
            mesh = _BAD
        elif mesh is not _BAD and matrix is not None:
            mesh = mesh.transformed(matrix)
        meshes.append(mesh)
    if _bad(angle, *meshes) or any(key not in ("operands", "sharp_angle_deg") for key in params):
        return _BAD
    try:
        return boolean(*meshes, sharp_angle=angle)
    except (FrustumError, ValueError, RuntimeError) as error:
        report.refused(path, {"operands": "..."}, error)
        return _BAD


def _octree(report: _Report, path: tuple, params: dict, octree: Any, base: Path, materials: dict) -> Any:
    """``Octree.from_mesh`` of the closed mesh the ``source`` geometry table builds (a mesh file, a primitive or a
    CSG expression, with its own ``transform`` list), down to ``depth`` levels (``shell`` for a surface)."""
    keys = ("source", "depth", "shell")
    _unknown_keys(report, path, params, keys)
    if "source" not in params:
        report.missing((*path, "source"), "give the solid as a geometry table, e.g. source = { type = 'sphere' }")
        return _BAD
    depth = _number(report, (*path, "depth"), params.get("depth", 6), low=0, high=12, integer=True)
    shell = _boolean(report, (*path, "shell"), params.get("shell", False))
    table = _table(report, (*path, "source"), params["source"])
    mesh = _BAD
    if table is not _BAD:
        table = dict(table)
        steps = table.pop("transform", None)
        mesh, _ = _geometry(report, (*path, "source"), table, base, materials)
        if mesh is not _BAD and not isinstance(mesh, Mesh):
            report.add((*path, "source", "type"), table.get("type"), "is not a solid", "give a closed mesh geometry")
            mesh = _BAD
        matrix = None if steps is None else _transform(report, (*path, "source", "transform"), steps)
        if matrix is _BAD:
            mesh = _BAD
        elif mesh is not _BAD and matrix is not None:
            mesh = mesh.transformed(matrix)
    if _bad(depth, shell, mesh) or any(key not in keys for key in params):
        return _BAD
    try:
        return octree.from_mesh(mesh, int(depth), shell=bool(shell))
    except FrustumError as error:
        report.refused(path, {"source": "...", "depth": depth}, error)
        return _BAD


def _as_mesh(report: _Report, path: tuple, value: Any, label: str) -> Any:
    if value is _BAD or isinstance(value, Mesh):
        return value
    report.add(path, label, "did not build a mesh", f"{label} returned {type(value).__name__}")
    return _BAD


def _mesh_file(report: _Report, path: tuple, params: dict, base: Path, loader: Callable) -> Any:
    _unknown_keys(report, path, params, ("path",))
    if "path" not in params:
        report.missing((*path, "path"), "give the mesh file, relative to the scene file")
        return _BAD
    name = params["path"]
    if not isinstance(name, str) or not name:
        report.add((*path, "path"), name, "is not a file name", "give a path string such as 'model.obj'")
        return _BAD
    file = (base / name).resolve()
    if not file.is_file():
        report.add((*path, "path"), name, f"does not exist (looked for {file})",
                   "give a mesh file relative to the scene file's folder")  # fmt: skip
        return _BAD
    if len(params) > 1:
        return _BAD
    try:
        return loader(file)
    except FrustumError as error:
        report.refused((*path, "path"), name, error)
    except (OSError, ValueError, TypeError, IndexError, KeyError) as error:
        report.refused((*path, "path"), name, error)
    return _BAD


def _terrain(report: _Report, path: tuple, params: dict, fbm_terrain: Callable) -> Any:
    """fbm_terrain heights (times ``height_scale``) as a heightfield mesh ``size`` wide, centred, heights along +y."""
    size = params.pop("size", 1.0)
    height_scale = params.pop("height_scale", 1.0)
    size = _number(report, (*path, "size"), size, low=0.0, low_open=True)
    height_scale = _number(report, (*path, "height_scale"), height_scale)
    if "level" in params and _number(report, (*path, "level"), params["level"], low=0, high=10, integer=True) is _BAD:
        return _BAD
    heights = _call(report, path, fbm_terrain, params, label="terrain")
    if _bad(heights, size, height_scale):
        return _BAD
    try:
        mesh_builder = importlib.import_module("frustum.geometry.fractals").heightfield_mesh
        mesh = mesh_builder(np.asarray(heights) * height_scale, size)
        # heightfield_mesh is z-up over [0, size]²: centre it and turn the heights to +y (world up in scene files)
        return mesh.transformed(rotate_x(-math.pi / 2) @ translate(-size / 2, -size / 2, 0.0))
    except FrustumError as error:
        report.refused(path, params, error)
        return _BAD


def _lsystem(report: _Report, path: tuple, params: dict, lsystem_type: Any) -> Any:
    """An L-system (a ``preset`` from CLASSIC_LSYSTEMS or axiom/rules/angle_deg) expanded and swept into tubes."""
    module = importlib.import_module("frustum.geometry.lsystem")
    level = params.pop("level", 3)
    radius = params.pop("radius", 0.05)
    level = _number(report, (*path, "level"), level, low=0, high=12, integer=True)
    radius = _number(report, (*path, "radius"), radius, low=0.0, low_open=True)
    if "preset" in params:
        preset = _choice(report, (*path, "preset"), params.pop("preset"), sorted(module.CLASSIC_LSYSTEMS))
        _unknown_keys(report, path, params, ("level", "radius", "preset"))
        system = _BAD if preset is _BAD or params else module.CLASSIC_LSYSTEMS[preset]
    else:
        system = _call(report, path, lsystem_type, params, label="LSystem")
    if _bad(system, level, radius):
        return _BAD
    try:
        return module.tube_mesh(system.path(level), radius)
    except FrustumError as error:
        report.refused(path, params, error)
        return _BAD


# --- materials, lights, nodes -------------------------------------------------------------------------------


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


def _node(report: _Report, path: tuple, value: dict, base: Path, materials: dict, names: set) -> Any:
    _unknown_keys(report, path, value, _NODE_KEYS)
    name = value.get("name", "")
    if not isinstance(name, str) or "/" in name:
        report.add((*path, "name"), name, "is not a name", "give a string without '/' ('/' separates node paths)")
        name = ""
    transform = _transform(report, (*path, "transform"), value["transform"]) if "transform" in value else None
    material = None
    if "material" in value:
        material = _material_reference(report, (*path, "material"), value["material"], materials)
    geometry, extras = (None, [])
    if "geometry" in value:
        geometry, extras = _geometry(report, (*path, "geometry"), value["geometry"], base, materials)
    lights = _lights(report, (*path, "lights"), value["lights"]) if "lights" in value else []
    children = []
    for i, child in enumerate(_table_list(report, (*path, "children"), value.get("children", []))):
        built = _node(report, (*path, "children", i), dict(child), base, materials, names)
        if built is not _BAD:
            children.append(built)
    if _bad(transform, material, geometry):
        return _BAD
    try:
        return Node(name, transform, geometry, material, [*extras, *children], lights)
    except FrustumError as error:
        report.refused(path, name, error)
        return _BAD


# --- camera ------------------------------------------------------------------------------------------------


def _camera(report: _Report, path: tuple, value: Any, size: tuple[int, int]) -> Any:
    """A Camera (or a StereoCamera, with ``[camera.stereo]``) from a camera table."""
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    _unknown_keys(report, path, params, _CAMERA_KEYS)
    get = params.get
    target = _vector(report, (*path, "target"), get("target", [0.0, 0.0, 0.0]))
    placement = [key for key in ("eye", "view", "azimuth_deg") if key in params]
    if len(placement) > 1:
        report.add((*path, placement[1]), params[placement[1]], f"conflicts with {placement[0]}",
                   "place the camera by eye (with up), or by view (a multiview preset), or by azimuth_deg and "
                   "elevation_deg, not several")  # fmt: skip
        return _BAD
    how = placement[0] if placement else None
    up = _vector(report, (*path, "up"), get("up", [0.0, 1.0, 0.0]))
    eye: Any = _BAD
    if how == "view":
        view = _choice(report, (*path, "view"), params["view"], sorted(MULTIVIEWS))
        distance = _number(report, (*path, "distance"), get("distance", 10.0), low=0.0, low_open=True)
        if "up" in params:
            report.add((*path, "up"), params["up"], "conflicts with view", "a multiview preset fixes its own up vector")
            up = _BAD
        if not _bad(view, distance, target, up):
            preset = MULTIVIEWS[view]
            eye = list(np.array(target) - distance * np.array(preset.direction))
            up = list(preset.up)
    elif how == "azimuth_deg":
        azimuth = _number(report, (*path, "azimuth_deg"), params["azimuth_deg"])
        elevation = _number(report, (*path, "elevation_deg"), get("elevation_deg", 0.0), low=-89.999, high=89.999)
        distance = _number(report, (*path, "distance"), get("distance", 10.0), low=0.0, low_open=True)
        if not _bad(azimuth, elevation, distance, target):
            a, e = math.radians(azimuth), math.radians(elevation)
            offset = distance * np.array([math.cos(e) * math.sin(a), math.sin(e), math.cos(e) * math.cos(a)])
            eye = list(np.array(target) + offset)
    elif how == "eye":
        eye = _vector(report, (*path, "eye"), params["eye"])
        if "distance" in params:
            report.add((*path, "distance"), params["distance"], "conflicts with eye",
                       "distance goes with view or azimuth_deg; eye fixes it already")  # fmt: skip
    else:
        report.missing((*path, "eye"), "place the camera with eye = [x, y, z], view = 'front' or azimuth_deg")
    if "elevation_deg" in params and how != "azimuth_deg":
        report.add((*path, "elevation_deg"), params["elevation_deg"], "needs azimuth_deg",
                   "give azimuth_deg too, or place the camera by eye")  # fmt: skip
    placed = not _bad(eye, up, target)
    distance = float(np.linalg.norm(np.array(target) - np.array(eye))) if placed else 10.0
    if placed:
        line_of_sight = np.array(target) - np.array(eye)
        if distance == 0.0:
            report.add((*path, "eye"), eye, "equals target", "the eye must not sit on the point it looks at")
            placed = False
        elif not np.linalg.norm(up) > 0.0:
            report.add((*path, "up"), up, "has zero length", "give a nonzero view-up vector such as [0, 1, 0]")
            placed = False
        elif np.linalg.norm(np.cross(np.array(up), line_of_sight)) <= 1e-9 * distance * np.linalg.norm(up):
            report.add((*path, "up"), up, f"is parallel to the view direction {describe(line_of_sight / distance)}",
                       "choose an up vector not along target - eye")  # fmt: skip
            placed = False
    projection = _projection(report, path, params, distance if distance > 0.0 else 10.0, how == "view")
    if projection is _BAD or not placed:
        return _BAD
    try:
        camera = Camera.look_at(eye, target, up, projection, *size)
    except FrustumError as error:
        report.refused(path, params, error)
        return _BAD
    if "stereo" in params:
        return _stereo(report, (*path, "stereo"), params["stereo"], camera, distance)
    return camera


def _projection(report: _Report, path: tuple, params: dict, distance: float, multiview: bool) -> Any:
    name = params.get("projection", "orthographic" if multiview else "perspective")
    name = _choice(report, (*path, "projection"), name, PROJECTIONS)
    if name is _BAD:
        return _BAD
    parallel = name not in ("perspective", "frustum")
    used = {"projection", "near", "far"}
    near = _number(report, (*path, "near"), params.get("near", 0.1))
    far = _number(report, (*path, "far"), params.get("far", max(100.0, 4.0 * distance)))
    # parallel views default to the window a 45° perspective shows at the target: switching keeps the framing
    height: Any = 2.0 * distance * math.tan(math.radians(22.5))
    if parallel:
        used.add("height")
        height = _number(report, (*path, "height"), params.get("height", height), low=0.0, low_open=True)
    specific = {
        "perspective": ("fovy_deg",),
        "frustum": ("left", "right", "bottom", "top"),
        "oblique": ("alpha_deg", "phi_deg", "z_vp"),
        "cavalier": ("phi_deg", "z_vp"),
        "cabinet": ("phi_deg", "z_vp"),
        "isometric": ("pivot",),
        "dimetric": ("ratio", "pivot"),
        "trimetric": ("rotation_y_deg", "rotation_x_deg", "pivot"),
        "orthographic": (),
    }[name]
    used.update(specific)
    for key in ("fovy_deg", "left", "right", "bottom", "top", "alpha_deg", "phi_deg", "z_vp", "ratio",
                "rotation_y_deg", "rotation_x_deg", "pivot", "height"):  # fmt: skip
        if key in params and key not in used:
            report.add((*path, key), params[key], f"does not apply to projection = {name!r}",
                       f"{name} takes {', '.join(sorted(used - {'projection'}))}")  # fmt: skip
    if not _is_number(near) or not _is_number(far) or not _is_number(height):
        return _BAD
    if not parallel and not near > 0.0:
        report.add((*path, "near"), near, "must be > 0", "near and far are positive distances, near < far")
        return _BAD
    if not far > near:
        report.add((*path, "far"), far, f"is not beyond near = {near!r}", "expected near < far")
        return _BAD
    values: dict[str, Any] = {}
    for key in specific:
        if key in params:
            values[key] = _number(report, (*path, key), params[key])
    if _bad(*values.values()):
        return _BAD
    degrees = {k[:-4]: math.radians(v) for k, v in values.items() if k.endswith("_deg")}
    plain = {k: v for k, v in values.items() if not k.endswith("_deg")}
    try:
        if name == "perspective":
            fovy = degrees.get("fovy", math.radians(45.0))
            if not 0.0 < fovy < math.pi:
                report.add((*path, "fovy_deg"), params.get("fovy_deg"), "is out of range",
                           "expected 0 < fovy_deg < 180")  # fmt: skip
                return _BAD
            return Perspective(fovy, near, far)
        if name == "frustum":
            missing = [key for key in specific if key not in plain]
            for key in missing:
                report.missing((*path, key), "a frustum projection needs left, right, bottom, top (near window)")
            return _BAD if missing else Frustum(plain["left"], plain["right"], plain["bottom"], plain["top"], near, far)
        if name == "orthographic":
            return Orthographic(height, near, far)
        z_vp = plain.get("z_vp", -distance)
        if name in ("oblique", "cavalier", "cabinet"):
            phi = degrees.get("phi", math.radians(45.0))
            alpha = {"cavalier": math.pi / 4, "cabinet": math.atan(2.0)}.get(name, degrees.get("alpha"))
            if alpha is None:
                report.missing((*path, "alpha_deg"), "an oblique projection needs alpha_deg (45: cavalier)")
                return _BAD
            return Oblique(alpha, phi, height, near, far, z_vp)
        pivot = plain.get("pivot", distance)
        if name == "isometric":
            return dataclasses.replace(Axonometric.isometric(height, near, far), pivot=pivot)
        if name == "dimetric":
            if "ratio" not in plain:
                report.missing((*path, "ratio"), "a dimetric projection needs ratio (f_y / f_x in (0, sqrt 2))")
                return _BAD
            return dataclasses.replace(Axonometric.dimetric(plain["ratio"], height, near, far), pivot=pivot)
        missing = [key for key in ("rotation_y_deg", "rotation_x_deg") if key not in values]
        for key in missing:
            report.missing((*path, key), "a trimetric projection needs rotation_y_deg and rotation_x_deg")
        if missing:
            return _BAD
        return Axonometric(degrees["rotation_y"], degrees["rotation_x"], height, near, far, pivot)
    except FrustumError as error:
        report.refused((*path, "projection"), name, error)
        return _BAD


def _stereo(report: _Report, path: tuple, value: Any, camera: Camera, distance: float) -> Any:
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    _unknown_keys(report, path, params, _STEREO_KEYS)
    stereo_module, images = _stereo_modules()
    if stereo_module is None:
        report.add(path, params, "is not available in this version", "frustum.stereo is missing")
        return _BAD
    separation = _number(report, (*path, "eye_separation"), params.get("eye_separation", distance / 30.0),
                         low=0.0, low_open=True)  # fmt: skip
    convergence = _number(report, (*path, "convergence_distance"), params.get("convergence_distance", distance),
                          low=0.0, low_open=True)  # fmt: skip
    layout = _choice(report, (*path, "layout"), params.get("layout", "anaglyph"), images.STEREO_LAYOUTS)
    method = _choice(report, (*path, "anaglyph_method"), params.get("anaglyph_method", "color"),
                     images.ANAGLYPH_METHODS)  # fmt: skip
    cross = _boolean(report, (*path, "cross_eyed"), params.get("cross_eyed", False))
    if _bad(separation, convergence, layout, method, cross):
        return _BAD
    try:
        stereo = stereo_module.StereoCamera(camera, separation, convergence)
    except FrustumError as error:
        report.refused(path, params, error)
        return _BAD
    return _Stereo(stereo, layout, method, cross)


def _stereo_modules() -> tuple[Any, Any]:
    """(frustum.stereo, the stereo image module) or (None, None) where this version has no stereo."""
    for images_name in ("frustum.output.stereo", "frustum.stereo_images"):
        try:
            return importlib.import_module("frustum.stereo"), importlib.import_module(images_name)
        except ImportError:
            continue
    return None, None


@dataclass(frozen=True)
class _Stereo:
    """A stereo camera with its image layout."""

    camera: Any  # frustum.stereo.StereoCamera
    layout: str
    anaglyph_method: str
    cross_eyed: bool


# --- render options, exploded/cutaway, outputs -------------------------------------------------------------


def _render_options(report: _Report, path: tuple, value: Any) -> tuple[dict, tuple[int, int], int]:
    params = _table(report, path, value)
    if params is _BAD:
        return {}, _DEFAULT_SIZE, 0
    _unknown_keys(report, path, params, _RENDER_KEYS)
    options: dict[str, Any] = {}
    size = _DEFAULT_SIZE
    if "size" in params:
        checked = _vector(report, (*path, "size"), params["size"], 2, "width, height")
        if checked is not _BAD and not all(c.is_integer() and 1 <= c <= _MAX_PIXELS for c in checked):
            report.add((*path, "size"), params["size"], "is not two positive integer pixel counts",
                       f"give [width, height], integers in [1, {_MAX_PIXELS}]")  # fmt: skip
        elif checked is not _BAD:
            size = (int(checked[0]), int(checked[1]))
    simple: dict[str, Callable[[tuple, Any], Any]] = {
        "shading": lambda p, v: _choice(report, p, v, tuple(SHADING_MODES)),
        "specular": lambda p, v: _choice(report, p, v, ("blinn-phong", "phong")),
        "background": lambda p, v: _color(report, p, v, alpha=True),
        "cull_back_faces": lambda p, v: _boolean(report, p, v),
        "mode": lambda p, v: _choice(report, p, v, RENDER_MODES),
        "edges": lambda p, v: _choice(report, p, v, ("all", "feature")),
        "edge_color": lambda p, v: _color(report, p, v, alpha=True),
        "hidden": lambda p, v: _choice(report, p, v, ("dimmed", "dashed")),
        "hidden_color": lambda p, v: _color(report, p, v, alpha=True),
        "line_width": lambda p, v: _number(report, p, v, low=1.0, high=64.0),
        "samples": lambda p, v: _number(report, p, v, low=1, high=64, integer=True),
        "filter": lambda p, v: _choice(report, p, v, ("box", "tent")),
        "color_space": lambda p, v: _choice(report, p, v, ("linear", "srgb")),
        "method": lambda p, v: _choice(report, p, v, tuple(RENDER_METHODS)),
        "transparency": lambda p, v: _choice(report, p, v, TRANSPARENCY_MODES),
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


# --- volumes ---------------------------------------------------------------------------------------------

_VOLUME_KEYS = ("source", "transfer_function", "mode", "transform", "step", "level", "shade", "material",
                "clip_planes", "sampling")  # fmt: skip
_VOLUME_SOURCES = {"file": "load", "fbm_cloud": "fbm_cloud", "quaternion_julia": "quaternion_julia_volume",
                   "blobby": "blobby_volume", "head_phantom": "head_phantom"}  # fmt: skip
_TRANSFER_KEYS = ("preset", "colormap", "range", "opacity", "values", "colors", "opacities")


def _volume(report: _Report, path: tuple, value: dict, base: Path, materials: dict, scene: Scene) -> None:
    """One ``[[volumes]]`` table: ``source = { type = ..., ... }``, a transfer function, the mode and options,
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
    ``{ values = [...], colors = [[r, g, b], ...], opacities = [...] }`` (range optional)."""
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


def _check_image_memory(report: _Report, options: dict, size: tuple[int, int], cameras: int) -> None:
    """The image budget (``render._check_image_budget``'s estimate) at load time, so the error has file:line:
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


def _explode_and_cut(report: _Report, data: dict, scene: Scene) -> Scene:
    if "exploded" in data:
        path = ("exploded",)
        params = _table(report, path, data["exploded"])
        if params is not _BAD:
            _unknown_keys(report, path, params, ("factor", "center", "node"))
            factor = _number(report, (*path, "factor"), params.get("factor", 0.5), low=0.0)
            center = None
            if "center" in params:
                center = _vector(report, (*path, "center"), params["center"])
            node_path = params.get("node")
            if factor is not _BAD and center is not _BAD:
                try:
                    if node_path is None:
                        scene = exploded(scene, factor, center)  # type: ignore[assignment]
                    else:
                        _explode_node(scene, str(node_path), factor, center)
                except FrustumError as error:
                    report.refused((*path, "node") if node_path is not None else path, node_path, error)
    if "cutaway" in data:
        path = ("cutaway",)
        params = _table(report, path, data["cutaway"])
        if params is not _BAD:
            scene = _cut(report, path, params, scene)
    return scene


def _explode_node(scene: Scene, node_path: str, factor: float, center: Any) -> None:
    node = scene.find(node_path)
    parent_path = node_path.strip("/").rsplit("/", 1)[0] if "/" in node_path.strip("/") else ""
    parent = scene.find(parent_path) if parent_path else scene.root
    replacement = exploded(node, factor, center)
    parent.children[parent.children.index(node)] = replacement  # type: ignore[assignment]


def _cut(report: _Report, path: tuple, params: dict, scene: Scene) -> Scene:
    _unknown_keys(report, path, params, ("plane_point", "plane_normal", "box_min", "box_max", "cap", "ghost"))
    has_plane = "plane_point" in params or "plane_normal" in params
    has_box = "box_min" in params or "box_max" in params
    if has_plane == has_box:
        report.add(path, params, "needs exactly one cut", "give plane_point and plane_normal, or box_min and box_max")
        return scene
    keys = ("plane_point", "plane_normal") if has_plane else ("box_min", "box_max")
    values = []
    for key in keys:
        if key not in params:
            report.missing((*path, key), f"give both {keys[0]} and {keys[1]}")
            values.append(_BAD)
        else:
            values.append(_vector(report, (*path, key), params[key]))
    cap = _boolean(report, (*path, "cap"), params.get("cap", True))
    ghost = None
    if "ghost" in params:
        ghost = _number(report, (*path, "ghost"), params["ghost"], low=0.0, high=1.0, low_open=True)
        if ghost == 1.0:
            report.add((*path, "ghost"), ghost, "is out of range", "expected an opacity in (0, 1)")
            ghost = _BAD
    if _bad(*values, cap, ghost):
        return scene
    try:
        if has_plane:
            return cutaway(scene, plane=(values[0], values[1]), cap=cap, ghost=ghost)
        return cutaway(scene, box=(values[0], values[1]), cap=cap, ghost=ghost)
    except (FrustumError, ImportError, ValueError, IndexError) as error:  # trimesh's capping may need rtree
        report.refused(path, params, error)
        return scene


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


# --- simulations: [[particles]] and [[cloth]] ---------------------------------------------------------------

_EMITTERS = {"point": "PointEmitter", "line": "LineEmitter", "disk": "DiskEmitter", "sphere": "SphereEmitter"}
_FORCES = {"gravity": "Gravity", "drag": "Drag", "wind": "Wind", "vortex": "Vortex", "attractor": "Attractor"}
_COLLIDERS = {"plane": "PlaneCollider", "sphere": "SphereCollider"}
_PARTICLE_KEYS = ("emitter", "forces", "colliders", "style", "blending")
_CLOTH_KEYS = ("material", "colliders", "name")


def _typed(report: _Report, path: tuple, value: Any, kinds: dict[str, str]) -> Any:
    """``{ type = "...", ... }`` → the simulation class of that type built from the other keys."""
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    kind = params.pop("type", None)
    if kind not in kinds:
        report.add((*path, "type"), kind, "is unknown" if kind is not None else "is missing",
                   f"expected one of {', '.join(repr(k) for k in kinds)}")  # fmt: skip
        return _BAD
    simulation = importlib.import_module("frustum.simulation")
    return _call(report, path, getattr(simulation, kinds[kind]), params, label=kinds[kind])


def _typed_list(report: _Report, path: tuple, value: Any, kinds: dict[str, str]) -> Any:
    if not isinstance(value, list):
        report.add(path, value, "is not a list of tables", "write e.g. [{ type = ... }, ...]")
        return _BAD
    built = [_typed(report, (*path, i), item, kinds) for i, item in enumerate(value)]
    return _BAD if any(item is _BAD for item in built) else built


def _simulations(report: _Report, data: dict, scene: Scene, materials: dict) -> None:
    """``[[particles]]`` (a ParticleSystem with its emitter, forces, colliders, style, blending) and ``[[cloth]]``
    (``frustum.cloth`` with its material and colliders) added to `scene`; ``[animation].warmup`` steps them."""
    if "particles" not in data and "cloth" not in data:
        return  # nothing to simulate: frustum.simulation is not loaded
    simulation = importlib.import_module("frustum.simulation")
    for i, entry in enumerate(_table_list(report, ("particles",), data.get("particles", []))):
        path, params = ("particles", i), dict(entry)
        if "emitter" not in params:
            report.missing((*path, "emitter"), "give an emitter = { type = 'point', position = [x, y, z] }")
            continue
        emitter = _typed(report, (*path, "emitter"), params["emitter"], _EMITTERS)
        forces = _typed_list(report, (*path, "forces"), params.get("forces", []), _FORCES)
        colliders = _typed_list(report, (*path, "colliders"), params.get("colliders", []), _COLLIDERS)
        style = _choice(report, (*path, "style"), params.get("style", "sprites"), ("sprites", "points", "streaks"))
        blending = _choice(report, (*path, "blending"), params.get("blending", "additive"), ("additive", "alpha"))
        if _bad(emitter, forces, colliders, style, blending):
            continue
        build = functools.partial(simulation.ParticleSystem, emitter=emitter, forces=forces, colliders=colliders)
        system = _call(report, path, build, params, label="ParticleSystem", skip=_PARTICLE_KEYS)
        if system is not _BAD:
            scene.add_particles(system, style=style, blending=blending)
    for i, entry in enumerate(_table_list(report, ("cloth",), data.get("cloth", []))):
        path, params = ("cloth", i), dict(entry)
        material = _material_reference(report, (*path, "material"), params["material"], materials) \
            if "material" in params else None  # fmt: skip
        colliders = _typed_list(report, (*path, "colliders"), params.get("colliders", []), _COLLIDERS)
        name = params.get("name", "")
        if not isinstance(name, str):
            report.add((*path, "name"), name, "is not a string", "give a node name in quotes")
            continue
        if _bad(material, colliders):
            continue
        build = functools.partial(simulation.cloth, colliders=colliders)
        system = _call(report, path, build, params, label="cloth", skip=_CLOTH_KEYS)
        if system is not _BAD:
            scene.add_mass_spring(system, material, name=name)


def _warm_up(report: _Report, scene: Scene, animation: dict) -> None:
    """Step the simulations ``[animation].warmup`` seconds (in steps of ``1/(fps·substeps)``) before any frame."""
    warmup = animation.get("warmup", 0.0)
    if not warmup or not (scene.particle_layers or scene.mass_springs):
        return
    step_scene = importlib.import_module("frustum.output.simulate").step_scene
    dt = 1.0 / (animation.get("fps", 12.0) * animation.get("substeps", 1))
    try:
        step_scene(scene, dt, round(warmup / dt))
    except FrustumError as error:
        report.refused(("animation", "warmup"), warmup, error)


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
                        if not check:  # not written (the caller writes elsewhere): not refused either
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


# --- the public API ------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class SceneFile:
    """A loaded scene file: the scene, its camera(s), render options and where to write.

    Attributes
    ----------
    scene : Scene
        Lights, materials and the node hierarchy, exploded and cut away as the file asks.
    camera : Camera or None
        The ``[camera]`` (for a stereo file, the centre camera); None when the file has ``[[cameras]]``.
    options : dict
        Keyword arguments for ``frustum.render`` (shading, mode, depth_cue, samples, ...).
    outputs : tuple of Path
        ``[output].files``, resolved against the scene file's folder (may be empty).
    cameras : tuple of Camera
        Every camera: ``(camera,)`` or the ``[[cameras]]`` list, rendered side by side in `columns` columns.
    stereo : object or None
        ``(camera, layout, anaglyph_method, cross_eyed)`` when ``[camera.stereo]`` is given; ``camera`` is a
        ``frustum.stereo.StereoCamera``.
    animation, svg : dict
        ``[animation]`` (frames, fps, axis) and ``[svg]`` (``render_svg`` keywords) settings.
    size : (int, int)
        Image width and height of each camera.
    """

    scene: Scene
    camera: Camera | None
    options: dict
    outputs: tuple[Path, ...]
    cameras: tuple[Camera, ...] = ()
    stereo: Any = None
    animation: dict = field(default_factory=dict)
    svg: dict = field(default_factory=dict)
    size: tuple[int, int] = _DEFAULT_SIZE
    columns: int = 0
    title: str = ""
    path: Path | None = None

    def resized(self, size: tuple[int, int]) -> SceneFile:
        """The same scene file with every camera's image `size` = (width, height) replaced."""
        where = "SceneFile.resized"
        if (
            not isinstance(size, tuple | list)
            or len(size) != 2
            or not all(isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= _MAX_PIXELS for v in size)
        ):
            raise OutputError(f"{where}: size = {describe(size)} is not (width, height); give two positive integers")
        width, height = int(size[0]), int(size[1])
        cameras = tuple(dataclasses.replace(c, width=width, height=height) for c in self.cameras)
        stereo = self.stereo
        if stereo is not None:
            centre = dataclasses.replace(stereo.camera.camera, width=width, height=height)
            rebuilt = type(stereo.camera)(centre, stereo.camera.eye_separation, stereo.camera.convergence_distance)
            stereo = dataclasses.replace(stereo, camera=rebuilt)
        camera = None if self.camera is None else cameras[0]
        return dataclasses.replace(self, camera=camera, cameras=cameras, stereo=stereo, size=(width, height))

    def render(self) -> Frame:
        """The PNG image: the stereo layout, the cameras side by side, or the one camera's frame."""
        if self.stereo is not None:
            render_stereo = _stereo_modules()[1].render_stereo
            return render_stereo(self.scene, self.stereo.camera, self.stereo.layout,
                                 anaglyph_method=self.stereo.anaglyph_method, cross_eyed=self.stereo.cross_eyed,
                                 **self.options)  # fmt: skip
        frames = [render(self.scene, camera, **self.options) for camera in self.cameras]
        if len(frames) == 1:
            return frames[0]
        return _tile(frames, self.columns or len(frames), self.options.get("background", (0.0, 0.0, 0.0, 1.0)))


def _tile(frames: list[Frame], columns: int, background: Sequence[float]) -> Frame:
    """Frames of one size laid out in rows of `columns` (the last row padded with background, depth 1)."""
    rows = -(-len(frames) // columns)
    h, w = frames[0].height, frames[0].width
    fill = np.rint(np.clip(np.array([*background, 1.0][:4]), 0.0, 1.0) * 255).astype(np.uint8)
    color = np.empty((rows * h, columns * w, 4), dtype=np.uint8)
    color[...] = fill
    depth = np.ones((rows * h, columns * w), dtype=np.float32)
    for k, frame in enumerate(frames):
        r, c = divmod(k, columns)
        color[r * h : (r + 1) * h, c * w : (c + 1) * w] = frame.color
        depth[r * h : (r + 1) * h, c * w : (c + 1) * w] = frame.depth
    return Frame(color, depth)


def load_scene(
    data: Mapping[str, Any] | str, *, source: str = "<scene>", base_dir: str | Path = ".", check_outputs: bool = True
) -> SceneFile:
    """Validate and build a scene from TOML text or an already parsed dictionary.

    Every problem is collected first; then one ``SceneFileError`` lists them all, one per line, as
    ``source:line: key = value problem; what is valid`` (no line numbers for a dictionary).

    Parameters
    ----------
    data : str or mapping
        TOML text, or the dictionary ``tomllib.loads`` would return.
    source : str
        The name errors start with (the file name).
    base_dir : str or Path
        Folder that relative paths (mesh files, outputs) are resolved against.
    check_outputs : bool
        True (default): ``[output].files`` outside `base_dir` are refused. False, for a caller that writes
        elsewhere (``frustum render FILE -o ...``): they are not written, so they are left out of ``outputs``.

    Raises
    ------
    SceneFileError
        Malformed TOML (tomllib's own line and column), or any invalid key or value.
    """
    lines: dict[tuple, int] | str | None = None
    if isinstance(data, str):
        _check_shape(data, source)
        try:
            parsed = tomllib.loads(data)
        except tomllib.TOMLDecodeError as error:
            found = re.search(r"at line (\d+), column (\d+)", str(error))
            at = f"{escape_control(source)}:{found.group(1)}" if found else escape_control(source)
            raise SceneFileError(
                f"{at}: the text is not valid TOML: {escape_control(str(error))}; fix the syntax there"
            ) from None
        except RecursionError:
            raise SceneFileError(f"{escape_control(source)}: the text nests too deeply to parse; "
                                 f"nest arrays and tables at most {_MAX_NESTING} deep") from None  # fmt: skip
        lines = data  # the key-line scan (linear, but slow in Python) runs only if a problem is reported
    elif isinstance(data, Mapping):
        parsed = dict(data)
    else:
        raise SceneFileError(f"{source}: data = {describe(data)} is not TOML text or a table; give a str or a dict")
    report = _Report(source, lines)
    scene_file = _build(report, parsed, Path(base_dir), check_outputs)
    report.raise_if_any()
    assert scene_file is not None
    return dataclasses.replace(scene_file, path=None)


_TOKENS = re.compile(r'"""|\'\'\'|"(?:\\.|[^"\\\n])*"|\'[^\'\n]*\'|#[^\n]*|[\[\]{}]|\n')
_DOTTED = re.compile(r"(?:(?:[A-Za-z0-9_-]+|\"[^\"\n]*\"|'[^'\n]*')[ \t]*\.[ \t]*){" + str(_MAX_NESTING) + "}")


def _check_shape(text: str, source: str) -> None:
    """Refuse text the TOML parser and the key-line scanner would take very long (or recurse too deep) on.

    One linear pass over the tokens outside strings and comments: the depth of ``[`` / ``{``, then dotted
    keys of more than `_MAX_NESTING` parts in the text with its strings blanked; the ``SceneFileError`` names
    the line.
    """
    where = escape_control(source)
    depth, line, multiline = 0, 1, None
    code: list[str] = []  # the text with strings emptied and comments dropped (newlines kept)
    last = 0
    for token in _TOKENS.finditer(text):
        value = token.group()
        if multiline is None:
            code.append(text[last : token.start()])
        last = token.end()
        if value == "\n":
            line += 1
            code.append("\n")
        elif multiline is not None:  # inside a multi-line string: only its closing quotes matter
            if value == multiline:
                multiline = None
                code.append('""')
        elif value in ('"""', "\'\'\'"):
            multiline = value
        elif value in "[{":
            code.append(value)
            depth += 1
            if depth > _MAX_NESTING:
                raise SceneFileError(f"{where}:{line}: arrays or tables nest more than {_MAX_NESTING} deep here; "
                                     f"nest them at most {_MAX_NESTING} deep")  # fmt: skip
        elif value in "]}":
            code.append(value)
            depth = max(depth - 1, 0)
        elif value[0] in "\"'":
            code.append('""')
    if multiline is None:
        code.append(text[last:])
    stripped = "".join(code)
    dotted = _DOTTED.search(stripped)
    if dotted:
        line = stripped.count("\n", 0, dotted.start()) + 1
        raise SceneFileError(f"{where}:{line}: a dotted key has more than {_MAX_NESTING} parts; write at most "
                             f"{_MAX_NESTING} levels of tables")  # fmt: skip


def _build(report: _Report, data: dict, base: Path, check_outputs: bool = True) -> SceneFile | None:
    _unknown_keys(report, (), data, _TOP_LEVEL)
    for key in ("title", "description"):
        if key in data and not isinstance(data[key], str):
            report.add((key,), data[key], "is not a string", "give text in quotes")
    options, size, columns = _render_options(report, ("render",), data.get("render", {}))
    materials: dict[str, Material] = {}
    if "materials" in data:
        table = _table(report, ("materials",), data["materials"])
        for name, value in table.items() if table is not _BAD else ():
            material = _material(report, ("materials", name), value)
            if material is not _BAD:
                materials[name] = material
    scene = Scene(_lights(report, ("lights",), data.get("lights", [])))
    names: set[str] = set()
    for i, value in enumerate(_table_list(report, ("nodes",), data.get("nodes", []))):
        node = _node(report, ("nodes", i), dict(value), base, materials, names)
        if node is not _BAD:
            scene.add(node)
    for i, value in enumerate(_table_list(report, ("volumes",), data.get("volumes", []))):
        _volume(report, ("volumes", i), dict(value), base, materials, scene)
    scene = _explode_and_cut(report, data, scene)
    _simulations(report, data, scene, materials)
    cameras: list[Camera] = []
    stereo = None
    if "camera" in data and "cameras" in data:
        report.add(("cameras",), "[[cameras]]", "conflicts with [camera]", "give one camera or a list, not both")
    elif "cameras" in data:
        entries = _table_list(report, ("cameras",), data["cameras"])
        if not entries and isinstance(data["cameras"], list):
            report.add(("cameras",), [], "is empty", "give at least one [[cameras]] table")
        for i, entry in enumerate(entries):
            if "stereo" in entry:
                report.add(("cameras", i, "stereo"), entry["stereo"], "is not allowed in [[cameras]]",
                           "stereo goes with a single [camera]")  # fmt: skip
                continue
            camera = _camera(report, ("cameras", i), entry, size)
            if camera is not _BAD:
                cameras.append(camera)
    elif "camera" in data:
        camera = _camera(report, ("camera",), data["camera"], size)
        if isinstance(camera, _Stereo):
            stereo, camera = camera, camera.camera.camera
        if camera is not _BAD:
            cameras.append(camera)
    else:
        report.missing(("camera",), "add a [camera] table with eye and target (or [[cameras]])")
    outputs, animation, svg = _outputs(report, data, base, check_outputs)
    _check_image_memory(report, options, size, max(len(cameras), 1))
    if not report.problems:
        _warm_up(report, scene, animation)
    if report.problems:
        return None
    title = data.get("title", "")
    single = cameras[0] if "camera" in data else None
    return SceneFile(scene, single, options, outputs, tuple(cameras), stereo, animation, svg, size, columns, title)


def load_scene_file(path: str | Path, *, check_outputs: bool = True) -> SceneFile:
    """Read, validate and build the TOML scene file at `path` (relative paths inside resolve against its folder).

    ``check_outputs=False``: ``[output].files`` outside the file's folder are not refused (see ``load_scene``).

    Raises
    ------
    SceneFileError
        If the file cannot be read, is not valid TOML, or has invalid keys or values; the message lists every
        problem as ``file:line: key = value problem; what is valid``.
    """
    file = Path(path)
    shown = escape_control(str(file))
    try:
        with open(file, "rb") as handle:
            raw = handle.read(MAX_SCENE_FILE_BYTES + 1)  # /dev/zero or a huge file: stop at the cap
        if len(raw) > MAX_SCENE_FILE_BYTES:
            raise SceneFileError(f"{shown}: is larger than {MAX_SCENE_FILE_BYTES // 2**20} MiB; a scene file "
                                 "describes a scene (put large data in mesh files it names)")  # fmt: skip
        text = raw.decode("utf-8")
    except (OSError, UnicodeDecodeError) as error:
        reason = getattr(error, "strerror", None) or str(error)
        raise SceneFileError(f"{shown}: cannot be read ({reason}); give an existing UTF-8 TOML scene file") from None
    scene_file = load_scene(text, source=str(file), base_dir=file.parent, check_outputs=check_outputs)
    return dataclasses.replace(scene_file, path=file)


def _write(scene_file: SceneFile, target: Path) -> Path:
    suffix = target.suffix.lower()
    if suffix not in OUTPUT_SUFFIXES:
        raise OutputError(
            f"render_scene_file: output = {str(target)!r} has suffix {suffix!r}; expected one of "
            f"{', '.join(OUTPUT_SUFFIXES)}"
        )
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise OutputError(f"render_scene_file: output folder {str(target.parent)!r} cannot be made ({error})") from None
    if suffix == ".png":
        scene_file.render().save(target)
        return target
    camera = scene_file.cameras[0]
    if suffix in (".svg", ".pdf"):
        try:
            svg = importlib.import_module("frustum.output.svg")
        except ImportError:
            raise OutputError("render_scene_file: SVG/PDF output is not available in this version") from None
        text = svg.render_svg(scene_file.scene, camera, **scene_file.svg)
        return Path(svg.save_svg(text, target))
    if scene_file.stereo is not None or len(scene_file.cameras) > 1:
        raise OutputError(
            f"render_scene_file: output = {str(target)!r} is an animation, but the file has a stereo camera or "
            "several cameras; animate a file with a single [camera]"
        )
    try:
        animation = importlib.import_module("frustum.output.animation")
    except ImportError:
        raise OutputError("render_scene_file: GIF/MP4 output is not available in this version") from None
    settings = {"frames": 36, "fps": 12.0, **scene_file.animation}
    if scene_file.scene.particle_layers or scene_file.scene.mass_springs:  # [[particles]] / [[cloth]]: simulate
        simulate = importlib.import_module("frustum.output.simulate").simulate
        simulate(scene_file.scene, camera, int(settings["frames"]), fps=settings["fps"],
                 substeps=int(settings.get("substeps", 1)), path=target, progress=False,
                 **scene_file.options)  # fmt: skip
        return target
    animation.turntable(scene_file.scene, camera, settings["frames"], settings.get("axis"), target,
                        settings["fps"], progress=False, **scene_file.options)  # fmt: skip
    return target


def render_scene_file(
    path: str | Path, output: str | Path | Sequence[str | Path] | None = None, *, size: tuple[int, int] | None = None
) -> Path | list[Path]:
    """Render the scene file at `path` and write it by suffix: PNG, SVG or PDF (line drawing), GIF or MP4 (turntable).

    Parameters
    ----------
    path : str or Path
        A TOML scene file.
    output : str, Path, a sequence of them, or None
        Where to write. None: the file's ``[output].files``, or ``out/<stem>.png`` next to the scene file.
    size : (int, int), optional
        Image width and height, replacing ``[render].size``.

    Returns
    -------
    Path or list of Path
        The file written (a list when several were asked for, or the file's ``[output].files`` list).

    Raises
    ------
    SceneFileError
        For an invalid scene file (every problem listed).
    OutputError
        For an unknown output suffix or an unwritable path; ``FrustumError`` from the renderer for options it
        refuses.
    """
    scene_file = load_scene_file(path, check_outputs=output is None)  # with `output` the file's are not written
    if size is not None:
        scene_file = scene_file.resized(tuple(size))  # type: ignore[arg-type]
    if output is None:
        targets = list(scene_file.outputs) or [Path(path).parent / "out" / (Path(path).stem + ".png")]
        single = not scene_file.outputs
    elif isinstance(output, str | Path):
        targets, single = [Path(output)], True
    else:
        targets, single = [Path(o) for o in output], False
    written = [_write(scene_file, target) for target in targets]
    return written[0] if single else written


def render_view_sheet(
    path: str | Path, output: str | Path, views: Sequence[str] = ("front", "top", "right", "isometric"), **options: Any
) -> Path:
    """An engineering drawing sheet (``drawing_sheet``) of the scene file's scene: SVG, or PDF/PNG by suffix.

    ``views`` accepts "iso" for "isometric". Other keywords go to ``drawing_sheet`` (scale, paper, title, ...).
    """
    scene_file = load_scene_file(path)
    try:
        sheet = importlib.import_module("frustum.output.sheet")
        svg = importlib.import_module("frustum.output.svg")
    except ImportError:
        raise OutputError("render_view_sheet: drawing sheets are not available in this version") from None
    names = ["isometric" if v == "iso" else v for v in views]
    options.setdefault("title", scene_file.title)
    text = sheet.drawing_sheet(scene_file.scene, names, **options)
    target = Path(output)
    target.parent.mkdir(parents=True, exist_ok=True)
    return Path(svg.save_svg(text, target))


def explain_scene_file(path: str | Path, point: Sequence[float] | None = None) -> Any:
    """``frustum.trace`` of `point` (world coordinates) or, without one, of every vertex, through the file's camera.

    Returns
    -------
    frustum.trace.Trace
        Every stage's matrix and coordinates; ``str()``, ``to_markdown()``, ``to_latex()`` print it.
    """
    scene_file = load_scene_file(path)
    try:
        trace = importlib.import_module("frustum.trace").trace
    except (ImportError, AttributeError):
        raise SceneFileError(f"{path}: explain is not available in this version (frustum.trace is missing)") from None
    camera = scene_file.cameras[0]
    if point is None:
        return trace(scene_file.scene, camera)
    return trace(np.asarray(point, dtype=float), camera)


def explain_method(path: str | Path, method: str) -> dict:
    """Render the scene file's first camera with the visible-surface `method` (``render(..., method=...)``, with
    the file's render options) and return ``Frame.stats``: what the method counted (spans and edge updates,
    areas per level, depth tests, fragments per pixel …) and, under ``"seconds"``, how long the render took.

    Raises
    ------
    SceneFileError
        For an invalid scene file.
    FrustumError
        For an unknown method (the message lists the valid ones).
    """
    import time

    scene_file = load_scene_file(path)
    render = importlib.import_module("frustum.render").render
    options = {key: value for key, value in scene_file.options.items() if key not in ("method", "stats")}
    start = time.perf_counter()
    frame = render(scene_file.scene, scene_file.cameras[0], method=method, stats=True, **options)
    stats = dict(frame.stats or {"method": method})
    stats["seconds"] = round(time.perf_counter() - start, 4)
    return stats


def render_examples(
    out_dir: str | Path = EXAMPLES_DIR / "out",
    size: tuple[int, int] | None = (320, 240),
    *,
    examples_dir: str | Path | None = None,
) -> list[Path]:
    """Render every ``*.toml`` of the example gallery to ``out_dir/<stem>.png`` (at `size`; None: each file's own).

    Raises
    ------
    OutputError
        If the gallery folder does not exist (an installed package has no examples: give `examples_dir`).
    """
    folder = Path(examples_dir) if examples_dir is not None else EXAMPLES_DIR
    files = sorted(folder.glob("*.toml"))
    if not files:
        raise OutputError(f"render_examples: examples_dir = {str(folder)!r} holds no *.toml scene files")
    out = Path(out_dir)
    return [render_scene_file(file, out / (file.stem + ".png"), size=size) for file in files]  # type: ignore[misc]
