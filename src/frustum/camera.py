"""The viewing frame (uvw), world-to-view transformation, and the Camera that bundles frame, projection and image.

World and view coordinates are right-handed; the camera sits at the view point P0 and looks down −z_view.
The seed's frame: $n = N/|N|$ (N points from the look-at point back toward the eye), $u = V×n/|V×n|$
(V is the view-up vector), $v = n×u$. ``view_from_world`` translates P0 to the origin and then rotates
u, v, n onto x, y, z; glm ``lookAtRH`` builds the same matrix.

A ``Camera`` maps world points to window coordinates in the order of the pipeline:
$window_from_world = window_from_ndc · divide · clip_from_view · view_from_world$. Window coordinates have
x in [0, width] to the right and **y in [0, height] upward** (OpenGL), pixel centers at half-integers, and
depth in [0, 1] with 1 = far. Images stored top row first use row = height − 1 − floor(y).

References: [HB 10] is Hearn & Baker, *Computer Graphics with OpenGL*, chapter 10, "Three-Dimensional
Viewing"; [seed] is the lecture notes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Literal, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum import camera_conventions as conventions
from frustum._arrays import Matrix4, Points, Vector3, as_points, as_scalar, as_vector3, describe, read_only
from frustum.errors import CameraError
from frustum.projection import (
    Axonometric,
    Frustum,
    Oblique,
    Orthographic,
    Perspective,
    Projection,
    multiview,
    viewport,
)
from frustum.transforms import Step, apply, compose, invert, translate

__all__ = [
    "Camera",
    "PrincipalVanishingPoints",
    "Ray",
    "ViewFrame",
    "look_at",
]

# |V × n| below this fraction of |V| counts as "up parallel to the view direction": the frame would be
# decided by round-off (glm returns NaN at exactly 0).
_PARALLEL_TOLERANCE = 1e-9
# |w| of a direction's clip image below this fraction of its scale counts as 0: the direction is parallel to
# the view plane and its lines have no vanishing point (far beyond any image at 1e12 times the window size).
_VANISHING_TOLERANCE = 1e-12

_PROJECTION_TYPES = (Perspective, Frustum, Orthographic, Oblique, Axonometric)
# Left-handed view coordinates (z_view toward the scene) to the right-handed ones the projections expect.
_FLIP_Z = np.diag([1.0, 1.0, -1.0, 1.0])


def _frame_axes(
    eye: Vector3, target: Vector3 | None, normal: Vector3 | None, up: Vector3, where: str
) -> tuple[Vector3, Vector3, Vector3]:
    """u, v, n of the seed's uvw frame; validated inputs in, CameraError for degenerate frames."""
    if target is not None:
        big_n = eye - target
        if not np.any(big_n):
            raise CameraError(
                f"{where}: target = {describe(target)} equals eye = {describe(eye)}; the view direction "
                "eye − target must be nonzero (put the target in front of the eye)"
            )
    else:
        assert normal is not None
        big_n = normal
        if not np.any(big_n):
            raise CameraError(
                f"{where}: normal = {describe(normal)} has zero length; give the nonzero view-plane normal N "
                "(pointing from the scene back toward the eye)"
            )
    n = big_n / np.linalg.norm(big_n)
    up_length = float(np.linalg.norm(up))
    if up_length == 0.0:
        raise CameraError(f"{where}: up = {describe(up)} has zero length; give a nonzero view-up vector V")
    v_cross_n = np.cross(up, n)
    length = float(np.linalg.norm(v_cross_n))
    if length <= _PARALLEL_TOLERANCE * up_length:
        raise CameraError(
            f"{where}: up = {describe(up)} is parallel to the view direction {describe(-n)}; "
            "choose an up vector not along eye − target"
        )
    u = v_cross_n / length
    v = np.cross(n, u)
    return u, v, n


@dataclass(frozen=True, eq=False)
class ViewFrame:
    """The uvw viewing frame at the view point `eye`: n from the view-plane normal N, u, v from the up vector V.

    $n = N/|N|$, $u = V×n/|V×n|$, $v = n×u$ with $N = eye − target$ (or the given `normal`): a
    right-handed orthonormal frame, u to the right, v up, n back toward the viewer, so the camera looks along
    −n. ``matrix`` is view_from_world: translate P0 = eye to the origin, then rotate u, v, n onto x, y, z
    (``R`` has rows u, v, n); ``steps`` gives both matrices separately.

    ``handedness="left"`` selects the seed's left-handed viewing coordinates: same u and v, but z_view points
    along the line of sight (rows u, v, −n), so z_view grows with distance from the eye. The frame's matrix
    then has determinant −1; a ``Camera`` converts back with z → −z before projecting, so both variants give
    the same picture.

    Parameters
    ----------
    eye : (3,) array_like
        The view point P0 in world coordinates.
    target : (3,) array_like, optional
        A look-at point; N = eye − target. Give exactly one of `target` and `normal`.
    up : (3,) array_like
        The view-up vector V, any length, not parallel to N. Positional order ``ViewFrame(eye, target, up)``
        matches ``look_at(eye, target, up)``.
    normal : (3,) array_like, optional, keyword-only
        The view-plane normal N directly (pointing from the scene toward the eye), any nonzero length:
        ``ViewFrame(eye, normal=N, up=V)``.
    handedness : "right" or "left", keyword-only

    Raises
    ------
    CameraError
        If eye == target, N or V is zero, V is parallel to N, both or neither of target/normal are given, or
        handedness is not "right" or "left".

    References
    ----------
    [HB 10] "Three-Dimensional Viewing-Coordinate Parameters", "Transformation from World to Viewing
    Coordinates"; [seed] "The uvw Viewing-coordinate Reference Frame", "Transformation from World to Viewing
    Coordinates".
    """

    eye: Vector3
    target: Vector3 | None = None
    up: Vector3 = (0.0, 1.0, 0.0)  # type: ignore[assignment]  # converted to an array in __post_init__
    normal: Vector3 | None = field(default=None, kw_only=True)
    handedness: Literal["right", "left"] = field(default="right", kw_only=True)

    def __post_init__(self) -> None:
        where = "ViewFrame"
        if (self.target is None) == (self.normal is None):
            raise CameraError(
                f"{where}: target = {describe(self.target)} and normal = {describe(self.normal)}; give exactly "
                "one of them (a look-at point, or the view-plane normal N)"
            )
        if self.handedness not in ("right", "left"):
            raise CameraError(f"{where}: handedness = {self.handedness!r} is unknown; expected 'right' or 'left'")
        eye = as_vector3(self.eye, "eye", where=where, error=CameraError)
        up = as_vector3(self.up, "up", where=where, error=CameraError)
        target = None if self.target is None else as_vector3(self.target, "target", where=where, error=CameraError)
        normal = None if self.normal is None else as_vector3(self.normal, "normal", where=where, error=CameraError)
        u, v, n = _frame_axes(eye, target, normal, up, where)
        for name, value in (("eye", eye), ("up", up), ("target", target), ("normal", normal)):
            object.__setattr__(self, name, None if value is None else read_only(value))
        for name, value in (("u", u), ("v", v), ("n", n)):
            object.__setattr__(self, name, read_only(value))

    u: Vector3 = field(init=False, repr=False, default=None)  # type: ignore[assignment]  # set in __post_init__
    v: Vector3 = field(init=False, repr=False, default=None)  # type: ignore[assignment]
    n: Vector3 = field(init=False, repr=False, default=None)  # type: ignore[assignment]

    @property
    def direction(self) -> Vector3:
        """Unit line of sight in world coordinates, −n."""
        return -self.n

    @cached_property
    def rotation(self) -> Matrix4:
        """The rotation step: rows u, v, n (or u, v, −n for a left-handed frame), $x_view = u·(P − P0)$."""
        matrix = np.eye(4)
        matrix[0, :3], matrix[1, :3] = self.u, self.v
        matrix[2, :3] = self.n if self.handedness == "right" else -self.n
        return read_only(matrix)

    @cached_property
    def steps(self) -> tuple[Step, ...]:
        """view_from_world as its two textbook steps, first-applied first: T(−P0), then R."""
        return (
            Step("translate the view point P0 to the origin", read_only(translate(*-self.eye))),
            Step("rotate u, v, n onto the x, y, z axes", self.rotation),
        )

    @cached_property
    def matrix(self) -> Matrix4:
        """$view_from_world = R · T(−P0)$: rows u, v, n and last column $−(u·P0, v·P0, n·P0)$."""
        return read_only(compose(*(step.matrix for step in self.steps)))

    @cached_property
    def world_from_view(self) -> Matrix4:
        """The inverse of ``matrix``: the camera's pose in the world (columns u, v, n and P0)."""
        return read_only(invert(self.matrix))


def look_at(eye: ArrayLike, target: ArrayLike, up: ArrayLike = (0.0, 1.0, 0.0)) -> Matrix4:
    """View-from-world matrix of a camera at `eye` looking at `target` with view-up `up` (right-handed).

    $view_from_world = R · T(−eye)$ with R's rows $u = V×n/|V×n|$, $v = n×u$,
    $n = (eye − target)/|eye − target|$; equal to glm ``lookAtRH`` and to ``ViewFrame(eye, target, up=up).matrix``.

    Raises
    ------
    CameraError
        If eye == target or `up` is parallel to eye − target (or zero).

    References
    ----------
    [HB 10] "Transformation from World to Viewing Coordinates"; [seed] "The uvw Viewing-coordinate Reference
    Frame".
    """
    where = "look_at"
    eye_ = as_vector3(eye, "eye", where=where, error=CameraError)
    target_ = as_vector3(target, "target", where=where, error=CameraError)
    up_ = as_vector3(up, "up", where=where, error=CameraError)
    u, v, n = _frame_axes(eye_, target_, None, up_, where)
    matrix = np.eye(4)
    matrix[0, :3], matrix[1, :3], matrix[2, :3] = u, v, n
    matrix[:3, 3] = -(matrix[:3, :3] @ eye_)
    return matrix


class Ray(NamedTuple):
    """A picking ray in world coordinates: points $origin + t·direction$ for t >= 0, direction of unit length."""

    origin: Points
    direction: Points


class PrincipalVanishingPoints(NamedTuple):
    """Vanishing points of the world x, y and z axes, and how many exist (0 for parallel projections)."""

    count: int
    x: NDArray[np.float64] | None
    y: NDArray[np.float64] | None
    z: NDArray[np.float64] | None


def _as_window_points(value: ArrayLike, name: str, where: str, width: int) -> tuple[bool, NDArray]:
    """(N, width) or (width,) finite float64 rows; `single` says a single row was given."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise CameraError(f"{where}: {name} = {describe(value)} is not numeric; expected numbers") from None
    single = array.shape == (width,)
    rows = array[None, :] if single else array
    if rows.ndim != 2 or rows.shape[1] != width:
        raise CameraError(
            f"{where}: {name} has shape {array.shape}; expected ({width},) or (N, {width}) window coordinates"
        )
    bad = np.flatnonzero(~np.isfinite(rows).all(axis=1))
    if bad.size:
        i = int(bad[0])
        raise CameraError(f"{where}: {name}[{i}] = {describe(rows[i])} is not finite; coordinates must be finite")
    return single, np.ascontiguousarray(rows)


MAX_IMAGE_SIZE = 65536
"""Largest image width or height a Camera accepts (an 8192-pixel image supersampled 64 times, ×8 a side, fits)."""


@dataclass(frozen=True, eq=False)
class Camera:
    """A viewing frame, a projection and an image size: everything that maps world points to pixels.

    $window_from_world = window_from_ndc · (divide by w) · clip_from_view · view_from_world$ with
    ``view_from_world = frame.matrix``, ``clip_from_view = projection.matrix(width / height)`` and
    $window_from_ndc = viewport(0, 0, width, height)$.

    Parameters
    ----------
    frame : ViewFrame
    projection : Perspective, Frustum, Orthographic, Oblique or Axonometric
    width, height : int
        Image size in pixels, in [1, MAX_IMAGE_SIZE] (65536).

    Raises
    ------
    CameraError
        If the frame or projection has the wrong type, or the image size is not an integer in [1, 65536].

    References
    ----------
    [HB 10] "The Three-Dimensional Viewing Pipeline", "The Viewport Transformation and Three-Dimensional Screen
    Coordinates".
    """

    frame: ViewFrame
    projection: Projection
    width: int = 640
    height: int = 480

    def __post_init__(self) -> None:
        where = "Camera"
        if not isinstance(self.frame, ViewFrame):
            raise CameraError(f"{where}: frame = {describe(self.frame)} is not a ViewFrame; build one with ViewFrame")
        if not isinstance(self.projection, _PROJECTION_TYPES):
            names = ", ".join(t.__name__ for t in _PROJECTION_TYPES)
            raise CameraError(
                f"{where}: projection = {describe(self.projection)} is not a projection type; expected one of {names}"
            )
        for name in ("width", "height"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | np.integer) or value <= 0:
                raise CameraError(
                    f"{where}: {name} = {describe(value)} is not a positive integer; an image needs at least "
                    "one pixel in each direction"
                )
            if value > MAX_IMAGE_SIZE:
                raise CameraError(
                    f"{where}: {name} = {int(value)} is above the limit of {MAX_IMAGE_SIZE} pixels a side; give "
                    f"width and height in [1, {MAX_IMAGE_SIZE}] (render's work budget, frustum.set_budget, bounds "
                    "the whole image)"
                )
            object.__setattr__(self, name, int(value))

    # --- constructors -------------------------------------------------------------------------------------

    @classmethod
    def look_at(
        cls,
        eye: ArrayLike,
        target: ArrayLike,
        up: ArrayLike = (0.0, 1.0, 0.0),
        projection: Projection | None = None,
        width: int = 640,
        height: int = 480,
        handedness: Literal["right", "left"] = "right",
    ) -> Camera:
        """Camera at `eye` looking at `target`; the projection defaults to ``Perspective(π/3, 0.1, 100)``."""
        frame = ViewFrame(eye, target=target, up=up, handedness=handedness)
        return cls(frame, Perspective(math.pi / 3, 0.1, 100.0) if projection is None else projection, width, height)

    @classmethod
    def orbit(
        cls,
        target: ArrayLike,
        distance: float,
        azimuth: float,
        elevation: float,
        projection: Projection | None = None,
        width: int = 640,
        height: int = 480,
    ) -> Camera:
        """Camera on a sphere around `target`, world y up, looking at the target.

        $eye = target + distance·(cos e·sin a, sin e, cos e·cos a)$ for azimuth a (radians about +y, from +z
        toward +x) and elevation e (radians above the xz plane, |e| < π/2: straight up or down leaves the
        view-up vector y parallel to the line of sight).

        Raises
        ------
        CameraError
            If distance <= 0, or |elevation| = π/2 (up parallel to the view direction).
        """
        where = "Camera.orbit"
        center = as_vector3(target, "target", where=where, error=CameraError)
        radius = as_scalar(distance, "distance", where=where, error=CameraError)
        if not radius > 0.0:
            raise CameraError(f"{where}: distance = {radius!r} must be > 0; the eye must not sit on the target")
        a = as_scalar(azimuth, "azimuth", where=where, error=CameraError)
        e = as_scalar(elevation, "elevation", where=where, error=CameraError)
        if abs(math.cos(e)) <= _PARALLEL_TOLERANCE:
            raise CameraError(
                f"{where}: elevation = {e!r} looks straight up or down, along the view-up vector y; "
                "keep |elevation| < pi/2"
            )
        offset = radius * np.array([math.cos(e) * math.sin(a), math.sin(e), math.cos(e) * math.cos(a)])
        return cls.look_at(center + offset, center, (0.0, 1.0, 0.0), projection, width, height)

    @classmethod
    def multiview(
        cls,
        name: str,
        projection: Projection,
        target: ArrayLike = (0.0, 0.0, 0.0),
        distance: float = 10.0,
        width: int = 640,
        height: int = 480,
    ) -> Camera:
        """Camera for a multiview elevation or plan view (``projection.multiview(name)``) of `target`.

        The eye sits `distance` back along the preset's line of sight; give a parallel projection (typically
        ``Orthographic``) whose near/far range contains the object around that distance.

        Raises
        ------
        CameraError
            If `name` is not a preset or distance <= 0.
        """
        preset = multiview(name)
        center = as_vector3(target, "target", where="Camera.multiview", error=CameraError)
        radius = as_scalar(distance, "distance", where="Camera.multiview", error=CameraError)
        if not radius > 0.0:
            raise CameraError(f"Camera.multiview: distance = {radius!r} must be > 0")
        eye = center - radius * np.array(preset.direction)
        return cls.look_at(eye, center, preset.up, projection, width, height)

    @classmethod
    def fit(
        cls,
        scene_or_bounds: object,
        direction: ArrayLike | None = None,
        fovy: float = math.radians(40.0),
        margin: float = 0.05,
        *,
        projection: Literal["perspective", "orthographic"] = "perspective",
        width: int = 640,
        height: int = 480,
        up: ArrayLike = (0.0, 1.0, 0.0),
    ) -> Camera:
        """A camera framing the bounding sphere of a scene (or of bounds) so that it touches the image's nearer
        edges `margin` in from them.

        The sphere is centred on the axis-aligned bounding box (centre ``(low + high)/2``) with the radius of the
        farthest point (for bounds ``[low, high]``: half the box's diagonal). Perspective:
        $distance = r / sin(atan((1 − 2·margin)·tan(half_fov)))$ where ``half_fov`` is the
        smaller of the vertical and horizontal half angles, so the sphere's image circle — the cone tangent to the
        sphere — spans $1 − 2·margin$ of the smaller image side. Orthographic: the view height is
        $2r / ((1 − 2·margin)·min(1, width/height))$ and the eye stands 3r back.

        Parameters
        ----------
        scene_or_bounds : Scene, SceneFile, Mesh, (2, 3) [low, high] or (N, 3) points
        direction : (3,) array_like, optional
            The line of sight (from the eye toward the centre). Default: the 3/4 view, the eye at azimuth 45°
            (between +z and +x) and 30° above the horizon.
        fovy : float
            Vertical field of view in radians (perspective).
        margin : float
            Fraction of the smaller image side left free on each side, in [0, 0.5).
        projection : "perspective" or "orthographic"
        width, height : int
            Image size in pixels.
        up : (3,) array_like
            View-up vector; when it is along `direction`, world −z (looking down) or +z (looking up) is used.

        Raises
        ------
        CameraError
            No points, non-finite bounds, a zero direction, fovy outside (0, π), margin outside [0, 0.5) or an
            unknown projection name.
        """
        where = "Camera.fit"
        points = _fit_points(scene_or_bounds, where)
        low, high = points.min(axis=0), points.max(axis=0)
        center = (low + high) / 2.0
        radius = float(np.sqrt(((points - center) ** 2).sum(axis=1).max()))
        radius = max(radius, 1e-6 * max(1.0, float(np.abs(center).max())))
        m = as_scalar(margin, "margin", where=where, error=CameraError)
        if not 0.0 <= m < 0.5:
            raise CameraError(f"{where}: margin = {m!r} is out of range; give a fraction in [0, 0.5)")
        if direction is None:
            a, e = math.radians(45.0), math.radians(30.0)
            line = -np.array([math.cos(e) * math.sin(a), math.sin(e), math.cos(e) * math.cos(a)])
        else:
            line = as_vector3(direction, "direction", where=where, error=CameraError)
            norm = float(np.linalg.norm(line))
            if not norm > 0.0:
                raise CameraError(f"{where}: direction = {describe(direction)} has zero length; give a line of sight")
            line = line / norm
        view_up = as_vector3(up, "up", where=where, error=CameraError)
        if np.linalg.norm(np.cross(view_up, line)) <= 1e-6 * float(np.linalg.norm(view_up)):
            view_up = np.array([0.0, 0.0, -1.0 if line[1] < 0 else 1.0])
        fill = 1.0 - 2.0 * m
        aspect = width / height if isinstance(width, int) and isinstance(height, int) and height > 0 else 1.0
        if projection == "perspective":
            f = as_scalar(fovy, "fovy", where=where, error=CameraError)
            if not 0.0 < f < math.pi:
                raise CameraError(f"{where}: fovy = {f!r} is out of range; give radians in (0, pi)")
            half = min(math.tan(f / 2.0), math.tan(f / 2.0) * aspect)
            distance = radius / math.sin(math.atan(fill * half)) if fill > 0.0 else radius * 1e6
            lens: Projection = Perspective(f, max(distance - 1.01 * radius, distance * 1e-4), distance + 1.01 * radius)
        elif projection == "orthographic":
            distance = 3.0 * radius
            lens = Orthographic(2.0 * radius / (fill * min(1.0, aspect)), radius, 5.0 * radius)
        else:
            raise CameraError(f"{where}: projection = {describe(projection)} is not 'perspective' or 'orthographic'")
        return cls.look_at(center - distance * line, center, view_up, lens, width, height)

    # --- other programs' conventions (frustum.camera_conventions holds the maths) -------------------------

    @classmethod
    def from_intrinsics(
        cls,
        K: ArrayLike,
        width: int,
        height: int,
        *,
        world_to_camera: ArrayLike | None = None,
        camera_to_world: ArrayLike | None = None,
        convention: Literal["opencv", "opengl"] = "opencv",
        near: float = 0.05,
        far: float = 100.0,
    ) -> Camera:
        """A pinhole camera from a 3x3 intrinsic matrix K and a pose, as OpenCV, COLMAP or nerfstudio give them.

        Pixel-centre rule: $u = fx·x/z + cx$ with the top-left pixel's centre at (0.5, 0.5) (COLMAP, pyrender;
        OpenCV counts centres at integers: for its calibrations pass cx + 0.5, cy + 0.5). An off-centre (cx, cy)
        gives an off-centre ``Frustum`` (``camera_conventions.near_plane_window``).

        Parameters
        ----------
        K : (3, 3) array_like
            [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] in pixels, fx, fy > 0, zero skew; v points down.
        width, height : int
            Image size in pixels.
        world_to_camera, camera_to_world : (4, 4) or (3, 4) array_like, keyword-only
            The pose as a rigid transform; give exactly one.
        convention : {"opencv", "opengl"}
            The pose's camera axes: "opencv" (x right, y down, looking down +z: OpenCV, COLMAP) or "opengl" (y up,
            looking down −z: nerfstudio, Blender, pyrender).
        near, far : float
            Clipping distances along the viewing axis, 0 < near < far (pyrender's defaults).

        Raises
        ------
        CameraError
            K not 3x3, fx or fy <= 0, nonzero skew, a pose that is not a rigid transform (the message names the
            failed check), both or neither pose given, or an unknown convention.
        """
        where = "Camera.from_intrinsics"
        fx, fy, cx, cy = conventions.pinhole_from_matrix(K, where)
        for name, value in (("width", width), ("height", height)):
            if isinstance(value, bool) or not isinstance(value, int | np.integer) or value <= 0:
                raise CameraError(f"{where}: {name} = {describe(value)} is not a positive integer (pixels)")
        eye, _u, v, n = conventions.view_from_pose(world_to_camera, camera_to_world, convention, where)
        near_ = as_scalar(near, "near", where=where, error=CameraError)
        left, right, bottom, top = conventions.near_plane_window(fx, fy, cx, cy, width, height, near_)
        frame = ViewFrame(eye, normal=n, up=v)
        return cls(frame, Frustum(left, right, bottom, top, near_, far), width, height)

    @classmethod
    def from_colmap(cls, camera: object, image: object, *, near: float = 0.05, far: float = 100.0) -> Camera:
        """The camera of a COLMAP image: `camera` a ``pycolmap.Camera`` or a cameras.txt row, `image` a
        ``pycolmap.Image`` or an images.txt row (world-to-camera quaternion and translation, OpenCV axes).

        Pixel-centre rule: COLMAP's, the top-left pixel's centre at (0.5, 0.5), as ``from_intrinsics``.
        Pinhole models only (SIMPLE_PINHOLE, PINHOLE); other models raise CameraError naming the model.
        """
        width, height, k = conventions.colmap_intrinsics(camera)
        pose = conventions.colmap_world_to_camera(image)
        return cls.from_intrinsics(k, width, height, world_to_camera=pose, convention="opencv", near=near, far=far)

    @classmethod
    def from_nerfstudio(
        cls, frame: dict, transforms: dict | None = None, *, near: float = 0.05, far: float = 100.0
    ) -> Camera:
        """The camera of one nerfstudio (or Blender NeRF) frame: its ``transform_matrix`` (camera-to-world,
        OpenGL axes) and intrinsics ``fl_x, fl_y, cx, cy, w, h`` from the frame or the file's top level
        (`transforms`, the parsed transforms.json; ``camera_angle_x`` stands in for ``fl_x``).

        Pixel-centre rule: nerfstudio's, the top-left pixel's centre at (0.5, 0.5), as ``from_intrinsics``.
        """
        where = "Camera.from_nerfstudio"
        if not isinstance(frame, dict) or "transform_matrix" not in frame:
            raise CameraError(f"{where}: frame = {describe(frame)} is not a dict with a 'transform_matrix'")
        width, height, k = conventions.nerfstudio_intrinsics(frame, transforms, where)
        return cls.from_intrinsics(k, width, height, camera_to_world=frame["transform_matrix"], convention="opengl",
                                   near=near, far=far)  # fmt: skip

    def intrinsics(self, width: int | None = None, height: int | None = None) -> NDArray[np.float64]:
        """The 3x3 K of this pinhole camera for a `width` x `height` image (default: the camera's own size).

        Pixel-centre rule: the top-left pixel's centre at (0.5, 0.5), as ``from_intrinsics``, which it inverts:
        $fx = W/2·P00$, $cx = W/2·(1 − P02)$, $fy = H/2·P11$, $cy = H/2·(1 + P12)$ for clip_from_view P.

        Raises
        ------
        CameraError
            If the projection is not a pinhole perspective (Perspective or Frustum).
        """
        w = self.width if width is None else width
        h = self.height if height is None else height
        aspect = w / h if isinstance(w, int) and isinstance(h, int) and h > 0 else 0.0
        return conventions.intrinsic_matrix(self.projection.matrix(aspect), w, h, "Camera.intrinsics")

    def world_to_camera(self, convention: Literal["opencv", "opengl"] = "opencv") -> Matrix4:
        """The 4x4 world-to-camera pose in OpenCV axes (x right, y down, looking down +z) or OpenGL ones (y up,
        looking down −z): ``from_intrinsics(camera.intrinsics(), W, H, world_to_camera=...)`` gives this camera back.
        """
        return conventions.world_to_camera(self.frame, convention)

    # --- matrices -----------------------------------------------------------------------------------------

    @property
    def aspect(self) -> float:
        """Image width / height."""
        return self.width / self.height

    @cached_property
    def view_matrix(self) -> Matrix4:
        """view_from_world, the frame's matrix."""
        return self.frame.matrix

    @cached_property
    def projection_matrix(self) -> Matrix4:
        """clip_from_view for this image's aspect (after z → −z for a left-handed frame)."""
        clip_from_view = self.projection.matrix(self.aspect)
        if self.frame.handedness == "left":
            clip_from_view = clip_from_view @ _FLIP_Z
        return read_only(clip_from_view)

    @cached_property
    def viewport_matrix(self) -> Matrix4:
        """window_from_ndc = ``viewport(0, 0, width, height)``: y up, depth in [0, 1]."""
        return read_only(viewport(0.0, 0.0, self.width, self.height))

    @cached_property
    def clip_from_world(self) -> Matrix4:
        """clip_from_view · view_from_world."""
        return read_only(self.projection_matrix @ self.view_matrix)

    @cached_property
    def world_from_window(self) -> Matrix4:
        """Inverse of window_from_ndc · clip_from_world (projective; divide by w after applying it)."""
        return read_only(np.linalg.inv(self.viewport_matrix @ self.clip_from_world))

    def steps(self) -> tuple[Step, ...]:
        """Every named matrix from world to window coordinates, first-applied first (the divide is implicit)."""
        projection_steps = self.projection.steps(self.aspect)
        if self.frame.handedness == "left":
            projection_steps = (Step("left-handed to right-handed view (z → −z)", _FLIP_Z.copy()), *projection_steps)
        return (
            *self.frame.steps,
            *projection_steps,
            Step("viewport: NDC to window coordinates", self.viewport_matrix),
        )

    # --- mapping points -----------------------------------------------------------------------------------

    def project(self, points: ArrayLike) -> Points:
        """Window coordinates of world points: x right in [0, width], **y up** in [0, height], depth in [0, 1].

        $window = window_from_ndc · (clip / w)$ with $clip = clip_from_view · view_from_world · P$; equal
        to glm ``project`` (OpenGL window, y up, depth (z_ndc + 1)/2). Pixel (i, j) has its center at
        (i + 0.5, j + 0.5); an image stored top row first shows it in row $height − 1 − j$. Points inside the
        view volume land inside the viewport with depth in [0, 1] (1 = far plane). Points on or behind the eye
        plane (w <= 0 under a perspective projection) have no image and come back as NaN rows; clip first.

        Parameters
        ----------
        points : (N, 3) or (3,) array_like
            World coordinates.

        Returns
        -------
        (N, 3) or (3,) float64
            (x_w, y_w, depth).

        References
        ----------
        [HB 10] "The Viewport Transformation and Three-Dimensional Screen Coordinates".
        """
        single = np.shape(points) == (3,)
        rows = as_points(np.atleast_2d(points) if single else points, where="Camera.project", error=CameraError)
        clip = rows @ self.clip_from_world[:, :3].T + self.clip_from_world[:, 3]
        window_h = clip @ self.viewport_matrix.T
        w = clip[:, 3]
        with np.errstate(divide="ignore", invalid="ignore"):
            window = window_h[:, :3] / w[:, None]
        window[w <= 0.0] = np.nan
        return window[0] if single else window

    def unproject(self, window: ArrayLike) -> Points:
        """World points whose window coordinates are `window`: the inverse of ``project``.

        $P = (window_from_world)⁻¹ · (x_w, y_w, depth, 1)$, then divide by w. Depth 0 gives the point on the
        near plane, 1 the point on the far plane; y is up, as in ``project`` (glm ``unProject``).

        Parameters
        ----------
        window : (N, 3) or (3,) array_like

        Raises
        ------
        CameraError
            If a window point maps to infinity (a depth that corresponds to the eye plane).
        """
        single, rows = _as_window_points(window, "window", "Camera.unproject", 3)
        world_h = rows @ self.world_from_window[:, :3].T + self.world_from_window[:, 3]
        at_infinity = np.flatnonzero(world_h[:, 3] == 0.0)
        if at_infinity.size:
            i = int(at_infinity[0])
            raise CameraError(
                f"Camera.unproject: window[{i}] = {describe(rows[i])} maps to a point at infinity (its depth "
                "lies on the eye plane); use depths in [0, 1]"
            )
        world = world_h[:, :3] / world_h[:, 3:]
        return world[0] if single else world

    def ray(self, pixel: ArrayLike) -> Ray:
        """World-space ray through window position `pixel` = (x, y), for picking.

        $origin = unproject(x, y, 0)$ on the near plane, $direction = unproject(x, y, 1) − origin$
        normalized. Window y is up; the center of pixel column i, row j (counted from the bottom) is
        (i + 0.5, j + 0.5), and row r counted from the top is y = height − r − 0.5. For a perspective camera
        the ray's line passes through the eye; for a parallel one its direction is the projection direction.

        Parameters
        ----------
        pixel : (2,) or (N, 2) array_like

        Returns
        -------
        Ray
            origin and unit direction, (3,) each for one pixel or (N, 3) for N.
        """
        single, rows = _as_window_points(pixel, "pixel", "Camera.ray", 2)
        near = np.column_stack([rows, np.zeros(len(rows))])
        far = np.column_stack([rows, np.ones(len(rows))])
        origin = self.unproject(near)
        direction = self.unproject(far) - origin
        direction /= np.linalg.norm(direction, axis=1)[:, None]
        return Ray(origin[0], direction[0]) if single else Ray(origin, direction)

    # --- vanishing points ---------------------------------------------------------------------------------

    def vanishing_point(self, direction: ArrayLike) -> NDArray[np.float64] | None:
        """Window (x, y) where projected world lines along `direction` meet, or None if they stay parallel.

        A direction is the point at infinity ``[d, 0]``; its image $h = clip_from_world · [d, 0]$ divides to
        ``h_xy / h_w``, mapped through the viewport. $h_w = 0$ (d parallel to the view plane, or any parallel
        projection) means the projected lines stay parallel: None. d and −d give the same point.

        Parameters
        ----------
        direction : (3,) array_like
            Any nonzero world direction.

        Returns
        -------
        (2,) float64 or None
            Window x, y (y up); it may lie outside the image.

        Raises
        ------
        CameraError
            If `direction` has zero length.

        References
        ----------
        [HB 10] "Perspective-Projection Vanishing Points"; [seed] "Vanishing points".
        """
        where = "Camera.vanishing_point"
        d = as_vector3(direction, "direction", where=where, error=CameraError)
        length = float(np.linalg.norm(d))
        if length == 0.0:
            raise CameraError(f"{where}: direction = {describe(d)} has zero length; give a nonzero direction")
        clip = self.clip_from_world[:, :3] @ (d / length)
        scale = float(np.linalg.norm(self.clip_from_world[3, :3]))
        if scale == 0.0 or abs(clip[3]) <= _VANISHING_TOLERANCE * scale:
            return None
        ndc_xy = clip[:2] / clip[3]
        return self.viewport_matrix[:2, :2] @ ndc_xy + self.viewport_matrix[:2, 3]

    def principal_vanishing_points(self) -> PrincipalVanishingPoints:
        """Vanishing points of the world x, y and z axes and their count: a 1-, 2- or 3-point perspective.

        The count is the number of principal axes that cut the view plane (not parallel to it): a view plane
        parallel to the xy plane gives one (z), one parallel to the y axis only gives two (x, z), a general
        orientation three. Parallel projections give 0.

        References
        ----------
        [HB 10] "Perspective-Projection Vanishing Points"; [seed] "Vanishing points" (one, two and three
        principal vanishing points).
        """
        points = [self.vanishing_point(axis) for axis in np.eye(3)]
        return PrincipalVanishingPoints(sum(p is not None for p in points), *points)


def _fit_points(value: object, where: str) -> NDArray[np.float64]:
    """World points whose bounds `Camera.fit` frames: a scene's placed vertices, a mesh's, or given points."""
    scene = getattr(value, "scene", value)  # a SceneFile holds its scene
    if hasattr(scene, "items") and not isinstance(scene, np.ndarray):
        chunks = [apply(item.world_from_model, item.mesh.vertices) for item in scene.items if item.mesh.vertex_count]
        for placed in getattr(scene, "point_clouds", ()):  # point clouds and splats: the corners of their boxes
            corners = np.array(np.meshgrid(*zip(*placed.geometry.bounds, strict=True))).reshape(3, -1).T
            chunks.append(apply(placed.world_from_model, corners))
        if not chunks:
            raise CameraError(f"{where}: the scene has no vertices; add a mesh before framing it")
        points = np.concatenate(chunks)
    elif hasattr(value, "vertices"):
        points = np.asarray(value.vertices, dtype=np.float64)
    else:
        try:
            points = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            points = np.empty(0)
        if points.ndim != 2 or points.shape[1] != 3 or len(points) == 0:
            raise CameraError(f"{where}: scene_or_bounds = {describe(value)} is not a scene, a mesh, [low, high] or "
                              "(N, 3) points")  # fmt: skip
    if len(points) == 0 or not np.isfinite(points).all():
        raise CameraError(f"{where}: the bounds are empty or not finite; give finite points")
    return points
