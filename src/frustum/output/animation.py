"""Animations: a turntable around a scene, and any sequence of frames written as an animated GIF or an MP4.

GIF frames go through Pillow with one adaptive palette per frame (median cut, at most 255 colors, no
dithering), so the same frames give the same bytes; MP4 goes through imageio's ffmpeg plugin (install
``imageio-ffmpeg``), H.264, yuv420p, an odd width or height padded by one repeated column or row.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import struct
import tempfile
from collections.abc import Iterable, Iterator
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import as_direction, as_scalar, describe
from frustum._files import atomic_path, os_reason, track_process
from frustum.budgets import check_operations
from frustum.camera import Camera, ViewFrame, _fit_points
from frustum.errors import CameraError, OutputError
from frustum.frame import Frame
from frustum.projection import Perspective
from frustum.render import render
from frustum.scene import Node, Scene
from frustum.transforms import apply, rotate

__all__ = ["ANIMATION_FORMATS", "framing_camera", "orbit_cameras", "turntable", "write_animation"]

ANIMATION_FORMATS = (".gif", ".mp4")
"""File suffixes ``write_animation`` and ``turntable`` accept."""

_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


def _suffix(path: str | os.PathLike, where: str) -> str:
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    if suffix not in ANIMATION_FORMATS:
        raise OutputError(
            f"{where}: path = {os.fspath(path)!r} has suffix {suffix!r}; expected one of "
            + ", ".join(repr(s) for s in ANIMATION_FORMATS)
        )
    return suffix


def _rgb(frame: Frame | ArrayLike, index: int, where: str) -> NDArray[np.uint8]:
    """(H, W, 3) uint8 of a Frame or an (H, W, 3|4) uint8 array (alpha dropped: animations are opaque)."""
    array = frame.color if isinstance(frame, Frame) else np.asarray(frame)
    if array.dtype != np.uint8 or array.ndim != 3 or array.shape[2] not in (3, 4) or 0 in array.shape:
        raise OutputError(
            f"{where}: frames[{index}] has dtype {array.dtype} and shape {array.shape}; expected a Frame or an "
            "(H, W, 3) or (H, W, 4) uint8 image"
        )
    return np.ascontiguousarray(array[:, :, :3])


def _fps(fps: Any, where: str) -> float:
    value = as_scalar(fps, "fps", where=where, error=OutputError)
    if not 0.0 < value <= 100.0:
        raise OutputError(f"{where}: fps = {value!r} is out of range; give frames per second in (0, 100]")
    return value


def _gif_image(rgb: NDArray[np.uint8], marked: bool) -> Any:
    """Palette image of `rgb`; palette entry k (one past the used ones) repeats pixel (0, 0)'s color.

    A `marked` frame shows pixel (0, 0) through that duplicate entry: the same picture with different indices,
    so Pillow does not merge it with an identical previous frame (it drops exact repeats, which would lose
    frames of a symmetric turntable).
    """
    from PIL import Image

    image = Image.fromarray(rgb, mode="RGB").quantize(colors=255, method=Image.Quantize.MEDIANCUT, dither=0)
    palette = image.getpalette() or []
    used = max(int(np.asarray(image).max()) + 1, 1)
    corner = int(np.asarray(image)[0, 0])
    palette = palette[: 3 * used] + palette[3 * corner : 3 * corner + 3]
    image.putpalette(palette)
    if marked:
        image.putpixel((0, 0), used)
    return image


def _gif_frame_block(rgb: NDArray[np.uint8], marked: bool, duration_cs: int) -> bytes:
    """One GIF frame (graphic control extension, image descriptor, local color table, LZW data) for streaming.

    Pillow encodes the frame as a one-image GIF; its global color table becomes the frame's local table, so
    every frame is written the moment it is rendered and none is kept ([GIF89a] sections 20, 21, 23).
    """
    buffer = io.BytesIO()
    _gif_image(rgb, marked).save(buffer, format="GIF", optimize=False)
    data = buffer.getvalue()
    packed = data[10]
    position, table, size_bits = 13, b"", 0
    if packed & 0x80:
        size_bits = packed & 0x07
        length = 3 * (2 << size_bits)
        table, position = data[13 : 13 + length], 13 + length
    while data[position] == 0x21:  # extensions Pillow may add before the image: skip their sub-blocks
        position += 2
        while data[position]:
            position += data[position] + 1
        position += 1
    if data[position] != 0x2C or data[-1] != 0x3B:  # pragma: no cover - Pillow always writes one image
        raise OutputError("write_animation: Pillow wrote an unexpected GIF layout; cannot stream the frame")
    descriptor = bytearray(data[position : position + 10])
    body = data[position + 10 : -1]
    if not descriptor[9] & 0x80:
        descriptor[9] = (descriptor[9] & 0x40) | 0x80 | size_bits  # the global table becomes the local one
        body = table + body
    control = b"\x21\xf9\x04\x04" + struct.pack("<H", duration_cs) + b"\x00\x00"  # disposal: keep; no transparency
    return control + bytes(descriptor) + body


def _write_gif(frames: Iterator[NDArray[np.uint8]], path: str, fps: float, where: str) -> int:
    duration = max(20, round(1000.0 / fps / 10) * 10)  # GIF stores centiseconds; browsers treat < 20 ms as slow
    count = 0
    with atomic_path(path, where=where) as temporary:
        try:
            with open(temporary, "wb") as file:
                previous: NDArray[np.uint8] | None = None
                previous_marked = False
                for index, rgb in enumerate(frames):
                    if previous is None:
                        height, width = rgb.shape[:2]
                        if max(width, height) > 65535:
                            raise OutputError(f"{where}: frames[0] is {width}x{height}; GIF allows at most 65535 "
                                              "pixels a side")  # fmt: skip
                        file.write(b"GIF89a" + struct.pack("<HHBBB", width, height, 0x70, 0, 0))
                        file.write(b"\x21\xff\x0bNETSCAPE2.0\x03\x01\x00\x00\x00")  # loop forever
                    elif rgb.shape != previous.shape:
                        raise OutputError(f"{where}: frames[{index}] has shape {rgb.shape}; expected "
                                          f"{previous.shape} like the first frame")  # fmt: skip
                    # a frame equal to the one before is marked (same picture, other indices) so players and
                    # Pillow keep it as its own frame
                    marked = previous is not None and not previous_marked and np.array_equal(rgb, previous)
                    file.write(_gif_frame_block(rgb, marked, duration // 10))
                    previous, previous_marked = rgb, marked
                    count += 1
                if count == 0:
                    raise OutputError(f"{where}: frames is empty; an animation needs at least one frame")
                file.write(b"\x3b")
        except OSError as error:
            raise OutputError(
                f"{where}: path = {str(path)!r} cannot be written ({os_reason(error)}); give a path in an "
                "existing, writable folder with free space"
            ) from None
    return count


def _write_mp4(frames: Iterator[NDArray[np.uint8]], path: str, fps: float, where: str) -> int:
    """Pipe raw RGB frames to ffmpeg (from imageio-ffmpeg) as they come: H.264, yuv420p, crf 25 (imageio's
    quality 5). frustum owns the process: its exit status reports a failed write, and a failure or Ctrl-C
    kills it before the temporary file is removed."""
    try:
        import imageio_ffmpeg
    except ImportError:
        raise OutputError(
            f"{where}: path = {str(path)!r} asks for MP4, which needs the imageio-ffmpeg package; install it "
            "(pip install imageio-ffmpeg) or write a '.gif'"
        ) from None
    import subprocess
    from fractions import Fraction

    ffmpeg = _ffmpeg_program(imageio_ffmpeg, path, where)
    count = 0
    with atomic_path(path, where=where) as temporary:
        process: subprocess.Popen | None = None
        try:
            with contextlib.ExitStack() as stack:
                for rgb in frames:
                    # yuv420p needs even sizes: repeat the last row / column rather than let ffmpeg rescale
                    even = np.pad(rgb, ((0, rgb.shape[0] % 2), (0, rgb.shape[1] % 2), (0, 0)), mode="edge")
                    if process is None:
                        height, width = even.shape[:2]
                        command = [ffmpeg, "-y", "-v", "error", "-f", "rawvideo",
                                   "-vcodec", "rawvideo", "-s", f"{width}x{height}", "-pix_fmt", "rgb24", "-r",
                                   str(Fraction(fps).limit_denominator()), "-i", "-", "-an", "-vcodec", "libx264",
                                   "-pix_fmt", "yuv420p", "-crf", "25", "-f", "mp4", str(temporary)]  # fmt: skip
                        log = stack.enter_context(tempfile.TemporaryFile())
                        # its own session: a terminal's Ctrl-C reaches frustum, which stops it
                        process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                                   stderr=log, start_new_session=True)  # fmt: skip
                        stack.enter_context(track_process(process))
                    elif even.shape[:2] != (height, width):
                        raise OutputError(f"{where}: frames[{count}] has shape {rgb.shape}; expected the first "
                                          "frame's size")  # fmt: skip
                    try:
                        process.stdin.write(np.ascontiguousarray(even).tobytes())  # type: ignore[union-attr]
                    except BrokenPipeError:  # ffmpeg stopped: say why (a full disk), not "broken pipe"
                        process.wait()
                        log.seek(0)
                        reason = " ".join(log.read().decode("utf-8", "replace").split())
                        raise OutputError(
                            f"{where}: path = {str(path)!r} cannot be written (the encoder stopped: "
                            f"{_ffmpeg_reason(reason)}); free space or choose another folder"
                        ) from None
                    count += 1
                if process is None:
                    raise OutputError(f"{where}: frames is empty; an animation needs at least one frame")
                process.stdin.close()  # type: ignore[union-attr]
                status = process.wait()
                log.seek(0)
                reason = " ".join(log.read().decode("utf-8", "replace").split())
            if status != 0 or not _complete_mp4(temporary):
                raise OutputError(
                    f"{where}: path = {str(path)!r} cannot be written (the encoder could not finish the file: "
                    f"{_ffmpeg_reason(reason)}); free space or choose another folder"
                )
        except (OSError, ValueError) as error:  # a broken pipe: ffmpeg stopped (a full disk, a bad folder)
            if isinstance(error, OutputError):
                raise
            raise OutputError(
                f"{where}: path = {str(path)!r} cannot be written ({os_reason(error)}); give a path in an "
                "existing, writable folder with free space"
            ) from None
    return count


def _ffmpeg_program(imageio_ffmpeg: Any, path: Any, where: str) -> str:
    """The ffmpeg program imageio-ffmpeg names (``IMAGEIO_FFMPEG_EXE``, else its own), checked to be an executable
    file before any frame is made: a missing one is said to be ffmpeg's fault, not the output folder's."""
    try:
        program = imageio_ffmpeg.get_ffmpeg_exe()
    except RuntimeError as error:
        raise OutputError(f"{where}: path = {str(path)!r} asks for MP4, but imageio-ffmpeg finds no ffmpeg program "
                          f"({error}); reinstall imageio-ffmpeg or write a '.gif'") from None  # fmt: skip
    if not (os.path.isfile(program) and os.access(program, os.X_OK)):
        named = " (IMAGEIO_FFMPEG_EXE)" if os.environ.get("IMAGEIO_FFMPEG_EXE") else ""
        raise OutputError(f"{where}: path = {str(path)!r} asks for MP4, but the ffmpeg program {program!r}{named} "
                          "is not an executable file; point IMAGEIO_FFMPEG_EXE at ffmpeg, unset it, or write a "
                          "'.gif'")  # fmt: skip
    return program


def _ffmpeg_reason(log: str) -> str:
    """The cause in ffmpeg's error output (never its command line)."""
    for known in ("No space left on device", "File too large", "Permission denied", "Disk quota exceeded"):
        if known.lower() in log.lower():
            return known
    return "the disk is full or the file too large"


def _complete_mp4(path: Any) -> bool:
    """Whether the file is a whole MP4: top-level boxes (32-bit size, type) tile it exactly and one is ``moov``
    (ffmpeg writes it last, so a truncated file lacks it) [ISO/IEC 14496-12 §4.2]."""
    size = os.path.getsize(path)
    position, found = 0, False
    with open(path, "rb") as file:
        while position < size:
            file.seek(position)
            header = file.read(16)
            if len(header) < 8:
                return False
            length, kind = struct.unpack(">I4s", header[:8])
            if length == 1 and len(header) == 16:  # 64-bit size
                length = struct.unpack(">Q", header[8:16])[0]
            elif length == 0:  # the box runs to the end of the file
                length = size - position
            if length < 8 or position + length > size:
                return False
            found = found or kind == b"moov"
            position += length
    return found


def write_animation(frames: Iterable[Frame | ArrayLike], path: str | os.PathLike, fps: float = 30.0) -> int:
    """Write `frames` (``Frame`` objects or (H, W, 3|4) uint8 images, all one size) as a GIF or MP4.

    Each frame shows for 1/fps seconds (GIF: rounded to 10 ms, at least 20 ms; it loops forever). Alpha is
    dropped. Frames are consumed one at a time and written as they come (neither format holds them all);
    the file appears under `path` only when complete (an existing one survives a failure or Ctrl-C).

    Parameters
    ----------
    frames : iterable of Frame or (H, W, 3|4) uint8 arrays
    path : str or PathLike
        Ends in ``.gif`` or ``.mp4`` (MP4 needs ``imageio-ffmpeg``).
    fps : float
        Frames per second, in (0, 100].

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    OutputError
        Unknown suffix, no frames, a frame of the wrong type or size, fps out of range, an unwritable path, or
        MP4 without imageio-ffmpeg installed.
    """
    where = "write_animation"
    suffix = _suffix(path, where)
    rate = _fps(fps, where)
    rgb_frames = (_rgb(frame, i, where) for i, frame in enumerate(frames))
    writer = _write_gif if suffix == ".gif" else _write_mp4
    return writer(rgb_frames, os.fspath(path), rate, where)


def _axis(axis: Any, camera: Camera, where: str) -> NDArray[np.float64]:
    if axis is None:
        return as_direction(camera.frame.up, "up", where=where, error=CameraError)
    if isinstance(axis, str):
        if axis not in _AXES:
            raise CameraError(
                f"{where}: axis = {axis!r} is unknown; expected 'x', 'y', 'z', a direction (dx, dy, dz), or None "
                "for the camera's up vector"
            )
        return np.array(_AXES[axis])
    return as_direction(axis, "axis", where=where, error=CameraError)


def orbit_cameras(camera: Camera, frames: int, axis: str | ArrayLike | None = None) -> list[Camera]:
    """`frames` cameras spaced evenly around one turn of `camera` about the line through its target along `axis`.

    Camera k has $eye_k = target + R(axis, 2πk/frames)·(eye − target)$ and $up_k = R·up$ (the rotation of
    ``transforms.rotate``, counter-clockwise about `axis`), the same projection and image size; camera 0 is
    `camera` itself and the last stops one step short of a full turn, so the animation loops seamlessly.

    Parameters
    ----------
    camera : Camera
        The start; built with a look-at point (``Camera.look_at`` or ``Camera.orbit``).
    frames : int
        Number of cameras, >= 1.
    axis : "x", "y", "z", (3,) array_like or None
        The turntable's axis; None (default) is the camera's view-up vector.

    Raises
    ------
    CameraError
        If `camera` is not a Camera or has no look-at point, frames < 1, or the axis is unknown or zero.
    """
    where = "orbit_cameras"
    if not isinstance(camera, Camera):
        raise CameraError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at(...)")
    if isinstance(frames, bool) or not isinstance(frames, int | np.integer) or frames < 1:
        raise CameraError(f"{where}: frames = {describe(frames)} is not a positive integer; give at least 1 frame")
    frame = camera.frame
    if frame.target is None:
        raise CameraError(
            f"{where}: camera has no look-at point (its frame was built from a normal); build it with "
            "Camera.look_at(eye, target, up) so the orbit has a center"
        )
    direction = _axis(axis, camera, where)
    return [_orbit_camera(camera, turn) for turn in _turns(direction, frame.target, int(frames))]


def _orbit_camera(camera: Camera, turn: NDArray[np.float64]) -> Camera:
    """`camera` with its eye and up turned by `turn` about its target."""
    frame = camera.frame
    eye = apply(turn, frame.eye[None, :])[0]
    up = turn[:3, :3] @ frame.up
    view = ViewFrame(eye, target=frame.target, up=up, handedness=frame.handedness)
    return Camera(view, camera.projection, camera.width, camera.height)


def _turns(direction: NDArray[np.float64], center: NDArray[np.float64], frames: int) -> Iterator[NDArray[np.float64]]:
    """R(axis, 2πk/frames) about the line through `center`, k = 0 … frames − 1, one at a time."""
    return (rotate(direction, 2.0 * math.pi * k / frames, center) for k in range(frames))


def _with_lights_turned(scene: Scene, turn: NDArray[np.float64]) -> Scene:
    """`scene` with the lights attached to its root turned by `turn` (the nodes, meshes and other lights shared)."""
    root = scene.root
    turned_root = Node(
        root.name, root.transform, root.geometry, root.material, root.children,
        [light.transformed(turn) for light in root.lights],
    )  # fmt: skip
    turned = Scene()
    turned.root = turned_root
    turned.particle_layers = list(getattr(scene, "particle_layers", ()))  # particles turn with the camera too
    return turned


def framing_camera(scene: Scene, width: int = 480, height: int = 480, elevation: float = math.radians(20)) -> Camera:
    """A perspective camera (fovy 40°) looking at the center of the scene's bounding box from the +z side, y up,
    raised by `elevation`, far enough that the bounding sphere fits the image."""
    where = "framing_camera"
    points = _fit_points(scene, where)  # the meshes' vertices and the point clouds' boxes
    low, high = points.min(axis=0), points.max(axis=0)
    center = (low + high) / 2
    radius = max(float(np.linalg.norm(high - low)) / 2, 1e-9)
    fovy = math.radians(40)
    half_angle = min(fovy, 2 * math.atan(math.tan(fovy / 2) * width / height)) / 2
    distance = 1.1 * radius / math.sin(half_angle)
    projection = Perspective(fovy, max(distance - 1.5 * radius, distance * 1e-3), distance + 1.5 * radius)
    return Camera.orbit(center, distance, 0.0, elevation, projection, width, height)


def turntable(
    scene: Scene,
    camera: Camera | None = None,
    frames: int = 120,
    axis: str | ArrayLike | None = None,
    path: str | os.PathLike | None = None,
    fps: float = 30.0,
    progress: Any = True,
    *,
    size: tuple[int, int] = (480, 480),
    lights_follow: bool = True,
    **render_options: Any,
) -> list[Frame] | int:
    """Render `scene` from `frames` cameras orbiting one full turn around the camera's target, as a loop.

    $eye_k = target + R(axis, 2πk/frames)·(eye − target)$ (``orbit_cameras``). With `path`, the frames are
    written as they are rendered (``write_animation``) and the frame count is returned; without, the list of
    ``Frame`` objects is returned.

    Parameters
    ----------
    scene : Scene
    camera : Camera, optional
        The first camera. None frames the whole scene (``framing_camera``: perspective, 20° above the
        horizon, from +z, y up) at `size`.
    frames : int
        Number of frames in the turn, >= 1.
    axis : "x", "y", "z", (3,) array_like or None
        The turntable's axis through the target; None (default) is the camera's view-up vector.
    path : str or PathLike, optional
        ``.gif`` or ``.mp4`` output file.
    fps : float
        Frames per second of the file.
    progress : bool or rich.console.Console
        True shows a Rich progress bar on standard error when it is a terminal (nothing otherwise, so logs and
        pipes stay clean); a Console draws the bar there; False shows nothing.
    size : (int, int)
        Width and height in pixels when `camera` is None.
    lights_follow : bool
        True (default): the lights attached to the scene's root turn with the camera, so every side is lit the
        same way, as on a real turntable (the object turns under fixed lights and a fixed camera). False: they
        stay put in the world. Lights riding other nodes always stay with their nodes.
    **render_options
        Passed to ``render`` (``shading``, ``background``, ``cull_back_faces``, ``mode``).

    Raises
    ------
    FrustumError
        CameraError for a bad camera, frame count or axis; OutputError for a bad path or fps; whatever
        ``render`` raises for bad options.
    """
    where = "turntable"
    if not isinstance(scene, Scene):
        raise OutputError(f"{where}: scene = {describe(scene)} is not a Scene; build one with Scene()")
    if camera is None:
        width, height = _size(size, where)
        camera = framing_camera(scene, width, height)
    if isinstance(frames, bool) or not isinstance(frames, int | np.integer) or frames < 1:
        orbit_cameras(camera, frames, axis)  # raises orbit_cameras' error for the frame count
    orbit_cameras(camera, 1, axis)  # checks camera and axis (a one-frame orbit is the camera itself)
    if path is not None:
        _suffix(path, where)
        _fps(fps, where)
    count = int(frames)
    # the whole turn's work, estimated before the first frame: each frame touches every pixel and every triangle
    triangles = sum(item.mesh.face_count for item in scene.items)
    cause = f"frames = {count} of {camera.width}x{camera.height} pixels and {triangles} triangles"
    check_operations(count * (camera.width * camera.height + triangles), where=where, cause=cause, error=OutputError)
    turns = _turns(_axis(axis, camera, where), camera.frame.target, count)

    def jobs() -> Iterator[tuple[Scene, Camera]]:  # one frame's scene and camera at a time: none are kept
        for turn in turns:
            yield (_with_lights_turned(scene, turn) if lights_follow else scene), _orbit_camera(camera, turn)

    rendered = _with_progress((render(s, c, **render_options) for s, c in jobs()), count, progress)
    if path is None:
        return list(rendered)
    return write_animation(rendered, path, fps)


def _size(size: Any, where: str) -> tuple[int, int]:
    if (
        not isinstance(size, tuple | list)
        or len(size) != 2
        or not all(isinstance(v, int | np.integer) and not isinstance(v, bool) and v > 0 for v in size)
    ):
        raise OutputError(f"{where}: size = {describe(size)} is not (width, height); give two positive integers")
    return int(size[0]), int(size[1])


def _with_progress(items: Iterator[Frame], total: int, progress: Any, label: str = "turntable") -> Iterator[Frame]:
    """Yield `items`, advancing a Rich progress bar on a terminal (or on the given Console)."""
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    if progress is False or progress is None:
        yield from items
        return
    console = progress if isinstance(progress, Console) else Console(stderr=True)
    if not console.is_terminal:
        yield from items
        return
    columns = (TextColumn(label), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    bar = Progress(*columns, console=console, transient=False)
    with bar:
        task = bar.add_task("render", total=total)
        for item in items:
            yield item
            bar.advance(task)
