"""The ``FrustumError`` family: every error frustum raises on purpose.

Each message follows one pattern, ``<where>: <name> = <value> <problem>; <what would be valid>``, so the
user learns which value was wrong and what to give instead. ``FrustumError`` subclasses ``ValueError``, so a
plain ``except ValueError`` still catches it.
"""

from __future__ import annotations

__all__ = [
    "CameraError",
    "ClippingError",
    "FrustumError",
    "FrustumWarning",
    "GeometryError",
    "OutputError",
    "SceneFileError",
    "ShadingError",
    "SimulationError",
    "TransformError",
]


class FrustumError(ValueError):
    """Base class of every error frustum raises on purpose (bad input, impossible request)."""


class GeometryError(FrustumError):
    """Bad points, faces, normals or meshes: wrong shape, non-finite coordinates, missing vertices."""


class TransformError(FrustumError):
    """A transformation that cannot be built or applied: zero-length axis, singular matrix, zero quaternion."""


class CameraError(FrustumError):
    """A degenerate camera or projection: up parallel to the view direction, near <= 0, empty viewport."""


class ShadingError(FrustumError):
    """A bad material or light: non-finite or out-of-range coefficients, zero-length light direction."""


class ClippingError(FrustumError):
    """Bad clipping input: wrong homogeneous shapes, non-finite coordinates, degenerate planes."""


class SceneFileError(FrustumError):
    """A malformed scene file; the message starts with ``file:line``."""


class OutputError(FrustumError):
    """A frame, drawing or animation that cannot be written: unknown format, unwritable path."""


class SimulationError(FrustumError):
    """A bad particle or mass-spring system, or a simulation whose state stopped being finite (a blow-up)."""


class FrustumWarning(UserWarning):
    """Something frustum went on without and says so: a texture a mesh file names that cannot be read, for one
    (``warnings.filterwarnings("error", category=FrustumWarning)`` turns these into errors)."""
