"""The viewport transformation: normalized device coordinates to window coordinates (``window_from_ndc``)."""

from __future__ import annotations

import numpy as np

from frustum._arrays import Matrix4, describe
from frustum.errors import CameraError
from frustum.projection.checks import as_number, check_positive

__all__ = ["viewport"]


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
    x = as_number(x, "x", where)
    y = as_number(y, "y", where)
    width = check_positive(width, "width", where, " (an empty viewport shows nothing); give a size in pixels")
    height = check_positive(height, "height", where, " (an empty viewport shows nothing); give a size in pixels")
    if np.shape(depth_range) != (2,):
        raise CameraError(
            f"{where}: depth_range = {describe(depth_range)} is not a pair; expected (near depth, far depth)"
        )
    d_near = as_number(depth_range[0], "depth_range[0]", where)
    d_far = as_number(depth_range[1], "depth_range[1]", where)
    # fmt: off
    return np.array([
        [width / 2, 0.0, 0.0, x + width / 2],
        [0.0, height / 2, 0.0, y + height / 2],
        [0.0, 0.0, (d_far - d_near) / 2, (d_far + d_near) / 2],
        [0.0, 0.0, 0.0, 1.0],
    ])
