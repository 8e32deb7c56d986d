"""The record of an algorithm at work: ``Step`` (one moment), ``Steps`` (the sequence) and their pictures.

A ``Steps`` holds the steps, the production function's result (``Steps.result``) and a painter that draws step
i onto a small vector canvas (``_Canvas``: world coordinates fixed for the whole sequence, so an animation does
not jump). From there: ``figure(i)`` (one SVG), ``save(path)`` (``.svg`` sheet or numbered files, ``.gif`` /
``.mp4`` one frame per step, ``.html`` a standalone page with a slider, ``.md`` a table) and ``_repr_html_``
(the slider in Jupyter).
"""

from __future__ import annotations

import html
import io
import itertools
import json
import math
import os
import textwrap
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, overload

import numpy as np

from frustum._files import atomic_path
from frustum.budgets import check_memory
from frustum.errors import OutputError

__all__ = ["FIGURE_HEIGHT", "FIGURE_WIDTH", "SAVE_FORMATS", "Step", "Steps"]

FIGURE_WIDTH = 640
"""Width of every step figure, in SVG user units (pixels when rasterized for an animation)."""
FIGURE_HEIGHT = 560
"""Height of every step figure: a 400-unit drawing above a caption (title, text, values)."""
_DRAWING_HEIGHT = 400
SAVE_FORMATS = (".gif", ".html", ".md", ".mp4", ".svg")
"""Suffixes ``Steps.save`` writes."""

# the figures' palette (one place): geometry, this step's element, accepted / rejected, faint context
COLORS = {
    "ink": "#222222",
    "faint": "#b8b8b8",
    "region": "#e8eef7",
    "highlight": "#d9480f",
    "accept": "#2b8a3e",
    "reject": "#c92a2a",
    "blue": "#1c63b7",
    "purple": "#7048e8",
}


@dataclass(frozen=True)
class Step:
    """One moment of an algorithm: a one-line `title`, a short paragraph `text` naming the test or formula
    applied (in the notes' terms), and `values`, the numbers involved (codes as 6-bit strings, u1/u2, ...)."""

    title: str
    text: str
    values: Mapping[str, Any] = field(default_factory=dict)


def format_value(value: Any) -> str:
    """A short, readable text of a value: numbers to 4 significant digits, arrays as nested brackets."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool | np.bool_):
        return str(bool(value))
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, float | np.floating):
        number = float(value)
        if number == 0.0:
            return "0"
        return f"{number:.4g}"
    if isinstance(value, np.ndarray | list | tuple):
        array = np.asarray(value, dtype=object) if isinstance(value, list | tuple) else value
        if array.ndim == 0:
            return format_value(array.item())
        return "(" + ", ".join(format_value(item) for item in array) + ")"
    return str(value)


class _Canvas:
    """World (x, y up) → figure (x right, y down) inside the drawing box; collects SVG elements."""

    def __init__(self, bounds: Sequence[float], width: float = FIGURE_WIDTH, height: float = _DRAWING_HEIGHT,
                 margin: float = 24.0) -> None:  # fmt: skip
        x0, y0, x1, y1 = (float(b) for b in bounds)
        span_x, span_y = max(x1 - x0, 1e-12), max(y1 - y0, 1e-12)
        self.scale = min((width - 2 * margin) / span_x, (height - 2 * margin) / span_y)
        self.offset_x = (width - self.scale * span_x) / 2.0 - self.scale * x0
        self.offset_y = (height + self.scale * span_y) / 2.0 + self.scale * y0
        self.elements: list[str] = []

    def xy(self, point: Sequence[float]) -> tuple[float, float]:
        return self.offset_x + self.scale * float(point[0]), self.offset_y - self.scale * float(point[1])

    def _points(self, points: Any) -> str:
        return " ".join("{:.2f},{:.2f}".format(*self.xy(p)) for p in np.asarray(points, dtype=float))

    def line(self, a: Sequence[float], b: Sequence[float], color: str = "ink", width: float = 1.5,
             dash: bool = False) -> None:  # fmt: skip
        (x0, y0), (x1, y1) = self.xy(a), self.xy(b)
        dashes = ' stroke-dasharray="5 4"' if dash else ""
        self.elements.append(
            f'<line x1="{x0:.2f}" y1="{y0:.2f}" x2="{x1:.2f}" y2="{y1:.2f}" stroke="{COLORS.get(color, color)}" '
            f'stroke-width="{width}"{dashes}/>'
        )

    def polyline(self, points: Any, color: str = "ink", width: float = 1.5, closed: bool = False,
                 fill: str | None = None, dash: bool = False, opacity: float = 1.0) -> None:  # fmt: skip
        if len(points) == 0:
            return
        tag = "polygon" if closed else "polyline"
        paint = COLORS.get(fill, fill) if fill else "none"
        dashes = ' stroke-dasharray="5 4"' if dash else ""
        self.elements.append(
            f'<{tag} points="{self._points(points)}" fill="{paint}" fill-opacity="{opacity}" '
            f'stroke="{COLORS.get(color, color)}" stroke-width="{width}" stroke-linejoin="round"{dashes}/>'
        )

    def rect(self, corner0: Sequence[float], corner1: Sequence[float], color: str = "ink", fill: str | None = None,
             width: float = 1.0, opacity: float = 1.0) -> None:  # fmt: skip
        (xa, ya), (xb, yb) = self.xy(corner0), self.xy(corner1)
        paint = COLORS.get(fill, fill) if fill else "none"
        self.elements.append(
            f'<rect x="{min(xa, xb):.2f}" y="{min(ya, yb):.2f}" width="{abs(xb - xa):.2f}" '
            f'height="{abs(yb - ya):.2f}" fill="{paint}" fill-opacity="{opacity}" '
            f'stroke="{COLORS.get(color, color)}" stroke-width="{width}"/>'
        )

    def dot(self, point: Sequence[float], color: str = "ink", radius: float = 4.0, label: str = "") -> None:
        x, y = self.xy(point)
        self.elements.append(f'<circle cx="{x:.2f}" cy="{y:.2f}" r="{radius}" fill="{COLORS.get(color, color)}"/>')
        if label:
            self.label((x + radius + 3, y - radius - 2), label, color=color, world=False)

    def image(self, rgb: np.ndarray, corner0: Sequence[float], corner1: Sequence[float]) -> None:
        """An (H, W, 3|4) uint8 image as an embedded PNG, stretched over the world box corner0–corner1, pixels kept
        sharp (a buffer, not a photograph)."""
        import base64

        from PIL import Image

        buffer = io.BytesIO()
        Image.fromarray(np.ascontiguousarray(rgb)).save(buffer, format="PNG")
        data = base64.b64encode(buffer.getvalue()).decode("ascii")
        (xa, ya), (xb, yb) = self.xy(corner0), self.xy(corner1)
        self.elements.append(
            f'<image x="{min(xa, xb):.2f}" y="{min(ya, yb):.2f}" width="{abs(xb - xa):.2f}" '
            f'height="{abs(yb - ya):.2f}" preserveAspectRatio="none" style="image-rendering:pixelated" '
            f'href="data:image/png;base64,{data}"/>'
        )

    def label(self, point: Sequence[float], text: str, color: str = "ink", size: float = 13.0,
              world: bool = True, anchor: str = "start") -> None:  # fmt: skip
        x, y = self.xy(point) if world else (float(point[0]), float(point[1]))
        self.elements.append(
            f'<text x="{x:.2f}" y="{y:.2f}" font-family="DejaVu Sans, sans-serif" font-size="{size}" '
            f'text-anchor="{anchor}" fill="{COLORS.get(color, color)}">{html.escape(text)}</text>'
        )


Painter = Callable[[int, _Canvas], None]


class Steps(Sequence[Step]):
    """The steps of one run of an algorithm, its result, and their figures.

    A sequence of ``Step`` (``len``, indexing, iteration). ``result`` is the production function's return value
    for the same inputs (the last step shows it); ``algorithm`` names the method.
    """

    def __init__(self, algorithm: str, steps: Sequence[Step], result: Any, painter: Painter,
                 bounds: Sequence[float]) -> None:  # fmt: skip
        if not steps:
            raise OutputError(f"Steps: algorithm {algorithm!r} recorded no steps; a record needs at least one")
        self.algorithm = algorithm
        self._steps = tuple(steps)
        self.result = result
        self._painter = painter
        self._bounds = tuple(float(b) for b in bounds)

    def __repr__(self) -> str:
        return f"Steps({self.algorithm!r}, {len(self)} steps)"

    def __len__(self) -> int:
        return len(self._steps)

    @overload
    def __getitem__(self, index: int) -> Step: ...
    @overload
    def __getitem__(self, index: slice) -> tuple[Step, ...]: ...
    def __getitem__(self, index: int | slice) -> Step | tuple[Step, ...]:
        return self._steps[index]

    def __iter__(self) -> Iterator[Step]:
        return iter(self._steps)

    # --- pictures ---------------------------------------------------------------------------------------

    def _index(self, i: Any, where: str) -> int:
        if isinstance(i, bool) or not isinstance(i, int | np.integer) or not -len(self) <= i < len(self):
            raise OutputError(f"{where}: i = {i!r} is not a step index; give an integer in [0, {len(self) - 1}]")
        return int(i) % len(self)

    def figure(self, i: int) -> str:
        """Step `i` as a standalone SVG document (the geometry, this step's highlighted element, a caption)."""
        index = self._index(i, "Steps.figure")
        canvas = _Canvas(self._bounds)
        self._painter(index, canvas)
        step = self._steps[index]
        caption = _caption(step, index, len(self))
        return (
            f'<svg xmlns="http://www.w3.org/2000/svg" width="{FIGURE_WIDTH}" height="{FIGURE_HEIGHT}" '
            f'viewBox="0 0 {FIGURE_WIDTH} {FIGURE_HEIGHT}">\n'
            f"<title>{html.escape(self.algorithm)}: step {index + 1} of {len(self)}: {html.escape(step.title)}"
            "</title>\n"
            f'<rect width="{FIGURE_WIDTH}" height="{FIGURE_HEIGHT}" fill="white"/>\n'
            + "\n".join(canvas.elements)
            + "\n"
            + caption
            + "\n</svg>\n"
        )

    def sheet(self, columns: int = 3) -> str:
        """All figures on one SVG sheet, `columns` across, in step order."""
        rows = math.ceil(len(self) / columns)
        cells = []
        for i in range(len(self)):
            row, column = divmod(i, columns)
            body = self.figure(i).split("\n", 1)[1].rsplit("</svg>", 1)[0]
            cells.append(
                f'<svg x="{column * FIGURE_WIDTH}" y="{row * FIGURE_HEIGHT}" width="{FIGURE_WIDTH}" '
                f'height="{FIGURE_HEIGHT}" viewBox="0 0 {FIGURE_WIDTH} {FIGURE_HEIGHT}">\n{body}</svg>'
            )
        width, height = columns * FIGURE_WIDTH, rows * FIGURE_HEIGHT
        return (
            f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
            f'viewBox="0 0 {width} {height}">\n' + "\n".join(cells) + "\n</svg>\n"
        )

    def to_markdown(self) -> str:
        """The steps as a Markdown table: number, title, text, values."""
        lines = [f"**{_markdown(self.algorithm)}**", "", "| # | step | what happens | values |", "|---|---|---|---|"]
        for i, step in enumerate(self._steps):
            values = "; ".join(f"{k} = {format_value(v)}" for k, v in step.values.items())
            lines.append(f"| {i + 1} | {_markdown(step.title)} | {_markdown(step.text)} | {_markdown(values)} |")
        return "\n".join(lines) + "\n"

    def to_html(self, standalone: bool = True) -> str:
        """The figures behind a slider (and previous / next buttons); a full page when `standalone`."""
        ident = f"frustum-steps-{next(_ids)}"
        figures = "\n".join(
            f'<div class="frustum-step" data-step="{i}" style="display:{"block" if i == 0 else "none"}">'
            f"{self.figure(i)}"
            "</div>"
            for i in range(len(self))
        )
        fragment = (
            f'<div id="{ident}" class="frustum-steps" style="font-family:sans-serif;max-width:{FIGURE_WIDTH}px">\n'
            f'<div><button type="button" class="prev">&#9664;</button> '
            f'<input type="range" class="slider" min="0" max="{len(self) - 1}" value="0" step="1" '
            f'style="width:{FIGURE_WIDTH - 180}px" aria-label="step"> '
            f'<button type="button" class="next">&#9654;</button> '
            f'<span class="counter">1 / {len(self)}</span></div>\n{figures}\n</div>\n'
            f"<script>{_SLIDER_SCRIPT.replace('__ID__', json.dumps(ident))}</script>\n"
        )
        if not standalone:
            return fragment
        return (
            '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
            f"<title>{html.escape(self.algorithm)}: {len(self)} steps</title>\n</head>\n<body>\n"
            f'<h1 style="font-family:sans-serif;font-size:1.3em">{html.escape(self.algorithm)}</h1>\n'
            f"{fragment}</body>\n</html>\n"
        )

    def _repr_html_(self) -> str:
        return self.to_html(standalone=False)

    def frames(self) -> Iterator[np.ndarray]:
        """Each figure rasterized (cairosvg) to an (H, W, 3) uint8 image, in step order."""
        import cairosvg
        from PIL import Image

        for i in range(len(self)):
            png = cairosvg.svg2png(bytestring=self.figure(i).encode("utf-8"))
            with Image.open(io.BytesIO(png)) as image:
                yield np.asarray(image.convert("RGB"))

    def save(self, path: str | os.PathLike, fps: float = 1.0, sheet: bool = True) -> list[Path]:
        """Write the steps: ``.svg`` (one sheet, or with ``sheet=False`` numbered files ``name-01.svg`` ...),
        ``.gif`` / ``.mp4`` (one frame per step, `fps` frames per second), ``.html`` (a page with a slider) or
        ``.md`` (a table). Returns the paths written.

        Raises
        ------
        OutputError
            Unknown suffix, unwritable path, fps out of range, MP4 without imageio-ffmpeg.
        """
        target = Path(os.fspath(path))
        suffix = target.suffix.lower()
        if suffix not in SAVE_FORMATS:
            raise OutputError(
                f"Steps.save: path = {str(target)!r} has suffix {suffix!r}; expected one of "
                + ", ".join(repr(s) for s in SAVE_FORMATS)
            )
        if suffix in (".gif", ".mp4"):
            from frustum.output.animation import write_animation

            write_animation(self.frames(), target, fps=fps)
            return [target]
        if suffix == ".svg" and not sheet:
            width = len(str(len(self)))
            paths = [target.with_name(f"{target.stem}-{i + 1:0{max(2, width)}d}.svg") for i in range(len(self))]
            for i, numbered in enumerate(paths):
                _write_text(numbered, self.figure(i))
            return paths
        text = {".svg": self.sheet, ".html": self.to_html, ".md": self.to_markdown}[suffix]()
        _write_text(target, text)
        return [target]


RECORDING_BASE_BYTES = 2**18
"""What any recording costs besides its drawn elements (steps, captions, the page): about 256 KiB."""


def log_geometric_sum(ratio: float, terms: int) -> float:
    """ln(Σ_{k=0}^{terms−1} ratio^k) = ln((ratio^terms − 1)/(ratio − 1)) for ratio > 1, computed in log space so that
    any number of terms gives a finite float (no OverflowError)."""
    exponent = terms * math.log(ratio)
    return exponent + math.log1p(-math.exp(-exponent)) - math.log(ratio - 1.0)


def check_recording(log_elements: float, bytes_per_element: float, where: str, cause: str) -> None:
    """Refuse, before any work, a recording of about e^log_elements drawn elements of `bytes_per_element` each
    (measured: the peak memory of building the steps and writing their sheet, per element) over the memory
    budget. The estimate is made in log space: ``level = 100000`` gives the budget's error, not an overflow."""
    log_bytes = math.log(bytes_per_element) + log_elements
    nbytes = RECORDING_BASE_BYTES + math.exp(min(log_bytes, 700.0))  # e^700 ≈ 1e304: still a float
    check_memory(nbytes, where=where, cause=cause, error=OutputError)


_ids = itertools.count(1)

_SLIDER_SCRIPT = """
(function () {
  var root = document.getElementById(__ID__);
  if (!root) { return; }
  var slider = root.querySelector('.slider');
  var figures = root.querySelectorAll('.frustum-step');
  var counter = root.querySelector('.counter');
  function show(i) {
    i = Math.max(0, Math.min(figures.length - 1, i));
    slider.value = String(i);
    for (var k = 0; k < figures.length; k++) {
      figures[k].style.display = (k === i) ? 'block' : 'none';
    }
    counter.textContent = (i + 1) + ' / ' + figures.length;
  }
  slider.addEventListener('input', function () { show(parseInt(slider.value, 10)); });
  root.querySelector('.prev').addEventListener('click', function () { show(parseInt(slider.value, 10) - 1); });
  root.querySelector('.next').addEventListener('click', function () { show(parseInt(slider.value, 10) + 1); });
})();
"""


def _write_text(path: Path, text: str) -> None:
    with atomic_path(path, where="Steps.save") as temporary:
        temporary.write_text(text, encoding="utf-8")


def _markdown(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _caption(step: Step, index: int, count: int) -> str:
    """Title (bold), the text wrapped, and the values, in the band below the drawing."""
    lines = [
        f'<line x1="16" y1="{_DRAWING_HEIGHT}" x2="{FIGURE_WIDTH - 16}" y2="{_DRAWING_HEIGHT}" stroke="#cccccc"/>',
        f'<text x="16" y="{_DRAWING_HEIGHT + 22}" font-family="DejaVu Sans, sans-serif" font-size="15" '
        f'font-weight="bold" fill="#222222">{index + 1}/{count}  {html.escape(step.title)}</text>',
    ]
    y = _DRAWING_HEIGHT + 42
    body = textwrap.wrap(step.text, 92)[:4]
    values = "; ".join(f"{k} = {format_value(v)}" for k, v in step.values.items())
    value_lines = textwrap.wrap(values, 96)[: max(1, 7 - len(body))]
    for text, color in [(t, "#333333") for t in body] + [(t, "#1c63b7") for t in value_lines]:
        lines.append(
            f'<text x="16" y="{y}" font-family="DejaVu Sans, sans-serif" font-size="12" fill="{color}">'
            f"{html.escape(text)}</text>"
        )
        y += 16
    return "\n".join(lines)
