"""Interpolating splines: Hermite curves (``M_H``, the blending functions), cardinal and Catmull–Rom splines (as
piecewise Bézier curves), and cubic-spline interpolation with natural, clamped, periodic or not-a-knot ends."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from frustum._arrays import as_count, as_scalar, describe, read_only
from frustum.errors import GeometryError
from frustum.geometry.curves._validation import FloatArray, _as_control_points, _as_parameters, _shape_result
from frustum.geometry.curves.bezier import M_B, BezierCurve
from frustum.geometry.curves.piecewise import PiecewiseBezier

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
