"""Multi-view datasets: cameras laid out around a scene, every buffer written per view, resumable and safe.

``render_dataset`` (and ``frustum dataset``) renders N views of a scene file and writes, under one folder::

    images/<key>.png      color, RGBA 8-bit
    depth/<key>.npy       metric z-depth, float32, 0 on background (or depth/<key>.png, uint16 · depth_scale)
    normals/<key>.npy     unit world normals, float32 (H, W, 3), 0 on background
    object_id/<key>.png   uint16 scene item index + 1, 0 on background
    masks/<key>.png       uint8 255 where a surface was drawn
    cameras.json          every view's intrinsics and poses in every convention (``cameras.camera_record``)
    transforms.json | sparse/0/*.txt | shards/*.tar   the format's camera files
    README.txt            the conventions
    manifest.jsonl        the run log: the configuration, then one line per finished view

Safety: every file is written under a temporary name and renamed; a run that stops (Ctrl-C, a crash, SIGKILL)
is resumed by running the same command again, which skips the views the manifest lists whose files exist.
A different configuration is refused (saying what changed) unless ``overwrite=True``. Views that fail are
retried, then listed with their errors.

`out` may be an fsspec URL (``s3://bucket/prefix``, ``gs://…``, ``file://…``, ``memory://…``;
``frustum.batch.storage``): the same files, each written whole or not at all. An object cannot be appended
to, so there the run log goes in parts (``manifest.parts/*.jsonl``, one every ``URL_LOG_SECONDS`` while views
finish) that the end of the run merges into ``manifest.jsonl``; resuming reads both, so a killed driver
loses at most the last few seconds of its log (those views are rendered again, to the same bytes).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from frustum._arrays import describe
from frustum.batch.bop import BOP_SCENE, bop_models, bop_paths
from frustum.batch.cameras import camera_record
from frustum.batch.executors import EXECUTORS, render_many
from frustum.batch.formats import CAMERA_WRITERS, SHARD_SIZE, check_format_camera
from frustum.batch.jobs import RenderJob
from frustum.batch.progress import ViewProgress
from frustum.batch.storage import TEMPORARY_MARK, RemotePath, to_location, write_atomically
from frustum.camera import Camera
from frustum.errors import CameraError, FrustumError, OutputError
from frustum.scene import Scene

__all__ = ["DEPTH_FORMATS", "FORMATS", "LAYOUTS", "DatasetResult", "dataset_cameras", "render_dataset", "view_seed"]

LAYOUTS = ("orbit", "sphere", "random", "file")
"""Camera layouts: a circle at the scene camera's height, a Fibonacci sphere, seeded random directions, a file."""
FORMATS = tuple(CAMERA_WRITERS)
"""Dataset formats (camera files): nerf, nerfstudio, colmap, files, webdataset; coco and bop (ground truth:
``frustum.batch.coco``, ``frustum.batch.bop``)."""
GROUND_TRUTH_FORMATS = ("coco", "bop")
"""Formats whose views are RGB images with per-object annotations rather than every buffer."""
DEPTH_FORMATS = ("npy", "png16")
"""Depth files: float32 .npy, or 16-bit PNG in steps of ``depth_scale`` world units."""
_FOLDERS = {"color": "images", "depth": "depth", "normals": "normals", "object_id": "object_id", "mask": "masks",
            "position": "position", "shadow": "shadow", "rgb": "images", "annotations": "annotations"}  # fmt: skip
_SUFFIXES = {"color": ".png", "depth": ".npy", "normals": ".npy", "object_id": ".png", "mask": ".png"}
_MANIFEST = "manifest.jsonl"
_MANIFEST_PARTS = "manifest.parts"
URL_LOG_SECONDS = 2.0
"""A URL output's run log is written as a new part at most this often (and when 1000 views are waiting)."""
_URL_LOG_LINES = 1000
_SHARED_FILES = ("cameras.json", "README.txt", "transforms.json", "sparse/0/cameras.txt", "sparse/0/images.txt",
                 "sparse/0/points3D.txt")  # fmt: skip
_BYTES_PER_PIXEL = 64
"""Render work per drawn sample: color 4, depth 4, normals 12, ids 4, face codes 8, barycentrics 8, slack."""
_BYTES_PER_OUTPUT_PIXEL = 48
"""Encoding per output pixel: metric depth in float64 and float32, ids in int64, the mask."""
_POLE = 0.999
"""|direction · y| above which a view uses z as its up vector (y would be nearly parallel to the line of sight)."""


@dataclass(frozen=True)
class DatasetResult:
    """What ``render_dataset`` did: views rendered now, skipped (done before), failed (key → error), files."""

    out: Path | str
    rendered: tuple[str, ...]
    skipped: tuple[str, ...]
    failed: dict[str, str] = field(default_factory=dict)
    camera_files: tuple[Path | str, ...] = ()

    @property
    def ok(self) -> bool:
        return not self.failed


def view_seed(seed: int, key: str) -> int:
    """A view's 64-bit seed from the base `seed` and its key (BLAKE2b): independent of view order and count."""
    digest = hashlib.blake2b(f"{int(seed)}/{key}".encode(), digest_size=8).digest()
    return int.from_bytes(digest, "little")


def _view_keys(count: int) -> list[str]:
    digits = max(5, len(str(count - 1)))
    return [f"view_{i:0{digits}d}" for i in range(count)]


def _aimed(camera: Camera, eye: np.ndarray, target: np.ndarray) -> Camera:
    direction = (target - eye) / np.linalg.norm(target - eye)
    up = (0.0, 1.0, 0.0) if abs(direction[1]) < _POLE else (0.0, 0.0, -1.0)
    return Camera.look_at(eye, target, up, camera.projection, camera.width, camera.height)


def _cameras_from_file(path: Path, camera: Camera, where: str) -> list[Camera]:
    try:
        entries = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise CameraError(f"{where}: cameras = {str(path)!r} cannot be read as JSON ({error}); give a JSON list "
                          'of {"eye": [x, y, z], "target": [x, y, z], "up": [x, y, z]}') from None  # fmt: skip
    if not isinstance(entries, list) or not entries:
        raise CameraError(f"{where}: cameras = {str(path)!r} holds {describe(entries)}; expected a non-empty JSON list")
    cameras = []
    for i, entry in enumerate(entries):
        if not isinstance(entry, dict) or "eye" not in entry or "target" not in entry:
            raise CameraError(f"{where}: {path}[{i}] = {describe(entry)} needs 'eye' and 'target' (and optional 'up')")
        try:
            cameras.append(Camera.look_at(entry["eye"], entry["target"], entry.get("up", (0.0, 1.0, 0.0)),
                                          camera.projection, camera.width, camera.height))  # fmt: skip
        except FrustumError as error:
            raise CameraError(f"{where}: {path}[{i}]: {error}") from None
    return cameras


def dataset_cameras(
    camera: Camera,
    views: int | None,
    layout: str = "orbit",
    *,
    seed: int = 0,
    target: Any = None,
    cameras_file: str | os.PathLike | None = None,
) -> list[tuple[str, Camera]]:
    """``(key, camera)`` per view: `camera`'s projection and size, placed by `layout` around `target`.

    The radius is `camera`'s distance to `target` (default: its look-at point). ``"orbit"``: azimuths
    $a₀ + 2πi/N$ at the camera's elevation (y up). ``"sphere"``: the Fibonacci sphere,
    $y_i = 1 − (2i + 1)/N$, longitude $i·π(3 − √5)$. ``"random"``: a direction uniform on the sphere drawn
    from ``view_seed(seed, key)``. ``"file"``: a JSON list of ``{"eye", "target", "up"}`` (`views` None or
    equal to its length). Views within 2.6° of the poles use z as the up vector.

    Raises
    ------
    CameraError
        Unknown layout (the valid ones listed), views < 1, an unreadable cameras file, a camera on the target.
    """
    where = "dataset_cameras"
    if layout not in LAYOUTS:
        raise CameraError(f"{where}: layout = {layout!r} is unknown; expected one of {', '.join(LAYOUTS)}")
    if layout == "file":
        if cameras_file is None:
            raise CameraError(f"{where}: layout = 'file' needs cameras_file (--cameras), a JSON list of cameras")
        cameras = _cameras_from_file(Path(cameras_file), camera, where)
        if views is not None and views != len(cameras):
            raise CameraError(f"{where}: views = {views!r} but {cameras_file} lists {len(cameras)} cameras; "
                              "leave views out or give the same count")  # fmt: skip
        return list(zip(_view_keys(len(cameras)), cameras, strict=True))
    if isinstance(views, bool) or not isinstance(views, int | np.integer) or views < 1:
        raise CameraError(f"{where}: views = {describe(views)} must be a positive integer")
    views = int(views)
    center = np.asarray(camera.frame.target if target is None else target, dtype=np.float64)
    eye = np.asarray(camera.frame.eye, dtype=np.float64)
    radius = float(np.linalg.norm(eye - center))
    if radius == 0.0:
        raise CameraError(f"{where}: the camera's eye {describe(eye)} sits on the target; the radius must be > 0")
    keys = _view_keys(views)
    offset = (eye - center) / radius
    if layout == "orbit":
        elevation = math.asin(max(-_POLE, min(_POLE, offset[1])))
        azimuth = math.atan2(offset[0], offset[2])
        directions = []
        for i in range(views):
            a = azimuth + 2.0 * math.pi * i / views
            ring = math.cos(elevation)
            directions.append((ring * math.sin(a), math.sin(elevation), ring * math.cos(a)))
    elif layout == "sphere":
        golden = math.pi * (3.0 - math.sqrt(5.0))
        directions = []
        for i in range(views):
            y = 1.0 - (2.0 * i + 1.0) / views
            r = math.sqrt(max(0.0, 1.0 - y * y))
            directions.append((r * math.cos(golden * i), y, r * math.sin(golden * i)))
    else:
        directions = []
        for key in keys:
            d = np.random.default_rng(view_seed(seed, key)).normal(size=3)
            directions.append(tuple(d / np.linalg.norm(d)))
    eyes = center + radius * np.asarray(directions)
    return [(key, _aimed(camera, eye_i, center)) for key, eye_i in zip(keys, eyes, strict=True)]


# --- manifest ---------------------------------------------------------------------------------------------------


def _read_manifest(out: Any) -> tuple[dict | None, dict[str, dict]]:
    """The configuration line and the finished views of a run log, every line checked.

    Only a torn last line (a killed run: no newline after it) is ignored; any other line that is not a
    configuration or a view entry, or a view entry naming a file outside `out`, stops the run with an
    ``OutputError`` naming the file and the line. At a URL, the parts of runs that did not reach their end
    (``manifest.parts/``) are read after the log, each checked the same way.
    """
    path = out / _MANIFEST
    if not isinstance(out, RemotePath) and path.is_symlink():
        raise OutputError(f"{path}: the run log is a symbolic link; frustum neither reads nor writes a run log "
                          "through one (remove it, or give another folder)")  # fmt: skip
    if not path.exists():
        return None, {}
    logs = [path, *(_log_parts(out) if isinstance(out, RemotePath) else [])]
    config, views = None, {}
    for log in logs:
        text = log.read_text(encoding="utf-8", errors="replace")
        lines = text.split("\n")
        for number, line in enumerate(lines, start=1):
            if not line.strip():
                continue
            torn = number == len(lines)  # the text does not end with a newline: its last line may be torn
            entry = _manifest_entry(line, out, where=f"{log}, line {number}", torn=torn)
            if entry is None:
                continue
            if "config" in entry:
                if config is not None or views:
                    raise OutputError(f"{log}, line {number}: a second configuration line; the run log is "
                                      "damaged (rerun with --overwrite to start again)")  # fmt: skip
                config = entry["config"]
            else:
                views[entry["view"]] = entry
    if views and config is None:
        raise OutputError(f"{path}: view lines but no configuration line; the run log is damaged "
                          "(rerun with --overwrite to start again)")  # fmt: skip
    return config, views


def _manifest_entry(line: str, out: Any, *, where: str, torn: bool) -> dict | None:
    """One run-log line checked: ``{"config": {...}}`` or ``{"view": key, "files": {kind: relative path}}``
    with every path inside `out` (after symbolic links); None for a torn last line."""
    try:
        entry = json.loads(line)
    except (json.JSONDecodeError, RecursionError, ValueError):
        if torn:
            return None
        raise OutputError(f"{where}: not a JSON line; the run log is damaged (rerun with --overwrite to start "
                          "again, or give another folder)") from None  # fmt: skip
    if isinstance(entry, dict) and set(entry) == {"config"} and isinstance(entry["config"], dict):
        return entry
    files = entry.get("files") if isinstance(entry, dict) else None
    if not (isinstance(entry, dict) and isinstance(entry.get("view"), str) and isinstance(files, dict)
            and all(isinstance(k, str) and isinstance(v, str) for k, v in files.items())):  # fmt: skip
        if torn:
            return None
        raise OutputError(f"{where}: expected a configuration line or a view line "
                          '({"view": KEY, "files": {KIND: PATH}}), got ' + describe(entry))  # fmt: skip
    for relative in files.values():
        _check_inside(out, relative, where)
    return entry


def _check_inside(out: Any, relative: str, where: str) -> None:
    """A path a run log names: one of the dataset's folders, inside `out` once symbolic links are followed."""
    parts = relative.replace("\\", "/").split("/")
    if (relative.startswith(("/", "\\")) or ".." in parts or ":" in parts[0] or len(parts) < 2
            or parts[0] not in _FOLDERS.values()):  # fmt: skip
        folders = ", ".join(sorted(set(_FOLDERS.values())))
        raise OutputError(f"{where}: the path {relative!r} is not a file of this dataset's folders ({folders}); "
                          "the run log is damaged or forged")  # fmt: skip
    if not isinstance(out, RemotePath):
        root = Path(out).resolve()
        if not Path(out, relative).resolve().is_relative_to(root):
            raise OutputError(f"{where}: the path {relative!r} leads outside {str(out)!r} through a symbolic "
                              "link; frustum reads and removes only files inside the output folder")  # fmt: skip


def _log_parts(out: RemotePath) -> list[RemotePath]:
    folder = out / _MANIFEST_PARTS
    return folder.glob("*.jsonl") if folder.exists() else []


class _RunLog:
    """The run log, one line per finished view. A folder: appended and flushed line by line. A URL: new parts
    every `URL_LOG_SECONDS` (an object cannot be appended to), merged into ``manifest.jsonl`` by ``close``."""

    def __init__(self, out: Any, config: dict | None) -> None:
        self.out, self.remote = out, isinstance(out, RemotePath)
        self.lines: list[str] = []
        self.flushed = time.monotonic()
        self.run = f"{time.time_ns():020d}-{os.getpid()}"
        self.parts = 0
        if not self.remote:
            flags = os.O_WRONLY | os.O_APPEND | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0)  # never through a link
            self.file: Any = os.fdopen(os.open(out / _MANIFEST, flags, 0o666), "a", encoding="utf-8")
            if config is not None:
                self.write(json.dumps({"config": config}))
        elif config is not None:
            (out / _MANIFEST).write_bytes((json.dumps({"config": config}) + "\n").encode("utf-8"))

    def write(self, line: str) -> None:
        if not self.remote:
            self.file.write(line + "\n")
            self.file.flush()
            return
        self.lines.append(line)
        if len(self.lines) >= _URL_LOG_LINES or time.monotonic() - self.flushed >= URL_LOG_SECONDS:
            self.flush()

    def flush(self) -> None:
        if self.remote and self.lines:
            part = self.out / _MANIFEST_PARTS / f"{self.run}-{self.parts:06d}.jsonl"
            part.write_bytes(("\n".join(self.lines) + "\n").encode("utf-8"))
            self.parts += 1
            self.lines = []
        self.flushed = time.monotonic()

    def close(self) -> None:
        if not self.remote:
            self.file.close()
            return
        self.flush()
        parts = _log_parts(self.out)
        if parts:  # merge: the new log first, then the parts go (a stop between leaves repeated lines, harmless)
            text = "\n".join(p.read_text(errors="replace").rstrip("\n") for p in [self.out / _MANIFEST, *parts])
            (self.out / _MANIFEST).write_bytes((text + "\n").encode("utf-8"))
            for part in parts:
                part.unlink(missing_ok=True)
            (self.out / _MANIFEST_PARTS).rmdir()


def _changes(old: dict, new: dict) -> list[str]:
    return [f"{k} = {old.get(k)!r} → {new.get(k)!r}" for k in sorted(set(old) | set(new)) if old.get(k) != new.get(k)]


def _sha256(path: Path | None) -> str | None:
    return None if path is None else hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _check_budget(scene_file: Any, camera: Camera, executor: str, workers: int | None, where: str) -> None:
    """Memory of the views drawn at once on this machine: frame buffers and a copy of the scene per worker."""
    from frustum.budgets import check_memory

    concurrent = 1 if executor != "process" else (workers or os.cpu_count() or 1)
    samples = int(scene_file.options.get("samples", 1))
    per_view = camera.width * camera.height * (_BYTES_PER_PIXEL * samples + _BYTES_PER_OUTPUT_PIXEL)
    scene_bytes = sum(item.mesh.vertices.nbytes * 3 + item.mesh.faces.nbytes for item in scene_file.scene.items)
    cause = f"size = {camera.width}x{camera.height}, samples = {samples}, {concurrent} views at once"
    check_memory(concurrent * (per_view + scene_bytes), where=where, cause=cause, error=OutputError)


def _check_folder(out: Any, where: str) -> None:
    remote = isinstance(out, RemotePath)
    try:
        if out.is_file():
            raise OutputError(f"{where}: out = {str(out)!r} is a file; give a folder (it is created if missing)")
        out.mkdir(parents=True, exist_ok=True)
        write_atomically(out / ".write-test", lambda file: file.write(b"frustum"))
        (out / ".write-test").unlink()
    except OutputError:
        raise
    except Exception as error:  # OSError locally; fsspec back ends (s3fs, gcsfs) raise their own types too
        if not remote and not isinstance(error, OSError):
            raise
        reason = getattr(error, "strerror", None) or " ".join(str(error).split()) or type(error).__name__
        raise OutputError(
            f"{where}: out = {str(out)!r} is not writable ({reason}); give a folder or URL you can write"
        ) from None


def _remove_partial_files(out: Any) -> None:
    """Temporary files of a run that was killed: never finished outputs."""
    if isinstance(out, RemotePath) and out.atomic_put:
        return  # an object store has no temporary files: each object is one PUT
    bop = [f"{BOP_SCENE}/{sub}" for sub in ("rgb", "depth", "mask", "mask_visib", ".")]
    for sub in (*_FOLDERS.values(), "shards", "sparse/0", "models", *bop, "."):
        folder = out / sub
        if folder.is_dir():
            for path in folder.iterdir():
                if TEMPORARY_MARK in path.name:
                    with contextlib.suppress(OSError):
                        path.unlink()


class _LoggedProgress(ViewProgress):
    """The progress bar that also appends each finished view to the run log, flushed at once."""

    def __init__(self, total: int, enabled: bool, log: _RunLog, out: Any) -> None:
        super().__init__(total, enabled=enabled, description="dataset")
        self.log, self.out = log, out

    def advance(self, result: Any) -> None:
        if result.ok:
            files = {kind: _relative(path, self.out) for kind, path in result.files.items()}
            entry = {"view": result.key, "files": files, "render_seconds": round(result.render_seconds, 4),
                     "write_seconds": round(result.write_seconds, 4), "worker": result.worker}  # fmt: skip
            self.log.write(json.dumps(entry))
        super().advance(result)

    def retrying(self, count: int) -> None:
        self.failed -= count
        self._refresh(-count)


def _relative(path: str, out: Any) -> str:
    """A written file's path relative to the dataset (POSIX), for the run log."""
    if isinstance(out, RemotePath):
        return RemotePath(path).relative_to(out)
    return Path(path).relative_to(out).as_posix()


def _paths(out: Any, files: dict[str, str]) -> dict[str, Any]:
    return {kind: out / relative for kind, relative in files.items()}


def _ground_truth_readme(config: dict, extra: dict) -> list[str]:
    """README lines of the COCO and BOP formats."""
    lines = [
        "Labels (class ids 1, 2, ... in this order; 0 = background): " + ", ".join(extra["labels"]),
        "Pixel coordinates (boxes, keypoints, cam_K): u right, v down, the centre of the top-left pixel at (0, 0).",
        "annotations/<key>.json  per view: every scene item's name, label, class_id, bbox_visible and bbox_amodal",
        "                        [x, y, w, h], bbox_3d (8 projected box corners) and bbox_3d_visible, pose (4x4",
        "                        model-to-camera, OpenCV axes, scene units), visibility, pixel counts, keypoints",
        "                        ([u, v, flag]: 0 outside, 1 hidden, 2 visible) and both masks as COCO RLE.",
    ]
    if config["format"] == "coco":
        lines += [
            "images/<key>.png        RGB 8 bits per channel",
            "annotations.json        COCO instances: images, categories, annotations (RLE segmentation of the",
            "                        visible pixels, area, bbox, iscrowd 0, keypoints when given).",
        ]
    else:
        lines += [
            f"BOP scenewise (the BOP toolkit's docs/bop_datasets_format.md): models/, {BOP_SCENE}/rgb, depth",
            f"(uint16; value * depth_scale = mm, depth_scale {extra['bop_depth_scale']!r}), mask (amodal),",
            "mask_visib, scene_camera.json, scene_gt.json, scene_gt_info.json. Scene units are metres (x 1000 = mm);",
            "obj_id is the label's class id.",
        ]
    lines += ["With samples > 1 every id comes from one sample of the pixel (no blending); depth is the nearest.", ""]
    return lines


def _readme(config: dict, camera: Camera, extra: dict) -> str:
    lines = [
        "frustum multi-view dataset",
        "==========================",
        "",
        f"Made by frustum {config['frustum']} from {config['scene']} ({config['views']} views, layout "
        f"{config['layout']}, format {config['format']}, {camera.width}x{camera.height} pixels, "
        f"seed {config['seed']}).",
        "Rerun the same command to resume; manifest.jsonl is the run log (configuration, then finished views).",
        "",
    ]
    if config["format"] in GROUND_TRUTH_FORMATS:
        return "\n".join(lines + _ground_truth_readme(config, extra)) + "\n"
    lines += [
        "Files per view (key = view_NNNNN, no dots):",
        "  images/<key>.png     color, RGBA 8 bits per channel, linear unless the scene asks for sRGB",
    ]
    if config["depth_format"] == "npy":
        lines.append("  depth/<key>.npy      metric z-depth, float32: distance along the camera's viewing axis in")
        lines.append("                       world units (not the distance to the eye); 0 where nothing was drawn")
    else:
        lines.append(f"  depth/<key>.png      metric z-depth as uint16 steps of {extra['depth_unit_scale_factor']!r} "
                     "world units (depth = value * scale); 0 where nothing was drawn")  # fmt: skip
    lines += [
        "  normals/<key>.npy    unit world-space normals, float32 (H, W, 3); 0 where nothing was drawn",
        "  object_id/<key>.png  uint16: index of the scene item seen + 1; 0 = background",
        "  masks/<key>.png      uint8: 255 where a surface was drawn, 0 elsewhere",
        "  position/<key>.npy   (scenes with [render] shadows) world points, float32 (H, W, 3); NaN on background",
        "  shadow/<key>.npy     (scenes with [render] shadows) fraction of each shadow-casting light reaching the",
        "                       pixel, float32 (H, W, L), lights in the scene's order; NaN on background",
        "",
        "Cameras (cameras.json has every view in every convention below):",
        "  camera_to_world_opengl  4x4, OpenGL camera axes: x right, y up, looking down -z",
        "                          (the transform_matrix of transforms.json)",
        "  world_to_camera_opencv  4x4, OpenCV camera axes: x right, y down, looking down +z (COLMAP's)",
        "  fx, fy, cx, cy          pixels; u to the right, v down, the centre of the top-left pixel at (0.5, 0.5)",
        "                          (COLMAP's and nerfstudio's convention): u = fx*X/Z + cx, v = fy*Y/Z + cy in",
        "                          OpenCV camera coordinates",
        "  camera_angle_x          horizontal field of view in radians (Blender NeRF)",
        "  view_from_world, clip_from_view  frustum's own matrices (column vectors, OpenGL clip space)",
        "",
        "Back-projection of pixel (row r, column i) with z-depth d: X = (i + 0.5 - cx)/fx * d,",
        "Y = (r + 0.5 - cy)/fy * d, Z = d in OpenCV camera axes;",
        "world = inverse(world_to_camera_opencv) @ (X, Y, Z, 1).",
    ]
    fmt = config["format"]
    if fmt == "nerf":
        lines += ["", "transforms.json: Blender NeRF; file_path omits .png (as in the NeRF synthetic scenes)."]
    elif fmt == "nerfstudio":
        lines += ["", "transforms.json: nerfstudio (OPENCV model without distortion); depth_file_path and mask_path",
                  "are relative to this folder."]  # fmt: skip
    elif fmt == "colmap":
        lines += ["", "sparse/0/cameras.txt (PINHOLE fx fy cx cy), images.txt (world-to-camera, QW QX QY QZ scalar",
                  "first, TX TY TZ; NAME relative to images/), points3D.txt (empty)."]  # fmt: skip
    elif fmt == "webdataset":
        lines += ["", f"shards/shard-NNNNNN.tar: WebDataset shards of {SHARD_SIZE} samples: <key>.png,",
                  "<key>.depth.npy, <key>.normals.npy, <key>.object_id.png, <key>.mask.png,",
                  "<key>.json (the view's camera record).",
                  "The per-view folders are kept (resuming reads them)."]  # fmt: skip
    lines += ["", "Supersampled scenes (samples > 1): depth is the nearest sample of each pixel's block, normals and",
              "object ids the block's middle sample.", ""]  # fmt: skip
    return "\n".join(lines)


def _keypoint_count(scene: Any, keypoints: Any, where: str) -> int:
    """The number of keypoints per item (COCO's categories list one count); 0 without keypoints."""
    if keypoints is None:
        return 0
    from frustum.output.annotations import _keypoints_per_item

    arrays = _keypoints_per_item(keypoints, scene.item_paths(), scene.item_labels(), where)
    counts = {a.shape[0] for a in arrays if a is not None}
    if len(counts) > 1:
        raise FrustumError(f"{where}: keypoints give {sorted(counts)} points to different items; a COCO dataset "
                           "has one keypoint count: give every item the same number")  # fmt: skip
    return counts.pop() if counts else 0


def render_dataset(
    scene: Any,
    out: str | os.PathLike,
    *,
    views: int | None = 100,
    layout: str = "orbit",
    format: str = "nerf",
    size: tuple[int, int] | None = None,
    seed: int = 0,
    cameras_file: str | os.PathLike | None = None,
    depth_format: str = "npy",
    executor: str = "process",
    workers: int | None = None,
    progress: bool = True,
    overwrite: bool = False,
    retries: int = 1,
    address: str | None = None,
    collect: str | None = None,
    keypoints: Any = None,
    cameras: Sequence[Camera] | None = None,
) -> DatasetResult:
    """Render a multi-view dataset of a scene file into the folder or URL `out` (see the module docstring).

    Parameters
    ----------
    scene : str, Path, SceneFile or Scene
        A TOML scene file (its camera gives projection, size, distance and the target), or a loaded one; or a
        ``Scene`` together with `cameras`.
    views, layout, seed, cameras_file
        ``dataset_cameras``.
    format : {"nerf", "nerfstudio", "colmap", "files", "webdataset", "coco", "bop"}
        ``"coco"``: RGB images and COCO instance annotations (``frustum.batch.coco``); ``"bop"``: a BOP
        scenewise dataset (``frustum.batch.bop``; the scene needs labels). Both write ``annotations/<key>.json``
        per view (``frustum.annotate``'s records), from which the run's end builds the format's files.
    size : (width, height) or None
        Overrides the scene file's image size.
    depth_format : {"npy", "png16"}
        png16 stores ``round(depth / scale)`` with $scale = far / 65535$, written in README.txt (and as
        nerfstudio's ``depth_unit_scale_factor``).
    out : str or Path
        A folder (created), or an fsspec URL (``s3://bucket/prefix``, ``gs://…``, ``file://…``, ``memory://…``).
    executor, workers, progress, address, collect
        ``render_many``. On a Ray cluster of several nodes a folder is written by this process from the
        workers' bytes, a URL by the workers themselves.
    overwrite : bool
        Start again in a folder that holds a dataset made with another configuration.
    retries : int
        How often failed views are tried again before they are listed.
    keypoints : None or as ``frustum.annotate``'s
        Model keypoints per item, written to the annotations (COCO ``keypoints``).
    cameras : sequence of Camera or None
        The views themselves (``frustum.batch.randomize.cameras_on_shell``), in place of `layout` and `views`.

    Returns
    -------
    DatasetResult

    Raises
    ------
    FrustumError
        Bad arguments (unknown names listed), a scene file that does not load (once), an output folder that is
        a file or not writable, a changed configuration without `overwrite`, a projection the format cannot
        describe.
    """
    where = "render_dataset"

    _check_choices(format, layout, depth_format, executor, retries, where)
    scene_file, scene_path = _scene_file(scene, cameras, where)
    if size is not None:
        scene_file = scene_file.resized(tuple(size))
    base = scene_file.cameras[0]
    if cameras is not None:
        cameras = list(cameras)
        if not cameras or not all(isinstance(c, Camera) for c in cameras):
            raise CameraError(f"{where}: cameras = {describe(cameras)} is not a non-empty list of Camera")
        base = cameras[0]
    check_format_camera(format, base, where)
    if format == "bop":
        bop_models(scene_file.scene, where)  # labels, one mesh and scale per label: refused before any view
    target = base.frame.target
    if target is None:  # a camera given by its view-plane normal: aim at the middle of the scene
        items = scene_file.scene.items
        corners = [item.world_from_model[:3, :3] @ item.mesh.bounds.T + item.world_from_model[:3, 3:4]
                   for item in items if item.mesh.vertex_count]  # fmt: skip
        target = np.hstack(corners).mean(axis=1) if corners else np.zeros(3)
    given = cameras is not None
    if given:
        cameras = list(zip(_view_keys(len(cameras)), cameras, strict=True))
    else:
        cameras = dataset_cameras(base, views, layout, seed=seed, target=target, cameras_file=cameras_file)
    _check_budget(scene_file, base, executor, workers, where)
    out = to_location(out)
    remote = isinstance(out, RemotePath)
    _check_folder(out, where)
    extra, depth_scale = _depth_scale(base, format, depth_format)
    if format in GROUND_TRUTH_FORMATS:
        count = _keypoint_count(scene_file.scene, keypoints, where)
        extra.update(scene=scene_file.scene, labels=scene_file.scene.labels, seed=int(seed), keypoint_count=count)
    config = _config(scene_file, scene_path, cameras, base, layout, format, seed, depth_format, cameras_file, given,
                     keypoints)  # fmt: skip
    old_config, finished = _read_manifest(out)
    if old_config is not None and old_config != config and not overwrite:
        raise OutputError(
            f"{where}: out = {str(out)!r} holds a dataset made with another configuration ("
            + "; ".join(_changes(old_config, config))
            + "); rerun with overwrite=True (--overwrite) to start again, or give another folder"
        )
    if overwrite and (old_config is not None or finished):
        _start_over(out, finished, remote)
        old_config, finished = None, {}
    _remove_partial_files(out)
    kinds = dict(_SUFFIXES)
    if depth_format == "png16":
        kinds["depth"] = ".png"
    if format in GROUND_TRUTH_FORMATS:
        kinds = {"rgb": ".png", "annotations": ".json"}
    if scene_file.options.get("shadows") in (True, "ray"):  # a scene with shadows: world points and light fractions
        kinds["position"] = kinds["shadow"] = ".npy"

    def files_of(key: str) -> dict[str, str]:
        if format == "bop":
            return bop_paths(key)
        return {kind: f"{_FOLDERS[kind]}/{key}{suffix}" for kind, suffix in kinds.items()}

    existing = out.files() if remote else None  # one listing of a bucket, not a request per file
    done = {key for key, _ in cameras
            if key in finished and finished[key].get("files") == files_of(key)
            and all(p in existing if remote else (out / p).is_file() for p in files_of(key).values())}  # fmt: skip
    jobs = [
        RenderJob(key, scene_file.scene, camera, _paths(out, files_of(key)), scene_file.options, depth_scale, keypoints)
        for key, camera in cameras
        if key not in done
    ]
    failed: dict[str, str] = {}
    rendered: list[str] = []
    log = _RunLog(out, config if old_config is None else None)
    try:
        bar = _LoggedProgress(len(cameras), bool(progress), log, out)
        with bar:
            bar.skip(len(done))
            remaining = jobs
            for attempt in range(retries + 1):
                if attempt:
                    bar.retrying(len(remaining))
                results = render_many(remaining, executor=executor, workers=workers, progress=bar, address=address,
                                      collect=collect)  # fmt: skip
                rendered += [r.key for r in results if r.ok]
                failed = {r.key: r.error for r in results if not r.ok}
                remaining = [job for job in remaining if job.key in failed]
                if not remaining:
                    break
    finally:
        log.close()
    complete = [(key, camera, files_of(key)) for key, camera in cameras if key not in failed]
    records = {key: camera_record(camera) for key, camera, _ in complete}
    write_atomically(out / "cameras.json", lambda file: file.write((json.dumps(records, indent=2) + "\n").encode()))
    written = [out / "cameras.json", *CAMERA_WRITERS[format](out, complete, extra)]
    write_atomically(out / "README.txt", lambda file: file.write(_readme(config, base, extra).encode("utf-8")))
    written = [str(path) if remote else path for path in (*written, out / "README.txt")]  # URLs as strings
    return DatasetResult(str(out) if remote else out, tuple(sorted(rendered)), tuple(sorted(done)), failed,
                         tuple(written))  # fmt: skip


def _check_choices(format: Any, layout: Any, depth_format: Any, executor: Any, retries: Any, where: str) -> None:
    """``render_dataset``'s named choices and retry count checked (the message lists the valid names)."""
    if format not in CAMERA_WRITERS:
        raise OutputError(f"{where}: format = {format!r} is unknown; expected one of {', '.join(FORMATS)}")
    if layout not in LAYOUTS:
        raise CameraError(f"{where}: layout = {layout!r} is unknown; expected one of {', '.join(LAYOUTS)}")
    if depth_format not in DEPTH_FORMATS:
        raise OutputError(f"{where}: depth_format = {depth_format!r} is unknown; expected one of "
                          f"{', '.join(DEPTH_FORMATS)}")  # fmt: skip
    if executor not in EXECUTORS:
        raise FrustumError(f"{where}: executor = {executor!r} is unknown; expected one of {', '.join(EXECUTORS)}")
    if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
        raise FrustumError(f"{where}: retries = {describe(retries)} must be an integer >= 0")


def _scene_file(scene: Any, cameras: Any, where: str) -> tuple[Any, Path | None]:
    """(the SceneFile, its path or None): `scene` as given, loaded from its path (a scene that does not load fails
    here, once), or a Scene with the first of `cameras`."""
    from frustum.scenefile import SceneFile, load_scene_file

    if isinstance(scene, SceneFile):
        return scene, scene.path
    if isinstance(scene, str | os.PathLike):
        return load_scene_file(Path(scene)), Path(scene)
    if isinstance(scene, Scene) and cameras:
        first = next(iter(cameras))
        return SceneFile(scene, first, {}, (), cameras=(first,)), None
    raise FrustumError(f"{where}: scene = {describe(scene)} is not a scene file path or a SceneFile (or a Scene "
                       "with cameras=[...])")  # fmt: skip


def _start_over(out: Any, finished: dict, remote: bool) -> None:
    """``overwrite=True``: remove the files of the finished views, the shared files, the shards and the manifest."""
    for entry in finished.values():
        for relative in entry.get("files", {}).values():
            with contextlib.suppress(OSError):
                (out / relative).unlink()
    parts = _log_parts(out) if remote else []
    for path in [*(out / name for name in _SHARED_FILES), *out.glob("shards/shard-*.tar"), *parts]:
        with contextlib.suppress(OSError):
            path.unlink()
    (out / _MANIFEST).unlink()


def _config(scene_file: Any, scene_path: Path | None, cameras: list, base: Any, layout: str, format: str, seed: int,
            depth_format: str, cameras_file: Any, given: bool, keypoints: Any) -> dict[str, Any]:  # fmt: skip
    """The dataset's configuration, the first line of its manifest: a resume must match it."""
    from frustum import __version__

    config = {
        "frustum": __version__,
        "scene": "<SceneFile>" if scene_path is None else scene_path.name,
        "scene_sha256": _sha256(scene_path),
        "views": len(cameras),
        "layout": layout,
        "format": format,
        "size": [base.width, base.height],
        "seed": int(seed),
        "depth_format": depth_format,
        "cameras_sha256": _sha256(Path(cameras_file)) if layout == "file" and cameras_file else None,
    }
    if given:  # the views themselves: their records decide whether a resume matches
        records_text = json.dumps([camera_record(c) for _, c in cameras], sort_keys=True)
        config["layout"] = "given"
        config["cameras_sha256"] = hashlib.sha256(records_text.encode("utf-8")).hexdigest()
    if keypoints is not None:
        config["keypoints_sha256"] = hashlib.sha256(repr(keypoints).encode("utf-8")).hexdigest()
    if scene_file.up is not None:  # a mesh file: its up axis turns the model, so a resume must match it
        config["up"] = scene_file.up
    return config


def _depth_scale(base: Any, format: str, depth_format: str) -> tuple[dict[str, Any], float]:
    """(the depth entries of the dataset's shared files, world units per step of a 16-bit depth PNG)."""
    extra: dict[str, Any] = {}
    depth_scale = 1e-3
    if depth_format == "png16":
        far = getattr(base.projection, "far", None)
        depth_scale = float(far) / 65535 if far else 1e-3
        extra["depth_unit_scale_factor"] = depth_scale
    if format == "bop":  # millimetres per step of depth PNGs (BOP's depth_scale): 0.1 mm while the far plane fits
        far = float(getattr(base.projection, "far", 0.0) or 0.0)
        extra["bop_depth_scale"] = max(0.1, far * 1000.0 / 65535.0)
        depth_scale = extra["bop_depth_scale"] / 1000.0  # world units (metres) per step
    return extra, depth_scale
