"""Tensor-product surfaces: Bézier, B-spline and NURBS patches, their normals and tessellation into a ``Mesh``.

A surface maps (u, v) in its domain to a 3-D point, $S(u, v) = Σ_i Σ_j B_i(u)·B_j(v)·P_ij$, with the control
grid ``P[i, j]`` of shape ``(m + 1, n + 1, 3)``: the first grid index goes with u, the second with v. The
normal is $S_u × S_v$ normalized, and tessellated faces are counter-clockwise seen from that side.

Where a whole edge of the control grid collapses to one point (a pole, as at the teapot's lid knob and bottom,
or a NURBS sphere's poles) $S_u × S_v$ vanishes. There the normal is its limit from inside the patch: with
``S_v → 0`` on the edge u = 0, $S_v ≈ u·S_uv$ and the normal is $S_u × S_uv$ (signs follow the side).

References
----------
[seed] "Bézier Surfaces" ("a bicubic Bézier surface from a 4x4 grid of control points"); [HB 14] "Bézier
Surfaces", "B-Spline Surfaces", "Rational Splines".
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, as_scalar, describe, read_only
from frustum.budgets import check_memory
from frustum.errors import GeometryError
from frustum.geometry.curves._validation import _as_degree, _as_parameters
from frustum.geometry.curves.bezier import MIN_RELATIVE_TOLERANCE, BezierCurve, _de_casteljau, _split_batch
from frustum.geometry.curves.bspline import NURBSCurve, _as_weights, _basis_matrix, _checked_knots, _knots_for
from frustum.geometry.mesh import Mesh, _normalize_rows

__all__ = ["BSplineSurface", "BezierSurface", "NURBSSurface"]

FloatArray = NDArray[np.float64]


def _as_grid(value: ArrayLike, name: str, *, where: str, min_shape: tuple[int, int] = (2, 2)) -> FloatArray:
    """A finite (rows, columns, 3) float64 control grid with at least `min_shape` points."""
    try:
        grid = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise GeometryError(
            f"{where}: {name} = {describe(value)} is not numeric; expected an (m + 1, n + 1, 3) control grid"
        ) from None
    if grid.ndim != 3 or grid.shape[2] != 3:
        raise GeometryError(f"{where}: {name} has shape {grid.shape}; expected an (m + 1, n + 1, 3) control grid")
    bad = np.argwhere(~np.isfinite(grid).all(axis=2))
    if bad.size:
        i, j = (int(v) for v in bad[0])
        raise GeometryError(
            f"{where}: {name}[{i}, {j}] = {describe(grid[i, j])} is not finite; coordinates must be finite numbers"
        )
    for axis, (size, least) in enumerate(zip(grid.shape[:2], min_shape, strict=True)):
        if size < least:
            raise GeometryError(
                f"{where}: {name}.shape[{axis}] = {size} is below {least}; give at least {least} control points "
                f"along {'uv'[axis]} (degree + 1)"
            )
    return np.ascontiguousarray(grid)


_ALL = ((0, 0), (1, 0), (0, 1), (1, 1))


class _Surface:
    """Shared evaluation, normals and tessellation; subclasses give the 1-D basis matrices of each direction."""

    __slots__ = ()
    grid: FloatArray  # (m + 1, n + 1, 3) control points; ``_net`` is what the bases weight (homogeneous for NURBS)

    # subclasses: domain_u, domain_v, _basis(axis, values, order)
    @property
    def domain_u(self) -> tuple[float, float]:
        raise NotImplementedError

    @property
    def domain_v(self) -> tuple[float, float]:
        raise NotImplementedError

    def _basis(self, axis: int, values: FloatArray, order: int) -> FloatArray:
        raise NotImplementedError

    def _params(self, u: ArrayLike, v: ArrayLike, where: str) -> tuple[FloatArray, FloatArray, bool]:
        su, scalar_u = _as_parameters(u, "u", *self.domain_u, where=where)
        sv, scalar_v = _as_parameters(v, "v", *self.domain_v, where=where)
        try:
            su, sv = np.broadcast_arrays(su, sv)
        except ValueError:
            raise GeometryError(
                f"{where}: u has {su.size} values and v has {sv.size}; give arrays of one length (or a scalar)"
            ) from None
        return np.ascontiguousarray(su), np.ascontiguousarray(sv), scalar_u and scalar_v

    @property
    def _net(self) -> FloatArray:
        """The net that the basis functions weight: the control grid (homogeneous (w·P, w) for NURBS)."""
        return self.grid

    def _raw(self, u: FloatArray, v: FloatArray, du: int, dv: int) -> FloatArray:
        """Σ_i Σ_j B_i^(du)(u)·B_j^(dv)(v)·grid[i, j] for pointwise (u, v): (N, dimension)."""
        bu = self._basis(0, u, du)
        bv = self._basis(1, v, dv)
        return np.einsum("ni,nj,ijd->nd", bu, bv, self._net)

    def _raw_grid(self, u: FloatArray, v: FloatArray, du: int, dv: int) -> FloatArray:
        """The same on the grid u × v: (len(u), len(v), dimension)."""
        return np.einsum("ai,ijd,bj->abd", self._basis(0, u, du), self._net, self._basis(1, v, dv))

    def _derivatives(self, raw: Any, keys: tuple[tuple[int, int], ...] = _ALL) -> dict[tuple[int, int], FloatArray]:
        """{(du, dv): value} for the requested keys from a function raw(du, dv) (NURBS: the quotient rule)."""
        return {key: raw(*key) for key in keys}

    def evaluate(self, u: ArrayLike, v: ArrayLike) -> FloatArray:
        """Points ``S(u, v)`` for matching arrays (or scalars) u, v: (N, 3) or (3,)."""
        su, sv, scalar = self._params(u, v, f"{type(self).__name__}.evaluate")
        points = self._derivatives(lambda a, b: self._raw(su, sv, a, b), ((0, 0),))[(0, 0)]
        return points[0] if scalar else points

    __call__ = evaluate

    def partial(self, u: ArrayLike, v: ArrayLike, du: int = 1, dv: int = 0) -> FloatArray:
        """The partial derivative $∂^(du+dv) S / ∂u^du ∂v^dv$ (du, dv in {0, 1}): (N, 3) or (3,)."""
        where = f"{type(self).__name__}.partial"
        du, dv = as_count(du, "du", 0, where=where), as_count(dv, "dv", 0, where=where)
        if du > 1 or dv > 1:
            raise GeometryError(f"{where}: (du, dv) = ({du}, {dv}) is not supported; give du, dv in {{0, 1}}")
        su, sv, scalar = self._params(u, v, where)
        values = self._derivatives(lambda a, b: self._raw(su, sv, a, b), ((du, dv),))[(du, dv)]
        return values[0] if scalar else values

    def normal(self, u: ArrayLike, v: ArrayLike) -> FloatArray:
        """Unit normals $(S_u × S_v)/|S_u × S_v|$, the limit from inside the patch at collapsed edges."""
        su, sv, scalar = self._params(u, v, f"{type(self).__name__}.normal")
        d = self._derivatives(lambda a, b: self._raw(su, sv, a, b))
        normals = _unit_normals(d, su, sv, self.domain_u, self.domain_v, self._scale())
        bad = np.flatnonzero(~np.isfinite(normals).all(axis=1))
        if bad.size:  # a singular point that is not a collapsed edge: step a little into the patch
            normals[bad] = self._nudged_normals(su[bad], sv[bad])
        return normals[0] if scalar else normals

    def _scale(self) -> float:
        return max(1.0, float(np.abs(self.grid).max()))

    def _nudged_normals(self, u: FloatArray, v: FloatArray) -> FloatArray:
        (u0, u1), (v0, v1) = self.domain_u, self.domain_v
        out = np.full((u.size, 3), np.nan)
        for step in (1e-7, 1e-5, 1e-3):
            todo = ~np.isfinite(out).all(axis=1)
            if not todo.any():
                break
            nu = u[todo] + step * (u1 - u0) * np.sign((u0 + u1) / 2 - u[todo])
            nv = v[todo] + step * (v1 - v0) * np.sign((v0 + v1) / 2 - v[todo])
            d = self._derivatives(lambda a, b, nu=nu, nv=nv: self._raw(nu, nv, a, b))
            cross = np.cross(d[(1, 0)], d[(0, 1)])
            length = np.linalg.norm(cross, axis=1)
            with np.errstate(invalid="ignore", divide="ignore"):
                out[todo] = np.where(length[:, None] > 0, cross / length[:, None], np.nan)
        out[~np.isfinite(out).all(axis=1)] = (0.0, 0.0, 1.0)
        return out

    def tessellate(self, nu: int = 16, nv: int = 16) -> Mesh:
        """A ``Mesh`` of (nu + 1)·(nv + 1) vertices on the uniform parameter grid with analytic unit normals.

        Vertex $i·(nv + 1) + j$ is ``S(u_i, v_j)``. Each grid cell gives two triangles, counter-clockwise seen
        from the normal side; triangles with two coincident corners (at collapsed edges) are dropped.
        """
        where = f"{type(self).__name__}.tessellate"
        nu, nv = as_count(nu, "nu", 1, where=where), as_count(nv, "nv", 1, where=where)
        # 6 derivative arrays + normals + points (3 float64 each) per vertex, 2 triangles (3 int64) per cell
        check_memory((nu + 1) * (nv + 1) * 8 * 24 + nu * nv * 48, where=where, cause=f"nu = {nu}, nv = {nv}",
                     error=GeometryError)  # fmt: skip
        u = np.linspace(*self.domain_u, nu + 1)
        v = np.linspace(*self.domain_v, nv + 1)
        uu, vv = (a.ravel() for a in np.meshgrid(u, v, indexing="ij"))
        d = self._derivatives(lambda a, b: self._raw_grid(u, v, a, b).reshape(uu.size, -1))
        normals = _unit_normals(d, uu, vv, self.domain_u, self.domain_v, self._scale())
        bad = np.flatnonzero(~np.isfinite(normals).all(axis=1))
        if bad.size:
            normals[bad] = self._nudged_normals(uu[bad], vv[bad])
        return Mesh(d[(0, 0)], _grid_faces(nu, nv, d[(0, 0)]), normals)

    def flatness_resolution(self, tolerance: float) -> tuple[int, int]:
        """(nu, nv) such that the uniform tessellation is within `tolerance` of the surface.

        Uses the bound for piecewise-linear interpolation on a triangulated grid of steps (h_u, h_v):
        $|S − T| <= (h_u²·M_uu + 2·h_u·h_v·M_uv + h_v²·M_vv)/8$ with M bounds of the second partials
        (Filip, Magedson & Markot 1986). Polynomial patches take M from the control nets of the second
        derivatives (convex hull property, a true bound); NURBS patches estimate M on a 33 × 33 sample, × 1.5.
        """
        where = f"{type(self).__name__}.flatness_resolution"
        tol = as_scalar(tolerance, "tolerance", where=where, error=GeometryError)
        if tol <= 0:
            raise GeometryError(f"{where}: tolerance = {tol!r} is not positive; give a positive distance")
        extent = float(np.ptp(self.grid.reshape(-1, 3), axis=0).max())
        if tol < MIN_RELATIVE_TOLERANCE * extent:
            raise GeometryError(
                f"{where}: tolerance = {tol!r} is below {MIN_RELATIVE_TOLERANCE:g} of the surface's extent "
                f"({extent:.6g}); give tolerance >= {MIN_RELATIVE_TOLERANCE * extent:.3g}"
            )
        m_uu, m_uv, m_vv = self._second_derivative_bounds()
        width_u = self.domain_u[1] - self.domain_u[0]
        width_v = self.domain_v[1] - self.domain_v[0]
        # split the budget in three: each term <= tol/3
        nu = max(1, math.ceil(width_u * math.sqrt(3 * m_uu / (8 * tol)))) if m_uu > 0 else 1
        nv = max(1, math.ceil(width_v * math.sqrt(3 * m_vv / (8 * tol)))) if m_vv > 0 else 1
        # the cross term: the smallest k with (nu + k)(nv + k) >= P, P = 3·2·w_u·w_v·M_uv / (8·tol), closed form
        product = 3 * 2 * width_u * width_v * m_uv / (8 * tol)
        if nu * nv < product:
            k = math.ceil((-(nu + nv) + math.sqrt((nu - nv) ** 2 + 4 * product)) / 2)
            while (nu + k) * (nv + k) < product:  # float rounding: at most a step or two
                k += 1
            nu, nv = nu + k, nv + k
        return nu, nv

    def _second_derivative_bounds(self) -> tuple[float, float, float]:
        u = np.linspace(*self.domain_u, 33)
        v = np.linspace(*self.domain_v, 33)
        bounds = []
        for du, dv in ((2, 0), (1, 1), (0, 2)):
            values = self._raw_grid(u, v, du, dv)
            bounds.append(1.5 * float(np.linalg.norm(values, axis=-1).max()))
        return bounds[0], bounds[1], bounds[2]

    def tessellate_adaptive(self, tolerance: float) -> Mesh:
        """``tessellate(*flatness_resolution(tolerance))``: as fine as this patch's curvature needs."""
        return self.tessellate(*self.flatness_resolution(tolerance))


def _unit_normals(
    d: dict[tuple[int, int], FloatArray],
    u: FloatArray,
    v: FloatArray,
    domain_u: tuple[float, float],
    domain_v: tuple[float, float],
    scale: float,
) -> FloatArray:
    """Normalized S_u × S_v; at vanishing S_u or S_v the limit S_u × S_uv or S_uv × S_v; NaN where undecided."""
    su, sv, suv = d[(1, 0)], d[(0, 1)], d[(1, 1)]
    cross = np.cross(su, sv)
    length = np.linalg.norm(cross, axis=1)
    tiny = 1e-10 * scale * scale
    degenerate = length <= tiny
    if degenerate.any():
        small_v = np.linalg.norm(sv, axis=1) <= 1e-10 * scale
        small_u = np.linalg.norm(su, axis=1) <= 1e-10 * scale
        mid_u, mid_v = sum(domain_u) / 2, sum(domain_v) / 2
        # S_v ≈ (u − u_edge)·S_uv near a collapsed u-edge; S_u ≈ (v − v_edge)·S_uv near a collapsed v-edge
        sign_u = np.where(u <= mid_u, 1.0, -1.0)[:, None]
        sign_v = np.where(v <= mid_v, 1.0, -1.0)[:, None]
        limit = np.where(
            (small_v & ~small_u)[:, None],
            sign_u * np.cross(su, suv),
            np.where((small_u & ~small_v)[:, None], sign_v * np.cross(suv, sv), np.nan),
        )
        cross = np.where(degenerate[:, None], limit, cross)
        length = np.linalg.norm(cross, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where((length > tiny)[:, None], cross / length[:, None], np.nan)


def _grid_faces(nu: int, nv: int, vertices: FloatArray) -> NDArray[np.int64]:
    """Two counter-clockwise triangles per cell (a, b, c), (a, c, d); drops triangles with two coincident corners."""
    return _grid_faces_batch(nu, nv, vertices[None])


def _grid_faces_batch(nu: int, nv: int, vertices: FloatArray) -> NDArray[np.int64]:
    """``_grid_faces`` of P grids at once, vertices (P, (nu + 1)·(nv + 1), 3): the faces of grid p index its
    vertices from p·(nu + 1)·(nv + 1), in grid order (as concatenating the single-grid results would)."""
    count, per_grid = vertices.shape[0], vertices.shape[1]
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = (i * (nv + 1) + j).ravel()
    b = a + nv + 1  # (i + 1, j)
    c = b + 1  # (i + 1, j + 1)
    d = a + 1  # (i, j + 1)
    faces = np.concatenate([np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)])
    order = np.argsort(np.concatenate([np.arange(a.size) * 2, np.arange(a.size) * 2 + 1]), kind="stable")
    faces = faces[order]
    p = vertices[np.arange(count)[:, None, None], faces]  # (P, F, 3 corners, 3)
    scale = np.maximum(1.0, np.abs(vertices).reshape(count, -1).max(axis=1, initial=0.0))
    shortest = np.sqrt(((p - p[:, :, [1, 2, 0]]) ** 2).sum(axis=3)).min(axis=2)
    keep = shortest > 1e-12 * scale[:, None]  # corners that coincide up to round-off (a collapsed edge)
    offsets = np.arange(count, dtype=np.int64)[:, None, None] * per_grid
    return np.ascontiguousarray((faces + offsets)[keep], dtype=np.int64)


def _tessellate_bezier_grids(patches: Sequence[BezierSurface], grids: FloatArray, nu: int, nv: int,
                             where: str) -> Mesh:  # fmt: skip
    """One ``Mesh`` of P Bézier patches of one degree, grids (P, m + 1, n + 1, 3), each tessellated nu × nv: the
    vertices, normals and faces of ``patch.tessellate(nu, nv)`` for every patch, concatenated (the same float64
    values), computed for all patches at once (the Bernstein matrices once, one einsum per derivative)."""
    count = grids.shape[0]
    per_patch = (nu + 1) * (nv + 1)
    check_memory(count * (per_patch * 8 * 24 + nu * nv * 48), where=where, cause=f"{count} patches x nu = {nu}, "
                 f"nv = {nv}", error=GeometryError)  # fmt: skip
    u = np.linspace(0.0, 1.0, nu + 1)
    v = np.linspace(0.0, 1.0, nv + 1)
    m, n = grids.shape[1] - 1, grids.shape[2] - 1
    bu = {order: _bernstein_matrix(m, u, order) for order in (0, 1)}
    bv = {order: _bernstein_matrix(n, v, order) for order in (0, 1)}
    d = {(a, b): np.einsum("ai,pijd,bj->pabd", bu[a], grids, bv[b]).reshape(count * per_patch, 3) for a, b in _ALL}
    uu, vv = (a.ravel() for a in np.meshgrid(u, v, indexing="ij"))
    scales = np.maximum(1.0, np.abs(grids).reshape(count, -1).max(axis=1))  # each patch's _scale()
    normals = _unit_normals(d, np.tile(uu, count), np.tile(vv, count), (0.0, 1.0), (0.0, 1.0),
                            np.repeat(scales, per_patch))  # fmt: skip
    bad = np.flatnonzero(~np.isfinite(normals).all(axis=1))
    for patch_index in sorted(set((bad // per_patch).tolist())):  # (np.unique would import numpy.ma: 15 ms)
        rows = bad[bad // per_patch == patch_index]
        local = rows - patch_index * per_patch
        normals[rows] = patches[patch_index]._nudged_normals(uu[local], vv[local])
    points = d[(0, 0)]
    faces = _grid_faces_batch(nu, nv, points.reshape(count, per_patch, 3))
    # each patch's Mesh normalized its normals once, and the concatenated Mesh again: the same two roundings
    _normalize_rows(normals, where)
    return Mesh(points, faces, normals)


# --- Bézier ------------------------------------------------------------------------------------------------


def _bernstein_matrix(degree: int, t: FloatArray, order: int) -> FloatArray:
    """(N, degree + 1): the `order`-th derivatives of all Bernstein polynomials b_{degree,i} at t."""
    curve = BezierCurve._from_parts(np.eye(degree + 1))
    for _ in range(order):
        curve = curve.derivative()
    return _de_casteljau(curve.control_points, t)


class BezierSurface(_Surface):
    """A tensor-product Bézier patch of degree m × n: $S(u, v) = Σ_i Σ_j b_{m,i}(u)·b_{n,j}(v)·P_ij$, u, v in [0, 1].

    Parameters
    ----------
    grid : (m + 1, n + 1, 3) array_like
        Control points, m, n >= 1 (the bicubic patch is 4 × 4).

    References
    ----------
    [seed] "Bézier Surfaces"; [HB 14] "Bézier Surfaces".
    """

    __slots__ = ("grid",)

    def __init__(self, grid: ArrayLike) -> None:
        self.grid = read_only(_as_grid(grid, "grid", where="BezierSurface"))

    @classmethod
    def _from_parts(cls, grid: FloatArray) -> BezierSurface:
        surface = cls.__new__(cls)
        surface.grid = read_only(np.ascontiguousarray(grid, dtype=np.float64))
        return surface

    def __repr__(self) -> str:
        return f"BezierSurface(degree={self.degree})"

    @property
    def degree(self) -> tuple[int, int]:
        """(m, n)."""
        return (self.grid.shape[0] - 1, self.grid.shape[1] - 1)

    @property
    def domain_u(self) -> tuple[float, float]:
        return (0.0, 1.0)

    @property
    def domain_v(self) -> tuple[float, float]:
        return (0.0, 1.0)

    def _basis(self, axis: int, values: FloatArray, order: int) -> FloatArray:
        return _bernstein_matrix(self.grid.shape[axis] - 1, values, order)

    def _second_derivative_bounds(self) -> tuple[float, float, float]:
        P = self.grid
        m, n = self.degree
        bounds = []
        for du, dv in ((2, 0), (1, 1), (0, 2)):
            net = P
            for axis, count, degree in ((0, du, m), (1, dv, n)):
                for k in range(count):
                    net = (degree - k) * np.diff(net, axis=axis) if degree - k > 0 else np.zeros_like(net[:1])
            bounds.append(float(np.linalg.norm(net, axis=-1).max()) if net.size else 0.0)
        return bounds[0], bounds[1], bounds[2]

    def split(self, u: float = 0.5, axis: int = 0) -> tuple[BezierSurface, BezierSurface]:
        """Subdivide along u (axis 0) or v (axis 1) at the parameter `u` by de Casteljau on every row/column."""
        where = "BezierSurface.split"
        t = as_scalar(u, "u", where=where, error=GeometryError)
        if not 0.0 <= t <= 1.0 or axis not in (0, 1):
            raise GeometryError(f"{where}: (u, axis) = ({t!r}, {axis!r}) is invalid; give 0 <= u <= 1, axis 0 or 1")
        if axis == 1:  # each row grid[i] is a Bézier curve in v
            left, right = _split_batch(self.grid, t)
        else:  # each column grid[:, j] is a Bézier curve in u
            left, right = (half.transpose(1, 0, 2) for half in _split_batch(self.grid.transpose(1, 0, 2), t))
        return BezierSurface._from_parts(left), BezierSurface._from_parts(right)


# --- B-spline ----------------------------------------------------------------------------------------------


class BSplineSurface(_Surface):
    """A tensor-product B-spline surface $S(u, v) = Σ_i Σ_j N_{i,p}(u)·N_{j,q}(v)·P_ij$.

    Parameters
    ----------
    grid : (m + 1, n + 1, 3) array_like
    degree_u, degree_v : int
        p, q >= 1, with at least p + 1 rows and q + 1 columns.
    knots_u, knots_v : "clamped", "uniform" or array_like
        As for ``BSpline`` (``clamped`` is the seed's open-uniform vector).

    References
    ----------
    [HB 14] "B-Spline Surfaces".
    """

    __slots__ = ("degrees", "grid", "knots_u", "knots_v")
    degrees: tuple[int, int]
    knots_u: FloatArray
    knots_v: FloatArray

    def __init__(
        self,
        grid: ArrayLike,
        degree_u: int = 3,
        degree_v: int = 3,
        knots_u: str | ArrayLike = "clamped",
        knots_v: str | ArrayLike = "clamped",
    ) -> None:
        where = "BSplineSurface"
        p = _as_degree(degree_u, where=where, name="degree_u")
        q = _as_degree(degree_v, where=where, name="degree_v")
        P = _as_grid(grid, "grid", where=where, min_shape=(p + 1, q + 1))
        tu = _surface_knots(knots_u, P.shape[0], p, where, "knots_u")
        tv = _surface_knots(knots_v, P.shape[1], q, where, "knots_v")
        self.grid = read_only(P)
        self.degrees = (p, q)
        self.knots_u, self.knots_v = read_only(tu), read_only(tv)

    def __repr__(self) -> str:
        return f"BSplineSurface(shape={self.grid.shape[:2]}, degrees={self.degrees})"

    @property
    def domain_u(self) -> tuple[float, float]:
        return (float(self.knots_u[self.degrees[0]]), float(self.knots_u[self.grid.shape[0]]))

    @property
    def domain_v(self) -> tuple[float, float]:
        return (float(self.knots_v[self.degrees[1]]), float(self.knots_v[self.grid.shape[1]]))

    def _basis(self, axis: int, values: FloatArray, order: int) -> FloatArray:
        knots = self.knots_u if axis == 0 else self.knots_v
        return _basis_matrix(knots, self.degrees[axis], self.grid.shape[axis], values, order)

    def _second_derivative_bounds(self) -> tuple[float, float, float]:
        bounds = []
        for du, dv in ((2, 0), (1, 1), (0, 2)):
            net = self.grid
            for axis, count in ((0, du), (1, dv)):
                knots = self.knots_u if axis == 0 else self.knots_v
                degree = self.degrees[axis]
                for k in range(count):
                    net = _derivative_net(net, knots[k : knots.size - k], degree - k, axis)
            bounds.append(float(np.linalg.norm(net, axis=-1).max()) if net.size else 0.0)
        return bounds[0], bounds[1], bounds[2]


def _derivative_net(net: FloatArray, knots: FloatArray, degree: int, axis: int) -> FloatArray:
    """Control net of the derivative along `axis`: $p·(P_{i+1} − P_i)/(t_{i+p+1} − t_{i+1})$ (0/0 = 0)."""
    if degree == 0:
        return np.zeros_like(net)
    count = net.shape[axis]
    denom = knots[degree + 1 : degree + count] - knots[1:count]
    shape = [1, 1, 1]
    shape[axis] = denom.size
    denom = denom.reshape(shape)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(denom > 0, degree * np.diff(net, axis=axis) / denom, 0.0)


def _surface_knots(kind: Any, count: int, degree: int, where: str, name: str) -> FloatArray:
    if isinstance(kind, str) and kind == "closed":
        raise GeometryError(
            f"{where}: {name} = 'closed' is not supported for surfaces; give 'clamped', 'uniform' or an array"
        )
    if isinstance(kind, str):
        return _knots_for(kind, count, degree, where)[0]
    return _checked_knots(kind, count, degree, where=where, name=name)


# --- NURBS -------------------------------------------------------------------------------------------------


class NURBSSurface(BSplineSurface):
    """A rational B-spline surface $S = Σ w_ij·P_ij·N_i(u)·N_j(v) / Σ w_ij·N_i(u)·N_j(v)$: exact quadrics.

    Evaluated as a B-spline surface in homogeneous coordinates (w·P, w); derivatives by the quotient rule
    $S_u = (A_u − w_u·S)/w$, $S_uv = (A_uv − w_uv·S − w_u·S_v − w_v·S_u)/w$.

    Parameters
    ----------
    grid : (m + 1, n + 1, 3) array_like
        Control points P_ij (``grid``; the homogeneous net (w·P, w) is internal).
    weights : (m + 1, n + 1) array_like
        Positive.
    degree_u, degree_v, knots_u, knots_v
        As for ``BSplineSurface``.

    References
    ----------
    [HB 14] "Rational Splines".
    """

    __slots__ = ("_homogeneous", "weights")
    weights: FloatArray
    _homogeneous: FloatArray

    def __init__(
        self,
        grid: ArrayLike,
        weights: ArrayLike,
        degree_u: int = 2,
        degree_v: int = 2,
        knots_u: str | ArrayLike = "clamped",
        knots_v: str | ArrayLike = "clamped",
    ) -> None:
        where = "NURBSSurface"
        super().__init__(grid, degree_u, degree_v, knots_u, knots_v)
        P = self.grid
        w = _as_weights(weights, P.shape[0] * P.shape[1], where=where).reshape(P.shape[:2])
        self.weights = read_only(w)
        self._homogeneous = read_only(np.ascontiguousarray(np.concatenate([P * w[..., None], w[..., None]], axis=2)))

    def __repr__(self) -> str:
        return f"NURBSSurface(shape={self.grid.shape[:2]}, degrees={self.degrees})"

    @property
    def _net(self) -> FloatArray:
        return self._homogeneous

    def _derivatives(self, raw: Any, keys: tuple[tuple[int, int], ...] = _ALL) -> dict[tuple[int, int], FloatArray]:
        needed = {(0, 0), *keys}
        if (1, 1) in needed:
            needed |= {(1, 0), (0, 1)}
        h = {key: raw(*key) for key in needed}
        w = h[(0, 0)][:, 3:]
        out = {(0, 0): h[(0, 0)][:, :3] / w}
        for key in ((1, 0), (0, 1)):
            if key in h:
                out[key] = (h[key][:, :3] - h[key][:, 3:] * out[(0, 0)]) / w
        if (1, 1) in h:
            out[(1, 1)] = (
                h[(1, 1)][:, :3]
                - h[(1, 1)][:, 3:] * out[(0, 0)]
                - h[(1, 0)][:, 3:] * out[(0, 1)]
                - h[(0, 1)][:, 3:] * out[(1, 0)]
            ) / w
        return out

    def _second_derivative_bounds(self) -> tuple[float, float, float]:
        u = np.linspace(*self.domain_u, 33)
        v = np.linspace(*self.domain_v, 33)
        uu, vv = (a.ravel() for a in np.meshgrid(u, v, indexing="ij"))
        h = {key: self._raw(uu, vv, *key) for key in ((0, 0), (1, 0), (0, 1), (2, 0), (0, 2), (1, 1))}
        w = h[(0, 0)][:, 3:]
        s = h[(0, 0)][:, :3] / w
        first = {k: (h[k][:, :3] - h[k][:, 3:] * s) / w for k in ((1, 0), (0, 1))}
        suu = (h[(2, 0)][:, :3] - h[(2, 0)][:, 3:] * s - 2 * h[(1, 0)][:, 3:] * first[(1, 0)]) / w
        svv = (h[(0, 2)][:, :3] - h[(0, 2)][:, 3:] * s - 2 * h[(0, 1)][:, 3:] * first[(0, 1)]) / w
        suv = (
            h[(1, 1)][:, :3]
            - h[(1, 1)][:, 3:] * s
            - h[(1, 0)][:, 3:] * first[(0, 1)]
            - h[(0, 1)][:, 3:] * first[(1, 0)]
        ) / w
        m_uu, m_uv, m_vv = (1.5 * float(np.linalg.norm(x, axis=1).max()) for x in (suu, suv, svv))
        return m_uu, m_uv, m_vv

    @classmethod
    def sphere(cls, radius: float = 1.0, center: ArrayLike = (0.0, 0.0, 0.0)) -> NURBSSurface:
        """The exact sphere: a quadratic NURBS circle (u, longitude) times a half circle (v, south to north pole).

        $P_ij = (x_j·c_i, z_j)$ with weight $w_i·w_j$; $S_u × S_v$ points outward; the poles are collapsed
        rows (their normals are the limits, ±z).
        """
        where = "NURBSSurface.sphere"
        r = as_scalar(radius, "radius", where=where, error=GeometryError)
        if r <= 0:
            raise GeometryError(f"{where}: radius = {r!r} is not positive; give a positive radius")
        c = _as_center(center, where)
        circle = NURBSCurve.circle(1.0, (0.0, 0.0))
        profile = NURBSCurve.arc(r, -math.pi / 2, math.pi / 2, (0.0, 0.0))
        return cls._revolve(circle, profile, c)

    @classmethod
    def cylinder(cls, radius: float = 1.0, height: float = 1.0, center: ArrayLike = (0.0, 0.0, 0.0)) -> NURBSSurface:
        """The exact open cylinder about the z axis through `center`, z from center − height/2 to center + height/2."""
        where = "NURBSSurface.cylinder"
        r = as_scalar(radius, "radius", where=where, error=GeometryError)
        h = as_scalar(height, "height", where=where, error=GeometryError)
        for name, value in (("radius", r), ("height", h)):
            if value <= 0:
                raise GeometryError(f"{where}: {name} = {value!r} is not positive; give a positive {name}")
        c = _as_center(center, where)
        circle = NURBSCurve.circle(1.0, (0.0, 0.0))
        line = NURBSCurve([[r, -h / 2], [r, h / 2]], [1.0, 1.0], 1, [0.0, 0.0, 1.0, 1.0])
        return cls._revolve(circle, line, c)

    @classmethod
    def _revolve(cls, circle: NURBSCurve, profile: NURBSCurve, center: FloatArray) -> NURBSSurface:
        """Surface of revolution about z: profile (x, z) points swept by the unit circle (c_x, c_y)."""
        cp, pp = circle.control_points, profile.control_points
        grid = np.empty((cp.shape[0], pp.shape[0], 3))
        grid[..., 0] = cp[:, None, 0] * pp[None, :, 0]
        grid[..., 1] = cp[:, None, 1] * pp[None, :, 0]
        grid[..., 2] = np.broadcast_to(pp[None, :, 1], grid.shape[:2])
        weights = circle.weights[:, None] * profile.weights[None, :]
        return cls(grid + center, weights, circle.degree, profile.degree, circle.knots, profile.knots)


def _as_center(center: ArrayLike, where: str) -> FloatArray:
    from frustum._arrays import as_vector3

    return as_vector3(center, "center", where=where, error=GeometryError)
