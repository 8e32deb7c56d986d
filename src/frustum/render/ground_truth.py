"""Ground-truth buffers for training vision models: ``instance``, ``semantic``, ``amodal`` (with
``Frame.visibility``), ``object_coords``, ``nocs`` and ``flow`` (with ``Frame.flow_occluded``).

A pass (``draw``), the last of the surface modes' passes (``render._draw``): every per-pixel id and point comes
from **one** sample of the ``object_id`` and ``position`` the surface passes leave in the frame's context (with
supersampling, the middle sample of each pixel's block, ``render.context.middle_samples``, which is then also the
sample ``Frame.depth`` reports), so a pixel never carries a blend of two objects and every id in a mask is an item
of the scene. The pass writes the Frame's fields at the output size into ``context.fields``.

- The objects (``objects``): the meshes of ``Scene.items`` (ids 0 … K − 1), then the point clouds and splat sets
  of ``Scene.point_clouds`` (ids K … K + P − 1, as the point and splat passes write them: ``render.points``,
  ``render.splats``; a splat pixel is its set's where the accumulated alpha reaches ½).
- ``instance``: ``object_id`` under its dataset name, the object's index (−1 background).
- ``semantic``: the class id of each pixel's object, $c = 1 + $ the position of its label in ``Scene.labels``
  (0 for the background and for objects without a label).
- ``amodal`` (K + P, H, W) bool: each object's silhouette alone, occluders ignored, still clipped by the view
  volume: one depth-only fill of each mesh (``raster.shadow.fill_depth_tiles``, the same coverage rule as the
  surface pass), each cloud or splat set drawn alone (``point_masks``). ``visibility`` (K + P,):
  $visible / amodal$ pixels, NaN where the amodal mask is empty.
- Point objects have no surface between their points: their pixels' world points (for ``object_coords``, ``nocs``
  and ``flow``; the passes write them, ``FrameContext.place_drawn``, or ``point_positions`` where the frame has
  none) are the window depth unprojected (``Camera.unproject``; a splat pixel's is its expected depth),
  their NOCS box the box of their points; the next frame's depth buffer of ``flow_occluded`` holds the meshes.
- ``object_coords`` (H, W, 3) float32: the visible point in its item's model coordinates,
  $X = (world\\_from\\_model)^{-1} · P_{world}$, NaN on the background.
- ``nocs``: Normalized Object Coordinate Space (Wang et al. 2019), $(X − c)/‖b_{max} − b_{min}‖ + ½$ with c the
  centre of the model's bounding box: the box diagonal has length 1 and the box sits centred in [0, 1]³.
- ``flow`` (H, W, 2) float32: the displacement, in pixels with x right and y down, of each visible point from its
  projection in this frame to its projection in the next, $p' − p$ with $p = π(camera, M·X)$ and
  $p' = π(camera', M'·X)$ (items matched by node path, ``Scene.item_paths``); NaN on the background, for items
  absent from the next scene and for points behind the next camera. ``flow_occluded`` (H, W) bool: the point is
  outside the next image, behind its camera, or farther than the next frame's depth buffer at the pixel holding
  it by more than ``DEPTH_TOLERANCE`` of its view distance.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from frustum.camera import Camera
from frustum.errors import FrustumError
from frustum.render.context import FrameContext, middle_samples, pixel_points
from frustum.render.options import GROUND_TRUTH_BUFFERS, RenderOptions
from frustum.scene import Scene, SceneItem

__all__ = [
    "DEPTH_TOLERANCE", "amodal_masks", "class_ids", "draw", "flow_setup", "model_from_world", "nocs_boxes",
    "object_labels", "object_paths", "objects", "point_buffers", "point_masks", "point_positions", "visibility",
]  # fmt: skip

DEPTH_TOLERANCE = 1e-2
"""``flow_occluded`` and the visible flags of ``frustum.annotate``: a point counts as hidden when its view distance
exceeds the depth buffer's (at the pixel that holds it) by more than this fraction (1 cm at 1 m): the buffer holds
the surface at the pixel's centre, not at the point, so a relative margin keeps sloped surfaces from hiding
themselves."""


def objects(scene: Scene) -> list[SceneItem]:
    """The objects the ids count (module docstring): ``Scene.items``, then each entry of ``Scene.point_clouds`` as a
    ``SceneItem`` whose ``mesh`` holds the PointCloud or GaussianSplats."""
    return [*scene.items, *(SceneItem(p.geometry, p.material, p.world_from_model) for p in scene.point_clouds)]


def object_labels(scene: Scene) -> list[str | None]:
    """Each object's label (``objects`` order)."""
    return [*scene.item_labels(), *scene.point_labels()]


def object_paths(scene: Scene) -> list[str]:
    """Each object's node path (``objects`` order)."""
    return [*scene.item_paths(), *scene.point_paths()]


def class_ids(scene: Scene) -> np.ndarray:
    """(K + P,) int32: each object's class id, 1-based in ``Scene.labels`` (0: no label)."""
    number = {label: i + 1 for i, label in enumerate(scene.labels)}
    return np.array([0 if label is None else number[label] for label in object_labels(scene)], dtype=np.int32)


def point_positions(camera: Camera, depth: np.ndarray, instance: np.ndarray, first: int,
                    position: np.ndarray) -> np.ndarray:  # fmt: skip
    """`position` with the world points of the point objects' pixels (ids >= `first`) replaced by their window
    depth unprojected (``Camera.unproject`` at the pixel centre)."""
    mask = instance >= first
    if not mask.any():
        return position
    result = np.array(position, dtype=np.float32)
    result[mask] = pixel_points(camera, depth, mask)
    return result


def amodal_masks(items: list[SceneItem], camera: Camera, cull: bool, factor: int) -> np.ndarray:
    """(K, H, W) bool: each item drawn alone (depth only) at `factor` times the camera's size, the middle sample
    of each factor × factor block kept (the sample ``object_id`` keeps)."""
    height, width = camera.height, camera.width
    big = dataclasses.replace(camera, width=width * factor, height=height * factor) if factor != 1 else camera
    masks = np.zeros((len(items), height, width), dtype=bool)
    depth = np.empty((big.height, big.width), dtype=np.float32)
    middle = factor // 2
    for k, item in enumerate(items):
        if item.mesh.face_count:
            _fill_depth(item, big, cull, depth, True)
            np.less(depth[middle::factor, middle::factor], 1.0, out=masks[k])
    return masks


def _fill_depth(item: SceneItem, camera: Camera, cull: bool, depth: np.ndarray, fresh: bool) -> None:
    """One item's depth-only fill into `depth` (cleared first where `fresh`): stages 1–3 (``render.stages.bin_item``)
    and ``raster.shadow.fill_depth_tiles``, the surface pass's coverage rule."""
    from frustum.raster import shadow
    from frustum.render.stages import TILED_BITS, bin_item

    binned = bin_item(item, camera, cull, tile_bits=TILED_BITS)
    tiling = np.array([1 << TILED_BITS, binned.tiles_x, 0, camera.width, camera.height], dtype=np.int64)
    shadow.fill_depth_tiles(
        binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tile_starts,
        binned.tile_entries, tiling, depth, fresh,
    )  # fmt: skip


def point_masks(scene: Scene, camera: Camera, options: RenderOptions) -> np.ndarray:
    """(P, H, W) bool: each entry of ``Scene.point_clouds`` drawn alone at ``options.factor`` times the camera's size,
    the middle sample of each block kept (the sample ``object_id`` keeps): a cloud where it writes depth
    (``render.points.silhouette``), a splat set where its accumulated alpha reaches ½ (``render.splats.silhouette``)."""
    from frustum.render import points, splats

    placed = scene.point_clouds
    factor, middle = options.factor, options.factor // 2
    big = dataclasses.replace(camera, width=camera.width * factor, height=camera.height * factor)
    masks = np.zeros((len(placed), camera.height, camera.width), dtype=bool)
    for k, item in enumerate(placed):
        drawn = splats.silhouette(item, big) if item.style.style == "splats" else points.silhouette(item, big, options)
        masks[k] = drawn[middle::factor, middle::factor]
    return masks


def visibility(instance: np.ndarray, amodal: np.ndarray) -> np.ndarray:
    """(K,) float64 $visible / amodal$ pixel counts per item; NaN where the item's amodal mask is empty."""
    count = amodal.shape[0]
    visible = np.bincount(instance.ravel() + 1, minlength=count + 1)[1 : count + 1].astype(np.float64)
    total = np.array([np.count_nonzero(mask) for mask in amodal], dtype=np.float64)  # 7x faster than axis=1
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(total > 0, visible / np.where(total > 0, total, 1.0), np.nan)


def model_from_world(items: list[SceneItem]) -> np.ndarray:
    """(K, 12) float64: each item's $(world\\_from\\_model)^{-1}$, the top three rows row-major (one row for no
    items: the kernels index it only at drawn pixels)."""
    rows = np.zeros((max(1, len(items)), 12))
    for k, item in enumerate(items):
        rows[k] = np.linalg.inv(np.asarray(item.world_from_model, dtype=np.float64))[:3].ravel()
    return rows


def nocs_boxes(items: list[SceneItem]) -> np.ndarray:
    """(K, 4) float64: the centre c of each model's bounding box and $1/‖b_{max} − b_{min}‖$ (1 for a point), the
    terms of NOCS's $(X − c)/‖b_{max} − b_{min}‖ + ½$ (module docstring)."""
    boxes = np.zeros((max(1, len(items)), 4))
    for k, item in enumerate(items):
        low, high = np.asarray(item.mesh.bounds, dtype=np.float64)
        diagonal = float(np.linalg.norm(high - low))
        boxes[k] = (*(0.5 * (low + high)), 1.0 / diagonal if diagonal > 0 else 1.0)
    return boxes


def _window(camera: Camera, points: np.ndarray, world_from_points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, 3) window coordinates (x right, y up, depth in [0, 1]) of points placed by `world_from_points`, and
    their clip w (> 0: in front of a perspective camera)."""
    clip_from_points = np.asarray(camera.projection_matrix) @ np.asarray(camera.view_matrix) @ world_from_points
    clip = points @ clip_from_points[:, :3].T + clip_from_points[:, 3]
    w = clip[:, 3].copy()
    with np.errstate(invalid="ignore", divide="ignore"):
        clip[:, :3] /= w[:, None]
    window = clip[:, :3]
    window[:, 0] = (window[:, 0] + 1.0) * (0.5 * camera.width)
    window[:, 1] = (window[:, 1] + 1.0) * (0.5 * camera.height)
    window[:, 2] = (window[:, 2] + 1.0) * 0.5
    return window, w


def hidden_points(camera: Camera, depth: np.ndarray, points: np.ndarray,
                  world_from_points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Window coordinates (N, 3) of points placed by `world_from_points` (NaN rows behind a perspective camera) and
    whether each is hidden from `camera` whose window depth buffer is `depth`: outside the image or the depth range,
    behind the camera, or farther than the buffer at the pixel holding it by more than ``DEPTH_TOLERANCE`` of its
    view distance."""
    window, w = _window(camera, points, world_from_points)
    window[w <= 0.0] = np.nan
    height, width = depth.shape
    column = np.floor(window[:, 0])
    row = height - 1 - np.floor(window[:, 1])
    with np.errstate(invalid="ignore"):
        inside = (w > 0.0) & (column >= 0) & (column < width) & (row >= 0) & (row < height)
        inside &= (window[:, 2] >= 0.0) & (window[:, 2] <= 1.0)
    hidden = ~inside
    c, r = column[inside].astype(np.int64), row[inside].astype(np.int64)
    surface = view_distance(camera, depth[r, c])
    point = view_distance(camera, window[inside, 2])
    hidden[inside] = point > surface * (1.0 + DEPTH_TOLERANCE)
    return window, hidden


def view_distance(camera: Camera, window_depth: np.ndarray) -> np.ndarray:
    """The distance along the viewing axis of window depths d, $z_{ndc} = 2d − 1 = (A·z + B)/(C·z + D)$ solved for
    $−z = −(B − z_{ndc}·D)/(z_{ndc}·C − A)$ with the projection's third and fourth rows (``metric_depth``'s
    formula)."""
    p = np.asarray(camera.projection_matrix)
    z_ndc = 2.0 * np.asarray(window_depth, dtype=np.float64) - 1.0
    with np.errstate(invalid="ignore", divide="ignore"):
        return -(p[2, 3] - z_ndc * p[3, 3]) / (z_ndc * p[3, 2] - p[2, 2])


def _depth_of(scene: Scene, camera: Camera, cull: bool) -> np.ndarray:
    """The window depth buffer of `scene`'s meshes seen by `camera` (depth-only fills, 1.0 where none)."""
    depth = np.ones((camera.height, camera.width), dtype=np.float32)
    for item in scene.items:
        if item.mesh.face_count:
            _fill_depth(item, camera, cull, depth, False)
    return depth


def matched_items(scene: Scene, next_scene: Scene, where: str) -> list[int]:
    """For each item of `scene`, the index of the item at the same node path in `next_scene` (−1: absent).

    Raises FrustumError naming the node when a path is not unique in either scene (an unmatched item would be
    ambiguous), or when no item of `scene` is in `next_scene` at all."""
    paths, next_paths = object_paths(scene), object_paths(next_scene)
    for label, listed in (("scene", paths), ("next scene", next_paths)):
        seen: set[str] = set()
        for path in listed:
            if path in seen:
                raise FrustumError(
                    f"{where}: the {label} has two meshes at node path {path!r}; flow matches items by path: give "
                    "sibling nodes distinct names"
                )
            seen.add(path)
    where_next = {path: i for i, path in enumerate(next_paths)}
    matched = [where_next.get(path, -1) for path in paths]
    if paths and all(m < 0 for m in matched):
        raise FrustumError(
            f"{where}: next scene has no item at the node paths of this scene (first: {paths[0]!r}; next scene: "
            f"{', '.join(repr(p) for p in next_paths[:5]) or 'no meshes'}); build the next scene with the same "
            "node names"
        )
    return matched


def flow_setup(scene: Scene, camera: Camera, next_scene: Scene, next_camera: Camera, cull: bool,
               where: str = "render") -> tuple[np.ndarray, ...]:  # fmt: skip
    """The terms of ``raster.ground_truth.point_truth``'s flow (its array contracts): clip_from_model of each item
    now and in the next frame, the matched items (``matched_items``), the next frame's depth buffer and the image
    sizes and next projection."""
    matched = matched_items(scene, next_scene, where)
    items, next_items = objects(scene), objects(next_scene)
    clip_from_world = np.asarray(camera.projection_matrix) @ np.asarray(camera.view_matrix)
    next_clip_from_world = np.asarray(next_camera.projection_matrix) @ np.asarray(next_camera.view_matrix)
    now, later = np.zeros((max(1, len(items)), 16)), np.zeros((max(1, len(items)), 16))
    for k, item in enumerate(items):
        now[k] = (clip_from_world @ np.asarray(item.world_from_model, dtype=np.float64)).ravel()
        if matched[k] >= 0:
            later[k] = (next_clip_from_world @ np.asarray(next_items[matched[k]].world_from_model, float)).ravel()
    p = np.asarray(next_camera.projection_matrix)
    setup = np.array([camera.width, camera.height, next_camera.width, next_camera.height, p[2, 2], p[2, 3], p[3, 2],
                      p[3, 3]], dtype=np.float64)  # fmt: skip
    return now, later, np.array(matched, dtype=np.int64), _depth_of(next_scene, next_camera, cull), setup


def point_buffers(scene: Scene, camera: Camera, instance: np.ndarray, position: np.ndarray, wanted: tuple[str, ...],
                  options: RenderOptions, where: str = "render") -> dict[str, np.ndarray]:  # fmt: skip
    """The Frame fields of the model points of the drawn pixels, those of `wanted` (``object_coords``, ``nocs``,
    ``flow`` with ``flow_occluded``), float32 (bool), NaN where nothing is drawn, in one pass over the pixels
    (``raster.ground_truth.point_truth``)."""
    from frustum.raster import ground_truth

    shape = instance.shape
    names = [name for name in ("object_coords", "nocs", "flow") if name in wanted]
    layers = {"object_coords": 3, "nocs": 3, "flow": 2, "flow_occluded": 0}
    if "flow" in wanted:
        assert options.next is not None  # required with "flow" (render.options.check_next)
        terms = flow_setup(scene, camera, *options.next, options.cull, where)
        names.append("flow_occluded")
    else:  # 1-row stand-ins, never read
        terms = (np.zeros((1, 16)), np.zeros((1, 16)), np.zeros(1, dtype=np.int64), np.ones((1, 1), np.float32),
                 np.ones(8))  # fmt: skip
    outputs = {  # the image-sized arrays asked for, 1-pixel dummies for the others
        name: np.empty((*(shape if name in names else (1, 1)), *((depth,) if depth else ())),
                       dtype=bool if name == "flow_occluded" else np.float32)
        for name, depth in layers.items()
    }  # fmt: skip
    flags = 1 * ("object_coords" in names) + 2 * ("nocs" in names) + 4 * ("flow" in names)
    ground_truth.point_truth(
        np.ascontiguousarray(instance, dtype=np.int32), np.ascontiguousarray(position, dtype=np.float64),
        model_from_world(objects(scene)), nocs_boxes(objects(scene)), *terms, DEPTH_TOLERANCE, flags,
        *outputs.values(),
    )  # fmt: skip
    return {name: outputs[name] for name in names}


def cast_positions(scene: Scene, camera: Camera, instance: np.ndarray, factor: int) -> np.ndarray:
    """(H, W, 3) float32 world points of the drawn pixels by casting each one's ray through the sample its id came
    from (``Scene.intersect``; the middle sample of its factor × factor block): for the methods that keep no
    per-pixel positions (``"ray-tracing"``). NaN elsewhere."""
    height, width = instance.shape
    rows, columns = np.nonzero(instance >= 0)
    offset = (factor // 2 + 0.5) / factor
    window = np.column_stack([columns + offset, height - rows - offset])
    result = np.full((height, width, 3), np.nan, dtype=np.float32)
    if rows.size:
        ray = camera.ray(window)
        hits = scene.intersect(ray.origin, ray.direction)
        result[rows, columns] = hits.point
    return result


def draw(scene: Scene, camera: Camera, options: RenderOptions, context: FrameContext, where: str = "render") -> None:
    """The ground-truth pass: the asked-for buffers (``Frame.instance`` …) into ``context.fields`` at the output size,
    from the middle sample of each pixel's block of the ids and points the surface passes left in the context
    (``object_id``, ``outputs["position"]``). Nothing where no ground truth is asked for."""
    wanted = tuple(name for name in options.buffers if name in GROUND_TRUTH_BUFFERS)
    if not wanted:
        return
    factor = options.factor
    if factor != 1:  # the drawn image is the output's √samples times
        camera = dataclasses.replace(camera, width=camera.width // factor, height=camera.height // factor)
    assert context.object_id is not None  # implied by every ground-truth buffer (render.options.with_implied)
    instance = middle_samples(context.object_id, factor)
    items = objects(scene)
    fields = context.fields
    if "instance" in wanted:
        fields["instance"] = instance
    if "semantic" in wanted:
        table = np.concatenate([[0], class_ids(scene)]).astype(np.int32)
        fields["semantic"] = table[instance + 1]
    if "amodal" in wanted:
        from frustum.budgets import check_memory

        cause = f"amodal masks of {len(items)} items at {camera.width} x {camera.height}"
        check_memory(len(items) * camera.width * camera.height, where=where, cause=cause)
        masks = amodal_masks(scene.items, camera, options.cull, factor)
        if scene.point_clouds:
            masks = np.concatenate([masks, point_masks(scene, camera, options)])
        fields["amodal"] = masks
        fields["visibility"] = visibility(instance, masks)
    if any(name in wanted for name in ("object_coords", "nocs", "flow")):
        drawn = context.outputs.get("position")  # the passes' world points (points and splats: depth unprojected)
        if drawn is not None:
            position = middle_samples(drawn, factor)
        else:
            position = point_positions(camera, middle_samples(context.depth, factor), instance, len(scene.items),
                                       cast_positions(scene, camera, instance, factor))  # fmt: skip
        fields.update(point_buffers(scene, camera, instance, position, wanted, options, where))
