"""Piecewise Bézier curves and the continuity of their joins (parametric C⁰–C² and geometric G¹–G²), and the
interpolating splines built of such pieces: Hermite curves (``M_H``, the blending functions), cardinal and
Catmull–Rom splines, and cubic-spline interpolation with natural, clamped, periodic or not-a-knot ends (one module:
``PiecewiseBezier.interpolate_c2`` is the cubic spline's Bézier form, and the splines return piecewise Bézier
curves)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, as_scalar, describe, read_only
from frustum.errors import GeometryError
from frustum.geometry.curves._validation import (
    FloatArray,
    _as_control_points,
    _as_knot_vector,
    _as_parameters,
    _shape_result,
)
from frustum.geometry.curves.bezier import M_B, BezierCurve, _de_casteljau


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


M_H: FloatArray = read_only(
    np.array([[2.0, -2.0, 1.0, 1.0], [-3.0, 3.0, -2.0, -1.0], [0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
)
"""The Hermite basis matrix: ``P(t) = [t³ t² t 1] · M_H · G_H`` with ``G_H = [P0; P1; R0; R1]``.

The seed's derivation prints the last row once as ``[0 1 0 0]`` and once as ``[1 0 0 0]``; the inverse of its
constraint matrix (and [HB 14] "Hermite Interpolation") gives ``[1 0 0 0]``.
"""


def hermite_blending(t: ArrayLike) -> FloatArray:
    """The four Hermite blending functions $[H1 H2 H3 H4] = [t³ t² t 1] · M_H$.

    $H1 = 2t³ − 3t² + 1$, $H2 = −2t³ + 3t²$, $H3 = t³ − 2t² + t$, $H4 = t³ − t²$ (weights of P0, P1,
    R0, R1).

    Returns
    -------
    (4,) or (N, 4) float64

    References
    ----------
    [seed] "Hermite Spline"; [HB 14] "Hermite Interpolation".
    """
    s, scalar = _as_parameters(t, "t", 0.0, 1.0, where="hermite_blending")
    T = np.stack([s**3, s**2, s, np.ones_like(s)], axis=1)
    return _shape_result(T @ M_H, scalar)


class HermiteCurve:
    """The cubic Hermite curve from P0 to P1 with end tangents R0, R1: $P(t) = [t³ t² t 1] · M_H · G_H$.

    Parameters
    ----------
    p0, p1, r0, r1 : (d,) array_like
        End points and end derivatives (d = 2 or 3).

    References
    ----------
    [seed] "Hermite Spline"; [HB 14] "Hermite Interpolation".
    """

    __slots__ = ("geometry",)
    geometry: FloatArray

    def __init__(self, p0: ArrayLike, p1: ArrayLike, r0: ArrayLike, r1: ArrayLike) -> None:
        where = "HermiteCurve"
        rows: list[FloatArray] = []
        for name, value in (("p0", p0), ("p1", p1), ("r0", r0), ("r1", r1)):
            allowed = (rows[0].size,) if rows else (2, 3)
            rows.append(_as_control_points([value], name, where=where, dimensions=allowed)[0])
        self.geometry = read_only(np.stack(rows))

    def __repr__(self) -> str:
        return f"HermiteCurve(dimension={self.geometry.shape[1]})"

    @property
    def domain(self) -> tuple[float, float]:
        return (0.0, 1.0)

    def evaluate(self, t: ArrayLike) -> FloatArray:
        """$[t³ t² t 1] · M_H · G_H$ = H1·P0 + H2·P1 + H3·R0 + H4·R1."""
        s, scalar = _as_parameters(t, "t", 0.0, 1.0, where="HermiteCurve.evaluate")
        T = np.stack([s**3, s**2, s, np.ones_like(s)], axis=1)
        return _shape_result(T @ M_H @ self.geometry, scalar)

    __call__ = evaluate

    def tangent(self, t: ArrayLike) -> FloatArray:
        """$P'(t) = [3t² 2t 1 0] · M_H · G_H$."""
        s, scalar = _as_parameters(t, "t", 0.0, 1.0, where="HermiteCurve.tangent")
        T = np.stack([3 * s**2, 2 * s, np.ones_like(s), np.zeros_like(s)], axis=1)
        return _shape_result(T @ M_H @ self.geometry, scalar)

    def to_bezier(self) -> BezierCurve:
        """The same cubic as a Bézier curve: $[P0, P0 + R0/3, P1 − R1/3, P1]$."""
        p0, p1, r0, r1 = self.geometry
        return BezierCurve._from_parts(np.stack([p0, p0 + r0 / 3.0, p1 - r1 / 3.0, p1]))


def cardinal_spline(points: ArrayLike, tension: float = 0.0) -> PiecewiseBezier:
    """The cardinal spline through points[1:-1]: Hermite pieces with tangents $R_k = (1 − c)/2 · (P_{k+1} − P_{k−1})$.

    As in [HB 14] "Cardinal Splines", the first and last points only shape the end tangents; piece k − 1 runs
    from P_k to P_{k+1} on the global parameter interval [k − 1, k]. Tension c = 0 gives Catmull–Rom.

    Parameters
    ----------
    points : (N, d) array_like
        N >= 4 points, d = 2 or 3.
    tension : float
        c; finite.

    Returns
    -------
    PiecewiseBezier
        N − 3 cubic pieces, C¹ at every join.
    """
    where = "cardinal_spline"
    P = _as_control_points(
        points, "points", where=where, min_count=4, reason="(the two end points only set the end tangents)"
    )
    c = as_scalar(tension, "tension", where=where, error=GeometryError)
    R = (1.0 - c) / 2.0 * (P[2:] - P[:-2])
    return PiecewiseBezier.from_tangents(P[1:-1], R)


def catmull_rom(points: ArrayLike) -> PiecewiseBezier:
    """The Catmull–Rom spline through points[1:-1]: ``cardinal_spline(points, 0)``, $R_k = (P_{k+1} − P_{k−1})/2$."""
    return cardinal_spline(points, 0.0)


_END_CONDITIONS = ("natural", "clamped", "periodic", "not-a-knot")


_PARAMETERIZATIONS = ("uniform", "chordal", "centripetal")


class CubicSpline:
    """The C² cubic spline through n + 1 points, with per-segment coefficients (a, b, c, d) as the seed writes them.

    Segment k (k = 0..n−1) is $P(u) = a_k·u³ + b_k·u² + c_k·u + d_k$ for the local parameter u in [0, 1],
    $u = (s − s_k)/(s_{k+1} − s_k)$, where s is the global parameter (the knots s_k).

    Parameters
    ----------
    points : (n + 1, d) array_like
        The points to interpolate, d = 2 or 3.
    end : {"natural", "clamped", "periodic", "not-a-knot"}
        ``natural``: P'' = 0 at both ends. ``clamped``: P' equals `end_tangents` (dP/ds at the first and last
        point; scipy's ``bc_type=((1, d0), (1, dn))``, *not* its ``'clamped'``, which means zero slopes).
        ``periodic``: a closed curve, C² across points[0]; the first point is appended at the end unless the
        last point already equals it. ``not-a-knot``: P''' continuous at the second and second-to-last knot.
    parameterization : {"uniform", "chordal", "centripetal"}
        Knot spacing $s_{k+1} − s_k = 1$, $|P_{k+1} − P_k|$ or $|P_{k+1} − P_k|^(1/2)$; $s_0 = 0$.
    end_tangents : (2, d) array_like, optional
        Required for ``clamped``.

    References
    ----------
    [seed] "Cubic-splines Interpolation methods"; [HB 14] "Natural Cubic Splines".
    """

    __slots__ = ("coefficients", "end", "knots", "parameterization", "points", "slopes")
    coefficients: FloatArray
    knots: FloatArray
    points: FloatArray
    slopes: FloatArray
    end: str
    parameterization: str

    def __init__(
        self,
        points: ArrayLike,
        end: str = "natural",
        parameterization: str = "uniform",
        end_tangents: ArrayLike | None = None,
    ) -> None:
        where = "CubicSpline"
        if end not in _END_CONDITIONS:
            raise GeometryError(f"{where}: end = {end!r} is unknown; give one of {', '.join(_END_CONDITIONS)}")
        if parameterization not in _PARAMETERIZATIONS:
            raise GeometryError(
                f"{where}: parameterization = {parameterization!r} is unknown; give one of "
                f"{', '.join(_PARAMETERIZATIONS)}"
            )
        minimum = {"natural": 2, "clamped": 2, "periodic": 3, "not-a-knot": 4}[end]
        P = _as_control_points(points, "points", where=where, min_count=minimum, reason=f"for end = {end!r}")
        if end == "periodic" and not np.array_equal(P[0], P[-1]):
            P = np.vstack([P, P[:1]])
        chords = np.linalg.norm(np.diff(P, axis=0), axis=1)
        repeated = np.flatnonzero(chords == 0.0)
        if parameterization != "uniform" and repeated.size:
            i = int(repeated[0]) + 1
            raise GeometryError(
                f"{where}: points[{i}] = {describe(P[i])} repeats the point before it; chordal and centripetal "
                "spacing need distinct consecutive points"
            )
        spacing = {"uniform": np.ones_like(chords), "chordal": chords, "centripetal": np.sqrt(chords)}
        h = spacing[parameterization]
        knots = np.concatenate([[0.0], np.cumsum(h)])
        tangents = None
        if end == "clamped":
            if end_tangents is None:
                raise GeometryError(
                    f"{where}: end_tangents = None with end = 'clamped'; give the (2, d) derivatives at both ends"
                )
            tangents = _as_control_points(end_tangents, "end_tangents", where=where, dimensions=(P.shape[1],))
            if tangents.shape[0] != 2:
                raise GeometryError(
                    f"{where}: len(end_tangents) = {tangents.shape[0]} is not 2; give the first and last derivative"
                )
        slopes = _spline_slopes(P, h, end, tangents)
        geometry = np.stack([P[:-1], P[1:], h[:, None] * slopes[:-1], h[:, None] * slopes[1:]], axis=1)
        self.points = read_only(P)
        self.knots = read_only(knots)
        self.slopes = read_only(slopes)
        self.coefficients = read_only(np.einsum("ij,kjd->kid", M_H, geometry))
        self.end = end
        self.parameterization = parameterization

    def __repr__(self) -> str:
        return f"CubicSpline(segments={self.coefficients.shape[0]}, end={self.end!r}, {self.parameterization!r})"

    @property
    def domain(self) -> tuple[float, float]:
        return (float(self.knots[0]), float(self.knots[-1]))

    def evaluate(self, s: ArrayLike, derivative: int = 0) -> FloatArray:
        """The spline (or its m-th derivative with respect to s, m <= 3) at global parameters s."""
        where = "CubicSpline.evaluate"
        order = as_count(derivative, "derivative", 0, where=where)
        values, scalar = _as_parameters(s, "s", *self.domain, where=where)
        k = np.clip(np.searchsorted(self.knots, values, side="right") - 1, 0, self.coefficients.shape[0] - 1)
        h = self.knots[k + 1] - self.knots[k]
        u = (values - self.knots[k]) / h
        rows = {
            0: [u**3, u**2, u, np.ones_like(u)],
            1: [3 * u**2, 2 * u, np.ones_like(u), np.zeros_like(u)],
            2: [6 * u, 2 * np.ones_like(u), np.zeros_like(u), np.zeros_like(u)],
            3: [6 * np.ones_like(u), np.zeros_like(u), np.zeros_like(u), np.zeros_like(u)],
        }
        if order > 3:
            return _shape_result(np.zeros((values.size, self.points.shape[1])), scalar)
        T = np.stack(rows[order], axis=1)
        out = np.einsum("ni,nid->nd", T, self.coefficients[k]) / h[:, None] ** order
        return _shape_result(out, scalar)

    __call__ = evaluate

    def to_bezier(self) -> PiecewiseBezier:
        """The spline as piecewise cubic Bézier with breakpoints at the knots ($G_B = M_B⁻¹ · [a; b; c; d]$)."""
        return PiecewiseBezier(np.einsum("ij,kjd->kid", np.linalg.inv(M_B), self.coefficients), self.knots)


def _spline_slopes(P: FloatArray, h: FloatArray, end: str, tangents: FloatArray | None) -> FloatArray:
    """Derivatives m_k = dP/ds at the knots from the C² conditions (a tridiagonal or cyclic linear system).

    Interior knot k: $h_k·m_{k−1} + 2(h_{k−1} + h_k)·m_k + h_{k−1}·m_{k+1} = 3(h_k·Δ_{k−1} + h_{k−1}·Δ_k)$,
    $Δ_k = (P_{k+1} − P_k)/h_k$.
    """
    from scipy.sparse import lil_matrix
    from scipy.sparse.linalg import spsolve

    n = P.shape[0] - 1
    slope = np.diff(P, axis=0) / h[:, None]
    size = n if end == "periodic" else n + 1
    A = lil_matrix((size, size))
    rhs = np.zeros((size, P.shape[1]))
    for k in range(1, n):
        A[k, k - 1], A[k, k], A[k, (k + 1) % size] = h[k], 2 * (h[k - 1] + h[k]), h[k - 1]
        rhs[k] = 3 * (h[k] * slope[k - 1] + h[k - 1] * slope[k])
    if end == "periodic":  # knot 0 joins segment n−1 to segment 0
        A[0, n - 1], A[0, 0], A[0, 1 % size] = h[0], 2 * (h[n - 1] + h[0]), h[n - 1]
        if n == 2:
            A[0, 1] = h[0] + h[n - 1]
            A[1, 0] = h[1] + h[0]
        rhs[0] = 3 * (h[0] * slope[n - 1] + h[n - 1] * slope[0])
    elif end == "natural":
        A[0, 0], A[0, 1], rhs[0] = 2.0, 1.0, 3 * slope[0]
        A[n, n - 1], A[n, n], rhs[n] = 1.0, 2.0, 3 * slope[n - 1]
    elif end == "clamped":
        assert tangents is not None
        A[0, 0], rhs[0] = 1.0, tangents[0]
        A[n, n], rhs[n] = 1.0, tangents[1]
    else:  # not-a-knot: third derivative continuous at knots 1 and n − 1
        d = h[0] + h[1]
        A[0, 0], A[0, 1] = h[1], d
        rhs[0] = ((h[0] + 2 * d) * h[1] * slope[0] + h[0] ** 2 * slope[1]) / d
        d = h[n - 1] + h[n - 2]
        A[n, n - 1], A[n, n] = d, h[n - 2]
        rhs[n] = (h[n - 1] ** 2 * slope[n - 2] + (2 * d + h[n - 1]) * h[n - 2] * slope[n - 1]) / d
    solution = spsolve(A.tocsc(), rhs)
    solution = np.asarray(solution, dtype=np.float64).reshape(size, P.shape[1])
    if end == "periodic":
        solution = np.vstack([solution, solution[:1]])
    return np.ascontiguousarray(solution)
