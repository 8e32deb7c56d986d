"""Polylines: connected line segments in model coordinates, the drawable form of curves and control polygons."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import Points, as_points, read_only
from frustum.errors import GeometryError

__all__ = ["Polyline"]


@dataclass(frozen=True, eq=False)
class Polyline:
    """Points ``P_0 … P_{N−1}`` (N, 3) joined by the segments ``P_i P_{i+1}`` (and ``P_{N−1} P_0`` when ``closed``).

    ``markers=True`` draws the points themselves (as squares of the line width plus two pixels) instead of the
    segments, e.g. the control points of a curve. The renderer draws polylines as depth-tested lines in the
    material's color in every mode. Raises ``GeometryError`` for non-finite points or wrong shapes.
    """

    points: Points
    closed: bool = False
    markers: bool = False

    def __post_init__(self) -> None:
        points = as_points(self.points, "points", where="Polyline")
        if not isinstance(self.closed, bool) or not isinstance(self.markers, bool):
            raise GeometryError(
                f"Polyline: closed = {self.closed!r}, markers = {self.markers!r}; both must be True or False"
            )
        object.__setattr__(self, "points", read_only(points))

    @property
    def vertex_count(self) -> int:
        """N, the number of points."""
        return int(self.points.shape[0])

    @cached_property
    def segments(self) -> NDArray[np.int64]:
        """(S, 2) index pairs of the drawn segments: N − 1 open, N closed (none for fewer than 2 points)."""
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
