"""The viewer's camera-interaction model: orbit angles, pan, zoom and presets, in plain Python.

The Jupyter widget and ``frustum serve`` both move the camera through one ``CameraControl``; the pointer, wheel
and key events arrive in image pixels (x right, y **down**, as the browser gives them) and change the control
exactly as written here:

* **orbit** (left drag): $azimuth −= ORBIT_RADIANS_PER_PIXEL·dx$, $elevation += ORBIT_RADIANS_PER_PIXEL·dy$,
  elevation clamped to [−π/2, π/2] (dragging right swings the eye to the left around the target, so the object
  turns right with the pointer; dragging down raises the eye);
* **pan** (right or shift drag): the target moves in the view plane by what one pixel spans at the target,
  $target −= s·(dx·u − dy·v)$ with $s = 2·distance·tan(fovy/2) / height$ (the point under the pointer
  stays under it);
* **zoom** (wheel): $distance ·= ZOOM_PER_NOTCH^(delta/100)$ (one 100-unit notch toward the user,
  delta < 0, brings the eye 1.1 times closer); the zoom factor is ``home distance / distance``, kept in
  [1e−3, 1e3];
* **presets** (keys): front, top, right and isometric set the orbit angles of the preset (``PRESETS``;
  isometric looks along −(1, 1, 1)) and an orthographic projection;
* **reset**: back to the camera the viewer started with.

The camera is ``Camera.look_at(eye, target, up)`` with $eye = target + distance·(cos e·sin a, sin e,
cos e·cos a)$ (``Camera.orbit``'s formula) and $up = (−sin e·sin a, cos e, −sin e·cos a)$, the direction
of increasing elevation: it equals ``Camera.orbit``'s frame for |e| < π/2 and stays defined at the poles (the
top view has up = −z, as ``MULTIVIEWS["top"]``).

References: [HB 10] "Three-Dimensional Viewing-Coordinate Parameters", "Orthogonal Projections" (multiview
projections); [seed] "Three-Dimensional Viewing".
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from frustum._arrays import as_vector3, describe
from frustum.camera import Camera
from frustum.errors import CameraError
from frustum.projection import Axonometric, Oblique, Orthographic, Perspective

__all__ = [
    "KEYS",
    "ORBIT_RADIANS_PER_PIXEL",
    "PRESETS",
    "PROJECTIONS",
    "ZOOM_PER_NOTCH",
    "CameraControl",
]

ORBIT_RADIANS_PER_PIXEL = 0.01
"""Orbit angle change per pixel of drag (radians)."""
ZOOM_PER_NOTCH = 1.1
"""Distance factor per 100 units of wheel delta (one mouse-wheel notch in the browser's pixel mode)."""
PROJECTIONS = ("perspective", "orthographic", "isometric", "cavalier", "cabinet")
"""Projection names the viewer's control offers."""
PRESETS: dict[str, tuple[float, float]] = {
    "front": (0.0, 0.0),
    "right": (math.pi / 2, 0.0),
    "top": (0.0, math.pi / 2),
    "isometric": (math.pi / 4, math.atan(1.0 / math.sqrt(2.0))),
}
"""Multiview presets as (azimuth, elevation) in radians: eye on +z, +x, +y, and along (1, 1, 1)."""
KEYS: dict[str, str] = {
    "f": "front",
    "1": "front",
    "r": "right",
    "3": "right",
    "t": "top",
    "7": "top",
    "i": "isometric",
    "5": "isometric",
    "0": "reset",
    "Home": "reset",
}
"""Key → action: the presets (letters, or Blender's numpad digits) and reset."""

_MIN_ZOOM, _MAX_ZOOM = 1e-3, 1e3
_DEFAULT_FOVY = math.radians(45.0)


def _finite(value: Any) -> float | None:
    """`value` as a float if it is a finite real number (bools excluded), else None."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        return None
    number = float(value)
    return number if math.isfinite(number) else None


@dataclass
class CameraControl:
    """Orbit camera state driven by pointer, wheel and key events (the module docstring gives the formulas).

    Parameters
    ----------
    target : (3,) array_like
        The point the camera orbits and looks at (world coordinates).
    distance : float
        Eye-to-target distance, > 0.
    azimuth, elevation : float
        Radians: azimuth about +y from +z toward +x, elevation above the xz plane in [−π/2, π/2].
    projection : str
        One of ``PROJECTIONS``.
    width, height : int
        Full image size in pixels.
    fovy : float
        Vertical field of view of the perspective projection (radians); the parallel ones show the window a
        perspective of this angle shows at the target, so switching keeps the framing.
    radius : float
        Radius of a sphere around the target holding the scene; near and far enclose it.

    Raises
    ------
    CameraError
        For a nonpositive distance, size or radius, an elevation outside [−π/2, π/2] or an unknown projection.
    """

    target: np.ndarray
    distance: float
    azimuth: float = 0.0
    elevation: float = 0.0
    projection: str = "perspective"
    width: int = 800
    height: int = 600
    fovy: float = _DEFAULT_FOVY
    radius: float = 1.0
    home: dict = dataclasses.field(default_factory=dict, repr=False)
    _drag: tuple[str, float, float] | None = dataclasses.field(default=None, repr=False)

    def __post_init__(self) -> None:
        where = "CameraControl"
        self.target = as_vector3(self.target, "target", where=where, error=CameraError).copy()
        for name in ("distance", "radius", "fovy"):
            value = _finite(getattr(self, name))
            if value is None or not value > 0.0:
                raise CameraError(f"{where}: {name} = {describe(getattr(self, name))} must be a finite number > 0")
            setattr(self, name, value)
        if not self.fovy < math.pi:
            raise CameraError(f"{where}: fovy = {self.fovy!r} must be < pi (radians)")
        for name in ("azimuth", "elevation"):
            value = _finite(getattr(self, name))
            if value is None:
                raise CameraError(f"{where}: {name} = {describe(getattr(self, name))} is not a finite number")
            setattr(self, name, value)
        if abs(self.elevation) > math.pi / 2:
            raise CameraError(f"{where}: elevation = {self.elevation!r} is outside [-pi/2, pi/2]")
        if self.projection not in PROJECTIONS:
            raise CameraError(
                f"{where}: projection = {describe(self.projection)} is unknown; expected one of "
                + ", ".join(PROJECTIONS)
            )
        for name in ("width", "height"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | np.integer) or value <= 0:
                raise CameraError(f"{where}: {name} = {describe(value)} is not a positive integer")
            setattr(self, name, int(value))
        if not self.home:
            self.home = self.state()

    # --- construction -------------------------------------------------------------------------------------

    @classmethod
    def from_camera(cls, camera: Camera, radius: float | None = None) -> CameraControl:
        """The control whose camera looks from `camera`'s eye at its target, with the closest projection.

        The eye direction becomes the orbit angles; world y stays up (a tilted up vector is not kept).
        Perspective keeps its fovy; an ``Orthographic``/``Oblique``/``Axonometric`` projection maps to
        orthographic, cavalier or cabinet (by its alpha), or isometric; a ``Frustum`` to a perspective of
        the same vertical angle at the axis.
        """
        if not isinstance(camera, Camera):
            raise CameraError(f"CameraControl.from_camera: camera = {describe(camera)} is not a Camera")
        frame = camera.frame
        eye = np.asarray(frame.eye, dtype=np.float64)
        target = np.asarray(frame.target if frame.target is not None else eye - frame.n, dtype=np.float64)
        offset = eye - target
        distance = float(np.linalg.norm(offset))
        azimuth = math.atan2(offset[0], offset[2])
        elevation = math.asin(max(-1.0, min(1.0, offset[1] / distance)))
        projection, fovy = "perspective", _DEFAULT_FOVY
        p = camera.projection
        if isinstance(p, Perspective):
            fovy = float(p.fovy)
        elif isinstance(p, Orthographic | Oblique | Axonometric):
            fovy = 2.0 * math.atan(float(p.height) / (2.0 * distance))
            if isinstance(p, Oblique):
                projection = "cavalier" if abs(p.alpha - math.pi / 4) < 1e-9 else "cabinet"
            else:
                projection = "isometric" if isinstance(p, Axonometric) else "orthographic"
        else:  # Frustum
            fovy = 2.0 * math.atan(max(abs(p.top), abs(p.bottom)) / p.near)
        return cls(
            target,
            distance,
            azimuth,
            elevation,
            projection,
            camera.width,
            camera.height,
            fovy,
            radius if radius is not None else distance / 2.0,
        )

    @classmethod
    def fitting(cls, center: Any, radius: float, width: int = 800, height: int = 600) -> CameraControl:
        """A perspective view of the sphere (center, radius) from azimuth 30°, elevation 20°, filling the image."""
        distance = 1.15 * radius / math.sin(_DEFAULT_FOVY / 2.0 * min(1.0, width / height))
        return cls(center, distance, math.radians(30.0), math.radians(20.0), "perspective", width, height,
                   _DEFAULT_FOVY, radius)  # fmt: skip

    def state(self) -> dict[str, Any]:
        """The state as plain JSON values (``from_state`` rebuilds the same control)."""
        return {
            "target": [float(v) for v in self.target],
            "distance": self.distance,
            "azimuth": self.azimuth,
            "elevation": self.elevation,
            "projection": self.projection,
            "width": self.width,
            "height": self.height,
            "fovy": self.fovy,
            "radius": self.radius,
        }

    @classmethod
    def from_state(cls, state: Mapping[str, Any]) -> CameraControl:
        """The control described by ``state()`` output."""
        return cls(**{key: state[key] for key in cls.__dataclass_fields__ if key in state and key != "home"})

    # --- the camera ---------------------------------------------------------------------------------------

    @property
    def zoom(self) -> float:
        """home distance / distance: 2 means twice as close as at the start."""
        return self.home["distance"] / self.distance

    @property
    def eye(self) -> np.ndarray:
        """(3,) float64: $target + distance·(cos e·sin a, sin e, cos e·cos a)$."""
        a, e = self.azimuth, self.elevation
        return self.target + self.distance * np.array(
            [math.cos(e) * math.sin(a), math.sin(e), math.cos(e) * math.cos(a)]
        )

    @property
    def up(self) -> np.ndarray:
        """(3,) float64 unit view-up $(−sin e·sin a, cos e, −sin e·cos a)$."""
        a, e = self.azimuth, self.elevation
        return np.array([-math.sin(e) * math.sin(a), math.cos(e), -math.sin(e) * math.cos(a)])

    def camera(self, width: int | None = None, height: int | None = None) -> Camera:
        """The Camera of the current state, at the full image size or at (`width`, `height`)."""
        d, r = self.distance, self.radius
        near = max(d - 2.0 * r, 1e-3 * d)
        far = d + 2.0 * r
        window_height = 2.0 * d * math.tan(self.fovy / 2.0)
        name = self.projection
        if name == "perspective":
            projection: Any = Perspective(self.fovy, near, far)
        elif name == "orthographic":
            projection = Orthographic(window_height, near, far)
        elif name == "isometric":
            projection = dataclasses.replace(Axonometric.isometric(window_height, near, far), pivot=d)
        elif name == "cavalier":
            projection = Oblique.cavalier(window_height, near, far)
        else:
            projection = Oblique.cabinet(window_height, near, far)
        if name in ("cavalier", "cabinet"):
            projection = dataclasses.replace(projection, z_vp=-d)  # shear about the target's plane
        return Camera.look_at(self.eye, self.target, self.up, projection, width or self.width, height or self.height)

    # --- events -------------------------------------------------------------------------------------------

    def begin_drag(self, x: float, y: float, kind: str = "orbit") -> bool:
        """Start an orbit or pan drag at image position (x, y), y down; False (ignored) if out of range."""
        fx, fy = _finite(x), _finite(y)
        if kind not in ("orbit", "pan") or fx is None or fy is None:
            return False
        if not (0.0 <= fx <= self.width and 0.0 <= fy <= self.height):
            return False
        self._drag = (kind, fx, fy)
        return True

    def drag_to(self, x: float, y: float) -> bool:
        """Continue the drag to (x, y); positions may leave the image by up to its size (pointer capture)."""
        fx, fy = _finite(x), _finite(y)
        if self._drag is None or fx is None or fy is None:
            return False
        if not (-self.width <= fx <= 2 * self.width and -self.height <= fy <= 2 * self.height):
            return False
        kind, x0, y0 = self._drag
        self._drag = (kind, fx, fy)
        if kind == "orbit":
            self.orbit(fx - x0, fy - y0)
        else:
            self.pan(fx - x0, fy - y0)
        return True

    def end_drag(self) -> bool:
        """End the drag; False if none was in progress."""
        dragging, self._drag = self._drag is not None, None
        return dragging

    @property
    def dragging(self) -> bool:
        return self._drag is not None

    def orbit(self, dx: float, dy: float) -> None:
        """Turn the eye about the target by a drag of (dx, dy) pixels (y down)."""
        self.azimuth -= ORBIT_RADIANS_PER_PIXEL * dx
        self.azimuth = math.remainder(self.azimuth, 2.0 * math.pi)
        self.elevation = min(math.pi / 2, max(-math.pi / 2, self.elevation + ORBIT_RADIANS_PER_PIXEL * dy))

    def pan(self, dx: float, dy: float) -> None:
        """Move the target in the view plane so that the scene follows a drag of (dx, dy) pixels (y down)."""
        camera = self.camera()
        per_pixel = 2.0 * self.distance * math.tan(self.fovy / 2.0) / self.height
        self.target = self.target - per_pixel * (dx * camera.frame.u - dy * camera.frame.v)

    def wheel(self, delta: float) -> bool:
        """Zoom by a wheel `delta` (browser ``deltaY``, pixels; > 0 away from the user zooms out)."""
        value = _finite(delta)
        if value is None or abs(value) > 10_000.0:
            return False
        distance = self.distance * ZOOM_PER_NOTCH ** (value / 100.0)
        home = self.home["distance"]
        self.distance = min(home / _MIN_ZOOM, max(home / _MAX_ZOOM, distance))
        return True

    def key(self, name: Any) -> bool:
        """Apply the action of key `name` (``KEYS``); False (ignored) for any other key."""
        action = KEYS.get(name) if isinstance(name, str) else None
        if action is None:
            return False
        if action == "reset":
            self.reset()
        else:
            self.preset(action)
        return True

    def preset(self, name: str) -> None:
        """Look along a multiview preset (``PRESETS``) with an orthographic projection."""
        if name not in PRESETS:
            raise CameraError(f"CameraControl.preset: name = {describe(name)} is unknown; expected one of "
                              + ", ".join(PRESETS))  # fmt: skip
        self.azimuth, self.elevation = PRESETS[name]
        self.projection = "orthographic"

    def set_projection(self, name: Any) -> bool:
        """Switch to projection `name` (one of ``PROJECTIONS``); False (ignored) otherwise."""
        if name not in PROJECTIONS:
            return False
        self.projection = name
        return True

    def reset(self) -> None:
        """Back to the state the control started with."""
        for key, value in self.home.items():
            setattr(self, key, np.array(value, dtype=np.float64) if key == "target" else value)
        self._drag = None
