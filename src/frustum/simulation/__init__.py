"""Things that move: Reeves particle systems and mass–spring systems, stepped in time, handed to the scene.

The simulation layer sits between modeling and the world (docs/architecture.md): it imports geometry, transforms and the
checkers, never the scene, the renderer or the kernels. State lives in numpy arrays and every step is
whole-array numpy work (a million particles per step without a Python loop per particle).
"""

from frustum.simulation.emitters import (
    DiskEmitter,
    Emitter,
    LineEmitter,
    MeshEmitter,
    PointEmitter,
    SphereEmitter,
)
from frustum.simulation.forces import (
    Attractor,
    Drag,
    Force,
    Gravity,
    MeshCollider,
    PlaneCollider,
    SphereCollider,
    Vortex,
    Wind,
)
from frustum.simulation.particles import ParticleSystem
from frustum.simulation.springs import INTEGRATORS, MassSpringSystem, cloth, rope, soft_body

__all__ = [
    "INTEGRATORS",
    "Attractor",
    "DiskEmitter",
    "Drag",
    "Emitter",
    "Force",
    "Gravity",
    "LineEmitter",
    "MassSpringSystem",
    "MeshCollider",
    "MeshEmitter",
    "ParticleSystem",
    "PlaneCollider",
    "PointEmitter",
    "SphereCollider",
    "SphereEmitter",
    "Vortex",
    "Wind",
    "cloth",
    "rope",
    "soft_body",
]
