"""Camera files of a multi-view dataset, one small writer per format (``CAMERA_WRITERS``).

Each writer takes the dataset folder, the finished views in key order as ``(key, camera, files)`` (``files``
maps output kind to a path relative to the folder) and writes its files atomically; it returns their paths.
Conventions and formulas: ``frustum.batch.cameras``.
"""

from __future__ import annotations

import io
import json
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from frustum.batch.bop import write_bop
from frustum.batch.cameras import camera_record, colmap_pose, intrinsics
from frustum.batch.coco import write_coco
from frustum.batch.jobs import write_atomically
from frustum.camera import Camera
from frustum.errors import CameraError

__all__ = ["CAMERA_WRITERS", "SHARD_SIZE", "check_format_camera"]

SHARD_SIZE = 1000
"""Views per WebDataset tar shard."""
_TOLERANCE = 1e-9

View = tuple[str, Camera, dict[str, str]]


def _json_writer(data: Any) -> Callable:
    text = json.dumps(data, indent=2, sort_keys=False) + "\n"
    return lambda file: file.write(text.encode("utf-8"))


def _text_writer(text: str) -> Callable:
    return lambda file: file.write(text.encode("utf-8"))


def check_format_camera(format: str, camera: Camera, where: str) -> None:
    """Raise CameraError if `format` cannot describe `camera` (one check before any view is rendered)."""
    if format in ("files", "webdataset", "coco"):
        return
    pinhole = intrinsics(camera, where=where)
    if format == "nerf":
        centred = (
            abs(pinhole["cx"] - camera.width / 2) <= _TOLERANCE * camera.width
            and abs(pinhole["cy"] - camera.height / 2) <= _TOLERANCE * camera.height
            and abs(pinhole["fx"] - pinhole["fy"]) <= _TOLERANCE * pinhole["fx"]
        )
        if not centred:
            raise CameraError(
                f"{where}: format = 'nerf' with an off-centre or non-square pinhole (fx = {pinhole['fx']:.6g}, "
                f"fy = {pinhole['fy']:.6g}, cx = {pinhole['cx']:.6g}, cy = {pinhole['cy']:.6g}); camera_angle_x "
                "describes a centred one only: use format 'nerfstudio' or 'colmap'"
            )


def _frame_entry(key: str, camera: Camera, files: dict[str, str], *, blender: bool) -> dict[str, Any]:
    record = camera_record(camera)
    color = files["color"]
    entry: dict[str, Any] = {
        "file_path": "./" + color[: -len(".png")] if blender else color,
        "transform_matrix": record["camera_to_world_opengl"],
    }
    if "depth" in files:
        entry["depth_file_path"] = files["depth"]
    if "mask" in files and not blender:
        entry["mask_path"] = files["mask"]
    return entry


def write_nerf(folder: Path, views: Sequence[View], extra: dict[str, Any]) -> list[Path]:
    """Blender-NeRF ``transforms.json``: ``camera_angle_x`` and per frame an OpenGL camera-to-world matrix.

    ``file_path`` omits ``.png``, as in the NeRF synthetic scenes (their loaders append it).
    """
    if not views:
        return []
    first = camera_record(views[0][1])
    data = {
        "camera_angle_x": first["camera_angle_x"],
        "frames": [_frame_entry(key, camera, files, blender=True) for key, camera, files in views],
    }
    target = folder / "transforms.json"
    write_atomically(target, _json_writer(data))
    return [target]


def write_nerfstudio(folder: Path, views: Sequence[View], extra: dict[str, Any]) -> list[Path]:
    """nerfstudio ``transforms.json``: shared ``fl_x, fl_y, cx, cy, w, h`` (OPENCV model, no distortion)."""
    if not views:
        return []
    first = camera_record(views[0][1])
    data: dict[str, Any] = {
        "camera_model": "OPENCV",
        "fl_x": first["fx"], "fl_y": first["fy"], "cx": first["cx"], "cy": first["cy"],
        "w": first["width"], "h": first["height"],
        "k1": 0.0, "k2": 0.0, "p1": 0.0, "p2": 0.0,
    }  # fmt: skip
    if "depth_unit_scale_factor" in extra:
        data["depth_unit_scale_factor"] = extra["depth_unit_scale_factor"]
    data["frames"] = [_frame_entry(key, camera, files, blender=False) for key, camera, files in views]
    target = folder / "transforms.json"
    write_atomically(target, _json_writer(data))
    return [target]


def write_colmap(folder: Path, views: Sequence[View], extra: dict[str, Any]) -> list[Path]:
    """COLMAP text model in ``sparse/0``: ``cameras.txt`` (one PINHOLE camera), ``images.txt``, ``points3D.txt``.

    images.txt gives world-to-camera poses (OpenCV axes) as ``QW QX QY QZ TX TY TZ``, each followed by an empty
    POINTS2D line; NAME is the image's path relative to ``images/``.
    """
    sparse = folder / "sparse" / "0"
    if not views:
        return []
    first = camera_record(views[0][1])
    w, h = first["width"], first["height"]
    cameras = (
        "# Camera list with one line of data per camera:\n"
        "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
        "# Number of cameras: 1\n"
        f"1 PINHOLE {w} {h} {first['fx']!r} {first['fy']!r} {first['cx']!r} {first['cy']!r}\n"
    )
    lines = [
        "# Image list with two lines of data per image:",
        "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME",
        "#   POINTS2D[] as (X, Y, POINT3D_ID)",
        f"# Number of images: {len(views)}, mean observations per image: 0",
    ]
    for image_id, (_, camera, files) in enumerate(views, start=1):
        (qw, qx, qy, qz), (tx, ty, tz) = colmap_pose(camera)
        name = files["color"].split("/", 1)[1]
        lines += [f"{image_id} {qw!r} {qx!r} {qy!r} {qz!r} {tx!r} {ty!r} {tz!r} 1 {name}", ""]
    points = "# 3D point list with one line of data per point:\n#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[]\n"
    written = []
    for name, text in (("cameras.txt", cameras), ("images.txt", "\n".join(lines) + "\n"), ("points3D.txt", points)):
        write_atomically(sparse / name, _text_writer(text))
        written.append(sparse / name)
    return written


def write_files(folder: Path, views: Sequence[View], extra: dict[str, Any]) -> list[Path]:
    """Only ``cameras.json`` (written for every format): nothing more."""
    return []


def _tar_member(archive: Any, name: str, data: bytes) -> None:
    import tarfile

    info = tarfile.TarInfo(name)  # fixed metadata: the same views give the same shard bytes
    info.size, info.mtime, info.mode, info.uid, info.gid, info.uname, info.gname = len(data), 0, 0o644, 0, 0, "", ""
    archive.addfile(info, io.BytesIO(data))


def write_webdataset(folder: Path, views: Sequence[View], extra: dict[str, Any]) -> list[Path]:
    """WebDataset tar shards ``shards/shard-000000.tar`` of `SHARD_SIZE` views each.

    A sample is the files sharing a key (keys have no dots): ``<key>.png`` (color), ``<key>.depth.npy`` (or
    ``.depth.png``), ``<key>.normals.npy``, ``<key>.object_id.png``, ``<key>.mask.png``, ``<key>.json`` (the
    camera record of ``cameras.json``).
    """
    import tarfile

    written = []
    for shard in range(math.ceil(len(views) / SHARD_SIZE)):
        chunk = views[shard * SHARD_SIZE : (shard + 1) * SHARD_SIZE]
        buffer = io.BytesIO()
        with tarfile.open(fileobj=buffer, mode="w", format=tarfile.USTAR_FORMAT) as archive:
            for key, camera, files in chunk:
                for kind, relative in files.items():
                    suffix = Path(relative).suffix
                    name = f"{key}{suffix}" if kind == "color" else f"{key}.{kind}{suffix}"
                    _tar_member(archive, name, (folder / relative).read_bytes())
                record = json.dumps(camera_record(camera), indent=2) + "\n"
                _tar_member(archive, f"{key}.json", record.encode("utf-8"))
        target = folder / "shards" / f"shard-{shard:06d}.tar"
        data = buffer.getvalue()
        write_atomically(target, lambda file, data=data: file.write(data))
        written.append(target)
    return written


CAMERA_WRITERS: dict[str, Callable[[Path, Sequence[View], dict[str, Any]], list[Path]]] = {
    "nerf": write_nerf,
    "nerfstudio": write_nerfstudio,
    "colmap": write_colmap,
    "files": write_files,
    "webdataset": write_webdataset,
    "coco": write_coco,
    "bop": write_bop,
}
"""Dataset format name to its camera-file writer."""
