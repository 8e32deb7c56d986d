"""The ``frustum`` command (Typer + Rich). Errors print as one line and exit 1, without a traceback."""

from __future__ import annotations

from collections.abc import Callable
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from frustum import __version__
from frustum.errors import FrustumError
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


class UsageError(FrustumError):
    """A command-line argument that frustum cannot read."""


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
) -> None:
    """The classical 3D graphics pipeline, inspectable at every stage."""


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


def main() -> None:
    """Entry point of the ``frustum`` console script."""
    try:
        app()
    except FrustumError as error:
        error_console.print(f"error: {error}", markup=False)
        raise SystemExit(1) from None
