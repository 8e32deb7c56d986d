"""Parametric curves: Bézier, piecewise Bézier, Hermite, cardinal/Catmull–Rom, cubic splines, B-splines, NURBS.

Every curve is immutable, lives in 2D or 3D (control points ``(N, 2)`` or ``(N, 3)`` float64, one per row) and
evaluates whole arrays of parameters at once. Parameters outside a curve's domain raise ``GeometryError``
instead of extrapolating silently. ``docs/curves.md`` maps each section of the seed's "Curves and Surfaces"
notes to the functions here.

References
----------
[seed] "Bezier Curves & surfaces", "Piecewise Cubic Bezier Curves", "Recursive Subdivision approach",
"Properties of Bezier Curves", "Cubic-splines Interpolation methods", "Hermite Spline", "B-Spline Curve".
[HB 14] "Spline Representations", "Cubic-Spline Interpolation Methods", "Bézier Spline Curves",
"B-Spline Curves", "Rational Splines".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, as_scalar, describe, read_only
from frustum.errors import GeometryError

__all__ = [
    "M_B",
    "M_H",
    "BSpline",
    "BezierCurve",
    "Continuity",
    "CubicSpline",
    "HermiteCurve",
    "NURBSCurve",
    "PiecewiseBezier",
    "bernstein",
    "bezier_matrix_form",
    "cardinal_spline",
    "catmull_rom",
    "continuity",
    "cox_de_boor",
    "hermite_blending",
    "open_uniform_knots",
]

FloatArray = NDArray[np.float64]

M_B: FloatArray = read_only(
    np.array([[-1.0, 3.0, -3.0, 1.0], [3.0, -6.0, 3.0, 0.0], [-3.0, 3.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
)
"""The cubic Bézier basis matrix: ``C(t) = [t³ t² t 1] · M_B · G_B`` with ``G_B = [P0; P1; P2; P3]``."""

M_H: FloatArray = read_only(
    np.array([[2.0, -2.0, 1.0, 1.0], [-3.0, 3.0, -2.0, -1.0], [0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
)
"""The Hermite basis matrix: ``P(t) = [t³ t² t 1] · M_H · G_H`` with ``G_H = [P0; P1; R0; R1]``.

The seed's derivation prints the last row once as ``[0 1 0 0]`` and once as ``[1 0 0 0]``; the inverse of its
constraint matrix (and [HB 14] "Hermite Interpolation") gives ``[1 0 0 0]``.
"""

_DOMAIN_SLACK = 1e-12  # parameters this far (relative) outside a domain are clamped, not refused


# --- validation (the curve-specific part; shapes of (N, 3) points live in frustum._arrays) ------------------


def _as_control_points(
    value: ArrayLike,
    name: str,
    *,
    where: str,
    min_count: int = 1,
    dimensions: tuple[int, ...] = (2, 3),
    reason: str = "",
) -> FloatArray:
    """Return `value` as a finite, C-contiguous (N, d) float64 array with d in `dimensions` and N >= min_count."""
    shape_text = " or ".join(f"(N, {d})" for d in dimensions)
    try:
        points = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(
            f"{where}: {name} = {describe(value)} is not numeric; expected an {shape_text} array of points"
        ) from None
    if points.ndim != 2 or points.shape[1] not in dimensions:
        raise GeometryError(f"{where}: {name} has shape {points.shape}; expected {shape_text} points, one per row")
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise GeometryError(
            f"{where}: {name}[{i}] = {describe(points[i])} is not finite; coordinates must be finite numbers"
        )
    if points.shape[0] < min_count:
        raise GeometryError(
            f"{where}: len({name}) = {points.shape[0]} is below {min_count}; give at least {min_count} points"
            + (f" {reason}" if reason else "")
        )
    return np.ascontiguousarray(points)


def _as_parameters(value: ArrayLike, name: str, low: float, high: float, *, where: str) -> tuple[FloatArray, bool]:
    """Return (1-D float64 parameters inside [low, high], whether `value` was a scalar); refuse others."""
    try:
        t = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(
            f"{where}: {name} = {describe(value)} is not numeric; expected numbers in [{low!r}, {high!r}]"
        ) from None
    scalar = t.ndim == 0
    if t.ndim > 1:
        raise GeometryError(f"{where}: {name} has shape {t.shape}; expected a number or a 1-D array of numbers")
    t = np.atleast_1d(t)
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise GeometryError(
            f"{where}: {name} = {float(t[bad[0]])!r} is not finite; expected numbers in [{low!r}, {high!r}]"
        )
    slack = _DOMAIN_SLACK * max(1.0, high - low, abs(low), abs(high))
    outside = np.flatnonzero((t < low - slack) | (t > high + slack))
    if outside.size:
        raise GeometryError(
            f"{where}: {name} = {float(t[outside[0]])!r} lies outside the domain [{low!r}, {high!r}]; "
            "give parameters inside the domain (curves do not extrapolate)"
        )
    return np.ascontiguousarray(np.clip(t, low, high)), scalar


def _as_degree(value: Any, *, where: str, name: str = "degree") -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not an integer; give an integer {name} >= 1")
    if value < 1:
        raise GeometryError(f"{where}: {name} = {int(value)} is below 1; give an integer {name} >= 1")
    return int(value)


def _shape_result(values: FloatArray, scalar: bool) -> FloatArray:
    return values[0] if scalar else values


# --- Bernstein polynomials and the cubic matrix form ------------------------------------------------------


def bernstein(n: int, i: int, t: ArrayLike) -> FloatArray | float:
    """The Bernstein polynomial ``b_{n,i}(t) = C(n, i) · tⁱ · (1 − t)ⁿ⁻ⁱ`` (the Bézier blending function).

    Parameters
    ----------
    n, i : int
        Degree n >= 0 and index 0 <= i <= n.
    t : float or (N,) array_like
        Parameters in [0, 1].

    Returns
    -------
    float or (N,) float64

    References
    ----------
    [seed] "Bezier Curves & surfaces"; [HB 14] "Bézier Curve Equations".
    """
    where = "bernstein"
    n = as_count(n, "n", 0, where=where)
    if isinstance(i, bool) or not isinstance(i, int | np.integer) or not 0 <= i <= n:
        raise GeometryError(f"{where}: i = {describe(i)} is not an integer in [0, {n}]; give 0 <= i <= n")
    s, scalar = _as_parameters(t, "t", 0.0, 1.0, where=where)
    values = math.comb(n, int(i)) * s ** int(i) * (1.0 - s) ** (n - int(i))
    return float(values[0]) if scalar else values


def bezier_matrix_form(t: ArrayLike, G: ArrayLike) -> FloatArray:
    """The cubic Bézier curve in matrix form, ``C(t) = [t³ t² t 1] · M_B · G_B``.

    Parameters
    ----------
    t : float or (N,) array_like
        Parameters in [0, 1].
    G : (4, d) array_like
        The geometry vector ``G_B = [P0; P1; P2; P3]`` (d = 2 or 3).

    Returns
    -------
    (d,) or (N, d) float64
        The same points as ``BezierCurve(G).evaluate(t)``, computed in the power basis.

    References
    ----------
    [seed] "Bezier Curves & surfaces" (the matrix ``M_B``); [HB 14] "Cubic Bézier Curves".
    """
    where = "bezier_matrix_form"
    geometry = _as_control_points(G, "G", where=where, min_count=4)
    if geometry.shape[0] != 4:
        raise GeometryError(f"{where}: len(G) = {geometry.shape[0]} is not 4; give the four points P0..P3")
    s, scalar = _as_parameters(t, "t", 0.0, 1.0, where=where)
    T = np.stack([s**3, s**2, s, np.ones_like(s)], axis=1)
    return _shape_result(T @ M_B @ geometry, scalar)


def hermite_blending(t: ArrayLike) -> FloatArray:
    """The four Hermite blending functions ``[H1 H2 H3 H4] = [t³ t² t 1] · M_H``.

    ``H1 = 2t³ − 3t² + 1``, ``H2 = −2t³ + 3t²``, ``H3 = t³ − 2t² + t``, ``H4 = t³ − t²`` (weights of P0, P1,
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


# --- Bézier curves ----------------------------------------------------------------------------------------


def _de_casteljau(points: FloatArray, t: FloatArray) -> FloatArray:
    """P_i^j = (1 − t)·P_i^{j−1} + t·P_{i+1}^{j−1} for every t at once; returns (N, d).

    Each level is a list of contiguous (N, d) arrays, so the work is n(n+1)/2 whole-array blends.
    """
    s = t[:, None]
    r = 1.0 - s
    level = [r * points[i] + s * points[i + 1] for i in range(points.shape[0] - 1)]
    if not level:
        return np.repeat(points[:1], t.size, axis=0)
    while len(level) > 1:
        level = [r * level[i] + s * level[i + 1] for i in range(len(level) - 1)]
    return level[0]


def _split_batch(pieces: FloatArray, t: float, record: Any = None) -> tuple[FloatArray, FloatArray]:
    """Split every control polygon of `pieces` (M, n+1, d) at t: the seed's A, AB, ABC, ABCD construction.
    ``record(level)`` (``frustum.steps``), if given, sees each level of points."""
    level = pieces
    left, right = [level[:, 0]], [level[:, -1]]
    for _ in range(pieces.shape[1] - 1):
        level = (1.0 - t) * level[:, :-1] + t * level[:, 1:]
        if record is not None:
            record(level)
        left.append(level[:, 0])
        right.append(level[:, -1])
    return np.stack(left, axis=1), np.stack(right[::-1], axis=1)


def _distance_to_segment(points: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Distance of points (M, K, d) to the segments a-b (M, d) (to a itself where a = b)."""
    ab = b - a
    length2 = (ab * ab).sum(axis=-1)
    rel = points - a[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(length2[:, None] > 0, (rel * ab[:, None]).sum(axis=-1) / length2[:, None], 0.0)
    s = np.clip(s, 0.0, 1.0)
    closest = a[:, None] + s[..., None] * ab[:, None]
    return np.sqrt(((points - closest) ** 2).sum(axis=-1))


MIN_RELATIVE_TOLERANCE = 1e-10
"""Smallest flattening tolerance (and pixel size) relative to a curve's or surface's extent: finer ones
would ask for more pieces than float64 can tell apart (1e-300 used to loop for minutes)."""


def _check_flatness_limit(points: FloatArray, limit: float, name: str, where: str) -> None:
    """Refuse a tolerance below MIN_RELATIVE_TOLERANCE × the extent of `points` (..., dim)."""
    flat = points.reshape(-1, points.shape[-1])
    extent = float((flat.max(axis=0) - flat.min(axis=0)).max()) if flat.size else 0.0
    floor = MIN_RELATIVE_TOLERANCE * extent
    if limit < floor:
        raise GeometryError(
            f"{where}: {name} = {limit!r} is below {MIN_RELATIVE_TOLERANCE:g} of the curve's extent ({extent:.6g}); "
            f"give {name} >= {floor:.3g}"
        )


def _flatten_pieces(
    control_points: FloatArray,
    tolerance: float | None,
    pixel_size: float | None,
    project: Callable[[FloatArray], ArrayLike] | None,
    max_depth: int,
    where: str,
    rational: bool = False,
) -> FloatArray:
    """Parameters in [0, 1] of the adaptive subdivision of one Bézier curve (the seed's recursive splitting).

    With ``rational`` the control points are homogeneous (w·P, w) and the tests use P (positive weights keep
    a rational piece inside the convex hull of its P, so the bound still holds).
    """
    if (tolerance is None) == (pixel_size is None):
        raise GeometryError(
            f"{where}: tolerance = {tolerance!r} and pixel_size = {pixel_size!r}; give exactly one of them"
        )
    limit = as_scalar(
        tolerance if tolerance is not None else pixel_size,
        "tolerance" if tolerance is not None else "pixel_size",
        where=where,
        error=GeometryError,
    )
    if limit <= 0:
        name = "tolerance" if tolerance is not None else "pixel_size"
        raise GeometryError(f"{where}: {name} = {limit!r} is not positive; give a positive length")
    pieces = control_points[None]
    starts, widths = np.zeros(1), np.ones(1)
    done_starts: list[FloatArray] = []
    for depth in range(max_depth + 1):
        measured = pieces[..., :-1] / pieces[..., -1:] if rational else pieces
        if project is not None:
            flat = measured.reshape(-1, measured.shape[-1])
            projected = np.asarray(project(flat), dtype=np.float64)
            if projected.ndim != 2 or projected.shape[0] != flat.shape[0] or projected.shape[1] < 2:
                raise GeometryError(
                    f"{where}: project returned shape {projected.shape}; expected ({flat.shape[0]}, 2 or more) "
                    "window coordinates"
                )
            if not np.isfinite(projected[:, :2]).all():
                raise GeometryError(
                    f"{where}: project returned non-finite window coordinates; clip the curve to the view first"
                )
            measured = projected[:, :2].reshape(*measured.shape[:2], 2)
        if depth == 0:
            _check_flatness_limit(measured, limit, "tolerance" if tolerance is not None else "pixel_size", where)
        if tolerance is not None:  # flat: every control point within `limit` of the chord P0–Pn
            size = _distance_to_segment(measured[:, 1:-1], measured[:, 0], measured[:, -1]).max(axis=1, initial=0.0)
        else:  # the seed: "until the sections are no bigger than individual pixels"
            size = (measured.max(axis=1) - measured.min(axis=1)).max(axis=1)
        finished = (size <= limit) | (depth == max_depth)
        done_starts.append(starts[finished])
        if finished.all():
            break
        left, right = _split_batch(pieces[~finished], 0.5)
        half = widths[~finished] / 2
        pieces = np.concatenate([left, right])
        starts = np.concatenate([starts[~finished], starts[~finished] + half])
        widths = np.concatenate([half, half])
    return np.concatenate([np.sort(np.concatenate(done_starts)), [1.0]])


class BezierCurve:
    """A Bézier curve of any degree n in 2D or 3D: ``C(t) = Σ_{i=0}^{n} b_{n,i}(t) · P_i``, t in [0, 1].

    Parameters
    ----------
    control_points : (n + 1, d) array_like
        The control polygon P0..Pn, d = 2 or 3, at least two points (degree >= 1).

    Raises
    ------
    GeometryError
        Wrong shape, fewer than two points, or non-finite coordinates.

    References
    ----------
    [seed] "Bezier Curves & surfaces", "Recursive Subdivision approach"; [HB 14] "Bézier Spline Curves".
    """

    __slots__ = ("control_points",)
    control_points: FloatArray

    def __init__(self, control_points: ArrayLike) -> None:
        points = _as_control_points(
            control_points, "control_points", where="BezierCurve", min_count=2, reason="(degree >= 1)"
        )
        self.control_points = read_only(points)

    @classmethod
    def _from_parts(cls, points: FloatArray) -> BezierCurve:
        curve = cls.__new__(cls)
        curve.control_points = read_only(np.ascontiguousarray(points, dtype=np.float64))
        return curve

    def __repr__(self) -> str:
        return f"BezierCurve(degree={self.degree}, dimension={self.dimension})"

    @property
    def degree(self) -> int:
        """n = number of control points − 1."""
        return int(self.control_points.shape[0] - 1)

    @property
    def dimension(self) -> int:
        """2 or 3."""
        return int(self.control_points.shape[1])

    @property
    def domain(self) -> tuple[float, float]:
        """(0.0, 1.0)."""
        return (0.0, 1.0)

    def evaluate(self, t: ArrayLike) -> FloatArray:
        """Points ``C(t)`` by de Casteljau's recursion ``P_i^j = (1 − t)·P_i^{j−1} + t·P_{i+1}^{j−1}``.

        Parameters
        ----------
        t : float or (N,) array_like
            Parameters in [0, 1]; others raise ``GeometryError``.

        Returns
        -------
        (d,) or (N, d) float64
        """
        s, scalar = _as_parameters(t, "t", 0.0, 1.0, where="BezierCurve.evaluate")
        return _shape_result(_de_casteljau(self.control_points, s), scalar)

    __call__ = evaluate

    def derivative(self) -> BezierCurve:
        """The hodograph ``C'(t) = n · Σ b_{n−1,i}(t) · (P_{i+1} − P_i)``, a Bézier curve of degree n − 1."""
        if self.degree == 0:
            return BezierCurve._from_parts(np.zeros_like(self.control_points))
        return BezierCurve._from_parts(self.degree * np.diff(self.control_points, axis=0))

    def tangent(self, t: ArrayLike) -> FloatArray:
        """``C'(t)``, not normalized."""
        s, scalar = _as_parameters(t, "t", 0.0, 1.0, where="BezierCurve.tangent")
        return _shape_result(_de_casteljau(self.derivative().control_points, s), scalar)

    def split(self, t: float = 0.5) -> tuple[BezierCurve, BezierCurve]:
        """The control points of the two halves at t (the seed's subdivision: A, AB, ABC, ABCD | ABCD, BCD, CD, D).

        The first curve reproduces ``C`` on [0, t], the second on [t, 1], each reparameterized to [0, 1].
        """
        where = "BezierCurve.split"
        s = as_scalar(t, "t", where=where, error=GeometryError)
        if not 0.0 <= s <= 1.0:
            raise GeometryError(f"{where}: t = {s!r} lies outside [0.0, 1.0]; give 0 <= t <= 1")
        left, right = _split_batch(self.control_points[None], s)
        return BezierCurve._from_parts(left[0]), BezierCurve._from_parts(right[0])

    def elevate(self) -> BezierCurve:
        """The same curve with degree n + 1: ``Q_i = i/(n+1)·P_{i−1} + (1 − i/(n+1))·P_i``, i = 0..n+1."""
        P, n = self.control_points, self.degree
        alpha = (np.arange(1, n + 1) / (n + 1))[:, None]
        middle = alpha * P[:-1] + (1.0 - alpha) * P[1:]
        return BezierCurve._from_parts(np.vstack([P[:1], middle, P[-1:]]))

    def flatten(
        self,
        tolerance: float | None = None,
        *,
        pixel_size: float | None = None,
        project: Callable[[FloatArray], ArrayLike] | None = None,
        max_depth: int = 24,
    ) -> FloatArray:
        """A polyline through curve points, by recursive subdivision at t = 1/2 (the seed's splitting process).

        Give exactly one criterion. ``tolerance``: a piece stops splitting when every control point lies within
        `tolerance` of the chord P0–Pn; by the convex-hull property the curve is then within `tolerance` of the
        polyline. ``pixel_size``: the seed's criterion, a piece stops when its control polygon fits in a
        `pixel_size` × `pixel_size` box. With ``project`` (for example ``camera.project``, any function from
        (N, d) points to (N, >= 2) window coordinates) both criteria are measured in window pixels.

        Returns
        -------
        (K, d) float64
            Curve points in order of t, including both ends.
        """
        where = "BezierCurve.flatten"
        depth = as_count(max_depth, "max_depth", 0, where=where)
        t = _flatten_pieces(self.control_points, tolerance, pixel_size, project, depth, where)
        return _de_casteljau(self.control_points, t)

    def length(self) -> float:
        """Arc length ``∫₀¹ |C'(t)| dt`` by adaptive Gauss–Kronrod quadrature (scipy ``quad``, ~1e-13)."""
        from scipy.integrate import quad

        hodograph = self.derivative().control_points

        def speed(t: float) -> float:
            return float(np.linalg.norm(_de_casteljau(hodograph, np.array([t]))[0]))

        value, _ = quad(speed, 0.0, 1.0, epsabs=1e-14, epsrel=1e-13, limit=500)
        return float(value)

    @property
    def bounding_box(self) -> FloatArray:
        """(2, d): the tight axis-aligned box [min; max] of the curve (ends and the roots of C'(t) per axis)."""
        P, n = self.control_points, self.degree
        candidates = [np.array([0.0, 1.0])]
        if n >= 2:
            D = n * np.diff(P, axis=0)  # hodograph control points, degree m = n − 1
            m = n - 1
            # power-basis coefficients of a Bernstein polynomial: a_k = C(m, k) Σ_{i<=k} (−1)^{k−i} C(k, i) D_i
            conv = np.zeros((m + 1, m + 1))
            for k in range(m + 1):
                for i in range(k + 1):
                    conv[k, i] = math.comb(m, k) * math.comb(k, i) * (-1.0) ** (k - i)
            power = conv @ D
            for axis in range(P.shape[1]):
                coefficients = power[:, axis]
                if np.abs(coefficients).max() == 0.0:
                    continue
                roots = np.polynomial.polynomial.polyroots(np.trim_zeros(coefficients, "b"))
                real = roots.real[np.abs(roots.imag) <= 1e-9]
                candidates.append(real[(real >= 0.0) & (real <= 1.0)])
        t = np.unique(np.concatenate(candidates))
        values = _de_casteljau(P, t)
        return read_only(np.stack([values.min(axis=0), values.max(axis=0)]))

    def convex_hull_contains(self, points: ArrayLike, tolerance: float = 1e-9) -> NDArray[np.bool_]:
        """Whether each point lies in the convex hull of the control polygon (within `tolerance`).

        Every point of the curve does (the seed's property 3). Degenerate hulls (collinear or coplanar control
        points) are handled in their affine hull.

        Returns
        -------
        (N,) bool
        """
        where = "BezierCurve.convex_hull_contains"
        query = _as_control_points(points, "points", where=where, dimensions=(self.dimension,))
        return _convex_hull_contains(self.control_points, query, tolerance)


def _convex_hull_contains(vertices: FloatArray, query: FloatArray, tolerance: float) -> NDArray[np.bool_]:
    """Points of `query` inside the convex hull of `vertices`, in the affine hull's own coordinates."""
    from scipy.spatial import ConvexHull

    origin = vertices.mean(axis=0)
    _, singular, vt = np.linalg.svd(vertices - origin, full_matrices=False)
    scale = max(1.0, float(np.abs(vertices).max()))
    rank = int((singular > 1e-10 * scale).sum())
    basis = vt[:rank]
    rel = query - origin
    coords = rel @ basis.T
    off = np.linalg.norm(rel - coords @ basis, axis=1) if rank else np.linalg.norm(rel, axis=1)
    inside = off <= tolerance * scale
    if rank == 0:
        return inside
    hull_coords = (vertices - origin) @ basis.T
    if rank == 1:
        low, high = hull_coords.min(), hull_coords.max()
        return inside & (coords[:, 0] >= low - tolerance * scale) & (coords[:, 0] <= high + tolerance * scale)
    hull = ConvexHull(hull_coords)
    distances = coords @ hull.equations[:, :-1].T + hull.equations[:, -1]
    return inside & (distances <= tolerance * scale).all(axis=1)


# --- piecewise Bézier curves and continuity ---------------------------------------------------------------


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

    Parameters
    ----------
    pieces : sequence of BezierCurve or (M, n + 1, d) array_like
        The pieces' control polygons, all of the same degree n and dimension d.
    breakpoints : (M + 1,) array_like, optional
        Strictly increasing global parameters of the joins; default 0, 1, ..., M.

    The constructors ``from_tangents`` (C¹) and ``interpolate_c2`` (C²) enforce continuity at the joins; the
    plain constructor accepts any pieces and ``continuity`` reports what they have.

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

        Piece k is ``[P_k, P_k + h_k·R_k/3, P_{k+1} − h_k·R_{k+1}/3, P_{k+1}]`` with h_k the width of its
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
      ``(C'' − (C''·T)T) / |C'|²`` ([HB 14] "Geometric Continuity Conditions": under G² the curvatures match).

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


# --- Hermite, cardinal and Catmull–Rom ---------------------------------------------------------------------


class HermiteCurve:
    """The cubic Hermite curve from P0 to P1 with end tangents R0, R1: ``P(t) = [t³ t² t 1] · M_H · G_H``.

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
        """``[t³ t² t 1] · M_H · G_H`` = H1·P0 + H2·P1 + H3·R0 + H4·R1."""
        s, scalar = _as_parameters(t, "t", 0.0, 1.0, where="HermiteCurve.evaluate")
        T = np.stack([s**3, s**2, s, np.ones_like(s)], axis=1)
        return _shape_result(T @ M_H @ self.geometry, scalar)

    __call__ = evaluate

    def tangent(self, t: ArrayLike) -> FloatArray:
        """``P'(t) = [3t² 2t 1 0] · M_H · G_H``."""
        s, scalar = _as_parameters(t, "t", 0.0, 1.0, where="HermiteCurve.tangent")
        T = np.stack([3 * s**2, 2 * s, np.ones_like(s), np.zeros_like(s)], axis=1)
        return _shape_result(T @ M_H @ self.geometry, scalar)

    def to_bezier(self) -> BezierCurve:
        """The same cubic as a Bézier curve: ``[P0, P0 + R0/3, P1 − R1/3, P1]``."""
        p0, p1, r0, r1 = self.geometry
        return BezierCurve._from_parts(np.stack([p0, p0 + r0 / 3.0, p1 - r1 / 3.0, p1]))


def cardinal_spline(points: ArrayLike, tension: float = 0.0) -> PiecewiseBezier:
    """The cardinal spline through points[1:-1]: Hermite pieces with tangents ``R_k = (1 − c)/2 · (P_{k+1} − P_{k−1})``.

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
    """The Catmull–Rom spline through points[1:-1]: ``cardinal_spline(points, 0)``, ``R_k = (P_{k+1} − P_{k−1})/2``."""
    return cardinal_spline(points, 0.0)


# --- cubic spline interpolation ----------------------------------------------------------------------------

_END_CONDITIONS = ("natural", "clamped", "periodic", "not-a-knot")
_PARAMETERIZATIONS = ("uniform", "chordal", "centripetal")


class CubicSpline:
    """The C² cubic spline through n + 1 points, with per-segment coefficients (a, b, c, d) as the seed writes them.

    Segment k (k = 0..n−1) is ``P(u) = a_k·u³ + b_k·u² + c_k·u + d_k`` for the local parameter u in [0, 1],
    ``u = (s − s_k)/(s_{k+1} − s_k)``, where s is the global parameter (the knots s_k).

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
        Knot spacing s_{k+1} − s_k = 1, |P_{k+1} − P_k| or |P_{k+1} − P_k|^(1/2); s_0 = 0.
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
        """The spline as piecewise cubic Bézier with breakpoints at the knots (``G_B = M_B⁻¹ · [a; b; c; d]``)."""
        return PiecewiseBezier(np.einsum("ij,kjd->kid", np.linalg.inv(M_B), self.coefficients), self.knots)


def _spline_slopes(P: FloatArray, h: FloatArray, end: str, tangents: FloatArray | None) -> FloatArray:
    """Derivatives m_k = dP/ds at the knots from the C² conditions (a tridiagonal or cyclic linear system).

    Interior knot k: ``h_k·m_{k−1} + 2(h_{k−1} + h_k)·m_k + h_{k−1}·m_{k+1} = 3(h_k·Δ_{k−1} + h_{k−1}·Δ_k)``,
    ``Δ_k = (P_{k+1} − P_k)/h_k``.
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


# --- B-splines ---------------------------------------------------------------------------------------------


def open_uniform_knots(count: int, degree: int) -> FloatArray:
    """The seed's open-uniform (clamped) knot vector for `count` = n + 1 control points and order k = degree + 1.

    ``x_i = 0 if i < k;  x_i = i − k + 1 if k <= i <= n;  x_i = n − k + 2 if i > n``, for i = 0..n+k. The
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


def _as_knot_vector(value: ArrayLike, name: str, *, where: str) -> FloatArray:
    try:
        knots = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(f"{where}: {name} = {describe(value)} is not numeric; give a 1-D array of knots") from None
    if knots.ndim != 1:
        raise GeometryError(f"{where}: {name} has shape {knots.shape}; expected a 1-D array of knots")
    bad = np.flatnonzero(~np.isfinite(knots))
    if bad.size:
        i = int(bad[0])
        raise GeometryError(f"{where}: {name}[{i}] = {float(knots[i])!r} is not finite; knots must be finite numbers")
    return np.ascontiguousarray(knots)


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
    """de Boor's algorithm for every u at once: (N, d) points of ``Σ P_i · N_{i,p}(u)``."""
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

    ``N_{i,k}(u) = (u − x_i)·N_{i,k−1}(u) / (x_{i+k−1} − x_i) + (x_{i+k} − u)·N_{i+1,k−1}(u) / (x_{i+k} − x_{i+1})``
    with a term whose denominator is 0 taken as 0 (0/0 = 0). ``N_{i,1}(u) = 1`` if ``x_i <= u < x_{i+1}``, else
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
    """A B-spline curve ``C(u) = Σ_{i=0}^{n} P_i · N_{i,k}(u)`` of degree p = k − 1, evaluated by de Boor's algorithm.

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
        """Points by de Boor's algorithm ``d_j ← (1 − α)·d_{j−1} + α·d_j``, ``α = (u − t_i)/(t_{i+p+1−r} − t_i)``."""
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
        """The derivative curve: degree p − 1, ``Q_i = p·(P_{i+1} − P_i)/(t_{i+p+1} − t_{i+1})`` (0/0 = 0)."""
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

        ``Q_i = (1 − a_i)·P_{i−1} + a_i·P_i``, ``a_i = (u − t_i)/(t_{i+p} − t_i)`` for s − p + 1 <= i <= s.
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


# --- NURBS -------------------------------------------------------------------------------------------------


class NURBSCurve:
    """A rational B-spline ``C(u) = Σ w_i·P_i·N_{i,p}(u) / Σ w_i·N_{i,p}(u)``: exact conics, circles included.

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
        """``C(u) = A(u)/w(u)`` with ``(A, w)`` the homogeneous B-spline."""
        s, scalar = _as_parameters(u, "u", *self.domain, where="NURBSCurve.evaluate")
        h = _de_boor(self.knots, self.degree, self._homogeneous.control_points, s)
        return _shape_result(h[:, :-1] / h[:, -1:], scalar)

    __call__ = evaluate

    def tangent(self, u: ArrayLike) -> FloatArray:
        """``C'(u) = (A'(u) − w'(u)·C(u)) / w(u)`` (quotient rule)."""
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

        Quadratic, one segment per started quarter turn; segment of sweep Δ: middle weight ``cos(Δ/2)``, middle
        control point at distance ``r/cos(Δ/2)`` on the bisector. In the plane z = center z for a 3-D center.
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
        """The exact ellipse (x/a)² + (y/b)² = 1 about `center`: the circle's net scaled (weights unchanged)."""
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
