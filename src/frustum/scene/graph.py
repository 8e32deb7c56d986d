"""The scene graph: a hierarchy of nodes placing geometry with materials, and the lights.

A node's ``transform`` maps its own (model) coordinates into its parent's; the world transform of a node is
the product down the parent chain, $world_from_model = T_root · … · T_parent · T_node$ (column vectors: the
node's own transform is applied first) [HB 9] "Composite Transformations", [HB 11] "Hierarchical Modeling"
(the seed's hierarchical polygon-mesh models). One mesh may hang on many nodes (instancing).

Why one module: the Scene and what it places (nodes, items, volumes, particles, lights, pick and ray queries).
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Iterable, Iterator
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from frustum._arrays import Matrix4, as_matrix, as_scalar, as_vector3, describe
from frustum.errors import FrustumError, GeometryError
from frustum.geometry import Mesh, Polyline
from frustum.scene_rays import RayHits
from frustum.shading import LIGHT_TYPES, Light, Material
from frustum.shading.environment import EnvironmentMap

if TYPE_CHECKING:  # imported where they are used: a scene of meshes and lines never loads these modules
    from frustum.geometry.octree import Octree
    from frustum.geometry.volume import TransferFunction, Volume
    from frustum.simulation import MassSpringSystem, ParticleSystem

__all__ = [
    "PARTICLE_BLENDING",
    "PARTICLE_STYLES",
    "Node",
    "ParticleLayer",
    "Pick",
    "Placed",
    "PointItem",
    "RayHits",
    "Scene",
    "SceneItem",
    "VolumeItem",
]


@functools.cache
def _default_material() -> Material:
    """``Material()``, the material of a node nothing above gives one, built once (it is frozen): the scene's item
    lists are asked for several times a frame, and a Material checks its fields when built."""
    return Material()


def is_octree(value: Any) -> bool:
    """``isinstance(value, Octree)`` by the class's own mark (``Octree.scene_geometry``), so that a scene of meshes
    never imports ``frustum.geometry.octree``."""
    return getattr(type(value), "scene_geometry", None) == "octree"


def _is_points(value: Any) -> bool:
    """A ``PointCloud`` or ``GaussianSplats``, by the class's own mark (``scene_geometry``), without importing
    their modules."""
    return getattr(type(value), "scene_geometry", None) in ("points", "splats")


PARTICLE_STYLES = ("sprites", "points", "streaks")
"""How ``Scene.add_particles`` draws particles: soft round sprites, hard squares, or motion streaks."""
PARTICLE_BLENDING = ("additive", "alpha")
"""How particles combine with what is under them: ``C + α·c`` (fire, sparks) or ``α·c + (1 − α)·C`` (smoke)."""

IDENTITY = np.eye(4)
IDENTITY.flags.writeable = False


class SceneItem(NamedTuple):
    """One placed mesh: $world = world_from_model · model$, drawn with ``material``."""

    mesh: Mesh
    material: Material
    world_from_model: Matrix4


class VolumeItem(NamedTuple):
    """One placed volume (``Scene.add_volume``): drawn by ray casting after the opaque meshes.

    ``clip_planes`` (P, 2, 3) world (point, normal) rows: the side each normal points to is cut away, as
    ``cutaway`` cuts meshes. ``step`` is the sample distance Δ in model units; ``shade`` gradient shading with
    the scene's lights and ``material``'s coefficients (base color from the transfer function); ``sampling``
    where the samples lie along a ray (``VOLUME_SAMPLINGS``).
    """

    volume: Volume
    transfer_function: TransferFunction
    mode: str
    world_from_model: Matrix4
    step: float
    level: float
    shade: bool
    material: Material
    clip_planes: np.ndarray
    sampling: str = "entry"


class Pick(NamedTuple):
    """What ``Scene.pick`` finds: the placed item, the face index in its mesh, the world point and the distance
    from the ray's origin on the near plane."""

    item: SceneItem
    face: int
    point: NDArray[np.float64]
    distance: float


class ParticleLayer(NamedTuple):
    """A particle system drawn over the surfaces (``Scene.add_particles``); particles are in world coordinates."""

    system: ParticleSystem
    style: str
    blending: str


class PointItem(NamedTuple):
    """One placed point cloud or set of Gaussian splats: $world = world_from_model · model$, drawn with
    ``material`` (its color multiplies the points' colors) in ``style`` (``frustum.geometry.points.PointStyle``)."""

    geometry: Any
    material: Material
    world_from_model: Matrix4
    style: Any


class Placed(NamedTuple):
    """A node and its world transform, as ``Scene.walk`` yields them (unpacks as ``node, world_from_model``)."""

    node: Node
    world_from_model: Matrix4

    @property
    def geometry(self) -> Any:
        return self.node.geometry

    @property
    def mesh(self) -> Any:
        return self.node.geometry

    @property
    def material(self) -> Material | None:
        return self.node.material


def modeling_transform(transform: ArrayLike | None, where: str) -> Matrix4:
    if transform is None:
        return IDENTITY
    matrix = as_matrix(transform, "transform", where=where)
    if abs(matrix[3] - (0.0, 0.0, 0.0, 1.0)).max() != 0.0:
        raise FrustumError(
            f"{where}: transform bottom row = {describe(matrix[3])} makes it projective; a modeling transform "
            "is affine (bottom row 0, 0, 0, 1)"
        )
    block = matrix[:3, :3]
    scale = float(np.abs(block).max())
    if scale == 0.0 or abs(float(np.linalg.det(block))) <= 1e-12 * scale**3:
        raise FrustumError(
            f"{where}: transform upper 3x3 = {describe(block)} is singular (determinant 0): it flattens the model "
            "onto a plane, a line or a point, where normals are undefined; give an invertible transform "
            "(no scale factor of 0)"
        )
    matrix.flags.writeable = False
    return matrix


class Node:
    """A scene-graph node: ``Node(name, transform, geometry, material, children)``.

    ``transform`` (4x4 affine, default identity) maps this node's coordinates into its parent's;
    ``geometry`` is a ``Mesh`` or a ``Polyline`` (or None for a pure group); ``material`` None inherits the
    nearest ancestor's (``Material()`` at the top); ``lights`` ride the node (they move with its world transform);
    ``label`` (a non-empty string, or None to inherit the nearest ancestor's) is the semantic class of the meshes,
    point clouds and splat sets at and below the node (``Scene.labels``, ``render(..., buffers=("semantic",))``).
    """

    def __init__(
        self,
        name: str = "",
        transform: ArrayLike | None = None,
        geometry: Mesh | Polyline | None = None,
        material: Material | None = None,
        children: Iterable[Node] = (),
        lights: Iterable[Light] = (),
        *,
        label: str | None = None,
    ) -> None:
        where = f"Node({name!r})"
        if not isinstance(name, str) or "/" in name:
            raise FrustumError(f"{where}: name = {describe(name)} is not a string without '/'; '/' separates paths")
        if label is not None and (not isinstance(label, str) or not label):
            raise FrustumError(
                f"{where}: label = {describe(label)} is not a class name; give a non-empty string such as 'mug', "
                "or None to inherit the parent's"
            )
        if geometry is not None and not (isinstance(geometry, Mesh | Polyline) or is_octree(geometry)
                                         or _is_points(geometry)):  # fmt: skip
            raise FrustumError(
                f"{where}: geometry = {describe(geometry)} is not a Mesh or Polyline; build one with Mesh(vertices, "
                "faces) or a primitive, tessellate a surface, or draw a curve as Polyline(points)"
            )
        if material is not None and not isinstance(material, Material):
            raise FrustumError(f"{where}: material = {describe(material)} is not a Material; build one with Material()")
        self.name = name
        self.transform = modeling_transform(transform, where)
        self.geometry = geometry
        self.material = material
        self.label = label
        self.children: list[Node] = []
        self.lights: list[Light] = []
        self.point_style: Any = None  # a PointCloud's drawing style (``frustum.geometry.points.PointStyle``) or None
        for child in children:
            self.add(child)
        for light in lights:
            self.add_light(light)

    def add(self, child: Node) -> Node:
        """Append `child` (a Node) and return it."""
        if not isinstance(child, Node):
            raise FrustumError(f"Node.add: child = {describe(child)} is not a Node; build one with Node(name, ...)")
        self.children.append(child)
        return child

    def add_light(self, light: Light) -> Node:
        """Attach a light to this node (it moves with the node); returns the node."""
        if not isinstance(light, LIGHT_TYPES):
            raise FrustumError(
                f"Node.add_light: light = {describe(light)} is not a light; give an AmbientLight, DirectionalLight, "
                "PointLight or SpotLight"
            )
        self.lights.append(light)
        return self

    def walk(self, parent_from_world: Matrix4 = IDENTITY) -> Iterator[Placed]:
        """Depth-first, parents before children: every node below and including this one with its world transform."""
        world = parent_from_world @ self.transform
        yield Placed(self, world)
        for child in self.children:
            yield from child.walk(world)

    def find(self, path: str) -> Node:
        """The descendant at ``"name/child/grandchild"`` (relative to this node); raises ``FrustumError`` if none."""
        node = self
        for part in path.strip("/").split("/"):
            matches = [child for child in node.children if child.name == part]
            if not matches:
                names = ", ".join(repr(child.name) for child in node.children) or "none"
                raise FrustumError(f"Node.find: path = {path!r} has no {part!r} under {node.name!r}; children: {names}")
            node = matches[0]
        return node

    def copy(self) -> Node:
        """A deep copy of the hierarchy (meshes and materials are immutable and shared)."""
        children = [c.copy() for c in self.children]
        node = Node(self.name, self.transform, self.geometry, self.material, children, self.lights,
                    label=self.label)
        node.point_style = self.point_style
        return node

    def __repr__(self) -> str:
        if isinstance(self.geometry, Mesh):
            kind = f"{self.geometry.face_count} faces"
        elif is_octree(self.geometry):
            kind = f"octree of depth {self.geometry.depth}"
        elif _is_points(self.geometry):
            kind = repr(self.geometry)
        else:
            kind = "group" if self.geometry is None else f"polyline of {self.geometry.vertex_count} points"
        return f"Node({self.name!r}, {kind}, {len(self.children)} children)"


class Scene:
    """A scene graph with a root node and lights: ``Scene(lights=[light]); node = scene.add(mesh, material=m)``.

    ``scene.items`` lists the placed meshes in drawing order (depth-first). The depth buffer makes the image
    independent of that order except for exactly equal depths (the first drawn wins under the "less" test).
    ``environment`` (an ``EnvironmentMap`` or None): the surroundings, shown where nothing is drawn (when
    ``render`` is given no background) and reflected by materials with $reflectivity > 0$.
    """

    def __init__(self, lights: Iterable[Light] = (), *, environment: EnvironmentMap | None = None) -> None:
        if environment is not None and not isinstance(environment, EnvironmentMap):
            raise FrustumError(
                f"Scene: environment = {describe(environment)} is not an EnvironmentMap; build one with "
                "EnvironmentMap(image) or EnvironmentMap.load(path)"
            )
        self.environment = environment
        self.root = Node("")
        self.particle_layers: list[ParticleLayer] = []
        self.mass_springs: list[tuple[Node, MassSpringSystem]] = []
        self.volumes: list[VolumeItem] = []
        for light in lights:
            self.add_light(light)

    @classmethod
    def from_trimesh(cls, scene_or_mesh: Any, *, resolution: Any = None) -> tuple[Scene, Any]:
        """``(Scene, Camera)`` of a ``trimesh.Scene`` or ``Trimesh``: its graph, visuals and camera
        (``frustum.interop.trimesh.scene_from_trimesh``; without a camera, ``Camera.fit``)."""
        # the adapter lives in the interface layer above the scene (import-linter layers): looked up by name
        return importlib.import_module("frustum.interop.trimesh").scene_from_trimesh(
            scene_or_mesh, resolution=resolution
        )

    @property
    def lights(self) -> list[Light]:
        """The lights attached to the root (world coordinates)."""
        return self.root.lights

    def add_light(self, light: Light, parent: Node | None = None) -> Scene:
        """Add a light at the root, or riding `parent`; returns the scene."""
        (self.root if parent is None else parent).add_light(light)
        return self

    def add(
        self,
        geometry: Mesh | Polyline | Octree | Node,
        material: Material | None = None,
        transform: ArrayLike | None = None,
        *,
        name: str = "",
        parent: Node | str | None = None,
        style: str | None = None,
        point_size: float | None = None,
        radius: float | None = None,
        label: str | None = None,
    ) -> Node:
        """Place `geometry` (a Mesh, a Polyline, a ``PointCloud``, ``GaussianSplats`` or a whole Node subtree) under
        `parent` (default the root); returns the node.

        For a Mesh or Polyline, a new ``Node(name, transform, geometry, material, label=label)`` is made; for a
        Node, `material`, `transform` and `label` must be left out (set them on the node). `label`: the semantic
        class (``Node``; ``Scene.labels``).
        A PointCloud is drawn in `style` ``"square"`` (default), ``"disk"``, ``"sphere"`` or ``"surfel"`` with
        `point_size` pixels or `radius` world units (``frustum.render.points``).
        """
        where = "Scene.add"
        host = self.root if parent is None else self.find(parent) if isinstance(parent, str) else parent
        if isinstance(geometry, Node):
            if material is not None or transform is not None or label is not None:
                raise FrustumError(f"{where}: give material, transform and label on the Node itself, not with a Node")
            return host.add(geometry)
        if _is_points(geometry) or (style, point_size, radius) != (None, None, None):
            from frustum.geometry.points import point_style

            node = Node(name, transform, geometry, material, label=label)
            node.point_style = point_style(geometry, style, point_size, radius, where)
            return host.add(node)
        if not (isinstance(geometry, Mesh | Polyline) or is_octree(geometry)):
            raise FrustumError(
                f"{where}: geometry = {describe(geometry)} is not a Mesh, Polyline or Node; build one with "
                "Mesh(vertices, faces)"
            )
        return host.add(Node(name, transform, geometry, material, label=label))

    def add_volume(
        self,
        volume: Volume,
        transfer_function: TransferFunction | None = None,
        mode: str = "composite",
        transform: ArrayLike | None = None,
        *,
        step: float | None = None,
        level: float | None = None,
        shade: bool | None = None,
        material: Material | None = None,
        clip_planes: Iterable[tuple[ArrayLike, ArrayLike]] = (),
        sampling: str = "entry",
    ) -> VolumeItem:
        """Place a ``Volume`` ($world = transform · model$) to be ray cast by ``render``; returns its record.

        `transfer_function` defaults to the grayscale preset over the data's range; `mode` is one of
        ``VOLUME_MODES``; `step` the sample distance in model units (default half the smallest spacing);
        `level` the isosurface value (default the middle of the data's range); `shade` gradient shading
        (default on for "isosurface" only); `clip_planes` world (point, normal) pairs whose normal side is cut;
        `sampling` where a ray's samples lie: ``"entry"`` (default) the middles of segments Δ from where the ray
        enters the volume, the last one shorter (its opacity corrected for its length), so the samples cover the
        ray's part exactly; ``"near"`` every whole multiple of Δ from the ray's point on the near plane, each
        standing for Δ (a parallel camera's samples then lie on the same planes for every ray, as in VTK's
        fixed-point ray caster).
        """
        from frustum.geometry.volume import VOLUME_MODES, VOLUME_SAMPLINGS, TransferFunction, Volume

        where = "Scene.add_volume"
        if not isinstance(volume, Volume):
            raise GeometryError(f"{where}: volume = {describe(volume)} is not a Volume; build one with Volume(data)")
        low, high = volume.value_range
        if transfer_function is None:
            transfer_function = TransferFunction.preset("grayscale", (low, high) if low < high else (low, low + 1.0))
        elif not isinstance(transfer_function, TransferFunction):
            raise GeometryError(f"{where}: transfer_function = {describe(transfer_function)} is not a "
                                "TransferFunction; build one with TransferFunction(values, colors, opacities)"
                                )  # fmt: skip
        if not isinstance(mode, str) or mode not in VOLUME_MODES:
            raise GeometryError(f"{where}: mode = {describe(mode)} is unknown; expected one of "
                                + ", ".join(repr(m) for m in VOLUME_MODES))  # fmt: skip
        delta = 0.5 * volume.unit_distance if step is None else as_scalar(step, "step", where=where,
                                                                           error=GeometryError)  # fmt: skip
        if not delta > 0.0:
            raise GeometryError(f"{where}: step = {delta!r} is not positive; give a sample distance > 0 (model units)")
        value = 0.5 * (low + high) if level is None else as_scalar(level, "level", where=where, error=GeometryError)
        if shade is not None and not isinstance(shade, bool | np.bool_):
            raise GeometryError(f"{where}: shade = {describe(shade)} is not a bool; give True or False")
        if material is not None and not isinstance(material, Material):
            raise GeometryError(f"{where}: material = {describe(material)} is not a Material")
        if not isinstance(sampling, str) or sampling not in VOLUME_SAMPLINGS:
            raise GeometryError(f"{where}: sampling = {describe(sampling)} is unknown; expected one of "
                                + ", ".join(repr(s) for s in VOLUME_SAMPLINGS))  # fmt: skip
        planes = []
        for index, plane in enumerate(clip_planes):
            try:
                point, normal = plane
            except (TypeError, ValueError):
                raise GeometryError(
                    f"{where}: clip_planes[{index}] = {describe(plane)} is not (point, normal)"
                ) from None
            point = as_vector3(point, f"clip_planes[{index}] point", where=where, error=GeometryError)
            normal = as_vector3(normal, f"clip_planes[{index}] normal", where=where, error=GeometryError)
            if not np.linalg.norm(normal) > 0.0:
                raise GeometryError(f"{where}: clip_planes[{index}] normal = {describe(normal)} has zero length")
            planes.append((point, normal / np.linalg.norm(normal)))
        item = VolumeItem(volume, transfer_function, mode, modeling_transform(transform, where), float(delta), value,
                          mode == "isosurface" if shade is None else bool(shade),
                          Material() if material is None else material,
                          np.array(planes, dtype=np.float64).reshape(-1, 2, 3), sampling)  # fmt: skip
        self.volumes.append(item)
        return item

    def add_particles(self, system: ParticleSystem, *, style: str = "sprites",
                      blending: str = "additive") -> ParticleLayer:  # fmt: skip
        """Draw `system` (a ``ParticleSystem``, world coordinates) as `style` with `blending`; returns its layer.

        Particles are drawn after the opaque surfaces, depth-tested against them without writing depth
        (``frustum.render.particles``); ``frustum.simulate`` steps the system between frames.
        """
        from frustum.simulation import ParticleSystem

        where = "Scene.add_particles"
        if not isinstance(system, ParticleSystem):
            raise FrustumError(f"{where}: system = {describe(system)} is not a ParticleSystem")
        for name, value, valid in (("style", style, PARTICLE_STYLES), ("blending", blending, PARTICLE_BLENDING)):
            if not isinstance(value, str) or value not in valid:
                raise FrustumError(f"{where}: {name} = {describe(value)} is unknown; expected one of "
                                   + ", ".join(repr(v) for v in valid))  # fmt: skip
        layer = ParticleLayer(system, style, blending)
        self.particle_layers.append(layer)
        return layer

    def add_mass_spring(self, system: MassSpringSystem, material: Material | None = None, *, name: str = "",
                        parent: Node | str | None = None) -> Node:  # fmt: skip
        """Place `system`'s current ``mesh`` (cloth, soft body) as a node; ``frustum.simulate`` replaces the
        node's geometry by the new mesh after every frame's steps. Returns the node."""
        from frustum.simulation import MassSpringSystem

        if not isinstance(system, MassSpringSystem):
            raise FrustumError(f"Scene.add_mass_spring: system = {describe(system)} is not a MassSpringSystem")
        node = self.add(system.mesh, material, name=name, parent=parent)
        self.mass_springs.append((node, system))
        return node

    def walk(self) -> Iterator[Placed]:
        """Every node (root excluded) with its ``world_from_model``, depth-first, parents first."""
        iterator = self.root.walk()
        next(iterator)
        yield from iterator

    def find(self, path: str) -> Node:
        """The node at ``"assembly/part"``; raises ``FrustumError`` naming the children there if there is none."""
        return self.root.find(path)

    @property
    def items(self) -> list[SceneItem]:
        """Placed meshes in drawing order, each with its (inherited) material and world transform; a placed
        Octree counts as its cell faces (``Octree.surface``), as the depth buffer draws it."""
        return self._placed(Mesh)

    @property
    def point_clouds(self) -> list[PointItem]:
        """Placed point clouds and Gaussian splats in drawing order, with their styles (``PointItem``)."""
        from frustum.geometry.points import point_style

        result: list[PointItem] = []
        for node, world, material in self._walk_materials():
            if _is_points(node.geometry):
                style = node.point_style or point_style(node.geometry, None, None, None, "Scene.point_clouds")
                result.append(PointItem(node.geometry, material, world, style))
        return result

    def _walk_materials(self) -> Iterator[tuple[Node, Matrix4, Material]]:
        """Every node (root excluded) with its world transform and inherited material, depth-first."""
        top = _default_material() if self.root.material is None else self.root.material
        stack = [(child, IDENTITY, top) for child in reversed(self.root.children)]
        while stack:
            node, parent, inherited = stack.pop()
            world = parent @ node.transform
            material = node.material if node.material is not None else inherited
            yield node, world, material
            stack.extend((child, world, material) for child in reversed(node.children))

    @property
    def labels(self) -> list[str]:
        """The semantic classes of the placed meshes in first-seen order (``items`` order; a node without a label
        inherits its nearest ancestor's), then those of the point clouds and splat sets (``point_clouds`` order)
        not seen among the meshes. Class id $c$ of a label is its 1-based position here; 0 is the background
        (``render(..., buffers=("semantic",))``)."""
        seen: dict[str, None] = {}
        for label in (*self.item_labels(), *self.point_labels()):
            if label is not None:
                seen.setdefault(label)
        return list(seen)

    def item_labels(self) -> list[str | None]:
        """Each item's label (``items`` order), inherited from the nearest labelled ancestor; None where none is."""
        return [label for _, label in self._item_nodes()]

    def item_paths(self) -> list[str]:
        """Each item's node path (``items`` order): the names from the root down, '/'-separated, an unnamed node
        written as ``#i`` (its position among its parent's children), so that ``next`` scenes of
        ``render(..., buffers=("flow",), next=...)`` and datasets match items across scenes."""
        return [path for path, _ in self._item_nodes()]

    def point_labels(self) -> list[str | None]:
        """Each placed point cloud's or splat set's label (``point_clouds`` order), inherited as ``item_labels``."""
        return [label for _, label in self._item_nodes(points=True)]

    def point_paths(self) -> list[str]:
        """Each placed point cloud's or splat set's node path (``point_clouds`` order), written as ``item_paths``."""
        return [path for path, _ in self._item_nodes(points=True)]

    def _item_nodes(self, points: bool = False) -> list[tuple[str, str | None]]:
        """(path, label) of each placed mesh, in ``_placed(Mesh)``'s order (`points`: of each point cloud or splat
        set, in ``point_clouds``' order)."""
        result: list[tuple[str, str | None]] = []

        def visit(node: Node, path: str, inherited: str | None) -> None:
            label = node.label if node.label is not None else inherited
            if _is_points(node.geometry) if points else (isinstance(node.geometry, Mesh) or is_octree(node.geometry)):
                result.append((path, label))
            for i, child in enumerate(node.children):
                visit(child, f"{path}/{child.name or f'#{i}'}".lstrip("/"), label)

        visit(self.root, "", self.root.label)
        return result

    @property
    def polylines(self) -> list[SceneItem]:
        """Placed polylines in drawing order (``SceneItem.mesh`` holds the Polyline)."""
        return self._placed(Polyline)

    @property
    def octrees(self) -> list[SceneItem]:
        """Placed octrees in drawing order (``SceneItem.mesh`` holds the Octree; ``render(..., method="octree")``)."""
        from frustum.geometry.octree import Octree

        return self._placed(Octree)

    def pick(self, camera: Any, x: float, y: float) -> Pick | None:
        """The surface seen at window position (x, y) (``Camera.ray``'s convention: y up, pixel centres at
        half-integers): the item, the face index in its mesh, the world point and the distance along the ray;
        None where the ray meets no mesh.

        All placed meshes are put in world coordinates into one triangle index (a bounding-volume hierarchy,
        ``raster.rays``, built once and kept until the scene's meshes or transforms change; ``intersect`` uses
        it too); the first hit of the ray from the near plane is the nearest triangle with t >= 0.
        """
        from frustum.camera import Camera
        from frustum.raster import rays

        where = "Scene.pick"
        if not isinstance(camera, Camera):
            raise FrustumError(f"{where}: camera = {describe(camera)} is not a Camera; build one with Camera.look_at")
        px = as_scalar(x, "x", where=where, error=FrustumError)
        py = as_scalar(y, "y", where=where, error=FrustumError)
        found = self._triangle_index(where=where)
        if found is None:
            return None
        items, index, starts = found
        ray = camera.ray((px, py))
        hits = rays.closest_hits(index, ray.origin[None], ray.direction[None])
        face = hits.face
        if face[0] < 0:
            return None
        item_index = int(np.searchsorted(starts, face[0], side="right") - 1)
        point = ray.origin + hits.t[0] * ray.direction
        return Pick(items[item_index], int(face[0] - starts[item_index]), point, float(hits.t[0]))

    def intersect(self, origins: Any, directions: Any, fields: Iterable[str] | None = None) -> RayHits:
        """The first surface each ray $origin + t·direction$ (t >= 0) meets: a ``RayHits`` of N rows.

        `origins`, `directions`: (N, 3) or (3,) world coordinates (directions need not be unit length; t is in
        units of their length). Every placed mesh (``Scene.items``) is hit, both sides of every face, through the
        scene's ray index (``raster.rays``: a SAH bounding-volume hierarchy of the world triangles, built on first
        use and kept until the meshes or their transforms change; ``pick``, ``occluded`` and
        ``render(..., method="ray-casting"/"ray-tracing")`` share it). Ties (a ray through an edge shared by two
        faces) go to the lower face number across the items in drawing order. `fields` names the ``RayHits``
        columns to compute (``frustum.scene_rays.RAY_FIELDS``; default all), each in the traversal's own pass;
        the others are None (``fields=("t", "item", "face")`` costs the traversal alone).

        Raises
        ------
        FrustumError
            Origins or directions not finite (N, 3) rows of the same N, a zero direction, or `fields` not names
            of ``RayHits`` columns.
        GeometryError
            The index would exceed the memory budget (``frustum.budgets``).
        """
        from frustum import scene_rays

        return scene_rays.intersect(self, origins, directions, fields)

    def occluded(self, origins: Any, directions: Any, t_max: Any) -> NDArray[np.bool_]:
        """(N,) bool: whether each ray $origin + t·direction$ meets a surface at some 0 <= t < `t_max`.

        `t_max` is a scalar or one value per ray (for a shadow ray from a point P to a light at Q: direction
        Q − P and t_max 1; to a directional light: ``np.inf``). Both sides of every face count. This is the
        any-hit query: the traversal stops at the first surface found, so it is faster than ``intersect``.
        Start shadow rays slightly off the surface (along its normal) so they do not meet it at t = 0.

        Raises
        ------
        FrustumError
            As ``intersect``, or `t_max` not a number >= 0 (NaN included) or not one per ray.
        """
        from frustum import scene_rays

        return scene_rays.occluded(self, origins, directions, t_max)

    def _triangle_index(self, where: str = "Scene.pick") -> tuple[list[SceneItem], Any, np.ndarray] | None:
        """The scene's triangle index, ``(items, index, starts)`` or None (``frustum.scene_rays.triangle_index``)."""
        from frustum import scene_rays

        return scene_rays.triangle_index(self, where)

    def _placed(self, kind: type) -> list[SceneItem]:
        result: list[SceneItem] = []

        def visit(node: Node, world: Matrix4, inherited: Material) -> None:
            world = world @ node.transform
            material = node.material if node.material is not None else inherited
            if isinstance(node.geometry, kind):
                result.append(SceneItem(node.geometry, material, world))
            elif kind is Mesh and is_octree(node.geometry):
                result.append(SceneItem(node.geometry.surface, material, world))
            for child in node.children:
                visit(child, world, material)

        visit(self.root, IDENTITY, _default_material() if self.root.material is None else self.root.material)
        return result

    def world_lights(self) -> list[Light]:
        """Every light in world coordinates (those riding nodes moved by the node's world transform)."""
        lights: list[Light] = []
        for node, world in self.root.walk():
            if node.lights:  # lights at the identity (the root's, usually all of them) need no copy
                identity = world is IDENTITY or np.array_equal(world, IDENTITY)
                lights.extend(node.lights if identity else [light.transformed(world) for light in node.lights])
        return lights

    def __len__(self) -> int:
        return len(self.items)

    def _with_root(self, root: Node) -> Scene:
        scene = Scene()
        scene.root = root
        scene.particle_layers = list(self.particle_layers)
        scene.volumes = list(self.volumes)
        scene.environment = self.environment
        return scene
