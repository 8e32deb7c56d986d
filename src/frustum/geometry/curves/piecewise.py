"""Piecewise Bézier curves and the continuity of their joins (parametric C⁰–C² and geometric G¹–G²)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import describe, read_only
from frustum.errors import GeometryError
from frustum.geometry.curves._validation import (
    FloatArray,
    _as_control_points,
    _as_knot_vector,
    _as_parameters,
    _shape_result,
)
from frustum.geometry.curves.bezier import BezierCurve, _de_casteljau


class Continuity(NamedTuple):
    """The order of continuity at one join: ``parametric`` n for Cⁿ, ``geometric`` n for Gⁿ (−1: broken).

    Orders above 2 are not classified (2 means "at least 2"). Geometric >= parametric always, since equal
    derivatives are proportional ones.
    """

    parametric: int
    geometric: int

    def __str__(self) -> str:
        names = [f"C{self.parametric}" if self.parametric >= 0 else "not C0"]
        names.append(f"G{self.geometric}" if self.geometric >= 0 else "not G0")
        return " ".join(names)


class PiecewiseBezier:
    """Bézier pieces of one degree joined end to end, piece i on the global parameter interval [b_i, b_{i+1}].

    The constructors ``from_tangents`` (C¹) and ``interpolate_c2`` (C²) enforce continuity at the joins; the
    plain constructor accepts any pieces and ``continuity`` reports what they have.

    Parameters
    ----------
    pieces : sequence of BezierCurve or (M, n + 1, d) array_like
        The pieces' control polygons, all of the same degree n and dimension d.
    breakpoints : (M + 1,) array_like, optional
        Strictly increasing global parameters of the joins; default 0, 1, ..., M.

    References
    ----------
    [seed] "Piecewise Cubic Bezier Curves", "Parametric continuity conditions"; [HB 14] "Parametric Continuity
    Conditions", "Geometric Continuity Conditions".
    """

    __slots__ = ("breakpoints", "control_points")
    control_points: FloatArray
    breakpoints: FloatArray

    def __init__(self, pieces: Sequence[BezierCurve] | ArrayLike, breakpoints: ArrayLike | None = None) -> None:
        where = "PiecewiseBezier"
        if isinstance(pieces, Sequence) and pieces and all(isinstance(p, BezierCurve) for p in pieces):
            shapes = {p.control_points.shape for p in pieces}
            if len(shapes) != 1:
                raise GeometryError(
                    f"{where}: pieces have control polygons of shapes {sorted(shapes)}; give pieces of one degree "
                    "and dimension"
                )
            array = np.stack([p.control_points for p in pieces])
        else:
            try:
                array = np.asarray(pieces, dtype=np.float64)
            except (TypeError, ValueError):
                raise GeometryError(
                    f"{where}: pieces = {describe(pieces)} is not numeric; give BezierCurves or an (M, n + 1, d) array"
                ) from None
        if array.ndim != 3 or array.shape[0] < 1 or array.shape[1] < 2 or array.shape[2] not in (2, 3):
            raise GeometryError(
                f"{where}: pieces has shape {array.shape}; expected (M, n + 1, d) with M >= 1, n >= 1, d = 2 or 3"
            )
        bad = np.argwhere(~np.isfinite(array).all(axis=2))
        if bad.size:
            m, i = (int(v) for v in bad[0])
            raise GeometryError(
                f"{where}: pieces[{m}][{i}] = {describe(array[m, i])} is not finite; coordinates must be finite"
            )
        count = array.shape[0]
        if breakpoints is None:
            knots = np.arange(count + 1, dtype=np.float64)
        else:
            knots = _as_knot_vector(breakpoints, "breakpoints", where=where)
            if knots.size != count + 1:
                raise GeometryError(
                    f"{where}: len(breakpoints) = {knots.size} does not match {count} pieces; give {count + 1} values"
                )
            step = np.flatnonzero(np.diff(knots) <= 0)
            if step.size:
                i = int(step[0])
                raise GeometryError(
                    f"{where}: breakpoints[{i + 1}] = {float(knots[i + 1])!r} is not above breakpoints[{i}] = "
                    f"{float(knots[i])!r}; give strictly increasing breakpoints"
                )
        self.control_points = read_only(np.ascontiguousarray(array))
        self.breakpoints = read_only(knots)

    def __repr__(self) -> str:
        return f"PiecewiseBezier(pieces={len(self)}, degree={self.degree}, dimension={self.dimension})"

    def __len__(self) -> int:
        return int(self.control_points.shape[0])

    @property
    def pieces(self) -> tuple[BezierCurve, ...]:
        """The pieces as ``BezierCurve`` objects, each on its own [0, 1]."""
        return tuple(BezierCurve._from_parts(p) for p in self.control_points)

    @property
    def degree(self) -> int:
        return int(self.control_points.shape[1] - 1)

    @property
    def dimension(self) -> int:
        return int(self.control_points.shape[2])

    @property
    def domain(self) -> tuple[float, float]:
        return (float(self.breakpoints[0]), float(self.breakpoints[-1]))

    def _locate(self, u: ArrayLike, where: str) -> tuple[NDArray[np.int64], FloatArray, bool]:
        s, scalar = _as_parameters(u, "u", *self.domain, where=where)
        index = np.clip(np.searchsorted(self.breakpoints, s, side="right") - 1, 0, len(self) - 1)
        width = self.breakpoints[index + 1] - self.breakpoints[index]
        return index, np.clip((s - self.breakpoints[index]) / width, 0.0, 1.0), scalar

    def evaluate(self, u: ArrayLike) -> FloatArray:
        """Points at global parameters u in [b_0, b_M]; a join belongs to the piece that starts there."""
        index, t, scalar = self._locate(u, "PiecewiseBezier.evaluate")
        out = np.empty((t.size, self.dimension))
        for piece in np.unique(index):
            mask = index == piece
            out[mask] = _de_casteljau(self.control_points[piece], t[mask])
        return _shape_result(out, scalar)

    __call__ = evaluate

    def derivative(self) -> PiecewiseBezier:
        """The derivative with respect to the global parameter: each hodograph divided by its interval width."""
        n = self.degree
        widths = np.diff(self.breakpoints)[:, None, None]
        if n == 1:
            d = np.repeat(np.diff(self.control_points, axis=1), 2, axis=1) / widths
        else:
            d = n * np.diff(self.control_points, axis=1) / widths
        return PiecewiseBezier(d, self.breakpoints)

    def flatten(
        self,
        tolerance: float | None = None,
        *,
        pixel_size: float | None = None,
        project: Callable[[FloatArray], ArrayLike] | None = None,
        max_depth: int = 24,
    ) -> FloatArray:
        """One polyline through all pieces (see ``BezierCurve.flatten``); shared join points appear once."""
        parts = [p.flatten(tolerance, pixel_size=pixel_size, project=project, max_depth=max_depth) for p in self.pieces]
        return np.concatenate([parts[0], *[p[1:] for p in parts[1:]]])

    @classmethod
    def from_tangents(
        cls, points: ArrayLike, tangents: ArrayLike, breakpoints: ArrayLike | None = None
    ) -> PiecewiseBezier:
        """The C¹ cubic through `points` with the given derivatives there (piecewise Hermite in Bézier form).

        Piece k is $[P_k, P_k + h_k·R_k/3, P_{k+1} − h_k·R_{k+1}/3, P_{k+1}]$ with h_k the width of its
        parameter interval, so the first derivative is the same on both sides of every join (C¹).
        """
        where = "PiecewiseBezier.from_tangents"
        P = _as_control_points(points, "points", where=where, min_count=2)
        R = _as_control_points(tangents, "tangents", where=where, dimensions=(P.shape[1],))
        if R.shape[0] != P.shape[0]:
            raise GeometryError(
                f"{where}: len(tangents) = {R.shape[0]} does not match len(points) = {P.shape[0]}; give one "
                "tangent per point"
            )
        knots = np.arange(P.shape[0], dtype=np.float64) if breakpoints is None else np.asarray(breakpoints, float)
        h = np.diff(knots)[:, None]
        pieces = np.stack([P[:-1], P[:-1] + h * R[:-1] / 3.0, P[1:] - h * R[1:] / 3.0, P[1:]], axis=1)
        return cls(pieces, None if breakpoints is None else knots)

    @classmethod
    def interpolate_c2(cls, points: ArrayLike, end: str = "natural") -> PiecewiseBezier:
        """The C² cubic through `points` (uniform parameter): ``CubicSpline(points, end).to_bezier()``."""
        from frustum.geometry.curves.splines import CubicSpline  # (the spline's pieces are a PiecewiseBezier)

        return CubicSpline(points, end=end).to_bezier()


def _derivatives_at_join(curve: PiecewiseBezier, join: int) -> tuple[FloatArray, FloatArray]:
    """(3, d) arrays [C, C', C''] at the end of piece `join` and at the start of piece `join + 1`."""
    widths = np.diff(curve.breakpoints)
    n = curve.degree

    def ends(k: int, at_end: bool) -> FloatArray:
        P = curve.control_points[k]
        index = -1 if at_end else 0
        values = [P[index]]
        d1 = n * np.diff(P, axis=0)
        values.append(d1[index] / widths[k])
        d2 = (n - 1) * np.diff(d1, axis=0) if n >= 2 else np.zeros((1, P.shape[1]))
        values.append(d2[index] / widths[k] ** 2)
        return np.stack(values)

    return ends(join, True), ends(join + 1, False)


def continuity(curve: PiecewiseBezier, at: int | None = None, tolerance: float = 1e-9) -> Continuity | list[Continuity]:
    """Classify the join(s) of a piecewise curve as C⁰/C¹/C² and G⁰/G¹/G².

    The seed's definitions, with derivatives taken with respect to the global parameter:

    - C⁰: the last point of one section is the first point of the next; C¹: the first derivatives are equal;
      C²: the first and second derivatives are equal.
    - Gⁿ: the derivatives are only proportional. G¹: same unit tangent. G²: G¹ and the same curvature vector
      $(C'' − (C''·T)T) / |C'|²$ ([HB 14] "Geometric Continuity Conditions": under G² the curvatures match).

    Parameters
    ----------
    curve : PiecewiseBezier
    at : int, optional
        Join index j (between pieces j and j + 1); all joins when omitted.
    tolerance : float
        Relative tolerance of the equality tests.

    Returns
    -------
    Continuity or list of Continuity
    """
    where = "continuity"
    if not isinstance(curve, PiecewiseBezier):
        raise GeometryError(f"{where}: curve = {describe(curve)} is not a PiecewiseBezier; give a PiecewiseBezier")
    joins = len(curve) - 1
    if at is None:
        return [continuity(curve, j, tolerance) for j in range(joins)]
    if isinstance(at, bool) or not isinstance(at, int | np.integer) or not 0 <= at < joins:
        raise GeometryError(
            f"{where}: at = {describe(at)} is not a join index; give an integer in [0, {joins - 1}]"
            if joins
            else f"{where}: at = {describe(at)} but the curve has one piece and no join; add pieces"
        )
    a, b = _derivatives_at_join(curve, int(at))
    scale = max(1.0, float(np.abs(curve.control_points).max()))

    def same(x: FloatArray, y: FloatArray) -> bool:
        size = max(scale, float(np.abs(x).max()), float(np.abs(y).max()))
        return bool(np.abs(x - y).max() <= tolerance * size)

    if not same(a[0], b[0]):
        return Continuity(-1, -1)
    parametric = 0
    if same(a[1], b[1]):
        parametric = 1
        if same(a[2], b[2]):
            parametric = 2
    geometric = 0
    la, lb = float(np.linalg.norm(a[1])), float(np.linalg.norm(b[1]))
    if la > 0 and lb > 0 and same(a[1] / la, b[1] / lb):
        geometric = 1
        ta, tb = a[1] / la, b[1] / lb
        ka = (a[2] - (a[2] @ ta) * ta) / la**2
        kb = (b[2] - (b[2] @ tb) * tb) / lb**2
        if same(ka, kb):
            geometric = 2
    return Continuity(parametric, max(geometric, parametric))
