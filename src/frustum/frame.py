"""The rendered image: an 8-bit RGBA color buffer and a float32 depth buffer, top row first."""

from __future__ import annotations

import io
import os
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import describe
from frustum.errors import FrustumError, OutputError

__all__ = ["Frame", "background_bytes"]


@dataclass(frozen=True, eq=False)
class Frame:
    """What ``render`` returns: ``color`` (H, W, 4) uint8 RGBA and ``depth`` (H, W) float32, top row first.

    Row ``r`` of both arrays is window row $y_w = H − 1 − r$ (OpenGL's readback flipped vertically, the way
    images are stored). ``depth`` is window depth in [0, 1], 1.0 where nothing was drawn. Color is linear RGB,
    not sRGB-encoded unless asked for. Optional buffers (``render(..., buffers=...)``): ``normals`` (H, W, 3)
    float32 unit world normals (0 where nothing was drawn) and ``object_id`` (H, W) int32, the index of the
    scene item seen at each pixel (−1 for background); ``position`` (H, W, 3) float32 world points of the nearest
    opaque surface (NaN where nothing was drawn) and ``shadow`` (H, W, L) float32, the fraction of each of the L
    shadow-casting lights reaching the pixel (1 lit, 0 in shadow, NaN where nothing was drawn; lights in
    ``Scene.world_lights`` order: the root's first, then those on nodes). Ground truth (``render.ground_truth``):
    ``instance`` (H, W) int32 (``object_id`` by its dataset name), ``semantic`` (H, W) int32 class ids (0 background),
    ``amodal`` (K, H, W) bool per-item silhouettes ignoring occluders with ``visibility`` (K,) float64 visible /
    amodal pixels (NaN outside the view), ``object_coords`` and ``nocs`` (H, W, 3) float32 model and normalized
    object coordinates (NaN on background), ``flow`` (H, W, 2) float32 pixels to the next frame (x right, y down)
    and ``flow_occluded`` (H, W) bool. All arrays are read-only. ``stats``:
    the visible-surface method's counts (``render(..., method=...)``; spans, areas per level, depth tests,
    fragments per pixel …), with ``stats["method"]`` its name, or None where none were asked for.
    """

    color: NDArray[np.uint8]
    depth: NDArray[np.float32]
    normals: NDArray[np.float32] | None = None
    object_id: NDArray[np.int32] | None = None
    stats: dict | None = None
    position: NDArray[np.float32] | None = None
    shadow: NDArray[np.float32] | None = None
    instance: NDArray[np.int32] | None = None
    semantic: NDArray[np.int32] | None = None
    amodal: NDArray[np.bool_] | None = None
    visibility: NDArray[np.float64] | None = None
    object_coords: NDArray[np.float32] | None = None
    nocs: NDArray[np.float32] | None = None
    flow: NDArray[np.float32] | None = None
    flow_occluded: NDArray[np.bool_] | None = None

    def __post_init__(self) -> None:
        color = np.ascontiguousarray(self.color)
        depth = np.ascontiguousarray(self.depth)
        if color.dtype != np.uint8 or color.ndim != 3 or color.shape[2] != 4:
            raise OutputError(
                f"Frame: color has dtype {color.dtype} and shape {color.shape}; expected (H, W, 4) uint8 RGBA"
            )
        if depth.dtype != np.float32 or depth.shape != color.shape[:2]:
            raise OutputError(
                f"Frame: depth has dtype {depth.dtype} and shape {depth.shape}; expected {color.shape[:2]} float32"
            )
        lights = None if self.shadow is None else np.shape(self.shadow)[2:3]
        items = None if self.amodal is None else np.shape(self.amodal)[:1]
        for name, dtype, shape in (
            ("normals", np.float32, (*depth.shape, 3)), ("object_id", np.int32, depth.shape),
            ("position", np.float32, (*depth.shape, 3)),
            ("shadow", np.float32, (*depth.shape, *(lights or (-1,)))),
            ("instance", np.int32, depth.shape), ("semantic", np.int32, depth.shape),
            ("amodal", np.bool_, (*(items or (-1,)), *depth.shape)), ("visibility", np.float64, items or (-1,)),
            ("object_coords", np.float32, (*depth.shape, 3)), ("nocs", np.float32, (*depth.shape, 3)),
            ("flow", np.float32, (*depth.shape, 2)), ("flow_occluded", np.bool_, depth.shape),
        ):  # fmt: skip
            value = getattr(self, name)
            if value is None:
                continue
            value = np.ascontiguousarray(value)
            if value.dtype != dtype or value.shape != shape:
                raise OutputError(
                    f"Frame: {name} has dtype {value.dtype} and shape {value.shape}; expected {shape} {dtype.__name__}"
                )
            value.flags.writeable = False
            object.__setattr__(self, name, value)
        color.flags.writeable = False
        depth.flags.writeable = False
        object.__setattr__(self, "color", color)
        object.__setattr__(self, "depth", depth)

    @property
    def width(self) -> int:
        return int(self.color.shape[1])

    @property
    def height(self) -> int:
        return int(self.color.shape[0])

    def to_pil(self):  # -> PIL.Image.Image
        """The color buffer as a Pillow RGBA image."""
        from PIL import Image

        return Image.fromarray(np.array(self.color), mode="RGBA")

    def save(self, path: str | os.PathLike) -> None:
        """Write the color buffer as a PNG file (RGBA, 8 bits per channel).

        Raises
        ------
        OutputError
            If the suffix is not ``.png`` or the file cannot be written.
        """
        suffix = os.path.splitext(os.fspath(path))[1].lower()
        if suffix != ".png":
            raise OutputError(f"Frame.save: path = {os.fspath(path)!r} has suffix {suffix!r}; expected '.png'")
        from frustum._files import atomic_path, os_reason

        image = self.to_pil()
        with atomic_path(path, where="Frame.save") as temporary:  # the old file survives a failed write
            try:
                # the temporary's suffix (.part.png) picks PNG: Pillow then loads its PNG plugin alone (an explicit
                # format="PNG" loads its five common plugins first, 17 ms)
                image.save(temporary)
            except OSError as error:
                raise OutputError(
                    f"Frame.save: path = {os.fspath(path)!r} cannot be written ({os_reason(error)}); "
                    "give a path in an existing, writable folder with free space"
                ) from None

    def _repr_png_(self) -> bytes:
        """PNG bytes of the color buffer, for Jupyter."""
        buffer = io.BytesIO()
        self.to_pil().save(buffer, format="PNG")
        return buffer.getvalue()


def background_bytes(background: Any, where: str) -> np.ndarray:
    """An RGBA color in [0, 1] as the (4,) uint8 bytes every renderer paints, $floor(255·v + 1/2)$."""
    try:
        values = np.asarray(background, dtype=np.float64)
    except (TypeError, ValueError):
        values = None
    if (
        values is None
        or values.shape != (4,)
        or not np.isfinite(values).all()
        or (values < 0).any()
        or (values > 1).any()
    ):
        raise FrustumError(
            f"{where}: background = {describe(background)} is not an RGBA color; expected four finite numbers in [0, 1]"
        )
    return np.floor(values * 255.0 + 0.5).astype(np.uint8)
