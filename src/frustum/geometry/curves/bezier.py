"""Bézier curves: Bernstein polynomials, the cubic matrix form (``M_B``), de Casteljau evaluation and subdivision,
adaptive flattening, and the convex-hull property (``BezierCurve``)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, as_scalar, describe, read_only
from frustum.errors import GeometryError
from frustum.geometry.curves._validation import FloatArray, _as_control_points, _as_parameters, _shape_result

M_B: FloatArray = read_only(
    np.array([[-1.0, 3.0, -3.0, 1.0], [3.0, -6.0, 3.0, 0.0], [-3.0, 3.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
)
"""The cubic Bézier basis matrix: ``C(t) = [t³ t² t 1] · M_B · G_B`` with ``G_B = [P0; P1; P2; P3]``."""


def bernstein(n: int, i: int, t: ArrayLike) -> FloatArray | float:
    """The Bernstein polynomial $b_{n,i}(t) = C(n, i) · tⁱ · (1 − t)ⁿ⁻ⁱ$ (the Bézier blending function).

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
    """The cubic Bézier curve in matrix form, $C(t) = [t³ t² t 1] · M_B · G_B$.

    Parameters
    ----------
    t : float or (N,) array_like
        Parameters in [0, 1].
    G : (4, d) array_like
        The geometry vector $G_B = [P0; P1; P2; P3]$ (d = 2 or 3).

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
    """A Bézier curve of any degree n in 2D or 3D: $C(t) = Σ_{i=0}^{n} b_{n,i}(t) · P_i$, t in [0, 1].

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
        """Points ``C(t)`` by de Casteljau's recursion $P_i^j = (1 − t)·P_i^{j−1} + t·P_{i+1}^{j−1}$.

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
        """The hodograph $C'(t) = n · Σ b_{n−1,i}(t) · (P_{i+1} − P_i)$, a Bézier curve of degree n − 1."""
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
        """The same curve with degree n + 1: $Q_i = i/(n+1)·P_{i−1} + (1 − i/(n+1))·P_i$, i = 0..n+1."""
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
        """Arc length $∫₀¹ |C'(t)| dt$ by adaptive Gauss–Kronrod quadrature (scipy ``quad``, ~1e-13)."""
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
