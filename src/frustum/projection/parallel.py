"""Parallel projections [HB 10]: orthographic (and the six multiviews), axonometric (isometric, dimetric, trimetric)
and oblique (cavalier, cabinet), each ``clip_from_view``."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from frustum._arrays import Matrix4, Vector3, as_vector3, describe
from frustum.errors import CameraError
from frustum.projection.checks import as_number, check_oblique_alpha, check_ordered, check_positive
from frustum.transforms import rotate_x, rotate_y

__all__ = [
    "CABINET_ALPHA",
    "ISOMETRIC_ROTATION_X",
    "MULTIVIEWS",
    "MultiView",
    "axonometric_rotation",
    "cabinet",
    "cavalier",
    "dimetric",
    "dimetric_rotation_x",
    "isometric",
    "multiview",
    "oblique",
    "oblique_from_vector",
    "oblique_normalized",
    "oblique_vector",
    "orthographic",
    "trimetric",
]


# Isometric tilt about x: sin(α) = tan(30°), α = 35.264°; with a 45° turn about y it foreshortens all three
# axes equally, to √(2/3).
ISOMETRIC_ROTATION_X = math.asin(math.tan(math.pi / 6))


# Cabinet projection: tan(α) = 2, α = 63.435°, receding lines drawn at half length (L1 = 1/tan α = 1/2).
CABINET_ALPHA = math.atan(2.0)


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
    xw_min, xw_max = check_ordered(left, right, "left", "right", where, "the clipping window")
    yw_min, yw_max = check_ordered(bottom, top, "bottom", "top", where, "the clipping window")
    near, far = check_ordered(near, far, "near", "far", where, "the view volume")
    z_near, z_far = -near, -far
    # fmt: off
    return np.array([
        [2 / (xw_max - xw_min), 0.0, 0.0, -(xw_max + xw_min) / (xw_max - xw_min)],
        [0.0, 2 / (yw_max - yw_min), 0.0, -(yw_max + yw_min) / (yw_max - yw_min)],
        [0.0, 0.0, -2 / (z_near - z_far), (z_near + z_far) / (z_near - z_far)],
        [0.0, 0.0, 0.0, 1.0],
    ])


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


def axonometric_rotation(rotation_y: float, rotation_x: float) -> Matrix4:
    """Rotation that turns an object for an axonometric view: first about y, then about x.

    $R = R_x(rotation_x) · R_y(rotation_y)$. An orthogonal projection of the rotated object onto the xy plane
    foreshortens the unit axes by ``f_i = |(R e_i)_xy|``, with $f_x² + f_y² + f_z² = 2$ for any rotation.

    References
    ----------
    [HB 10] "Axonometric and Isometric Orthogonal Projections"; [seed] "Axonometric and Isometric Orthogonal
    Projections".
    """
    return rotate_x(as_number(rotation_x, "rotation_x", "axonometric_rotation")) @ rotate_y(
        as_number(rotation_y, "rotation_y", "axonometric_rotation")
    )


def dimetric_rotation_x(ratio: float, where: str) -> float:
    ratio = as_number(ratio, "ratio", where)
    if not 0.0 < ratio < math.sqrt(2.0):
        raise CameraError(
            f"{where}: ratio = {ratio!r} is outside (0, sqrt(2)); the y foreshortening over the x and z "
            "foreshortening must lie strictly between 0 (plan view) and sqrt(2) (front view)"
        )
    # With R_y(45°): f_x = f_z = √((1 + sin²α)/2), f_y = cos α, so ratio² = 2(1 − s)/(1 + s), s = sin²α.
    return math.asin(math.sqrt((2.0 - ratio**2) / (2.0 + ratio**2)))


def _cube(size: float, where: str) -> Matrix4:
    half = check_positive(size, "size", where, " (half the edge of the view cube)")
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
    rotation = axonometric_rotation(math.pi / 4, dimetric_rotation_x(ratio, "dimetric"))
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
    z_vp = as_number(z_vp, "z_vp", where)
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


def oblique_vector(alpha: float, phi: float, where: str) -> Vector3:
    l1 = 1.0 / math.tan(check_oblique_alpha(alpha, where))
    phi = as_number(phi, "phi", where)
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
    vector = oblique_vector(alpha, phi, "oblique")
    return oblique_from_vector(vector, as_number(z_vp, "z_vp", "oblique"))


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
