"""Loading a scene file: the shape checks of hostile text (size, nesting, dotted keys), TOML parsing, every section
built with all problems reported at once (``_build``), and the ``SceneFile`` it returns."""

from __future__ import annotations

import dataclasses
import os
import re
import sys
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from frustum._arrays import describe, escape_control
from frustum.camera import Camera
from frustum.errors import OutputError, SceneFileError
from frustum.frame import Frame
from frustum.render import render
from frustum.scene import Scene
from frustum.scenefile.camera import _camera, _Stereo, _stereo_modules
from frustum.scenefile.checks import _table, _table_list, _unknown_keys
from frustum.scenefile.lights_materials import _environment, _lights, _material
from frustum.scenefile.models import default_lights
from frustum.scenefile.nodes import _explode_and_cut, _node
from frustum.scenefile.outputs import _DEFAULT_SIZE, _MAX_PIXELS, _check_image_memory, _outputs, _render_options
from frustum.scenefile.report import _BAD, _Report
from frustum.scenefile.sheet import _sheet_options
from frustum.scenefile.simulation import _simulations, _warm_up
from frustum.scenefile.volumes import _volume
from frustum.shading import Material

SCHEMA_PATH = Path(__file__).parent.parent / "scene.schema.json"
"""The JSON Schema (draft 2020-12) of the scene-file format (the loader checks more: see the module docstring)."""


MAX_SCENE_FILE_BYTES = 16 * 2**20
"""Largest scene file read (16 MiB): ``frustum render /dev/zero`` stops there instead of reading gigabytes."""


_MAX_NESTING = 64
"""Deepest nesting of arrays / inline tables, and most parts of a dotted key, a scene file may use."""


_TOP_LEVEL = (
    "title", "description", "camera", "cameras", "lights", "materials", "nodes", "render", "exploded", "cutaway",
    "output", "animation", "svg", "particles", "cloth", "volumes", "sheet", "environment", "radiosity",
)  # fmt: skip

RADIOSITY_KEYS = {"patch_size": float, "hemicube": int, "tolerance": float, "max_iterations": int, "shooter": float}
"""``[radiosity]``: the keywords of ``frustum.radiosity`` a scene file may set."""


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
    radiosity : dict or None
        ``[radiosity]`` (``frustum.radiosity`` keywords): when given, ``render`` lights the scene by radiosity first
        and draws the lit scene with ``shading="none"``.
    up : str or None
        A mesh file's up axis as it was loaded ("y" or "z"; ``load_scene_file(..., up=)``); None for a TOML scene.
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
    sheet: dict = field(default_factory=dict)
    radiosity: dict | None = None
    up: str | None = None

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
        if self.path is not None and self.path.suffix.lower() in MODEL_SUFFIXES and self.camera is not None:
            cameras = (Camera.fit(self.scene, -self.camera.frame.n, width=width, height=height),)  # keep it framed
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
        scene, options = self.scene, self.options
        if self.radiosity is not None:
            from frustum.render.radiosity import radiosity

            scene, options = radiosity(self.scene, **self.radiosity).scene, {**self.options, "shading": "none"}
        frames = [render(scene, camera, **options) for camera in self.cameras]
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
    data: Mapping[str, Any] | str | Path,
    *,
    source: str = "<scene>",
    base_dir: str | Path = ".",
    allow_read: Sequence[str | Path] = (),
) -> SceneFile:
    """Validate and build a scene from TOML text or an already parsed dictionary; or load a file: a ``Path``, or a
    one-line string ending in ``.toml`` or a mesh suffix (``MODEL_SUFFIXES``), goes to ``load_scene_file``.

    Every problem is collected first; then one ``SceneFileError`` lists them all, one per line, as
    $source:line: key = value problem; what is valid$ (no line numbers for a dictionary).

    Parameters
    ----------
    data : str, Path or mapping
        TOML text, or the dictionary ``tomllib.loads`` would return, or the path of a scene or mesh file.
    source : str
        The name errors start with (the file name).
    base_dir : str or Path
        Folder that relative paths (mesh files, outputs) are resolved against.
    allow_read : sequence of str or Path
        Folders outside `base_dir` whose files (meshes, images) the scene may read. By default a scene reads
        only inside its own folder, as it writes only there: a path that leads elsewhere (``..``, absolute, or
        through a symbolic link) is refused.

    Raises
    ------
    SceneFileError
        Malformed TOML (tomllib's own line and column), or any invalid key or value.
    """
    if isinstance(data, Path) or (
        isinstance(data, str) and "\n" not in data and data.lower().endswith((".toml", *MODEL_SUFFIXES))
    ):
        return load_scene_file(data, allow_read=allow_read)
    return _load_scene(data, source=source, base_dir=base_dir, allow_read=allow_read)


def _load_scene(
    data: Mapping[str, Any] | str,
    *,
    source: str = "<scene>",
    base_dir: str | Path = ".",
    check_outputs: bool = True,
    allow_read: Sequence[str | Path] = (),
) -> SceneFile:
    """``load_scene``. ``check_outputs=False`` for a caller that writes elsewhere (``render_scene_file`` with an
    output, ``frustum render FILE -o``): ``[output].files`` outside `base_dir` are not written, so not refused;
    they are left out of ``outputs``."""
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
        except ValueError as error:  # an integer of more digits than Python converts (sys.get_int_max_str_digits)
            raise SceneFileError(f"{escape_control(source)}: a number in the text is too long to read "
                                 f"({escape_control(str(error))[:120]}); write numbers of at most "
                                 f"{sys.get_int_max_str_digits()} digits") from None  # fmt: skip
        lines = data  # the key-line scan (linear, but slow in Python) runs only if a problem is reported
    elif isinstance(data, Mapping):
        parsed = dict(data)
    else:
        raise SceneFileError(f"{source}: data = {describe(data)} is not TOML text or a table; give a str or a dict")
    report = _Report(source, lines)
    report.allow_read = tuple(_as_folders(allow_read))
    scene_file = _build(report, parsed, Path(base_dir), check_outputs)
    report.raise_if_any()
    assert scene_file is not None
    return dataclasses.replace(scene_file, path=None)


_TOKENS = re.compile(r'"""|\'\'\'|"[^"\\\n]*(?:\\.[^"\\\n]*)*"|\'[^\'\n]*\'|#[^\n]*|[\[\]{}]|\n')
"""Triple quotes, strings (the basic one written as an unrolled loop, so a long string is one linear match),
comments, brackets and newlines."""


_KEY_TOKENS = re.compile(r'[A-Za-z0-9_-]+|""|[ \t]+|\.|\n|[^A-Za-z0-9_\-". \t\n]+|"')
"""The text with its strings blanked, cut into bare keys, empty strings, blanks, dots, newlines and the rest: every
alternative either matches what it consumes or fails on its first character, so the scan is linear."""


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
        elif value in ('"""', "'''"):
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
    line = _deep_dotted_key_line(stripped)
    if line is not None:
        raise SceneFileError(f"{where}:{line}: a dotted key has more than {_MAX_NESTING} parts; write at most "
                             f"{_MAX_NESTING} levels of tables")  # fmt: skip


def _deep_dotted_key_line(code: str) -> int | None:
    """The line of the first dotted key of more than `_MAX_NESTING` parts in `code` (strings blanked), or None.

    A state machine over `_KEY_TOKENS` (no backtracking pattern on user text: linear in the text's length)."""
    line, dots, after_key = 1, 0, False
    for token in _KEY_TOKENS.finditer(code):
        value = token.group()
        if value == ".":
            dots = dots + 1 if after_key else 0
            after_key = False
            if dots >= _MAX_NESTING:
                return line
        elif value[0] in " \t":
            continue
        elif value == '""' or value[0].isalnum() or value[0] in "_-":
            if after_key:  # two keys in a row: a new key, not the next part of this one
                dots = 0
            after_key = True
        else:
            dots, after_key = 0, False
            line += value == "\n"
    return None


def _radiosity(report: _Report, path: tuple, value: Any) -> dict | None:
    params = _table(report, path, value)
    if params is _BAD:
        return None
    _unknown_keys(report, path, params, tuple(RADIOSITY_KEYS))
    settings = {}
    for key, kind in RADIOSITY_KEYS.items():
        if key not in params:
            continue
        number = params[key]
        ok = not isinstance(number, bool) and isinstance(number, int | float if kind is float else int)
        if not ok or (not number > 0 and key != "max_iterations") or (kind is int and number < 0):
            report.add((*path, key), number, "is not a positive number" if kind is float else "is not a count",
                       "see frustum.radiosity: patch_size > 0, hemicube even 8…2048, 0 < tolerance < 1")  # fmt: skip
            continue
        settings[key] = number
    return settings


def _build(report: _Report, data: dict, base: Path, check_outputs: bool = True) -> SceneFile | None:
    report.base = base  # image files of materials and the environment are read relative to it
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
    if "environment" in data:
        environment = _environment(report, ("environment",), data["environment"])
        if environment is not _BAD:
            scene.environment = environment
    radiosity = _radiosity(report, ("radiosity",), data["radiosity"]) if "radiosity" in data else None
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
            camera = _camera(report, ("cameras", i), entry, size, scene)
            if camera is not _BAD:
                cameras.append(camera)
    elif "camera" in data:
        camera = _camera(report, ("camera",), data["camera"], size, scene)
        if isinstance(camera, _Stereo):
            stereo, camera = camera, camera.camera.camera
        if camera is not _BAD:
            cameras.append(camera)
    else:
        report.missing(("camera",), "add a [camera] table with eye and target (or [[cameras]])")
    if cameras and _wants_default_lights(data, scene, options):
        physical = any(item.material.model == "pbr" for item in scene.items)  # lights in lux for those materials
        for light in default_lights(cameras[0], physical):  # no lights named: the three-point set around the camera
            scene.root.add_light(light)
    outputs, animation, svg = _outputs(report, data, base, check_outputs)
    _check_image_memory(report, options, size, max(len(cameras), 1))
    if not report.problems:
        _warm_up(report, scene, animation)
    if report.problems:
        return None
    sheet = _sheet_options(report, data.get("sheet", {}))
    if report.problems:
        return None
    title = data.get("title", "")
    single = cameras[0] if "camera" in data else None
    return SceneFile(scene, single, options, outputs, tuple(cameras), stereo, animation, svg, size, columns, title,
                     sheet=sheet, radiosity=radiosity)  # fmt: skip


_LIT_SHADINGS = ("phong", "gouraud", "flat")
"""``[render] shading`` values whose pictures depend on the lights."""


def _wants_default_lights(data: dict, scene: Scene, options: dict) -> bool:
    """Whether a scene file gets ``default_lights``: it names no lights anywhere (no ``[[lights]]`` key, not even
    ``lights = []``, which keeps a scene unlit on purpose; no lights in nodes), has no ``[environment]`` and no
    ``[radiosity]`` (they light it), and draws lit surfaces: meshes, in mode "surface" or "surface+edges" with
    shading "phong", "gouraud" or "flat". Otherwise the picture would not depend on lights, or is meant to be unlit:
    wireframes, hidden-line drawings, volumes, radiosity, shading "none", "normals" or "depth". A fitted camera
    (``fit = true``) gets them as before."""
    if "lights" in data or scene.world_lights() or "environment" in data or "radiosity" in data:
        return False
    if _fits(data):
        return True
    lit_mode = options.get("mode", "surface") in ("surface", "surface+edges")
    return bool(scene.items) and lit_mode and options.get("shading", "phong") in _LIT_SHADINGS


def _fits(data: dict) -> bool:
    """Whether the file's camera (or first camera) is placed by $fit = true$."""
    camera = data.get("camera", (data.get("cameras") or [None])[0] if isinstance(data.get("cameras"), list) else None)
    return isinstance(camera, dict) and camera.get("fit") is True


def load_scene_file(path: str | Path, *, up: str = "y", allow_read: Sequence[str | Path] = ()) -> SceneFile:
    """Read, validate and build the TOML scene file at `path` (relative paths inside resolve against its folder),
    or the scene of a mesh file (.obj .stl .ply .off .gltf .glb).

    A mesh file gives the scene a file with only ``[[nodes]] geometry = { type = "mesh", path = ... }`` would,
    with the file's materials and textures, a camera framing it from a 3/4 view (``Camera.fit``) and the default
    lights (``frustum.scenefile.models``); `up` = "z" stands a z-up model upright (glTF is y-up and ignores it).
    A scene file reads meshes and images only inside its own folder and the folders of `allow_read`
    (``load_scene``).

    Raises
    ------
    SceneFileError
        If the file cannot be read, is not valid TOML, or has invalid keys or values; the message lists every
        problem as $file:line: key = value problem; what is valid$.
    GeometryError
        If a mesh file cannot be read.
    """
    return _load_scene_file(path, up=up, allow_read=allow_read)


ALLOW_READ_VARIABLE = "FRUSTUM_ALLOW_READ"
"""Folders (``os.pathsep``-separated) every scene file may read besides its own: what ``frustum --allow-read PATH``
sets, so that worker processes and the viewer's server follow the same rule."""


def _as_folders(allow_read: Any) -> list[Path]:
    """`allow_read` as a list of folders (a single path is one folder), with those of ``FRUSTUM_ALLOW_READ``; names
    that are not paths are refused."""
    if isinstance(allow_read, (str, Path)):
        allow_read = [allow_read]
    allow_read = [*allow_read, *filter(None, os.environ.get(ALLOW_READ_VARIABLE, "").split(os.pathsep))]
    folders = []
    for entry in allow_read:
        if not isinstance(entry, (str, Path)) or not str(entry) or "\0" in str(entry):
            raise SceneFileError(f"allow_read = {describe(entry)} is not a folder path; give folder paths")
        folders.append(Path(entry))
    return folders


def _load_scene_file(
    path: str | Path, check_outputs: bool = True, *, up: str = "y", allow_read: Sequence[str | Path] = ()
) -> SceneFile:
    """``load_scene_file``; ``check_outputs`` as for ``_load_scene``."""
    file = Path(path)
    if file.suffix.lower() in MODEL_SUFFIXES:
        return _model_scene_file(file, up)
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
    scene_file = _load_scene(text, source=str(file), base_dir=file.parent, check_outputs=check_outputs,
                             allow_read=allow_read)  # fmt: skip
    return dataclasses.replace(scene_file, path=file)


MODEL_SUFFIXES = (".obj", ".stl", ".ply", ".off", ".gltf", ".glb", ".xyz", ".pts")
"""Suffixes ``load_scene_file`` reads as a mesh file (a model) instead of a TOML scene file."""


def _model_scene_file(file: Path, up: str) -> SceneFile:
    from frustum.scenefile.models import model_options, model_scene, physical_options

    scene, camera = model_scene(file, up=up, size=_DEFAULT_SIZE)
    options = {**model_options(scene), **physical_options(scene)}
    return SceneFile(scene, camera, options, (), (camera,), size=_DEFAULT_SIZE, title=file.stem, path=file,
                     up=up)  # fmt: skip
