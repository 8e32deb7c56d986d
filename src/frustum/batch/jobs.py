"""One view as plain data (``RenderJob``), what comes back (``ViewResult``), and the worker side that renders it.

A job names a scene, one camera, ``render`` options and the files to write; a worker renders the view and
encodes each file (``encode_view``), then either writes every file under a temporary name in the target folder
and renames it into place (``os.replace``, atomic on one file system; a URL: ``frustum.batch.storage``) and
returns only metadata (``render_view``), or returns the encoded bytes for the caller to write
(``write_view``: a Ray driver collecting the files of workers whose disks it cannot see). Frames never travel
between processes (a 1024² frame with its buffers is about 25 MB; the encoded files are a sixth of that).

Output kinds (``RenderJob.outputs`` keys):

| kind | file | content |
|---|---|---|
| ``color`` | ``.png`` | RGBA 8-bit, top row first |
| ``depth`` | ``.npy`` | float32 metric z-depth (distance along the viewing axis, world units), 0 on background |
| ``depth`` | ``.png`` | uint16 z-depth / ``depth_scale`` rounded, 0 on background (the caller writes the scale down) |
| ``normals`` | ``.npy`` | float32 (H, W, 3) unit world normals, 0 on background |
| ``object_id`` | ``.png`` | uint16 index of the scene item + 1, 0 on background |
| ``mask`` | ``.png`` | uint8 255 where a surface was drawn, 0 on background |
| ``rgb`` | ``.png`` | RGB 8-bit (the color without alpha: COCO and BOP images) |
| ``annotations`` | ``.json`` | ``frustum.batch.coco.view_annotations``: per-item boxes, pose, masks as RLE |
"""

from __future__ import annotations

import io
import json
import os
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from frustum._arrays import describe
from frustum.batch.storage import TEMPORARY_MARK as TEMPORARY_MARK
from frustum.batch.storage import is_url, write_atomically
from frustum.errors import FrustumError, OutputError

__all__ = ["OUTPUT_KINDS", "RenderJob", "ViewResult", "encode_view", "render_view", "write_atomically", "write_view"]

OUTPUT_KINDS = {
    "color": (".png",),
    "depth": (".npy", ".png"),
    "normals": (".npy",),
    "object_id": (".png",),
    "mask": (".png",),
    "position": (".npy",),
    "shadow": (".npy",),
    "rgb": (".png",),
    "annotations": (".json",),
}
"""Output kinds a job may ask for, with the file suffixes each accepts."""
_MAX_UINT16 = 65535
PNG_COMPRESS_LEVEL = 1
"""zlib level of the PNGs: measured on the bunny at 512², level 1 encodes the color image in 15 ms against 70 ms at
Pillow's default 6, for 13 % more bytes (88 against 77 KB): encoding, not rendering, was the larger half of a view."""


@dataclass(frozen=True)
class RenderJob:
    """One view to render: plain data that pickles cheaply (the scene is sent once per worker, not per job).

    Parameters
    ----------
    key : str
        The view's name, unique among the jobs of one call (used in manifests and error lists).
    scene : Scene or str or Path
        A ``Scene``, or a TOML scene file loaded once in the calling process (its ``[render]`` options are
        the defaults under `options`).
    camera : Camera or None
        The view; None takes the scene file's camera.
    outputs : mapping of str to str or Path
        Output kind (``OUTPUT_KINDS``) to file path; folders are created as needed.
    options : mapping
        Keyword arguments for ``frustum.render`` (shading, background, samples, ...); ``buffers`` is set from
        the outputs.
    depth_scale : float
        World units per step of a 16-bit depth PNG (only for a ``depth`` output ending in ``.png``).
    keypoints : None or as ``frustum.annotate``'s
        Model keypoints for an ``annotations`` output.
    """

    key: str
    scene: Any
    camera: Any = None
    outputs: Mapping[str, Any] = field(default_factory=dict)
    options: Mapping[str, Any] = field(default_factory=dict)
    depth_scale: float = 1e-3
    keypoints: Any = None


@dataclass(frozen=True)
class ViewResult:
    """What a worker returns for one job: metadata only.

    ``files`` maps output kind to the written path (empty when the view failed); ``error`` is None or
    ``"<ErrorType>: <message>"``; ``render_seconds`` and ``write_seconds`` time the two halves; ``worker`` is
    ``host:pid``.
    """

    key: str
    files: dict[str, str]
    error: str | None = None
    render_seconds: float = 0.0
    write_seconds: float = 0.0
    worker: str = ""

    @property
    def ok(self) -> bool:
        return self.error is None


def check_job(job: Any, index: int, where: str) -> None:
    """Raise a FrustumError unless `job` is a RenderJob with known output kinds and suffixes."""
    if not isinstance(job, RenderJob):
        raise FrustumError(f"{where}: jobs[{index}] = {describe(job)} is not a RenderJob; build one per view")
    if not isinstance(job.key, str) or not job.key:
        raise FrustumError(f"{where}: jobs[{index}].key = {describe(job.key)} is not a non-empty string")
    for kind, path in job.outputs.items():
        if kind not in OUTPUT_KINDS:
            raise OutputError(
                f"{where}: jobs[{index}].outputs has kind {kind!r}; expected one of {', '.join(sorted(OUTPUT_KINDS))}"
            )
        suffix = Path(str(path)).suffix.lower()
        if suffix not in OUTPUT_KINDS[kind]:
            raise OutputError(
                f"{where}: jobs[{index}].outputs[{kind!r}] = {str(path)!r} has suffix {suffix!r}; expected "
                f"{' or '.join(OUTPUT_KINDS[kind])}"
            )
    if not (isinstance(job.depth_scale, int | float) and job.depth_scale > 0):
        raise FrustumError(f"{where}: jobs[{index}].depth_scale = {describe(job.depth_scale)} must be a number > 0")


def _png_writer(array: np.ndarray) -> Any:
    from PIL import Image

    image = Image.fromarray(np.ascontiguousarray(array))
    return lambda file: image.save(file, format="PNG", compress_level=PNG_COMPRESS_LEVEL)


def _npy_writer(array: np.ndarray) -> Any:
    return lambda file: np.save(file, np.ascontiguousarray(array), allow_pickle=False)


def _encoded(kind: str, suffix: str, frame: Any, camera: Any, depth_scale: float) -> Any:
    """The writer of one output kind (a function of an open binary file)."""
    from frustum.batch.cameras import metric_depth

    drawn = frame.depth < 1.0
    if kind == "color":
        return _png_writer(frame.color)
    if kind == "rgb":
        return _png_writer(frame.color[..., :3])
    if kind == "depth":
        depth = metric_depth(frame.depth, camera)
        if suffix == ".npy":
            return _npy_writer(depth)
        steps = np.floor(depth.astype(np.float64) / depth_scale + 0.5)
        if steps.max(initial=0.0) > _MAX_UINT16:
            raise OutputError(
                f"render_view: depth up to {float(depth.max()):.6g} at depth_scale = {depth_scale!r} exceeds "
                f"{_MAX_UINT16} steps of a 16-bit PNG; raise depth_scale or write depth as .npy"
            )
        return _png_writer(steps.astype(np.uint16))
    if kind == "normals":
        return _npy_writer(frame.normals)
    if kind in ("position", "shadow"):  # float32 (H, W, 3) world points / (H, W, L) light fractions, NaN background
        return _npy_writer(getattr(frame, kind))
    if kind == "object_id":
        ids = frame.object_id.astype(np.int64) + 1  # background −1 → 0
        if ids.max(initial=0) > _MAX_UINT16:
            raise OutputError(f"render_view: object id {int(ids.max()) - 1} does not fit a 16-bit PNG (≤ 65534)")
        return _png_writer(ids.astype(np.uint16))
    assert kind == "mask"
    return _png_writer(np.where(drawn, 255, 0).astype(np.uint8))


def _path_text(path: Any) -> str:
    return str(path) if is_url(path) else os.fspath(path)


def encode_view(
    scene: Any, job: RenderJob, options: Mapping[str, Any] | None = None
) -> tuple[ViewResult, dict[str, bytes]]:
    """Render one job's view of `scene` and encode its files in memory: the result and ``{kind: bytes}``.

    Nothing is written. ``ViewResult.files`` names the paths the bytes belong to and ``write_seconds`` is the
    encoding time (``write_view`` adds the writing). Errors come back in the result (and no bytes), not raised;
    KeyboardInterrupt and SystemExit pass through.
    """
    import socket

    from frustum.render import render

    worker = f"{socket.gethostname()}:{os.getpid()}"
    start = time.perf_counter()
    render_seconds = 0.0
    try:
        buffers = tuple(b for b in ("normals", "object_id", "position", "shadow") if b in job.outputs)
        if "annotations" in job.outputs:
            buffers += ("instance", "amodal")
        merged = {**(options or {}), **job.options, "buffers": buffers}
        frame = render(scene, job.camera, **merged)
        render_seconds = time.perf_counter() - start
        encoding = time.perf_counter()
        files: dict[str, str] = {}
        encoded: dict[str, bytes] = {}
        for kind, path in job.outputs.items():
            suffix = Path(str(path)).suffix.lower()
            buffer = io.BytesIO()
            if kind == "annotations":
                from frustum.batch.coco import view_annotations

                record = view_annotations(frame, _scene_of(scene), job.camera, job.keypoints)
                buffer.write((json.dumps(record) + "\n").encode("utf-8"))
            else:
                _encoded(kind, suffix, frame, job.camera, job.depth_scale)(buffer)
            encoded[kind] = buffer.getvalue()
            files[kind] = _path_text(path)
        return ViewResult(job.key, files, None, render_seconds, time.perf_counter() - encoding, worker), encoded
    except Exception as error:  # every failure of one view is reported with the view, not raised
        return _failed(job, error, render_seconds, worker), {}


def _scene_of(scene: Any) -> Any:
    """The Scene of a worker's scene (a loaded scene file holds one)."""
    return getattr(scene, "scene", scene)


def _failed(job: RenderJob, error: Exception, render_seconds: float, worker: str) -> ViewResult:
    message = " ".join(str(error).split()) or "no details"
    return ViewResult(job.key, {}, f"{type(error).__name__}: {message}", render_seconds, 0.0, worker)


def write_view(job: RenderJob, result: ViewResult, encoded: Mapping[str, Any]) -> ViewResult:
    """Write the bytes ``encode_view`` returned to the job's outputs, each atomically; the result, timed.

    A file's bytes may also come as a list of pieces, written one after the other (a Ray driver's ``collect``).

    A failed write (a full disk, a refused URL) comes back as the view's error, not raised.
    """
    if not result.ok:
        return result
    from dataclasses import replace

    start = time.perf_counter()
    try:
        for kind, path in job.outputs.items():
            data = encoded[kind]
            pieces = data if isinstance(data, list) else [data]
            write_atomically(path, lambda file, pieces=pieces: [file.write(piece) for piece in pieces])
    except Exception as error:  # reported with the view, as a rendering failure is
        return _failed(job, error, result.render_seconds, result.worker)
    return replace(result, write_seconds=result.write_seconds + time.perf_counter() - start)


def render_view(scene: Any, job: RenderJob, options: Mapping[str, Any] | None = None) -> ViewResult:
    """Render one job's view of `scene` and write its files; errors come back in the result, not raised.

    `options` are defaults (a scene file's ``[render]`` table) under ``job.options``. KeyboardInterrupt and
    SystemExit pass through (a temporary file is removed first). ``write_seconds`` is encoding plus writing.
    """
    result, encoded = encode_view(scene, job, options)
    return write_view(job, result, encoded)
