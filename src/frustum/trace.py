"""``trace``: every stage of the viewing pipeline for a few points (or a scene), with its matrix and coordinates.

The seed's pipeline, stage by stage, as the renderer runs it (``render/``)::

    modeling ──world_from_model──▶ world ──T(−P0)──▶ ──R(u, v, n)──▶ view ──projection──▶ ──normalization──▶ clip
      ──region codes (clipping)──▶ ──divide by w──▶ NDC ──window_from_ndc──▶ window (pixel x, y up; depth)

Each ``Stage`` holds the matrix that takes the previous stage's coordinates to its own (None where the stage
is not a matrix: the modeling input, clipping, the divide, or a step that another matrix already includes) and
the coordinates of every traced point there: homogeneous ``(N, 4)`` rows up to the clipping stage, Cartesian
``(N, 3)`` after the divide. Window positions agree with ``Camera.project`` and with the pixel that
``render(scene, camera, mode="points")`` draws for each vertex.

References: [HB 10] "The Three-Dimensional Viewing Pipeline"; [seed] "Three-Dimensional Viewing Pipeline".
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Matrix4, Points, as_matrix, as_points, describe, read_only
from frustum.camera import Camera
from frustum.clipping import clip_lines, clip_triangles, region_code
from frustum.clipping.codes import region_names
from frustum.errors import FrustumError
from frustum.geometry import Mesh
from frustum.scene import Scene
from frustum.transforms import Step

__all__ = ["STAGE_NAMES", "SegmentClipping", "Stage", "Trace", "TracedPart", "TriangleClipping", "trace"]

STAGE_NAMES = (
    "modeling",
    "world",
    "view_translate",
    "view_rotate",
    "projection",
    "normalization",
    "clipping",
    "perspective_divide",
    "viewport",
)
"""The stages of every trace, in pipeline order (``Trace.stage(name)`` looks one up)."""

_TITLES = {
    "modeling": "Modeling coordinates",
    "world": "World coordinates (modeling transformation)",
    "view_translate": "Viewing transformation, step 1: translate the view point to the origin",
    "view_rotate": "Viewing transformation, step 2: rotate u, v, n onto x, y, z (view coordinates)",
    "projection": "Projection",
    "normalization": "Normalization to the symmetric cube (clip coordinates)",
    "clipping": "Clipping: region codes against -w <= x, y, z <= w",
    "perspective_divide": "Perspective divide (normalized device coordinates)",
    "viewport": "Viewport transformation (window coordinates: pixel x, y up, depth in [0, 1])",
}
_FLIP_Z = np.diag([1.0, 1.0, -1.0, 1.0])
_SHOWN_POINTS = 8  # points listed per stage in the text reports; the arrays hold them all


class Stage(NamedTuple):
    """One stage of the pipeline: its matrix (from the previous stage) and the traced points' coordinates there.

    ``points`` is ``(N, 4)`` homogeneous up to ``"clipping"`` and ``(N, 3)`` from ``"perspective_divide"`` on;
    ``points_here = points_before @ matrix.T`` ($P' = M·P$) wherever ``matrix`` is not None. ``codes`` holds
    the six-bit region code of each point at the clipping stage (None elsewhere).
    """

    name: str
    """One of ``STAGE_NAMES``."""
    description: str
    """What the stage does, in the textbook's words (which step, or why there is no matrix)."""
    matrix: Matrix4 | None
    """(4, 4) float64 column-vector matrix ``b_from_a``, or None; the row-vector form is ``matrix.T``."""
    points: NDArray[np.float64]
    """(N, 4) or (N, 3) float64 coordinates at this stage."""
    codes: NDArray[np.int64] | None = None
    """(N,) int64 region codes (``clipping.region_code``) at the clipping stage, else None."""

    @property
    def title(self) -> str:
        """The stage's heading in reports."""
        return _TITLES[self.name]

    @property
    def row_matrix(self) -> Matrix4 | None:
        """The row-vector form $Mᵀ$ ($P' = P·Mᵀ$), or None."""
        return None if self.matrix is None else self.matrix.T


class TriangleClipping(NamedTuple):
    """What clipping does to each triangle of a traced mesh (``clipping.clip_triangles``)."""

    faces: NDArray[np.int64]
    """(M, 3) int64 vertex indices of the triangles."""
    accepted: NDArray[np.bool_]
    """(M,) bool: wholly inside (the OR of the corner codes is 0), kept unchanged."""
    rejected: NDArray[np.bool_]
    """(M,) bool: wholly outside one plane (the AND of the corner codes is nonzero), dropped."""
    pieces: NDArray[np.int64]
    """(M,) int64: how many triangles each one becomes (1 if accepted, 0 if rejected or clipped away)."""

    @property
    def clipped(self) -> NDArray[np.bool_]:
        """(M,) bool: crossing a plane, cut by Sutherland–Hodgman."""
        return ~self.accepted & ~self.rejected

    def summary(self) -> str:
        """One sentence: how many triangles were accepted, rejected and clipped, and into how many pieces."""
        clipped = self.clipped
        total = int(self.accepted.size)
        return (
            f"{total} triangle{'s' * (total != 1)}: {int(self.accepted.sum())} inside (trivially accepted), "
            f"{int(self.rejected.sum())} outside (trivially rejected), {int(clipped.sum())} crossing a plane, "
            f"clipped into {int(self.pieces[clipped].sum())} triangles "
            f"({int((clipped & (self.pieces == 0)).sum())} vanished)"
        )


class SegmentClipping(NamedTuple):
    """What clipping does to each segment of a traced polyline (Liang–Barsky, ``clipping.clip_lines``)."""

    segments: NDArray[np.int64]
    """(K, 2) int64 point indices of each segment, ``(i, i + 1)``."""
    accepted: NDArray[np.bool_]
    """(K,) bool: both ends inside (the OR of their codes is 0), kept unchanged."""
    rejected: NDArray[np.bool_]
    """(K,) bool: both ends outside one plane (the AND of their codes is nonzero), dropped."""
    parameters: NDArray[np.float64]
    """(K, 2) float64 visible part ``[u_start, u_end]`` of ``P = P1 + (P2 − P1)u``; ``(1, 0)`` if none."""

    @property
    def visible(self) -> NDArray[np.bool_]:
        """(K,) bool: some part of the segment is inside."""
        return self.parameters[:, 0] <= self.parameters[:, 1]

    def summary(self) -> str:
        """One sentence: how many segments were accepted, rejected and clipped."""
        clipped = ~self.accepted & ~self.rejected
        total = int(self.accepted.size)
        return (
            f"{total} segment{'s' * (total != 1)}: {int(self.accepted.sum())} inside (trivially accepted), "
            f"{int(self.rejected.sum())} outside (trivially rejected), {int(clipped.sum())} clipped "
            f"({int((clipped & ~self.visible).sum())} of them wholly outside)"
        )

    def details(self) -> list[str]:
        """One line per segment (the first few): its status and visible parameter range."""
        lines = []
        for k, (i, j) in enumerate(self.segments[:_SHOWN_POINTS]):
            if self.accepted[k]:
                status = "inside: kept whole"
            elif self.rejected[k]:
                status = "outside: dropped"
            elif self.visible[k]:
                u0, u1 = self.parameters[k]
                status = f"clipped: u in [{_number(float(u0))}, {_number(float(u1))}] stays"
            else:
                status = "clipped: nothing inside"
            lines.append(f"segment p{i}-p{j}: {status}")
        if self.segments.shape[0] > _SHOWN_POINTS:
            lines.append(f"... {self.segments.shape[0] - _SHOWN_POINTS} more segments")
        return lines


class TracedPart(NamedTuple):
    """The trace of one point set or one placed mesh: its label, its stages and what clipping does to its
    triangles (a mesh) or segments (a polyline)."""

    label: str
    stages: tuple[Stage, ...]
    triangles: TriangleClipping | None = None
    segments: SegmentClipping | None = None

    def clipping_notes(self) -> list[str]:
        """Text lines on the clipping of triangles or segments (empty for plain points)."""
        notes = []
        if self.triangles is not None:
            notes.append(self.triangles.summary())
        if self.segments is not None:
            notes += [self.segments.summary(), *self.segments.details()]
        return notes

    def stage(self, name: str) -> Stage:
        """The stage called `name` (one of ``STAGE_NAMES``)."""
        for stage in self.stages:
            if stage.name == name:
                return stage
        raise FrustumError(
            f"Trace.stage: name = {describe(name)} is unknown; expected one of " + ", ".join(STAGE_NAMES)
        )


@dataclass(frozen=True, eq=False)
class Trace:
    """What ``trace`` returns: every stage's matrix and coordinates, printable for teaching.

    ``str(trace)`` is a plain-text report; ``to_markdown()`` and ``to_latex()`` give the same content to paste
    into notes; Jupyter shows the Markdown (``_repr_markdown_``) and Rich prints tables (``__rich__``). Every
    matrix appears twice: the column-vector form ``M`` ($P' = M·P$, frustum's) and the row-vector form
    $Mᵀ$ ($P' = P·Mᵀ$).
    """

    camera: Camera
    parts: tuple[TracedPart, ...]

    @property
    def stages(self) -> tuple[Stage, ...]:
        """The stages of the first (for a point list, the only) traced part."""
        return self.parts[0].stages

    def stage(self, name: str, part: int = 0) -> Stage:
        """The stage called `name` of part `part` (0 for a point list)."""
        if (
            isinstance(part, bool)
            or not isinstance(part, int | np.integer)
            or not -len(self.parts) <= part < len(self.parts)
        ):
            raise FrustumError(
                f"Trace.stage: part = {describe(part)} is not a part index; expected an integer in "
                f"[0, {len(self.parts) - 1}]"
            )
        return self.parts[part].stage(name)

    @property
    def window(self) -> Points:
        """(N, 3) window coordinates of every traced point, all parts in order (NaN rows where w <= 0)."""
        return np.concatenate([part.stage("viewport").points for part in self.parts]).reshape(-1, 3)

    # --- reports ------------------------------------------------------------------------------------------

    def _header(self) -> str:
        camera = self.camera
        count = sum(part.stages[0].points.shape[0] for part in self.parts)
        return (
            f"{count} point{'s' * (count != 1)} through the viewing pipeline; camera {camera.width}x{camera.height}, "
            f"eye {_vector(camera.frame.eye)}, u {_vector(camera.frame.u)}, v {_vector(camera.frame.v)}, "
            f"n {_vector(camera.frame.n)}, {camera.projection!r}"
        )

    def __str__(self) -> str:
        lines = ["Trace: " + self._header(), ""]
        for part in self.parts:
            if len(self.parts) > 1:
                lines += [f"=== {part.label} ===", ""]
            for number, stage in enumerate(part.stages, start=1):
                lines.append(f"{number}. {stage.title}")
                lines.append(f"   {stage.description}")
                if stage.matrix is not None:
                    lines.append("   column vectors, P' = M·P:")
                    lines += ["     " + row for row in _grid(stage.matrix)]
                    lines.append("   row vectors, P' = P·Mᵀ:")
                    lines += ["     " + row for row in _grid(stage.matrix.T)]
                lines.append("   points:")
                lines += ["     " + row for row in _point_lines(stage)]
                if stage.name == "clipping":
                    lines += ["   " + note for note in part.clipping_notes()]
                lines.append("")
        return "\n".join(lines).rstrip() + "\n"

    def to_markdown(self) -> str:
        """The report as Markdown: a heading per stage, matrices and points as tables."""
        lines = ["## Trace", "", _markdown_escape(self._header()), ""]
        for part in self.parts:
            if len(self.parts) > 1:
                lines += [f"## {_markdown_escape(part.label)}", ""]
            for number, stage in enumerate(part.stages, start=1):
                lines += [f"### {number}. {stage.title}", "", _markdown_escape(stage.description), ""]
                if stage.matrix is not None:
                    lines += ["Column vectors, P' = M·P:", "", *_markdown_matrix(stage.matrix), ""]
                    lines += ["Row vectors, P' = P·Mᵀ:", "", *_markdown_matrix(stage.matrix.T), ""]
                lines += [*_markdown_points(stage), ""]
                if stage.name == "clipping" and part.clipping_notes():
                    lines += [*(f"- {_markdown_escape(note)}" for note in part.clipping_notes()), ""]
        return "\n".join(lines).rstrip() + "\n"

    def _repr_markdown_(self) -> str:
        return self.to_markdown()

    def to_latex(self) -> str:
        """The report as a LaTeX fragment (needs ``amsmath``): a subsection per stage, ``bmatrix`` matrices."""
        lines = [r"\section*{Trace}", _latex_escape(self._header()), ""]
        for part in self.parts:
            if len(self.parts) > 1:
                lines += [rf"\subsection*{{{_latex_escape(part.label)}}}", ""]
            for number, stage in enumerate(part.stages, start=1):
                lines += [
                    rf"\subsubsection*{{{number}. {_latex_escape(stage.title)}}}",
                    _latex_escape(stage.description),
                ]
                if stage.matrix is not None:
                    lines += [
                        r"\[",
                        r"M = " + _latex_matrix(stage.matrix) + r" \quad (P' = M P), \qquad",
                        r"M^{\mathsf{T}} = " + _latex_matrix(stage.matrix.T) + r" \quad (P' = P M^{\mathsf{T}})",
                        r"\]",
                    ]
                lines += _latex_points(stage)
                if stage.name == "clipping" and part.clipping_notes():
                    notes = part.clipping_notes()
                    lines += [r"\begin{itemize}", *(rf"\item {_latex_escape(n)}" for n in notes), r"\end{itemize}"]
                lines.append("")
        return "\n".join(lines).rstrip() + "\n"

    def __rich__(self) -> Any:
        """Rich renderable: a table per stage with both matrix forms and the points."""
        from rich.console import Group
        from rich.table import Table
        from rich.text import Text

        items: list[Any] = [Text("Trace: " + self._header(), style="bold")]
        for part in self.parts:
            if len(self.parts) > 1:
                items.append(Text(part.label, style="bold underline"))
            for number, stage in enumerate(part.stages, start=1):
                items += [Text(f"{number}. {stage.title}", style="bold"), Text(stage.description, style="dim")]
                if stage.matrix is not None:
                    matrices = Table()
                    matrices.add_column("M (P' = M·P)", justify="right")
                    matrices.add_column("Mᵀ (P' = P·Mᵀ)", justify="right")
                    matrices.add_row("\n".join(_grid(stage.matrix)), "\n".join(_grid(stage.matrix.T)))
                    items.append(matrices)
                header, rows = _point_table(stage)
                points = Table()
                for column in header:
                    points.add_column(column, justify="left" if column in ("point", "region") else "right")
                for row in rows:
                    points.add_row(*row)
                items.append(points)
                if stage.name == "clipping":
                    items += [Text(note) for note in part.clipping_notes()]
        return Group(*items)


# --- formatting helpers ---------------------------------------------------------------------------------------


def _number(value: float) -> str:
    """6 significant digits; within 1e-12 of an integer prints as that integer (cos 90° = 6e-17 → 0)."""
    if not np.isfinite(value):
        return "nan" if np.isnan(value) else ("inf" if value > 0 else "-inf")
    rounded = round(value)
    if abs(value - rounded) <= 1e-12 * max(1.0, abs(value)):
        value = float(rounded)
    return f"{value + 0.0:.6g}"


def _vector(values: ArrayLike) -> str:
    return "(" + ", ".join(_number(float(v)) for v in np.asarray(values).ravel()) + ")"


def _grid(matrix: Matrix4) -> list[str]:
    cells = [[_number(float(v)) for v in row] for row in matrix]
    width = max(len(c) for row in cells for c in row)
    return ["[ " + "  ".join(c.rjust(width) for c in row) + " ]" for row in cells]


def _region_text(code: int, w: float) -> str:
    if code == 0:
        return "inside" if w > 0 else "outside (w <= 0)"
    return "outside: " + ", ".join(region_names(code))


def _axes(stage: Stage) -> tuple[str, ...]:
    return ("x", "y", "z", "w") if stage.points.shape[1] == 4 else ("x", "y", "z")


def _point_table(stage: Stage) -> tuple[list[str], list[list[str]]]:
    """Header and rows (first _SHOWN_POINTS points) of a stage's point table."""
    header = ["point", *_axes(stage)]
    if stage.codes is not None:
        header += ["code", "region"]
    rows = []
    for i, point in enumerate(stage.points[:_SHOWN_POINTS]):
        row = [f"p{i}", *(_number(float(v)) for v in point)]
        if stage.codes is not None:
            code = int(stage.codes[i])
            row += [f"{code:06b}", _region_text(code, float(point[3]))]
        rows.append(row)
    if stage.points.shape[0] > _SHOWN_POINTS:
        rows.append([f"... {stage.points.shape[0] - _SHOWN_POINTS} more", *([""] * (len(header) - 1))])
    return header, rows


def _point_lines(stage: Stage) -> list[str]:
    _, rows = _point_table(stage)
    if not rows:
        return ["(no points)"]
    lines = []
    for row in rows:
        if row[0].startswith("..."):
            lines.append(row[0])
            continue
        text = f"{row[0]} = ({', '.join(row[1 : 1 + len(_axes(stage))])})"
        if stage.codes is not None:
            text += f"  code {row[-2]}  {row[-1]}"
        lines.append(text)
    return lines


def _markdown_escape(text: str) -> str:
    return "".join("\\" + c if c in "\\`*_[]<>|#" else c for c in text)


def _markdown_matrix(matrix: Matrix4) -> list[str]:
    rows = [[_number(float(v)) for v in row] for row in matrix]
    return ["|   |   |   |   |", "|--:|--:|--:|--:|", *("| " + " | ".join(r) + " |" for r in rows)]


def _markdown_points(stage: Stage) -> list[str]:
    header, rows = _point_table(stage)
    return [
        "| " + " | ".join(header) + " |",
        "|" + "|".join(":--" if c in ("point", "region") else "--:" for c in header) + "|",
        *("| " + " | ".join(_markdown_escape(c) for c in row) + " |" for row in rows),
    ]


_LATEX_SPECIAL = {
    "\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
    "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}",
    "<": r"$<$", ">": r"$>$", "³": r"$^3$", "×": r"$\times$",
    "·": r"$\cdot$", "ᵀ": r"$^{\mathsf{T}}$", "−": "-", "→": r"$\to$", "≤": r"$\le$", "°": r"$^\circ$",
}  # fmt: skip


def _latex_escape(text: str) -> str:
    return "".join(_LATEX_SPECIAL.get(c, c) for c in text)


def _latex_matrix(matrix: Matrix4) -> str:
    rows = (" & ".join(_number(float(v)) for v in row) for row in matrix)
    return r"\begin{bmatrix} " + r" \\ ".join(rows) + r" \end{bmatrix}"


def _latex_points(stage: Stage) -> list[str]:
    header, rows = _point_table(stage)
    spec = "".join("l" if c in ("point", "region") else "r" for c in header)
    return [
        rf"\begin{{tabular}}{{{spec}}}",
        " & ".join(header) + r" \\ \hline",
        *(" & ".join(_latex_escape(c) for c in row) + r" \\" for row in rows),
        r"\end{tabular}",
    ]


# --- the trace itself ---------------------------------------------------------------------------------------------


def _placed_meshes(scene: Any) -> Iterator[tuple[str, Mesh, Matrix4]]:
    """(label, mesh, world_from_model) of every placed mesh: ``scene.walk()`` if the scene has one, else items."""
    walk = getattr(scene, "walk", None)
    entries = walk() if callable(walk) else scene.items
    index = 0
    for entry in entries:
        if hasattr(entry, "mesh") and hasattr(entry, "world_from_model"):
            mesh, matrix = entry.mesh, entry.world_from_model
        else:  # a plain (mesh, material, world_from_model) tuple
            mesh, matrix = entry[0], entry[-1]
        if mesh is None:  # a group node: nothing to draw
            continue
        name = getattr(getattr(entry, "node", None), "name", None) or getattr(entry, "name", None)
        label = f"item {index}" + (f" ({name})" if name else "") + f": {mesh.vertex_count} vertices"
        index += 1
        yield label, mesh, np.asarray(matrix, dtype=np.float64)


_BOX_FACES = np.array([[0, 3, 2], [0, 1, 3], [4, 7, 5], [4, 6, 7], [0, 5, 1], [0, 4, 5], [2, 7, 6], [2, 3, 7],
                       [0, 6, 4], [0, 2, 6], [1, 7, 3], [1, 5, 7]], dtype=np.int64)  # fmt: skip
"""The 12 triangles of a box whose corner ``4i + 2j + k`` is (i, j, k) ∈ {0, 1}³ (outward winding)."""


def _placed_volumes(scene: Any) -> Iterator[tuple[str, NDArray[np.float64], Matrix4]]:
    """(label, the 8 model-space corners of the grid's box, world_from_model) of every placed volume."""
    for index, item in enumerate(getattr(scene, "volumes", ())):
        volume = item.volume
        grid = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=np.float64)
        grid *= np.array(volume.shape, dtype=np.float64) - 1.0
        model = grid @ volume.model_from_grid[:3, :3].T + volume.model_from_grid[:3, 3]
        shape = "x".join(str(n) for n in volume.shape)
        label = f"volume {index} ({item.mode}, {shape} grid): the 8 corners of its box"
        yield label, model, np.asarray(item.world_from_model, dtype=np.float64)


def _projection_steps(camera: Camera) -> tuple[tuple[str, Matrix4 | None], tuple[str, Matrix4 | None]]:
    """(description, matrix) of the projection and the normalization stage; their product is clip_from_view."""
    steps = list(camera.projection.steps(camera.aspect))
    if camera.frame.handedness == "left":  # the camera turns left-handed view coordinates right-handed first
        steps[0] = Step(steps[0].name + " (after z → −z: left- to right-handed view)", steps[0].matrix @ _FLIP_Z)
    if len(steps) == 2:
        return (steps[0].name, steps[0].matrix), (steps[1].name, steps[1].matrix)
    (step,) = steps
    if camera.projection.parallel:
        return (
            "orthogonal projection: projectors along z_view, so x and y stay as they are and z is kept for depth "
            "(no matrix; the normalization does the rest)",
            None,
        ), (step.name, step.matrix)
    return (step.name + " (maps the frustum onto the clip cube -w <= x, y, z <= w)", step.matrix), (
        "included in the projection matrix above (no separate matrix)",
        None,
    )


def _trace_points(points_model: Points, world_from_model: Matrix4, camera: Camera, label: str) -> TracedPart:
    stages: list[Stage] = []
    current = np.column_stack([points_model, np.ones(points_model.shape[0])])

    def add(name: str, description: str, matrix: Matrix4 | None) -> None:
        nonlocal current
        if matrix is not None:
            matrix = read_only(np.array(matrix, dtype=np.float64))
            current = current @ matrix.T  # P' = M·P for each row
        stages.append(Stage(name, description, matrix, read_only(current.copy())))

    add("modeling", "the points in their own (model) coordinates, as homogeneous columns (x, y, z, 1)", None)
    add("world", "world_from_model: the modeling transformation that places the points in the world",
        world_from_model)  # fmt: skip
    translate_step, rotate_step = camera.frame.steps
    add("view_translate", translate_step.name + " (T(−P0))", translate_step.matrix)
    add("view_rotate", rotate_step.name + " (rows u, v, n)", rotate_step.matrix)
    (projection_text, projection), (normalization_text, normalization) = _projection_steps(camera)
    add("projection", projection_text, projection)
    add("normalization", normalization_text, normalization)
    clip = current
    codes = read_only(np.asarray(region_code(clip), dtype=np.int64).reshape(-1))
    inside = int(((codes == 0) & (clip[:, 3] > 0)).sum())
    stages.append(
        Stage(
            "clipping",
            f"region codes, bits far near top bottom right left (high to low): {inside} of {codes.size} points "
            "inside the view volume; a point outside is clipped (not drawn)",
            None,
            stages[-1].points,
            codes,
        )
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        ndc = clip[:, :3] / clip[:, 3:]
    ndc[clip[:, 3] <= 0.0] = np.nan  # on or behind the eye plane: no image (as Camera.project)
    stages.append(
        Stage(
            "perspective_divide",
            "(x, y, z, w) → (x/w, y/w, z/w): the cube [-1, 1]³ (NaN where w <= 0: no image)",
            None,
            read_only(ndc),
        )
    )
    window_from_ndc = read_only(np.array(camera.viewport_matrix))
    window = ndc @ window_from_ndc[:3, :3].T + window_from_ndc[:3, 3]
    stages.append(
        Stage(
            "viewport",
            f"window_from_ndc = viewport(0, 0, {camera.width}, {camera.height}): pixel column floor(x), row "
            "height − 1 − floor(y) from the top, depth (z + 1)/2",
            window_from_ndc,
            read_only(window),
        )
    )
    return TracedPart(label, tuple(stages))


def _clip_faces(part: TracedPart, faces: NDArray[np.int64]) -> TriangleClipping:
    stage = part.stage("clipping")
    corner_codes = stage.codes[faces] if faces.size else np.zeros((0, 3), dtype=np.int64)
    accepted = np.bitwise_or.reduce(corner_codes, axis=1) == 0
    rejected = np.bitwise_and.reduce(corner_codes, axis=1) != 0
    clipped = clip_triangles(stage.points, faces)
    pieces = np.bincount(clipped.face_sources, minlength=faces.shape[0]).astype(np.int64)
    return TriangleClipping(read_only(faces), read_only(accepted), read_only(rejected), read_only(pieces))


def _clip_polyline(part: TracedPart) -> SegmentClipping:
    stage = part.stage("clipping")
    count = stage.points.shape[0]
    segments = np.column_stack([np.arange(count - 1), np.arange(1, count)]).astype(np.int64).reshape(-1, 2)
    codes = stage.codes[segments]
    accepted = (codes[:, 0] | codes[:, 1]) == 0
    rejected = (codes[:, 0] & codes[:, 1]) != 0
    clipped = clip_lines(stage.points[segments[:, 0]], stage.points[segments[:, 1]])
    return SegmentClipping(read_only(segments), read_only(accepted), read_only(rejected), read_only(clipped.parameters))


def trace(
    points_or_scene: ArrayLike | Mesh | Scene, camera: Camera, *, model: ArrayLike | None = None, polyline: bool = False
) -> Trace:
    """Follow points (or every vertex of a mesh or scene) through each stage of the viewing pipeline.

    $window = window_from_ndc · divide(normalization · projection · R(u, v, n) · T(−P0) · world_from_model · P)$
    — the renderer's order; the window positions equal ``camera.project`` of the world points and the pixels
    ``render(..., mode="points")`` draws.

    Parameters
    ----------
    points_or_scene : (N, 3) or (3,) array_like, Mesh, or Scene
        Points in model coordinates; a ``Mesh`` (its vertices, and what clipping does to its triangles); or a
        ``Scene`` (every vertex of every placed mesh, one ``TracedPart`` per mesh, in drawing order; then one
        part per placed volume (``Scene.add_volume``): the 8 corners of its grid's box, model coordinates
        $model_from_grid·(i, j, k)$, and what clipping does to the box's 12 triangles — the region its rays
        are cast through).
    camera : Camera
    model : (4, 4) array_like, optional
        world_from_model for points or a mesh (identity by default). A scene places its meshes itself.
    polyline : bool
        For points: also connect them in order, p0–p1–p2–…, and report what Liang–Barsky clipping keeps of
        each segment (``TracedPart.segments``).

    Returns
    -------
    Trace
        ``parts`` (one per point set or placed mesh), each with the stages of ``STAGE_NAMES``.

    Raises
    ------
    FrustumError
        If `camera` is not a Camera, the points are not (N, 3) finite numbers (GeometryError), `model` is not
        a finite affine (4, 4) matrix, or `model` is given with a scene.

    References
    ----------
    [HB 10] "The Three-Dimensional Viewing Pipeline", "Transformation from World to Viewing Coordinates",
    "Clipping in Three-Dimensional Homogeneous Coordinates", "The Viewport Transformation and
    Three-Dimensional Screen Coordinates"; [seed] "Three-Dimensional Viewing Pipeline".
    """
    where = "trace"
    if not isinstance(camera, Camera):
        raise FrustumError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at(...)")
    if isinstance(points_or_scene, Scene) or hasattr(points_or_scene, "walk"):
        if model is not None:
            raise FrustumError(
                f"{where}: model = {describe(model)} was given with a scene; a scene places each mesh by its own "
                "world_from_model, so leave model out"
            )
        parts = []
        for label, mesh, world_from_model in _placed_meshes(points_or_scene):
            part = _trace_points(mesh.vertices, world_from_model, camera, label)
            parts.append(part._replace(triangles=_clip_faces(part, mesh.faces)))
        for label, corners, world_from_model in _placed_volumes(points_or_scene):  # ray cast inside their boxes
            part = _trace_points(corners, world_from_model, camera, label)
            parts.append(part._replace(triangles=_clip_faces(part, _BOX_FACES)))
        if not parts:
            parts.append(_trace_points(np.empty((0, 3)), np.eye(4), camera, "empty scene"))
        return Trace(camera, tuple(parts))
    world_from_model = np.eye(4) if model is None else as_matrix(model, "model", where=where, error=FrustumError)
    if abs(world_from_model[3] - (0.0, 0.0, 0.0, 1.0)).max() != 0.0:
        raise FrustumError(
            f"{where}: model bottom row = {describe(world_from_model[3])} makes it projective; a modeling "
            "transformation is affine (bottom row 0, 0, 0, 1)"
        )
    if isinstance(points_or_scene, Mesh):
        mesh = points_or_scene
        part = _trace_points(mesh.vertices, world_from_model, camera, f"mesh: {mesh.vertex_count} vertices")
        return Trace(camera, (part._replace(triangles=_clip_faces(part, mesh.faces)),))
    try:
        single = np.shape(points_or_scene) == (3,)
    except ValueError:  # ragged nested sequences: as_points names the problem
        single = False
    values = np.atleast_2d(points_or_scene) if single else points_or_scene
    points = as_points(values, "points", where=where)
    part = _trace_points(points, world_from_model, camera, f"{points.shape[0]} points")
    if polyline:
        part = part._replace(segments=_clip_polyline(part))
    return Trace(camera, (part,))
