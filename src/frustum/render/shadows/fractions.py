"""The shadow pass of ``render``: which part of each light reaches each visible point.

"Apply a hidden-surface method with the light source at the view position" [HB 17, "Shadows"]: once the opaque
surfaces are in the depth buffer, every drawn pixel's world point (``surface_points``) is tested against each
shadow-casting light in one of two ways.

- **Shadow maps** (``shadows=True``): the depth-buffer method run from the light (the renderer's own binning and
  tile set-up, ``render.bin_item`` + ``raster.shadow.fill_depth_tiles``, depth alone, into a float32 depth map of
  ``shadow_map_size``² texels; both sides of an open surface, the front faces of a closed one). A directional
  light gets an orthographic map fitted to what the camera sees (the light-space box of the drawn points, widened
  by the filter's reach; a frame drawn tile by tile, ``render.shadows.draw_tiled``, fits it before drawing:
  ``view_map``, and reuses the map of an earlier frame when the casters' bytes, their transforms, the light
  camera and the size are the same: ``kept_maps``, ``set_map_reuse``; all casters are filled in one pass per
  culling, ``caster_groups``) and
  deep enough toward the light to hold every caster (the scene's box); a spot light a perspective map over its
  cone; a point light a cube of six perspective maps (each a little wider than 90° so filter taps near a cube
  edge stay on their face). A point is lit where its distance along the light's axis, less a bias, is not beyond
  the map's: the bias is slope-scaled, $texel·(1 + (1 + softness)·min(tan θ, 8))$ with θ the angle between the
  face normal and the light, and the point is first moved one texel along its face normal (normal offset), so lit
  faces show no acne while shadows stay attached at contact. Percentage-closer filtering: softness 0, the
  nearest texel (hard edges); 0 < softness <= 1 (the default 1), the 2 × 2 texels around the point bilinearly
  weighted (``sampler2DShadow`` with linear filtering), each weight ramping over ``softness`` texels; above 1, a
  (2m + 1)² grid of taps spanning ±``shadow_softness`` texels (m = ⌈softness⌉).
- **Shadow rays** (``shadows="ray"``): a ray from each point (moved off its face by a small epsilon along the face
  normal) toward the light, any hit before the light ends it (``occluded``: ``Scene.occluded``, the any-hit
  query through the scene's BVH, ``raster.rays``). Exact up to the epsilon.

Either way a point whose drawn side faces away from the light gets 0 (the surface itself is in the way). What
casts and receives: opaque meshes cast and receive (with bump or normal maps, or reflective, too); transparent
items (``Material.opacity < 1``) cast no shadow and receive none; volumes, particles, polylines and edges neither
cast nor receive. Outside a spot light's map (beyond its cone, where it gives no light anyway) the fraction is 1.

How the fractions enter the shading (``raster.shadow.shade_pixels_shadowed``): per-pixel Phong scales each
light's diffuse and specular terms at the pixel; Gouraud and flat shading keep each light's terms per vertex (per
face) apart and scale them, interpolated (constant), by the pixel's fraction, so a shadow edge is as sharp as
the map or the rays make it in every mode; ``"none"``, ``"normals"`` and ``"depth"`` ignore shadows.

Lights are gathered as ``Scene.world_lights`` gathers them: the root's lights first, then the lights riding
nodes in depth-first order; ``Frame.shadow[..., j]`` is the j-th of those with ``cast_shadows`` (ambient lights
cast none).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import Any

import numpy as np

from frustum.budgets import check_memory, format_bytes
from frustum.camera import Camera, ViewFrame
from frustum.projection import Orthographic, Perspective
from frustum.render.buffers import give_back, keeps_memory, release_work_arrays, take_array
from frustum.render.options import SHADOW_METHODS, ShadowOptions, check_shadows
from frustum.render.shadows import merged
from frustum.render.stages import TILED_BITS, bin_item
from frustum.scene import Scene, SceneItem
from frustum.shading import AmbientLight, DirectionalLight, PointLight, SpotLight

__all__ = [
    "SHADOW_METHODS", "ShadowOptions", "casters_key", "check_shadows", "give_back", "keep_maps", "kept_maps",
    "light_fractions", "map_key", "map_record", "occluded", "release_memory", "set_map_reuse", "shadow_lights",
    "surface_points", "take_array", "view_map",
]  # fmt: skip

RAY_EPSILON = 1e-6
"""Shadow rays start this far off the surface along its face normal, relative to the scene's size (its box's
diagonal): well above the float64 round-off of a hit point, far below a pixel."""
_MARGIN_TEXELS = 3.0
_LOCK = threading.Lock()


@keeps_memory
def release_memory() -> int:
    """Free the work arrays the shadow pass keeps between frames and the shadow maps kept for reuse; return their
    bytes."""
    released = release_work_arrays()
    with _LOCK:
        released += sum(maps.nbytes for _, maps in _KEPT)
        _KEPT.clear()
        _MEMO.clear()
    return released + merged.release()


_MEMO: dict[tuple, Any] = {}
"""Small results of the map fit kept by their inputs (``_memo``): the casters' bounds, the light cameras."""


def _memo(key: tuple | None, make: Callable[[], Any]) -> Any:
    """``make()``, kept under `key` for later calls (the 32 most recent keys; none kept where `key` is None)."""
    if key is None:
        return make()
    with _LOCK:
        found = _MEMO.get(key)
    if found is None:
        found = make()
        with _LOCK:
            while len(_MEMO) >= 32:
                _MEMO.pop(next(iter(_MEMO)))
            _MEMO[key] = found
    return found


_KEPT: list[tuple[tuple, np.ndarray]] = []
"""Shadow maps kept for reuse, ``(key, maps)``, the most recently used last (``kept_maps``, ``keep_maps``)."""
KEPT_MAPS = 2
"""How many drawn map sets (one frame's maps) are kept for reuse."""
KEPT_BYTES = 256 << 20
"""The most bytes of shadow maps kept for reuse (a set larger than this is drawn every frame: 4096² maps of four
lights are 256 MiB)."""
_REUSE = [True]


def set_map_reuse(enabled: bool) -> bool:
    """Whether ``render`` may reuse a shadow map drawn for an earlier frame when nothing it depends on has changed
    (on by default; off: every frame draws its maps, as a benchmark of the map pass wants); returns the previous
    setting. The maps kept so far stay kept (``release_memory`` frees them)."""
    previous = _REUSE[0]
    _REUSE[0] = bool(enabled)
    return previous


def casters_key(item: SceneItem, cull: bool) -> tuple | None:
    """What a shadow map of one placed mesh depends on besides the light's camera: fingerprints of the bytes of its
    vertices and faces (``raster.shadow.fingerprint``, ~0.1 ms for 10⁵ faces: a vertex array changed in place,
    which a ``Mesh(copy=False)`` would allow, changes the key too), its modeling transform and whether back faces
    are skipped; None where maps are not reused (``set_map_reuse``)."""
    if not _REUSE[0]:
        return None
    from frustum.raster import shadow

    mesh = item.mesh
    return (
        int(shadow.fingerprint(_words(mesh.vertices), np.uint64(mesh.vertices.dtype.itemsize))),
        int(shadow.fingerprint(_words(mesh.faces), np.uint64(mesh.faces.dtype.itemsize))),
        mesh.vertices.shape,
        mesh.faces.shape,
        np.asarray(item.world_from_model, dtype=np.float64).tobytes(),
        bool(cull),
    )


def _words(array: np.ndarray) -> np.ndarray:
    """The bytes of `array` as (n,) uint64 words, the last one zero-padded (a view where the size allows)."""
    data = np.ascontiguousarray(array).reshape(-1).view(np.uint8)
    whole = data.size // 8 * 8
    if whole == data.size and data.ctypes.data % 8 == 0:
        return data.view(np.uint64)
    words = np.zeros(-(-data.size // 8), dtype=np.uint64)
    words.view(np.uint8)[: data.size] = data
    return words


def map_key(casters: tuple | None, cameras: list[Camera], records: np.ndarray) -> tuple | None:
    """The key of one frame's map set: the casters' key (``casters_key``) and each light camera's matrices, size
    and record; None where maps are not reused."""
    if casters is None:
        return None
    lights = tuple((np.asarray(c.clip_from_world, dtype=np.float64).tobytes(), c.width, c.height) for c in cameras)
    return casters, lights, records.tobytes()


def kept_maps(key: tuple | None, shape: tuple[int, ...]) -> np.ndarray | None:
    """The map set drawn earlier under `key` (``keep_maps``), or None. The caller holds it alone until it hands it
    back with ``keep_maps`` (a frame drawn meanwhile on another thread with the same key draws its own), so a set
    in use is never evicted to the work-array pool."""
    if key is None:
        return None
    with _LOCK:
        for at, (kept, maps) in enumerate(_KEPT):
            if kept == key and maps.shape == shape:
                del _KEPT[at]
                return maps
    return None


def keep_maps(key: tuple | None, maps: np.ndarray) -> None:
    """Keep the map set `maps` drawn (or taken with ``kept_maps``) under `key` for later frames, the most recently
    used last; the least recently used set beyond ``KEPT_MAPS`` sets or ``KEPT_BYTES`` goes back to the work-array
    pool (as does one kept under the same key meanwhile). Without a key (reuse off) or too large, `maps` goes
    straight back to the pool."""
    if key is None or maps.nbytes > KEPT_BYTES:
        give_back(maps)
        return
    with _LOCK:
        evicted = [m for kept, m in _KEPT if kept == key]
        _KEPT[:] = [(kept, m) for kept, m in _KEPT if kept != key]
        _KEPT.append((key, maps))
        while len(_KEPT) > KEPT_MAPS or sum(m.nbytes for _, m in _KEPT) > KEPT_BYTES:
            evicted.append(_KEPT.pop(0)[1])
    give_back(*evicted)


def shadow_lights(scene: Scene) -> tuple[list[int], list[Any]]:
    """The positions among the packed (non-ambient) lights of those that cast shadows, and those lights, in
    ``Scene.world_lights`` order (the order of ``Frame.shadow``'s channels)."""
    rows, casting = [], []
    packed = [light for light in scene.world_lights() if not isinstance(light, AmbientLight)]
    for row, light in enumerate(packed):
        if getattr(light, "cast_shadows", False):
            rows.append(row)
            casting.append(light)
    return rows, casting


def surface_points(
    items: list[SceneItem], drawn: list[tuple[int, np.ndarray, int]], depth: np.ndarray, codes: np.ndarray,
    bary: np.ndarray, normals: bool = True,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """(H, W, 3) float64 world points (NaN where nothing is drawn) and, where `normals`, unit face normals turned
    toward the viewer (else a (1, 1, 3) stand-in), from the depth buffer's codes and weights of the drawn items
    ``(index, world positions, face offset)``."""
    from frustum.raster import shadow

    height, width = depth.shape
    points = take_array((height, width, 3), np.float64)
    points.fill(np.nan)
    facing = take_array((height, width, 3) if normals else (1, 1, 3), np.float64)
    for index, world, offset in drawn:
        item = items[index]
        if item.mesh.face_count == 0:
            continue
        faces = _world_faces(item)
        shadow.surface_points(depth, codes, bary, faces, np.ascontiguousarray(world, dtype=np.float64), offset,
                              points, facing, normals)  # fmt: skip
    return points, facing


def _world_faces(item: SceneItem) -> np.ndarray:
    """The faces counter-clockwise after the modeling transform (corners 1, 2 swapped where det < 0)."""
    faces = np.asarray(item.mesh.faces, dtype=np.int64)
    if np.linalg.det(np.asarray(item.world_from_model, dtype=np.float64)[:3, :3]) < 0.0:
        return np.ascontiguousarray(faces[:, [0, 2, 1]])
    return faces


def draw_depth(item: SceneItem, camera: Camera, depth: np.ndarray, fresh: bool, cull: bool | None = None) -> None:
    """Stages 1–4 of one item into `depth` alone (``raster.shadow.fill_depth_tiles``: no face codes or weights,
    64-pixel tiles): a shadow map, cleared first where `fresh`. Both sides of an open surface; the front faces alone
    of a closed one (``Mesh.is_watertight``: along any ray from outside the first surface met is a front face, so
    the map is the same, for half the fill). `cull`: whether to skip back faces, where the caller knows (items
    merged into one, ``caster_groups``)."""
    from frustum.raster import shadow

    if cull is None:
        cull = bool(item.mesh.is_watertight)
    binned = bin_item(item, camera, cull, tile_bits=TILED_BITS)
    tiling = np.array([1 << TILED_BITS, binned.tiles_x, 0, depth.shape[1], depth.shape[0]], dtype=np.int64)
    shadow.fill_depth_tiles(
        binned.faces, binned.win_int, binned.win_float, binned.tri_int, binned.tri_float, binned.tile_starts,
        binned.tile_entries, tiling, depth, fresh,
    )  # fmt: skip


def caster_groups(casters: list[SceneItem], keys: list[tuple | None]) -> list[tuple[SceneItem, bool]]:
    """The casters as at most two items to fill a map with in one pass each (``merged.merge``): the closed meshes
    (back faces skipped) and the open ones (both sides), each with its culling; a group of one item is that item.
    `keys`: each caster's ``casters_key`` (the merged groups are kept under them)."""
    groups = []
    for cull in (True, False):
        chosen = [(item, key) for item, key in zip(casters, keys, strict=True) if bool(item.mesh.is_watertight) == cull]
        if len(chosen) == 1:
            groups.append((chosen[0][0], cull))
        elif chosen:
            parts = [key for _, key in chosen]
            key = None if any(part is None for part in parts) else ("group", cull, *parts)
            groups.append((merged.merge([item for item, _ in chosen], key).item, cull))
    return groups


def light_fractions(
    scene: Scene, items: list[SceneItem], camera: Camera, options: ShadowOptions, lights: np.ndarray,
    depth: np.ndarray, points: np.ndarray, facing: np.ndarray, where: str,
) -> np.ndarray:  # fmt: skip
    """(H, W, K) float32: the fraction of each packed light (rows of `lights`) reaching each drawn pixel (1 for
    lights that cast no shadow and on the background). The maps are drawn by ``draw_depth``, the renderer's
    depth pass of one item."""
    from frustum.raster import shadow

    height, width = depth.shape
    seen = np.ones((height, width, lights.shape[0]), dtype=np.float32)
    rows, casting = shadow_lights(scene)
    casters = [item for item in items if item.material.opacity >= 1.0 and item.mesh.face_count > 0]
    drawn = depth < 1.0
    if not rows or not casters or not drawn.any():
        return seen
    box = _scene_box(casters)
    if options.method == "ray":
        epsilon = RAY_EPSILON * max(float(np.linalg.norm(box[1] - box[0])), 1e-300)
        origin = points[drawn]
        normal = facing[drawn]
        for channel, light in zip(rows, casting, strict=True):
            direction, t_max = _to_light(light, origin)
            fraction = np.where((normal * direction).sum(axis=1) > 0.0, 1.0, 0.0)
            toward = fraction > 0.0
            start = origin[toward] + epsilon * normal[toward]
            blocked = occluded(scene, start, direction[toward], t_max[toward])
            fraction[np.flatnonzero(toward)[blocked]] = 0.0
            seen[..., channel][drawn] = fraction
        return seen
    size = options.map_size
    cube_count = sum(isinstance(light, PointLight) for light in casting)
    nbytes = (6 * cube_count + len(casting) - cube_count) * size * size * 4 + size * size * 12
    check_memory(
        nbytes,
        where=where,
        cause=f"shadow_map_size = {size} with {len(casting)} shadow-casting light(s), "
        f"{cube_count} of them point lights (a cube of six maps each, {format_bytes(6 * size * size * 4)})",
    )
    seen_points = points[drawn]
    # a light's maps depend on every caster's bytes and transform and on the light cameras alone: kept and reused
    # while those stay (a point or spot light's cameras follow the light and the casters' box, not the view)
    keys = [casters_key(item, bool(item.mesh.is_watertight)) for item in casters]
    every = None if any(key is None for key in keys) else tuple(keys)
    for channel, light in zip(rows, casting, strict=True):
        cameras = _light_cameras(light, seen_points, box, size, options.softness)
        if not cameras:
            continue
        views = np.zeros((len(cameras), shadow.MAP_FIELDS))
        for face, (light_camera, texel) in enumerate(cameras):
            views[face] = map_record(light_camera, texel, light)
        key = map_key(every, [light_camera for light_camera, _ in cameras], views)
        maps = kept_maps(key, (len(cameras), size, size))
        if maps is None:  # all casters in one pass per culling (caster_groups)
            maps = take_array((len(cameras), size, size), np.float32)
            groups = caster_groups(casters, keys)
            for face, (light_camera, _) in enumerate(cameras):
                for number, (item, cull) in enumerate(groups):
                    draw_depth(item, light_camera, maps[face], number == 0, cull)
        shadow.map_visibility(depth, points, facing, maps, views, np.ascontiguousarray(lights[channel]),
                              float(options.softness), seen, channel)  # fmt: skip
        keep_maps(key, maps)
    return seen


def occluded(scene: Scene, origins: np.ndarray, directions: np.ndarray, t_max: np.ndarray) -> np.ndarray:
    """(N,) bool: whether an opaque surface of `scene` meets each ray $origin + t·direction$, 0 <= t < t_max.

    ``Scene.occluded`` (the any-hit query through the scene's BVH). Transparent items cast no shadow: where the
    scene has any, the rays go through a scene of its opaque items alone (whose index is built for the call)."""
    origins = np.ascontiguousarray(origins, dtype=np.float64)
    directions = np.ascontiguousarray(directions, dtype=np.float64)
    t_max = np.ascontiguousarray(t_max, dtype=np.float64)
    if origins.shape[0] == 0:
        return np.zeros(0, dtype=bool)
    if any(item.material.opacity < 1.0 for item in scene.items):
        opaque = Scene()
        for item in scene.items:
            if item.material.opacity >= 1.0:
                opaque.add(item.mesh, item.material, transform=item.world_from_model)
        scene = opaque
    return np.asarray(scene.occluded(origins, directions, t_max), dtype=bool)


def _to_light(light: Any, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions from `points` toward `light` and the distance to it (inf for a directional light)."""
    if isinstance(light, DirectionalLight):
        direction = np.broadcast_to(-np.asarray(light.direction, dtype=np.float64), points.shape)
        return np.ascontiguousarray(direction), np.full(points.shape[0], np.inf)
    offset = np.asarray(light.position, dtype=np.float64) - points
    distance = np.sqrt((offset * offset).sum(axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        direction = offset / distance[:, None]
    return np.nan_to_num(direction), distance


def _scene_box(items: list[SceneItem]) -> np.ndarray:
    """(2, 3): the world-space bounding box of the items' vertices."""
    lows, highs = [], []
    for item in items:
        m = np.asarray(item.world_from_model, dtype=np.float64)
        corners = np.array(np.meshgrid(*item.mesh.bounds.T, indexing="ij")).reshape(3, -1).T
        world = corners @ m[:3, :3].T + m[:3, 3]
        lows.append(world.min(axis=0))
        highs.append(world.max(axis=0))
    return np.array([np.min(lows, axis=0), np.max(highs, axis=0)])


def _up_for(axis: np.ndarray) -> np.ndarray:
    """A view-up vector not parallel to `axis`."""
    return np.array([0.0, 0.0, 1.0]) if abs(axis[1]) > 0.9 else np.array([0.0, 1.0, 0.0])


def _light_cameras(
    light: Any, seen_points: np.ndarray, box: np.ndarray, size: int, softness: float
) -> list[tuple[Camera, float]]:  # fmt: skip
    """The light's map cameras and their texel sizes (world units per texel for an orthographic map; per unit of
    distance for a perspective one)."""
    corners = np.array(np.meshgrid(*box.T, indexing="ij")).reshape(3, -1).T
    reach = (softness + _MARGIN_TEXELS) / size  # filter taps and the normal offset stay on the map
    if isinstance(light, DirectionalLight):
        to_light = -np.asarray(light.direction, dtype=np.float64)
        frame = ViewFrame(np.zeros(3), normal=to_light, up=_up_for(to_light))
        view = frame.matrix[:3, :3]
        # light-view coordinates of the seen points, row by row (no BLAS call: its threads fight the kernels')
        seen = [(seen_points[:, 0] * r[0] + seen_points[:, 1] * r[1]) + seen_points[:, 2] * r[2] for r in view]
        low = np.array([axis.min() for axis in seen])
        high = np.array([axis.max() for axis in seen])
        return [_directional_camera(to_light, low, high, box, size, reach)]
    position = np.asarray(light.position, dtype=np.float64)
    distances = np.linalg.norm(corners - position, axis=1)
    far = float(distances.max()) * 1.01 + 1e-9
    nearest = float(np.linalg.norm(np.clip(position, box[0], box[1]) - position))
    if isinstance(light, SpotLight):
        axis = np.asarray(light.direction, dtype=np.float64)
        half = min(light.outer_angle, math.radians(85.0))
        fovy = 2.0 * math.atan(math.tan(half) * (1.0 + 2.0 * reach))
        frame = ViewFrame(position, normal=-axis, up=_up_for(axis))
        near = _near_plane(nearest, fovy, far)
        return [(Camera(frame, Perspective(fovy, near, far), size, size), 2.0 * math.tan(fovy / 2.0) / size)]
    cameras = []
    fovy = 2.0 * math.atan(1.0 + 2.0 * reach)
    near = _near_plane(nearest, fovy, far)
    for axis in np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=np.float64):
        frame = ViewFrame(position, normal=-axis, up=_up_for(axis))
        cameras.append((Camera(frame, Perspective(fovy, near, far), size, size), 2.0 * math.tan(fovy / 2.0) / size))
    return cameras


def _near_plane(nearest: float, fovy: float, far: float) -> float:
    """The near plane of a square perspective map from a light `nearest` from the casters' box: every caster inside
    the map's pyramid lies beyond it. A point at distance r from the light and angle θ off the map's axis lies at
    depth r·cos θ, and θ reaches the pyramid's corner rays, $tan θ_max = √2 · tan(fovy / 2)$: so
    $near = 0.99 · nearest / √(1 + 2 tan²(fovy / 2))$ (at least $10⁻³ · far$)."""
    return max(0.99 * nearest / math.sqrt(1.0 + 2.0 * math.tan(fovy / 2.0) ** 2), 1e-3 * far)


def _directional_camera(
    to_light: np.ndarray, low: np.ndarray, high: np.ndarray, box: np.ndarray, size: int, reach: float,
    frame: ViewFrame | None = None,
) -> tuple[Camera, float]:  # fmt: skip
    """The orthographic map over the light-view box [low, high] of the receivers (``_light_cameras``), deep enough
    toward the light for the casters' box, widened by `reach` (a fraction of its side) on each side. `frame`: the
    light's view frame at the origin, where the caller has it."""
    if frame is None:
        frame = ViewFrame(np.zeros(3), normal=to_light, up=_up_for(to_light))
    view = frame.matrix[:3, :3]
    corners = np.array(np.meshgrid(*box.T, indexing="ij")).reshape(3, -1).T
    side = float(max(high[0] - low[0], high[1] - low[1]))
    span = float(np.linalg.norm(box[1] - box[0]))
    side = max(side, 1e-9 * max(span, 1.0)) * (1.0 + 2.0 * reach)
    centre = 0.5 * (low + high)
    eye = centre[0] * frame.u + centre[1] * frame.v
    caster_z = float((corners @ view.T)[:, 2].max())
    near, far = -caster_z, -float(low[2])
    pad = 1e-3 * max(far - near, span, 1e-12)
    light_frame = ViewFrame(eye, normal=to_light, up=_up_for(to_light))
    return Camera(light_frame, Orthographic(side, near - pad, far + pad), size, size), side / size


def view_map(
    light: DirectionalLight, world: np.ndarray, camera: Camera, size: int, softness: float,
    casters: tuple | None = None,
) -> tuple[Camera, float] | None:  # fmt: skip
    """The orthographic map of a directional light fitted, before anything is drawn, to what the camera can see
    of one mesh (world vertex positions `world`): the light-view box of the part of the mesh's box inside the
    camera's view volume (their intersection, a convex polytope, clipped exactly), cut down to the light-view box
    of the vertices. (The stage-by-stage path fits its map to the drawn points themselves, ``light_fractions``:
    the one-mesh tile pipeline shades as it draws.) None where the mesh's box misses the view volume. `casters`:
    the mesh's ``casters_key``, where known: the vertices' boxes are then kept for the next frame under it and the
    light's direction (a turntable refits only to the view). The light camera of the same fit is the same
    ``Camera`` (kept by its inputs)."""
    to_light = -np.asarray(light.direction, dtype=np.float64)
    clip = np.asarray(camera.clip_from_world, dtype=np.float64)
    key = None
    if casters is not None:  # the same casters, light and view: the same map camera as last time
        key = ("view_map", casters, to_light.tobytes(), clip.tobytes(), camera.width, camera.height, size, softness)
    return _memo(key, lambda: _view_map(to_light, clip, world, camera, size, softness, casters))


def _view_map(
    to_light: np.ndarray, clip: np.ndarray, world: np.ndarray, camera: Camera, size: int, softness: float,
    casters: tuple | None,
) -> tuple[Camera, float] | None:  # fmt: skip
    """``view_map``'s work."""
    from frustum.raster import shadow

    frame = ViewFrame(np.zeros(3), normal=to_light, up=_up_for(to_light))
    view = frame.matrix[:3, :3]
    points = np.asarray(world)
    if points.dtype not in (np.float32, np.float64) or not points.flags.c_contiguous:
        points = np.ascontiguousarray(points, dtype=np.float64)
    if points.shape[0] == 0:
        return None

    def fit() -> np.ndarray:
        bounds = np.empty((4, 3))
        shadow.fit_points(points, np.ascontiguousarray(view), bounds)  # one pass: the box and the light-view box
        bounds.setflags(write=False)
        return bounds

    bounds = _memo(None if casters is None else ("bounds", casters, to_light.tobytes()), fit)
    box = bounds[:2]
    polytope = _memo(("polytope", box.tobytes(), clip.tobytes()), lambda: _box_in_view(box, camera))
    if polytope.shape[0] == 0:
        return None
    inside = polytope @ view.T
    low = np.maximum(inside.min(axis=0), bounds[2])
    high = np.minimum(inside.max(axis=0), bounds[3])
    if (low > high).any():
        return None
    reach = (softness + _MARGIN_TEXELS) / size
    key = ("camera", to_light.tobytes(), low.tobytes(), high.tobytes(), box.tobytes(), size, reach)
    return _memo(key, lambda: _directional_camera(to_light, low, high, box, size, reach, frame))


def _box_in_view(box: np.ndarray, camera: Camera) -> np.ndarray:
    """(V, 3): the corners of the intersection of the world box `box` (2, 3) with the camera's view volume (empty
    where they do not meet): every face of each solid clipped by the other's planes (Sutherland–Hodgman, in
    Python floats: a few hundred small steps)."""
    clip = np.asarray(camera.clip_from_world, dtype=np.float64)
    cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=np.float64)
    inside = box[0] + cube * (box[1] - box[0])
    planes = np.concatenate([clip[3] + clip[:3], clip[3] - clip[:3]])
    values = (planes[:, :1] * inside[:, 0] + planes[:, 1:2] * inside[:, 1]) + (
        planes[:, 2:3] * inside[:, 2] + planes[:, 3:]
    )  # _clip_polygon's values of each corner (columns) for each plane (rows)
    if (values > 0.0).all():  # the box strictly inside the view volume: the intersection is the box (a turntable)
        return inside
    view_planes = [tuple(plane) for plane in planes]
    box_planes = []
    for axis in range(3):
        low, high = [0.0] * 4, [0.0] * 4
        low[axis], low[3] = 1.0, -float(box[0, axis])
        high[axis], high[3] = -1.0, float(box[1, axis])
        box_planes += [tuple(low), tuple(high)]
    quads = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    box_corners = inside.tolist()
    ndc = np.hstack([2.0 * cube - 1.0, np.ones((8, 1))]) @ np.linalg.inv(clip).T
    view_corners = (ndc[:, :3] / ndc[:, 3:]).tolist()
    found: list = []
    for corners, planes in ((box_corners, view_planes), (view_corners, box_planes)):
        for quad in quads:
            polygon = [corners[k] for k in quad]
            for plane in planes:
                polygon = _clip_polygon(polygon, plane)
                if not polygon:
                    break
            found += polygon
    return np.array(found, dtype=np.float64).reshape(-1, 3)


def _clip_polygon(polygon: list, plane: tuple) -> list:
    """The part of a convex polygon (a list of [x, y, z]) where $plane · (p, 1) ≥ 0$ (Sutherland–Hodgman)."""
    a, b, c, d = plane
    values = [(a * p[0] + b * p[1]) + (c * p[2] + d) for p in polygon]
    kept = []
    for i, p in enumerate(polygon):
        j = (i + 1) % len(polygon)
        if values[i] >= 0.0:
            kept.append(p)
        if (values[i] >= 0.0) != (values[j] >= 0.0):
            t = values[i] / (values[i] - values[j])
            q = polygon[j]
            kept.append([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), p[2] + t * (q[2] - p[2])])
    return kept


def map_record(camera: Camera, texel: float, light: Any) -> np.ndarray:
    """The ``raster.shadow`` map record of one light camera."""
    from frustum.raster import shadow

    record = np.zeros(shadow.MAP_FIELDS)
    record[shadow.M_MATRIX : shadow.M_MATRIX + 16] = (camera.viewport_matrix @ camera.clip_from_world).ravel()
    record[shadow.M_KIND] = shadow.KIND_ORTHOGRAPHIC if camera.projection.parallel else shadow.KIND_PERSPECTIVE
    record[shadow.M_NEAR], record[shadow.M_FAR] = camera.projection.near, camera.projection.far
    record[shadow.M_TEXEL] = texel
    return record
