"""L-systems: parallel string rewriting read by a 3D turtle into branch polylines or tube meshes.

Turtle commands (Prusinkiewicz & Lindenmayer, *The Algorithmic Beauty of Plants*, 1990, §1.5):

=========  ==========================================================================================
``F``/``G``  move forward one step drawing a segment
``f``        move forward one step without drawing
``+``/``-``  turn left / right by δ about the up vector U (yaw)
``&``/``^``  pitch down / up by δ about the left vector L
``\\``/``/``  roll left / right by δ about the heading H
``|``        turn around (yaw by 180°)
``[``/``]``  push / pop the turtle state (position, orientation, branch depth)
=========  ==========================================================================================

The turtle frame is right-handed, $H × L = U$. "Turn left by δ" rotates H towards L:
$H' = H cos δ + L sin δ$, $L' = −H sin δ + L cos δ$ (counter-clockwise seen from +U). Pitch down rotates H
towards −U, roll left rotates L towards U. Any other symbol must have a production (a variable such as
``X``) or be listed in ``ignore``; it is then skipped by the turtle.

References
----------
[HB 15] "Shape Grammars and Other Procedural Methods"; P. Prusinkiewicz, A. Lindenmayer, *The Algorithmic
Beauty of Plants*, Springer 1990, ch. 1.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_scalar, as_vector3, describe
from frustum.errors import GeometryError
from frustum.geometry.fractals.checks import byte_budget, check_fractal_memory, check_level
from frustum.geometry.mesh import Mesh

__all__ = ["CLASSIC_LSYSTEMS", "LSystem", "TurtlePath", "interpret", "parse_rules", "tube_mesh"]


def _kernels() -> ModuleType:
    """The compiled kernels of this module (``raster/turtle.py``), imported on first use: ``import frustum``
    never loads Numba."""
    from frustum.raster import turtle

    return turtle

TURTLE_COMMANDS = "FGf+-&^\\/|[]"
_OPCODES = {c: i + 1 for i, c in enumerate(TURTLE_COMMANDS)}  # 0 = no-op (variables, ignored symbols)


def parse_rules(rules: str | Mapping[str, str]) -> dict[str, str]:
    """Parse productions ``A -> word`` (one per line or separated by ``;``; ``→`` and ``=`` also work).

    Blank lines and text after ``#`` are ignored; spaces inside a word are dropped. A mapping is accepted too.
    Each predecessor must be a single symbol with exactly one production.

    Raises
    ------
    GeometryError
        A line without an arrow, a predecessor that is not one symbol, a repeated predecessor, or a successor
        with unbalanced brackets.
    """
    where = "parse_rules"
    out: dict[str, str] = {}
    if isinstance(rules, Mapping):
        items = [(str(k), str(v), f"rules[{k!r}]") for k, v in rules.items()]
    elif isinstance(rules, str):
        items = []
        chunks = [c for line in rules.splitlines() for c in line.split("#", 1)[0].split(";")]
        for number, chunk in enumerate(chunks, 1):
            text = chunk.strip()
            if not text:
                continue
            for arrow in ("->", "→", "="):
                if arrow in text:
                    left, right = text.split(arrow, 1)
                    break
            else:
                raise GeometryError(
                    f"{where}: rule {number} = {text!r} has no arrow; write 'A -> successor' (or '→', '=')"
                )
            items.append((left.strip(), right, f"rule {number}"))
    else:
        raise GeometryError(f"{where}: rules = {describe(rules)} is not text or a mapping; give 'A -> word' lines")
    for left, right, label in items:
        if len(left) != 1 or left.isspace():
            raise GeometryError(
                f"{where}: {label} predecessor = {left!r} is not one symbol; give a single-character predecessor"
            )
        if left in out:
            raise GeometryError(f"{where}: {label} predecessor = {left!r} has a second production; give one rule")
        word = "".join(right.split())
        _check_brackets(word, f"{where}: {label} successor")
        out[left] = word
    return out


def _check_brackets(word: str, label: str) -> None:
    depth = 0
    for i, symbol in enumerate(word):
        depth += (symbol == "[") - (symbol == "]")
        if depth < 0:
            raise GeometryError(f"{label} = {word!r} closes a bracket at position {i} that was never opened; "
                                "balance '[' and ']'")  # fmt: skip
    if depth:
        raise GeometryError(f"{label} = {word!r} leaves {depth} '[' unclosed; balance '[' and ']'")


@dataclass(frozen=True)
class LSystem:
    """A deterministic context-free L-system (D0L) with turtle parameters.

    Parameters
    ----------
    axiom : str
        The start word.
    rules : str or mapping
        Productions, see ``parse_rules``. Symbols without a production are copied unchanged.
    angle : float
        δ, the turtle's turning angle in **degrees** (the L-system literature's unit).
    ignore : str
        Extra symbols with no production and no turtle meaning, allowed in words (skipped when drawing).
    scale : float
        Step length factor per level: ``interpret(expand(n))`` uses step ``scale**n`` (1/3 for Koch keeps the
        curve's size fixed).

    Raises
    ------
    GeometryError
        Unbalanced brackets, or symbols that are neither turtle commands, variables nor ignored (all listed).
    """

    axiom: str
    rules: Any
    angle: float
    ignore: str = ""
    scale: float = 1.0
    productions: dict[str, str] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        where = "LSystem"
        if not isinstance(self.axiom, str) or not self.axiom:
            raise GeometryError(f"{where}: axiom = {describe(self.axiom)} is not a nonempty string; give a start word")
        productions = parse_rules(self.rules)
        _check_brackets(self.axiom, f"{where}: axiom")
        known = set(TURTLE_COMMANDS) | set(productions) | set(self.ignore)
        used = set(self.axiom).union(*[set(w) for w in productions.values()])
        unknown = sorted(used - known)
        if unknown:
            raise GeometryError(
                f"{where}: symbols {unknown} are unknown; use turtle commands {TURTLE_COMMANDS!r}, symbols with a "
                "production, or list them in ignore="
            )
        as_scalar(self.angle, "angle", where=where, error=GeometryError)
        s = as_scalar(self.scale, "scale", where=where, error=GeometryError)
        if s <= 0.0:
            raise GeometryError(f"{where}: scale = {s!r} is not positive; give a step factor > 0")
        object.__setattr__(self, "productions", productions)

    def length(self, level: int) -> int:
        """Exact length of the word after `level` rewritings (integer matrix power, nothing expanded)."""
        n = check_level(level, "LSystem.length")
        symbols = sorted(set(self.axiom).union(*[set(w) for w in self.productions.values()], self.productions))
        index = {s: i for i, s in enumerate(symbols)}
        counts = [0] * len(symbols)
        for s in self.axiom:
            counts[index[s]] += 1
        growth = [[0] * len(symbols) for _ in symbols]  # growth[a][b]: b's in the successor of a
        for a in symbols:
            for b in self.productions.get(a, a):
                growth[index[a]][index[b]] += 1
        for _ in range(n):
            counts = [sum(counts[a] * growth[a][b] for a in range(len(symbols))) for b in range(len(symbols))]
        return sum(counts)

    def expand(self, level: int, *, max_bytes: int | None = None) -> str:
        """The word after `level` parallel rewritings of the axiom (every symbol at once).

        Raises ``GeometryError`` before expanding when the word (plus the turtle's arrays, ~64 bytes per symbol)
        would exceed `max_bytes`.
        """
        where = "LSystem.expand"
        n = check_level(level, where)
        check_fractal_memory(self.length(n) * 64, byte_budget(max_bytes, where), where=where, name="level", value=n)
        table = str.maketrans(self.productions)
        word = self.axiom
        for _ in range(n):
            word = word.translate(table)
        return word

    def path(self, level: int, *, start: ArrayLike = (0.0, 0.0, 0.0), heading: ArrayLike = (1.0, 0.0, 0.0),
             left: ArrayLike = (0.0, 1.0, 0.0), max_bytes: int | None = None) -> TurtlePath:  # fmt: skip
        """``interpret(self.expand(level), self.angle, step=self.scale**level, ...)``."""
        return interpret(self.expand(level, max_bytes=max_bytes), self.angle, step=self.scale**level,
                         start=start, heading=heading, left=left)  # fmt: skip


@dataclass(frozen=True)
class TurtlePath:
    """What the turtle drew: segments with their branch depth.

    Attributes
    ----------
    segments : (M, 2, 3) float64
        Start and end point of each drawn step, in drawing order.
    depths : (M,) int64
        Bracket depth at which each segment was drawn (0 = trunk), for tapering tubes.
    """

    segments: NDArray[np.float64]
    depths: NDArray[np.int64]

    @property
    def polylines(self) -> list[Points]:
        """Connected runs of segments as (k, 3) polylines (a new run starts where a segment does not continue
        the previous one, e.g. after ``]`` or ``f``)."""
        seg = self.segments
        if seg.shape[0] == 0:
            return []
        breaks = np.flatnonzero(np.any(seg[1:, 0] != seg[:-1, 1], axis=1)) + 1
        runs = np.split(np.arange(seg.shape[0]), breaks)
        return [np.concatenate([seg[r, 0], seg[r[-1:], 1]]) for r in runs]

    @property
    def points(self) -> Points:
        """(M + 1, 3) the vertices of an unbranched path (start of every segment, then the last end)."""
        if self.segments.shape[0] == 0:
            return np.empty((0, 3))
        return np.concatenate([self.segments[:, 0], self.segments[-1:, 1]])


def interpret(word: str, angle: float, *, step: float = 1.0, start: ArrayLike = (0.0, 0.0, 0.0),
              heading: ArrayLike = (1.0, 0.0, 0.0), left: ArrayLike = (0.0, 1.0, 0.0)) -> TurtlePath:  # fmt: skip
    """Read `word` with the 3D turtle (commands in the module docstring); other symbols are skipped.

    Parameters
    ----------
    angle : float
        δ in degrees.
    step : float
        Length of one ``F``/``G``/``f`` step.
    heading, left : (3,) array_like
        Initial H and L (normalized; L is made orthogonal to H); U = H × L. The default draws in the xy plane
        heading +x, with ``+`` turning counter-clockwise.

    Raises
    ------
    GeometryError
        Unbalanced brackets; non-finite or degenerate frame.
    """
    where = "interpret"
    if not isinstance(word, str):
        raise GeometryError(f"{where}: word = {describe(word)} is not a string; give an L-system word")
    _check_brackets(word, f"{where}: word")
    delta = math.radians(as_scalar(angle, "angle", where=where, error=GeometryError))
    length = as_scalar(step, "step", where=where, error=GeometryError)
    p0 = as_vector3(start, "start", where=where, error=GeometryError)
    h = as_vector3(heading, "heading", where=where, error=GeometryError)
    lv = as_vector3(left, "left", where=where, error=GeometryError)
    hn = float(np.linalg.norm(h))
    if hn == 0.0:
        raise GeometryError(f"{where}: heading = {describe(h)} has zero length; give a nonzero direction")
    h = h / hn
    lv = lv - h * float(h @ lv)
    ln = float(np.linalg.norm(lv))
    if ln < 1e-12:
        raise GeometryError(f"{where}: left = {describe(left)} is parallel to heading; give a perpendicular vector")
    lv = lv / ln
    frame = np.ascontiguousarray(np.stack([h, lv, np.cross(h, lv)]))
    lookup = np.zeros(256, dtype=np.int64)
    for symbol, code in _OPCODES.items():
        lookup[ord(symbol)] = code
    raw = np.frombuffer(word.encode("utf-32-le"), dtype=np.uint32).astype(np.int64)
    codes = np.where(raw < 256, lookup[np.minimum(raw, 255)], 0)
    n_draw = int(np.count_nonzero((codes == 1) | (codes == 2)))
    depth = np.cumsum((codes == 11).astype(np.int64) - (codes == 12))
    max_depth = int(depth.max(initial=0))
    segments = np.empty((n_draw, 2, 3))
    depths = np.empty(n_draw, dtype=np.int64)
    written = _kernels()._turtle_kernel(codes, math.cos(delta), math.sin(delta), length, frame, p0, max_depth,
                                        segments, depths)  # fmt: skip
    assert written == n_draw
    return TurtlePath(segments, depths)


def tube_mesh(path: TurtlePath, radius: float = 0.1, *, taper: float = 0.7, sides: int = 6,
              max_bytes: int | None = None) -> Mesh:  # fmt: skip
    """A closed prism (tube with end caps) around every segment of `path`.

    A segment at branch depth d has radius $radius·taper**d$. Each tube has `sides` quads (two triangles
    each) and two fan caps of $sides − 2$ triangles, wound outward.

    Returns
    -------
    Mesh with 2·sides vertices and 4·sides − 4 faces per segment.
    """
    where = "tube_mesh"
    if not isinstance(path, TurtlePath):
        raise GeometryError(f"{where}: path = {describe(path)} is not a TurtlePath; give interpret(...)'s result")
    r0 = as_scalar(radius, "radius", where=where, error=GeometryError)
    tp = as_scalar(taper, "taper", where=where, error=GeometryError)
    if r0 <= 0.0 or tp <= 0.0:
        raise GeometryError(f"{where}: radius = {r0!r}, taper = {tp!r} must both be positive; give values > 0")
    if isinstance(sides, bool) or not isinstance(sides, int) or sides < 3:
        raise GeometryError(f"{where}: sides = {describe(sides)} is not an integer >= 3; give at least 3 sides")
    seg = np.asarray(path.segments, dtype=np.float64)
    if seg.ndim != 3 or seg.shape[1:] != (2, 3) or not np.isfinite(seg).all():
        raise GeometryError(f"{where}: path.segments has shape {seg.shape} or non-finite values; give (M, 2, 3) finite")
    if np.shape(path.depths) != (seg.shape[0],):
        raise GeometryError(
            f"{where}: path.depths has shape {np.shape(path.depths)}; give one depth per segment ({seg.shape[0]},)"
        )
    m = seg.shape[0]
    check_fractal_memory(m * (2 * sides * 3 * 8 * 3 + (4 * sides - 4) * 3 * 8), byte_budget(max_bytes, where),
                         where=where, name="segments", value=m)  # fmt: skip
    if m == 0:
        return Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=np.int64))
    p, q = seg[:, 0], seg[:, 1]
    axis = q - p
    length = np.linalg.norm(axis, axis=1)
    # a zero-length segment gets an arbitrary axis (its tube is a flat disc, still finite)
    axis = np.where((length > 0)[:, None], axis / np.where(length > 0, length, 1.0)[:, None], [[0.0, 0.0, 1.0]])
    helper = np.where((np.abs(axis[:, 2]) < 0.9)[:, None], [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    u = np.cross(axis, helper)
    u /= np.linalg.norm(u, axis=1)[:, None]
    v = np.cross(axis, u)  # (u, v, axis) right-handed
    r = r0 * tp ** np.asarray(path.depths, dtype=np.float64)
    theta = 2.0 * np.pi * np.arange(sides) / sides
    ring = np.cos(theta)[None, :, None] * u[:, None, :] + np.sin(theta)[None, :, None] * v[:, None, :]
    ring = ring * r[:, None, None]
    vertices = np.concatenate([p[:, None, :] + ring, q[:, None, :] + ring], axis=1).reshape(-1, 3)
    i = np.arange(sides)
    j = (i + 1) % sides
    side_faces = np.concatenate([np.column_stack([i, j, j + sides]), np.column_stack([i, j + sides, i + sides])])
    fan = np.arange(1, sides - 1)
    bottom = np.column_stack([np.zeros_like(fan), fan + 1, fan])  # seen from −axis: counter-clockwise
    top = np.column_stack([np.full_like(fan, sides), fan + sides, fan + 1 + sides])
    local = np.concatenate([side_faces, bottom, top])
    faces = (local[None] + (2 * sides * np.arange(m))[:, None, None]).reshape(-1, 3).astype(np.int64)
    return Mesh(vertices, faces)


CLASSIC_LSYSTEMS: dict[str, LSystem] = {
    # Koch curve: same vertices as fractals.koch_curve(level) (segment 3^-level)
    "koch": LSystem("F", "F -> F+F--F+F", angle=60.0, scale=1 / 3),
    "koch_snowflake": LSystem("F--F--F", "F -> F+F--F+F", angle=60.0, scale=1 / 3),
    "sierpinski_arrowhead": LSystem("F", "F -> G-F-G; G -> F+G+F", angle=60.0, scale=1 / 2),
    "dragon": LSystem("FX", "X -> X+YF+; Y -> -FX-Y", angle=90.0),
    "hilbert": LSystem("A", "A -> +BF-AFA-FB+; B -> -AF+BFB+FA-", angle=90.0, scale=1 / 2),
    # ABOP fig. 1.24(f)
    "plant": LSystem("X", "X -> F+[[X]-X]-F[-FX]+X; F -> FF", angle=25.0, scale=1 / 2),
    # a 3D bush after ABOP fig. 1.25: branches rolled about the heading
    "tree_3d": LSystem(
        "A", "A -> [&FL!A]/////[&FL!A]///////[&FL!A]; F -> S/////F; S -> FL; L -> ", angle=22.5, ignore="!"
    ),
}
"""Classic L-systems by name; draw one with ``CLASSIC_LSYSTEMS[name].path(level)``."""
