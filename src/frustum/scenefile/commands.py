"""What is done with a scene file: render it to PNG, SVG/PDF or an animation (``render_scene_file``), a drawing
sheet (``render_view_sheet``), the trace of its points (``explain_scene_file``), a visible-surface method's
counts (``explain_method``), and the example gallery (``render_examples``)."""

from __future__ import annotations

import dataclasses
import importlib
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from frustum.errors import FrustumError, OutputError, SceneFileError
from frustum.scenefile.loader import SceneFile, _load_scene_file, load_scene_file
from frustum.scenefile.outputs import OUTPUT_SUFFIXES

EXAMPLES_DIR = Path(__file__).resolve().parents[3] / "examples"
"""The gallery of example scene files in a source checkout (``render_examples`` renders them)."""


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
    path: str | Path,
    output: str | Path | Sequence[str | Path] | None = None,
    *,
    size: tuple[int, int] | None = None,
    shadows: bool | str | None = None,
    up: str = "y",
) -> Path | list[Path]:
    """Render the scene file at `path` and write it by suffix: PNG, SVG or PDF (line drawing), GIF or MP4 (turntable).

    Parameters
    ----------
    path : str or Path
        A TOML scene file, or a mesh file (``load_scene_file``).
    output : str, Path, a sequence of them, or None
        Where to write. None: the file's ``[output].files``, or ``out/<stem>.png`` next to the scene file.
    size : (int, int), optional
        Image width and height, replacing ``[render].size``.
    shadows : True, False, "ray" or None
        Replaces ``[render].shadows`` (None: the file's).
    up : "y" or "z"
        A mesh file's up axis (glTF is y-up and ignores it).

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
    # with `output`, the file's own outputs are not written
    scene_file = _load_scene_file(path, check_outputs=output is None, up=up)
    if size is not None:
        scene_file = scene_file.resized(tuple(size))  # type: ignore[arg-type]
    if shadows is not None:
        scene_file = dataclasses.replace(scene_file, options={**scene_file.options, "shadows": shadows})
    if output is None:
        targets = list(scene_file.outputs) or [Path(path).parent / "out" / (Path(path).stem + ".png")]
        single = not scene_file.outputs
    elif isinstance(output, str | Path):
        targets, single = [Path(output)], True
    else:
        targets, single = [Path(o) for o in output], False
    written = [_write(scene_file, target) for target in targets]
    return written[0] if single else written


def render_view_sheet(path: str | Path, output: str | Path, views: Sequence[str] | None = None, *, up: str = "y",
                      **options: Any) -> Path:  # fmt: skip
    """An engineering drawing sheet (``drawing_sheet``) of the scene file's scene: SVG, or PDF/PNG/DXF by suffix.

    ``views`` accepts "iso" for "isometric" (default: the file's ``[sheet] views``, else front, top, right and
    isometric). `up` is a mesh file's up axis ("y" or "z", ``load_scene_file``). Other keywords go to
    ``drawing_sheet`` (scale, paper, title, title_block, ...) and override the file's ``[sheet]`` table;
    ``title_block`` fields are merged over the file's.
    """
    scene_file = load_scene_file(path, up=up)
    try:
        sheet = importlib.import_module("frustum.output.sheet")
        svg = importlib.import_module("frustum.output.svg")
    except ImportError:
        raise OutputError("render_view_sheet: drawing sheets are not available in this version") from None
    settings = dict(scene_file.sheet)
    file_views = settings.pop("views", ("front", "top", "right", "isometric"))
    names = ["isometric" if v == "iso" else v for v in (views if views is not None else file_views)]
    title_block = {**settings.pop("title_block", {}), **(options.pop("title_block", None) or {})}
    settings.update({key: value for key, value in options.items() if value is not None})
    settings.setdefault("title", scene_file.title)
    target = Path(output)
    target.parent.mkdir(parents=True, exist_ok=True)
    if target.suffix.lower() == ".dxf":
        sheet.drawing_sheet(scene_file.scene, names, title_block=title_block or None, path=target, **settings)
        return target
    text = sheet.drawing_sheet(scene_file.scene, names, title_block=title_block or None, **settings)
    return Path(svg.save_svg(text, target))


def explain_scene_file(path: str | Path, point: Sequence[float] | None = None, *, up: str = "y") -> Any:
    """``frustum.trace`` of `point` (world coordinates) or, without one, of every vertex, through the file's camera
    (`up`: a mesh file's up axis, ``load_scene_file``).

    Returns
    -------
    frustum.trace.Trace
        Every stage's matrix and coordinates; ``str()``, ``to_markdown()``, ``to_latex()`` print it.
    """
    scene_file = load_scene_file(path, up=up)
    try:
        trace = importlib.import_module("frustum.trace").trace
    except (ImportError, AttributeError):
        raise SceneFileError(f"{path}: explain is not available in this version (frustum.trace is missing)") from None
    camera = scene_file.cameras[0]
    if point is None:
        return trace(scene_file.scene, camera)
    return trace(np.asarray(point, dtype=float), camera)


def explain_method(path: str | Path, method: str, *, up: str = "y") -> dict:
    """Render the scene file's first camera with the visible-surface `method` (``render(..., method=...)``, with
    the file's render options) and return ``Frame.stats``: what the method counted (spans and edge updates,
    areas per level, depth tests, fragments per pixel …) and, under ``"seconds"``, how long the render took.
    `up` is a mesh file's up axis (``load_scene_file``).

    Raises
    ------
    SceneFileError
        For an invalid scene file.
    FrustumError
        For an unknown method (the message lists the valid ones).
    """
    import time

    scene_file = load_scene_file(path, up=up)
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
    skipped: list[tuple[str, str]] | None = None,
) -> list[Path]:
    """Render every ``*.toml`` of the example gallery to ``out_dir/<stem>.png`` (at `size`; None: each file's own).

    With a `skipped` list, an example that needs an optional extra which is not installed (its error names a
    ``pip install`` command) is appended as ``(file name, message)`` and the rest are still rendered.

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
    written = []
    for file in files:
        try:
            written.append(render_scene_file(file, out / (file.stem + ".png"), size=size))
        except FrustumError as error:
            if skipped is None or "pip install" not in str(error):
                raise
            skipped.append((file.name, str(error)))
    return written  # type: ignore[return-value]


def extra_install_command(message: str) -> str:
    """The ``pip install ...`` command an extra-missing error message names ("" when none)."""
    found = re.search(r"pip install ('[^']+'|\S+)", message)
    return found.group(0).rstrip(";,.") if found else ""
