"""pyrender's ``OffscreenRenderer``, drawn by frustum: the same call, the same arrays, no OpenGL context.

    from frustum.interop.pyrender import OffscreenRenderer, RenderFlags   # was: from pyrender import ...
    renderer = OffscreenRenderer(640, 480)
    color, depth = renderer.render(scene)        # a pyrender.Scene, unchanged

``render`` reads the ``pyrender.Scene`` (pyrender is imported only to read its objects: that import needs no
display, and pyrender itself need not be able to render) and draws it with ``frustum.render``:

- mesh nodes and their primitives (positions, normals, indices, ``COLOR_0``, ``TEXCOORD_0``, ``poses`` for
  instancing), each placed at ``scene.get_pose(node)`` (times the instance pose);
- ``MetallicRoughnessMaterial``: ``baseColorFactor``, ``baseColorTexture``, ``metallicFactor``,
  ``roughnessFactor``, ``emissiveFactor``, ``doubleSided``;
- the main camera: ``PerspectiveCamera`` (``zfar=None`` gets a far plane just behind the scene),
  ``IntrinsicsCamera`` (fx, fy, cx, cy in pixels, top-left pixel centre at (0.5, 0.5):
  ``Camera.from_intrinsics``), ``OrthographicCamera`` (``ymag``; pyrender sets ``xmag`` from the aspect);
  poses camera-to-world in OpenGL axes;
- directional, point and spot lights with their intensities, ``ambient_light``, ``bg_color``.

Colour is pyrender's light model evaluated per pixel on frustum's buffers (``interop.pyrender_shading``: its
BRDF, its light units, its gamma 1/2.2). Outputs as pyrender's: ``color`` (H, W, 3) uint8 (RGBA: (H, W, 4)),
``depth`` (H, W) float32, the metric distance along the viewing axis, 0 where nothing is drawn (also for
orthographic cameras, where pyrender 0.1.45 linearizes the depth as if the projection were perspective).

Differences that remain: frustum does not multisample (pyrender draws colour with 4× MSAA, so silhouette
pixels blend there, and reads depth from sample 0 at (0.375, 0.875) of the pixel), samples textures without
mipmaps, and lights the back faces it draws (``SKIP_CULL_FACES``, ``doubleSided``) with the normal turned toward
the viewer, where pyrender keeps the front face's normal. Everything pyrender draws that frustum cannot is a
``FrustumError`` naming the feature (normal, occlusion, emissive and metallic–roughness textures, alpha
blending and masking, wireframes, points and lines, specular–glossiness materials, the normal-drawing flags).

References: pyrender 0.1.45 ``renderer.py``, ``camera.py``, ``shaders/mesh.frag``; docs/how-to/headless.md.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from frustum._arrays import describe
from frustum.camera import Camera, ViewFrame
from frustum.camera_conventions import view_from_pose
from frustum.errors import FrustumError
from frustum.geometry import Mesh
from frustum.interop import pyrender_shading
from frustum.projection import Orthographic
from frustum.scene import Node, Scene
from frustum.shading import DirectionalLight, Material, PointLight, SpotLight

__all__ = ["OffscreenRenderer", "RenderFlags"]


class RenderFlags:
    """pyrender's render flags, the same bits (``pyrender.RenderFlags`` values work too); combine with ``|``."""

    NONE = 0
    DEPTH_ONLY = 1
    OFFSCREEN = 2
    FLIP_WIREFRAME = 4
    ALL_WIREFRAME = 8
    ALL_SOLID = 16
    SHADOWS_DIRECTIONAL = 32
    SHADOWS_POINT = 64
    SHADOWS_SPOT = 128
    SHADOWS_ALL = 32 | 64 | 128
    VERTEX_NORMALS = 256
    FACE_NORMALS = 512
    SKIP_CULL_FACES = 1024
    RGBA = 2048
    FLAT = 4096
    SEG = 8192


_KNOWN_FLAGS = 16383
_UNSUPPORTED_FLAGS = {
    RenderFlags.FLIP_WIREFRAME: "FLIP_WIREFRAME (wireframes)",
    RenderFlags.ALL_WIREFRAME: "ALL_WIREFRAME (wireframes)",
    RenderFlags.VERTEX_NORMALS: "VERTEX_NORMALS (drawing normals as lines)",
    RenderFlags.FACE_NORMALS: "FACE_NORMALS (drawing normals as lines)",
}
_TRIANGLES = 4  # GLTF.TRIANGLES
_PRIMITIVE_MODES = {0: "POINTS", 1: "LINES", 2: "LINE_LOOP", 3: "LINE_STRIP", 5: "TRIANGLE_STRIP", 6: "TRIANGLE_FAN"}
_UNSUPPORTED_TEXTURES = ("normalTexture", "occlusionTexture", "emissiveTexture", "metallicRoughnessTexture")
# Far plane behind the scene for a perspective camera with zfar=None: the farthest bounding-box corner along the
# view axis times this (depth precision stays that of a finite frustum around the scene).
_FAR_MARGIN = 1.05


def _pyrender() -> Any:
    """The pyrender module, or a FrustumError naming the extra that installs it."""
    try:
        import pyrender
    except ImportError as error:
        raise FrustumError(
            f"frustum.interop.pyrender reads pyrender scenes and needs pyrender ({error}); install it with "
            "pip install 'frustum[pyrender]' (pyrender itself need not be able to render: no display or GPU)"
        ) from None
    return pyrender


def _record(material: Any, primitive: Any) -> np.ndarray:
    """The pixel shader's row of one placed primitive (``pyrender_shading.shade``'s `items`)."""
    if primitive.color_0 is not None:
        mode = pyrender_shading.MODE_VERTEX
    elif material.baseColorTexture is not None:
        mode = pyrender_shading.MODE_TEXTURED
    else:
        mode = pyrender_shading.MODE_CONSTANT
    return np.array([
        *np.asarray(material.baseColorFactor, dtype=np.float64)[:3], float(material.metallicFactor),
        float(material.roughnessFactor), *np.asarray(material.emissiveFactor, dtype=np.float64)[:3], mode,
        1.0 if primitive.normals is not None else 0.0,
    ])  # fmt: skip


def _item_table(items: list[tuple[Any, np.ndarray]]) -> np.ndarray:
    return np.array([record for _, record in items]).reshape(-1, 10)


class OffscreenRenderer:
    """A drop-in for ``pyrender.OffscreenRenderer``: ``render(scene, flags, seg_node_map)`` and ``delete()``.

    Parameters
    ----------
    viewport_width, viewport_height : int
        Image size in pixels.
    point_size : float
        Accepted for pyrender's signature; point primitives are not drawn (a FrustumError names them).
    """

    def __init__(self, viewport_width: int, viewport_height: int, point_size: float = 1.0) -> None:
        self.viewport_width = viewport_width
        self.viewport_height = viewport_height
        self.point_size = point_size
        self._deleted = False
        self._meshes: dict[int, tuple[Any, tuple, Mesh, Material, Material]] = {}

    @property
    def viewport_width(self) -> int:
        return self._width

    @viewport_width.setter
    def viewport_width(self, value: int) -> None:
        self._width = _size(value, "viewport_width")

    @property
    def viewport_height(self) -> int:
        return self._height

    @viewport_height.setter
    def viewport_height(self, value: int) -> None:
        self._height = _size(value, "viewport_height")

    def delete(self) -> None:
        """Free what the renderer holds (the converted meshes); rendering afterwards is an error, as in pyrender."""
        self._meshes.clear()
        self._deleted = True

    def render(self, scene: Any, flags: int = RenderFlags.NONE, seg_node_map: dict | None = None) -> Any:
        """Render a ``pyrender.Scene``: ``(color, depth)``, or ``depth`` alone with ``RenderFlags.DEPTH_ONLY``.

        ``color`` (H, W, 3) uint8, (H, W, 4) with ``RGBA``; ``depth`` (H, W) float32 metric z-distance, 0 where
        nothing is drawn. ``FLAT``: the base colour without lighting. ``SEG``: only the nodes in `seg_node_map`
        are drawn, each in its colour (an int gray level or an (r, g, b) of 0–255) on black. ``SKIP_CULL_FACES``:
        back faces are drawn. ``SHADOWS_DIRECTIONAL`` / ``SHADOWS_SPOT`` / ``SHADOWS_POINT`` (``SHADOWS_ALL``):
        frustum's shadow maps for those lights (pyrender itself has no point-light shadows).

        Raises
        ------
        FrustumError
            For a scene feature or flag frustum does not draw (the message names it), a scene without a camera,
            or a renderer already deleted.
        """
        if self._deleted:
            raise FrustumError("OffscreenRenderer.render: the renderer was deleted; create a new OffscreenRenderer")
        pyrender = _pyrender()
        where = "OffscreenRenderer.render"
        if not isinstance(scene, pyrender.Scene):
            raise FrustumError(f"{where}: scene = {describe(scene)} is not a pyrender.Scene")
        flags = _check_flags(flags, where)
        seg = bool(flags & RenderFlags.SEG)
        if seg_node_map is None:
            seg_node_map = {}
        lit = not (flags & (RenderFlags.DEPTH_ONLY | RenderFlags.FLAT | RenderFlags.SEG))
        built, items, cull = self._scene(pyrender, scene, flags, seg_node_map if seg else None, lit, where)
        camera = _camera(pyrender, scene, built, self._width, self._height, where)
        shadow_kinds = _shadow_kinds(flags) if lit else ()
        lights = _lights(pyrender, scene, built, shadow_kinds)
        shadows = any(light.cast_shadows for light in built.lights)
        from frustum.render import render

        buffers: tuple[str, ...] = ()
        if lit:
            buffers = ("object_id", "normals", "shadow") if shadows else ("object_id", "normals")
        elif seg:
            buffers = ("object_id",)
        background = (0.0, 0.0, 0.0, 1.0) if seg else np.clip(np.asarray(scene.bg_color, dtype=np.float64), 0, 1)
        frame = render(built, camera, shading="none", buffers=buffers, cull_back_faces=cull, background=background,
                       shadows=True if shadows else None)  # fmt: skip
        color, depth = pyrender_shading.shade(frame, camera, _item_table(items), [shading for _, shading in lights],
                                              scene.ambient_light, lit)  # fmt: skip
        if flags & RenderFlags.DEPTH_ONLY:
            return depth
        if seg:
            color[:, :, :3] = _segmentation(frame.object_id, items, seg_node_map, where)
        if not flags & RenderFlags.RGBA:
            return np.ascontiguousarray(color[:, :, :3]), depth
        return color, depth

    # --- reading the scene ----------------------------------------------------------------------------------

    def _scene(self, pyrender: Any, scene: Any, flags: int, seg_nodes: dict | None, lit: bool,
               where: str) -> tuple[Scene, list[tuple[Any, np.ndarray]], bool]:  # fmt: skip
        """frustum's Scene of the visible mesh nodes (only `seg_nodes` for SEG), the per-item records in
        ``Scene.items`` order, and whether back faces are culled."""
        built = Scene()
        items: list[tuple[Any, np.ndarray]] = []
        double_sided: set[bool] = set()
        for node in sorted(scene.mesh_nodes, key=_node_order):
            mesh = node.mesh
            if not mesh.is_visible or (seg_nodes is not None and node not in seg_nodes):
                continue
            pose = scene.get_pose(node)
            for primitive in mesh.primitives:
                frustum_mesh, material_lit, material_flat, record = self._primitive(pyrender, primitive, flags, where)
                double_sided.add(bool(primitive.material.doubleSided))
                material = material_lit if lit else material_flat
                instances = [None] if primitive.poses is None else list(primitive.poses)
                for instance in instances:
                    world = pose if instance is None else pose @ np.asarray(instance, dtype=np.float64)
                    built.add(Node(node.name or "", world, frustum_mesh, material))
                    items.append((node, record))
        if flags & RenderFlags.SKIP_CULL_FACES:
            return built, items, False
        if len(double_sided) > 1:
            raise FrustumError(
                f"{where}: some primitives are doubleSided and others are not; frustum culls back faces for a whole "
                "frame: make them agree or pass RenderFlags.SKIP_CULL_FACES"
            )
        return built, items, double_sided != {True}

    def _primitive(
        self, pyrender: Any, primitive: Any, flags: int, where: str
    ) -> tuple[Mesh, Material, Material, np.ndarray]:
        """The frustum Mesh, its lit and flat Materials and the shading record of a primitive (cached while its
        arrays and material factors stay the same objects and values)."""
        material = primitive.material
        _check_primitive(pyrender, primitive, flags, where)
        key = (
            id(primitive.positions), id(primitive.indices), id(primitive.normals), id(primitive.color_0),
            id(primitive.texcoord_0), id(material), _material_key(material),
        )  # fmt: skip
        cached = self._meshes.get(id(primitive))
        if cached is not None and cached[0] is primitive and cached[1] == key:
            return cached[2], cached[3], cached[4], _record(material, primitive)
        positions = np.asarray(primitive.positions, dtype=np.float64)
        if primitive.indices is None:
            faces = np.arange(len(positions)).reshape(-1, 3)
        else:
            faces = np.asarray(primitive.indices, dtype=np.int64).reshape(-1, 3)
        colors = None
        if primitive.color_0 is not None:
            colors = np.asarray(primitive.color_0, dtype=np.float64)
            if colors.shape[1] == 4 and (colors[:, 3] < 1.0).any():
                raise FrustumError(
                    f"{where}: a primitive's COLOR_0 has alpha < 1 (transparency by vertex colour); frustum draws "
                    "these primitives opaque only"
                )
            colors = colors[:, :3]
        uvs = None if primitive.texcoord_0 is None else np.asarray(primitive.texcoord_0, dtype=np.float64)[:, :2]
        mesh = Mesh(positions, faces, vertex_normals=_normals(primitive.normals, positions, faces, where), uvs=uvs,
                    vertex_colors=colors)  # fmt: skip
        texture = None
        if material.baseColorTexture is not None:
            if uvs is None:
                raise FrustumError(f"{where}: a material has a baseColorTexture but its primitive has no TEXCOORD_0")
            texture = _texture_texels(material.baseColorTexture)
        if texture is not None and colors is not None:
            raise FrustumError(f"{where}: a primitive has both COLOR_0 and a baseColorTexture; frustum's "
                               "OffscreenRenderer lights one or the other (FLAT draws both)")  # fmt: skip
        factor = np.clip(np.asarray(material.baseColorFactor, dtype=np.float64)[:3], 0.0, 1.0)
        # lit: frustum draws the texture's own bytes (or the vertex colours) in white; the shading step decodes
        # them from sRGB after the bilinear lookup, as pyrender's shader does, and multiplies in the factor
        lit = Material(color=(1.0, 1.0, 1.0), texture=texture)
        flat = Material(color=factor, texture=texture)
        self._meshes[id(primitive)] = (primitive, key, mesh, lit, flat)
        return mesh, lit, flat, _record(material, primitive)


def _size(value: Any, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value <= 0:
        raise FrustumError(f"OffscreenRenderer: {name} = {describe(value)} is not a positive integer (pixels)")
    return int(value)


def _node_order(node: Any) -> tuple:
    """A stable drawing order for pyrender's set of mesh nodes (depth ties only): by name, then creation."""
    return (node.name or "", id(node))


def _check_flags(flags: Any, where: str) -> int:
    if isinstance(flags, bool) or not isinstance(flags, int | np.integer) or not 0 <= flags <= _KNOWN_FLAGS:
        raise FrustumError(f"{where}: flags = {describe(flags)} is not a combination of RenderFlags")
    for bit, name in _UNSUPPORTED_FLAGS.items():
        if flags & bit:
            raise FrustumError(f"{where}: RenderFlags.{name} is not drawn by frustum's OffscreenRenderer")
    return int(flags)


def _shadow_kinds(flags: int) -> tuple[type, ...]:
    kinds: list[type] = []
    if flags & RenderFlags.SHADOWS_DIRECTIONAL:
        kinds.append(DirectionalLight)
    if flags & RenderFlags.SHADOWS_SPOT:
        kinds.append(SpotLight)
    if flags & RenderFlags.SHADOWS_POINT:
        kinds.append(PointLight)
    return tuple(kinds)


def _material_key(material: Any) -> tuple:
    return (
        tuple(np.asarray(material.baseColorFactor, dtype=float).tolist()), id(material.baseColorTexture),
        float(material.metallicFactor), float(material.roughnessFactor),
        tuple(np.asarray(material.emissiveFactor, dtype=float).tolist()), material.alphaMode, material.doubleSided,
        material.wireframe,
    )  # fmt: skip


def _check_primitive(pyrender: Any, primitive: Any, flags: int, where: str) -> None:
    """A FrustumError naming the first feature of `primitive` frustum does not draw."""
    if primitive.mode != _TRIANGLES:
        name = _PRIMITIVE_MODES.get(primitive.mode, str(primitive.mode))
        raise FrustumError(f"{where}: a primitive has mode {name}; frustum's OffscreenRenderer draws TRIANGLES only")
    material = primitive.material
    if not isinstance(material, pyrender.MetallicRoughnessMaterial):
        raise FrustumError(
            f"{where}: material = {type(material).__name__} is not drawn (pyrender 0.1.45 leaves specular-glossiness "
            "materials black too); use a MetallicRoughnessMaterial"
        )
    for name in _UNSUPPORTED_TEXTURES:
        if getattr(material, name, None) is not None:
            raise FrustumError(f"{where}: the material's {name} is not drawn by frustum's OffscreenRenderer; "
                               "remove it (baseColorTexture is drawn)")  # fmt: skip
    if material.wireframe and not flags & RenderFlags.ALL_SOLID:
        raise FrustumError(f"{where}: a material has wireframe=True; wireframes are not drawn (RenderFlags.ALL_SOLID "
                           "draws it solid)")  # fmt: skip
    mode = material.alphaMode or "OPAQUE"
    if mode == "MASK":
        raise FrustumError(f"{where}: a material has alphaMode 'MASK' (alpha cutoff), which is not drawn")
    if mode == "BLEND" and float(np.asarray(material.baseColorFactor)[3]) < 1.0:
        raise FrustumError(
            f"{where}: a material has alphaMode 'BLEND' with baseColorFactor alpha "
            f"{float(np.asarray(material.baseColorFactor)[3])!r} < 1 (transparency); frustum's OffscreenRenderer "
            "draws opaque materials only"
        )


def _normals(normals: Any, positions: np.ndarray, faces: np.ndarray, where: str) -> np.ndarray | None:
    """The primitive's normals; a zero normal on a vertex that no face of nonzero area uses (trimesh gives those
    to unreferenced vertices and to vertices of degenerate faces) becomes +z, which draws nothing; one on a drawn
    vertex is an error (pyrender's shader would divide by zero there)."""
    if normals is None:
        return None
    normals = np.asarray(normals, dtype=np.float64)
    zero = ~(normals != 0.0).any(axis=1)
    if zero.any():
        corners = positions[faces]
        area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
        used = np.zeros(len(normals), dtype=bool)
        used[faces[area > 0.0].ravel()] = True
        drawn = np.flatnonzero(zero & used)
        if drawn.size:
            raise FrustumError(f"{where}: a primitive's normal {int(drawn[0])} is zero on a vertex its faces use; "
                               "give nonzero normals")  # fmt: skip
        normals = normals.copy()
        normals[zero] = (0.0, 0.0, 1.0)
    return normals


def _texture_texels(texture: Any) -> np.ndarray:
    """A texture's source as (H, W, 4) float64 in [0, 1] (pyrender keeps uint8 or float sources)."""
    source = np.asarray(texture.source)
    texels = source.astype(np.float64) / 255.0 if source.dtype == np.uint8 else source.astype(np.float64)
    if texels.ndim == 2:
        texels = texels[:, :, None]
    if texels.shape[2] == 1:
        texels = np.repeat(texels, 3, axis=2)
    if texels.shape[2] == 3:
        texels = np.concatenate([texels, np.ones((*texels.shape[:2], 1))], axis=2)
    if (texels[:, :, 3] < 1.0).any():
        raise FrustumError("OffscreenRenderer.render: a baseColorTexture has alpha < 1 (transparency); frustum's "
                           "OffscreenRenderer draws opaque textures only")  # fmt: skip
    return np.clip(texels[:, :, :4], 0.0, 1.0)


def _camera(pyrender: Any, scene: Any, built: Scene, width: int, height: int, where: str) -> Camera:
    """frustum's Camera for pyrender's main camera node (camera-to-world pose, OpenGL axes)."""
    node = scene.main_camera_node
    if node is None:
        raise FrustumError(f"{where}: the scene has no camera; add one with scene.add(camera, pose=...)")
    lens = node.camera
    pose = scene.get_pose(node)
    near = float(lens.znear)
    if isinstance(lens, pyrender.IntrinsicsCamera):
        k = [[lens.fx, 0.0, lens.cx], [0.0, lens.fy, lens.cy], [0.0, 0.0, 1.0]]
        far = float(lens.zfar) if lens.zfar is not None else _far(built, pose, near)
        return Camera.from_intrinsics(k, width, height, camera_to_world=pose, convention="opengl", near=near, far=far)
    if isinstance(lens, pyrender.PerspectiveCamera):
        aspect = width / height if lens.aspectRatio is None else float(lens.aspectRatio)
        t = math.tan(float(lens.yfov) / 2.0)
        fx, fy = width / (2.0 * aspect * t), height / (2.0 * t)
        k = [[fx, 0.0, width / 2.0], [0.0, fy, height / 2.0], [0.0, 0.0, 1.0]]
        far = float(lens.zfar) if lens.zfar is not None else _far(built, pose, near)
        return Camera.from_intrinsics(k, width, height, camera_to_world=pose, convention="opengl", near=near, far=far)
    if isinstance(lens, pyrender.OrthographicCamera):
        eye, _, v, n = view_from_pose(None, pose, "opengl", where)
        frame = ViewFrame(eye, normal=n, up=v)
        return Camera(frame, Orthographic(2.0 * float(lens.ymag), near, float(lens.zfar)), width, height)
    raise FrustumError(f"{where}: camera = {type(lens).__name__} is not a PerspectiveCamera, IntrinsicsCamera or "
                       "OrthographicCamera")  # fmt: skip


def _far(built: Scene, pose: np.ndarray, near: float) -> float:
    """A far plane just behind every placed vertex (pyrender's zfar=None is an infinite far plane)."""
    axis, eye = -pose[:3, 2] / np.linalg.norm(pose[:3, 2]), pose[:3, 3]
    farthest = near
    for item in built.items:
        low, high = item.mesh.vertices.min(axis=0), item.mesh.vertices.max(axis=0)
        corners = np.array([[x, y, z, 1.0] for x in (low[0], high[0]) for y in (low[1], high[1])
                            for z in (low[2], high[2])])  # fmt: skip
        world = corners @ item.world_from_model.T
        farthest = max(farthest, float(((world[:, :3] - eye) @ axis).max()))
    return max(farthest * _FAR_MARGIN, 2.0 * near)


def _lights(pyrender: Any, scene: Any, built: Scene, shadow_kinds: tuple[type, ...]) -> list[tuple]:
    """pyrender's lights in world coordinates, each as (frustum light, shading tuple); the frustum lights (which
    only cast the shadow maps: the colour is pyrender's model) are added to `built`."""
    lights = []
    columns = 0  # the shadow buffer holds the shadow-casting lights in order
    for node in sorted(scene.light_nodes, key=_node_order):
        light, pose = node.light, scene.get_pose(node)
        position, direction = pose[:3, 3], -pose[:3, 2] / np.linalg.norm(pose[:3, 2])
        energy = np.asarray(light.color, dtype=np.float64)[:3] * float(light.intensity)
        if isinstance(light, pyrender.SpotLight):
            cos_inner, cos_outer = math.cos(light.innerConeAngle), math.cos(light.outerConeAngle)
            scale = 1.0 / max(0.001, cos_inner - cos_outer)
            shading = (pyrender_shading.LIGHT_SPOT, energy, position, direction, scale, -cos_outer * scale)
            outer = min(float(light.outerConeAngle), math.pi / 2 - 1e-6)
            ours: Any = SpotLight(position, direction, inner_angle=min(float(light.innerConeAngle), outer),
                                  outer_angle=outer, cast_shadows=SpotLight in shadow_kinds)  # fmt: skip
        elif isinstance(light, pyrender.PointLight):
            shading = (pyrender_shading.LIGHT_POINT, energy, position, direction, 0.0, 0.0)
            ours = PointLight(position, cast_shadows=PointLight in shadow_kinds)
        else:
            shading = (pyrender_shading.LIGHT_DIRECTIONAL, energy, position, direction, 0.0, 0.0)
            ours = DirectionalLight(direction, cast_shadows=DirectionalLight in shadow_kinds)
        built.add_light(ours)
        column = -1
        if ours.cast_shadows:
            column, columns = columns, columns + 1
        lights.append((ours, (*shading, column)))
    return lights


def _segmentation(object_id: np.ndarray, items: list[tuple[Any, np.ndarray]], seg_node_map: dict,
                  where: str) -> np.ndarray:  # fmt: skip
    """(H, W, 3) uint8: each item's node colour from `seg_node_map` (a gray int or (r, g, b)), black elsewhere."""
    table = np.zeros((len(items) + 1, 3), dtype=np.uint8)
    for index, (node, _) in enumerate(items):
        value = seg_node_map[node]
        rgb = np.repeat(value, 3) if np.ndim(value) == 0 else np.asarray(value)[:3]
        rgb = np.asarray(rgb, dtype=np.float64)
        if rgb.shape != (3,) or not np.isfinite(rgb).all() or (rgb < 0).any() or (rgb > 255).any():
            raise FrustumError(f"{where}: seg_node_map colour {describe(value)} is not a gray level or (r, g, b) "
                               "in 0–255")  # fmt: skip
        table[index] = np.floor(rgb + 0.5).astype(np.uint8)
    return table[np.where(object_id >= 0, object_id, len(items))]
