"""B-splines and NURBS: knot vectors, the Cox–de Boor recursion, de Boor evaluation, basis matrices (``BSpline``),
and rational B-splines with weights (``NURBSCurve``)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, as_scalar, describe, read_only
from frustum.errors import GeometryError
from frustum.geometry.curves._validation import (
    FloatArray,
    _as_control_points,
    _as_degree,
    _as_knot_vector,
    _as_parameters,
    _shape_result,
)
from frustum.geometry.curves.bezier import _de_casteljau, _flatten_pieces
from frustum.geometry.curves.piecewise import PiecewiseBezier


def open_uniform_knots(count: int, degree: int) -> FloatArray:
    """The seed's open-uniform (clamped) knot vector for `count` = n + 1 control points and order k = degree + 1.

    $x_i = 0 if i < k;  x_i = i − k + 1 if k <= i <= n;  x_i = n − k + 2 if i > n$, for i = 0..n+k. The
    domain is [0, n − k + 2]; every end knot is repeated k times, so the curve starts at P0 and ends at Pn.

    References
    ----------
    [seed] "B-Spline Curve"; [HB 14] "Open Uniform B-Splines".
    """
    where = "open_uniform_knots"
    p = _as_degree(degree, where=where)
    count = as_count(count, "count", p + 1, where=where)
    n, k = count - 1, p + 1
    i = np.arange(n + k + 1)
    return np.where(i < k, 0.0, np.where(i <= n, i - k + 1.0, n - k + 2.0))


def _checked_knots(value: ArrayLike, count: int, degree: int, *, where: str, name: str = "knots") -> FloatArray:
    knots = _as_knot_vector(value, name, where=where)
    expected = count + degree + 1
    if knots.size != expected:
        raise GeometryError(
            f"{where}: len({name}) = {knots.size} does not fit {count} control points of degree {degree}; "
            f"give count + degree + 1 = {expected} knots"
        )
    down = np.flatnonzero(np.diff(knots) < 0)
    if down.size:
        i = int(down[0]) + 1
        raise GeometryError(
            f"{where}: {name}[{i}] = {float(knots[i])!r} is below {name}[{i - 1}] = {float(knots[i - 1])!r}; "
            "knots must be non-decreasing"
        )
    if not knots[degree] < knots[count]:
        raise GeometryError(
            f"{where}: {name} has an empty domain [{float(knots[degree])!r}, {float(knots[count])!r}]; "
            "knots[degree] must be below knots[count]"
        )
    values, multiplicity = np.unique(knots, return_counts=True)
    too_many = np.flatnonzero(multiplicity > degree + 1)
    if too_many.size:
        j = int(too_many[0])
        raise GeometryError(
            f"{where}: {name} repeats {float(values[j])!r} {int(multiplicity[j])} times; a knot may repeat at most "
            f"degree + 1 = {degree + 1} times"
        )
    return knots


def _knots_for(kind: Any, count: int, degree: int, where: str) -> tuple[FloatArray, bool]:
    """(knot vector, closed?) for a named kind or an explicit array."""
    if isinstance(kind, str):
        if kind == "clamped":
            return open_uniform_knots(count, degree), False
        if kind == "uniform":
            return np.arange(count + degree + 1, dtype=np.float64), False
        if kind == "closed":
            return np.arange(count + 2 * degree + 1, dtype=np.float64), True
        raise GeometryError(
            f"{where}: knots = {kind!r} is unknown; give 'clamped', 'uniform', 'closed' or a knot array"
        )
    return _checked_knots(kind, count, degree, where=where), False


def _find_spans(knots: FloatArray, degree: int, count: int, u: FloatArray) -> NDArray[np.int64]:
    """Span index s with t_s <= u < t_{s+1}, clamped to [degree, last non-empty span <= count − 1]."""
    nonempty = np.flatnonzero(knots[degree:count] < knots[degree + 1 : count + 1]) + degree
    last = int(nonempty[-1])
    return np.clip(np.searchsorted(knots, u, side="right") - 1, degree, last)


def _de_boor(knots: FloatArray, degree: int, points: FloatArray, u: FloatArray) -> FloatArray:
    """de Boor's algorithm for every u at once: (N, d) points of $Σ P_i · N_{i,p}(u)$."""
    p = degree
    spans = _find_spans(knots, p, points.shape[0], u)
    d = [points[spans - p + j] for j in range(p + 1)]  # contiguous (N, dim) arrays
    for r in range(1, p + 1):
        for j in range(p, r - 1, -1):
            i = spans - p + j
            left, right = knots[i], knots[i + p + 1 - r]
            denom = right - left
            with np.errstate(invalid="ignore", divide="ignore"):
                alpha = np.where(denom > 0, (u - left) / denom, 0.0)[:, None]
            d[j] = (1.0 - alpha) * d[j - 1] + alpha * d[j]
    return d[p]


def _basis_matrix(knots: FloatArray, degree: int, count: int, u: FloatArray, order: int = 0) -> FloatArray:
    """(N, count): every B-spline basis function N_{i,degree} (or its `order`-th derivative) at every u."""
    identity = np.eye(count)
    curve = BSpline._from_parts(identity, degree, knots)
    for _ in range(order):
        curve = curve.derivative()
    return curve.evaluate(u)


def cox_de_boor(knots: ArrayLike, i: int, k: int, u: ArrayLike, *, record: Any = None) -> FloatArray | float:
    """The B-spline basis function of order k (degree k − 1) by the seed's Cox–de Boor recursion.

    $N_{i,k}(u) = (u − x_i)·N_{i,k−1}(u) / (x_{i+k−1} − x_i) + (x_{i+k} − u)·N_{i+1,k−1}(u) / (x_{i+k} − x_{i+1})$
    with a term whose denominator is 0 taken as 0 (0/0 = 0). $N_{i,1}(u) = 1$ if $x_i <= u < x_{i+1}$, else
    0; the seed prints ``<=`` on both sides, which counts a knot twice, so the half-open interval is used, and at
    the last knot the last non-empty interval is closed so that the basis sums to 1 there too.

    Parameters
    ----------
    knots : (m,) array_like
        Non-decreasing knots x_0..x_{m−1}.
    i : int
        0 <= i <= m − k − 1.
    k : int
        Order >= 1.
    u : float or (N,) array_like
        Parameters in [x_0, x_{m−1}].
    record : callable, optional
        Called as ``record(i, k, values)`` for every N_{i,k} the recursion computes (``frustum.steps``).

    References
    ----------
    [seed] "B-Spline Curve"; [HB 14] "B-Spline Curve Equations".
    """
    where = "cox_de_boor"
    x = _as_knot_vector(knots, "knots", where=where)
    down = np.flatnonzero(np.diff(x) < 0)
    if down.size:
        j = int(down[0]) + 1
        raise GeometryError(
            f"{where}: knots[{j}] = {float(x[j])!r} is below knots[{j - 1}] = {float(x[j - 1])!r}; "
            "knots must be non-decreasing"
        )
    k = _as_degree(k, where=where, name="k")
    if isinstance(i, bool) or not isinstance(i, int | np.integer) or not 0 <= i <= x.size - k - 1:
        raise GeometryError(
            f"{where}: i = {describe(i)} is out of range for {x.size} knots of order {k}; give 0 <= i <= "
            f"{x.size - k - 1}"
        )
    s, scalar = _as_parameters(u, "u", float(x[0]), float(x[-1]), where=where)
    last = int(np.flatnonzero(x[:-1] < x[1:])[-1]) if (x[:-1] < x[1:]).any() else -1
    values = _cox_de_boor(x, int(i), k, s, last, record)
    return float(values[0]) if scalar else values


def _cox_de_boor(x: FloatArray, i: int, k: int, u: FloatArray, last: int, record: Any = None) -> FloatArray:
    """N_{i,k}(u); ``record(i, k, values)`` (``frustum.steps``), if given, sees every N_{i,k} computed."""
    if k == 1:
        inside = (x[i] <= u) & (u < x[i + 1])
        if i == last:
            inside |= u == x[i + 1]
        out = inside.astype(np.float64)
    else:
        out = np.zeros_like(u)
        if x[i + k - 1] != x[i]:
            out += (u - x[i]) * _cox_de_boor(x, i, k - 1, u, last, record) / (x[i + k - 1] - x[i])
        if x[i + k] != x[i + 1]:
            out += (x[i + k] - u) * _cox_de_boor(x, i + 1, k - 1, u, last, record) / (x[i + k] - x[i + 1])
    if record is not None:
        record(i, k, out)
    return out


class BSpline:
    """A B-spline curve $C(u) = Σ_{i=0}^{n} P_i · N_{i,k}(u)$ of degree $p = k − 1$, evaluated by de Boor's algorithm.

    Parameters
    ----------
    control_points : (n + 1, d) array_like
        d = 2 or 3; at least degree + 1 points.
    degree : int
        p >= 1 (scipy's k; the seed's order is k = p + 1).
    knots : {"clamped", "uniform", "closed"} or (n + p + 2,) array_like
        ``clamped``: the seed's open-uniform vector (``open_uniform_knots``; the curve starts at P0, ends at
        Pn; domain [0, n − p + 1]). ``uniform``: 0, 1, ..., n + p + 1 (H&B "uniform periodic"; domain [p, n + 1]).
        ``closed``: a closed curve, C^{p−1} everywhere: the first p control points are appended and the knots
        are 0..n + 2p + 1 (domain [p, n + 1 + p]); ``control_points`` then holds the wrapped net. An array: any
        non-decreasing vector of length n + p + 2 (domain [t_p, t_{n+1}]).

    References
    ----------
    [seed] "B-Spline Curve"; [HB 14] "B-Spline Curves", "Uniform Periodic B-Splines", "Open Uniform B-Splines".
    """

    __slots__ = ("closed", "control_points", "degree", "knots")
    control_points: FloatArray
    knots: FloatArray
    degree: int
    closed: bool

    def __init__(self, control_points: ArrayLike, degree: int = 3, knots: str | ArrayLike = "clamped") -> None:
        where = "BSpline"
        p = _as_degree(degree, where=where)
        P = _as_control_points(control_points, "control_points", where=where, min_count=p + 1, reason=f"for degree {p}")
        vector, closed = _knots_for(knots, P.shape[0], p, where)
        if closed:
            P = np.vstack([P, P[:p]])
        self.control_points = read_only(P)
        self.knots = read_only(np.ascontiguousarray(vector))
        self.degree = p
        self.closed = closed

    @classmethod
    def _from_parts(cls, points: FloatArray, degree: int, knots: FloatArray, closed: bool = False) -> BSpline:
        curve = cls.__new__(cls)
        curve.control_points = read_only(np.ascontiguousarray(points, dtype=np.float64))
        curve.knots = read_only(np.ascontiguousarray(knots, dtype=np.float64))
        curve.degree = int(degree)
        curve.closed = closed
        return curve

    def __repr__(self) -> str:
        return f"BSpline(count={self.count}, degree={self.degree}, domain={self.domain})"

    @property
    def count(self) -> int:
        """n + 1, the number of control points (of the wrapped net for a closed curve)."""
        return int(self.control_points.shape[0])

    @property
    def order(self) -> int:
        """k = degree + 1 (the seed's and Hearn & Baker's d)."""
        return self.degree + 1

    @property
    def dimension(self) -> int:
        return int(self.control_points.shape[1])

    @property
    def domain(self) -> tuple[float, float]:
        """[t_p, t_{n+1}]: where the basis functions sum to one."""
        return (float(self.knots[self.degree]), float(self.knots[self.count]))

    def evaluate(self, u: ArrayLike) -> FloatArray:
        """Points by de Boor's algorithm $d_j ← (1 − α)·d_{j−1} + α·d_j$, $α = (u − t_i)/(t_{i+p+1−r} − t_i)$."""
        s, scalar = _as_parameters(u, "u", *self.domain, where="BSpline.evaluate")
        return _shape_result(_de_boor(self.knots, self.degree, self.control_points, s), scalar)

    __call__ = evaluate

    def basis(self, i: int, k: int, u: ArrayLike) -> FloatArray | float:
        """``N_{i,k}(u)`` over this curve's knots by the seed's Cox–de Boor recursion (k = order; ``cox_de_boor``)."""
        return cox_de_boor(self.knots, i, k, u)

    def support(self, i: int) -> tuple[float, float]:
        """[t_i, t_{i+k}]: the only parameters that control point i influences (local control)."""
        if isinstance(i, bool) or not isinstance(i, int | np.integer) or not 0 <= i < self.count:
            raise GeometryError(
                f"BSpline.support: i = {describe(i)} is not a control point index; give 0 <= i < {self.count}"
            )
        return (float(self.knots[i]), float(self.knots[i + self.order]))

    def derivative(self, order: int = 1) -> BSpline:
        """The derivative curve: degree p − 1, $Q_i = p·(P_{i+1} − P_i)/(t_{i+p+1} − t_{i+1})$ (0/0 = 0)."""
        order = as_count(order, "order", 0, where="BSpline.derivative")
        curve = self
        for _ in range(order):
            curve = curve._first_derivative()
        return curve

    def _first_derivative(self) -> BSpline:
        p, t, P = self.degree, self.knots, self.control_points
        if p == 0:
            return BSpline._from_parts(np.zeros_like(P), 0, t)
        denom = (t[p + 1 : p + self.count] - t[1 : self.count])[:, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            Q = np.where(denom > 0, p * np.diff(P, axis=0) / denom, 0.0)
        return BSpline._from_parts(Q, p - 1, t[1:-1], self.closed)

    def insert_knot(self, u: float, times: int = 1) -> BSpline:
        """The same curve with knot u inserted `times` times (Boehm's algorithm).

        $Q_i = (1 − a_i)·P_{i−1} + a_i·P_i$, $a_i = (u − t_i)/(t_{i+p} − t_i)$ for s − p + 1 <= i <= s.
        """
        where = "BSpline.insert_knot"
        value = as_scalar(u, "u", where=where, error=GeometryError)
        times = as_count(times, "times", 1, where=where)
        low, high = self.domain
        if not low <= value <= high:
            raise GeometryError(
                f"{where}: u = {value!r} lies outside the domain [{low!r}, {high!r}]; insert knots inside the domain"
            )
        multiplicity = int((self.knots == value).sum())
        if multiplicity + times > self.order:
            raise GeometryError(
                f"{where}: times = {times} would repeat u = {value!r} {multiplicity + times} times; a knot may "
                f"repeat at most degree + 1 = {self.order} times"
            )
        return self._insert_times(value, times)

    def _insert_times(self, value: float, times: int) -> BSpline:
        curve = self
        for _ in range(times):
            curve = curve._insert_once(value)
        return curve

    def _insert_once(self, u: float) -> BSpline:
        p, t, P = self.degree, self.knots, self.control_points
        s = int(_find_spans(t, p, self.count, np.array([u]))[0])
        Q = np.empty((self.count + 1, self.dimension))
        Q[: s - p + 1] = P[: s - p + 1]
        Q[s + 1 :] = P[s:]
        for i in range(s - p + 1, s + 1):
            denom = t[i + p] - t[i]
            a = (u - t[i]) / denom if denom > 0 else 0.0
            Q[i] = (1.0 - a) * P[i - 1] + a * P[i]
        return BSpline._from_parts(Q, p, np.insert(t, s + 1, u), self.closed)

    def to_bezier(self) -> PiecewiseBezier:
        """The curve on its domain as Bézier pieces of degree p, one per non-empty knot span.

        Every distinct knot inside the domain (and each domain end) is raised to multiplicity p by knot
        insertion; the p + 1 control points of each span are then its Bézier control polygon. Breakpoints are
        the distinct knots, so ``to_bezier().evaluate(u) == evaluate(u)``.
        """
        return PiecewiseBezier(*self._bezier_segments())

    def _bezier_segments(self) -> tuple[FloatArray, FloatArray]:
        """((M, p + 1, d) Bézier control polygons, (M + 1,) breakpoints) by knot insertion; any d."""
        p = self.degree
        low, high = self.domain
        curve = self
        for value in np.unique(self.knots[(self.knots >= low) & (self.knots <= high)]):
            missing = p - int((curve.knots == value).sum())
            if missing > 0:
                curve = curve._insert_times(float(value), missing)
        t = curve.knots
        spans = [s for s in range(p, curve.count) if t[s] < t[s + 1] and low <= t[s] and t[s + 1] <= high]
        pieces = np.stack([curve.control_points[s - p : s + 1] for s in spans])
        breakpoints = np.array([t[spans[0]], *[t[s + 1] for s in spans]])
        return pieces, breakpoints

    def flatten(
        self,
        tolerance: float | None = None,
        *,
        pixel_size: float | None = None,
        project: Callable[[FloatArray], ArrayLike] | None = None,
        max_depth: int = 24,
    ) -> FloatArray:
        """A polyline within `tolerance` of the curve (``to_bezier().flatten``; see ``BezierCurve.flatten``)."""
        return self.to_bezier().flatten(tolerance, pixel_size=pixel_size, project=project, max_depth=max_depth)


class NURBSCurve:
    """A rational B-spline $C(u) = Σ w_i·P_i·N_{i,p}(u) / Σ w_i·N_{i,p}(u)$: exact conics, circles included.

    Evaluated as a B-spline in homogeneous coordinates (w·P, w), then divided by w.

    Parameters
    ----------
    control_points : (n + 1, d) array_like
    weights : (n + 1,) array_like
        Positive, finite.
    degree : int
    knots : "clamped", "uniform" or (n + p + 2,) array_like

    References
    ----------
    [seed] "B-Spline Curve" ("Limitation": polynomial curves cannot represent circles); [HB 14] "Rational
    Splines".
    """

    __slots__ = ("_homogeneous", "control_points", "weights")
    control_points: FloatArray
    weights: FloatArray
    _homogeneous: BSpline

    def __init__(
        self, control_points: ArrayLike, weights: ArrayLike, degree: int = 2, knots: str | ArrayLike = "clamped"
    ) -> None:
        where = "NURBSCurve"
        p = _as_degree(degree, where=where)
        P = _as_control_points(control_points, "control_points", where=where, min_count=p + 1, reason=f"for degree {p}")
        w = _as_weights(weights, P.shape[0], where=where)
        if isinstance(knots, str) and knots == "closed":
            raise GeometryError(f"{where}: knots = 'closed' is not supported; give 'clamped', 'uniform' or an array")
        vector, _ = _knots_for(knots, P.shape[0], p, where)
        self.control_points = read_only(P)
        self.weights = read_only(w)
        self._homogeneous = BSpline._from_parts(np.c_[P * w[:, None], w], p, vector)

    def __repr__(self) -> str:
        return f"NURBSCurve(count={self.control_points.shape[0]}, degree={self.degree})"

    @property
    def degree(self) -> int:
        return self._homogeneous.degree

    @property
    def knots(self) -> FloatArray:
        return self._homogeneous.knots

    @property
    def domain(self) -> tuple[float, float]:
        return self._homogeneous.domain

    def evaluate(self, u: ArrayLike) -> FloatArray:
        """$C(u) = A(u)/w(u)$ with ``(A, w)`` the homogeneous B-spline."""
        s, scalar = _as_parameters(u, "u", *self.domain, where="NURBSCurve.evaluate")
        h = _de_boor(self.knots, self.degree, self._homogeneous.control_points, s)
        return _shape_result(h[:, :-1] / h[:, -1:], scalar)

    __call__ = evaluate

    def tangent(self, u: ArrayLike) -> FloatArray:
        """$C'(u) = (A'(u) − w'(u)·C(u)) / w(u)$ (quotient rule)."""
        s, scalar = _as_parameters(u, "u", *self.domain, where="NURBSCurve.tangent")
        h = _de_boor(self.knots, self.degree, self._homogeneous.control_points, s)
        d = self._homogeneous.derivative()
        dh = _de_boor(d.knots, d.degree, d.control_points, s)
        c = h[:, :-1] / h[:, -1:]
        return _shape_result((dh[:, :-1] - dh[:, -1:] * c) / h[:, -1:], scalar)

    def flatten(
        self,
        tolerance: float | None = None,
        *,
        pixel_size: float | None = None,
        project: Callable[[FloatArray], ArrayLike] | None = None,
        max_depth: int = 24,
    ) -> FloatArray:
        """A polyline through curve points by adaptive subdivision of its rational Bézier pieces.

        Same criteria as ``BezierCurve.flatten``; they are tested on the pieces' control points P_i, whose
        convex hull holds a rational piece with positive weights, so ``tolerance`` bounds the distance.
        """
        where = "NURBSCurve.flatten"
        depth = as_count(max_depth, "max_depth", 0, where=where)
        pieces, _ = self._homogeneous._bezier_segments()
        parts = []
        for k, piece in enumerate(pieces):
            t = _flatten_pieces(piece, tolerance, pixel_size, project, depth, where, rational=True)
            h = _de_casteljau(piece, t if k == 0 else t[1:])
            parts.append(h[:, :-1] / h[:, -1:])
        return np.concatenate(parts)

    @classmethod
    def arc(
        cls, radius: float = 1.0, start: float = 0.0, end: float = 2 * math.pi, center: ArrayLike = (0.0, 0.0, 0.0)
    ) -> NURBSCurve:
        """The exact circular arc from angle `start` to `end` (radians, counter-clockwise, sweep in (0, 2π]).

        Quadratic, one segment per started quarter turn; segment of sweep Δ: middle weight $cos(Δ/2)$, middle
        control point at distance $r/cos(Δ/2)$ on the bisector. In the plane z = center z for a 3-D center.
        """
        where = "NURBSCurve.arc"
        r = as_scalar(radius, "radius", where=where, error=GeometryError)
        if r <= 0:
            raise GeometryError(f"{where}: radius = {r!r} is not positive; give a positive radius")
        a0 = as_scalar(start, "start", where=where, error=GeometryError)
        a1 = as_scalar(end, "end", where=where, error=GeometryError)
        sweep = a1 - a0
        if not 0 < sweep <= 2 * math.pi * (1 + 1e-12):
            raise GeometryError(f"{where}: end − start = {sweep!r} is outside (0, 2π]; give 0 < end − start <= 2π")
        c = _as_control_points([center], "center", where=where)[0]
        return cls._conic(r, r, a0, sweep, c)

    @classmethod
    def circle(cls, radius: float = 1.0, center: ArrayLike = (0.0, 0.0, 0.0)) -> NURBSCurve:
        """The exact circle: 9 control points, weights 1, √2/2, ..., knots [0,0,0,¼,¼,½,½,¾,¾,1,1,1]."""
        return cls.arc(radius, 0.0, 2 * math.pi, center)

    @classmethod
    def ellipse(cls, a: float = 1.0, b: float = 0.5, center: ArrayLike = (0.0, 0.0, 0.0)) -> NURBSCurve:
        """The exact ellipse $(x/a)² + (y/b)² = 1$ about `center`: the circle's net scaled (weights unchanged)."""
        where = "NURBSCurve.ellipse"
        sa = as_scalar(a, "a", where=where, error=GeometryError)
        sb = as_scalar(b, "b", where=where, error=GeometryError)
        for name, value in (("a", sa), ("b", sb)):
            if value <= 0:
                raise GeometryError(f"{where}: {name} = {value!r} is not positive; give positive semi-axes")
        c = _as_control_points([center], "center", where=where)[0]
        return cls._conic(sa, sb, 0.0, 2 * math.pi, c)

    @classmethod
    def _conic(cls, a: float, b: float, start: float, sweep: float, center: FloatArray) -> NURBSCurve:
        segments = max(1, math.ceil(sweep / (math.pi / 2) - 1e-9))
        delta = sweep / segments
        w_mid = math.cos(delta / 2)
        angles = start + delta * np.arange(2 * segments + 1) / 2
        radii = np.where(np.arange(2 * segments + 1) % 2 == 1, 1.0 / w_mid, 1.0)
        points = np.zeros((angles.size, center.size))
        points[:, 0] = center[0] + a * radii * np.cos(angles)
        points[:, 1] = center[1] + b * radii * np.sin(angles)
        if center.size == 3:
            points[:, 2] = center[2]
        weights = np.where(np.arange(2 * segments + 1) % 2 == 1, w_mid, 1.0)
        interior = np.repeat(np.arange(1, segments) / segments, 2)
        knots = np.concatenate([[0.0] * 3, interior, [1.0] * 3])
        return cls(points, weights, 2, knots)


def _as_weights(value: ArrayLike, count: int, *, where: str, name: str = "weights") -> FloatArray:
    try:
        w = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not numeric; give positive weights") from None
    if w.shape != (count,) and not (w.ndim > 1 and w.size == count):
        raise GeometryError(f"{where}: {name} has shape {w.shape}; give one weight per control point ({count})")
    flat = w.ravel()
    bad = np.flatnonzero(~np.isfinite(flat) | (flat <= 0))
    if bad.size:
        i = int(bad[0])
        raise GeometryError(
            f"{where}: {name}[{i}] = {float(flat[i])!r} is not a positive finite number; weights must be positive"
        )
    return np.ascontiguousarray(w)
