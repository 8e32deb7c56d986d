"""The argument checks the projections share: numbers, ordered bounds, near and far, angles, the aspect."""

from __future__ import annotations

import math

from frustum._arrays import as_scalar
from frustum.errors import CameraError

__all__ = [
    "as_number",
    "centered_box",
    "check_aspect",
    "check_near_far",
    "check_oblique_alpha",
    "check_ordered",
    "check_positive",
]


def as_number(value: float, name: str, where: str) -> float:
    return as_scalar(value, name, where=where, error=CameraError)


def check_ordered(low: float, high: float, low_name: str, high_name: str, where: str, what: str) -> tuple[float, float]:
    low = as_number(low, low_name, where)
    high = as_number(high, high_name, where)
    if not low < high:
        raise CameraError(
            f"{where}: {low_name} = {low!r} is not less than {high_name} = {high!r}; "
            f"{what} needs {low_name} < {high_name}"
        )
    return low, high


def check_near_far(near: float, far: float, where: str) -> tuple[float, float]:
    """Positive near/far distances of a perspective projection: 0 < near < far."""
    near = as_number(near, "near", where)
    far = as_number(far, "far", where)
    if not near > 0.0:
        raise CameraError(
            f"{where}: near = {near!r} must be > 0 (near and far are positive distances from the eye, near < far)"
        )
    if not far > near:
        raise CameraError(
            f"{where}: far = {far!r} must be > near = {near!r} (near and far are positive distances, near < far)"
        )
    return near, far


def check_positive(value: float, name: str, where: str, what: str = "") -> float:
    number = as_number(value, name, where)
    if not number > 0.0:
        raise CameraError(f"{where}: {name} = {number!r} must be > 0{what}")
    return number


def check_oblique_alpha(alpha: float, where: str) -> float:
    alpha = as_number(alpha, "alpha", where)
    if not 0.0 < alpha < math.pi / 2:
        raise CameraError(
            f"{where}: alpha = {alpha!r} is outside (0, pi/2); the angle between the projection lines and the "
            "view plane must be strictly between 0 (lines in the plane) and pi/2 (orthogonal projection)"
        )
    return alpha


def check_aspect(aspect: float, where: str) -> float:
    return check_positive(aspect, "aspect", where, " (image width / height)")


def centered_box(height: float, near: float, far: float, where: str) -> tuple[float, float, float]:
    height = check_positive(height, "height", where, " (height of the view window in view units)")
    near, far = check_ordered(near, far, "near", "far", where, "the view volume")
    return height, near, far
