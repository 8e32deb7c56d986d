"""Many input files in one command: ``frustum render a.ply b.stl c.glb -o out/{stem}.png`` (and ``turntable``,
``view``, ``info``): every input in one process (or on ``--jobs N`` worker processes), no resident process needed.

- **Inputs**: files as given (a shell glob expands to them), a folder (its scene and mesh files, sorted, not its
  subfolders), or a quoted glob pattern (``"models/*.ply"``: expanded here, sorted).
- **Outputs**: ``-o`` is a pattern; ``{stem}`` (``bunny``), ``{name}`` (``bunny.ply``), ``{suffix}`` (``.ply``)
  and ``{index}`` (the input's position from 1; ``{index:03d}`` pads it) are the input's. Several inputs need a
  field in every pattern, and two inputs that would write the same file are an error before any work.
- **Failures**: one ``error: INPUT: message`` line per failed input; the others are still done; the exit status is
  1 when any failed. A Rich progress bar on stderr while there are several (a terminal only).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from frustum.app.runtime import UsageError, error_line, exit_with_parent, failure, install_compile_notice, say

__all__ = ["FIELDS", "expand_inputs", "output_paths", "render_inputs", "run_each"]

FIELDS = ("stem", "name", "suffix", "index")
"""The fields of an output pattern, each the input's."""

_GLOB_CHARACTERS = frozenset("*?[")


def input_suffixes() -> tuple[str, ...]:
    """The suffixes a folder's files are taken with: TOML scene files and the mesh files frustum reads."""
    from frustum.scenefile.loader import MODEL_SUFFIXES

    return (".toml", *MODEL_SUFFIXES)


def expand_inputs(arguments: Sequence[Path], suffixes: Sequence[str] | None = None) -> tuple[list[Path], bool]:
    """The input files of `arguments` (folders and glob patterns expanded, in order) and whether the command works
    on several (more than one argument, or any folder or pattern)."""
    suffixes = tuple(suffixes or input_suffixes())
    found: list[Path] = []
    several = len(arguments) > 1
    for argument in arguments:
        text = str(argument)
        if argument.is_dir():
            several = True
            files = sorted(path for path in argument.iterdir() if path.is_file() and path.suffix.lower() in suffixes)
            if not files:
                raise UsageError(f"the folder {text!r} holds no input file ({', '.join(suffixes)})")
            found += files
        elif not argument.exists() and _GLOB_CHARACTERS & set(text):
            import glob

            several = True
            matches = sorted(Path(match) for match in glob.glob(text) if os.path.isfile(match))
            if not matches:
                raise UsageError(f"the pattern {text!r} matches no file")
            found += matches
        else:
            found.append(argument)
    return found, several


def _fields(source: Path, index: int) -> dict[str, Any]:
    return {"stem": source.stem, "name": source.name, "suffix": source.suffix, "index": index}


def has_fields(pattern: str) -> bool:
    """Whether `pattern` names a field of ``FIELDS`` (``{stem}``, ``{index:03d}``, ...)."""
    import string

    try:
        return any(field is not None for _, field, _, _ in string.Formatter().parse(pattern))
    except ValueError:
        return True  # a malformed pattern: ``output_paths`` says what is wrong


def _format(pattern: str, source: Path, index: int) -> Path:
    try:
        return Path(pattern.format_map(_fields(source, index)))
    except KeyError as error:
        raise UsageError(f"-o {pattern!r}: {{{error.args[0]}}} is not a field; use {{stem}}, {{name}}, {{suffix}} "
                         "or {index}") from None  # fmt: skip
    except (ValueError, IndexError, AttributeError) as error:
        raise UsageError(f"-o {pattern!r} is not a pattern ({error}); e.g. out/{{stem}}.png") from None


def output_paths(inputs: Sequence[Path], patterns: Sequence[Path] | None, several: bool) -> list[list[Path] | None]:
    """Each input's output files from the ``-o`` `patterns` (None: each input's own outputs), checked before any
    work: with `several` inputs every pattern names a field, and no two inputs write the same file."""
    if not patterns:
        return [None] * len(inputs)
    texts = [str(pattern) for pattern in patterns]
    if several:
        for text in texts:
            if not has_fields(text):
                raise UsageError(f"-o {text!r} names one file for {len(inputs)} inputs; put {{stem}} (or {{name}}, "
                                 "{index}) in it, e.g. out/{stem}.png")  # fmt: skip
    outputs = [[_format(text, source, index) if has_fields(text) else Path(text) for text in texts]
               for index, source in enumerate(inputs, start=1)]  # fmt: skip
    writers: dict[str, Path] = {}
    for source, paths in zip(inputs, outputs, strict=True):
        for path in paths:
            key = os.path.normcase(os.path.abspath(path))
            if key in writers:
                other = writers[key]
                raise UsageError(f"the inputs {str(other)!r} and {str(source)!r} would both write {str(path)!r}; "
                                 "tell them apart with {name} or {index} in -o")  # fmt: skip
            writers[key] = source
    return outputs


Task = Callable[[Path, "list[Path] | None", dict[str, Any]], list[str]]
"""One input's work: (input, its outputs or None, the command's options) -> the lines to print on stdout."""


def _attempt(task: Task, source: Path, outputs: list[Path] | None, options: dict[str, Any]) -> tuple[bool, Any]:
    """(True, lines) or (False, the one-line message of the failure): one input's failure is the input's alone."""
    try:
        return True, task(source, outputs, options)
    except Exception as error:  # reported as the program reports it, the other inputs go on
        return False, failure(error)[0]


_PARENT: dict[str, int] = {}


def _init_worker(parent: int, threads: int) -> None:
    """A ``--jobs`` worker: ignore Ctrl-C (the command's process handles it), share the cores, the program's compile
    notice, and exit (removing its partial files) as soon as the command's process is gone."""
    import signal

    from frustum.raster._jit import set_threads

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    set_threads(threads)
    install_compile_notice()
    _PARENT["pid"] = parent
    exit_with_parent(parent)


def _bar_may_show(count: int) -> bool:
    """Whether Rich could show a progress bar on stderr for `count` inputs: several, and stderr a terminal or taken
    for one (``TTY_COMPATIBLE``, ``FORCE_COLOR``). When not, Rich is not even imported (a batch in a script)."""
    if count <= 1:
        return False
    if os.environ.get("TTY_COMPATIBLE") or os.environ.get("FORCE_COLOR") is not None:
        return True
    try:
        return sys.stderr.isatty()
    except ValueError:  # a closed stream
        return False


def _progress(label: str, count: int) -> Any:
    """The Rich progress bar of `count` inputs on stderr (shown on a terminal only), or None (``_bar_may_show``)."""
    if not _bar_may_show(count):
        return None
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    console = Console(stderr=True, highlight=False, soft_wrap=True)
    columns = (TextColumn(label), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
               TextColumn("{task.description}"))  # fmt: skip
    return Progress(*columns, console=console, transient=True, disable=not console.is_terminal, redirect_stdout=False,
                    redirect_stderr=False)  # fmt: skip


def run_each(task: Task, inputs: Sequence[Path], outputs: Sequence[list[Path] | None], options: dict[str, Any],
             jobs: int = 1, label: str = "render") -> int:  # fmt: skip
    """Do `task` for every input (on `jobs` worker processes when > 1), print each one's lines (stdout) or its error
    line (stderr) as it ends, with a progress bar while there are several; the exit status (1 when any failed)."""
    if jobs < 1:
        raise UsageError(f"--jobs = {jobs} is not a number of processes; give 1 or more")
    import contextlib

    progress = _progress(label, len(inputs))
    shown = progress is not None and not progress.disable
    failed = 0
    with progress if progress is not None else contextlib.nullcontext():
        bar = progress.add_task("", total=len(inputs)) if progress is not None else None

        def advance(description: str, steps: int = 0) -> None:
            if progress is not None:
                progress.update(bar, advance=steps, description=description)

        def report(source: Path, ok: bool, result: Any) -> None:
            nonlocal failed
            lines = result if ok else [error_line(f"{source}: {result}")]
            stream = sys.stdout if ok else sys.stderr
            for line in lines:
                if shown and stream.isatty():
                    progress.console.print(line, markup=False, highlight=False)
                else:
                    say(line, stream)
            failed += not ok
            advance(source.name, 1)

        if jobs == 1 or len(inputs) == 1:
            for source, paths in zip(inputs, outputs, strict=True):
                advance(source.name)
                report(source, *_attempt(task, source, paths, options))
        else:
            _pool(task, inputs, outputs, options, min(jobs, len(inputs)), report)
    return 1 if failed else 0


def _pool(task: Task, inputs: Sequence[Path], outputs: Sequence[list[Path] | None], options: dict[str, Any],
          jobs: int, report: Callable[[Path, bool, Any], None]) -> None:  # fmt: skip
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    threads = max(1, (os.cpu_count() or 1) // jobs)
    # spawn, not fork: the command runs on a worker thread, and a forked child of a threaded process can deadlock
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(jobs, mp_context=context, initializer=_init_worker,
                             initargs=(os.getpid(), threads)) as pool:  # fmt: skip
        futures = {pool.submit(_attempt, task, source, paths, options): source
                   for source, paths in zip(inputs, outputs, strict=True)}  # fmt: skip
        for future in as_completed(futures):
            report(futures[future], *future.result())


def render_inputs(scenes: Sequence[Path], output: Sequence[Path] | None, size: str | None, up: str,
                  shadows: str | None, jobs: int = 1) -> int:  # fmt: skip
    """``frustum render``: one input as before (its errors raised), several (``expand_inputs``) each in turn or on
    `jobs` processes; the exit status."""
    from frustum.app.work import image_size, render_files, render_task, shadow_choice

    inputs, several = expand_inputs(scenes)
    outputs = output_paths(inputs, output, several)
    if not several:
        for path in render_files(inputs[0], outputs[0], size, up, shadows):
            say(f"wrote {path}")
        return 0
    if size:
        image_size(size)  # a bad value fails once, before any work
    shadow_choice(shadows)
    return run_each(render_task, inputs, outputs, {"size": size, "up": up, "shadows": shadows}, jobs)
