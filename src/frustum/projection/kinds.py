"""The frozen projection types a ``Camera`` holds: parameters checked once, ``.matrix(aspect)``, ``.steps(aspect)``."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TypeAlias

from frustum._arrays import Matrix4
from frustum.projection.checks import as_number, centered_box, check_aspect
from frustum.projection.parallel import (
    CABINET_ALPHA,
    ISOMETRIC_ROTATION_X,
    axonometric_rotation,
    dimetric_rotation_x,
    oblique,
    oblique_vector,
    orthographic,
)
from frustum.projection.perspectives import frustum, perspective
from frustum.transforms import Step, compose, translate

__all__ = ["Axonometric", "Frustum", "Oblique", "Orthographic", "Perspective", "Projection"]


@dataclass(frozen=True)
class Perspective:
    """Symmetric perspective projection with vertical field of view `fovy`; the camera supplies the aspect.

    $matrix(aspect) = perspective(fovy, aspect, near, far)$. fovy in radians, 0 < fovy < π; 0 < near < far.
    """

    fovy: float
    near: float
    far: float

    parallel = False
    """Perspective projections have vanishing points."""

    def __post_init__(self) -> None:
        perspective(self.fovy, 1.0, self.near, self.far)  # validate once, with the builder's messages
        for name in ("fovy", "near", "far"):
            object.__setattr__(self, name, float(getattr(self, name)))

    def matrix(self, aspect: float) -> Matrix4:
        """Clip-from-view matrix for an image of the given width / height."""
        return perspective(self.fovy, check_aspect(aspect, "Perspective.matrix"), self.near, self.far)

    def steps(self, aspect: float) -> tuple[Step, ...]:
        """The named matrices of ``matrix(aspect)``, first-applied first."""
        return (Step("perspective projection and normalization", self.matrix(aspect)),)


@dataclass(frozen=True)
class Frustum:
    """Perspective projection through a fixed, possibly off-center window on the near plane (stereo, tiles).

    $matrix(aspect) = frustum(left, right, bottom, top, near, far)$; `aspect` is ignored, so choose a window
    with (right − left)/(top − bottom) equal to the image aspect or the picture is stretched.
    """

    left: float
    right: float
    bottom: float
    top: float
    near: float
    far: float

    parallel = False

    def __post_init__(self) -> None:
        frustum(self.left, self.right, self.bottom, self.top, self.near, self.far)
        for name in ("left", "right", "bottom", "top", "near", "far"):
            object.__setattr__(self, name, float(getattr(self, name)))

    def matrix(self, aspect: float) -> Matrix4:
        """Clip-from-view matrix; `aspect` is checked but does not change the fixed window."""
        check_aspect(aspect, "Frustum.matrix")
        return frustum(self.left, self.right, self.bottom, self.top, self.near, self.far)

    def steps(self, aspect: float) -> tuple[Step, ...]:
        """The named matrices of ``matrix(aspect)``, first-applied first."""
        return (Step("oblique perspective projection and normalization", self.matrix(aspect)),)


@dataclass(frozen=True)
class Orthographic:
    """Orthogonal projection of a centered view window `height` units tall (width = height · aspect).

    $matrix(aspect) = orthographic(−w/2, w/2, −height/2, height/2, near, far)$ with w = height · aspect.
    near < far; near may be <= 0 for a parallel projection.
    """

    height: float
    near: float
    far: float

    parallel = True
    """Parallel projections keep parallel lines parallel: no vanishing points."""

    def __post_init__(self) -> None:
        values = centered_box(self.height, self.near, self.far, "Orthographic")
        for name, value in zip(("height", "near", "far"), values, strict=True):
            object.__setattr__(self, name, value)

    def matrix(self, aspect: float) -> Matrix4:
        """Clip-from-view matrix $M_{ortho,norm}$ for an image of the given width / height."""
        half_width = self.height * check_aspect(aspect, "Orthographic.matrix") / 2
        return orthographic(-half_width, half_width, -self.height / 2, self.height / 2, self.near, self.far)

    def steps(self, aspect: float) -> tuple[Step, ...]:
        """The named matrices of ``matrix(aspect)``, first-applied first."""
        return (Step("orthogonal normalization M_ortho,norm", self.matrix(aspect)),)


@dataclass(frozen=True)
class Oblique:
    """Oblique parallel projection (alpha, phi) normalized to the canonical cube: $M_{ortho,norm} · M_oblique$.

    The view plane is $z = z_vp$; by default $z_vp = −(near + far)/2$, the middle of the depth range, so
    an object placed there (a camera target at that distance) is drawn true-size and stays centered.
    ``Oblique.cavalier(...)`` and ``Oblique.cabinet(...)`` fix alpha at 45° and atan 2.
    """

    alpha: float
    phi: float
    height: float
    near: float
    far: float
    z_vp: float | None = None

    parallel = True

    def __post_init__(self) -> None:
        oblique_vector(self.alpha, self.phi, "Oblique")
        values = centered_box(self.height, self.near, self.far, "Oblique")
        for name, value in zip(("height", "near", "far"), values, strict=True):
            object.__setattr__(self, name, value)
        z_vp = -(self.near + self.far) / 2 if self.z_vp is None else as_number(self.z_vp, "z_vp", "Oblique")
        object.__setattr__(self, "z_vp", z_vp)
        object.__setattr__(self, "alpha", float(self.alpha))
        object.__setattr__(self, "phi", float(self.phi))

    @classmethod
    def cavalier(cls, height: float, near: float, far: float, phi: float = math.pi / 4) -> Oblique:
        """Cavalier projection (alpha = 45°, receding edges full length)."""
        return cls(math.pi / 4, phi, height, near, far)

    @classmethod
    def cabinet(cls, height: float, near: float, far: float, phi: float = math.pi / 4) -> Oblique:
        """Cabinet projection (alpha = atan 2 ≈ 63.43°, receding edges half length)."""
        return cls(CABINET_ALPHA, phi, height, near, far)

    def steps(self, aspect: float) -> tuple[Step, ...]:
        """$M_oblique$, then $M_{ortho,norm}$, first-applied first."""
        half_width = self.height * check_aspect(aspect, "Oblique.matrix") / 2
        box = (-half_width, half_width, -self.height / 2, self.height / 2, self.near, self.far)
        assert self.z_vp is not None  # set in __post_init__
        return (
            Step("oblique shear M_oblique onto orthogonal coordinates", oblique(self.alpha, self.phi, self.z_vp)),
            Step("orthogonal normalization M_ortho,norm", orthographic(*box)),
        )

    def matrix(self, aspect: float) -> Matrix4:
        """Clip-from-view matrix $M_{ortho,norm} · M_oblique$ for an image of the given width / height."""
        return compose(*(step.matrix for step in self.steps(aspect)))


@dataclass(frozen=True)
class Axonometric:
    """Axonometric parallel projection: rotate view space about a pivot, then project orthogonally.

    $matrix(aspect) = M_{ortho,norm} · T(0, 0, −pivot) · R_x(rotation_x) · R_y(rotation_y) · T(0, 0, pivot)$:
    the rotation turns the scene about the point at distance `pivot` on the line of sight (default the middle
    of [near, far]), so a camera aimed at a target at that distance keeps it centered while the principal axes
    of a camera looking down world −z are drawn isometrically, dimetrically or trimetrically.
    ``Axonometric.isometric(...)``, ``.dimetric(...)`` and ``.trimetric(...)`` build the classic cases.
    """

    rotation_y: float
    rotation_x: float
    height: float
    near: float
    far: float
    pivot: float | None = None

    parallel = True

    def __post_init__(self) -> None:
        axonometric_rotation(self.rotation_y, self.rotation_x)
        values = centered_box(self.height, self.near, self.far, "Axonometric")
        for name, value in zip(("height", "near", "far"), values, strict=True):
            object.__setattr__(self, name, value)
        pivot = (self.near + self.far) / 2 if self.pivot is None else as_number(self.pivot, "pivot", "Axonometric")
        object.__setattr__(self, "pivot", pivot)
        object.__setattr__(self, "rotation_y", float(self.rotation_y))
        object.__setattr__(self, "rotation_x", float(self.rotation_x))

    @classmethod
    def isometric(cls, height: float, near: float, far: float) -> Axonometric:
        """Isometric view: $rotation_y = 45°$, $rotation_x = 35.264°$ (all axes foreshortened by $√(2/3)$)."""
        return cls(math.pi / 4, ISOMETRIC_ROTATION_X, height, near, far)

    @classmethod
    def dimetric(cls, ratio: float, height: float, near: float, far: float) -> Axonometric:
        """Dimetric view with $f_y / f_x = f_y / f_z = ratio ∈ (0, √2)$, as ``dimetric``."""
        return cls(math.pi / 4, dimetric_rotation_x(ratio, "Axonometric.dimetric"), height, near, far)

    @classmethod
    def trimetric(cls, rotation_y: float, rotation_x: float, height: float, near: float, far: float) -> Axonometric:
        """Trimetric view with the given rotations, as ``trimetric``."""
        return cls(rotation_y, rotation_x, height, near, far)

    def steps(self, aspect: float) -> tuple[Step, ...]:
        """Rotation about the pivot, then $M_{ortho,norm}$, first-applied first."""
        assert self.pivot is not None  # set in __post_init__
        rotation = translate(0.0, 0.0, -self.pivot) @ axonometric_rotation(self.rotation_y, self.rotation_x)
        rotation = rotation @ translate(0.0, 0.0, self.pivot)
        half_width = self.height * check_aspect(aspect, "Axonometric.matrix") / 2
        box = (-half_width, half_width, -self.height / 2, self.height / 2, self.near, self.far)
        return (
            Step("axonometric rotation about the pivot", rotation),
            Step("orthogonal normalization M_ortho,norm", orthographic(*box)),
        )

    def matrix(self, aspect: float) -> Matrix4:
        """Clip-from-view matrix for an image of the given width / height."""
        return compose(*(step.matrix for step in self.steps(aspect)))


Projection: TypeAlias = Perspective | Frustum | Orthographic | Oblique | Axonometric
"""Any projection a ``Camera`` can hold: it has ``.matrix(aspect)``, ``.steps(aspect)`` and ``.parallel``."""
