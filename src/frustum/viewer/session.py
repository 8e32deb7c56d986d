"""One viewer's state and its message protocol, shared by the Jupyter widget and ``frustum serve``.

The page sends small JSON messages (pointer, wheel, key, control, pick); ``ViewerSession.handle`` validates
each one (anything malformed or out of range is ignored and ``handle`` returns None) and says what to send back:

============================================================  ================================================
message                                                       effect
============================================================  ================================================
``{"type": "pointer", "action": "down", "x", "y", "button",   start an orbit drag (button 0) or a pan (button
"shift"}``                                                    1 or 2, or shift held); x, y in image pixels, y down
``{"type": "pointer", "action": "move", "x", "y"}``           drag: a low-resolution frame ("interactive")
``{"type": "pointer", "action": "up"}``                       end the drag: a full frame ("rest")
``{"type": "wheel", "delta"}``                                zoom: "interactive" (the page asks for "rest")
``{"type": "rest"}``                                          the full-resolution, supersampled frame
``{"type": "key", "key"}``                                    a preset or reset (``interaction.KEYS``)
``{"type": "control", "name", "value"}``                      projection, shading, mode, depth_cue, shadows
``{"type": "reset"}``                                         back to the starting camera
``{"type": "pick", "x", "y"}``                                pick the surface point under pixel (x, y)
``{"type": "steps", "algorithm"}``                            record a visible-surface method (``STEPS_METHODS``)
                                                              on the current view, at most ``STEPS_SIZE`` pixels
                                                              across: the steps panel's figures
============================================================  ================================================

Frames go back as a header (``frame_header``, with the ``state()`` of the view it shows under ``"state"``) and
the raw RGBA bytes of ``Frame.color`` (top row first, the layout of the browser's ``ImageData``): while the
pointer drags, at half the width and height with one sample; at rest, at full size with ``rest_samples`` samples
per pixel.

Picking reads the depth buffer of a full-size frame: pixel (column c, row r from the top) is the window point
$(c + 0.5, H − r − 0.5, depth[r, c])$, which ``Camera.unproject`` maps back to the world
($P = (window_from_world)⁻¹·(x, y, depth, 1)$ then divide by w); the frame's ``object_id`` buffer names the
scene item, whose inverse modeling transformation gives the point in modeling coordinates, and
``frustum.trace`` follows it through every stage.

References: [HB 10] "The Three-Dimensional Viewing Pipeline"; [HB 16] "Depth-Buffer Method".
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager, nullcontext
from typing import Any

import numpy as np

from frustum._arrays import describe, escape_control
from frustum.camera import Camera
from frustum.clipping.codes import region_names
from frustum.errors import FrustumError
from frustum.frame import Frame
from frustum.scene import Scene
from frustum.shading import DepthCue
from frustum.transforms import apply
from frustum.viewer.interaction import PROJECTIONS, CameraControl

__all__ = [
    "CONTROLS",
    "MODES",
    "SHADINGS",
    "STEPS_METHODS",
    "STEPS_SIZE",
    "ViewerSession",
    "frame_bytes",
    "scene_bounds",
]

_log = logging.getLogger("frustum.viewer")

SHADINGS = ("phong", "pbr", "gouraud", "flat", "normals", "depth", "none")
"""Shading models the viewer offers (``render``'s ``shading``)."""
MODES = ("surface", "wireframe", "hidden-line", "surface+edges")
"""Render modes the viewer offers (``render``'s ``mode``)."""
CONTROLS: dict[str, tuple[Any, ...]] = {
    "projection": PROJECTIONS,
    "shading": SHADINGS,
    "mode": MODES,
    "depth_cue": (False, True),
    "shadows": (False, True),
}
"""Each control's allowed values."""
_SWITCHES = ("depth_cue", "shadows")
"""Controls that are checkboxes (bool values)."""
STEPS_METHODS = ("depth-buffer", "scan-line", "warnock", "a-buffer", "ray-casting")
"""Visible-surface methods the steps panel records on the current view (``frustum steps`` names)."""
STEPS_SIZE = 64
"""Longest side (pixels) of the steps panel's recording: the current camera, same view, this small; every pixel
of the record is drawn in the figures (the notes' examples are this size)."""
_STEPS_OPTIONS = ("specular", "background", "cull_back_faces", "color_space")
"""The scene file's ``render`` keywords a recording keeps (beside the shading control); others (samples, mode,
shadows, depth cue) do not apply to one method's record."""


def scene_bounds(scene: Scene) -> tuple[np.ndarray, float]:
    """(center, radius) of a sphere holding every placed mesh and polyline (world coordinates); unit at 0 if empty."""
    lows, highs = [], []
    for item in (*scene.items, *scene.polylines):
        points = getattr(item.mesh, "vertices", None)
        if points is None:
            points = item.mesh.points
        if len(points):
            world = apply(item.world_from_model, points)
            lows.append(world.min(axis=0))
            highs.append(world.max(axis=0))
    if not lows:
        return np.zeros(3), 1.0
    low, high = np.min(lows, axis=0), np.max(highs, axis=0)
    radius = float(np.linalg.norm(high - low)) / 2.0
    return (low + high) / 2.0, radius if radius > 0.0 else 1.0


def frame_bytes(width: int, height: int, samples: int, object_id: bool = False) -> int:
    """Peak memory of one viewer frame of width × height pixels with `samples` samples each (bytes).

    Per rendered sample (width·height·samples of them) 24 bytes: measured with the peak RSS of the teapot at
    1024×768 and 2048×1536, 4 samples (22–23 bytes: color and depth buffers, the renderer's work arrays), plus
    4 for an ``object_id`` buffer (picks); per output pixel 8 bytes more: the RGBA bytes and their copy in the
    WebSocket message.
    """
    return width * height * (samples * (24 + 4 * object_id) + 8)


def _number(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return float(value) if math.isfinite(value) else None


class ViewerSession:
    """The state behind one view: scene, render options, camera control and controls (see the module docstring).

    Parameters
    ----------
    scene : Scene
    camera : Camera, optional
        The starting camera (its size is the image size); default: a perspective view fitting the scene,
        800×600.
    options : mapping, optional
        ``render`` keywords (a scene file's ``SceneFile.options``); the controls override shading, mode and
        depth_cue.
    rest_samples : int
        Samples per pixel of the frame drawn when the pointer rests (``render``'s `samples`, a square).

    Raises
    ------
    FrustumError
        If `scene` is not a Scene, `camera` not a Camera, or `rest_samples` not a square (1, 4, 9, ...).
    """

    def __init__(
        self,
        scene: Scene,
        camera: Camera | None = None,
        options: Mapping[str, Any] | None = None,
        *,
        rest_samples: int = 4,
    ) -> None:
        if (
            isinstance(rest_samples, bool)
            or not isinstance(rest_samples, int)
            or rest_samples < 1
            or math.isqrt(rest_samples) ** 2 != rest_samples
        ):
            raise FrustumError(
                f"Viewer: rest_samples = {describe(rest_samples)} is not a square number of samples; "
                "expected 1, 4, 9, 16, ..."
            )
        self.error: str | None = None
        self.work: Callable[[int, str], AbstractContextManager[Any]] | None = None
        """Called as ``with work(nbytes, cause):`` around every render (``frustum serve``'s ``WorkLedger``)."""
        self.control: CameraControl
        self.set_scene(scene, camera, options)
        self.rest_samples = rest_samples
        self.frames = 0

    def set_scene(self, scene: Scene, camera: Camera | None = None, options: Mapping[str, Any] | None = None) -> None:
        """Show `scene` (a reloaded file): keep the current view if there is one, and the new home camera."""
        where = "Viewer"
        if not isinstance(scene, Scene):
            raise FrustumError(
                f"{where}: scene = {describe(scene)} is not a Scene; build one with Scene() or load_scene_file"
            )
        if camera is not None and not isinstance(camera, Camera):
            raise FrustumError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at")
        center, radius = scene_bounds(scene)
        if camera is not None:
            eye_distance = float(np.linalg.norm(np.asarray(camera.frame.eye) - center))
            home = CameraControl.from_camera(camera, radius=max(radius, 1e-6 * eye_distance))
        else:
            home = CameraControl.fitting(center, radius)
        previous = getattr(self, "control", None)
        if previous is not None:
            state = previous.state()  # keep the user's view; take the file's image size and scene radius
            state.update(radius=home.radius, width=home.width, height=home.height)
            home_state = home.state()
            self.control = CameraControl.from_state(state)
            self.control.home = home_state
        else:
            self.control = home
        base = dict(options or {})
        self.options = {
            key: value
            for key, value in base.items()
            if key not in ("shading", "mode", "depth_cue", "samples", "shadows")
        }
        shading = base.get("shading", "phong")
        self.controls = {
            "projection": self.control.projection,
            "shading": "none" if shading is None else shading,
            "mode": base.get("mode", "surface") if base.get("mode", "surface") in MODES else "surface",
            "depth_cue": base.get("depth_cue") is not None,
            "shadows": base.get("shadows") in (True, "ray"),
        }
        self._file_depth_cue = base.get("depth_cue")
        self._file_shadows = base.get("shadows") if base.get("shadows") in (True, "ray") else True
        self.scene = scene

    # --- messages -----------------------------------------------------------------------------------------

    def handle(self, message: Any) -> str | None:
        """Apply one page message; returns "interactive", "rest", "pick" or "" (nothing to draw), None if ignored."""
        if not isinstance(message, Mapping):
            return None
        kind = message.get("type")
        control = self.control
        if kind == "pointer":
            action = message.get("action")
            if action == "down":
                button = message.get("button", 0)
                if isinstance(button, bool) or button not in (0, 1, 2):
                    return None
                drag = "pan" if button != 0 or message.get("shift") is True else "orbit"
                return "" if control.begin_drag(message.get("x"), message.get("y"), drag) else None
            if action == "move":
                return "interactive" if control.drag_to(message.get("x"), message.get("y")) else None
            if action == "up":
                return "rest" if control.end_drag() else None
            return None
        if kind == "wheel":
            return "interactive" if control.wheel(message.get("delta")) else None
        if kind == "rest":
            return "rest"
        if kind == "key":
            if not control.key(message.get("key")):
                return None
            self.controls["projection"] = control.projection
            return "rest"
        if kind == "reset":
            control.reset()
            self.controls["projection"] = control.projection
            return "rest"
        if kind == "control":
            name, value = message.get("name"), message.get("value")
            if not isinstance(name, str) or name not in CONTROLS or isinstance(value, bool) != (name in _SWITCHES):
                return None
            if value not in CONTROLS[name]:
                return None
            self.controls[name] = value
            if name == "projection":
                control.set_projection(value)
            return "rest"
        if kind == "pick":
            x, y = _number(message.get("x")), _number(message.get("y"))
            if x is None or y is None or not (0.0 <= x < control.width and 0.0 <= y < control.height):
                return None
            return "pick"
        if kind == "steps":
            algorithm = message.get("algorithm")
            return "steps" if isinstance(algorithm, str) and algorithm in STEPS_METHODS else None
        return None

    # --- frames -------------------------------------------------------------------------------------------

    def render_options(self, quality: str = "rest") -> dict[str, Any]:
        """The ``render`` keywords of a frame of `quality` ("interactive" or "rest")."""
        options = dict(self.options)
        options["shading"] = self.controls["shading"]
        options["mode"] = self.controls["mode"]
        options["samples"] = 1 if quality == "interactive" else self.rest_samples
        if self.controls["depth_cue"]:
            cue = self._file_depth_cue
            if cue is None:
                d, r = self.control.distance, self.control.radius
                cue = DepthCue(max(0.0, d - r), d + r, min_intensity=0.15)
            options["depth_cue"] = cue
        # shadows fall on shaded surfaces: the file's method (maps or rays) in the surface modes, none in the others
        surfaces = options["mode"] in ("surface", "surface+edges")
        options["shadows"] = self._file_shadows if self.controls["shadows"] and surfaces else False
        return options

    def camera(self, quality: str = "rest") -> Camera:
        """The camera of the current state: full size at rest, half width and height while interacting."""
        control = self.control
        if quality == "interactive":
            return control.camera(max(1, control.width // 2), max(1, control.height // 2))
        return control.camera()

    def render(self, quality: str = "rest") -> Frame:
        """Render the current view at `quality`."""
        from frustum.render import render

        self.frames += 1
        camera, options = self.camera(quality), self.render_options(quality)
        with self._work(camera, options["samples"], quality):
            return render(self.scene, camera, **options)

    def _work(self, camera: Camera, samples: int, what: str, object_id: bool = False) -> AbstractContextManager[Any]:
        if self.work is None:
            return nullcontext()
        cause = f"a {what} frame of {camera.width} x {camera.height} pixels x samples = {samples}"
        return self.work(frame_bytes(camera.width, camera.height, samples, object_id), cause)

    def frame_header(self, frame: Frame, quality: str, seq: Any = None) -> dict[str, Any]:
        """The JSON header sent before a frame's RGBA bytes."""
        height, width = frame.depth.shape
        return {"type": "frame", "width": width, "height": height, "quality": quality,
                "seq": seq if isinstance(seq, int) and not isinstance(seq, bool) else None}  # fmt: skip

    def state(self) -> dict[str, Any]:
        """Camera state, the three matrices of the full-size camera (column-vector form), controls and error."""
        camera = self.control.camera()
        return {
            "type": "state",
            "camera": self.control.state(),
            "zoom": self.control.zoom,
            "matrices": {
                "view": camera.view_matrix.tolist(),
                "projection": camera.projection_matrix.tolist(),
                "viewport": camera.viewport_matrix.tolist(),
            },
            "controls": dict(self.controls),
            "choices": {name: list(values) for name, values in CONTROLS.items()},
            "steps": {"methods": list(STEPS_METHODS), "size": STEPS_SIZE},
            "error": self.error,
        }

    def replies(self, messages: Any) -> list[tuple[dict[str, Any], bytes | None]]:
        """What to send back for page messages (one, or a list that arrived together): (JSON header, RGBA bytes
        or None) pairs, in order: the answer to a pick, then at most one frame (its header holding the state).

        The messages are applied in order and the view is rendered once, at rest quality if any of them asks
        for it; the frame header carries the last ``seq`` seen (the page measures latency with it). Picks merge
        like pointer moves: only the latest of a list is answered (each costs a full-size render); so do steps requests
        (answered with ``steps``'s record, before the pick and the frame). A message
        whose handling raises is ignored (logged on the ``frustum.viewer`` logger), never raised.
        ``{"type": "hello"}`` (a page that has just opened) gets the state and a rest
        frame; if every message was ignored the answer is ``{"type": "ignored"}`` (the page then sends its next
        pointer move). A render that fails (a ``FrustumError``, e.g. over the work budget) is answered with
        ``{"type": "error", "message": ...}``, shown above the picture.
        """
        batch = [messages] if isinstance(messages, Mapping) or not isinstance(messages, list | tuple) else messages
        out: list[tuple[dict[str, Any], bytes | None]] = []
        quality: str | None = None
        seq = None
        ignored = False
        pick = None
        record = None
        for message in batch:
            try:
                hello = isinstance(message, Mapping) and message.get("type") == "hello"
                action = "rest" if hello else self.handle(message)
            except Exception as error:  # the guard: a message that breaks a handler is ignored, not fatal
                reason = escape_control(str(error)[:120])
                _log.warning("ignored a viewer message (%s: %s)", type(error).__name__, reason)
                action = None
            if action is None:
                ignored = True
            elif action == "pick":
                pick = message  # picks merge like pointer moves: the latest wins
            elif action == "steps":
                record = message["algorithm"]  # so do steps requests
            elif action:
                quality = "rest" if "rest" in (quality, action) else action
                if isinstance(message.get("seq"), int) and not isinstance(message.get("seq"), bool):
                    seq = message["seq"]
        if record is not None:
            out.append((self.steps(record), None))
        if pick is not None:
            try:
                out.append((self.pick(pick["x"], pick["y"]), None))
            except FrustumError as error:
                out.append(({"type": "error", "message": str(error)}, None))
        if quality is not None:
            try:
                frame = self.render(quality)
            except FrustumError as error:  # e.g. over the work budget: say so on the page, keep serving
                return [*out, ({"type": "error", "message": str(error)}, None)]
            header = self.frame_header(frame, quality, seq)
            header["state"] = self.state()  # the panel's numbers travel with the picture they belong to
            out.append((header, frame.color.tobytes()))
        elif ignored and not out:
            out.append(({"type": "ignored"}, None))
        return out

    # --- the steps panel ----------------------------------------------------------------------------------

    def steps_camera(self) -> Camera:
        """The current view at most ``STEPS_SIZE`` pixels across (the image's aspect kept, each side ≥ 1)."""
        control = self.control
        scale = min(1.0, STEPS_SIZE / max(control.width, control.height))
        return control.camera(max(1, round(control.width * scale)), max(1, round(control.height * scale)))

    def steps(self, algorithm: str) -> dict[str, Any]:
        """The steps panel's record: `algorithm` (one of ``STEPS_METHODS``) run by ``frustum.steps`` on the
        scene and the current view (``steps_camera``), as JSON values.

        Returns ``{"type": "steps", "algorithm", "size": [w, h], "camera"`` (the view's state),
        ``"titles", "figures"`` (each step's SVG, ``Steps.figure``) ``}``; a record that cannot be made (over
        the budget, nothing to show) gives ``"error"`` with the message instead of titles and figures.
        """
        from frustum.steps import visible_surfaces

        record = {
            "depth-buffer": visible_surfaces.depth_buffer,
            "scan-line": visible_surfaces.scan_line,
            "warnock": visible_surfaces.area_subdivision,
            "a-buffer": visible_surfaces.a_buffer,
            "ray-casting": visible_surfaces.ray_casting,
        }.get(algorithm)
        camera = self.steps_camera()
        answer: dict[str, Any] = {"type": "steps", "algorithm": algorithm, "size": [camera.width, camera.height],
                                  "camera": self.control.state()}  # fmt: skip
        if record is None:
            answer["error"] = f"steps: algorithm = {algorithm!r} is not one of {', '.join(STEPS_METHODS)}"
            return answer
        options = {key: value for key, value in self.options.items() if key in _STEPS_OPTIONS}
        options["shading"] = self.controls["shading"]
        try:
            with self._work(camera, 1, f"{algorithm} steps"):
                recorded = record(self.scene, camera, **options)
                figures = [recorded.figure(i) for i in range(len(recorded))]
        except FrustumError as error:
            answer["error"] = str(error)
            return answer
        answer.update(titles=[step.title for step in recorded], figures=figures)
        return answer

    # --- picking ------------------------------------------------------------------------------------------

    def pick(self, x: float, y: float) -> dict[str, Any]:
        """The surface point under image position (x, y) (pixels, y down) and its trace, as JSON values.

        Returns ``{"type": "pick", "hit": False, ...}`` on background, else ``hit``, ``pixel`` (column, row),
        ``window`` (x, y up, depth), ``world``, ``item`` (index in ``scene.items`` or None for a line),
        ``label`` and ``stages``: for each stage of ``frustum.trace`` its name, title, description, matrix
        (column form, or None) and the point's coordinates; the clipping stage adds the region code and the
        names of its set bits.
        """
        from frustum.render import render
        from frustum.trace import trace

        camera = self.control.camera()
        column, row = int(x), int(y)
        options = self.render_options("rest")
        options["samples"] = 1
        options["buffers"] = ("object_id",)
        with self._work(camera, 1, "pick", object_id=True):
            frame = render(self.scene, camera, **options)
        depth = float(frame.depth[row, column])
        result: dict[str, Any] = {"type": "pick", "pixel": [column, row], "hit": False}
        if not depth < 1.0:
            result["label"] = "background: nothing drawn at this pixel"
            return result
        window = np.array([column + 0.5, camera.height - row - 0.5, depth])
        world = camera.unproject(window)
        assert frame.object_id is not None
        index = int(frame.object_id[row, column])
        if index >= 0:
            item = self.scene.items[index]
            world_from_model = np.asarray(item.world_from_model, dtype=np.float64)
            point_model = apply(np.linalg.inv(world_from_model), world[None, :])
            label = f"scene item {index}: {item.mesh.vertex_count}-vertex mesh"
        else:  # a line or point pixel: no item index, so modeling coordinates = world coordinates
            world_from_model = np.eye(4)
            point_model = world[None, :]
            label = "a line (no mesh item): modeling coordinates shown as world coordinates"
        traced = trace(point_model, camera, model=world_from_model)
        stages = []
        for stage in traced.stages:
            entry: dict[str, Any] = {
                "name": stage.name,
                "title": stage.title,
                "description": stage.description,
                "matrix": None if stage.matrix is None else stage.matrix.tolist(),
                "point": stage.points[0].tolist(),
            }
            if stage.codes is not None:
                code = int(stage.codes[0])
                entry["code"] = code
                entry["regions"] = region_names(code)
            stages.append(entry)
        result.update(
            hit=True,
            window=window.tolist(),
            world=world.tolist(),
            item=index if index >= 0 else None,
            label=label,
            stages=stages,
        )
        return result
