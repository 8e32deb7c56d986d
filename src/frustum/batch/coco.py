"""COCO instance annotations (``render_dataset(format="coco")``): one ``annotations.json`` beside the RGB images.

Per view the workers write ``annotations/<key>.json`` (``view_annotations``: ``frustum.annotate``'s records with
the visible and amodal masks as RLE); at the end ``write_coco`` gathers them into COCO's ``images``,
``categories`` (the scene's labels, ids 1-based as ``Scene.labels``) and ``annotations``: one per labelled item
with visible pixels, ``segmentation`` an RLE of its instance mask (``counts`` a compressed string, exactly as
pycocotools encodes it), ``area`` its pixel count, ``bbox`` its ``[x, y, w, h]``, ``iscrowd`` 0 and, where
keypoints were given, ``keypoints`` $[u_1, v_1, f_1, …]$ and ``num_keypoints`` (the count with $f > 0$).

RLE (COCO's run-length encoding): the mask read column by column (Fortran order) as alternating runs of 0 and 1,
starting with 0s; each run length $x_i$ (minus $x_{i−2}$ for $i > 2$) is written in 5-bit groups, low first, each
group $c$ with bit 5 set when more follow, as the character $c + 48$ (pycocotools' ``rleToString``).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from frustum.batch.storage import write_atomically

__all__ = ["rle_decode", "rle_encode", "view_annotations", "write_coco"]

View = tuple[str, Any, dict[str, str]]


def rle_encode(mask: np.ndarray) -> dict[str, Any]:
    """COCO compressed RLE ``{"size": [H, W], "counts": str}`` of an (H, W) bool mask (module docstring)."""
    flat = np.asarray(mask, dtype=bool).ravel(order="F")
    changes = np.flatnonzero(flat[1:] != flat[:-1]) + 1
    bounds = np.concatenate([[0], changes, [flat.size]])
    runs = np.diff(bounds).tolist()
    if flat.size and flat[0]:
        runs = [0, *runs]
    characters = []
    for i, run in enumerate(runs):
        x = run - runs[i - 2] if i > 2 else run
        more = True
        while more:
            c = x & 0x1F
            x >>= 5
            more = x != -1 if c & 0x10 else x != 0
            if more:
                c |= 0x20
            characters.append(chr(c + 48))
    return {"size": [int(mask.shape[0]), int(mask.shape[1])], "counts": "".join(characters)}


def rle_decode(rle: dict[str, Any]) -> np.ndarray:
    """The (H, W) bool mask of a compressed RLE (the inverse of ``rle_encode``)."""
    height, width = rle["size"]
    text = rle["counts"]
    runs: list[int] = []
    p = 0
    while p < len(text):
        x, k, more = 0, 0, True
        while more:
            c = ord(text[p]) - 48
            x |= (c & 0x1F) << (5 * k)
            more = bool(c & 0x20)
            p += 1
            k += 1
            if not more and c & 0x10:
                x |= -1 << (5 * k)
        if len(runs) > 2:
            x += runs[-2]
        runs.append(x)
    values = np.zeros(height * width, dtype=bool)
    position = 0
    for i, run in enumerate(runs):
        if i % 2:
            values[position : position + run] = True
        position += run
    return values.reshape((width, height)).T


def _finite(value: float) -> float | None:
    return None if math.isnan(value) else float(value)


def view_annotations(frame: Any, scene: Any, camera: Any, keypoints: Any = None) -> dict[str, Any]:
    """One view's JSON record (``annotations/<key>.json``): the image size and ``frustum.annotate``'s records with
    the masks as RLE (``segmentation_visible``, ``segmentation_amodal``) and ``px_count_valid`` (amodal pixels with
    a depth, BOP's field)."""
    from frustum.output.annotations import annotate

    records = annotate(frame, scene, camera, keypoints)
    instance = frame.instance if frame.instance is not None else frame.object_id
    drawn = frame.depth < 1.0
    objects = []
    for k, record in enumerate(records):
        amodal = frame.amodal[k]
        entry = {
            "name": record["name"], "kind": record["kind"], "label": record["label"], "class_id": record["class_id"],
            "bbox_visible": record["bbox_visible"], "bbox_amodal": record["bbox_amodal"],
            "bbox_3d": [[_finite(v) for v in row] for row in record["bbox_3d"].tolist()],
            "bbox_3d_visible": [bool(v) for v in record["bbox_3d_visible"]],
            "pose": record["pose"].tolist(), "visibility": _finite(record["visibility"]),
            "px_count_visible": record["px_count_visible"], "px_count_all": record["px_count_all"],
            "px_count_valid": int((amodal & drawn).sum()),
            "segmentation_visible": rle_encode(instance == k), "segmentation_amodal": rle_encode(amodal),
        }  # fmt: skip
        if "keypoints" in record:
            entry["keypoints"] = [[_finite(v) for v in row] for row in record["keypoints"].tolist()]
        objects.append(entry)
    return {"width": camera.width, "height": camera.height, "objects": objects}


def read_views(folder: Any, views: Sequence[View]) -> list[dict[str, Any]]:
    """The per-view records the workers wrote, in view order."""
    return [json.loads((folder / files["annotations"]).read_bytes()) for _, _, files in views]


def write_coco(folder: Path, views: Sequence[View], extra: dict[str, Any]) -> list[Path]:
    """``annotations.json`` (module docstring) from the views' ``annotations/<key>.json``."""
    labels = list(extra.get("labels", ()))
    keypoint_count = int(extra.get("keypoint_count", 0))
    categories = []
    for i, label in enumerate(labels):
        category: dict[str, Any] = {"id": i + 1, "name": label, "supercategory": "object"}
        if keypoint_count:
            category["keypoints"] = [str(j) for j in range(keypoint_count)]
            category["skeleton"] = []
        categories.append(category)
    images, annotations = [], []
    for image_id, ((_, _, files), view) in enumerate(zip(views, read_views(folder, views), strict=True), start=1):
        images.append({"id": image_id, "file_name": files["rgb"], "width": view["width"],
                       "height": view["height"]})  # fmt: skip
        for item in view["objects"]:
            if item["class_id"] == 0 or item["px_count_visible"] == 0:
                continue
            annotation: dict[str, Any] = {
                "id": len(annotations) + 1, "image_id": image_id, "category_id": item["class_id"],
                "segmentation": item["segmentation_visible"], "area": item["px_count_visible"],
                "bbox": item["bbox_visible"], "iscrowd": 0,
            }  # fmt: skip
            if "keypoints" in item:
                flat: list[float] = []
                for u, v, flag in item["keypoints"]:
                    flat += [u, v, flag] if flag else [0.0, 0.0, 0.0]
                annotation["keypoints"] = flat
                annotation["num_keypoints"] = sum(1 for *_, flag in item["keypoints"] if flag)
            annotations.append(annotation)
    data = {
        "info": {"description": "frustum synthetic dataset", "seed": extra.get("seed")},
        "images": images,
        "categories": categories,
        "annotations": annotations,
    }
    target = folder / "annotations.json"
    text = json.dumps(data) + "\n"
    write_atomically(target, lambda file: file.write(text.encode("utf-8")))
    return [target]
