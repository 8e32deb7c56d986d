"""Projections: view coordinates to clip coordinates, normalization to the canonical volume, and the viewport.

Every builder returns a fresh ``(4, 4) float64`` matrix named by the frames it maps. Projection builders
return ``clip_from_view``: view coordinates are right-handed with the camera at the origin looking down
−z_view; clip coordinates divide by w into the left-handed normalized cube [−1, 1]³ (NDC) with the near plane
at z_ndc = −1 and the far plane at +1, as in OpenGL and glm's ``*RH_NO`` builders. ``viewport`` returns
``window_from_ndc``.

``near`` and ``far`` are positive distances in front of the eye, as in glm. The textbook writes the same
planes as view-plane coordinates $z_near = −near$ and $z_far = −far$; each docstring gives both forms.

The package: ``parallel`` (orthographic, multiview, axonometric and oblique projections), ``perspectives``
(symmetric and general perspective, the frustum), ``viewports`` (NDC to window), ``kinds`` (the frozen types
``Perspective``, ``Frustum``, ``Orthographic``, ``Oblique`` and ``Axonometric`` a ``Camera`` holds: each stores
its parameters, validated once, and builds its matrix with ``.matrix(aspect)``; ``.steps(aspect)`` lists the
named matrices whose product ``.matrix`` is, for ``trace``) and ``checks`` (the argument checks they share).

References: [HB 10] is Hearn & Baker, *Computer Graphics with OpenGL*, chapter 10, "Three-Dimensional
Viewing"; [seed] is the lecture notes.
"""

from frustum.projection.kinds import Axonometric, Frustum, Oblique, Orthographic, Perspective, Projection
from frustum.projection.parallel import (
    CABINET_ALPHA as CABINET_ALPHA,
)
from frustum.projection.parallel import (
    ISOMETRIC_ROTATION_X as ISOMETRIC_ROTATION_X,
)
from frustum.projection.parallel import (
    MULTIVIEWS,
    MultiView,
    axonometric_rotation,
    cabinet,
    cavalier,
    dimetric,
    isometric,
    multiview,
    oblique,
    oblique_from_vector,
    oblique_normalized,
    orthographic,
    trimetric,
)
from frustum.projection.perspectives import (
    frustum,
    general_perspective,
    general_perspective_steps,
    perspective,
    perspective_onto_plane,
)
from frustum.projection.viewports import viewport

__all__ = [
    "MULTIVIEWS",
    "Axonometric",
    "Frustum",
    "MultiView",
    "Oblique",
    "Orthographic",
    "Perspective",
    "Projection",
    "axonometric_rotation",
    "cabinet",
    "cavalier",
    "dimetric",
    "frustum",
    "general_perspective",
    "general_perspective_steps",
    "isometric",
    "multiview",
    "oblique",
    "oblique_from_vector",
    "oblique_normalized",
    "orthographic",
    "perspective",
    "perspective_onto_plane",
    "trimetric",
    "viewport",
]
