"""A Rich progress bar of views: done, skipped, failed, views per second and time left."""

from __future__ import annotations

import time
from typing import Any

__all__ = ["ViewProgress"]


class ViewProgress:
    """Context manager counting views on a Rich progress bar (on stderr); ``enabled=False`` counts silently.

    ``skip(n)`` counts views found done by an earlier run, ``advance(result)`` one finished view (failed when
    ``result.error`` is set). Views per second count views rendered in this run only.
    """

    def __init__(self, total: int, *, enabled: bool = True, description: str = "views") -> None:
        self.total, self.enabled, self.description = total, enabled, description
        self.done = self.skipped = self.failed = 0
        self._progress: Any = None
        self._task: Any = None
        self._start = time.perf_counter()

    def __enter__(self) -> ViewProgress:
        self._start = time.perf_counter()
        if self.enabled:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

            self._progress = Progress(
                TextColumn("{task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn("done {task.fields[done]} · skipped {task.fields[skipped]} · failed {task.fields[failed]}"),
                TextColumn("{task.fields[rate]} views/s"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
                transient=False,
            )
            self._progress.start()
            self._task = self._progress.add_task(self.description, total=self.total, **self._fields())
        return self

    def __exit__(self, *exc: object) -> None:
        if self._progress is not None:
            self._refresh(0)
            self._progress.stop()

    @property
    def rate(self) -> float:
        """Views rendered (done or failed) per second in this run."""
        elapsed = time.perf_counter() - self._start
        return (self.done + self.failed) / elapsed if elapsed > 0 else 0.0

    def _fields(self) -> dict[str, Any]:
        return {"done": self.done, "skipped": self.skipped, "failed": self.failed, "rate": f"{self.rate:.1f}"}

    def _refresh(self, advance: int) -> None:
        if self._progress is not None:
            self._progress.update(self._task, advance=advance, **self._fields())

    def skip(self, count: int = 1) -> None:
        self.skipped += count
        self._refresh(count)

    def advance(self, result: Any) -> None:
        if result.error is None:
            self.done += 1
        else:
            self.failed += 1
        self._refresh(1)
