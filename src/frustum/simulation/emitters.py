"""Particle emitters (Reeves' generation shapes): a point, a line, a disk, a sphere, the surface of a mesh.

Each emitter places new particles on its shape and gives them a velocity $speed·d$ with ``d`` drawn uniformly
from the spherical cap of half-angle `spread` around the emitter's direction (the "ejection angle" of Reeves'
model), ``speed`` varying as $speed + speed_variance·U(−1, 1)$. Random numbers come from the system's
``numpy.random.Generator`` in a fixed order, so the same seed gives the same particles.

References
----------
[HB 15] "Particle Systems"; W. T. Reeves, "Particle Systems — a Technique for Modeling a Class of Fuzzy
Objects", SIGGRAPH 1983, §2.1 (generation, initial attributes); [seed] "Particle systems".
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_direction, as_scalar, as_vector3, describe
from frustum.errors import SimulationError
from frustum.geometry import Mesh
from frustum.simulation._checks import as_nonnegative, as_positive

__all__ = ["DiskEmitter", "Emitter", "LineEmitter", "MeshEmitter", "PointEmitter", "SphereEmitter", "cone_directions"]


def _basis(axis: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Two unit vectors completing the unit `axis` to a right-handed orthonormal frame."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    first = np.cross(axis, helper)
    first /= np.linalg.norm(first)
    return first, np.cross(axis, first)


def cone_directions(
    rng: np.random.Generator, axes: NDArray[np.float64], spread: float
) -> NDArray[np.float64]:  # fmt: skip
    """(N, 3) unit directions uniform on the cap of half-angle `spread` (radians) around each unit row of `axes`.

    $cos θ = 1 − u·(1 − cos spread)$, $φ = 2π·v$ (area-uniform on the cap), around each axis.
    `axes` is (N, 3); the generator draws u for all N, then v for all N.
    """
    count = axes.shape[0]
    u = rng.random(count)
    v = rng.random(count)
    cos_theta = 1.0 - u * (1.0 - math.cos(spread))
    sin_theta = np.sqrt(np.maximum(0.0, 1.0 - cos_theta * cos_theta))
    phi = 2.0 * math.pi * v
    helper = np.where(np.abs(axes[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    first = np.cross(axes, helper)
    first /= np.linalg.norm(first, axis=1)[:, None]
    second = np.cross(axes, first)
    return (
        cos_theta[:, None] * axes
        + (sin_theta * np.cos(phi))[:, None] * first
        + (sin_theta * np.sin(phi))[:, None] * second
    )


class Emitter:
    """Base of the emitters: a shape (``_origins``), a direction with a spread cone, a speed ± variance."""

    _where = "Emitter"

    def __init__(self, direction: ArrayLike | None, spread: float, speed: float, speed_variance: float) -> None:
        where = self._where
        self.direction = None if direction is None else as_direction(direction, "direction", where=where,
                                                                     error=SimulationError)  # fmt: skip
        self.spread = as_nonnegative(spread, "spread", where)
        if self.spread > math.pi:
            raise SimulationError(f"{where}: spread = {self.spread!r} is above pi; give a cone half-angle in [0, pi]")
        self.speed = as_scalar(speed, "speed", where=where, error=SimulationError)
        self.speed_variance = as_nonnegative(speed_variance, "speed_variance", where)

    def _origins(
        self, rng: np.random.Generator, count: int
    ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:  # fmt: skip
        """(count, 3) start positions and their outward normals (None where the shape has none)."""
        raise NotImplementedError

    def sample(self, rng: np.random.Generator, count: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(positions, velocities) of `count` new particles, both (count, 3) float64."""
        positions, normals = self._origins(rng, count)
        if self.direction is not None:
            axes = np.broadcast_to(self.direction, (count, 3))
        elif normals is not None:
            axes = normals
        else:
            axes = np.broadcast_to(np.array([0.0, 1.0, 0.0]), (count, 3))
        directions = cone_directions(rng, np.ascontiguousarray(axes), self.spread)
        speeds = self.speed + self.speed_variance * (2.0 * rng.random(count) - 1.0)
        return positions, directions * speeds[:, None]

    def _describe(self) -> str:
        direction = "normal" if self.direction is None else describe(self.direction)
        return f"direction={direction}, spread={self.spread!r}, speed={self.speed!r}"


class PointEmitter(Emitter):
    """Particles start at `position`; direction (default +y) with a cone of half-angle `spread` radians.

    Parameters
    ----------
    position : (3,) array_like
        World (or model) coordinates of the point.
    direction : (3,) array_like
        Mean direction of motion (normalized); default (0, 1, 0).
    spread : float
        Half-angle of the cone of directions in radians, in [0, π] (π: every direction).
    speed, speed_variance : float
        Initial speed $speed + speed_variance·U(−1, 1)$ (units per second).
    """

    _where = "PointEmitter"

    def __init__(self, position: ArrayLike, direction: ArrayLike = (0.0, 1.0, 0.0), spread: float = 0.0,
                 speed: float = 1.0, speed_variance: float = 0.0) -> None:  # fmt: skip
        super().__init__(direction, spread, speed, speed_variance)
        self.position = as_vector3(position, "position", where=self._where, error=SimulationError)

    def _origins(self, rng: np.random.Generator, count: int):
        return np.repeat(self.position[None, :], count, axis=0), None

    def __repr__(self) -> str:
        return f"PointEmitter({describe(self.position)}, {self._describe()})"


class LineEmitter(Emitter):
    """Particles start uniformly on the segment from `start` to `end`; direction default +y."""

    _where = "LineEmitter"

    def __init__(self, start: ArrayLike, end: ArrayLike, direction: ArrayLike = (0.0, 1.0, 0.0),
                 spread: float = 0.0, speed: float = 1.0, speed_variance: float = 0.0) -> None:  # fmt: skip
        super().__init__(direction, spread, speed, speed_variance)
        self.start = as_vector3(start, "start", where=self._where, error=SimulationError)
        self.end = as_vector3(end, "end", where=self._where, error=SimulationError)

    def _origins(self, rng: np.random.Generator, count: int):
        t = rng.random(count)
        return self.start + t[:, None] * (self.end - self.start), None


class DiskEmitter(Emitter):
    """Particles start uniformly on the disk of `radius` around `center` perpendicular to `normal`
    ($r = R·√u$, area-uniform); direction default the normal."""

    _where = "DiskEmitter"

    def __init__(self, center: ArrayLike, normal: ArrayLike = (0.0, 1.0, 0.0), radius: float = 1.0,
                 direction: ArrayLike | None = None, spread: float = 0.0, speed: float = 1.0,
                 speed_variance: float = 0.0) -> None:  # fmt: skip
        super().__init__(direction, spread, speed, speed_variance)
        self.center = as_vector3(center, "center", where=self._where, error=SimulationError)
        self.normal = as_direction(normal, "normal", where=self._where, error=SimulationError)
        self.radius = as_positive(radius, "radius", self._where)

    def _origins(self, rng: np.random.Generator, count: int):
        first, second = _basis(self.normal)
        r = self.radius * np.sqrt(rng.random(count))
        phi = 2.0 * math.pi * rng.random(count)
        positions = self.center + (r * np.cos(phi))[:, None] * first + (r * np.sin(phi))[:, None] * second
        return positions, np.broadcast_to(self.normal, (count, 3))


class SphereEmitter(Emitter):
    """Particles start uniformly on the sphere of `radius` around `center`; direction default outward."""

    _where = "SphereEmitter"

    def __init__(self, center: ArrayLike, radius: float = 1.0, direction: ArrayLike | None = None,
                 spread: float = 0.0, speed: float = 1.0, speed_variance: float = 0.0) -> None:  # fmt: skip
        super().__init__(direction, spread, speed, speed_variance)
        self.center = as_vector3(center, "center", where=self._where, error=SimulationError)
        self.radius = as_positive(radius, "radius", self._where)

    def _origins(self, rng: np.random.Generator, count: int):
        z = 2.0 * rng.random(count) - 1.0
        phi = 2.0 * math.pi * rng.random(count)
        s = np.sqrt(np.maximum(0.0, 1.0 - z * z))
        normals = np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)
        return self.center + self.radius * normals, normals


class MeshEmitter(Emitter):
    """Particles start uniformly on the surface of `mesh` (a face chosen with probability ∝ its area, then a
    uniform point in it: $√u$ barycentric sampling); direction default the face normal."""

    _where = "MeshEmitter"

    def __init__(self, mesh: Mesh, direction: ArrayLike | None = None, spread: float = 0.0, speed: float = 1.0,
                 speed_variance: float = 0.0) -> None:  # fmt: skip
        super().__init__(direction, spread, speed, speed_variance)
        if not isinstance(mesh, Mesh) or mesh.face_count == 0 or not mesh.area > 0.0:
            raise SimulationError(
                f"{self._where}: mesh = {describe(mesh)} is not a Mesh with area; give a Mesh with faces"
            )
        self.mesh = mesh
        areas = mesh.face_areas
        self._cumulative = np.cumsum(areas) / areas.sum()

    def _origins(self, rng: np.random.Generator, count: int):
        faces = np.minimum(np.searchsorted(self._cumulative, rng.random(count), side="right"),
                           self.mesh.face_count - 1)  # fmt: skip
        root = np.sqrt(rng.random(count))
        v = rng.random(count)
        corners = self.mesh.vertices[self.mesh.faces[faces]]
        positions = ((1.0 - root)[:, None] * corners[:, 0] + (root * (1.0 - v))[:, None] * corners[:, 1]
                     + (root * v)[:, None] * corners[:, 2])  # fmt: skip
        return positions, np.ascontiguousarray(self.mesh.face_normals[faces])


def check_emitter(emitter: Any, where: str) -> Emitter:
    if not isinstance(emitter, Emitter):
        raise SimulationError(
            f"{where}: emitter = {describe(emitter)} is not an emitter; give a PointEmitter, LineEmitter, "
            "DiskEmitter, SphereEmitter or MeshEmitter"
        )
    return emitter
