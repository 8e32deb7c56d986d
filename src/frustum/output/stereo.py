"""Stereo images: red/cyan anaglyphs, side-by-side and over-under pairs, and ``render_stereo`` (output layer).

The compositions work on the (H, W, 4) uint8 RGBA color buffers that ``render`` returns (``Frame.color``),
whose channels are linear RGB. An anaglyph codes the left image in the red channel and the right image in
green and blue, for red (left) / cyan (right) glasses:

* ``"color"``: ``(R_left, G_right, B_right)``, the full-color anaglyph;
* ``"gray"``: ``(Y_left, Y_right, Y_right)`` with the luma $Y = 0.299 R + 0.587 G + 0.114 B$ (ITU-R BT.601),
  no retinal rivalry between differently colored objects;
* ``"dubois"``: Dubois's least-squares projection $RGB = clip(M_left · RGB_left + M_right · RGB_right)$,
  which accounts for the transmission of real red/cyan filters (less ghosting).

Alpha of an anaglyph is the larger of the two alphas. Side-by-side puts the left image on the left (parallel
viewing) or on the right (``cross_eyed=True``); over-under puts the left image on top.

References
----------
[seed] "Three-dimensional and stereoscopic viewing"; E. Dubois, "A projection method to generate anaglyph
stereo images", Proc. IEEE ICASSP 2001 (the red/cyan matrices as published on the author's page).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import describe
from frustum.errors import OutputError
from frustum.frame import Frame
from frustum.render import render
from frustum.scene import Scene
from frustum.stereo import StereoCamera

__all__ = ["ANAGLYPH_METHODS", "STEREO_LAYOUTS", "anaglyph", "over_under", "render_stereo", "side_by_side"]

ANAGLYPH_METHODS = ("color", "gray", "dubois")
"""Anaglyph codings ``anaglyph`` accepts."""
STEREO_LAYOUTS = ("anaglyph", "side-by-side", "over-under")
"""Image layouts ``render_stereo`` accepts."""

_LUMA = np.array([0.299, 0.587, 0.114])
# Dubois's red/cyan least-squares matrices (rows: output R, G, B; columns: input R, G, B).
_DUBOIS_LEFT = np.array([[0.456, 0.500, 0.176], [-0.040, -0.038, -0.016], [-0.015, -0.021, -0.005]])
_DUBOIS_RIGHT = np.array([[-0.043, -0.088, -0.002], [0.378, 0.734, -0.018], [-0.072, -0.113, 1.226]])


def _as_rgba(value: ArrayLike, name: str, where: str) -> NDArray[np.uint8]:
    image = np.asarray(value)
    if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != 4:
        raise OutputError(
            f"{where}: {name} has dtype {image.dtype} and shape {image.shape}; expected an (H, W, 4) uint8 RGBA "
            "image (Frame.color)"
        )
    return image


def _pair(left: ArrayLike, right: ArrayLike, where: str) -> tuple[NDArray[np.uint8], NDArray[np.uint8]]:
    left_image, right_image = _as_rgba(left, "left", where), _as_rgba(right, "right", where)
    if left_image.shape != right_image.shape:
        raise OutputError(
            f"{where}: right has shape {right_image.shape} but left has {left_image.shape}; the two eyes' images "
            "must have the same size"
        )
    return left_image, right_image


def anaglyph(left: ArrayLike, right: ArrayLike, method: str = "color") -> NDArray[np.uint8]:
    """Red/cyan anaglyph of a stereo pair: the left image in red, the right one in green and blue.

    ``"color"``: ``(R_l, G_r, B_r)``; ``"gray"``: ``(Y_l, Y_r, Y_r)``, $Y = 0.299 R + 0.587 G + 0.114 B$;
    ``"dubois"``: $clip(M_l · rgb_l + M_r · rgb_r, 0, 1)$ with Dubois's least-squares matrices. Alpha is
    ``max(A_l, A_r)``.

    Parameters
    ----------
    left, right : (H, W, 4) uint8
        RGBA images of the left and right eye (``Frame.color``), the same size.
    method : {"color", "gray", "dubois"}

    Returns
    -------
    (H, W, 4) uint8

    Raises
    ------
    OutputError
        If an image is not (H, W, 4) uint8, the sizes differ, or the method is unknown.

    References
    ----------
    [seed] "Three-dimensional and stereoscopic viewing"; Dubois, ICASSP 2001.
    """
    where = "anaglyph"
    left_image, right_image = _pair(left, right, where)
    if not isinstance(method, str) or method not in ANAGLYPH_METHODS:
        raise OutputError(f"{where}: method = {describe(method)} is unknown; expected one of {list(ANAGLYPH_METHODS)}")
    out = np.empty_like(left_image)
    out[..., 3] = np.maximum(left_image[..., 3], right_image[..., 3])
    if method == "color":
        out[..., 0] = left_image[..., 0]
        out[..., 1:3] = right_image[..., 1:3]
        return out
    rgb_left = left_image[..., :3].astype(np.float64) / 255.0
    rgb_right = right_image[..., :3].astype(np.float64) / 255.0
    if method == "gray":
        luma_left, luma_right = rgb_left @ _LUMA, rgb_right @ _LUMA
        rgb = np.stack([luma_left, luma_right, luma_right], axis=-1)
    else:
        rgb = rgb_left @ _DUBOIS_LEFT.T + rgb_right @ _DUBOIS_RIGHT.T
    out[..., :3] = np.rint(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)
    return out


def side_by_side(left: ArrayLike, right: ArrayLike, cross_eyed: bool = False) -> NDArray[np.uint8]:
    """(H, 2W, 4) image: left | right for parallel (wall-eyed) viewing, right | left when `cross_eyed`.

    Raises
    ------
    OutputError
        If an image is not (H, W, 4) uint8 or the sizes differ.
    """
    left_image, right_image = _pair(left, right, "side_by_side")
    halves = (right_image, left_image) if cross_eyed else (left_image, right_image)
    return np.ascontiguousarray(np.concatenate(halves, axis=1))


def over_under(left: ArrayLike, right: ArrayLike) -> NDArray[np.uint8]:
    """(2H, W, 4) image: the left eye's image on top, the right eye's below (above-below format).

    Raises
    ------
    OutputError
        If an image is not (H, W, 4) uint8 or the sizes differ.
    """
    left_image, right_image = _pair(left, right, "over_under")
    return np.ascontiguousarray(np.concatenate((left_image, right_image), axis=0))


def render_stereo(
    scene: Scene,
    stereo_camera: StereoCamera,
    layout: str = "anaglyph",
    *,
    anaglyph_method: str = "color",
    cross_eyed: bool = False,
    **render_options: Any,
) -> Frame:
    """Render `scene` for both eyes of `stereo_camera` and compose one ``Frame`` in the given layout.

    ``"anaglyph"``: ``anaglyph(left, right, anaglyph_method)``, size (H, W), depth the per-pixel minimum of
    the two eyes' depths. ``"side-by-side"``: (H, 2W), left | right (right | left when `cross_eyed`).
    ``"over-under"``: (2H, W), left on top. The depth buffers (and the optional ``normals`` and ``object_id``
    buffers, when requested through `render_options`) are laid out like the colors; an anaglyph has none.

    Parameters
    ----------
    scene : Scene
    stereo_camera : StereoCamera
    layout : {"anaglyph", "side-by-side", "over-under"}
    anaglyph_method : {"color", "gray", "dubois"}
    cross_eyed : bool
        Side-by-side only: swap the halves for cross-eyed free viewing.
    **render_options
        Passed to ``frustum.render`` for each eye (shading, background, cull_back_faces, mode).

    Raises
    ------
    OutputError
        If `stereo_camera` is not a StereoCamera or `layout` / `anaglyph_method` is unknown; ``render`` raises
        for bad render options.
    """
    where = "render_stereo"
    if not isinstance(stereo_camera, StereoCamera):
        raise OutputError(
            f"{where}: stereo_camera = {describe(stereo_camera)} is not a StereoCamera; build one with "
            "StereoCamera(camera, eye_separation, convergence_distance)"
        )
    if not isinstance(layout, str) or layout not in STEREO_LAYOUTS:
        raise OutputError(f"{where}: layout = {describe(layout)} is unknown; expected one of {list(STEREO_LAYOUTS)}")
    if layout == "anaglyph" and (not isinstance(anaglyph_method, str) or anaglyph_method not in ANAGLYPH_METHODS):
        raise OutputError(
            f"{where}: anaglyph_method = {describe(anaglyph_method)} is unknown; expected one of "
            f"{list(ANAGLYPH_METHODS)}"
        )
    left = render(scene, stereo_camera.left, **render_options)
    right = render(scene, stereo_camera.right, **render_options)
    if layout == "anaglyph":
        return Frame(anaglyph(left.color, right.color, anaglyph_method), np.minimum(left.depth, right.depth))
    if layout == "side-by-side":
        first, second = (right, left) if cross_eyed else (left, right)
        axis = 1
    else:
        first, second, axis = left, right, 0
    extra = {
        name: np.concatenate([getattr(first, name), getattr(second, name)], axis=axis)
        for name in ("normals", "object_id")
        if getattr(first, name, None) is not None and getattr(second, name, None) is not None
    }
    color = np.concatenate([first.color, second.color], axis=axis)
    return Frame(color, np.concatenate([first.depth, second.depth], axis=axis), **extra)
