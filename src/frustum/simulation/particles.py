"""Reeves' particle systems: particles born from an emitter, moved by forces, bounced by colliders, dying of age.

One step of ``ParticleSystem.step(dt)``, in order (every stage a whole-array numpy operation, no per-particle
Python loop):

1. **Move** (semi-implicit, "symplectic" Euler): $a = Σ forces(x, v)$, $v ← v + a·dt$, $x ← x + v·dt$,
   ``age ← age + dt``; the previous positions are kept (streaks draw from them). Under constant gravity g this
   gives $x_n = x₀ + v₀·t_n + g·t_n²/2 + g·dt·t_n/2$: the parabola plus a known first-order term.
2. **Collide**: each collider moves particles inside it back out and reflects their velocities
   (``frustum.simulation.forces``).
3. **Die**: a particle whose $age >= lifetime$ (or that left the `region` box) is removed; the survivors keep
   their order.
4. **Generate** (Reeves §2.1): $n = ⌊(rate + rate_variance·U(−1, 1))·dt + u⌋$ new particles with u uniform in
   [0, 1) (stochastic rounding: $E[n] = rate·dt$ exactly), placed by the emitter with age 0 and a lifetime
   $lifetime + lifetime_variance·U(−1, 1)$. Their $Var[n] = (rate_variance·dt)²/3 + E[f·(1 − f)]$, f the
   fractional part of the real count (1/6 when the count spreads evenly over whole numbers).

Attributes over life: `size`, `color` and `opacity` are constants or ramps over the normalized age
``age/lifetime`` (``[(0, (1, 1, 0.2)), (0.5, (1, 0.3, 0)), (1, (0.2, 0, 0))]``), evaluated when read
(``sizes``, ``colors``, ``opacities``).

Determinism: one ``numpy.random.Generator`` (PCG64) seeded by `seed`, drawn in a fixed order; numpy runs these
operations on one thread, so the same seed gives the same bytes on any machine thread count.

References
----------
W. T. Reeves, "Particle Systems — a Technique for Modeling a Class of Fuzzy Objects", SIGGRAPH 1983, §2
(generation $NParts = MeanParts + Rand()·VarParts$, attributes, dynamics, extinction); [HB 15] "Particle
Systems"; [seed] "Particle systems".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_count, as_vector3, describe
from frustum.budgets import check_memory
from frustum.errors import SimulationError
from frustum.simulation._checks import (
    as_nonnegative,
    as_positive,
    as_ramp,
    as_time_step,
    evaluate_ramp,
    state_not_finite,
)
from frustum.simulation.emitters import Emitter, check_emitter
from frustum.simulation.forces import Drag, Gravity, PlaneCollider, Wind, check_colliders, check_forces

__all__ = ["ParticleSystem"]

FUSED_STEP_MINIMUM = 50_000
"""From this many particles on, a step under gravity, drag, wind and planes only runs as one compiled pass
(``raster.particle_step``); smaller systems stay whole-array numpy (no compilation for a few particles)."""
_BYTES_PER_PARTICLE = 4 * 3 * 8 + 2 * 8
"""Positions, velocities, previous positions, a work array (3 float64 each), age and lifetime."""


class ParticleSystem:
    """A Reeves particle system: ``ParticleSystem(emitter=PointEmitter(p, direction=d, spread=s, speed=v),
    rate=500, lifetime=2.0, forces=[Gravity()], seed=1)``; ``system.step(dt)``.

    Parameters
    ----------
    emitter : Emitter
        ``PointEmitter``, ``LineEmitter``, ``DiskEmitter``, ``SphereEmitter`` or ``MeshEmitter``.
    rate : float
        Mean number of new particles per second of simulated time, >= 0.
    lifetime : float
        Mean lifetime in seconds, > 0.
    forces : list of Force
        ``Gravity``, ``Drag``, ``Wind``, ``Vortex``, ``Attractor`` (accelerations; particles have unit mass).
    seed : int
        Seed of the random generator (>= 0).
    rate_variance : float
        Reeves' ± variance of the rate: the rate of one step is $rate + rate_variance·U(−1, 1)$ (clamped at 0).
    lifetime_variance : float
        A lifetime is $lifetime + lifetime_variance·U(−1, 1)$; must stay below `lifetime`.
    colliders : list
        ``PlaneCollider`` and ``SphereCollider`` obstacles.
    region : ((3,), (3,)) or None
        An axis-aligned box (min, max): particles outside it die.
    size : float or ramp
        Sprite radius (world units) over life.
    color : (3,) or ramp
        RGB in [0, 1] over life.
    opacity : float or ramp
        Opacity in [0, 1] over life.

    Raises
    ------
    SimulationError
        Bad arguments (negative rate or lifetime, unknown emitter, force or collider, bad ramps), or a step
        whose state is no longer finite.
    """

    def __init__(
        self,
        emitter: Emitter,
        rate: float,
        lifetime: float,
        forces: Any = (),
        seed: int = 0,
        *,
        rate_variance: float = 0.0,
        lifetime_variance: float = 0.0,
        colliders: Any = (),
        region: tuple[ArrayLike, ArrayLike] | None = None,
        size: Any = 0.05,
        color: Any = (1.0, 1.0, 1.0),
        opacity: Any = 1.0,
    ) -> None:
        where = "ParticleSystem"
        self.emitter = check_emitter(emitter, where)
        self.rate = as_nonnegative(rate, "rate", where)
        self.rate_variance = as_nonnegative(rate_variance, "rate_variance", where)
        self.lifetime = as_positive(lifetime, "lifetime", where)
        self.lifetime_variance = as_nonnegative(lifetime_variance, "lifetime_variance", where)
        if self.lifetime_variance >= self.lifetime:
            raise SimulationError(
                f"{where}: lifetime_variance = {self.lifetime_variance!r} is not below lifetime = "
                f"{self.lifetime!r}; every lifetime must stay positive"
            )
        self.forces = check_forces(forces, where)
        self.colliders = check_colliders(colliders, where)
        if region is None:
            self.region = None
        else:
            if not isinstance(region, list | tuple) or len(region) != 2:
                raise SimulationError(f"{where}: region = {describe(region)} is not (min, max); give two points")
            low = as_vector3(region[0], "region min", where=where, error=SimulationError)
            high = as_vector3(region[1], "region max", where=where, error=SimulationError)
            if not (low < high).all():
                raise SimulationError(f"{where}: region = ({describe(low)}, {describe(high)}) is empty; need min < max")
            self.region = (low, high)
        self.seed = as_count(seed, "seed", 0, where=where, error=SimulationError)
        self.size = as_ramp(size, 1, "size", where)
        self.color = as_ramp(color, 3, "color", where, high=1.0)
        self.opacity = as_ramp(opacity, 1, "opacity", where, high=1.0)
        self._rng = np.random.default_rng(self.seed)
        self.time = 0.0
        self.steps = 0
        self._count = 0
        self._allocate(0)

    # --- storage -------------------------------------------------------------------------------------------

    def _allocate(self, capacity: int) -> None:
        self._x = np.empty((capacity, 3))
        self._v = np.empty((capacity, 3))
        self._previous = np.empty((capacity, 3))
        self._age = np.empty(capacity)
        self._life = np.empty(capacity)

    def _reserve(self, total: int) -> None:
        """Grow the arrays (doubling) so that `total` particles fit; checks the memory budget first."""
        if total <= self._x.shape[0]:
            return
        capacity = max(total, 2 * self._x.shape[0], 1024)
        check_memory(capacity * _BYTES_PER_PARTICLE, where="ParticleSystem.step", cause=f"{total} particles",
                     error=SimulationError)  # fmt: skip
        n = self._count
        old = (self._x, self._v, self._previous, self._age, self._life)
        self._allocate(capacity)
        for new, array in zip((self._x, self._v, self._previous, self._age, self._life), old, strict=True):
            new[:n] = array[:n]

    # --- state ---------------------------------------------------------------------------------------------

    @property
    def count(self) -> int:
        """Number of living particles."""
        return self._count

    def _view(self, array: np.ndarray) -> np.ndarray:
        view = array[: self._count]
        view.flags.writeable = False
        return view

    @property
    def positions(self) -> NDArray[np.float64]:
        """(count, 3) float64 positions (a read-only view, valid until the next step)."""
        return self._view(self._x)

    @property
    def velocities(self) -> NDArray[np.float64]:
        """(count, 3) float64 velocities (units per second; read-only view)."""
        return self._view(self._v)

    @property
    def previous_positions(self) -> NDArray[np.float64]:
        """(count, 3) positions at the start of the last step (a new particle's own position); streaks end here."""
        return self._view(self._previous)

    @property
    def ages(self) -> NDArray[np.float64]:
        """(count,) seconds since each particle was born."""
        return self._view(self._age)

    @property
    def lifetimes(self) -> NDArray[np.float64]:
        """(count,) each particle's lifetime in seconds."""
        return self._view(self._life)

    def _normalized_age(self) -> NDArray[np.float64]:
        return np.minimum(self._age[: self._count] / self._life[: self._count], 1.0)

    @property
    def sizes(self) -> NDArray[np.float64]:
        """(count,) sprite radii (world units) from the `size` ramp at each particle's age/lifetime."""
        return evaluate_ramp(self.size, self._normalized_age())[:, 0]

    @property
    def colors(self) -> NDArray[np.float64]:
        """(count, 3) RGB in [0, 1] from the `color` ramp."""
        return evaluate_ramp(self.color, self._normalized_age())

    @property
    def opacities(self) -> NDArray[np.float64]:
        """(count,) opacity in [0, 1] from the `opacity` ramp."""
        return evaluate_ramp(self.opacity, self._normalized_age())[:, 0]

    # --- dynamics ------------------------------------------------------------------------------------------

    def emit(self, count: int) -> None:
        """Add `count` particles now (a burst), at age 0, placed by the emitter."""
        count = as_count(count, "count", 0, where="ParticleSystem.emit", error=SimulationError)
        self._emit(count)

    def _emit(self, count: int) -> None:
        if count == 0:
            return
        self._reserve(self._count + count)
        positions, velocities = self.emitter.sample(self._rng, count)
        lifetimes = self.lifetime + self.lifetime_variance * (2.0 * self._rng.random(count) - 1.0)
        s = slice(self._count, self._count + count)
        self._x[s] = positions
        self._previous[s] = positions
        self._v[s] = velocities
        self._age[s] = 0.0
        self._life[s] = lifetimes
        self._count += count

    def _generated(self, dt: float) -> int:
        """Reeves' count for one step: ⌊(rate + rate_variance·U(−1, 1))·dt + u⌋, u in [0, 1)."""
        spread = 2.0 * self._rng.random() - 1.0
        rounding = self._rng.random()
        mean = max(0.0, (self.rate + self.rate_variance * spread) * dt)
        count = math.floor(mean + rounding)
        check_memory((self._count + count) * _BYTES_PER_PARTICLE, where="ParticleSystem.step",
                     cause=f"rate = {self.rate!r} with dt = {dt!r} ({count} new particles)",
                     error=SimulationError)  # fmt: skip
        return count

    def _linear_forces(self) -> tuple[np.ndarray, float, np.ndarray] | None:
        """(c, k, planes) when every force is gravity, drag or wind ($a = c − k·v$) and every collider a plane:
        the case ``raster.particle_step.step_linear`` runs in one fused pass. None otherwise."""
        if not all(type(f) in (Gravity, Drag, Wind) for f in self.forces):
            return None
        if not all(type(c) is PlaneCollider for c in self.colliders):
            return None
        constant, damping = np.zeros(3), 0.0
        for force in self.forces:
            if type(force) is Gravity:
                constant += force.vector
            elif type(force) is Drag:
                damping += force.coefficient
            else:
                constant += force.coefficient * force.velocity
                damping += force.coefficient
        planes = np.array([[*c.point, *c.normal, c.restitution, c.friction] for c in self.colliders]).reshape(-1, 8)
        return constant, damping, planes

    def step(self, dt: float) -> ParticleSystem:
        """Advance the system by `dt` seconds (move, collide, die, generate; see the module docstring); returns it."""
        where = "ParticleSystem.step"
        dt = as_time_step(dt, where)
        n = self._count
        x, v = self._x[:n], self._v[:n]
        linear = self._linear_forces() if n >= FUSED_STEP_MINIMUM else None
        if linear is not None:  # one compiled pass (same formulas, to round-off): 10x fewer passes over memory
            from frustum.raster.particle_step import step_linear

            constant, damping, planes = linear
            with np.errstate(over="ignore", invalid="ignore"):
                bad = step_linear(x, v, self._previous[:n], self._age[:n], constant, damping, planes, dt)
            self._finish_step(dt, where, finite=bad == 0)
            return self
        with np.errstate(over="ignore", invalid="ignore"):
            constant = np.zeros(3)
            varying = None
            for force in self.forces:
                a = force.acceleration(x, v)
                if a.ndim == 1:
                    constant += a
                elif varying is None:
                    varying = a
                else:
                    varying += a
            self._previous[:n] = x
            if varying is not None:
                varying *= dt
                v += varying
            if constant.any():
                v += constant * dt
            x += v * dt
            self._age[:n] += dt
        for collider in self.colliders:
            collider.resolve(x, v)
        self._finish_step(dt, where, finite=not n or bool(np.isfinite(x).all() and np.isfinite(v).all()))
        return self

    def _finish_step(self, dt: float, where: str, finite: bool) -> None:
        """Count the step, refuse a blow-up, remove the dead, generate the newborn."""
        n = self._count
        x = self._x[:n]
        self.steps += 1
        self.time += dt
        if not finite:
            raise state_not_finite(where, self.steps, self.time, dt, "symplectic-euler")
        alive = self._age[:n] < self._life[:n]
        if self.region is not None:
            low, high = self.region
            alive &= ((x >= low) & (x <= high)).all(axis=1)
        if not alive.all():
            keep = np.flatnonzero(alive)
            m = keep.size
            for array in (self._x, self._v, self._previous, self._age, self._life):
                array[:m] = array[keep]
            self._count = m
        self._emit(self._generated(dt))

    def __repr__(self) -> str:
        return (f"ParticleSystem({self.emitter!r}, rate={self.rate!r}, lifetime={self.lifetime!r}, "
                f"{self._count} particles, t={self.time:g} s)")  # fmt: skip
