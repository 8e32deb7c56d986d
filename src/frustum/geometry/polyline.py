"""Polylines: connected line segments in model coordinates, the drawable form of curves and control polygons."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Points, as_count, as_points, read_only
from frustum.budgets import check_memory
from frustum.errors import GeometryError

__all__ = ["Polyline"]


@dataclass(frozen=True, eq=False)
class Polyline:
    """Points $P_0 … P_{N−1}$ (N, 3) joined by the segments ``P_i P_{i+1}`` (and $P_{N−1} P_0$ when ``closed``).

    ``markers=True`` draws the points themselves (as squares of the line width plus two pixels) instead of the
    segments, e.g. the control points of a curve. ``pairs`` (S, 2) indices replace the consecutive segments by
    any set of segments (``from_segments``, e.g. a control net). The renderer draws polylines as depth-tested,
    depth-cued lines in the material's color in every mode. Points may be 2D (z = 0 is added). Raises
    ``GeometryError`` for non-finite points, wrong shapes or indices out of range.
    """

    points: Points
    closed: bool = False
    markers: bool = False
    pairs: NDArray[np.int64] | None = None
    curve: Any = field(default=None, repr=False, compare=False)
    """The curve this polyline was flattened from (``from_curve``), kept so exact outputs (SVG Bézier paths
    under parallel projections) can use its control points."""

    def __post_init__(self) -> None:
        raw = np.asarray(self.points, dtype=np.float64) if not isinstance(self.points, np.ndarray) else self.points
        if raw.ndim == 2 and raw.shape[1] == 2:
            raw = np.column_stack([raw, np.zeros(raw.shape[0])])
        points = as_points(raw, "points", where="Polyline")
        if not isinstance(self.closed, bool) or not isinstance(self.markers, bool):
            raise GeometryError(
                f"Polyline: closed = {self.closed!r}, markers = {self.markers!r}; both must be True or False"
            )
        object.__setattr__(self, "points", read_only(points))
        if self.pairs is not None:
            pairs = np.asarray(self.pairs)
            if pairs.ndim != 2 or pairs.shape[1] != 2 or not np.issubdtype(pairs.dtype, np.integer):
                raise GeometryError(f"Polyline: pairs has shape {pairs.shape}; expected (S, 2) integer indices")
            if pairs.size and (pairs.min() < 0 or pairs.max() >= points.shape[0]):
                raise GeometryError(
                    f"Polyline: pairs index {int(pairs.max())} or {int(pairs.min())} is outside [0, {points.shape[0]})"
                )
            object.__setattr__(self, "pairs", read_only(np.ascontiguousarray(pairs, dtype=np.int64)))

    @classmethod
    def from_segments(cls, segments: ArrayLike) -> Polyline:
        """Separate segments (S, 2, 3) (e.g. ``BezierPatchSet.control_net()``) as one drawable polyline."""
        array = np.asarray(segments, dtype=np.float64)
        if array.ndim != 3 or array.shape[1] != 2 or array.shape[2] not in (2, 3):
            raise GeometryError(f"Polyline.from_segments: segments has shape {array.shape}; expected (S, 2, 3)")
        return cls(array.reshape(-1, array.shape[2]), pairs=np.arange(2 * array.shape[0]).reshape(-1, 2))

    @classmethod
    def from_curve(cls, curve: Any, tolerance: float = 1e-3, samples: int | None = None) -> Polyline:
        """A curve of ``frustum.geometry.curves`` as a polyline: adaptive ``curve.flatten(tolerance)`` (chord
        within `tolerance` of the curve) or, with `samples`, that many parameter values evenly over its domain."""
        if samples is not None:
            as_count(samples, "samples", 2, where="Polyline.from_curve")
        if samples is None and hasattr(curve, "flatten"):
            return cls(curve.flatten(tolerance), curve=curve)
        if not hasattr(curve, "evaluate") or not hasattr(curve, "domain"):
            raise GeometryError(f"Polyline.from_curve: curve = {curve!r} has no evaluate/domain; give a curve")
        low, high = curve.domain
        count = 200 if samples is None else as_count(samples, "samples", 2, where="Polyline.from_curve")
        check_memory(count * 3 * 8 * 4, where="Polyline.from_curve", cause=f"samples = {count}", error=GeometryError)
        return cls(curve.evaluate(np.linspace(low, high, count)), curve=curve)

    @classmethod
    def control_polygon(cls, curve: Any, markers: bool = False) -> Polyline:
        """The control polygon of a curve (its control points joined in order), or the points alone."""
        points = np.asarray(curve.control_points, dtype=np.float64)
        return cls(points.reshape(-1, points.shape[-1]), markers=markers)

    @property
    def vertex_count(self) -> int:
        """N, the number of points."""
        return int(self.points.shape[0])

    @cached_property
    def segments(self) -> NDArray[np.int64]:
        """(S, 2) index pairs of the drawn segments: N − 1 open, N closed (none for fewer than 2 points)."""
        if self.pairs is not None:
            return self.pairs
        n = self.vertex_count
        if n < 2:
            return read_only(np.empty((0, 2), dtype=np.int64))
        starts = np.arange(n if self.closed and n > 2 else n - 1, dtype=np.int64)
        return read_only(np.column_stack([starts, (starts + 1) % n]))

    @cached_property
    def bounds(self) -> Points:
        """(2, 3): the minimum and maximum corner of the axis-aligned bounding box (NaN for no points)."""
        if self.vertex_count == 0:
            return read_only(np.full((2, 3), np.nan))
        return read_only(np.stack([self.points.min(axis=0), self.points.max(axis=0)]))
