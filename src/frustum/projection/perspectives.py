"""Perspective projections [HB 10]: symmetric (``perspective``), general frustum (``frustum``), onto a plane from a
projection reference point, and the general perspective normalization as named steps."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from frustum._arrays import Matrix4, as_vector3, describe
from frustum.errors import CameraError
from frustum.projection.checks import as_number, check_near_far, check_ordered, check_positive
from frustum.transforms import Step, compose, translate

__all__ = ["frustum", "general_perspective", "general_perspective_steps", "perspective", "perspective_onto_plane"]


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
    fovy = as_number(fovy, "fovy", where)
    if not 0.0 < fovy < math.pi:
        raise CameraError(
            f"{where}: fovy = {fovy!r} is outside (0, pi); the vertical field of view is a full angle in "
            "radians, strictly between 0 and pi"
        )
    aspect = check_positive(aspect, "aspect", where, " (width / height of the view window)")
    near, far = check_near_far(near, far, where)
    f = 1.0 / math.tan(fovy / 2.0)
    z_near, z_far = -near, -far
    # fmt: off
    return np.array([
        [f / aspect, 0.0, 0.0, 0.0],
        [0.0, f, 0.0, 0.0],
        [0.0, 0.0, (z_near + z_far) / (z_near - z_far), -2 * z_near * z_far / (z_near - z_far)],
        [0.0, 0.0, -1.0, 0.0],
    ])


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
    xw_min, xw_max = check_ordered(left, right, "left", "right", where, "the near-plane window")
    yw_min, yw_max = check_ordered(bottom, top, "bottom", "top", where, "the near-plane window")
    near, far = check_near_far(near, far, where)
    z_near, z_far = -near, -far
    # fmt: off
    return np.array([
        [-2 * z_near / (xw_max - xw_min), 0.0, (xw_max + xw_min) / (xw_max - xw_min), 0.0],
        [0.0, -2 * z_near / (yw_max - yw_min), (yw_max + yw_min) / (yw_max - yw_min), 0.0],
        [0.0, 0.0, (z_near + z_far) / (z_near - z_far), -2 * z_near * z_far / (z_near - z_far)],
        [0.0, 0.0, -1.0, 0.0],
    ])


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
    z_vp = as_number(z_vp, "z_vp", where)
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
    z_vp = as_number(z_vp, "z_vp", where)
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
    xw_min, xw_max = check_ordered(values[0], values[1], "xw_min", "xw_max", where, "the clipping window")
    yw_min, yw_max = check_ordered(values[2], values[3], "yw_min", "yw_max", where, "the clipping window")
    near, far = check_near_far(near, far, where)
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
