"""The splat pass of ``render``: every placed ``GaussianSplats`` composited over the opaque surfaces by the 3DGS
method (``raster.splats``: EWA projection, 3σ bounds, 16 × 16 tiles, a front-to-back sort, alpha compositing).

All placed splat sets are projected (``project_splats``, parallel over splats), sorted together by the window depth
of their centres (a stable sort: equal depths keep scene and file order), binned into tiles in that order
(``count_tiles`` / ``fill_tiles``) and blended per tile (``blend_tiles``, parallel over tiles) against the depth
buffer of the opaque surfaces. The frame's pixel becomes

$$C = Σ cᵢ·αᵢ·Tᵢ + T·C_under,   A = (1 − T) + T·A_under$$

with C_under, A_under what the surfaces (or the background) left there. Splat colours are display values, as 3DGS
files store them: written as they are (no lighting, no tone map; ``color_space="srgb"`` still encodes the frame).
``Frame.depth`` where splats contribute is their expected window depth $Σ wᵢ zᵢ / Σ wᵢ$ ($wᵢ = αᵢ·Tᵢ$, zᵢ the
window depth of splat i's centre), in front of whatever was there; elsewhere it is unchanged.

Object ids (``buffers=("object_id",)``, and so ``instance``, ``semantic`` and the datasets): a pixel whose
accumulated splat alpha $1 − T$ reaches ½ gets the id of the splat set of its median splat (the one whose
compositing brings $1 − T$ to ½ or more, ``raster.splats``), $len(scene.items) + i$ for the i-th entry of
``Scene.point_clouds`` as points have; its normal becomes (0, 0, 0) (splats have no surface). Below ½ the pixel
keeps the id, normal and world point (``buffers=("position",)``) of what is under the splats (a surface, or −1 on
the background); a pixel the splats own has the world point of its expected depth. A splat set's amodal mask
(``silhouette``) is the same rule applied to the set drawn alone.

References
----------
Kerbl et al., "3D Gaussian Splatting for Real-Time Radiance Field Rendering" (2023) §6 (the tile rasterizer).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from frustum.camera import Camera
from frustum.render.buffers import Scratch
from frustum.render.context import FrameContext
from frustum.render.options import RenderOptions
from frustum.scene import PointItem, Scene

__all__ = ["SplatLayer", "draw_splats", "project", "silhouette", "splat_layer"]


class SplatLayer(NamedTuple):
    """What the splats of a frame add: premultiplied ``color`` (H, W, 3), ``transmittance`` (H, W) (1: nothing),
    expected window ``depth`` (H, W) (NaN where no splat contributes), all float32, and ``item`` (H, W) int32, the
    index in the drawn items of the median splat's set (−1 where $1 − T < ½$), rows top first."""

    color: np.ndarray
    transmittance: np.ndarray
    depth: np.ndarray
    item: np.ndarray


def project(items: list[PointItem], camera: Camera, scratch: Scratch | None = None) -> np.ndarray:
    """(N, SPLAT_FIELDS) float64 records of every splat of `items` (``raster.splats``), in item order (arrays from
    `scratch` when given: a frame of an animation reuses the last frame's)."""
    from frustum.raster import splats as kernels

    empty = np.empty if scratch is None else scratch.empty
    total = sum(item.geometry.count for item in items)
    records = empty((total, kernels.SPLAT_FIELDS))
    first = 0
    frame = np.array([camera.width, camera.height, *camera.frame.eye], dtype=np.float64)
    clip_from_view = np.asarray(camera.projection_matrix, dtype=np.float64)
    for item in items:
        splats = item.geometry
        world_from_model = np.asarray(item.world_from_model, dtype=np.float64)
        matrices = np.ascontiguousarray(np.stack([
            camera.view_matrix @ world_from_model, clip_from_view, np.linalg.inv(world_from_model), world_from_model,
        ]))  # fmt: skip
        part = records[first : first + splats.count]
        kernels.project_splats(np.ascontiguousarray(splats.positions), np.ascontiguousarray(splats.scales),
                               np.ascontiguousarray(splats.rotations), np.ascontiguousarray(splats.opacities),
                               np.ascontiguousarray(splats.sh), matrices, frame, part)  # fmt: skip
        first += splats.count
    return records


def splat_layer(items: list[PointItem], camera: Camera, depth: np.ndarray | None = None,
                scratch: Scratch | None = None) -> SplatLayer:  # fmt: skip
    """The splats of `items` seen by `camera` in front of `depth` ((H, W) float32 window depth; None: nothing
    opaque), as a ``SplatLayer`` (work arrays from `scratch` when given)."""
    from frustum.raster import splats as kernels

    height, width = camera.height, camera.width
    if depth is None:
        depth = np.ones((height, width), dtype=np.float32)
    empty = np.empty if scratch is None else scratch.empty
    records = project(items, camera, scratch)
    kept = np.flatnonzero(records[:, kernels.F_RADIUS] > 0.0)
    order = kept[np.argsort(records[kept, kernels.F_Z], kind="stable")]
    tiles_x, tiles_y = -(-width // kernels.TILE), -(-height // kernels.TILE)
    counts = np.zeros(tiles_x * tiles_y, dtype=np.int64)
    kernels.count_tiles(records, order, height, tiles_x, tiles_y, counts)
    starts = np.zeros(counts.size + 1, dtype=np.int64)
    np.cumsum(counts, out=starts[1:])
    entries = np.empty(int(starts[-1]), dtype=np.int64)
    kernels.fill_tiles(records, order, height, tiles_x, tiles_y, starts, entries)
    layer = empty((height, width, kernels.LAYER_CHANNELS), np.float32)
    item_starts = np.cumsum([0] + [item.geometry.count for item in items], dtype=np.int64)  # items' records
    kernels.blend_tiles(records, starts, entries, tiles_x, np.ascontiguousarray(depth, dtype=np.float32), item_starts,
                        layer)  # fmt: skip
    with np.errstate(invalid="ignore", divide="ignore"):
        expected = np.where(layer[..., 4] > 0.0, layer[..., 5] / layer[..., 4], np.nan).astype(np.float32)
    return SplatLayer(layer[..., :3], layer[..., 3], expected, layer[..., 6].astype(np.int32))


def draw_splats(scene: Scene, camera: Camera, options: RenderOptions, buffers: FrameContext) -> None:
    """Composite every placed splat set of `scene` over `buffers` (the module docstring's equations)."""
    placed = [(i, item) for i, item in enumerate(scene.point_clouds)
              if item.style.style == "splats" and item.geometry.count]  # fmt: skip
    if not placed:
        return
    items = [item for _, item in placed]
    layer = splat_layer(items, camera, buffers.depth, buffers.scratch)
    covered = layer.item >= 0
    if buffers.object_id is not None:
        ids = len(scene.items) + np.array([i for i, _ in placed], dtype=np.int32)
        buffers.object_id[covered] = ids[layer.item[covered]]
    if buffers.normals is not None:
        buffers.normals[covered] = 0.0
    seen = ~np.isnan(layer.depth)
    buffers.depth[seen] = layer.depth[seen]
    buffers.place_drawn(camera, covered)
    color = buffers.color
    under = color.astype(np.float32) / 255.0
    t = layer.transmittance[..., None]
    rgb = layer.color + t * under[..., :3]
    alpha = (1.0 - layer.transmittance) + layer.transmittance * under[..., 3]
    color[..., :3] = np.floor(np.clip(rgb, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
    color[..., 3] = np.floor(np.clip(alpha, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)


def silhouette(item: PointItem, camera: Camera) -> np.ndarray:
    """(H, W) bool: where the splat set `item` drawn alone reaches an accumulated alpha of ½ (its amodal mask, the
    module docstring's rule)."""
    return splat_layer([item], camera).item >= 0
