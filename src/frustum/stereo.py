"""Stereoscopic viewing: a left and a right camera with off-axis (asymmetric-frustum) projections.

Stereoscopic devices present two views of a scene, one for the left eye and one for the right eye. Both
eyes look along the same direction (parallel lines of sight, not "toe-in" rotation, which gives vertical
parallax at the image corners); each eye is offset by half the eye separation e along the camera's u axis,
and its near-plane window is shifted toward the other eye so that both view volumes meet on the plane of
zero parallax, the convergence plane at distance D in front of the eyes:

$$eye_left = eye − (e/2)·u,   eye_right = eye + (e/2)·u,   s = (e/2)·near/D$$

the left window spanning $x ∈ [−w + s, w + s]$ and the right one $x ∈ [−w − s, w − s]$, with
$w = near·tan(fovy/2)·aspect$ the half width of the centre camera's near-plane window. A point on
the convergence plane then lands on the same window position in both images (zero parallax); a point beyond
it has positive parallax (x_right − x_left > 0, it appears behind the screen), a point in front of it negative
parallax (it appears in front of the screen).

References
----------
[seed] "Three-dimensional and stereoscopic viewing" ("two views of a scene: one for the left eye and the other
for the right eye"); [HB 10] "Oblique Perspective-Projection Frustum" (the off-centre window of each eye).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_scalar, describe
from frustum.camera import Camera, ViewFrame
from frustum.errors import CameraError
from frustum.projection import Frustum, Perspective

__all__ = ["StereoCamera"]


@dataclass(frozen=True, eq=False)
class StereoCamera:
    """A stereo pair built from one perspective `camera`: ``left`` and ``right`` cameras with off-axis frusta.

    Each eye sits at $eye ∓ (e/2)·u$ with the centre camera's view direction and up vector, and projects
    through $frustum(−w ± s, w ± s, −t, t, near, far)$ (upper sign: left eye) with $t = near·tan(fovy/2)$,
    $w = t·aspect$ and the shift $s = (e/2)·near/D$, so that the convergence plane at distance D is the
    plane of zero parallax. The images have the centre camera's size.

    Parameters
    ----------
    camera : Camera
        The centre camera; its projection must be a ``Perspective`` (a symmetric frustum).
    eye_separation : float
        Distance e between the two eyes in world units, > 0 (interocular distance; about D/30 is comfortable).
    convergence_distance : float
        Distance D of the zero-parallax plane from the eyes along the line of sight, > near.

    Raises
    ------
    CameraError
        If `camera` is not a Camera with a Perspective projection, e <= 0 or not finite, or D <= near or not
        finite.

    References
    ----------
    [seed] "Three-dimensional and stereoscopic viewing"; [HB 10] "Oblique Perspective-Projection Frustum".
    """

    camera: Camera
    eye_separation: float
    convergence_distance: float
    left: Camera = field(init=False, repr=False)
    right: Camera = field(init=False, repr=False)

    def __post_init__(self) -> None:
        where = "StereoCamera"
        if not isinstance(self.camera, Camera):
            raise CameraError(f"{where}: camera = {describe(self.camera)} is not a Camera; build one with Camera")
        projection = self.camera.projection
        if not isinstance(projection, Perspective):
            raise CameraError(
                f"{where}: camera.projection = {describe(projection)} is not a Perspective projection; stereo pairs "
                "need a perspective centre camera (give Perspective(fovy, near, far))"
            )
        separation = as_scalar(self.eye_separation, "eye_separation", where=where, error=CameraError)
        if not separation > 0.0:
            raise CameraError(
                f"{where}: eye_separation = {separation!r} must be > 0; the eyes need a positive distance apart"
            )
        distance = as_scalar(self.convergence_distance, "convergence_distance", where=where, error=CameraError)
        if not distance > projection.near:
            raise CameraError(
                f"{where}: convergence_distance = {distance!r} is not beyond near = {projection.near!r}; the "
                "zero-parallax plane must lie in front of the near plane (convergence_distance > near)"
            )
        object.__setattr__(self, "eye_separation", separation)
        object.__setattr__(self, "convergence_distance", distance)
        object.__setattr__(self, "left", self._eye(-1.0))
        object.__setattr__(self, "right", self._eye(+1.0))

    def _eye(self, side: float) -> Camera:
        """The camera of one eye: side = −1 left, +1 right."""
        camera, frame = self.camera, self.camera.frame
        projection: Perspective = camera.projection  # type: ignore[assignment]  # checked in __post_init__
        offset = side * (self.eye_separation / 2.0) * frame.u
        if frame.target is not None:
            eye_frame = ViewFrame(
                frame.eye + offset, target=frame.target + offset, up=frame.up, handedness=frame.handedness
            )
        else:
            eye_frame = ViewFrame(frame.eye + offset, normal=frame.n, up=frame.up, handedness=frame.handedness)
        top = projection.near * math.tan(projection.fovy / 2.0)
        half_width = top * camera.aspect
        shift = -side * (self.eye_separation / 2.0) * projection.near / self.convergence_distance
        window = Frustum(-half_width + shift, half_width + shift, -top, top, projection.near, projection.far)
        return Camera(eye_frame, window, camera.width, camera.height)

    @property
    def eyes(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World positions of the left and right eye, $eye ∓ (e/2)·u$."""
        return np.array(self.left.frame.eye), np.array(self.right.frame.eye)

    def parallax(self, points: ArrayLike) -> NDArray[np.float64]:
        """(N,) horizontal screen parallax $x_right − x_left$ of world points, in pixels (window x).

        Zero on the convergence plane, positive behind it (the point appears behind the screen), negative in
        front of it. Points behind either eye give NaN (see ``Camera.project``).
        """
        single = np.shape(points) == (3,)
        parallax = self.right.project(np.atleast_2d(points))[:, 0] - self.left.project(np.atleast_2d(points))[:, 0]
        return parallax[0] if single else parallax
