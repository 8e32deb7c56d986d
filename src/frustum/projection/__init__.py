"""Projections: view coordinates to clip coordinates, normalization to the canonical volume, and the viewport.

Every builder returns a fresh ``(4, 4) float64`` matrix named by the frames it maps. Projection builders
return ``clip_from_view``: view coordinates are right-handed with the camera at the origin looking down
−z_view; clip coordinates divide by w into the left-handed normalized cube [−1, 1]³ (NDC) with the near plane
at z_ndc = −1 and the far plane at +1, as in OpenGL and glm's ``*RH_NO`` builders. ``viewport`` returns
``window_from_ndc``.

``near`` and ``far`` are positive distances in front of the eye, as in glm. The textbook writes the same
planes as view-plane coordinates $z_near = −near$ and $z_far = −far$; each docstring gives both forms.

The frozen types ``Perspective``, ``Frustum``, ``Orthographic``, ``Oblique`` and ``Axonometric`` are what a
``Camera`` holds: each stores its parameters (validated once) and builds its matrix with ``.matrix(aspect)``,
where ``aspect`` = image width / height comes from the camera. ``.steps(aspect)`` lists the named matrices
whose product ``.matrix`` is, for ``trace``.

Why one module: every projection of the viewing chapter, builder and frozen type, side by side.

References: [HB 10] is Hearn & Baker, *Computer Graphics with OpenGL*, chapter 10, "Three-Dimensional
Viewing"; [seed] is the lecture notes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple, TypeAlias

import numpy as np
from numpy.typing import ArrayLike

from frustum._arrays import Matrix4, Vector3, as_scalar, as_vector3, describe
from frustum.errors import CameraError
from frustum.transforms import Step, compose, rotate_x, rotate_y, translate

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

# Isometric tilt about x: sin(α) = tan(30°), α = 35.264°; with a 45° turn about y it foreshortens all three
# axes equally, to √(2/3).
ISOMETRIC_ROTATION_X = math.asin(math.tan(math.pi / 6))
# Cabinet projection: tan(α) = 2, α = 63.435°, receding lines drawn at half length (L1 = 1/tan α = 1/2).
CABINET_ALPHA = math.atan(2.0)


# --- validation helpers -----------------------------------------------------------------------------------


def _number(value: float, name: str, where: str) -> float:
    return as_scalar(value, name, where=where, error=CameraError)


def _ordered(low: float, high: float, low_name: str, high_name: str, where: str, what: str) -> tuple[float, float]:
    low = _number(low, low_name, where)
    high = _number(high, high_name, where)
    if not low < high:
        raise CameraError(
            f"{where}: {low_name} = {low!r} is not less than {high_name} = {high!r}; "
            f"{what} needs {low_name} < {high_name}"
        )
    return low, high


def _near_far(near: float, far: float, where: str) -> tuple[float, float]:
    """Positive near/far distances of a perspective projection: 0 < near < far."""
    near = _number(near, "near", where)
    far = _number(far, "far", where)
    if not near > 0.0:
        raise CameraError(
            f"{where}: near = {near!r} must be > 0 (near and far are positive distances from the eye, near < far)"
        )
    if not far > near:
        raise CameraError(
            f"{where}: far = {far!r} must be > near = {near!r} (near and far are positive distances, near < far)"
        )
    return near, far


def _positive(value: float, name: str, where: str, what: str = "") -> float:
    number = _number(value, name, where)
    if not number > 0.0:
        raise CameraError(f"{where}: {name} = {number!r} must be > 0{what}")
    return number


def _oblique_alpha(alpha: float, where: str) -> float:
    alpha = _number(alpha, "alpha", where)
    if not 0.0 < alpha < math.pi / 2:
        raise CameraError(
            f"{where}: alpha = {alpha!r} is outside (0, pi/2); the angle between the projection lines and the "
            "view plane must be strictly between 0 (lines in the plane) and pi/2 (orthogonal projection)"
        )
    return alpha


# --- orthographic -----------------------------------------------------------------------------------------


def orthographic(left: float, right: float, bottom: float, top: float, near: float, far: float) -> Matrix4:
    """Clip-from-view matrix $M_{ortho,norm}$: the orthogonal view box onto the symmetric cube [−1, 1]³.

    $x_n = 2x/(xw_max − xw_min) − (xw_max + xw_min)/(xw_max − xw_min)$, alike for y, and
    $z_n = −2z/(z_near − z_far) + (z_near + z_far)/(z_near − z_far)$ with $z_near = −near$,
    $z_far = −far$; w stays 1. The target cube is left-handed (z_view = −near maps to −1, −far to +1).
    Equal to glm ``orthoRH_NO``.

    Parameters
    ----------
    left, right, bottom, top : float
        The clipping window xw_min, xw_max, yw_min, yw_max in view coordinates; left < right, bottom < top.
    near, far : float
        Distances of the near and far planes along the line of sight (−z_view), near < far. Unlike a
        perspective projection, a parallel one allows near <= 0 (a box reaching behind the eye).

    Raises
    ------
    CameraError
        If left >= right, bottom >= top, near >= far, or any argument is not finite.

    References
    ----------
    [HB 10] "Normalization Transformation for an Orthogonal Projection"; [seed] "Normalization Transformation
    for an Orthogonal Projection" (its matrix is garbled in the notes; this is the book's form).
    """
    where = "orthographic"
    xw_min, xw_max = _ordered(left, right, "left", "right", where, "the clipping window")
    yw_min, yw_max = _ordered(bottom, top, "bottom", "top", where, "the clipping window")
    near, far = _ordered(near, far, "near", "far", where, "the view volume")
    z_near, z_far = -near, -far
    # fmt: off
    return np.array([
        [2 / (xw_max - xw_min), 0.0, 0.0, -(xw_max + xw_min) / (xw_max - xw_min)],
        [0.0, 2 / (yw_max - yw_min), 0.0, -(yw_max + yw_min) / (yw_max - yw_min)],
        [0.0, 0.0, -2 / (z_near - z_far), (z_near + z_far) / (z_near - z_far)],
        [0.0, 0.0, 0.0, 1.0],
    ])
    # fmt: on


class MultiView(NamedTuple):
    """One multiview orthographic preset: the world direction the camera looks along, and its up vector."""

    name: str
    direction: tuple[float, float, float]
    up: tuple[float, float, float]


MULTIVIEWS: dict[str, MultiView] = {
    view.name: view
    for view in (
        # elevations: horizontal lines of sight, world y up
        MultiView("front", (0.0, 0.0, -1.0), (0.0, 1.0, 0.0)),
        MultiView("rear", (0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
        MultiView("right", (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
        MultiView("left", (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
        # plan views: vertical lines of sight; the object's front (+z) is drawn toward the bottom of the top
        # view and toward the top of the bottom view, so that x runs to the right in both
        MultiView("top", (0.0, -1.0, 0.0), (0.0, 0.0, -1.0)),
        MultiView("bottom", (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
    )
}
"""Front, rear, right and left side elevations and top/bottom plan views of an object whose front faces +z."""


def multiview(name: str) -> MultiView:
    """The multiview preset `name`: "front", "rear", "right", "left" (elevations) or "top", "bottom" (plans).

    A multiview drawing is a set of orthogonal projections along the principal axes. ``direction`` is the
    line of sight in world coordinates (the view-plane normal N is its negative), ``up`` the view-up vector V.
    The "right" elevation looks at the object's right side (+x), so its line of sight is −x.

    Raises
    ------
    CameraError
        If `name` is not one of the six presets.

    References
    ----------
    [HB 10] "Orthogonal Projections"; [seed] "Elevation and Plan View".
    """
    if name not in MULTIVIEWS:
        raise CameraError(f"multiview: name = {name!r} is unknown; expected one of {sorted(MULTIVIEWS)}")
    return MULTIVIEWS[name]


# --- axonometric ------------------------------------------------------------------------------------------


def axonometric_rotation(rotation_y: float, rotation_x: float) -> Matrix4:
    """Rotation that turns an object for an axonometric view: first about y, then about x.

    $R = R_x(rotation_x) · R_y(rotation_y)$. An orthogonal projection of the rotated object onto the xy plane
    foreshortens the unit axes by ``f_i = |(R e_i)_xy|``, with $f_x² + f_y² + f_z² = 2$ for any rotation.

    References
    ----------
    [HB 10] "Axonometric and Isometric Orthogonal Projections"; [seed] "Axonometric and Isometric Orthogonal
    Projections".
    """
    return rotate_x(_number(rotation_x, "rotation_x", "axonometric_rotation")) @ rotate_y(
        _number(rotation_y, "rotation_y", "axonometric_rotation")
    )


def _dimetric_rotation_x(ratio: float, where: str) -> float:
    ratio = _number(ratio, "ratio", where)
    if not 0.0 < ratio < math.sqrt(2.0):
        raise CameraError(
            f"{where}: ratio = {ratio!r} is outside (0, sqrt(2)); the y foreshortening over the x and z "
            "foreshortening must lie strictly between 0 (plan view) and sqrt(2) (front view)"
        )
    # With R_y(45°): f_x = f_z = √((1 + sin²α)/2), f_y = cos α, so ratio² = 2(1 − s)/(1 + s), s = sin²α.
    return math.asin(math.sqrt((2.0 - ratio**2) / (2.0 + ratio**2)))


def _cube(size: float, where: str) -> Matrix4:
    half = _positive(size, "size", where, " (half the edge of the view cube)")
    return orthographic(-half, half, -half, half, -half, half)


def isometric(size: float = 1.0) -> Matrix4:
    """Clip-from-world matrix of the isometric view of an object centered at the origin.

    $M = M_{ortho,norm} · R_x(35.264°) · R_y(45°)$ with $sin 35.264° = tan 30°$: the three principal axes make
    equal angles with the view plane and are all foreshortened by √(2/3) ≈ 0.8165 (before the normalization
    scale 1/size). The view volume is the cube [−size, size]³ around the origin.

    Raises
    ------
    CameraError
        If size <= 0.

    References
    ----------
    [HB 10] "Axonometric and Isometric Orthogonal Projections"; [seed] "Isometric" (α = β = γ).
    """
    return _cube(size, "isometric") @ axonometric_rotation(math.pi / 4, ISOMETRIC_ROTATION_X)


def dimetric(ratio: float, size: float = 1.0) -> Matrix4:
    """Clip-from-world matrix of a dimetric view: x and z foreshortened equally, y by `ratio` times as much.

    $M = M_{ortho,norm} · R_x(α) · R_y(45°)$ with $sin²α = (2 − ratio²)/(2 + ratio²)$, so that
    $f_x = f_z = √((1 + sin²α)/2)$ and $f_y = cos α = ratio · f_x$. $ratio = 1$ is the isometric view;
    $ratio = 0.5$ draws verticals at half the scale of the two horizontal axes.

    Parameters
    ----------
    ratio : float
        f_y / f_x, in (0, √2).
    size : float
        Half the edge of the view cube [−size, size]³ around the origin, > 0.

    Raises
    ------
    CameraError
        If ratio is outside (0, √2) or size <= 0.

    References
    ----------
    [HB 10] "Axonometric and Isometric Orthogonal Projections"; [seed] "Symmetric" (the notes' name for
    dimetric: two of the three angles equal).
    """
    rotation = axonometric_rotation(math.pi / 4, _dimetric_rotation_x(ratio, "dimetric"))
    return _cube(size, "dimetric") @ rotation


def trimetric(rotation_y: float, rotation_x: float, size: float = 1.0) -> Matrix4:
    """Clip-from-world matrix of a trimetric view: rotate about y, then about x, then project orthogonally.

    $M = M_{ortho,norm} · R_x(rotation_x) · R_y(rotation_y)$; the foreshortenings ``f_i = |(R e_i)_xy|`` are all
    different for general angles ($rotation_y = 45°$ gives a dimetric view, plus $rotation_x = 35.264°$ the
    isometric one).

    Raises
    ------
    CameraError
        If an angle is not finite or size <= 0.

    References
    ----------
    [HB 10] "Axonometric and Isometric Orthogonal Projections"; [seed] "Torsometric" (the notes' name for
    trimetric: all three angles different).
    """
    return _cube(size, "trimetric") @ axonometric_rotation(rotation_y, rotation_x)


# --- oblique ----------------------------------------------------------------------------------------------


def oblique_from_vector(projection_vector: ArrayLike, z_vp: float = 0.0) -> Matrix4:
    """The seed's M_oblique: shear view space along the projection vector Vp onto orthogonal coordinates.

    $x_p = x + (z_vp − z)·Vpx/Vpz$, $y_p = y + (z_vp − z)·Vpy/Vpz$, z unchanged (kept for depth), so an
    orthogonal projection of the sheared points is the oblique projection onto the view plane z = z_vp.

    Parameters
    ----------
    projection_vector : (3,) array_like
        Vp, the direction of the projection lines in view coordinates; Vpz != 0.
    z_vp : float
        View-plane position on the z_view axis; points on it do not move.

    Raises
    ------
    CameraError
        If Vpz = 0 (projection lines parallel to the view plane never reach it).

    References
    ----------
    [HB 10] "Oblique Parallel-Projection Transformation Matrix"; [seed] "Oblique Projection".
    """
    where = "oblique_from_vector"
    vp_x, vp_y, vp_z = as_vector3(projection_vector, "projection_vector", where=where, error=CameraError).tolist()
    z_vp = _number(z_vp, "z_vp", where)
    if vp_z == 0.0:
        raise CameraError(
            f"{where}: projection_vector = {describe((vp_x, vp_y, vp_z))} is parallel to the view plane "
            "(Vpz = 0); the projection lines must cross the view plane (Vpz != 0)"
        )
    # fmt: off
    return np.array([
        [1.0, 0.0, -vp_x / vp_z, z_vp * vp_x / vp_z],
        [0.0, 1.0, -vp_y / vp_z, z_vp * vp_y / vp_z],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ])
    # fmt: on


def _oblique_vector(alpha: float, phi: float, where: str) -> Vector3:
    l1 = 1.0 / math.tan(_oblique_alpha(alpha, where))
    phi = _number(phi, "phi", where)
    return np.array([l1 * math.cos(phi), l1 * math.sin(phi), 1.0])


def oblique(alpha: float, phi: float, z_vp: float = 0.0) -> Matrix4:
    """M_oblique for projection lines at angle `alpha` to the view plane, receding edges drawn at angle `phi`.

    $x_p = x + L1·(z_vp − z)·cos φ$, $y_p = y + L1·(z_vp − z)·sin φ$ with $L1 = 1/tan α$ (Hearn & Baker's
    sign: a point a distance d behind the view plane moves by L1·d along the direction φ). This is
    $oblique_from_vector((L1 cos φ, L1 sin φ, 1), z_vp)$. A unit edge perpendicular to the view plane is
    drawn with length L1 at angle φ from the x axis.

    Parameters
    ----------
    alpha : float
        Angle between the projection lines and the view plane, radians, in (0, π/2).
    phi : float
        Direction of the receding lines in the view plane, radians from the x axis (30° or 45° are usual).
    z_vp : float
        View-plane position on the z_view axis.

    Raises
    ------
    CameraError
        If alpha is outside (0, π/2) (0: lines in the plane; π/2: an orthogonal projection).

    References
    ----------
    [HB 10] "Oblique Parallel Projections in Drafting and Design", "Oblique Parallel-Projection Vector";
    [seed] "Oblique Projection".
    """
    vector = _oblique_vector(alpha, phi, "oblique")
    return oblique_from_vector(vector, _number(z_vp, "z_vp", "oblique"))


def cavalier(phi: float = math.pi / 4, z_vp: float = 0.0) -> Matrix4:
    """Cavalier projection: $oblique(α = 45°, phi)$, L1 = 1, receding edges drawn at full length.

    References
    ----------
    [HB 10] "Cavalier and Cabinet Oblique Parallel Projections".
    """
    return oblique(math.pi / 4, phi, z_vp)


def cabinet(phi: float = math.pi / 4, z_vp: float = 0.0) -> Matrix4:
    """Cabinet projection: $oblique(α = atan 2 ≈ 63.43°, phi)$, L1 = 1/2, receding edges drawn at half length.

    References
    ----------
    [HB 10] "Cavalier and Cabinet Oblique Parallel Projections".
    """
    return oblique(CABINET_ALPHA, phi, z_vp)


def oblique_normalized(
    projection_vector: ArrayLike,
    left: float,
    right: float,
    bottom: float,
    top: float,
    near: float,
    far: float,
    z_vp: float = 0.0,
) -> Matrix4:
    """Clip-from-view matrix of an oblique parallel projection: $M_{oblique,norm} = M_{ortho,norm} · M_oblique$.

    The shear turns the oblique view volume (a parallelepiped along Vp) into the orthogonal box
    [left, right] × [bottom, top] × [−far, −near], which ``orthographic`` maps onto [−1, 1]³.

    Raises
    ------
    CameraError
        As ``oblique_from_vector`` and ``orthographic``.

    References
    ----------
    [HB 10] "Normalization Transformation for an Oblique Parallel Projection"; [seed] "Normalization
    transformation for an oblique parallel projection".
    """
    shear = oblique_from_vector(projection_vector, z_vp)
    return orthographic(left, right, bottom, top, near, far) @ shear


# --- perspective ------------------------------------------------------------------------------------------


def perspective(fovy: float, aspect: float, near: float, far: float) -> Matrix4:
    """Clip-from-view matrix of a symmetric perspective frustum (right-handed view, NDC z in [−1, 1]).

    With $f = cot(fovy/2)$: $x_c = (f/aspect)·x$, $y_c = f·y$,
    $z_c = (z_near + z_far)/(z_near − z_far)·z − 2·z_near·z_far/(z_near − z_far)$, $w_c = −z$, where
    $z_near = −near$, $z_far = −far$. Equal to glm ``perspectiveRH_NO``, and to ``frustum`` with
    $top = near·tan(fovy/2)$, $right = aspect·top$.

    Parameters
    ----------
    fovy : float
        Full vertical field of view in radians, 0 < fovy < π.
    aspect : float
        Width / height of the view window, > 0.
    near, far : float
        Positive distances from the eye to the clipping planes, 0 < near < far.

    Raises
    ------
    CameraError
        If any argument is outside the ranges above.

    References
    ----------
    [HB 10] "Symmetric Perspective-Projection Frustum", "Normalized Perspective-Projection Transformation
    Coordinates".
    """
    where = "perspective"
    fovy = _number(fovy, "fovy", where)
    if not 0.0 < fovy < math.pi:
        raise CameraError(
            f"{where}: fovy = {fovy!r} is outside (0, pi); the vertical field of view is a full angle in "
            "radians, strictly between 0 and pi"
        )
    aspect = _positive(aspect, "aspect", where, " (width / height of the view window)")
    near, far = _near_far(near, far, where)
    f = 1.0 / math.tan(fovy / 2.0)
    z_near, z_far = -near, -far
    # fmt: off
    return np.array([
        [f / aspect, 0.0, 0.0, 0.0],
        [0.0, f, 0.0, 0.0],
        [0.0, 0.0, (z_near + z_far) / (z_near - z_far), -2 * z_near * z_far / (z_near - z_far)],
        [0.0, 0.0, -1.0, 0.0],
    ])
    # fmt: on


def frustum(left: float, right: float, bottom: float, top: float, near: float, far: float) -> Matrix4:
    """Clip-from-view matrix of a general (possibly oblique, off-axis) perspective frustum.

    $x_c = (−2z_near·x + (xw_max + xw_min)·z)/(xw_max − xw_min)$, alike for y, $z_c$ and $w_c = −z$ as in
    ``perspective``; the window [left, right] × [bottom, top] lies on the near plane $z = z_near = −near$.
    Off-center windows (left != −right) are the oblique frusta used for stereo pairs. Equal to glm
    ``frustumRH_NO``, and to ``general_perspective`` with the PRP at the origin and z_vp = −near.

    Parameters
    ----------
    left, right, bottom, top : float
        The window on the near plane, view coordinates; left < right, bottom < top.
    near, far : float
        Positive distances to the clipping planes, 0 < near < far.

    Raises
    ------
    CameraError
        If the window is empty or inverted, or near/far are outside the ranges above.

    References
    ----------
    [HB 10] "Oblique Perspective-Projection Frustum", "Normalized Perspective-Projection Transformation
    Coordinates".
    """
    where = "frustum"
    xw_min, xw_max = _ordered(left, right, "left", "right", where, "the near-plane window")
    yw_min, yw_max = _ordered(bottom, top, "bottom", "top", where, "the near-plane window")
    near, far = _near_far(near, far, where)
    z_near, z_far = -near, -far
    # fmt: off
    return np.array([
        [-2 * z_near / (xw_max - xw_min), 0.0, (xw_max + xw_min) / (xw_max - xw_min), 0.0],
        [0.0, -2 * z_near / (yw_max - yw_min), (yw_max + yw_min) / (yw_max - yw_min), 0.0],
        [0.0, 0.0, (z_near + z_far) / (z_near - z_far), -2 * z_near * z_far / (z_near - z_far)],
        [0.0, 0.0, -1.0, 0.0],
    ])
    # fmt: on


def perspective_onto_plane(prp: ArrayLike, z_vp: float) -> Matrix4:
    """The seed's parametric perspective projection onto the view plane z = z_vp, as a homogeneous matrix.

    Along the line from P to the projection reference point PRP, $P' = P − (P − PRP)·u$; where it meets the
    view plane, $u = (z_vp − z)/(z_prp − z)$, so
    $x_p = (x·(z_prp − z_vp) + x_prp·(z_vp − z))/(z_prp − z)$ (alike for y) and $z_p = z_vp$.
    Homogeneous form: $h = z_prp − z$,
    $M_pers = [[d_p, 0, −x_prp, x_prp·z_vp], [0, d_p, −y_prp, y_prp·z_vp], [0, 0, −z_vp, z_vp·z_prp],
    [0, 0, −1, z_prp]]$ with $d_p = z_prp − z_vp$. The depth is lost; ``general_perspective`` keeps it.

    Parameters
    ----------
    prp : (3,) array_like
        Projection reference point (center of projection) in view coordinates.
    z_vp : float
        View-plane position on the z_view axis, != z_prp.

    Raises
    ------
    CameraError
        If z_vp = z_prp (the center of projection lies in the view plane).

    References
    ----------
    [HB 10] "Perspective-Projection Transformation Coordinates", "Perspective-Projection Transformation
    Matrix"; [seed] "Perspective - Projection Transformation Coordinates".
    """
    where = "perspective_onto_plane"
    x_prp, y_prp, z_prp = as_vector3(prp, "prp", where=where, error=CameraError).tolist()
    z_vp = _number(z_vp, "z_vp", where)
    if z_vp == z_prp:
        raise CameraError(
            f"{where}: z_vp = {z_vp!r} equals the PRP's z = {z_prp!r}; the view plane must not pass through "
            "the center of projection"
        )
    d_p = z_prp - z_vp
    # fmt: off
    return np.array([
        [d_p, 0.0, -x_prp, x_prp * z_vp],
        [0.0, d_p, -y_prp, y_prp * z_vp],
        [0.0, 0.0, -z_vp, z_vp * z_prp],
        [0.0, 0.0, -1.0, z_prp],
    ])
    # fmt: on


def general_perspective_steps(
    prp: ArrayLike, z_vp: float, window: ArrayLike, near: float, far: float
) -> tuple[Step, ...]:
    """The seed's general perspective normalization, step by step, first-applied first.

    With the projection reference point PRP, the view plane z = z_vp and the clipping window
    (xw_min, xw_max, yw_min, yw_max) on it:

    1. $T(−PRP)$: move the PRP to the origin (window and view plane move with it: $z'_vp = z_vp − z_prp$).
    2. ``M_zshear``: $x' = x + sh_zx·z$, $y' = y + sh_zy·z$ with $sh_zx = −(xw_min + xw_max)/(2z'_vp)$,
       $sh_zy = −(yw_min + yw_max)/(2z'_vp)$ (window relative to the PRP): the frustum centerline, from the
       PRP through the window center, becomes the z axis.
    3. ``M_pers``: $x_h = −z'_vp·x$, $y_h = −z'_vp·y$, $z_h = s_z·z + t_z$, $h = −z$ with
       $s_z = (z_near + z_far)/(z_near − z_far)$, $t_z = −2·z_near·z_far/(z_near − z_far)$: the perspective
       transformation onto the view plane, keeping depth (near → −1, far → +1 after the divide).
    4. $M_xyscale = S(2/(xw_max − xw_min), 2/(yw_max − yw_min), 1)$: the symmetric frustum becomes the
       canonical cube [−1, 1]³.

    Parameters
    ----------
    prp : (3,) array_like
        Projection reference point in view coordinates.
    z_vp : float
        View-plane position, z_vp < z_prp (the view plane lies in front of the PRP, which looks down −z).
    window : (4,) array_like
        (xw_min, xw_max, yw_min, yw_max) on the view plane, view coordinates; min < max.
    near, far : float
        Positive distances of the clipping planes in front of the PRP, 0 < near < far; in the PRP-centered
        coordinates of step 3 they are $z_near = −near$, $z_far = −far$ (in view coordinates
        $z_prp − near$ and $z_prp − far$).

    Raises
    ------
    CameraError
        If z_vp >= z_prp, the window is empty, or near/far are out of range.

    References
    ----------
    [HB 10] "Perspective-Projection Transformation Matrix", "Oblique Perspective-Projection Frustum",
    "Normalized Perspective-Projection Transformation Coordinates"; [seed] "View Volume" (producing a
    canonical view volume for a perspective projection: step 1 shear, step 2 scale).
    """
    where = "general_perspective"
    center = as_vector3(prp, "prp", where=where, error=CameraError)
    z_vp = _number(z_vp, "z_vp", where)
    if not z_vp < center[2]:
        raise CameraError(
            f"{where}: z_vp = {z_vp!r} is not less than the PRP's z = {float(center[2])!r}; the view plane must lie "
            "in front of the projection reference point (z_vp < z_prp)"
        )
    values = np.asarray(window, dtype=object)
    if values.shape != (4,):
        raise CameraError(
            f"{where}: window = {describe(window)} has shape {values.shape}; expected (xw_min, xw_max, yw_min, yw_max)"
        )
    xw_min, xw_max = _ordered(values[0], values[1], "xw_min", "xw_max", where, "the clipping window")
    yw_min, yw_max = _ordered(values[2], values[3], "yw_min", "yw_max", where, "the clipping window")
    near, far = _near_far(near, far, where)
    z_vp_rel = z_vp - center[2]
    x_lo, x_hi = xw_min - center[0], xw_max - center[0]
    y_lo, y_hi = yw_min - center[1], yw_max - center[1]
    shear = np.eye(4)
    shear[0, 2] = -(x_lo + x_hi) / (2 * z_vp_rel)
    shear[1, 2] = -(y_lo + y_hi) / (2 * z_vp_rel)
    z_near, z_far = -near, -far
    # fmt: off
    pers = np.array([
        [-z_vp_rel, 0.0, 0.0, 0.0],
        [0.0, -z_vp_rel, 0.0, 0.0],
        [0.0, 0.0, (z_near + z_far) / (z_near - z_far), -2 * z_near * z_far / (z_near - z_far)],
        [0.0, 0.0, -1.0, 0.0],
    ])
    # fmt: on
    xy_scale = np.diag([2 / (xw_max - xw_min), 2 / (yw_max - yw_min), 1.0, 1.0])
    return (
        Step("translate the projection reference point to the origin", translate(*-center)),
        Step("shear the frustum centerline onto the z axis", shear),
        Step("perspective transformation onto the view plane, keeping depth", pers),
        Step("scale x and y to the canonical view volume", xy_scale),
    )


def general_perspective(prp: ArrayLike, z_vp: float, window: ArrayLike, near: float, far: float) -> Matrix4:
    """Clip-from-view matrix of the seed's general perspective: $M_xyscale · M_pers · M_zshear · T(−PRP)$.

    ``general_perspective_steps`` explains each factor and the parameters; their product maps the frustum
    from the PRP through the window onto [−1, 1]³ (near → −1, far → +1).

    References
    ----------
    [HB 10] "Normalized Perspective-Projection Transformation Coordinates"; [seed] "View Volume".
    """
    return compose(*(step.matrix for step in general_perspective_steps(prp, z_vp, window, near, far)))


# --- viewport ---------------------------------------------------------------------------------------------


def viewport(x: float, y: float, width: float, height: float, depth_range: tuple[float, float] = (0.0, 1.0)) -> Matrix4:
    """Window-from-NDC matrix: the canonical cube [−1, 1]³ onto the viewport rectangle and the depth range.

    $x_w = x + width·(x_n + 1)/2$, $y_w = y + height·(y_n + 1)/2$,
    $z_w = d_near + (d_far − d_near)·(z_n + 1)/2$. Window y points up (OpenGL, glm ``project``); window
    coordinates are continuous, with pixel (i, j) covering [x + i, x + i + 1) × [y + j, y + j + 1) and its
    center at the half-integers (x + i + 0.5, y + j + 0.5). NDC x = −1 is the left edge of pixel 0, not its
    center. Depth 1 is the far plane.

    Parameters
    ----------
    x, y : float
        Lower-left corner of the viewport in window coordinates.
    width, height : float
        Size in pixels, > 0.
    depth_range : (float, float)
        Window depth of the near and far planes, (0, 1) by default (glDepthRange).

    Raises
    ------
    CameraError
        If width or height <= 0, or any value is not finite.

    References
    ----------
    [HB 10] "The Viewport Transformation and Three-Dimensional Screen Coordinates".
    """
    where = "viewport"
    x = _number(x, "x", where)
    y = _number(y, "y", where)
    width = _positive(width, "width", where, " (an empty viewport shows nothing); give a size in pixels")
    height = _positive(height, "height", where, " (an empty viewport shows nothing); give a size in pixels")
    if np.shape(depth_range) != (2,):
        raise CameraError(
            f"{where}: depth_range = {describe(depth_range)} is not a pair; expected (near depth, far depth)"
        )
    d_near = _number(depth_range[0], "depth_range[0]", where)
    d_far = _number(depth_range[1], "depth_range[1]", where)
    # fmt: off
    return np.array([
        [width / 2, 0.0, 0.0, x + width / 2],
        [0.0, height / 2, 0.0, y + height / 2],
        [0.0, 0.0, (d_far - d_near) / 2, (d_far + d_near) / 2],
        [0.0, 0.0, 0.0, 1.0],
    ])
    # fmt: on


# --- projection types held by a Camera --------------------------------------------------------------------


def _aspect(aspect: float, where: str) -> float:
    return _positive(aspect, "aspect", where, " (image width / height)")


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
        return perspective(self.fovy, _aspect(aspect, "Perspective.matrix"), self.near, self.far)

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
        _aspect(aspect, "Frustum.matrix")
        return frustum(self.left, self.right, self.bottom, self.top, self.near, self.far)

    def steps(self, aspect: float) -> tuple[Step, ...]:
        """The named matrices of ``matrix(aspect)``, first-applied first."""
        return (Step("oblique perspective projection and normalization", self.matrix(aspect)),)


def _centered_box(height: float, near: float, far: float, where: str) -> tuple[float, float, float]:
    height = _positive(height, "height", where, " (height of the view window in view units)")
    near, far = _ordered(near, far, "near", "far", where, "the view volume")
    return height, near, far


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
        values = _centered_box(self.height, self.near, self.far, "Orthographic")
        for name, value in zip(("height", "near", "far"), values, strict=True):
            object.__setattr__(self, name, value)

    def matrix(self, aspect: float) -> Matrix4:
        """Clip-from-view matrix $M_{ortho,norm}$ for an image of the given width / height."""
        half_width = self.height * _aspect(aspect, "Orthographic.matrix") / 2
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
        _oblique_vector(self.alpha, self.phi, "Oblique")
        values = _centered_box(self.height, self.near, self.far, "Oblique")
        for name, value in zip(("height", "near", "far"), values, strict=True):
            object.__setattr__(self, name, value)
        z_vp = -(self.near + self.far) / 2 if self.z_vp is None else _number(self.z_vp, "z_vp", "Oblique")
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
        half_width = self.height * _aspect(aspect, "Oblique.matrix") / 2
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
        values = _centered_box(self.height, self.near, self.far, "Axonometric")
        for name, value in zip(("height", "near", "far"), values, strict=True):
            object.__setattr__(self, name, value)
        pivot = (self.near + self.far) / 2 if self.pivot is None else _number(self.pivot, "pivot", "Axonometric")
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
        return cls(math.pi / 4, _dimetric_rotation_x(ratio, "Axonometric.dimetric"), height, near, far)

    @classmethod
    def trimetric(cls, rotation_y: float, rotation_x: float, height: float, near: float, far: float) -> Axonometric:
        """Trimetric view with the given rotations, as ``trimetric``."""
        return cls(rotation_y, rotation_x, height, near, far)

    def steps(self, aspect: float) -> tuple[Step, ...]:
        """Rotation about the pivot, then $M_{ortho,norm}$, first-applied first."""
        assert self.pivot is not None  # set in __post_init__
        rotation = translate(0.0, 0.0, -self.pivot) @ axonometric_rotation(self.rotation_y, self.rotation_x)
        rotation = rotation @ translate(0.0, 0.0, self.pivot)
        half_width = self.height * _aspect(aspect, "Axonometric.matrix") / 2
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
