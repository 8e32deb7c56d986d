"""Per-object annotations of a rendered frame: ``annotate(frame, scene, camera, keypoints=None)``.

One record per scene object (``render.ground_truth.objects``: ``Scene.items``, then ``Scene.point_clouds``) with
what detectors, segmenters and 6-DoF pose estimators train on: 2D boxes from the masks, the projected 3D box, the
model-to-camera pose, visibility and keypoints (meshes only). A point cloud's or splat set's 3D box is the box of
its points (splat centres).

Pixel coordinates are OpenCV's (and COCO's, BOP's): u right, v down, the centre of the top-left pixel at (0, 0),
so a window point $(x_w, y_w)$ (y up, centres at half-integers, ``Camera.project``) is at
$u = x_w − ½$, $v = H − y_w − ½$. Boxes are COCO's ``[x, y, width, height]`` of the pixels a mask covers:
$x = min(column)$, $width = max(column) − min(column) + 1$ (``pycocotools.mask.toBbox``), ``[0, 0, 0, 0]`` for an
empty mask. The pose is $camera_{cv}\\_from\\_model = diag(1, −1, −1, 1) · view\\_from\\_world · world\\_from\\_model$
(OpenCV camera axes: x right, y down, looking down +z), in the scene's units. A point is *visible* when it lies in
the image and the depth buffer at its pixel is not nearer than it by more than
``render.ground_truth.DEPTH_TOLERANCE`` of its view distance.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from frustum._arrays import describe
from frustum.camera import Camera
from frustum.errors import FrustumError
from frustum.frame import Frame
from frustum.geometry import Mesh
from frustum.render.ground_truth import class_ids, hidden_points, object_labels, object_paths, objects
from frustum.scene import Scene

__all__ = ["OPENCV_FROM_VIEW", "annotate", "mask_box"]

OPENCV_FROM_VIEW = np.diag([1.0, -1.0, -1.0, 1.0])
"""Half a turn about x: frustum's view axes (y up, looking down −z) to OpenCV camera axes (y down, looking down +z)."""
OPENCV_FROM_VIEW.flags.writeable = False


def mask_box(mask: np.ndarray) -> list[int]:
    """COCO box ``[x, y, width, height]`` of the True pixels of an (H, W) mask; ``[0, 0, 0, 0]`` when empty."""
    rows = np.flatnonzero(mask.any(axis=1))
    columns = np.flatnonzero(mask.any(axis=0))
    if rows.size == 0:
        return [0, 0, 0, 0]
    return [int(columns[0]), int(rows[0]), int(columns[-1] - columns[0] + 1), int(rows[-1] - rows[0] + 1)]


def _box_corners(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """The 8 corners of an axis-aligned box, x fastest: (x0 y0 z0), (x1 y0 z0), (x0 y1 z0), … (x1 y1 z1)."""
    return np.array([[(low, high)[i & 1][0], (low, high)[(i >> 1) & 1][1], (low, high)[(i >> 2) & 1][2]]
                     for i in range(8)], dtype=np.float64)  # fmt: skip


def _keypoints_per_item(keypoints: Any, paths: list[str], labels: list[str | None], where: str) -> list[Any]:
    """One (M, 3) float64 array or None per item from `keypoints`: None, one (M, 3) array for every item, a mapping
    from label or node path to (M, 3), or a sequence with one (M, 3) or None per item."""
    count = len(paths)
    if keypoints is None:
        return [None] * count

    def checked(value: Any, name: str) -> np.ndarray:
        try:
            array = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            array = None
        if array is None or array.ndim != 2 or array.shape[1] != 3 or not np.isfinite(array).all():
            raise FrustumError(
                f"{where}: {name} = {describe(value)} is not an (M, 3) array of finite model points; give one row "
                "x, y, z per keypoint, in the item's model coordinates"
            )
        return array

    if isinstance(keypoints, Mapping):
        known = set(paths) | {label for label in labels if label is not None}
        for key in keypoints:
            if key not in known:
                raise FrustumError(
                    f"{where}: keypoints has key {key!r}, which is neither a label nor a node path of the scene; "
                    f"labels: {sorted(x for x in set(labels) if x is not None)}, paths: {paths[:5]}"
                )
        result = []
        for path, label in zip(paths, labels, strict=True):
            value = keypoints.get(path, keypoints.get(label) if label is not None else None)
            key = path if path in keypoints else label
            result.append(None if value is None else checked(value, f"keypoints[{key!r}]"))
        return result
    per_item = isinstance(keypoints, list | tuple) and keypoints and all(
        k is None or np.ndim(k) == 2 for k in keypoints
    )  # fmt: skip
    if per_item:
        if len(keypoints) != count:
            raise FrustumError(
                f"{where}: keypoints lists {len(keypoints)} arrays for {count} items; give one (M, 3) array or None "
                "per item (Scene.items order), one array for every item, or a mapping from label to array"
            )
        return [None if k is None else checked(k, f"keypoints[{i}]") for i, k in enumerate(keypoints)]
    single = checked(keypoints, "keypoints")
    return [single] * count


def annotate(frame: Frame, scene: Scene, camera: Camera, keypoints: Any = None) -> list[dict[str, Any]]:
    """One record per object of `scene` (``Scene.items`` order, then ``Scene.point_clouds``) of a frame rendered with
    ``buffers=("instance", "amodal")`` (conventions: the module docstring).

    Each record: ``name`` (the node path), ``kind`` (``"mesh"``, ``"points"`` or ``"splats"``), ``label`` (or
    None), ``class_id`` (1-based in ``Scene.labels``, 0 without a label), ``bbox_visible`` and ``bbox_amodal``
    (COCO ``[x, y, w, h]`` of the instance and amodal masks),
    ``bbox_3d`` ((8, 2) pixel coordinates of the model's bounding-box corners, x fastest, NaN behind the camera) with
    ``bbox_3d_visible`` (8,) bool, ``pose`` (4×4 model-to-camera in OpenCV axes), ``visibility`` (visible / amodal
    pixels, NaN outside the view), ``px_count_visible`` and ``px_count_all`` (pixels of the two masks) and, where
    keypoints are given for the item, ``keypoints`` ((M, 3): u, v and COCO's v = 0 outside the image or behind the
    camera, 1 in the image but hidden, 2 visible).

    Parameters
    ----------
    keypoints : None, (M, 3) array_like, mapping or sequence
        Model points of the meshes: one array for every mesh item, a mapping from label or node path to an array,
        or one array (or None) per item of ``Scene.items`` (point objects get none).

    Raises
    ------
    FrustumError
        A frame without the instance and amodal buffers or of another size than the camera, a scene whose items do
        not match the frame's, keypoints of the wrong shape or naming unknown items.
    """
    where = "annotate"
    if not isinstance(frame, Frame):
        raise FrustumError(f"{where}: frame = {describe(frame)} is not a Frame; render one with frustum.render")
    if not isinstance(scene, Scene) or not isinstance(camera, Camera):
        raise FrustumError(f"{where}: give the Scene and the Camera the frame was rendered with")
    instance = frame.instance if frame.instance is not None else frame.object_id
    if instance is None or frame.amodal is None:
        raise FrustumError(
            f"{where}: the frame has no {'instance' if instance is None else 'amodal'} buffer; render it with "
            "buffers=('instance', 'amodal')"
        )
    if (frame.height, frame.width) != (camera.height, camera.width):
        raise FrustumError(
            f"{where}: the frame is {frame.width} x {frame.height} but the camera {camera.width} x {camera.height}; "
            "give the camera the frame was rendered with"
        )
    items = objects(scene)
    if frame.amodal.shape[0] != len(items):
        raise FrustumError(
            f"{where}: the frame has amodal masks of {frame.amodal.shape[0]} objects but the scene has {len(items)}; "
            "give the scene the frame was rendered from"
        )
    paths, labels = object_paths(scene), object_labels(scene)
    points = _keypoints_per_item(keypoints, scene.item_paths(), scene.item_labels(), where)
    points += [None] * (len(items) - len(points))
    classes = class_ids(scene)
    view_from_world = np.asarray(camera.view_matrix, dtype=np.float64)
    counts = np.bincount(instance[instance >= 0].ravel(), minlength=len(items))
    records = []
    for k, item in enumerate(items):
        world_from_model = np.asarray(item.world_from_model, dtype=np.float64)
        visible_mask = instance == k
        amodal = frame.amodal[k]
        total = int(amodal.sum())
        low, high = np.asarray(item.mesh.bounds, dtype=np.float64)
        corners, corner_hidden = _project(camera, frame.depth, world_from_model, _box_corners(low, high))
        record: dict[str, Any] = {
            "name": paths[k],
            "kind": _kind(item.mesh),
            "label": labels[k],
            "class_id": int(classes[k]),
            "bbox_visible": mask_box(visible_mask),
            "bbox_amodal": mask_box(amodal),
            "bbox_3d": corners,
            "bbox_3d_visible": ~corner_hidden,
            "pose": OPENCV_FROM_VIEW @ view_from_world @ world_from_model,
            "visibility": float(counts[k]) / total if total else float("nan"),
            "px_count_visible": int(counts[k]),
            "px_count_all": total,
        }
        if points[k] is not None:
            pixels, hidden = _project(camera, frame.depth, world_from_model, points[k])
            inside = ~np.isnan(pixels[:, 0]) & (pixels[:, 0] >= -0.5) & (pixels[:, 0] < camera.width - 0.5)
            inside &= (pixels[:, 1] >= -0.5) & (pixels[:, 1] < camera.height - 0.5)
            flags = np.where(inside, np.where(hidden, 1, 2), 0)
            record["keypoints"] = np.column_stack([pixels, flags.astype(np.float64)])
        records.append(record)
    return records


def _project(camera: Camera, depth: np.ndarray, world_from_model: np.ndarray,
             model: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """(N, 2) OpenCV pixel coordinates of model points (NaN behind the camera) and whether each is hidden."""
    window, hidden = hidden_points(camera, depth, model, world_from_model)
    pixels = np.column_stack([window[:, 0] - 0.5, camera.height - window[:, 1] - 0.5])
    return pixels, hidden


def _kind(geometry: object) -> str:
    """``"mesh"``, ``"points"`` (a PointCloud) or ``"splats"`` (GaussianSplats)."""
    if isinstance(geometry, Mesh):
        return "mesh"
    return "splats" if hasattr(geometry, "opacities") else "points"
