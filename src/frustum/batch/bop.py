"""BOP datasets (``render_dataset(format="bop")``), scenewise as the BOP toolkit's ``docs/bop_datasets_format.md``
describes them: one scene ``train/000000/`` of every view, and the object models.

::

    models/obj_OOOOOO.ply          each class's model in millimetres (ASCII PLY with vertex normals)
    models/models_info.json        per obj_id: diameter, min_x, min_y, min_z, size_x, size_y, size_z (mm)
    train/000000/rgb/IIIIII.png    color (RGB)
    train/000000/depth/IIIIII.png  uint16 depth; depth × depth_scale = millimetres along the viewing axis
    train/000000/mask/IIIIII_GGGGGG.png        amodal silhouette of annotation G (255 inside)
    train/000000/mask_visib/IIIIII_GGGGGG.png  its visible part
    train/000000/scene_camera.json   per image: cam_K (row-wise, pixel centres at integers), cam_R_w2c,
                                     cam_t_w2c (mm), depth_scale
    train/000000/scene_gt.json       per image, per annotation: obj_id, cam_R_m2c (row-wise), cam_t_m2c (mm)
    train/000000/scene_gt_info.json  per image, per annotation: bbox_obj, bbox_visib, px_count_all,
                                     px_count_valid, px_count_visib, visib_fract

The annotations of an image are the scene's labelled items in ``Scene.items`` order (unlabelled ones, such as a
support plane, occlude but are not annotated); ``obj_id`` is the label's class id (1-based in ``Scene.labels``),
so items of one label must share one mesh and one scale. A BOP object is a mesh model: point clouds and splat sets
(``Scene.point_clouds``) are never annotated, labelled or not; they occlude the meshes (``mask_visib``) and are in
the depth images. Scene units are taken as metres (× 1000 = mm). A
modeling transform $A = R·S$ (polar decomposition: R a rotation, S symmetric positive definite) gives the pose R
and the model $1000·S·V$; BOP poses are rigid.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from frustum.batch.cameras import OPENCV_FROM_OPENGL, intrinsics
from frustum.batch.coco import read_views, rle_decode
from frustum.batch.jobs import _png_writer, write_atomically
from frustum.errors import OutputError

__all__ = ["BOP_SCENE", "bop_models", "bop_paths", "write_bop"]

BOP_SCENE = "train/000000"
"""Where the one scene of a frustum BOP dataset goes (split ``train``, scene id 0)."""
MILLIMETRES = 1000.0
"""Millimetres per scene unit (scenes are in metres)."""

View = tuple[str, Any, dict[str, str]]


def image_id(key: str) -> int:
    """A view key ``view_NNNNN`` → its image id N."""
    return int(key.rsplit("_", 1)[1])


def bop_paths(key: str) -> dict[str, str]:
    """A view's per-view files: color, depth and the annotations record the writer reads."""
    number = image_id(key)
    return {"rgb": f"{BOP_SCENE}/rgb/{number:06d}.png", "depth": f"{BOP_SCENE}/depth/{number:06d}.png",
            "annotations": f"annotations/{key}.json"}  # fmt: skip


def _polar(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """$A = R·S$ of a 3×3 matrix with positive determinant: $A = UΣVᵀ$, $R = UVᵀ$, $S = VΣVᵀ$."""
    u, sigma, vt = np.linalg.svd(matrix)
    return u @ vt, vt.T @ np.diag(sigma) @ vt


def bop_models(scene: Any, where: str = "render_dataset") -> dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per obj_id (class id): the model's vertices and normals in mm (scale applied) and its faces.

    Raises
    ------
    OutputError
        A scene without labelled meshes, a labelled item mirrored by its transform, or two items of one label with
        different meshes or scales.
    """
    labels = scene.labels
    if all(label is None for label in scene.item_labels()):
        raise OutputError(
            f"{where}: format = 'bop' needs labels on the scene's objects (obj_id is the label's class id; a BOP "
            "object is a mesh model) and the scene has none on its meshes; give label= to Scene.add or Node, or "
            'label = "..." on a scene file\'s node'
        )
    models: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    owners: dict[int, tuple[str, Any, np.ndarray]] = {}
    for item, label, path in zip(scene.items, scene.item_labels(), scene.item_paths(), strict=True):
        if label is None:
            continue
        number = labels.index(label) + 1
        block = np.asarray(item.world_from_model, dtype=np.float64)[:3, :3]
        if np.linalg.det(block) <= 0:
            raise OutputError(f"{where}: item {path!r} (label {label!r}) is mirrored by its transform; BOP poses are "
                              "rotations: place it without a reflection")  # fmt: skip
        _, stretch = _polar(block)
        if number in owners:
            first, mesh, first_stretch = owners[number]
            if mesh is not item.mesh or not np.allclose(stretch, first_stretch, rtol=1e-9, atol=1e-12):
                raise OutputError(
                    f"{where}: items {first!r} and {path!r} share label {label!r} but not one mesh and scale; a BOP "
                    "obj_id has one model: give them distinct labels"
                )
            continue
        owners[number] = (path, item.mesh, stretch)
        vertices = MILLIMETRES * np.asarray(item.mesh.vertices, dtype=np.float64) @ stretch.T
        normals = np.asarray(item.mesh.vertex_normals, dtype=np.float64) @ np.linalg.inv(stretch)
        normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
        models[number] = (vertices, normals, np.asarray(item.mesh.faces, dtype=np.int64))
    return models


def _ply(vertices: np.ndarray, normals: np.ndarray, faces: np.ndarray) -> str:
    """An ASCII PLY of vertices with normals and triangle faces."""
    header = ["ply", "format ascii 1.0", "comment frustum BOP model, millimetres", f"element vertex {len(vertices)}",
              "property float x", "property float y", "property float z", "property float nx", "property float ny",
              "property float nz", f"element face {len(faces)}", "property list uchar int vertex_indices",
              "end_header"]  # fmt: skip
    rows = [" ".join(f"{v:.9g}" for v in (*p, *n)) for p, n in zip(vertices.tolist(), normals.tolist(), strict=True)]
    polygons = [f"3 {a} {b} {c}" for a, b, c in faces.tolist()]
    return "\n".join([*header, *rows, *polygons]) + "\n"


def _diameter(vertices: np.ndarray) -> float:
    """The largest distance between two vertices (over the convex hull's vertices, in chunks)."""
    points = vertices
    if len(points) > 4:
        from scipy.spatial import ConvexHull

        try:
            points = vertices[ConvexHull(vertices).vertices]
        except Exception:  # a flat model (qhull refuses it): every vertex
            points = vertices
    best = 0.0
    for start in range(0, len(points), 512):
        block = points[start : start + 512]
        best = max(best, float(np.sqrt(((block[:, None, :] - points[None]) ** 2).sum(axis=2)).max()))
    return best


def _json(data: Any) -> Any:
    text = json.dumps(data, indent=2) + "\n"
    return lambda file: file.write(text.encode("utf-8"))


def write_bop(folder: Path, views: Sequence[View], extra: dict[str, Any]) -> list[Path]:
    """The models, masks and ``scene_*.json`` files (module docstring) from the views' annotation records."""
    scene = extra["scene"]
    depth_scale = float(extra["bop_depth_scale"])
    written = []
    info = {}
    for number, (vertices, normals, faces) in sorted(bop_models(scene).items()):
        target = folder / "models" / f"obj_{number:06d}.ply"
        text = _ply(vertices, normals, faces)
        write_atomically(target, lambda file, text=text: file.write(text.encode("ascii")))
        written.append(target)
        low, high = vertices.min(axis=0), vertices.max(axis=0)
        info[str(number)] = {"diameter": _diameter(vertices), "min_x": float(low[0]), "min_y": float(low[1]),
                             "min_z": float(low[2]), "size_x": float(high[0] - low[0]),
                             "size_y": float(high[1] - low[1]), "size_z": float(high[2] - low[2])}  # fmt: skip
    write_atomically(folder / "models" / "models_info.json", _json(info))
    written.append(folder / "models" / "models_info.json")
    cameras, truths, truth_info = {}, {}, {}
    for (key, camera, _), view in zip(views, read_views(folder, views), strict=True):
        number = image_id(key)
        pinhole = intrinsics(camera, where="render_dataset")
        k_matrix = [pinhole["fx"], 0.0, pinhole["cx"] - 0.5, 0.0, pinhole["fy"], pinhole["cy"] - 0.5, 0.0, 0.0, 1.0]
        camera_from_world = OPENCV_FROM_OPENGL @ np.asarray(camera.view_matrix, dtype=np.float64)
        cameras[str(number)] = {"cam_K": k_matrix, "cam_R_w2c": camera_from_world[:3, :3].ravel().tolist(),
                                "cam_t_w2c": (MILLIMETRES * camera_from_world[:3, 3]).tolist(),
                                "depth_scale": depth_scale}  # fmt: skip
        gts, infos = [], []
        for item in (entry for entry in view["objects"] if entry["class_id"] > 0 and entry["kind"] == "mesh"):
            pose = np.asarray(item["pose"], dtype=np.float64)
            rotation, _ = _polar(pose[:3, :3])
            gts.append({"cam_R_m2c": rotation.ravel().tolist(), "cam_t_m2c": (MILLIMETRES * pose[:3, 3]).tolist(),
                        "obj_id": item["class_id"]})  # fmt: skip
            total, seen = item["px_count_all"], item["px_count_visible"]
            infos.append({"bbox_obj": item["bbox_amodal"], "bbox_visib": item["bbox_visible"], "px_count_all": total,
                          "px_count_valid": item["px_count_valid"], "px_count_visib": seen,
                          "visib_fract": seen / total if total else 0.0})  # fmt: skip
            gt = len(gts) - 1
            for sub, rle in (("mask", item["segmentation_amodal"]), ("mask_visib", item["segmentation_visible"])):
                mask = np.where(rle_decode(rle), 255, 0).astype(np.uint8)
                target = folder / BOP_SCENE / sub / f"{number:06d}_{gt:06d}.png"
                write_atomically(target, _png_writer(mask))
                written.append(target)
        truths[str(number)], truth_info[str(number)] = gts, infos
    for name, data in (("scene_camera.json", cameras), ("scene_gt.json", truths), ("scene_gt_info.json", truth_info)):
        write_atomically(folder / BOP_SCENE / name, _json(data))
        written.append(folder / BOP_SCENE / name)
    return written
