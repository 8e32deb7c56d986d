"""``[camera]`` and ``[[cameras]]``: the viewing frame, the projection (``PROJECTIONS``, multiview and orbit
placement) and ``[camera.stereo]``."""

from __future__ import annotations

import dataclasses
import importlib
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from frustum._arrays import describe
from frustum.camera import Camera
from frustum.errors import FrustumError
from frustum.projection import MULTIVIEWS, Axonometric, Frustum, Oblique, Orthographic, Perspective
from frustum.scenefile.checks import _boolean, _choice, _is_number, _number, _table, _unknown_keys, _vector
from frustum.scenefile.report import _BAD, _bad, _Report

PROJECTIONS = (
    "perspective", "frustum", "orthographic", "oblique", "cavalier", "cabinet", "isometric", "dimetric", "trimetric",
)  # fmt: skip
"""``camera.projection`` values."""


_CAMERA_KEYS = (
    "eye", "target", "up", "projection", "fovy_deg", "near", "far", "height", "left", "right", "bottom", "top",
    "alpha_deg", "phi_deg", "ratio", "rotation_y_deg", "rotation_x_deg", "pivot", "z_vp", "view", "distance",
    "azimuth_deg", "elevation_deg", "stereo", "fit", "margin",
)  # fmt: skip

AXONOMETRIC_VIEWS = {"iso": (-1.0, -1.0, -1.0), "isometric": (-1.0, -1.0, -1.0)}
"""``camera.view`` names beside the multiview presets: the isometric line of sight (from +x, +y, +z), world y up
(the names ``frustum view --views`` takes)."""

VIEWS = (*sorted(MULTIVIEWS), *AXONOMETRIC_VIEWS)
"""Every ``camera.view`` value."""


def _view_direction(name: str) -> tuple[np.ndarray, list[float]]:
    """The line of sight and up vector of a ``VIEWS`` name."""
    if name in AXONOMETRIC_VIEWS:
        return np.array(AXONOMETRIC_VIEWS[name]) / math.sqrt(3.0), [0.0, 1.0, 0.0]
    preset = MULTIVIEWS[name]
    return np.array(preset.direction, dtype=np.float64), list(preset.up)


_STEREO_KEYS = ("eye_separation", "convergence_distance", "layout", "anaglyph_method", "cross_eyed")


def _camera(report: _Report, path: tuple, value: Any, size: tuple[int, int], scene: Any = None) -> Any:
    """A Camera (or a StereoCamera, with ``[camera.stereo]``) from a camera table."""
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    _unknown_keys(report, path, params, _CAMERA_KEYS)
    if "fit" in params:
        return _fitted(report, path, params, size, scene)
    if "margin" in params:
        report.add((*path, "margin"), params["margin"], "needs fit = true", "margin is the fitted camera's border")
    get = params.get
    target = _vector(report, (*path, "target"), get("target", [0.0, 0.0, 0.0]))
    placement = [key for key in ("eye", "view", "azimuth_deg") if key in params]
    if len(placement) > 1:
        report.add((*path, placement[1]), params[placement[1]], f"conflicts with {placement[0]}",
                   "place the camera by eye (with up), or by view (a multiview preset), or by azimuth_deg and "
                   "elevation_deg, not several")  # fmt: skip
        return _BAD
    how = placement[0] if placement else None
    up = _vector(report, (*path, "up"), get("up", [0.0, 1.0, 0.0]))
    eye: Any = _BAD
    if how == "view":
        view = _choice(report, (*path, "view"), params["view"], VIEWS)
        distance = _number(report, (*path, "distance"), get("distance", 10.0), low=0.0, low_open=True)
        if "up" in params:
            report.add((*path, "up"), params["up"], "conflicts with view", "a multiview preset fixes its own up vector")
            up = _BAD
        if not _bad(view, distance, target, up):
            line, up = _view_direction(view)
            eye = list(np.array(target) - distance * line)
    elif how == "azimuth_deg":
        azimuth = _number(report, (*path, "azimuth_deg"), params["azimuth_deg"])
        elevation = _number(report, (*path, "elevation_deg"), get("elevation_deg", 0.0), low=-89.999, high=89.999)
        distance = _number(report, (*path, "distance"), get("distance", 10.0), low=0.0, low_open=True)
        if not _bad(azimuth, elevation, distance, target):
            a, e = math.radians(azimuth), math.radians(elevation)
            offset = distance * np.array([math.cos(e) * math.sin(a), math.sin(e), math.cos(e) * math.cos(a)])
            eye = list(np.array(target) + offset)
    elif how == "eye":
        eye = _vector(report, (*path, "eye"), params["eye"])
        if "distance" in params:
            report.add((*path, "distance"), params["distance"], "conflicts with eye",
                       "distance goes with view or azimuth_deg; eye fixes it already")  # fmt: skip
    else:
        report.missing((*path, "eye"), "place the camera with eye = [x, y, z], view = 'front' or azimuth_deg")
    if "elevation_deg" in params and how != "azimuth_deg":
        report.add((*path, "elevation_deg"), params["elevation_deg"], "needs azimuth_deg",
                   "give azimuth_deg too, or place the camera by eye")  # fmt: skip
    placed = not _bad(eye, up, target)
    distance = float(np.linalg.norm(np.array(target) - np.array(eye))) if placed else 10.0
    if placed:
        line_of_sight = np.array(target) - np.array(eye)
        if distance == 0.0:
            report.add((*path, "eye"), eye, "equals target", "the eye must not sit on the point it looks at")
            placed = False
        elif not np.linalg.norm(up) > 0.0:
            report.add((*path, "up"), up, "has zero length", "give a nonzero view-up vector such as [0, 1, 0]")
            placed = False
        elif np.linalg.norm(np.cross(np.array(up), line_of_sight)) <= 1e-9 * distance * np.linalg.norm(up):
            report.add((*path, "up"), up, f"is parallel to the view direction {describe(line_of_sight / distance)}",
                       "choose an up vector not along target - eye")  # fmt: skip
            placed = False
    projection = _projection(report, path, params, distance if distance > 0.0 else 10.0, how == "view")
    if projection is _BAD or not placed:
        return _BAD
    try:
        camera = Camera.look_at(eye, target, up, projection, *size)
    except FrustumError as error:
        report.refused(path, params, error)
        return _BAD
    if "stereo" in params:
        return _stereo(report, (*path, "stereo"), params["stereo"], camera, distance)
    return camera


def _fitted(report: _Report, path: tuple, params: dict, size: tuple[int, int], scene: Any) -> Any:
    """$fit = true$: ``Camera.fit`` of the scene from `view`, from `azimuth_deg`/`elevation_deg`, or the 3/4 view;
    perspective (``fovy_deg``) or orthographic, ``margin`` the free border (a fraction of the smaller side)."""
    fit = _boolean(report, (*path, "fit"), params["fit"])
    allowed = ("fit", "view", "azimuth_deg", "elevation_deg", "projection", "fovy_deg", "margin", "stereo")
    for key in params:
        if key not in allowed and key in _CAMERA_KEYS:
            report.add(
                (*path, key),
                params[key],
                "does not apply to fit = true",
                f"a fitted camera takes {', '.join(allowed[1:])}; it places eye, target and distance itself",
            )
            return _BAD
    if fit is _BAD:
        return _BAD
    if not fit:
        report.add((*path, "fit"), False, "is false", "give fit = true, or leave it out and place the camera")
        return _BAD
    if "view" in params and "azimuth_deg" in params:
        report.add((*path, "azimuth_deg"), params["azimuth_deg"], "conflicts with view", "give one of them")
        return _BAD
    direction: Any = None
    up = [0.0, 1.0, 0.0]
    if "view" in params:
        view = _choice(report, (*path, "view"), params["view"], VIEWS)
        if view is _BAD:
            return _BAD
        direction, up = _view_direction(view)
    elif "azimuth_deg" in params or "elevation_deg" in params:
        azimuth = _number(report, (*path, "azimuth_deg"), params.get("azimuth_deg", 45.0))
        elevation = _number(report, (*path, "elevation_deg"), params.get("elevation_deg", 30.0), low=-89.999,
                            high=89.999)  # fmt: skip
        if _bad(azimuth, elevation):
            return _BAD
        a, e = math.radians(azimuth), math.radians(elevation)
        direction = -np.array([math.cos(e) * math.sin(a), math.sin(e), math.cos(e) * math.cos(a)])
    name = _choice(
        report,
        (*path, "projection"),
        params.get("projection", "orthographic" if "view" in params else "perspective"),
        ("perspective", "orthographic"),
    )
    fovy = _number(report, (*path, "fovy_deg"), params.get("fovy_deg", 40.0), low=0.0, high=180.0, low_open=True)
    margin = _number(report, (*path, "margin"), params.get("margin", 0.05), low=0.0, high=0.49)
    if _bad(name, fovy, margin):
        return _BAD
    if scene is None or not scene.items:
        report.add((*path, "fit"), True, "has nothing to frame", "add [[nodes]] with geometry, or place the camera")
        return _BAD
    try:
        camera = Camera.fit(scene, direction, math.radians(fovy), margin, projection=name, width=size[0],
                            height=size[1], up=up)  # fmt: skip
    except FrustumError as error:
        report.refused(path, params, error)
        return _BAD
    if "stereo" in params:
        distance = float(np.linalg.norm(np.array(camera.frame.eye) - np.array(camera.frame.target)))
        return _stereo(report, (*path, "stereo"), params["stereo"], camera, distance)
    return camera


def _projection(report: _Report, path: tuple, params: dict, distance: float, multiview: bool) -> Any:
    name = params.get("projection", "orthographic" if multiview else "perspective")
    name = _choice(report, (*path, "projection"), name, PROJECTIONS)
    if name is _BAD:
        return _BAD
    parallel = name not in ("perspective", "frustum")
    used = {"projection", "near", "far"}
    near = _number(report, (*path, "near"), params.get("near", 0.1))
    far = _number(report, (*path, "far"), params.get("far", max(100.0, 4.0 * distance)))
    # parallel views default to the window a 45° perspective shows at the target: switching keeps the framing
    height: Any = 2.0 * distance * math.tan(math.radians(22.5))
    if parallel:
        used.add("height")
        height = _number(report, (*path, "height"), params.get("height", height), low=0.0, low_open=True)
    specific = {
        "perspective": ("fovy_deg",),
        "frustum": ("left", "right", "bottom", "top"),
        "oblique": ("alpha_deg", "phi_deg", "z_vp"),
        "cavalier": ("phi_deg", "z_vp"),
        "cabinet": ("phi_deg", "z_vp"),
        "isometric": ("pivot",),
        "dimetric": ("ratio", "pivot"),
        "trimetric": ("rotation_y_deg", "rotation_x_deg", "pivot"),
        "orthographic": (),
    }[name]
    used.update(specific)
    for key in ("fovy_deg", "left", "right", "bottom", "top", "alpha_deg", "phi_deg", "z_vp", "ratio",
                "rotation_y_deg", "rotation_x_deg", "pivot", "height"):  # fmt: skip
        if key in params and key not in used:
            report.add((*path, key), params[key], f"does not apply to projection = {name!r}",
                       f"{name} takes {', '.join(sorted(used - {'projection'}))}")  # fmt: skip
    if not _is_number(near) or not _is_number(far) or not _is_number(height):
        return _BAD
    if not parallel and not near > 0.0:
        report.add((*path, "near"), near, "must be > 0", "near and far are positive distances, near < far")
        return _BAD
    if not far > near:
        report.add((*path, "far"), far, f"is not beyond near = {near!r}", "expected near < far")
        return _BAD
    values: dict[str, Any] = {}
    for key in specific:
        if key in params:
            values[key] = _number(report, (*path, key), params[key])
    if _bad(*values.values()):
        return _BAD
    degrees = {k[:-4]: math.radians(v) for k, v in values.items() if k.endswith("_deg")}
    plain = {k: v for k, v in values.items() if not k.endswith("_deg")}
    try:
        if name == "perspective":
            fovy = degrees.get("fovy", math.radians(45.0))
            if not 0.0 < fovy < math.pi:
                report.add((*path, "fovy_deg"), params.get("fovy_deg"), "is out of range",
                           "expected 0 < fovy_deg < 180")  # fmt: skip
                return _BAD
            return Perspective(fovy, near, far)
        if name == "frustum":
            missing = [key for key in specific if key not in plain]
            for key in missing:
                report.missing((*path, key), "a frustum projection needs left, right, bottom, top (near window)")
            return _BAD if missing else Frustum(plain["left"], plain["right"], plain["bottom"], plain["top"], near, far)
        if name == "orthographic":
            return Orthographic(height, near, far)
        z_vp = plain.get("z_vp", -distance)
        if name in ("oblique", "cavalier", "cabinet"):
            phi = degrees.get("phi", math.radians(45.0))
            alpha = {"cavalier": math.pi / 4, "cabinet": math.atan(2.0)}.get(name, degrees.get("alpha"))
            if alpha is None:
                report.missing((*path, "alpha_deg"), "an oblique projection needs alpha_deg (45: cavalier)")
                return _BAD
            return Oblique(alpha, phi, height, near, far, z_vp)
        pivot = plain.get("pivot", distance)
        if name == "isometric":
            return dataclasses.replace(Axonometric.isometric(height, near, far), pivot=pivot)
        if name == "dimetric":
            if "ratio" not in plain:
                report.missing((*path, "ratio"), "a dimetric projection needs ratio (f_y / f_x in (0, sqrt 2))")
                return _BAD
            return dataclasses.replace(Axonometric.dimetric(plain["ratio"], height, near, far), pivot=pivot)
        missing = [key for key in ("rotation_y_deg", "rotation_x_deg") if key not in values]
        for key in missing:
            report.missing((*path, key), "a trimetric projection needs rotation_y_deg and rotation_x_deg")
        if missing:
            return _BAD
        return Axonometric(degrees["rotation_y"], degrees["rotation_x"], height, near, far, pivot)
    except FrustumError as error:
        report.refused((*path, "projection"), name, error)
        return _BAD


def _stereo(report: _Report, path: tuple, value: Any, camera: Camera, distance: float) -> Any:
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    _unknown_keys(report, path, params, _STEREO_KEYS)
    stereo_module, images = _stereo_modules()
    if stereo_module is None:
        report.add(path, params, "is not available in this version", "frustum.stereo is missing")
        return _BAD
    separation = _number(report, (*path, "eye_separation"), params.get("eye_separation", distance / 30.0),
                         low=0.0, low_open=True)  # fmt: skip
    convergence = _number(report, (*path, "convergence_distance"), params.get("convergence_distance", distance),
                          low=0.0, low_open=True)  # fmt: skip
    layout = _choice(report, (*path, "layout"), params.get("layout", "anaglyph"), images.STEREO_LAYOUTS)
    method = _choice(report, (*path, "anaglyph_method"), params.get("anaglyph_method", "color"),
                     images.ANAGLYPH_METHODS)  # fmt: skip
    cross = _boolean(report, (*path, "cross_eyed"), params.get("cross_eyed", False))
    if _bad(separation, convergence, layout, method, cross):
        return _BAD
    try:
        stereo = stereo_module.StereoCamera(camera, separation, convergence)
    except FrustumError as error:
        report.refused(path, params, error)
        return _BAD
    return _Stereo(stereo, layout, method, cross)


def _stereo_modules() -> tuple[Any, Any]:
    """(frustum.stereo, the stereo image module) or (None, None) where this version has no stereo."""
    for images_name in ("frustum.output.stereo", "frustum.stereo_images"):
        try:
            return importlib.import_module("frustum.stereo"), importlib.import_module(images_name)
        except ImportError:
            continue
    return None, None


@dataclass(frozen=True)
class _Stereo:
    """A stereo camera with its image layout."""

    camera: Any  # frustum.stereo.StereoCamera
    layout: str
    anaglyph_method: str
    cross_eyed: bool
