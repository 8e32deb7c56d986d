"""The options of one ``render`` call, checked once: ``RenderOptions.from_keywords`` turns ``render``'s keyword
arguments (or a scene file's ``[render]`` table, the same names) into one frozen object that every pass reads.

Every check names the bad value and lists what would be valid (``FrustumError``); the order of the checks is the
order in which ``render`` has always made them, so the first error a call gets is the same.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from frustum._arrays import as_scalar, describe
from frustum.budgets import check_memory
from frustum.camera import Camera
from frustum.errors import FrustumError
from frustum.frame import background_bytes
from frustum.raster import shade
from frustum.raster.pbr import SHADE_PBR
from frustum.scene import Scene
from frustum.shading import SPECULAR_MODELS, DepthCue

SHADING_MODES = {
    "phong": shade.SHADE_PHONG,
    "gouraud": shade.SHADE_GOURAUD,
    "flat": shade.SHADE_FLAT,
    "normals": shade.SHADE_NORMALS,
    "depth": shade.SHADE_DEPTH,
    "none": shade.SHADE_NONE,
    "pbr": SHADE_PBR,
}
"""Shading names ``render`` accepts (``None`` means ``"none"``)."""
RENDER_MODES = ("surface", "wireframe", "points", "hidden-line", "surface+edges")
"""What ``render`` draws: filled surfaces, edges as lines, vertices as pixels, visible edges only, or both."""
LINE_MODES = ("wireframe", "points")
"""Modes that draw no surfaces: lines or points straight into the depth buffer (``render.lines``)."""
EDGE_MODES = ("hidden-line", "surface+edges")
"""Modes that draw surfaces, then their visible edges against the finished depth buffer."""
HIDDEN_STYLES = (None, "dimmed", "dashed")
"""How ``mode="hidden-line"`` draws the hidden parts of edges: not at all, solid in `hidden_color`, or dashed."""
EDGE_SETS = ("all", "feature")
FILTERS = ("box", "tent")
COLOR_SPACES = ("linear", "srgb")
GROUND_TRUTH_BUFFERS = ("instance", "semantic", "amodal", "object_coords", "nocs", "flow")
"""Ground-truth buffers (``render.ground_truth``), computed from the ``object_id`` and ``position`` samples."""
BUFFERS = ("normals", "object_id", "position", "shadow", *GROUND_TRUTH_BUFFERS)
TRANSPARENCY_MODES = ("sort", "a-buffer")
METHOD_NAMES = ("depth-buffer", "scan-line", "area-subdivision", "depth-sort", "bsp", "a-buffer", "octree",
                "ray-casting", "ray-tracing")  # fmt: skip
"""``render(..., method=...)``, in the order error messages list them (``render.methods.RENDER_METHODS``)."""
PLANNED_METHODS: dict[str, str] = {}
"""Methods of the visible-surface chapter that this version does not draw yet."""
MAX_DEPTH = 64
"""Largest ``max_depth`` (reflection and refraction levels) of ``method="ray-tracing"``."""
MAX_LINE_WIDTH = 256.0
"""Widest line (and largest point) ``render`` draws, in output pixels."""

SHADOW_METHODS = (None, False, True, "ray")
"""``render(..., shadows=...)``: the method's own (off for every method of today), off, shadow maps, rays."""
MIN_MAP_SIZE, MAX_MAP_SIZE = 64, 16384

DEFAULT_BACKGROUND = (0.0, 0.0, 0.0, 1.0)
"""``render``'s default background (opaque black). Left at this very object, a scene's environment map is shown
instead (``frustum.render.reflection``)."""

DEFAULTS: dict[str, Any] = {
    "shading": "phong",
    "specular": "blinn-phong",
    "background": DEFAULT_BACKGROUND,
    "cull_back_faces": True,
    "mode": "surface",
    "edges": None,
    "crease_angle": math.radians(30.0),
    "edge_color": None,
    "hidden": None,
    "hidden_color": (0.6, 0.6, 0.6),
    "line_width": 1.0,
    "depth_cue": None,
    "samples": 1,
    "filter": "box",
    "color_space": "linear",
    "buffers": (),
    "method": "depth-buffer",
    "transparency": "sort",
    "stats": False,
    "max_depth": 5,
    "shadows": None,
    "shadow_map_size": 2048,
    "shadow_softness": 1.0,
    "eye_dome": False,
    "eye_dome_strength": 1.0,
    "tone_map": "none",
    "exposure": 1.0,
    "next": None,
}
"""``render``'s keyword arguments and their defaults (a test holds them equal to ``render``'s signature)."""


@dataclasses.dataclass(frozen=True)
class RenderOptions:
    """``render``'s options, checked and in the form the passes use (kernel codes, color bytes).

    Configuration only: what the passes produce (counts, buffers, the shadow pass's outputs) goes into the
    frame's ``render.context.FrameContext``. ``factor`` is √samples (the supersampling factor).
    """

    shade_mode: int
    specular_model: int
    background: np.ndarray  # (4,) uint8
    cull: bool
    mode: str
    edges: str
    crease_angle: float
    edge_color: np.ndarray | None  # (4,) bytes as float, or None for the material color
    hidden: str | None
    hidden_color: np.ndarray
    line_width: float
    depth_cue: DepthCue | None
    buffers: tuple[str, ...]
    method: str = "depth-buffer"
    transparency: str = "sort"
    counted: bool = False  # the method counts its work into Frame.stats (render.context.FrameContext.counts)
    factor: int = 1
    filter: str = "box"
    color_space: str = "linear"
    shadow: Any = None  # ShadowOptions, or None: no shadows
    environment: Any = None  # the scene's EnvironmentMap, for reflections (and the background, below)
    environment_background: bool = False  # no background given: the environment map is the background
    max_depth: int = 5
    shadows: bool = False  # method="ray-tracing": cast shadow rays (the other methods: ``shadow`` above)
    eye_dome: float = 0.0  # eye-dome lighting strength (``render.eye_dome``); 0: off
    tone_map: int = 0  # shading.tone.TONE_MAPS code (the metallic–roughness model's output transform)
    exposure: float = 1.0
    physical_ambient: Any = None  # (3,) the scene's AmbientLights summed (zero without one): shading.pbr's I_a
    implied: tuple[str, ...] = ()  # buffers the ground truth is computed from, not asked for: left off the Frame
    next: Any = None  # (Scene, Camera) of the next frame, for the "flow" buffer (``check_next``)

    @classmethod
    def from_keywords(cls, scene: Any, camera: Any, where: str = "render", **keywords: Any) -> RenderOptions:
        """Check `keywords` (``render``'s, missing ones at their ``DEFAULTS``) and build the options; a
        FrustumError (prefixed by `where`) for the first bad one. The image budget is checked last, before any
        buffer is allocated."""
        unknown = sorted(set(keywords) - set(DEFAULTS))
        if unknown:
            raise FrustumError(
                f"{where}: unknown option {', '.join(map(repr, unknown))}; expected one of " + ", ".join(DEFAULTS)
            )
        k = {**DEFAULTS, **keywords}
        check_method(k["method"], where)
        options = check_arguments(
            scene, camera, k["shading"], k["specular"], k["background"], k["cull_back_faces"], k["mode"], k["edges"],
            k["crease_angle"], k["edge_color"], k["hidden"], k["hidden_color"], k["line_width"], k["depth_cue"],
            k["buffers"], where,
        )  # fmt: skip
        factor = supersampling(k["samples"], where)
        options = method_options(options, k["method"], k["transparency"], k["stats"], where)
        tracing = options.method == "ray-tracing"  # shadow rays of its own (ray_options), never shadow maps
        options = shadow_options(options, None if tracing else k["shadows"], k["shadow_map_size"],
                                 k["shadow_softness"], where)  # fmt: skip
        choice(k["filter"], FILTERS, "filter", where)
        choice(k["color_space"], COLOR_SPACES, "color_space", where)
        depth, shadows = ray_options(options, k["max_depth"], k["shadows"], k["depth_cue"], k["shading"], where)
        eye_dome = eye_dome_strength(k["eye_dome"], k["eye_dome_strength"], where)
        check_image_budget(camera, factor, options.buffers, k["filter"], k["color_space"], where)
        following = check_next(options.buffers, k["next"], where)
        environment = getattr(scene, "environment", None)
        tone_map, exposure, ambient = physical_options(scene, options, k["tone_map"], k["exposure"], where)
        return dataclasses.replace(options, factor=factor, filter=k["filter"], color_space=k["color_space"],
                                   environment=environment, tone_map=tone_map, exposure=exposure,
                                   physical_ambient=ambient,
                                   environment_background=environment is not None
                                   and k["background"] is DEFAULT_BACKGROUND,
                                   max_depth=depth, shadows=shadows, eye_dome=eye_dome, next=following)  # fmt: skip

    def supersampled(self) -> RenderOptions:
        """The options for the √samples-times larger image: lines √samples times as wide."""
        return dataclasses.replace(self, line_width=self.line_width * self.factor)

    @property
    def positions_wanted(self) -> bool:
        """Whether the shadow pass finds the world points of the drawn pixels (``render.shadows``): shadows on, or
        the "position" buffer asked for."""
        return self.shadow is not None or "position" in self.buffers

    @property
    def volumes_with_surfaces(self) -> bool:
        """Whether the volumes are ray cast right after the opaque surfaces (``"surface"``, ``"surface+edges"``:
        before transparent items) rather than after the lines (``"wireframe"``, ``"points"``, ``"hidden-line"``)."""
        return self.mode in ("surface", "surface+edges")


def shadow_options(options: RenderOptions, shadows: Any, map_size: Any, softness: Any, where: str) -> RenderOptions:
    """Check the shadow arguments (``check_shadows``); the options with the shadow settings."""
    shadow = check_shadows(shadows, map_size, softness, options.method, options.mode, where)
    if "shadow" in options.buffers and shadow is None:
        raise FrustumError(
            f"{where}: buffers = {describe(options.buffers)} asks for 'shadow' with shadows = {describe(shadows)}; "
            "give shadows=True or 'ray'"
        )
    if "position" in options.buffers and options.mode in LINE_MODES:
        raise FrustumError(
            f"{where}: buffers = {describe(options.buffers)} asks for 'position' with mode = {options.mode!r}; "
            "positions are those of surfaces: use a surface mode"
        )
    return dataclasses.replace(options, shadow=shadow)


def eye_dome_strength(on: Any, strength: Any, where: str) -> float:
    """The eye-dome lighting strength (> 0) where `on`, else 0."""
    if not isinstance(on, bool | np.bool_):
        raise FrustumError(f"{where}: eye_dome = {describe(on)} is not a bool; give True or False")
    value = as_scalar(strength, "eye_dome_strength", where=where, error=FrustumError)
    if not value > 0.0:
        raise FrustumError(f"{where}: eye_dome_strength = {value!r} is not positive; give a strength > 0 (1: default)")
    return value if on else 0.0
def physical_options(scene: Scene, options: RenderOptions, tone_map: Any, exposure: Any,
                     where: str) -> tuple[int, float, np.ndarray]:  # fmt: skip
    """The metallic–roughness model's output transform (``shading.tone``: the tone map's code and the exposure, a
    linear factor > 0) and the scene's ambient radiance; shading "pbr" is not drawn by the A-buffer."""
    from frustum.shading import AmbientLight
    from frustum.shading.tone import TONE_MAPS

    choice(tone_map, tuple(TONE_MAPS), "tone_map", where)
    factor = as_scalar(exposure, "exposure", where=where, error=FrustumError)
    if not (math.isfinite(factor) and factor > 0.0):
        raise FrustumError(f"{where}: exposure = {factor!r} is not a factor > 0 (1: the radiance as computed)")
    if options.shade_mode == SHADE_PBR and "a-buffer" in (options.method, options.transparency):
        raise FrustumError(
            f"{where}: shading = 'pbr' is not drawn by the A-buffer (method or transparency 'a-buffer'); use the "
            "depth buffer or another method with transparency 'sort'"
        )
    ambient = np.zeros(3)
    for light in scene.world_lights():
        if isinstance(light, AmbientLight):
            ambient = ambient + light.color * light.intensity
    return TONE_MAPS[tone_map], factor, ambient


def choice(value: Any, valid: tuple, name: str, where: str) -> Any:
    if not isinstance(value, str | type(None)) or value not in valid:
        raise FrustumError(
            f"{where}: {name} = {describe(value)} is unknown; expected one of " + ", ".join(repr(v) for v in valid)
        )
    return value


def supersampling(samples: Any, where: str) -> int:
    """√samples for a perfect square samples >= 1, else a FrustumError."""
    if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 1:
        raise FrustumError(f"{where}: samples = {describe(samples)} is not a positive integer; use 1, 4, 9 or 16")
    factor = math.isqrt(int(samples))
    if factor * factor != samples:
        raise FrustumError(f"{where}: samples = {samples} is not a perfect square; use 1, 4, 9 or 16")
    return factor


def color_bytes(value: Any, name: str, where: str) -> np.ndarray:
    """(4,) float64 bytes of an RGB or RGBA color in [0, 1] (alpha 1 if not given)."""
    try:
        array = np.asarray(value, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        array = np.array([np.nan])
    if array.shape not in ((3,), (4,)) or not np.isfinite(array).all() or (array < 0).any() or (array > 1).any():
        raise FrustumError(
            f"{where}: {name} = {describe(value)} is not an RGB(A) color; expected 3 or 4 numbers in [0, 1]"
        )
    if array.shape == (3,):
        array = np.append(array, 1.0)
    return np.floor(array * 255.0 + 0.5)


def check_image_budget(camera: Camera, factor: int, buffers: tuple[str, ...], filter: str, color_space: str,
                       where: str) -> None:  # fmt: skip
    """Refuse, before any buffer is allocated, an image whose buffers exceed the memory budget (``frustum.budgets``).

    Per rendered pixel ($width·height·samples$ of them): color 4 + depth 4 bytes, about 4 bytes of the
    renderer's work arrays (measured with tracemalloc: 12 bytes a pixel at 1024², surface mode), 12 for a
    ``normals`` buffer and 4 for ``object_id``; a float64 copy for the tent filter or sRGB (2 × 32 bytes).
    """
    pixels = camera.width * camera.height * factor * factor
    per_pixel = 12 + 12 * ("normals" in buffers) + 4 * ("object_id" in buffers)
    if filter != "box" or color_space != "linear":
        per_pixel += 64
    cause = f"a {camera.width} x {camera.height} image x samples = {factor * factor}"
    check_memory(pixels * per_pixel, where=where, cause=cause, error=FrustumError)


def check_arguments(
    scene: Any, camera: Any, shading: Any, specular: Any, background: Any, cull_back_faces: Any, mode: Any,
    edges: Any, crease_angle: Any, edge_color: Any, hidden: Any, hidden_color: Any, line_width: Any,
    depth_cue: Any, buffers: Any, where: str,
) -> RenderOptions:  # fmt: skip
    """The scene, the camera and the drawing options (everything but the method, samples and the resolve)."""
    if not isinstance(scene, Scene):
        raise FrustumError(f"{where}: scene = {describe(scene)} is not a Scene; build one with Scene(lights=[...])")
    if not isinstance(camera, Camera):
        raise FrustumError(
            f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at(eye, target, up)"
        )
    name = "none" if shading is None else shading
    if not isinstance(name, str) or name not in SHADING_MODES:
        raise FrustumError(
            f"{where}: shading = {describe(shading)} is unknown; expected one of "
            + ", ".join(repr(n) for n in SHADING_MODES)
            + " or None"
        )
    choice(specular, SPECULAR_MODELS, "specular", where)
    choice(mode, RENDER_MODES, "mode", where)
    if not isinstance(cull_back_faces, bool | np.bool_):
        raise FrustumError(f"{where}: cull_back_faces = {describe(cull_back_faces)} is not a bool; give True or False")
    if edges is None:
        edges = "all" if mode in LINE_MODES else "feature"
    choice(edges, EDGE_SETS, "edges", where)
    angle = as_scalar(crease_angle, "crease_angle", where=where, error=FrustumError)
    if not 0.0 <= angle <= math.pi:
        raise FrustumError(f"{where}: crease_angle = {angle!r} is outside [0, pi] radians")
    choice(hidden, HIDDEN_STYLES, "hidden", where)
    width = as_scalar(line_width, "line_width", where=where, error=FrustumError)
    if width < 1.0:
        raise FrustumError(f"{where}: line_width = {width!r} is below 1; give a width in pixels >= 1")
    if width > MAX_LINE_WIDTH:
        raise FrustumError(
            f"{where}: line_width = {width!r} is above {MAX_LINE_WIDTH:g}; give a width in pixels in [1, "
            f"{MAX_LINE_WIDTH:g}]"
        )
    if depth_cue is not None and not isinstance(depth_cue, DepthCue):
        raise FrustumError(
            f"{where}: depth_cue = {describe(depth_cue)} is not a DepthCue; build one with DepthCue(near, far)"
        )
    if isinstance(buffers, str) or not all(isinstance(b, str) and b in BUFFERS for b in buffers):
        raise FrustumError(
            f"{where}: buffers = {describe(buffers)} is not a tuple of buffer names; valid names: "
            + ", ".join(repr(b) for b in BUFFERS)
        )
    background_rgba = background_bytes(background, where)
    full = with_implied(tuple(buffers), mode, where)
    if edge_color is None:  # material colors for wireframes; black on light backgrounds, white on dark ones
        light = background_rgba[:3].astype(float) @ (0.2126, 0.7152, 0.0722) > 127.5
        edge = None if mode in LINE_MODES else np.array([0.0, 0.0, 0.0, 255.0]) * light + 255.0 * (not light)
    else:
        edge = color_bytes(edge_color, "edge_color", where)
    return RenderOptions(
        shade_mode=SHADING_MODES[name],
        specular_model=shade.SPECULAR_PHONG if specular == "phong" else shade.SPECULAR_BLINN,
        background=background_rgba,
        cull=bool(cull_back_faces),
        mode=mode,
        edges=edges,
        crease_angle=angle,
        edge_color=edge,
        hidden=hidden,
        hidden_color=color_bytes(hidden_color, "hidden_color", where),
        line_width=width,
        depth_cue=depth_cue,
        buffers=full,
        implied=tuple(name for name in full if name not in buffers),
    )


def with_implied(buffers: tuple[str, ...], mode: str, where: str) -> tuple[str, ...]:
    """`buffers` and those the ground-truth buffers are computed from (``render.ground_truth``): ``object_id``
    for each, ``position`` for ``object_coords``, ``nocs`` and ``flow``; these need surfaces (a surface mode)."""
    truth = [name for name in buffers if name in GROUND_TRUTH_BUFFERS]
    if not truth:
        return buffers
    if mode in LINE_MODES:
        raise FrustumError(
            f"{where}: buffers = {describe(buffers)} asks for ground truth with mode = {mode!r}; ids and points are "
            "those of surfaces: use a surface mode"
        )
    implied = ["object_id"] + (["position"] if {"object_coords", "nocs", "flow"} & set(truth) else [])
    return buffers + tuple(name for name in implied if name not in buffers)


def check_next(buffers: Any, next: Any, where: str) -> tuple[Scene, Camera] | None:
    """`next` as ``(scene, camera)``; None when not given. Required by (and only allowed with) ``"flow"``."""
    buffers = tuple(buffers) if isinstance(buffers, tuple | list) else ()
    if next is None:
        if "flow" in buffers:
            raise FrustumError(
                f"{where}: buffers = {describe(buffers)} asks for 'flow' without next; give next=(scene_next, "
                "camera_next), the same scene and camera at the next frame"
            )
        return None
    if (not isinstance(next, tuple | list) or len(next) != 2 or not isinstance(next[0], Scene)
            or not isinstance(next[1], Camera)):  # fmt: skip
        raise FrustumError(f"{where}: next = {describe(next)} is not a (Scene, Camera) pair")
    if "flow" not in buffers:
        raise FrustumError(f"{where}: next is given but buffers = {describe(buffers)} has no 'flow'; add 'flow'")
    return next[0], next[1]


def check_method(method: Any, where: str) -> None:
    """A FrustumError listing the available methods for an unknown or not yet available `method`."""
    valid = ", ".join(repr(name) for name in METHOD_NAMES)
    if isinstance(method, str) and method in PLANNED_METHODS:
        raise FrustumError(
            f"{where}: method = {method!r} is not available yet ({PLANNED_METHODS[method]}); available: {valid}"
        )
    if not isinstance(method, str) or method not in METHOD_NAMES:
        raise FrustumError(f"{where}: method = {describe(method)} is unknown; expected one of {valid}")


def method_options(options: RenderOptions, method: Any, transparency: Any, stats: Any, where: str) -> RenderOptions:
    """Check `transparency` and `stats`; the options with the method (a mesh pipeline one, ``check_method``
    first), the transparency and whether the frame's work is counted (``Frame.stats``)."""
    choice(transparency, TRANSPARENCY_MODES, "transparency", where)
    if not isinstance(stats, bool | np.bool_):
        raise FrustumError(f"{where}: stats = {describe(stats)} is not a bool; give True or False")
    if (method != "depth-buffer" or transparency != "sort") and options.mode in LINE_MODES:
        raise FrustumError(
            f"{where}: method = {method!r} with transparency = {transparency!r} draws surfaces; mode = "
            f"{options.mode!r} draws lines or points with the depth buffer: use mode 'surface', 'hidden-line' or "
            "'surface+edges', or method 'depth-buffer'"
        )
    if method == "a-buffer" and options.buffers:
        raise FrustumError(
            f"{where}: buffers = {describe(options.buffers)} are not available with method 'a-buffer' (a pixel "
            "holds several surfaces); use another method for per-pixel normals or object ids"
        )
    counted = method != "depth-buffer" or transparency != "sort" or bool(stats)
    return dataclasses.replace(options, method=method, transparency=transparency, counted=counted)


def ray_options(options: RenderOptions, max_depth: Any, shadows: Any, depth_cue: Any, shading: Any,
                where: str) -> tuple[int, bool]:  # fmt: skip
    """``max_depth`` (0 … MAX_DEPTH) and whether ``method="ray-tracing"`` casts shadow rays (``shadows`` None, True
    or "ray": yes; False: no; False for the other methods, whose shadows are the shadow pass's); what
    ``"ray-tracing"`` does not draw (other modes, shading models, depth cueing, A-buffer transparency)."""
    if isinstance(max_depth, bool) or not isinstance(max_depth, int | np.integer) or not 0 <= max_depth <= MAX_DEPTH:
        raise FrustumError(
            f"{where}: max_depth = {describe(max_depth)} is not an integer in [0, {MAX_DEPTH}] (levels of reflected "
            "and refracted rays)"
        )
    tracing = options.method == "ray-tracing"
    if not tracing:  # shadow maps or rays of the shadow pass: checked by shadow_options
        return int(max_depth), False
    if shadows is not None and not isinstance(shadows, bool | np.bool_) and shadows != "ray":
        raise FrustumError(f"{where}: shadows = {describe(shadows)} is not None, False, True or 'ray'")
    if tracing:
        name = "none" if shading is None else shading
        if (options.mode != "surface" or name not in ("phong", "pbr") or depth_cue is not None
                or options.transparency != "sort"):  # fmt: skip
            raise FrustumError(
                f"{where}: method 'ray-tracing' draws mode 'surface' with shading 'phong' or 'pbr', no depth_cue and "
                f"transparency 'sort' (transparent surfaces refract); got mode = {options.mode!r}, shading = "
                f"{shading!r}, depth_cue = {describe(depth_cue)}, transparency = {options.transparency!r}"
            )
    return int(max_depth), bool(tracing if shadows is None else shadows)


@dataclasses.dataclass(frozen=True)
class ShadowOptions:
    """What ``render`` was asked for: ``"map"`` or ``"ray"``, the map size in texels and the PCF radius."""

    method: str
    map_size: int = 2048
    softness: float = 1.0


def check_shadows(
    shadows: Any, shadow_map_size: Any, shadow_softness: Any, method: str, mode: str, where: str
) -> ShadowOptions | None:  # fmt: skip
    """The ``shadows``/``shadow_map_size``/``shadow_softness`` arguments checked; None where shadows are off."""
    if not (shadows is None or isinstance(shadows, bool | np.bool_) or shadows == "ray"):
        raise FrustumError(
            f"{where}: shadows = {describe(shadows)} is unknown; expected None (the method's own), False, True "
            "(shadow maps) or 'ray' (shadow rays)"
        )
    if isinstance(shadow_map_size, bool) or not isinstance(shadow_map_size, int | np.integer):
        raise FrustumError(
            f"{where}: shadow_map_size = {describe(shadow_map_size)} is not an integer; give a power of two in "
            f"[{MIN_MAP_SIZE}, {MAX_MAP_SIZE}]"
        )
    size = int(shadow_map_size)
    if not (MIN_MAP_SIZE <= size <= MAX_MAP_SIZE and size & (size - 1) == 0):
        raise FrustumError(
            f"{where}: shadow_map_size = {size} is not a power of two in [{MIN_MAP_SIZE}, {MAX_MAP_SIZE}]; give "
            "e.g. 1024, 2048 or 4096"
        )
    try:
        softness = float(shadow_softness)
    except (TypeError, ValueError):
        softness = math.nan
    if isinstance(shadow_softness, bool) or not (0.0 <= softness <= 16.0):
        raise FrustumError(
            f"{where}: shadow_softness = {describe(shadow_softness)} is not a number in [0, 16]; give the "
            "filter radius in shadow-map texels (0: hard edges)"
        )
    if shadows is None or shadows is False or (isinstance(shadows, np.bool_) and not shadows):
        return None
    if mode not in ("surface", "surface+edges"):
        raise FrustumError(
            f"{where}: shadows = {shadows!r} with mode = {mode!r}: shadows fall on shaded surfaces; use mode "
            "'surface' or 'surface+edges', or shadows=False"
        )
    if method in ("octree", "a-buffer"):
        raise FrustumError(
            f"{where}: shadows = {shadows!r} is not available with method = {method!r}; use another method, "
            "or shadows=False"
        )
    kind = "ray" if shadows == "ray" or method == "ray-casting" else "map"
    return ShadowOptions(kind, size, softness)
