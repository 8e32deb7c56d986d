"""The ``frustum`` command (Typer + Rich).

Commands: ``render`` (a TOML scene file to PNG, SVG, PDF, GIF or MP4), ``explain`` (a scene file's camera and
points through every stage, with every matrix), ``view`` (a scene as an engineering sheet of views),
``examples`` (the gallery), ``compose`` (transformation steps and their composite), ``trace`` (one camera,
points through every stage of the pipeline), ``info`` (a mesh file's counts, bounds, watertightness and
normals), ``turntable`` (a GIF or MP4 orbiting a mesh) and ``dataset`` (many views with depth,
normals, ids and cameras). Errors print as one line, ``error: <message>``,
without a traceback (the global ``--debug`` option shows it): exit status 1 for a bad value or an unreadable
file, 2 for a command line that cannot be parsed (unknown option, missing argument, malformed numbers), 130
after Ctrl-C (honoured at once: the work runs on a worker thread; no partial output file is left). The global
options ``--max-bytes`` and ``--max-operations`` set the work budget (``frustum.set_budget``); ``--allow-read PATH``
(repeatable) lets scene files read meshes and images in a folder outside their own (``FRUSTUM_ALLOW_READ``).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer
from rich.console import Console

from frustum import __version__
from frustum.app.mesh_info import info_table, load_mesh
from frustum.app.runtime import (
    _STATE,
    REPORTED,
    UsageError,
    error_line,
    fail,
    failure,
    install_compile_notice,
    run_interruptible,
    run_program,
    say,
)
from frustum.app.work import image_size as _image_size
from frustum.camera import Camera
from frustum.errors import FrustumError, OutputError
from frustum.projection import Orthographic, Perspective
from frustum.quaternion import Quaternion
from frustum.transforms import (
    Step,
    apply,
    compose,
    reflect,
    rotate,
    rotate_x,
    rotate_y,
    rotate_z,
    scale,
    shear,
    to_row_major,
    translate,
)

app = typer.Typer(
    name="frustum",
    help="The classical 3D graphics pipeline, inspectable at every stage.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console()
error_console = Console(stderr=True, highlight=False, soft_wrap=True)


def _numbers(text: str, counts: tuple[int, ...], step: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")] if text else []
    except ValueError:
        raise UsageError(f"step {step!r}: {text!r} is not a comma-separated list of numbers") from None
    if len(values) not in counts:
        expected = " or ".join(str(c) for c in counts)
        raise UsageError(f"step {step!r}: got {len(values)} numbers; expected {expected}")
    return values


def _rotate_deg(values: list[float]) -> np.ndarray:
    return rotate(values[:3], np.radians(values[3]), values[4:] or (0.0, 0.0, 0.0))


def _scale(values: list[float]) -> np.ndarray:
    factors = values * 3 if len(values) == 1 else values[:3]
    return scale(*factors, fixed=values[3:] or (0.0, 0.0, 0.0))


# name -> (allowed counts of numbers, builder from those numbers, the syntax shown in --help)
_STEPS: dict[str, tuple[tuple[int, ...], Callable[[list[float]], np.ndarray], str]] = {
    "translate": ((3,), lambda v: translate(*v), "translate=tx,ty,tz"),
    "rotate_x_deg": ((1,), lambda v: rotate_x(np.radians(v[0])), "rotate_x_deg=angle"),
    "rotate_y_deg": ((1,), lambda v: rotate_y(np.radians(v[0])), "rotate_y_deg=angle"),
    "rotate_z_deg": ((1,), lambda v: rotate_z(np.radians(v[0])), "rotate_z_deg=angle"),
    "rotate_deg": ((4, 7), _rotate_deg, "rotate_deg=ax,ay,az,angle[,px,py,pz]"),
    "scale": ((1, 3, 6), _scale, "scale=s | sx,sy,sz[,fx,fy,fz]"),
    "reflect": ((3, 6), lambda v: reflect(v[:3], v[3:] or (0.0, 0.0, 0.0)), "reflect=xy|yz|zx | nx,ny,nz[,px,py,pz]"),
    "quaternion": ((4,), lambda v: Quaternion(*v).to_matrix(), "quaternion=w,x,y,z"),
}


def parse_step(text: str) -> Step:
    """One ``name=numbers`` command-line step as a named matrix (angles in degrees)."""
    name, sep, arguments = text.partition("=")
    name = name.strip()
    if not sep:
        raise UsageError(f"step {text!r} has no '='; write name=values, e.g. translate=1,0,0")
    if name == "reflect" and arguments.strip() in ("xy", "yz", "zx", "xz"):
        return Step(text, reflect(arguments.strip()))
    if name == "shear":
        axis, _, rest = arguments.partition(",")
        values = _numbers(rest, (2, 3), text)
        return Step(text, shear(axis.strip(), *values))
    if name not in _STEPS:
        known = ", ".join([*sorted(_STEPS), "shear"])
        raise UsageError(f"step {text!r}: {name!r} is not a transformation; expected one of {known}")
    counts, build, _ = _STEPS[name]
    return Step(text, build(_numbers(arguments, counts, text)))


def _print_matrix(title: str, matrix: np.ndarray) -> None:
    """A titled 4x4 grid; entries within 1e-12 of an integer print as that integer (cos 90° = 6e-17 → 0)."""
    from rich.table import Table

    table = Table(show_header=False, box=None, pad_edge=False)
    for _ in range(matrix.shape[1]):
        table.add_column(justify="right")
    shown = np.where(np.abs(matrix - np.round(matrix)) <= 1e-12, np.round(matrix), matrix) + 0.0
    for row in shown:
        table.add_row(*(f"{v:.6g}" for v in row))
    console.print(title, markup=False)
    console.print(table)


def _version(value: bool) -> None:
    if value:
        console.print(f"frustum {__version__}")
        raise typer.Exit()


@app.callback()
def _main(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit.")
    ] = False,
    debug: Annotated[bool, typer.Option("--debug", help="Show the full traceback of an error.")] = False,
    max_bytes: Annotated[
        str | None,
        typer.Option("--max-bytes", help="Memory budget of one request, e.g. 16G or 2e9 (default 8G; "
                     "env FRUSTUM_MAX_BYTES).", metavar="BYTES"),
    ] = None,
    max_operations: Annotated[
        str | None,
        typer.Option("--max-operations", help="Work budget of one request in inner iterations, e.g. 1e11 "
                     "(default 5e10; env FRUSTUM_MAX_OPERATIONS).", metavar="COUNT"),
    ] = None,
    allow_read: Annotated[
        list[Path] | None,
        typer.Option("--allow-read", help="A folder outside a scene file's own whose meshes and images it may read "
                     "(repeatable; env FRUSTUM_ALLOW_READ).", metavar="PATH"),
    ] = None,
) -> None:
    """The classical 3D graphics pipeline, inspectable at every stage."""
    _STATE["debug"] = debug
    if allow_read:  # through the environment: worker processes and every command's loader see the same rule
        import os

        from frustum.scenefile import ALLOW_READ_VARIABLE

        folders = [str(path.resolve()) for path in allow_read]
        previous = os.environ.get(ALLOW_READ_VARIABLE)
        os.environ[ALLOW_READ_VARIABLE] = os.pathsep.join(folders + ([previous] if previous else []))
    if max_bytes is not None or max_operations is not None:
        from frustum.budgets import set_budget

        try:
            set_budget(bytes=max_bytes, operations=max_operations)
        except FrustumError as error:
            raise UsageError(str(error).replace("set_budget: bytes", "--max-bytes").replace(
                "set_budget: operations", "--max-operations")) from None


_STEP_HELP = "; ".join([syntax for _, _, syntax in _STEPS.values()] + ["shear=x|y|z,a,b[,ref]"])


@app.command("compose")
def compose_command(
    steps: Annotated[list[str], typer.Argument(help=f"Transformations in the order applied: {_STEP_HELP}.")],
    point: Annotated[
        str | None, typer.Option("--point", "-p", help="Also transform this point, given as x,y,z.")
    ] = None,
    row_major: Annotated[
        bool, typer.Option("--row-major", help="Also print the composite for row vectors (P' = P·M).")
    ] = False,
) -> None:
    """Print each step's 4x4 matrix and the composite (column vectors, P' = M·P; angles in degrees)."""
    parsed = [parse_step(text) for text in steps]
    for i, step in enumerate(parsed, start=1):
        _print_matrix(f"{i}. {step.name}", step.matrix)
        console.print()
    composite = compose(*(s.matrix for s in parsed))
    _print_matrix("composite M = " + " · ".join(f"M{i}" for i in range(len(parsed), 0, -1)), composite)
    if row_major:
        console.print()
        _print_matrix("row-vector form Mᵀ (P' = P·Mᵀ)", to_row_major(composite))
    if point is not None:
        p = _numbers(point, (3,), f"--point {point}")
        moved = apply(composite, p)
        console.print()
        console.print(f"M · ({', '.join(f'{v:g}' for v in p)}, 1) = ({', '.join(f'{v:.6g}' for v in moved)}, 1)")


def _check_up(up: str) -> None:
    """A mesh file's ``--up`` axis: y or z (the message ``load_scene_file`` gives for a mesh file)."""
    from frustum.scenefile.models import MODEL_UP_AXES

    if up not in MODEL_UP_AXES:
        from frustum.errors import SceneFileError

        raise SceneFileError(f"up = {up!r} is not an axis; give 'y' or 'z'")


def _model_scene_file(path: Path, up: str) -> Any:
    """A mesh file loaded with its `up` axis (a ``SceneFile``), or the path of any other file as it is."""
    from frustum.scenefile.loader import MODEL_SUFFIXES

    if path.suffix.lower() not in MODEL_SUFFIXES:
        return path
    from frustum.scenefile import load_scene_file

    return load_scene_file(path, up=up)


# --- trace ----------------------------------------------------------------------------------------------------


def _vector3(text: str, option: str) -> list[float]:
    """``x,y,z`` from the command line as three floats, or a UsageError naming the option."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise UsageError(f"{option} = {text!r} is not a comma-separated list of numbers; write x,y,z") from None
    if len(values) != 3:
        raise UsageError(f"{option} = {text!r} has {len(values)} numbers; expected 3, written x,y,z")
    return values


@app.command("trace")
def trace_command(
    point: Annotated[
        list[str], typer.Option("--point", "-p", help="A world point x,y,z to follow (repeat for more points).")
    ],
    eye: Annotated[str, typer.Option(help="View point P0 as x,y,z.")] = "0,0,5",
    target: Annotated[str, typer.Option(help="Look-at point as x,y,z.")] = "0,0,0",
    up: Annotated[str, typer.Option(help="View-up vector V as x,y,z.")] = "0,1,0",
    fovy_deg: Annotated[float, typer.Option(help="Vertical field of view in degrees (perspective).")] = 60.0,
    ortho_height: Annotated[
        float | None, typer.Option(help="Use an orthographic projection with a view window this tall instead.")
    ] = None,
    near: Annotated[float, typer.Option(help="Near plane distance (> 0 for perspective).")] = 0.1,
    far: Annotated[float, typer.Option(help="Far plane distance.")] = 100.0,
    size: Annotated[str, typer.Option(help="Image size WIDTHxHEIGHT in pixels.")] = "640x480",
    polyline: Annotated[
        bool, typer.Option("--polyline", help="Connect the points in order and show how each segment is clipped.")
    ] = False,
    markdown: Annotated[bool, typer.Option("--markdown", help="Print Markdown (to paste into notes).")] = False,
    latex: Annotated[bool, typer.Option("--latex", help="Print a LaTeX fragment (amsmath).")] = False,
) -> None:
    """Follow points through every stage of the viewing pipeline: each matrix (column and row form) and the
    coordinates after it, from world to window."""
    from frustum.trace import trace

    if markdown and latex:
        raise UsageError("--markdown and --latex were both given; choose one output format")
    points = [_vector3(text, "--point") for text in point]
    width, height = _image_size(size)
    if ortho_height is None:
        projection: Perspective | Orthographic = Perspective(math.radians(fovy_deg), near, far)
    else:
        projection = Orthographic(ortho_height, near, far)
    camera = Camera.look_at(
        _vector3(eye, "--eye"), _vector3(target, "--target"), _vector3(up, "--up"), projection, width, height
    )
    result = trace(points, camera, polyline=polyline)
    if markdown or latex:
        sys.stdout.write(result.to_markdown() if markdown else result.to_latex())
    else:
        console.print(result)


# --- info -------------------------------------------------------------------------------------------------------


@app.command("info")
def info_command(
    mesh: Annotated[list[Path], typer.Argument(help="Mesh files (.ply, .obj, .stl, .off, .glb), or folders of them.")],
) -> None:
    """Print mesh files' counts, bounds, watertightness and normals (one table each; several: one line per
    unreadable file, exit status 1)."""
    from frustum.app.many import expand_inputs
    from frustum.scenefile.loader import MODEL_SUFFIXES

    inputs, several = expand_inputs(mesh, MODEL_SUFFIXES)
    if not several:
        console.print(info_table(inputs[0]))
        return
    failed = 0
    for source in inputs:
        try:
            table = info_table(source)
        except REPORTED as error:
            failed += 1
            say(error_line(f"{source}: {failure(error)[0]}"), sys.stderr)
            continue
        console.print(table)
    if failed:
        raise typer.Exit(1)


# --- turntable --------------------------------------------------------------------------------------------------


def _turntable_task(mesh: Path, outputs: list[Path] | None, options: dict[str, Any]) -> list[str]:
    """One input of ``frustum turntable`` (several: ``frustum.app.many``): its ``wrote`` line."""
    from frustum.geometry.points import point_file_kind
    from frustum.output.animation import framing_camera, turntable
    from frustum.scenefile.models import model_options, model_scene, physical_options

    assert outputs is not None
    output = outputs[0]
    width, height = options["size"]
    if point_file_kind(mesh) is None:
        load_mesh(mesh, "turntable")  # the CLI's checks and messages for a bad mesh file
    scene, _ = model_scene(mesh, up=options["up"], size=(width, height))
    camera = framing_camera(scene, width, height, elevation=math.radians(options["elevation_deg"]))
    count = turntable(scene, camera, options["frames"], options["axis"], output, options["fps"],
                      progress=options.get("progress", False), cull_back_faces=False, mode=options["mode"],
                      **model_options(scene), **physical_options(scene, options["tone_map"], options["exposure"]))
    return [f"wrote {output} ({count} frames, {width}x{height})"]


@app.command("turntable")
def turntable_command(
    mesh: Annotated[list[Path], typer.Argument(help="Mesh files (.ply, .obj, .stl, .off, .glb), or folders of them.")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The animation file, .gif or .mp4; for several "
                                         "meshes a pattern with {stem}, {name}, {suffix} or {index}.")],
    frames: Annotated[int, typer.Option(help="Frames in one full turn.")] = 120,
    size: Annotated[str, typer.Option(help="Image size WIDTHxHEIGHT in pixels.")] = "480x480",
    fps: Annotated[float, typer.Option(help="Frames per second.")] = 30.0,
    axis: Annotated[str, typer.Option(help="Turntable axis through the mesh's center: x, y or z.")] = "y",
    elevation_deg: Annotated[float, typer.Option(help="Camera height above the horizon in degrees.")] = 20.0,
    mode: Annotated[str, typer.Option(help="surface, wireframe or points.")] = "surface",
    up: Annotated[str, typer.Option(help="The model's up axis, y or z (glTF is always y).")] = "y",
    jobs: Annotated[int, typer.Option("--jobs", "-j", help="Worker processes for several meshes.")] = 1,
    tone_map: Annotated[str | None, typer.Option(help="none, aces or khronos-neutral (default: khronos-neutral "
                                                 "for a glTF or PBR model, else none).")] = None,
    exposure: Annotated[float, typer.Option(help="Exposure of the physically based shading (a factor > 0).")] = 1.0,
) -> None:
    """Render a mesh from a camera orbiting it once and write the frames as a looping GIF or an MP4 (the file's
    materials and textures, the default lights of frustum.scenefile.models, or a glTF file's own lights)."""
    from frustum.app.many import expand_inputs, output_paths, run_each
    from frustum.scenefile.loader import MODEL_SUFFIXES

    width, height = _image_size(size)
    if not 0 <= abs(elevation_deg) < 90:
        raise UsageError(f"--elevation-deg = {elevation_deg!r} is out of range; give an angle in (-90, 90)")
    inputs, several = expand_inputs(mesh, MODEL_SUFFIXES)
    outputs = output_paths(inputs, [output], several)
    options = {"size": (width, height), "up": up, "elevation_deg": elevation_deg, "frames": frames, "axis": axis,
               "fps": fps, "mode": mode, "tone_map": tone_map, "exposure": exposure}  # fmt: skip
    if not several:
        for line in _turntable_task(inputs[0], outputs[0], {**options, "progress": error_console}):
            say(line)
        return
    status = run_each(_turntable_task, inputs, outputs, options, jobs, "turntable")
    if status:
        raise typer.Exit(status)


# --- scene files ------------------------------------------------------------------------------------------------


@app.command("render")
def render_command(
    scene: Annotated[
        list[Path], typer.Argument(help="TOML scene files or mesh files, folders of them, or quoted glob patterns.")
    ],
    output: Annotated[
        list[Path] | None,
        typer.Option("--output", "-o", help="Output file(s): .png .svg .pdf .gif .mp4; for several inputs a pattern "
                     "with {stem}, {name}, {suffix} or {index}, e.g. out/{stem}.png."),
    ] = None,
    size: Annotated[str | None, typer.Option(help="Image size WIDTHxHEIGHT, overriding the file's.")] = None,
    up: Annotated[str, typer.Option(help="A mesh file's up axis, y or z (glTF is always y).")] = "y",
    shadows: Annotated[
        str | None, typer.Option(help="Shadows, overriding the file's: on (shadow maps), off, or ray (shadow rays).")
    ] = None,
    jobs: Annotated[int, typer.Option("--jobs", "-j", help="Worker processes for several inputs.")] = 1,
) -> None:
    """Render scene files or mesh files (framed from a 3/4 view, default lights, the file's materials); without
    -o, the outputs each file names (or out/<name>.png beside it). Several inputs: one line per failed input, the
    others still rendered, exit status 1 when any failed."""
    from frustum.app.many import render_inputs

    status = render_inputs(scene, output or None, size, up, shadows, jobs)  # also run without Typer: _program
    if status:
        raise typer.Exit(status)


@app.command("explain")
def explain_command(
    scene: Annotated[Path, typer.Argument(help="A TOML scene file or a mesh file.")],
    point: Annotated[str | None, typer.Option(help="A world point x,y,z (default: the scene's vertices).")] = None,
    markdown: Annotated[bool, typer.Option("--markdown", help="Print Markdown instead of tables.")] = False,
    latex: Annotated[bool, typer.Option("--latex", help="Print LaTeX instead of tables.")] = False,
    method: Annotated[
        str | None,
        typer.Option(help="A visible-surface method (scan-line, area-subdivision, a-buffer, ...): print its counts."),
    ] = None,
    up: Annotated[str, typer.Option(help="A mesh file's up axis, y or z (glTF is always y).")] = "y",
) -> None:
    """Print every stage of the pipeline (matrices in column- and row-vector form) for the scene's camera; with
    --method, what that visible-surface method counted drawing the scene (spans, areas per level, fragments …)."""
    from frustum.scenefile import explain_method, explain_scene_file

    if method is not None:
        for key, value in explain_method(scene, method, up=up).items():
            console.print(f"{key:>24}  {value}", markup=False, highlight=False, soft_wrap=True)
        return

    trace = explain_scene_file(scene, _vector3(point, "--point") if point else None, up=up)
    if markdown or latex:
        console.print(trace.to_markdown() if markdown else trace.to_latex(), markup=False, highlight=False)
    else:
        console.print(trace)


@app.command("view")
def view_command(
    scene: Annotated[list[Path], typer.Argument(help="TOML scene files or mesh files, or folders of them.")],
    output: Annotated[
        Path, typer.Option("--output", "-o", help="The sheet: .svg, .pdf, .png or .dxf (CAD); for several scenes a "
                           "pattern with {stem}, {name}, {suffix} or {index}.")
    ],
    views: Annotated[
        str | None, typer.Option(help="Comma-separated views: front, top, right, left, rear, bottom, iso.")
    ] = None,
    paper: Annotated[str | None, typer.Option(help="Sheet size: A4, A3, A2, A1, A0, Letter or Tabloid.")] = None,
    orientation: Annotated[str | None, typer.Option(help="landscape or portrait.")] = None,
    angle: Annotated[
        str | None, typer.Option(help="Projection angle: third (US, ISO E) or first (ISO, Europe).")
    ] = None,
    dimensions: Annotated[
        str | None, typer.Option(help="parts (each part's sizes; default), overall (each view's extent) or none.")
    ] = None,
    title: Annotated[str | None, typer.Option(help="Title block: the drawing's title.")] = None,
    drawing_number: Annotated[str | None, typer.Option(help="Title block: drawing number.")] = None,
    sheet_number: Annotated[str | None, typer.Option("--sheet", help="Title block: sheet n/N, e.g. 1/2.")] = None,
    date: Annotated[str | None, typer.Option(help="Title block: date of issue.")] = None,
    author: Annotated[str | None, typer.Option(help="Title block: drawn by.")] = None,
    tolerance: Annotated[str | None, typer.Option(help="Title block: general tolerances (ISO 2768-m).")] = None,
    units: Annotated[str | None, typer.Option(help="Title block: model units (mm).")] = None,
    up: Annotated[str, typer.Option(help="A mesh file's up axis, y or z (glTF is always y).")] = "y",
    jobs: Annotated[int, typer.Option("--jobs", "-j", help="Worker processes for several scenes.")] = 1,
) -> None:
    """Draw the scene as an engineering sheet: orthographic views at the largest standard scale that fits, with
    hidden lines, dimensions, title block and scale bar (the scene file's \\[sheet] table sets the defaults).
    Several scenes: -o is a pattern with {stem}, {name}, {suffix} or {index}."""
    from frustum.app.many import expand_inputs, output_paths, run_each

    fields = {"title": title, "drawing_number": drawing_number, "sheet": sheet_number, "date": date,
              "author": author, "tolerance": tolerance, "units": units}  # fmt: skip
    options = {"views": tuple(v.strip() for v in views.split(",") if v.strip()) if views is not None else None,
               "up": up, "paper": paper, "orientation": orientation, "projection_angle": angle,
               "dimensions": False if dimensions == "none" else dimensions,
               "title_block": {key: value for key, value in fields.items() if value is not None}}  # fmt: skip
    inputs, several = expand_inputs(scene)
    outputs = output_paths(inputs, [output], several)
    if not several:
        for line in _view_task(inputs[0], outputs[0], options):
            say(line)
        return
    status = run_each(_view_task, inputs, outputs, options, jobs, "view")
    if status:
        raise typer.Exit(status)


def _view_task(scene: Path, outputs: list[Path] | None, options: dict[str, Any]) -> list[str]:
    """One input of ``frustum view`` (several: ``frustum.app.many``): its ``wrote`` line."""
    from frustum.scenefile import render_view_sheet

    assert outputs is not None
    options = dict(options)
    written = render_view_sheet(scene, outputs[0], options.pop("views"), **options)
    return [f"wrote {written}"]


@app.command("warmup")
def warmup_command(
    processes: Annotated[int | None, typer.Option(help="Parallel processes (default: the number of cores).")] = None,
) -> None:
    """Compile every kernel ahead of time into Numba's on-disk cache, so no later render waits for it."""
    from frustum.app.warmup import warmup

    error_console.print("compiling every kernel (once per environment) ...", markup=False)
    console.print(str(warmup(processes)), markup=False, highlight=False)


@app.command("resident")
def resident_command(
    action: Annotated[str, typer.Argument(help="start: start one; status: list the running ones; stop: end them.")],
) -> None:
    """The resident render process, started on purpose: plain `frustum render FILE -o OUT` commands hand it their
    work and skip Python's and Numba's start-up (or FRUSTUM_RESIDENT=1: the first successful render starts it;
    FRUSTUM_RESIDENT=0: commands ignore it). It exits after 10 idle minutes."""
    from frustum.app import resident

    if action == "start":
        if not resident.enabled():
            raise FrustumError("resident: a resident render process needs Linux (SO_PEERCRED and fork)")
        if resident.start(wait=True) is None:
            entry = resident.running()
            if entry is None:
                raise FrustumError("resident: no resident render process could be started (is the runtime folder "
                                   "private to you?)")  # fmt: skip
            console.print(f"a resident render process is already running (pid {entry.get('pid')})", markup=False,
                          highlight=False, soft_wrap=True)  # fmt: skip
    elif action == "status":
        running = resident.status()
        for entry in running:
            busy = ", rendering now" if entry.get("busy") else ""
            console.print(f"pid {entry.get('pid')}: {entry.get('requests')} renders served{busy}, idle "
                          f"{entry.get('idle_s')} s, frustum at {entry.get('package')}", markup=False,
                          highlight=False, soft_wrap=True)  # fmt: skip
        if not running:
            console.print("no resident render process is running", markup=False, highlight=False)
    elif action == "stop":
        console.print(f"stopped {resident.stop()} resident render process(es)", markup=False, highlight=False)
    else:
        raise FrustumError(f"resident: action {action!r} is unknown; expected start, status or stop")


@app.command("examples")
def examples_command(
    out: Annotated[Path, typer.Option(help="Folder for the pictures.")] = Path("examples/out"),
    size: Annotated[str, typer.Option(help="Image size WIDTHxHEIGHT.")] = "320x240",
) -> None:
    """Render the example gallery (examples/*.toml) into a folder; examples that need an optional extra which is
    not installed are listed with the pip command (exit 0)."""
    from frustum.scenefile import render_examples
    from frustum.scenefile.commands import extra_install_command

    skipped: list[tuple[str, str]] = []
    for path in render_examples(out, _image_size(size), skipped=skipped):
        console.print(f"wrote {path}", markup=False, highlight=False, soft_wrap=True)
    for name, message in skipped:  # exit 0: only optional extras are missing
        command = extra_install_command(message)
        console.print(f"skipped {name}: needs an optional extra ({command or message})",
                      markup=False, highlight=False, soft_wrap=True)  # fmt: skip


# --- datasets ---------------------------------------------------------------------------------------------------


@app.command("dataset")
def dataset_command(
    scene: Annotated[
        Path, typer.Argument(help="A TOML scene file (its camera sets projection, size and distance) or a mesh file.")
    ],
    out: Annotated[str, typer.Option("--out", help="Output folder or URL (s3://bucket/prefix); rerun to resume.")],
    views: Annotated[int | None, typer.Option(help="Number of views (default 100; --layout file: the file's).")] = None,
    layout: Annotated[str, typer.Option(help="orbit, sphere, random or file.")] = "orbit",
    format_: Annotated[
        str, typer.Option("--format", help="nerf, nerfstudio, colmap, files, webdataset, coco or bop.")
    ] = "nerf",
    size: Annotated[str | None, typer.Option(help="Image size WIDTHxHEIGHT, overriding the file's.")] = None,
    seed: Annotated[int, typer.Option(help="Base seed; each view's seed derives from it and the view's key.")] = 0,
    cameras: Annotated[Path | None, typer.Option(help="--layout file: a JSON list of {eye, target, up}.")] = None,
    depth_format: Annotated[str, typer.Option(help="npy (float32) or png16 (uint16, scale in README.txt).")] = "npy",
    executor: Annotated[str, typer.Option(help="serial, process or ray.")] = "process",
    workers: Annotated[int | None, typer.Option(help="Worker processes or Ray actors (default: all cores).")] = None,
    address: Annotated[str | None, typer.Option(help="Ray cluster address (e.g. auto) for --executor ray.")] = None,
    collect: Annotated[str | None, typer.Option(help="Ray: driver or workers write the files (see docs).")] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help="Start again over a different configuration.")] = False,
    retries: Annotated[int, typer.Option(help="Tries again for failed views before listing them.")] = 1,
    progress: Annotated[bool, typer.Option("--progress/--no-progress", help="Show the progress bar.")] = True,
    up: Annotated[str, typer.Option(help="A mesh file's up axis, y or z (glTF is always y).")] = "y",
) -> None:
    """Render a multi-view dataset: color, metric depth, normals, object ids, masks and the cameras of a format.

    Exit status 3 when views failed (listed with their errors after the retries).
    """
    from frustum.batch import render_dataset

    result = render_dataset(
        _model_scene_file(scene, up), out,
        views=views if views is not None or layout == "file" else 100, layout=layout, format=format_,
        size=_image_size(size) if size else None, seed=seed, cameras_file=cameras, depth_format=depth_format,
        executor=executor, workers=workers, progress=progress, overwrite=overwrite, retries=retries,
        address=address, collect=collect,
    )  # fmt: skip
    for key, error in sorted(result.failed.items()):
        error_console.print(f"failed {key}: {error}", markup=False)
    console.print(
        f"wrote {out}: {len(result.rendered)} views rendered, {len(result.skipped)} skipped (done before), "
        f"{len(result.failed)} failed",
        markup=False, highlight=False, soft_wrap=True,
    )  # fmt: skip
    if result.failed:
        raise typer.Exit(3)


@app.command("serve")
def serve_command(
    scene: Annotated[Path, typer.Argument(help="A TOML scene file or a mesh file (reloaded whenever it is saved).")],
    host: Annotated[
        str, typer.Option(help="Interface to listen on; 127.0.0.1 is this machine only, 0.0.0.0 every interface.")
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option(help="TCP port; 0 picks a free one.")] = 8000,
    allow_origin: Annotated[
        list[str] | None,
        typer.Option("--allow-origin", help="Also let pages of this origin (e.g. http://localhost:8888) use the "
                     "viewer, for deliberate embedding; repeatable. Other pages get 403."),
    ] = None,
    no_token: Annotated[
        bool, typer.Option("--no-token", help="Serve a non-loopback --host without the random URL token.")
    ] = False,
    up: Annotated[str, typer.Option(help="A mesh file's up axis, y or z (glTF is always y).")] = "y",
) -> None:
    """Open an interactive viewer of a scene file in the browser (orbit, pan, zoom, the pipeline beside it)."""
    from frustum.viewer.server import serve

    _check_up(up)  # before serving: the page would show it only after the first connection

    def ready(url: str) -> None:
        console.print(f"frustum serve: {scene} at {url}", markup=False, highlight=False, soft_wrap=True)
        if host in ("127.0.0.1", "localhost", "::1"):
            console.print("listening on this machine only; --host 0.0.0.0 serves other machines too; Ctrl-C stops",
                          markup=False, highlight=False, soft_wrap=True)  # fmt: skip
        elif "?token=" in url:
            console.print("other machines need the URL with its token; --no-token serves without one; Ctrl-C stops",
                          markup=False, highlight=False, soft_wrap=True)  # fmt: skip
        console.file.flush()

    serve(scene, host, port, ready=ready, allow_origins=tuple(allow_origin or ()), token=False if no_token else None,
          up=up)  # fmt: skip


@app.command("steps")
def steps_command(
    algorithm: Annotated[str | None, typer.Argument(help="Algorithm name (frustum steps --list).")] = None,
    scene_file: Annotated[Path | None, typer.Argument(help="A TOML scene file (depth-buffer).")] = None,
    size: Annotated[str | None, typer.Option(help="Image size WxH for a scene file's camera.")] = None,
    output: Annotated[Path | None, typer.Option("-o", "--output", help="Output .svg, .gif, .mp4, .html, .md.")] = None,
    list_algorithms: Annotated[bool, typer.Option("--list", help="List the algorithms and exit.")] = False,
    from_: Annotated[str | None, typer.Option("--from", help="Segment start x,y,z[,w].")] = None,
    to: Annotated[str | None, typer.Option("--to", help="Segment end x,y,z[,w].")] = None,
    points: Annotated[str | None, typer.Option(help="Points x,y[,z];x,y[,z];...")] = None,
    t: Annotated[str | None, typer.Option("--t", help="Curve parameter in [0, 1].")] = None,
    level: Annotated[str | None, typer.Option(help="Fractal iterations.")] = None,
    axis: Annotated[str | None, typer.Option(help="Rotation axis x,y,z.")] = None,
    point: Annotated[str | None, typer.Option(help="A point on the rotation axis x,y,z.")] = None,
    angle_deg: Annotated[str | None, typer.Option(help="Rotation angle in degrees.")] = None,
    knots: Annotated[str | None, typer.Option(help="Knot vector, comma-separated.")] = None,
    order: Annotated[str | None, typer.Option(help="B-spline order k (degree k - 1).")] = None,
    u: Annotated[str | None, typer.Option("--u", help="B-spline parameter whose knot span is shown.")] = None,
    seed: Annotated[str | None, typer.Option(help="Random seed.")] = None,
    fps: Annotated[float, typer.Option(help="Animation frames (steps) per second.")] = 1.0,
    up: Annotated[str, typer.Option(help="A mesh file's up axis, y or z (glTF is always y).")] = "y",
) -> None:
    """Record an algorithm of the lecture notes step by step and write its figures, animation, page or table."""
    from frustum.steps.catalog import build, describe_algorithms

    if list_algorithms:
        console.print(describe_algorithms(), markup=False, highlight=False, soft_wrap=True)
        return
    if algorithm is None or output is None:
        raise UsageError("frustum steps: give an ALGORITHM and -o out.svg|gif|mp4|html|md (or --list)")
    options: dict[str, Any] = {"from": from_, "to": to, "points": points, "t": t, "level": level, "axis": axis,
                               "point": point, "angle_deg": angle_deg, "knots": knots, "order": order, "u": u,
                               "seed": seed}  # fmt: skip
    if scene_file is not None:
        from frustum.scenefile import load_scene_file

        loaded = load_scene_file(scene_file, up=up)
        camera = loaded.camera or loaded.cameras[0]
        if size is not None:
            width, height = _image_size(size)
            camera = Camera(camera.frame, camera.projection, width, height)
        options.update(scene=loaded.scene, camera=camera)
    recorded = build(algorithm, options)
    written = recorded.save(output, fps=fps)
    console.print(f"frustum steps: {algorithm}, {len(recorded)} steps -> {', '.join(map(str, written))}",
                  markup=False, highlight=False, soft_wrap=True)  # fmt: skip


# --- entry point ------------------------------------------------------------------------------------------------


@app.command("radiosity")
def radiosity_command(
    scene: Annotated[Path, typer.Argument(help="A TOML scene file (emissive materials and/or lights).")],
    output: Annotated[Path, typer.Option("--output", "-o", help="The picture to write (.png).")],
    patch_size: Annotated[
        # "\\[": rich markup would take [radiosity] for a style tag and drop it
        float | None, typer.Option(help="Longest patch edge in world units (default: the \\[radiosity] table's, or a "
                                        "twentieth of the scene's diagonal).")
    ] = None,
    hemicube: Annotated[int | None, typer.Option(help="Hemicube pixels a side (default 128).")] = None,
    tolerance: Annotated[float | None, typer.Option(help="Stop at this unshot / emitted power (default 1e-3).")] = None,
    size: Annotated[str | None, typer.Option(help="Image size WIDTHxHEIGHT, overriding the file's.")] = None,
    up: Annotated[str, typer.Option(help="A mesh file's up axis, y or z (glTF is always y).")] = "y",
) -> None:
    """Light a scene file by radiosity (diffuse light bouncing between surfaces, ray-cast form factors, progressive
    refinement) and render the lit scene from the file's camera: each pixel the interpolated radiosity."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from frustum.render import render
    from frustum.render.radiosity import radiosity
    from frustum.scenefile import load_scene_file

    if output.suffix.lower() != ".png":
        raise OutputError(f"radiosity: output = {str(output)!r} is not a .png file; radiosity writes a PNG picture")
    scene_file = load_scene_file(scene, up=up)
    if size:
        scene_file = scene_file.resized(_image_size(size))
    settings = dict(getattr(scene_file, "radiosity", None) or {})
    for name, value in (("patch_size", patch_size), ("hemicube", hemicube), ("tolerance", tolerance)):
        if value is not None:
            settings[name] = value
    tolerance_value = settings.get("tolerance", 1e-3)
    # the progress bar's goal; a tolerance outside (0, 1) is left for radiosity() to refuse with its message
    goal = -math.log10(tolerance_value) if isinstance(tolerance_value, float | int) and 0 < tolerance_value < 1 else 3.0
    columns = (TextColumn("radiosity"), BarColumn(), TextColumn("{task.fields[shots]} shots, residual "
               "{task.fields[residual]:.1e}"), TimeElapsedColumn())  # fmt: skip
    with Progress(*columns, console=error_console, transient=True) as bar:
        task = bar.add_task("radiosity", total=goal, shots=0, residual=1.0)

        def progress(shots: int, residual: float) -> None:
            done = min(-math.log10(max(residual, 1e-300)), goal)
            bar.update(task, completed=done, shots=shots, residual=residual)

        result = run_interruptible(lambda: radiosity(scene_file.scene, progress=progress, **settings))
    keep = {k: v for k, v in scene_file.options.items() if k in ("background", "samples", "color_space", "filter")}
    output.parent.mkdir(parents=True, exist_ok=True)
    render(result.scene, scene_file.cameras[0], shading="none", **keep).save(output)
    console.print(f"wrote {output} ({result.patches} patches, {result.iterations} shots, residual "
                  f"{result.residual:.1e})", markup=False, highlight=False, soft_wrap=True)  # fmt: skip


def _click_exception(name: str) -> type[Exception]:
    """Click's exception class `name`, found through Typer's re-export (Typer may bundle its own copy of Click)."""
    return next(c for c in typer.BadParameter.__mro__ if c.__name__ == name)


_CLICK_USAGE_ERROR = _click_exception("UsageError")
_CLICK_EXCEPTION = _click_exception("ClickException")


def main(arguments: Sequence[str] | None = None) -> None:
    """Entry point of the ``frustum`` console script: one-line errors, exit 1 (2 for usage), tracebacks on --debug.

    The command runs on a worker thread (``runtime.run_interruptible``): Ctrl-C exits with status 130 within a
    fraction of a second, leaving no partial output file. Run as the program (`arguments` None), it runs as a
    short-lived program (``runtime.run_program``); called from Python the garbage collector is left alone.
    """
    if arguments is not None:
        _main(list(arguments))
        return
    run_program(lambda: _main(sys.argv[1:]))


def _main(argv: list[str]) -> None:
    _STATE["debug"] = "--debug" in argv
    install_compile_notice()
    try:
        status = run_interruptible(lambda: app(args=argv, prog_name="frustum", standalone_mode=False))
    except _CLICK_USAGE_ERROR as error:
        message = " ".join(error.format_message().split())
        if not message:  # no command given: the help was printed instead
            raise SystemExit(2) from None
        fail(message, 2)
    except typer.Abort:
        fail("aborted", 1)
    except RecursionError as error:
        if _STATE["debug"]:
            raise
        fail(*failure(error))
    except _CLICK_EXCEPTION as error:
        fail(" ".join(error.format_message().split()), error.exit_code)
    except REPORTED as error:
        if _STATE["debug"]:
            raise
        fail(*failure(error))
    if isinstance(status, int) and status:
        raise SystemExit(status)
