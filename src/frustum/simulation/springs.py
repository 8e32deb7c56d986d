"""Mass–spring systems: point masses joined by damped springs, stepped by five integrators; cloth, ropes, soft bodies.

Spring s joins masses i and j with stiffness k, damping c and rest length L. With $d = x_j − x_i$,
$l = |d|$ and $u = d/l$, the force on i is (Hooke's law plus damping along the spring)

$$f_i = k·(l − L)·u + c·((v_j − v_i)·u)·u,   f_j = −f_i,$$

plus gravity $m·g$ and air drag $−drag·m·v$ on every mass (drag per unit mass, so a finer mesh of the
same total mass falls the same way). Pinned masses never move. The energy
$E = Σ ½·m·|v|² + Σ ½·k·(l − L)² − Σ m·g·x$ is conserved without damping and drag.

Integrators, for $ẋ = v$, $v̇ = a(x, v) = f/m$ and a step h:

- ``"explicit-euler"`` (forward): $x' = x + h·v$, $v' = v + h·a(x, v)$; order 1, energy grows.
- ``"symplectic-euler"`` (semi-implicit): $v' = v + h·a(x, v)$, $x' = x + h·v'$; order 1, energy bounded.
- ``"verlet"`` (velocity Verlet): $x' = x + h·v + h²/2·a₀$, $v' = v + h/2·(a₀ + a(x', v + h·a₀))$; order 2.
- ``"rk4"``: classical Runge–Kutta on (x, v); order 4.
- ``"implicit-euler"`` (backward, one Newton step as in Baraff & Witkin 1998): solve
  $(M − h·∂f/∂v − h²·∂f/∂x)·Δv = h·(f₀ + h·∂f/∂x·v)$ by SciPy's sparse conjugate gradient, then
  $v' = v + Δv$, $x' = x + h·v'$; order 1, stable for any h (the stiffness term is kept positive
  definite: $max(0, 1 − L/l)$ in the transverse part, as in Choi & Ko 2002).

After a step, colliders (planes, spheres) push masses out and respond their velocities (``forces`` module).
A state that stops being finite raises ``SimulationError`` naming the step.

References
----------
[HB 15] "Physically Based Modeling"; [seed] "Physically based modeling"; D. Baraff and A. Witkin, "Large Steps
in Cloth Simulation", SIGGRAPH 1998, §§4–5; E. Hairer, C. Lubich, G. Wanner, "Geometric Numerical
Integration", §I.1 (symplectic Euler, Störmer–Verlet); X. Provot, "Deformation Constraints in a Mass-Spring
Model to Describe Rigid Cloth Behavior", 1995 (structural, shear and bend springs).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, as_faces, as_points, as_vector3, describe
from frustum.budgets import check_memory
from frustum.errors import SimulationError
from frustum.geometry import Mesh
from frustum.simulation._checks import as_nonnegative, as_time_step, per_item, state_not_finite
from frustum.simulation.forces import check_colliders

__all__ = ["INTEGRATORS", "MassSpringSystem", "cloth", "rope", "soft_body"]

_CG_TOLERANCE = 1e-8
"""Relative residual at which the implicit step's conjugate gradient stops (far below backward Euler's O(h) error)."""

INTEGRATORS = ("explicit-euler", "symplectic-euler", "verlet", "rk4", "implicit-euler")
"""Integrator names ``MassSpringSystem`` accepts."""


class MassSpringSystem:
    """Point masses joined by springs: ``MassSpringSystem(positions, masses, springs, stiffness=100.0)``.

    Parameters
    ----------
    positions : (N, 3) array_like
        Initial positions (float64).
    masses : float or (N,) array_like
        Masses, > 0.
    springs : (S, 2) array_like of int
        Index pairs (i, j), i != j, into `positions`.
    stiffness : float or (S,) array_like
        Spring constants k >= 0 (force per unit stretch).
    damping : float or (S,) array_like
        Spring damping c >= 0 (force per unit relative speed along the spring).
    rest_lengths : (S,) array_like, optional
        Rest lengths L >= 0; default the initial distances.
    pinned : sequence of int or (N,) bool array_like
        Masses held in place.
    gravity : (3,) array_like
        Acceleration of gravity (default none).
    integrator : str
        One of ``INTEGRATORS``.
    drag : float
        Air drag coefficient >= 0 (1/s): force $−drag·m·v$ on every mass.
    colliders : list
        ``PlaneCollider`` / ``SphereCollider`` obstacles.
    faces : (M, 3) array_like of int, optional
        Triangles over the masses: ``mesh`` then gives the state as a ``Mesh``.
    velocities : (N, 3) array_like, optional
        Initial velocities (default zero).

    Raises
    ------
    SimulationError
        Negative masses, stiffness or damping, springs naming missing points, unknown integrator; a step whose
        state is not finite (naming the step, suggesting a smaller dt or ``"implicit-euler"``).
    """

    def __init__(
        self,
        positions: ArrayLike,
        masses: Any,
        springs: ArrayLike,
        *,
        stiffness: Any,
        damping: Any = 0.0,
        rest_lengths: ArrayLike | None = None,
        pinned: Any = (),
        gravity: ArrayLike = (0.0, 0.0, 0.0),
        integrator: str = "symplectic-euler",
        drag: float = 0.0,
        colliders: Any = (),
        faces: ArrayLike | None = None,
        velocities: ArrayLike | None = None,
    ) -> None:
        where = "MassSpringSystem"
        x = as_points(positions, "positions", where=where, error=SimulationError)
        n = x.shape[0]
        if n == 0:
            raise SimulationError(f"{where}: positions is empty; give at least one point")
        self.masses = per_item(masses, n, "masses", where, positive=True)
        self.springs = _as_springs(springs, n, where)
        s = self.springs.shape[0]
        self.stiffness = per_item(stiffness, s, "stiffness", where)
        self.damping = per_item(damping, s, "damping", where)
        if rest_lengths is None:
            self.rest_lengths = np.linalg.norm(x[self.springs[:, 1]] - x[self.springs[:, 0]], axis=1)
        else:
            self.rest_lengths = per_item(rest_lengths, s, "rest_lengths", where)
        self.pinned = _as_pinned(pinned, n, where)
        self.gravity = as_vector3(gravity, "gravity", where=where, error=SimulationError)
        if not isinstance(integrator, str) or integrator not in INTEGRATORS:
            raise SimulationError(
                f"{where}: integrator = {describe(integrator)} is unknown; expected one of "
                + ", ".join(repr(name) for name in INTEGRATORS)
            )
        self.integrator = integrator
        self.drag = as_nonnegative(drag, "drag", where)
        self.colliders = check_colliders(colliders, where)
        self.faces = None if faces is None else as_faces(faces, n, "faces", where=where, error=SimulationError)
        check_memory(n * 200 + s * 400, where=where, cause=f"{n} masses and {s} springs", error=SimulationError)
        self._x = x.copy()
        if velocities is None:
            self._v = np.zeros_like(x)
        else:
            self._v = as_points(velocities, "velocities", where=where, error=SimulationError).copy()
            if self._v.shape != x.shape:
                raise SimulationError(f"{where}: velocities has shape {self._v.shape}; expected {x.shape}")
        self._v[self.pinned] = 0.0
        self._free = ~self.pinned
        self.time = 0.0
        self.steps = 0
        self.uvs: NDArray[np.float64] | None = None
        self._last_change: NDArray[np.float64] | None = None

    # --- state ---------------------------------------------------------------------------------------------

    @property
    def count(self) -> int:
        """Number of masses."""
        return self._x.shape[0]

    @property
    def positions(self) -> NDArray[np.float64]:
        """(N, 3) float64 positions (a read-only view, valid until the next step)."""
        view = self._x[:]
        view.flags.writeable = False
        return view

    @property
    def velocities(self) -> NDArray[np.float64]:
        """(N, 3) float64 velocities (read-only view)."""
        view = self._v[:]
        view.flags.writeable = False
        return view

    @property
    def mesh(self) -> Mesh:
        """The current state as a ``Mesh`` over `faces` (normals recomputed from the moved vertices)."""
        if self.faces is None:
            raise SimulationError(
                "MassSpringSystem.mesh: this system has no faces; give faces=... (cloth and soft_body have them)"
            )
        return Mesh(self._x, self.faces, uvs=self.uvs)

    def energy(self) -> float:
        """Total energy $Σ ½·m·|v|² + Σ ½·k·(l − L)² − Σ m·g·x$ (kinetic + spring + gravity)."""
        kinetic = 0.5 * float((self.masses * (self._v * self._v).sum(axis=1)).sum())
        lengths = np.linalg.norm(self._x[self.springs[:, 1]] - self._x[self.springs[:, 0]], axis=1)
        spring = 0.5 * float((self.stiffness * (lengths - self.rest_lengths) ** 2).sum())
        gravity = -float((self.masses * (self._x @ self.gravity)).sum())
        return kinetic + spring + gravity

    # --- forces --------------------------------------------------------------------------------------------

    def _spring_terms(self, x: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        """Per spring: the unit direction u (S, 3), the length l (S,), and d = x_j − x_i (S, 3)."""
        i, j = self.springs[:, 0], self.springs[:, 1]
        d = x[j] - x[i]
        length = np.sqrt((d * d).sum(axis=1))
        safe = np.where(length > 0.0, length, 1.0)
        return d / safe[:, None], length, d

    def forces(self, positions: NDArray, velocities: NDArray) -> NDArray[np.float64]:
        """(N, 3) total force on each mass (springs, spring damping, gravity, drag); zero on pinned masses."""
        i, j = self.springs[:, 0], self.springs[:, 1]
        u, length, _ = self._spring_terms(positions)
        relative = ((velocities[j] - velocities[i]) * u).sum(axis=1)
        magnitude = self.stiffness * (length - self.rest_lengths) + self.damping * relative
        along = magnitude[:, None] * u
        n = positions.shape[0]
        total = np.empty((n, 3))
        for c in range(3):
            total[:, c] = np.bincount(i, along[:, c], n) - np.bincount(j, along[:, c], n)
        total += self.masses[:, None] * self.gravity
        if self.drag:
            total -= (self.drag * self.masses)[:, None] * velocities
        total[self.pinned] = 0.0
        return total

    def _acceleration(self, x: NDArray, v: NDArray) -> NDArray[np.float64]:
        return self.forces(x, v) / self.masses[:, None]

    # --- integrators ---------------------------------------------------------------------------------------

    def step(self, dt: float) -> MassSpringSystem:
        """Advance by `dt` seconds with the chosen integrator, then resolve collisions; returns the system."""
        where = "MassSpringSystem.step"
        h = as_time_step(dt, where)
        x, v = self._x, self._v
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            if self.integrator == "explicit-euler":
                a = self._acceleration(x, v)
                x_new, v_new = x + h * v, v + h * a
            elif self.integrator == "symplectic-euler":
                v_new = v + h * self._acceleration(x, v)
                x_new = x + h * v_new
            elif self.integrator == "verlet":
                a0 = self._acceleration(x, v)
                x_new = x + h * v + (0.5 * h * h) * a0
                a1 = self._acceleration(x_new, v + h * a0)
                v_new = v + (0.5 * h) * (a0 + a1)
            elif self.integrator == "rk4":
                k1x, k1v = v, self._acceleration(x, v)
                k2x = v + 0.5 * h * k1v
                k2v = self._acceleration(x + 0.5 * h * k1x, k2x)
                k3x = v + 0.5 * h * k2v
                k3v = self._acceleration(x + 0.5 * h * k2x, k3x)
                k4x = v + h * k3v
                k4v = self._acceleration(x + h * k3x, k4x)
                x_new = x + (h / 6.0) * (k1x + 2.0 * k2x + 2.0 * k3x + k4x)
                v_new = v + (h / 6.0) * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
            else:
                v_new = v + self._implicit_velocity_change(h)
                x_new = x + h * v_new
        v_new[self.pinned] = 0.0
        x_new[self.pinned] = x[self.pinned]
        for collider in self.colliders:
            collider.resolve(x_new, v_new)
        self.steps += 1
        self.time += h
        if not (np.isfinite(x_new).all() and np.isfinite(v_new).all()):
            raise state_not_finite(where, self.steps, self.time, h, self.integrator)
        self._x, self._v = x_new, v_new
        return self

    def _implicit_velocity_change(self, h: float) -> NDArray[np.float64]:
        """Δv of backward Euler linearized once (Baraff–Witkin): $A·Δv = b$ by sparse conjugate gradient."""
        from scipy.sparse import coo_matrix, diags
        from scipy.sparse.linalg import cg

        x, v = self._x, self._v
        n = x.shape[0]
        i, j = self.springs[:, 0], self.springs[:, 1]
        u, length, _ = self._spring_terms(x)
        outer = u[:, :, None] * u[:, None, :]  # (S, 3, 3)
        ratio = np.where(length > 0.0, self.rest_lengths / np.where(length > 0.0, length, 1.0), 0.0)
        transverse = np.maximum(0.0, 1.0 - ratio)
        identity = np.eye(3)
        # ∂f_i/∂x_j = k·(u·uᵀ + max(0, 1 − L/l)·(I − u·uᵀ)), ∂f_i/∂v_j = c·u·uᵀ (the damping's ∂/∂x left out)
        stiffness_blocks = self.stiffness[:, None, None] * (outer + transverse[:, None, None] * (identity - outer))
        blocks = (h * h) * stiffness_blocks + h * self.damping[:, None, None] * outer
        relative = v[j] - v[i]
        k_v = np.einsum("sab,sb->sa", stiffness_blocks, relative)  # (∂f/∂x·v) for mass i; −that for j
        force = self.forces(x, v)
        rhs = force.copy()
        for c in range(3):
            rhs[:, c] += h * (np.bincount(i, k_v[:, c], n) - np.bincount(j, k_v[:, c], n))
        rhs *= h
        # A = M·(1 + h·drag) + Σ_s blocks on (ii, jj) and −blocks on (ij, ji)
        a_idx = np.arange(3)
        row_i = (3 * i[:, None, None] + a_idx[None, :, None]) * np.ones((1, 1, 3), dtype=np.int64)
        col_i = (3 * i[:, None, None] + a_idx[None, None, :]) * np.ones((1, 3, 1), dtype=np.int64)
        row_j = (3 * j[:, None, None] + a_idx[None, :, None]) * np.ones((1, 1, 3), dtype=np.int64)
        col_j = (3 * j[:, None, None] + a_idx[None, None, :]) * np.ones((1, 3, 1), dtype=np.int64)
        diagonal = np.repeat(self.masses * (1.0 + h * self.drag), 3)
        rows = np.concatenate([row_i.ravel(), row_j.ravel(), row_i.ravel(), row_j.ravel(), np.arange(3 * n)])
        cols = np.concatenate([col_i.ravel(), col_j.ravel(), col_j.ravel(), col_i.ravel(), np.arange(3 * n)])
        values = np.concatenate([blocks.ravel(), blocks.ravel(), -blocks.ravel(), -blocks.ravel(), diagonal])
        pinned_dof = np.repeat(self.pinned, 3)
        if pinned_dof.any():  # pinned rows and columns become identity with a zero right-hand side
            keep = ~(pinned_dof[rows] | pinned_dof[cols])
            rows, cols, values = rows[keep], cols[keep], values[keep]
            fixed = np.flatnonzero(pinned_dof)
            rows = np.concatenate([rows, fixed])
            cols = np.concatenate([cols, fixed])
            values = np.concatenate([values, np.ones(fixed.size)])
        matrix = coo_matrix((values, (rows, cols)), shape=(3 * n, 3 * n)).tocsr()
        b = rhs.ravel()
        b[pinned_dof] = 0.0
        if not np.isfinite(b).all() or not np.isfinite(matrix.data).all():
            return np.full((n, 3), np.nan)
        # Jacobi preconditioner, warm start from the last step's Δv; BLAS on one thread (the vectors are short:
        # OpenBLAS threads on a busy machine made each dot product 50x slower)
        jacobi = diags(1.0 / matrix.diagonal())
        start = self._last_change.ravel() if self._last_change is not None else None
        # absolute floor: a residual worth a velocity change of 1e-12·max(1, |v|) (a system coming to rest has b → 0)
        floor = 1e-12 * float(np.linalg.norm(self.masses)) * max(1.0, float(np.abs(v).max()))
        with _one_blas_thread():
            solution, info = cg(matrix, b, x0=start, rtol=_CG_TOLERANCE, atol=floor, maxiter=max(100, 10 * 3 * n),
                                M=jacobi)  # fmt: skip
        if info != 0:
            raise SimulationError(
                f"MassSpringSystem.step: the implicit solve (conjugate gradient) did not converge at step "
                f"{self.steps + 1} with dt = {h!r}; give a smaller dt"
            )
        self._last_change = solution.reshape(n, 3)
        return self._last_change

    def __repr__(self) -> str:
        return (f"MassSpringSystem({self.count} masses, {self.springs.shape[0]} springs, "
                f"integrator={self.integrator!r}, t={self.time:g} s)")  # fmt: skip


def _one_blas_thread() -> Any:
    """A context limiting BLAS to one thread (``threadpoolctl``), or doing nothing where it is not installed."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        import contextlib

        return contextlib.nullcontext()
    return threadpool_limits(limits=1, user_api="blas")


def _as_springs(value: ArrayLike, count: int, where: str) -> NDArray[np.int64]:
    """(S, 2) int64 index pairs into `count` points, i != j; (0, 2) is valid."""
    try:
        springs = np.asarray(value)
    except ValueError:
        raise SimulationError(f"{where}: springs = {describe(value)} is not an array; give (S, 2) indices") from None
    if springs.size == 0:
        return np.empty((0, 2), dtype=np.int64)
    if springs.ndim != 2 or springs.shape[1] != 2:
        raise SimulationError(f"{where}: springs has shape {springs.shape}; expected (S, 2) index pairs (i, j)")
    if springs.dtype == np.bool_ or not np.issubdtype(springs.dtype, np.integer):
        raise SimulationError(f"{where}: springs has dtype {springs.dtype}; expected integer indices")
    outside = np.flatnonzero(((springs < 0) | (springs >= count)).any(axis=1))
    if outside.size:
        k = int(outside[0])
        raise SimulationError(
            f"{where}: springs[{k}] = {springs[k].tolist()} names a missing point; indices must lie in "
            f"[0, {count - 1}] for {count} points"
        )
    same = np.flatnonzero(springs[:, 0] == springs[:, 1])
    if same.size:
        k = int(same[0])
        raise SimulationError(f"{where}: springs[{k}] = {springs[k].tolist()} joins a point to itself; need i != j")
    return np.ascontiguousarray(springs, dtype=np.int64)


def _as_pinned(value: Any, count: int, where: str) -> NDArray[np.bool_]:
    """(count,) bool mask from indices or a mask."""
    array = np.asarray(value)
    if array.dtype == np.bool_:
        if array.shape != (count,):
            raise SimulationError(f"{where}: pinned mask has shape {array.shape}; expected ({count},)")
        return array.copy()
    if array.size == 0:
        return np.zeros(count, dtype=bool)
    if array.ndim != 1 or not np.issubdtype(array.dtype, np.integer):
        raise SimulationError(f"{where}: pinned = {describe(value)} is not a list of point indices")
    bad = np.flatnonzero((array < 0) | (array >= count))
    if bad.size:
        raise SimulationError(
            f"{where}: pinned[{int(bad[0])}] = {int(array[bad[0]])} names a missing point; indices must lie in "
            f"[0, {count - 1}]"
        )
    mask = np.zeros(count, dtype=bool)
    mask[array] = True
    return mask


def cloth(
    width: float,
    height: float,
    nx: int,
    ny: int,
    *,
    center: ArrayLike = (0.0, 0.0, 0.0),
    plane: str = "xz",
    mass: float = 1.0,
    stiffness: float = 500.0,
    shear_stiffness: float | None = None,
    bend_stiffness: float | None = None,
    damping: float = 0.02,
    pinned: Any = (),
    gravity: ArrayLike = (0.0, -9.81, 0.0),
    integrator: str = "implicit-euler",
    drag: float = 0.0,
    colliders: Any = (),
) -> MassSpringSystem:
    """A rectangular cloth of `nx` × `ny` masses with structural, shear and bend springs (Provot 1995).

    Mass (r, c) (row r < ny, column c < nx) is number $r·nx + c$, at $center + (−width/2 + width·c/(nx − 1))·e₁
    + (−height/2 + height·r/(ny − 1))·e₂$ with (e₁, e₂) = (x, z) for ``plane="xz"`` (horizontal, faces toward +y)
    or (x, y) for ``plane="xy"`` (hanging, row 0 at the bottom, faces toward +z). Springs: structural between
    4-neighbours (`stiffness`), shear along both diagonals (`shear_stiffness`, default `stiffness`), bend between
    masses two apart (`bend_stiffness`, default `stiffness`/10). `mass` is the total, shared equally. The faces
    split every grid cell in two, counter-clockwise from the face side; uvs span [0, 1]². ``pinned``,
    ``gravity`` (default Earth's, y up), ``integrator`` (default ``"implicit-euler"``, stable at frame-rate steps),
    ``drag`` and ``colliders`` go to ``MassSpringSystem``.
    """
    where = "cloth"
    from frustum._arrays import as_scalar

    w = as_scalar(width, "width", where=where, error=SimulationError)
    d = as_scalar(height, "height", where=where, error=SimulationError)
    if not (w > 0.0 and d > 0.0):
        raise SimulationError(f"{where}: width, height = {w!r}, {d!r} must be > 0")
    nx = as_count(nx, "nx", 2, where=where, error=SimulationError)
    ny = as_count(ny, "ny", 2, where=where, error=SimulationError)
    check_memory(nx * ny * 600.0, where=where, cause=f"nx = {nx}, ny = {ny}", error=SimulationError)
    origin = as_vector3(center, "center", where=where, error=SimulationError)
    if plane not in ("xz", "xy"):
        raise SimulationError(f"{where}: plane = {describe(plane)} is unknown; expected 'xz' or 'xy'")
    total = as_nonnegative(mass, "mass", where)
    k = as_nonnegative(stiffness, "stiffness", where)
    k_shear = k if shear_stiffness is None else as_nonnegative(shear_stiffness, "shear_stiffness", where)
    k_bend = k / 10.0 if bend_stiffness is None else as_nonnegative(bend_stiffness, "bend_stiffness", where)
    c, r = np.meshgrid(np.arange(nx), np.arange(ny))
    s = -w / 2 + w * c.ravel() / (nx - 1)
    t = -d / 2 + d * r.ravel() / (ny - 1)
    zero = np.zeros_like(s)
    points = np.stack([s, zero, t] if plane == "xz" else [s, t, zero], axis=1) + origin
    index = np.arange(nx * ny).reshape(ny, nx)
    pairs = [
        (np.stack([index[:, :-1].ravel(), index[:, 1:].ravel()], 1), k),
        (np.stack([index[:-1, :].ravel(), index[1:, :].ravel()], 1), k),
        (np.stack([index[:-1, :-1].ravel(), index[1:, 1:].ravel()], 1), k_shear),
        (np.stack([index[:-1, 1:].ravel(), index[1:, :-1].ravel()], 1), k_shear),
        (np.stack([index[:, :-2].ravel(), index[:, 2:].ravel()], 1), k_bend),
        (np.stack([index[:-2, :].ravel(), index[2:, :].ravel()], 1), k_bend),
    ]
    springs = np.concatenate([p for p, _ in pairs])
    constants = np.concatenate([np.full(p.shape[0], value) for p, value in pairs])
    a, b = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    cc, dd = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    if plane == "xz":  # counter-clockwise seen from +y: (a, c, b), (b, c, d)
        faces = np.concatenate([np.stack([a, cc, b], 1), np.stack([b, cc, dd], 1)])
    else:  # seen from +z: (a, b, c), (b, d, c)
        faces = np.concatenate([np.stack([a, b, cc], 1), np.stack([b, dd, cc], 1)])
    if total <= 0.0:
        raise SimulationError(f"{where}: mass = {total!r} is not positive; give the cloth's total mass > 0")
    system = MassSpringSystem(points, total / (nx * ny), springs, stiffness=constants, damping=damping,
                              faces=faces, pinned=pinned, gravity=gravity, integrator=integrator, drag=drag,
                              colliders=colliders)  # fmt: skip
    system.uvs = np.stack([c.ravel() / (nx - 1), r.ravel() / (ny - 1)], axis=1)
    return system


def rope(
    start: ArrayLike, end: ArrayLike, count: int, *, mass: float = 1.0, stiffness: float = 500.0,
    bend_stiffness: float = 0.0, damping: float = 0.02, **options: Any,
) -> MassSpringSystem:  # fmt: skip
    """A rope of `count` masses evenly from `start` to `end`: springs between neighbours (`stiffness`) and, with
    `bend_stiffness` > 0, between masses two apart. `mass` is the total; other keywords go to ``MassSpringSystem``
    (``pinned=[0]`` hangs it from `start`)."""
    where = "rope"
    a = as_vector3(start, "start", where=where, error=SimulationError)
    b = as_vector3(end, "end", where=where, error=SimulationError)
    n = as_count(count, "count", 2, where=where, error=SimulationError)
    total = as_nonnegative(mass, "mass", where)
    if total <= 0.0:
        raise SimulationError(f"{where}: mass = {total!r} is not positive; give the rope's total mass > 0")
    points = a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)
    index = np.arange(n)
    springs = [np.stack([index[:-1], index[1:]], 1)]
    constants = [np.full(n - 1, as_nonnegative(stiffness, "stiffness", where))]
    if as_nonnegative(bend_stiffness, "bend_stiffness", where) > 0.0 and n > 2:
        springs.append(np.stack([index[:-2], index[2:]], 1))
        constants.append(np.full(n - 2, float(bend_stiffness)))
    return MassSpringSystem(points, total / n, np.concatenate(springs), stiffness=np.concatenate(constants),
                            damping=damping, **options)  # fmt: skip


def soft_body(
    mesh: Mesh, *, mass: float = 1.0, stiffness: float = 500.0, bend_stiffness: float | None = None,
    damping: float = 0.02, **options: Any,
) -> MassSpringSystem:  # fmt: skip
    """A soft body from a closed mesh: a mass at every vertex, a spring along every edge (`stiffness`) and one
    across every pair of adjacent triangles, joining the two vertices opposite their shared edge
    (`bend_stiffness`, default `stiffness`), which resists folding and keeps the volume from collapsing.
    `mass` is the total; the faces are the mesh's, so ``system.mesh`` renders it."""
    where = "soft_body"
    if not isinstance(mesh, Mesh) or mesh.face_count == 0:
        raise SimulationError(f"{where}: mesh = {describe(mesh)} is not a Mesh with faces")
    total = as_nonnegative(mass, "mass", where)
    if total <= 0.0:
        raise SimulationError(f"{where}: mass = {total!r} is not positive; give the body's total mass > 0")
    k = as_nonnegative(stiffness, "stiffness", where)
    k_bend = k if bend_stiffness is None else as_nonnegative(bend_stiffness, "bend_stiffness", where)
    welded = mesh.welded()
    faces = welded.faces
    edges = welded.edges
    # opposite vertices across each interior edge: group the three directed edges of every face by their edge
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    opposite = np.concatenate([faces[:, 2], faces[:, 0], faces[:, 1]])
    keys = np.sort(directed, axis=1)
    order = np.lexsort((keys[:, 1], keys[:, 0]))
    keys, opposite = keys[order], opposite[order]
    same = (keys[1:] == keys[:-1]).all(axis=1)
    bend = np.stack([opposite[:-1][same], opposite[1:][same]], 1)
    bend = bend[bend[:, 0] != bend[:, 1]]
    springs = np.concatenate([edges, bend])
    constants = np.concatenate([np.full(edges.shape[0], k), np.full(bend.shape[0], k_bend)])
    return MassSpringSystem(welded.vertices, total / welded.vertex_count, springs, stiffness=constants,
                            damping=damping, faces=faces, **options)  # fmt: skip
