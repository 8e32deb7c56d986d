"""The per-frame context: what the passes of one image draw into and hand to each other, and the Frame made of it.

The options (``render.options.RenderOptions``) are configuration, checked once and frozen. What the passes produce
travels here: the driver (``render._draw``) makes one ``FrameContext`` per image (``FrameContext.for_image``),
hands it to every pass with the options, and turns it into the returned ``Frame`` at the end
(``FrameContext.to_frame``). A pass reads the options and writes into the context:

- ``color`` (H, W, 4) uint8 and ``depth`` (H, W) float32: set by the first pass that draws (the surface passes
  take recycled ``FrameBuffers``, the line modes fresh arrays);
- ``normals`` (H, W, 3) float32 and ``object_id`` (H, W) int32: the extra buffers the shading kernels write
  (None where not asked for; ``extra`` gives the kernels 1-pixel dummies then);
- ``counts``: ``Frame.stats`` (a dict where the method counts its work, ``options.counted``; else None);
- ``outputs``: per-pixel arrays passes hand to later passes and to the Frame, by name: ``"position"`` (world
  points of the drawn pixels), ``"seen"`` (the fraction of each light reaching them) and ``"casting"`` (which
  lights cast shadows), written by the shadow pass (``render.shadows``);
- ``fields``: ``Frame`` fields a pass makes at the output size from the middle samples itself
  (``middle_samples``), set on the Frame as they are: the ground-truth pass's (``render.ground_truth``);
- ``scratch``: the call's work arrays (``render.buffers.Scratch``).

**Adding a buffer pass** (a per-pixel output such as instance ids or object coordinates):

1. its name in ``render.options.BUFFERS`` (``render(buffers=(...))`` accepts it; a check in ``check_arguments``
   where it needs one);
2. a module ``render/<name>.py`` with ``draw(scene, camera, options, context)`` that writes
   ``context.outputs[<name>]``, an array whose first two axes are the drawn image's (√samples times the
   output's where supersampled), and one line in the driver's ``_draw`` where it belongs among the passes (after
   the opaque surfaces, ``context.depth`` holds the nearest surface's window depth);
3. its ``Frame`` field, set in ``to_frame`` from ``frame_outputs`` (``to_frame`` has already taken the middle
   sample of each block of every image-sized output when supersampled, as for normals).

Nothing else changes: the options stay frozen, no pass reaches into another's module.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from frustum.camera import Camera
from frustum.frame import Frame
from frustum.render.buffers import Scratch, block_min, downsample, give_back, resolve_color
from frustum.render.options import GROUND_TRUTH_BUFFERS, RenderOptions

__all__ = ["FrameContext", "middle_samples", "pixel_points"]


@dataclasses.dataclass
class FrameContext:
    """What one image's passes draw into and produce (see the module docstring)."""

    normals: np.ndarray | None
    object_id: np.ndarray | None
    scratch: Scratch
    counts: dict[str, Any] | None = None
    outputs: dict[str, np.ndarray] = dataclasses.field(default_factory=dict)
    fields: dict[str, Any] = dataclasses.field(default_factory=dict)
    color: np.ndarray = dataclasses.field(default_factory=lambda: np.empty((0, 0, 4), dtype=np.uint8))
    depth: np.ndarray = dataclasses.field(default_factory=lambda: np.empty((0, 0), dtype=np.float32))

    @classmethod
    def for_image(cls, camera: Camera, options: RenderOptions) -> FrameContext:
        """The context of one image at the camera's size: the extra buffers of `options.buffers` (zero normals,
        object id −1), and counts where the method counts (``{"method": ...}``)."""
        height, width = camera.height, camera.width
        normals = np.zeros((height, width, 3), dtype=np.float32) if "normals" in options.buffers else None
        ids = np.full((height, width), -1, dtype=np.int32) if "object_id" in options.buffers else None
        counts = {"method": options.method} if options.counted else None
        return cls(normals, ids, Scratch(), counts)

    def start(self, camera: Camera, options: RenderOptions) -> None:
        """New color and depth arrays at the camera's size, cleared to the background and the far plane (the line
        modes: nothing to recycle them from)."""
        self.depth = np.ones((camera.height, camera.width), dtype=np.float32)
        self.color = np.empty((camera.height, camera.width, 4), dtype=np.uint8)
        self.color[:, :] = options.background

    def extra(self) -> tuple[np.ndarray, np.ndarray]:
        """The normal and object-id buffers ``shade.shade_pixels`` writes, or 1-pixel dummies where not asked for."""
        return (
            np.zeros((1, 1, 3), dtype=np.float32) if self.normals is None else self.normals,
            np.zeros((1, 1), dtype=np.int32) if self.object_id is None else self.object_id,
        )

    def place_drawn(self, camera: Camera, drawn: np.ndarray) -> None:
        """The world points of the pixels a pass after the surfaces took (`drawn`, (H, W) bool: points, splats) into
        ``outputs["position"]`` where it is kept: their window depth unprojected at the pixel centres
        (``Camera.unproject``)."""
        points = self.outputs.get("position")
        if points is not None and drawn.any():
            points[drawn] = pixel_points(camera, self.depth, drawn)

    def counter(self) -> dict[str, Any]:
        """The dict a pass adds its counts to: ``counts``, or a throwaway one where the frame is not counted."""
        return self.counts if self.counts is not None else {}

    def to_frame(self, options: RenderOptions) -> Frame:
        """The Frame of the drawn image: downsampled by ``options.factor`` with ``options.filter`` (depth keeps each
        block's nearest, or with ground truth asked for the middle sample its ids and points come from; normals,
        object ids and every image-sized output the block's middle sample), encoded in ``options.color_space``,
        with the ``fields`` passes made; the buffers only implied by the ground truth left off."""
        color, depth, normals, ids = self.color, self.depth, self.normals, self.object_id
        factor = options.factor
        linear = None
        if factor != 1:
            if options.filter == "box" and options.color_space == "linear":
                color = resolve_color(color, factor)
            else:
                linear = downsample(color.astype(np.float64) / 255.0, factor, options.filter)
            truth = any(name in GROUND_TRUTH_BUFFERS for name in options.buffers)
            depth = middle_samples(depth, factor) if truth else block_min(depth, factor)
            normals = None if normals is None else middle_samples(normals, factor)
            ids = None if ids is None else middle_samples(ids, factor)
            for key, array in self.outputs.items():  # the middle sample of each block, as for normals
                if array.shape[:2] == self.depth.shape:
                    self.outputs[key] = middle_samples(array, factor)
        if options.color_space == "srgb":
            values = color.astype(np.float64) / 255.0 if linear is None else linear
            values[..., :3] = np.where(
                values[..., :3] <= 0.0031308, 12.92 * values[..., :3], 1.055 * values[..., :3] ** (1 / 2.4) - 0.055
            )
            linear = values
        if linear is not None:
            color = np.floor(np.clip(linear, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
        ids = None if "object_id" in options.implied else ids
        return Frame(color=color, depth=depth, normals=normals, object_id=ids, stats=self.counts,
                     **self.frame_outputs(options), **self.fields)  # fmt: skip

    def frame_outputs(self, options: RenderOptions) -> dict[str, np.ndarray | None]:
        """The Frame fields made of ``outputs``: ``position`` and ``shadow`` where asked for (float32, NaN where
        nothing is drawn)."""
        points = self.outputs.get("position")
        if points is None:
            return {"position": None, "shadow": None}
        asked = "position" in options.buffers and "position" not in options.implied
        position = points.astype(np.float32) if asked else None
        shadow = None
        if "shadow" in options.buffers:
            seen = self.outputs["seen"][..., self.outputs["casting"]]
            shadow = np.where(np.isnan(points[..., :1]), np.float32(np.nan), seen).astype(np.float32)
        give_back(points)  # copied out above: the next frame may have it
        return {"position": position, "shadow": shadow}


def pixel_points(camera: Camera, depth: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """(N, 3) world points of the `mask` pixels (row-major order) at their window depth: ``Camera.unproject`` of
    the pixel centres $(c + ½, H − r − ½, depth)$."""
    rows, columns = np.nonzero(mask)
    return camera.unproject(np.column_stack([columns + 0.5, camera.height - rows - 0.5, depth[rows, columns]]))


def middle_samples(array: np.ndarray, factor: int) -> np.ndarray:
    """The middle sample of each factor × factor block of an image-sized array (the array itself at factor 1)."""
    if factor == 1:
        return array
    middle = factor // 2
    return np.ascontiguousarray(array[middle::factor, middle::factor])
