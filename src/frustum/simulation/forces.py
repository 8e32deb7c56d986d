"""Forces on particles (per unit mass, i.e. accelerations) and collision responses with planes and spheres.

A force maps the state ``(x, v)`` of N particles to accelerations: either one (3,) vector shared by all
(gravity) or an (N, 3) array. A collider moves particles that ended a step inside it back out along its normal
and reflects the normal part of their velocity: with $d < 0$ the signed distance and ``n`` the unit normal,
$x' = x − (1 + e)·d·n$ (the mirror image scaled by the restitution e, so $d' = −e·d ≥ 0$), and
$v' = (1 − μ)·v_t − e·v_n$ when the particle moves into the surface ($v·n < 0$), with $v_n = (v·n)·n$,
$v_t = v − v_n$, e the restitution and μ the friction (a fraction of the tangential velocity removed per
contact). With e = 1 and μ = 0 the speed is kept.

References
----------
[HB 15] "Physically Based Modeling"; Reeves 1983 §2.3 (particle dynamics); A. Witkin, "Physically Based
Modeling: Particle System Dynamics", SIGGRAPH course notes 2001, §§3–5 (forces, collisions).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_direction, as_scalar, as_vector3, describe
from frustum.errors import SimulationError
from frustum.simulation._checks import as_nonnegative, as_positive

__all__ = [
    "Attractor",
    "Drag",
    "Force",
    "Gravity",
    "MeshCollider",
    "PlaneCollider",
    "SphereCollider",
    "Vortex",
    "Wind",
    "check_colliders",
    "check_forces",
]


class Force:
    """Base class: ``acceleration(positions, velocities)`` → (3,) or (N, 3) float64."""

    def acceleration(self, positions: NDArray[np.float64], velocities: NDArray[np.float64]) -> NDArray[np.float64]:
        raise NotImplementedError


class Gravity(Force):
    """A constant acceleration ``g`` (default (0, −9.81, 0) m/s², y up)."""

    def __init__(self, acceleration: ArrayLike = (0.0, -9.81, 0.0)) -> None:
        self.vector = as_vector3(acceleration, "acceleration", where="Gravity", error=SimulationError)

    def acceleration(self, positions, velocities):
        return self.vector

    def __repr__(self) -> str:
        return f"Gravity({describe(self.vector)})"


class Drag(Force):
    """Linear (Stokes) drag $a = −k·v$ with `coefficient` k >= 0 (1/s)."""

    def __init__(self, coefficient: float) -> None:
        self.coefficient = as_nonnegative(coefficient, "coefficient", "Drag")

    def acceleration(self, positions, velocities):
        return -self.coefficient * velocities


class Wind(Force):
    """Drag toward the air's `velocity`: $a = k·(w − v)$ with `coefficient` k >= 0 (1/s)."""

    def __init__(self, velocity: ArrayLike, coefficient: float = 1.0) -> None:
        self.velocity = as_vector3(velocity, "velocity", where="Wind", error=SimulationError)
        self.coefficient = as_nonnegative(coefficient, "coefficient", "Wind")

    def acceleration(self, positions, velocities):
        return self.coefficient * (self.velocity - velocities)


class Vortex(Force):
    """A swirl about the line through `center` along `axis`: $a = s·(â × r⊥)/(|r⊥|² + c²)$, r⊥ the offset
    from the axis, `strength` s (counter-clockwise about â for s > 0) and `core` radius c > 0 (no singularity)."""

    def __init__(self, center: ArrayLike, axis: ArrayLike = (0.0, 1.0, 0.0), strength: float = 1.0,
                 core: float = 0.1) -> None:  # fmt: skip
        self.center = as_vector3(center, "center", where="Vortex", error=SimulationError)
        self.axis = as_direction(axis, "axis", where="Vortex", error=SimulationError)
        self.strength = as_scalar(strength, "strength", where="Vortex", error=SimulationError)
        self.core = as_positive(core, "core", "Vortex")

    def acceleration(self, positions, velocities):
        offset = positions - self.center
        radial = offset - (offset @ self.axis)[:, None] * self.axis
        squared = (radial * radial).sum(axis=1) + self.core**2
        return self.strength * np.cross(self.axis, radial) / squared[:, None]


class Attractor(Force):
    """A point attractor (negative `strength`: repeller): $a = s·(p − x)/(|p − x|² + ε²)^{3/2}$, an inverse
    square law softened by `softening` ε > 0."""

    def __init__(self, position: ArrayLike, strength: float = 1.0, softening: float = 0.1) -> None:
        self.position = as_vector3(position, "position", where="Attractor", error=SimulationError)
        self.strength = as_scalar(strength, "strength", where="Attractor", error=SimulationError)
        self.softening = as_positive(softening, "softening", "Attractor")

    def acceleration(self, positions, velocities):
        offset = self.position - positions
        squared = (offset * offset).sum(axis=1) + self.softening**2
        return self.strength * offset / (squared * np.sqrt(squared))[:, None]


class _Collider:
    def __init__(self, restitution: float, friction: float, where: str) -> None:
        self.restitution = as_nonnegative(restitution, "restitution", where)
        self.friction = as_nonnegative(friction, "friction", where)
        if self.restitution > 1.0 or self.friction > 1.0:
            name, value = ("restitution", self.restitution) if self.restitution > 1.0 else ("friction", self.friction)
            raise SimulationError(f"{where}: {name} = {value!r} is above 1; give a number in [0, 1]")

    def _signed_distance(self, positions: NDArray[np.float64]) -> NDArray[np.float64]:
        raise NotImplementedError

    def _normals(self, positions: NDArray[np.float64]) -> NDArray[np.float64]:
        raise NotImplementedError

    def resolve(self, positions: NDArray[np.float64], velocities: NDArray[np.float64]) -> None:
        """Move particles inside the collider out and respond their velocities, in place."""
        inside, depth = self._inside(positions)
        if inside.size == 0:
            return
        normals = self._normals(positions[inside])
        positions[inside] -= ((1.0 + self.restitution) * depth)[:, None] * normals
        self._respond(velocities, inside, normals)

    def _inside(self, positions: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """The indices of the particles inside the collider and their signed distances (< 0)."""
        if positions.shape[0] == 0:
            return np.empty(0, dtype=np.int64), np.empty(0)
        distance = self._signed_distance(positions)
        inside = np.flatnonzero(distance < 0.0)
        return inside, distance[inside]

    def _respond(
        self, velocities: NDArray[np.float64], inside: NDArray[np.int64], normals: NDArray[np.float64]
    ) -> None:
        """$v ← (1 − μ)·v_t − e·v_n$ for the particles `inside` that approach the surface (module docstring)."""
        e, mu = self.restitution, self.friction
        v = velocities[inside]
        normal_speed = (v * normals).sum(axis=1)
        normal_part = normal_speed[:, None] * normals
        response = (1.0 - mu) * (v - normal_part) - e * normal_part
        velocities[inside] = np.where((normal_speed < 0.0)[:, None], response, v)


class PlaneCollider(_Collider):
    """The half-space behind the plane through `point` with unit `normal` (particles stay on the normal's side).

    Signed distance $d = (x − p)·n$. See the module docstring for the response (`restitution` e and
    `friction` μ, both in [0, 1]).
    """

    def __init__(self, point: ArrayLike = (0.0, 0.0, 0.0), normal: ArrayLike = (0.0, 1.0, 0.0),
                 restitution: float = 0.5, friction: float = 0.0) -> None:  # fmt: skip
        super().__init__(restitution, friction, "PlaneCollider")
        self.point = as_vector3(point, "point", where="PlaneCollider", error=SimulationError)
        self.normal = as_direction(normal, "normal", where="PlaneCollider", error=SimulationError)

    def _signed_distance(self, positions):
        return (positions - self.point) @ self.normal

    def _normals(self, positions):
        return np.broadcast_to(self.normal, positions.shape)


class SphereCollider(_Collider):
    """A solid ball of `radius` around `center`: signed distance $d = |x − c| − r$, normal $(x − c)/|x − c|$
    (moving out along it puts a particle at $r + e·|d|$, outside)."""

    def __init__(self, center: ArrayLike, radius: float, restitution: float = 0.5, friction: float = 0.0) -> None:
        super().__init__(restitution, friction, "SphereCollider")
        self.center = as_vector3(center, "center", where="SphereCollider", error=SimulationError)
        self.radius = as_positive(radius, "radius", "SphereCollider")

    def _signed_distance(self, positions):
        return np.linalg.norm(positions - self.center, axis=1) - self.radius

    def _normals(self, positions):
        offset = positions - self.center
        length = np.linalg.norm(offset, axis=1)
        at_center = length == 0.0
        offset[at_center] = (0.0, 1.0, 0.0)
        length[at_center] = 1.0
        return offset / length[:, None]


class MeshCollider(_Collider):
    """A closed (watertight) mesh as a solid obstacle: particles that end a step inside it are moved to the
    nearest surface point ``c`` plus $e·|d|$ along its outward normal $n = (c − x)/|c − x|$ (``d`` the
    distance to c), and their velocities respond as for a plane with that normal.

    Inside tests and closest points come from trimesh (ray parity and an R-tree of the triangles), only for the
    particles inside the mesh's bounding box: exact, but far slower per particle than planes and spheres.
    """

    def __init__(self, mesh: Any, restitution: float = 0.5, friction: float = 0.0) -> None:
        super().__init__(restitution, friction, "MeshCollider")
        from frustum.geometry import Mesh

        if not isinstance(mesh, Mesh) or mesh.face_count == 0 or not mesh.welded().is_watertight:
            raise SimulationError(
                f"MeshCollider: mesh = {describe(mesh)} is not a closed Mesh; give a watertight mesh (a solid)"
            )
        self.mesh = mesh
        self._low, self._high = mesh.bounds[0], mesh.bounds[1]
        self._solid = None
        self._closest: NDArray[np.float64] | None = None

    def _trimesh(self) -> Any:
        if self._solid is None:
            import trimesh

            self._solid = trimesh.Trimesh(self.mesh.vertices, self.mesh.faces, process=False)
        return self._solid

    def _signed_distance(self, positions):
        distance = np.ones(positions.shape[0])
        near = np.flatnonzero(((positions >= self._low) & (positions <= self._high)).all(axis=1))
        self._closest = None
        if near.size == 0:
            return distance
        import trimesh

        solid = self._trimesh()
        inside = near[solid.contains(positions[near])]
        if inside.size == 0:
            return distance
        closest, gap, _ = trimesh.proximity.closest_point(solid, positions[inside])
        distance[inside] = -np.maximum(gap, 1e-300)
        self._closest = np.empty_like(positions)
        self._closest[inside] = closest
        return distance

    def _normals(self, positions):
        return np.zeros_like(positions)  # unused: resolve below moves to the surface point directly

    def resolve(self, positions: NDArray[np.float64], velocities: NDArray[np.float64]) -> None:
        inside, _ = self._inside(positions)
        if inside.size == 0:
            return
        closest = self._closest[inside]
        offset = closest - positions[inside]
        depth = np.linalg.norm(offset, axis=1)
        normals = offset / np.where(depth > 0.0, depth, 1.0)[:, None]
        positions[inside] = closest + (self.restitution * depth)[:, None] * normals
        self._respond(velocities, inside, normals)


def check_forces(forces: Any, where: str) -> tuple[Force, ...]:
    return _items_of(forces, Force, "forces", where, "[Gravity(), Drag(0.1)] (Gravity, Drag, Wind, Vortex, Attractor)")


def check_colliders(colliders: Any, where: str) -> tuple[_Collider, ...]:
    return _items_of(colliders, _Collider, "colliders", where,
                     "[PlaneCollider((0, 0, 0), (0, 1, 0))] (PlaneCollider, SphereCollider, MeshCollider)")  # fmt: skip


def _items_of(value: Any, kind: type, name: str, where: str, example: str) -> tuple[Any, ...]:
    """`value` (a list or tuple of `kind` instances) as a tuple, or SimulationError naming it with `example`."""
    items = tuple(value) if isinstance(value, list | tuple) else None
    if items is None or not all(isinstance(item, kind) for item in items):
        raise SimulationError(f"{where}: {name} = {describe(value)} is not a list of {name}; give e.g. {example}")
    return items
