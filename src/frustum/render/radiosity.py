"""The radiosity lighting model: diffuse light bouncing between surfaces, by hemicubes and progressive refinement.

Every surface is split into small patches k with area A_k, reflectance ρ_k and emission E_k; the light leaving
each patch (its radiosity $B_k$, uniform over the patch) obeys the radiosity equation [HB "Radiosity Lighting
Model"]

$$B_k = E_k + ρ_k Σ_j B_j F_jk$$

with the form factor $F_jk$, the fraction of the light leaving patch j that arrives at patch k. Reciprocity
$A_j F_jk = A_k F_kj$ gives the shooting form $B_k += ρ_k ΔB_j F_jk A_j / A_k$.

* **Form factors by ray casting** (``form_factors="ray"``, the default; Wallace, Elmquist & Haines 1989): at
  each receiving patch's centre, the exact point-to-area form factor to the shooting group, by Lambert's contour
  formula [Baum, Rushmeier & Winget 1989] (``raster.form_factors``; over a flat piece's boundary edges alone, the
  shared edges cancelling), times whether a shadow ray reaches each quarter of the group; shot as
  $B_k += ρ_k F_k,group ΔB_group$ with no division by the receiver's area, so a small receiver is as exact as a
  large one. Receivers nearer a group than its size take each member's factor and own unshot radiosity.

* **Form factors by the hemicube** (``form_factors="hemicube"``; Cohen & Greenberg 1985): a half cube of side 2
  centred on the shooting patch, its top face at height 1 along the patch normal, is rasterized face by face (five
  faces: the top and the upper halves of the four sides) with frustum's own depth-buffer kernels
  (``raster.tiles`` / ``raster.triangles`` through the render package's item pass), writing the code of the
  nearest patch into each pixel. Each pixel adds its *delta form factor* to the patch it shows, at (x, y, 1) on
  the top face and at (x, 1, z) on a side face

    $$ΔF = ΔA / (π (x² + y² + 1)²)$$

    $$ΔF = z ΔA / (π (x² + z² + 1)²)$$

    with $ΔA = (2/N)²$, N the hemicube resolution. The delta form factors of the whole hemicube sum to 1 (up to
    the pixel sampling).

* **Progressive refinement** (Cohen, Chen, Wallace & Greenberg 1988): repeatedly shoot the patch with the most
  unshot power ΔB_j A_j: render its hemicube, add $ρ_k ΔB_j F_jk A_j / A_k$ to B_k and to the unshot ΔB_k of
  every patch it sees, and set $ΔB_j = 0$. The residual is the unshot power over the power emitted.
* **Ambient term for display**: the unshot power not yet distributed is spread as an ambient term
  $B_k + ρ_k · R · Σ_j ΔB_j A_j / Σ_j A_j$ with the mean interreflection factor $R = 1 / (1 − ρ_avg)$,
  $ρ_avg = Σ ρ_j A_j / Σ A_j$ (Cohen et al. 1988) — it vanishes as the solution converges.

Units: B is in the same units as the local illumination model's diffuse term. Emitters are faces whose material
has ``emissive`` × ``emission`` > 0 ($E_k = emissive · emission$, which may exceed 1); the scene's positioned
lights shoot first: their direct light on each patch is the depth buffer's diffuse term $ρ_k f_l I_l max(N·L,
0)$ (attenuation and spot cone included), averaged over four points of the patch, each lit when the light's own
depth-buffer view (a cube of six faces for point and spot lights, an orthographic view for directional lights)
shows that patch there. With emission given as radiance, B equals radiance as a path tracer measures it (the
radiosity equation divided by π): no scale between frustum's B and, e.g., Mitsuba's pixel values.

References
----------
[HB] "Radiosity Lighting Model" (the radiosity equation, form factors, the hemicube, progressive refinement).
Cohen & Greenberg, "The Hemi-Cube", SIGGRAPH 1985; Cohen, Chen, Wallace & Greenberg, "A Progressive Refinement
Approach to Fast Radiosity Image Generation", SIGGRAPH 1988; Wallace, Elmquist & Haines, "A Ray Tracing Algorithm
for Progressive Radiosity", SIGGRAPH 1989; Baum, Rushmeier & Winget, "Improving Radiosity Solutions Through the
Use of Analytically Determined Form-Factors", SIGGRAPH 1989.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from frustum._arrays import as_scalar, describe
from frustum.budgets import check_memory, check_operations
from frustum.camera import Camera, ViewFrame
from frustum.errors import FrustumError
from frustum.geometry.mesh import Mesh
from frustum.projection import Frustum, Orthographic
from frustum.scene import Scene, SceneItem
from frustum.shading import DirectionalLight, Material, PointLight, SpotLight
from frustum.shading.light import toward_light

__all__ = [
    "Patches",
    "RadiosityError",
    "RadiosityResult",
    "form_factors",
    "hemicube_delta_form_factors",
    "patches_of",
    "radiosity",
]  # fmt: skip


class RadiosityError(FrustumError):
    """A radiosity request that cannot be solved: bad parameters, no emitters, or over the work budget."""


class Patches(NamedTuple):
    """The scene's surfaces split into patches (triangles), in world coordinates.

    ``vertices`` (V, 3) float64; ``faces`` (P, 3) int64; ``item`` (P,) the scene item each patch comes from;
    ``area`` (P,), ``centre`` (P, 3), ``normal`` (P, 3) unit; ``reflectance`` (P, 3) ρ = diffuse · color;
    ``emission`` (P, 3) E = emissive · emission.
    """

    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    item: NDArray[np.int64]
    area: NDArray[np.float64]
    centre: NDArray[np.float64]
    normal: NDArray[np.float64]
    reflectance: NDArray[np.float64]
    emission: NDArray[np.float64]

    @property
    def count(self) -> int:
        return int(self.faces.shape[0])


class RadiosityResult(NamedTuple):
    """What ``radiosity`` returns.

    ``scene``: a new scene of the patches, each vertex colored by the interpolated radiosity (the area-weighted
    mean of the patches sharing it on the same flat or smooth side, plus the display ambient term, clipped at 1):
    render it with ``shading="none"``. ``patches``: the patch count; ``radiosity`` (P, 3) B per patch (linear, not
    clipped, no ambient term); ``iterations``: shots taken (light sources included); ``residual``: unshot power
    over emitted power at the end; ``patch_mesh``: the (P,)-patch ``Patches`` record (geometry, ρ, E).
    """

    scene: Scene
    patches: int
    radiosity: NDArray[np.float64]
    iterations: int
    residual: float
    patch_mesh: Patches


# --- patches ---------------------------------------------------------------------------------------------------


def default_patch_size(scene: Scene) -> float:
    """The default patch size: a twentieth of the diagonal of the scene's bounding box."""
    low, high = _bounds(scene.items)
    return float(np.linalg.norm(high - low)) / 20.0


def _bounds(items: list[SceneItem]) -> tuple[np.ndarray, np.ndarray]:
    lows, highs = [], []
    for item in items:
        if item.mesh.vertex_count:
            world = _world(item)
            lows.append(world.min(axis=0))
            highs.append(world.max(axis=0))
    if not lows:
        raise RadiosityError("radiosity: the scene has no surfaces; add meshes to light")
    return np.min(lows, axis=0), np.max(highs, axis=0)


def _world(item: SceneItem) -> np.ndarray:
    model = np.asarray(item.world_from_model, dtype=np.float64)
    return item.mesh.vertices @ model[:3, :3].T + model[:3, 3]


def patches_of(scene: Scene, patch_size: float) -> Patches:
    """Split every mesh of `scene` into triangles whose edges are at most `patch_size` (world units) long.

    Triangles are halved at their edge midpoints until short enough (``trimesh.remesh.subdivide_to_size``).
    """
    from trimesh.remesh import subdivide_to_size

    items = scene.items
    _bounds(items)
    vertices, faces, owner, rho, emit = [], [], [], [], []
    offset = 0
    for index, item in enumerate(items):
        if item.mesh.face_count == 0:
            continue
        world = _world(item)
        v, f = subdivide_to_size(world, item.mesh.faces, max_edge=patch_size, max_iter=40)
        v, f = np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64)
        vertices.append(v)
        faces.append(f + offset)
        offset += v.shape[0]
        owner.append(np.full(f.shape[0], index, dtype=np.int64))
        material = item.material
        rho.append(np.tile(np.asarray(material.color) * material.diffuse, (f.shape[0], 1)))
        emit.append(np.tile(np.asarray(material.emissive) * material.emission, (f.shape[0], 1)))
    v, f = np.concatenate(vertices), np.concatenate(faces)
    p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    cross = np.cross(p1 - p0, p2 - p0)
    length = np.linalg.norm(cross, axis=1)
    keep = length > 0.0  # degenerate triangles neither shoot nor receive
    normal = cross[keep] / length[keep, None]
    return Patches(v, f[keep], np.concatenate(owner)[keep], 0.5 * length[keep], (p0 + p1 + p2)[keep] / 3.0, normal,
                   np.concatenate(rho)[keep], np.concatenate(emit)[keep])  # fmt: skip


def _estimated_patches(scene: Scene, patch_size: float) -> float:
    """About how many patches ``patches_of`` makes: each face's area over a patch's (an equilateral triangle of
    side patch_size / 2 at least: the halving stops between patch_size / 2 and patch_size)."""
    total = 0.0
    for item in scene.items:
        if item.mesh.face_count:
            world = _world(item)
            f = item.mesh.faces
            cross = np.cross(world[f[:, 1]] - world[f[:, 0]], world[f[:, 2]] - world[f[:, 0]])
            total += float(np.maximum(0.5 * np.linalg.norm(cross, axis=1) / (math.sqrt(3) / 16 * patch_size**2),
                                      1.0).sum())  # fmt: skip
    return total


# --- the hemicube ------------------------------------------------------------------------------------------------


def hemicube_delta_form_factors(resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """Delta form factors of the hemicube's pixels: ``(top, side)``, (N, N) and (N/2, N) float64, rows top first.

    Top face pixel centre (x, y, 1): $ΔF = ΔA / (π (x² + y² + 1)²)$; side face pixel centre (x, 1, z), z the
    height above the patch plane: $ΔF = z ΔA / (π (x² + z² + 1)²)$; $ΔA = (2/N)²$. Row 0 is the top of each
    face's image (z = 1 on a side face), as the frame buffers store them.
    """
    n = resolution
    centres = (np.arange(n) + 0.5) * (2.0 / n) - 1.0  # x from −1 to 1, left to right
    delta_area = (2.0 / n) ** 2
    x, y = np.meshgrid(centres, centres[::-1])  # row 0 = y near +1 (image top)
    top = delta_area / (math.pi * (x * x + y * y + 1.0) ** 2)
    heights = 1.0 - (np.arange(n // 2) + 0.5) * (2.0 / n)  # row 0 = z near 1
    xs, zs = np.meshgrid(centres, heights)
    side = zs * delta_area / (math.pi * (xs * xs + zs * zs + 1.0) ** 2)
    return top, side


def _tangent(normal: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to `normal`."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = np.cross(normal, helper)
    return t / np.linalg.norm(t)


class _Rasterizer:
    """The patches as one scene item, drawn into code buffers by the depth buffer's item pass."""

    def __init__(self, patches: Patches) -> None:
        mesh = Mesh(patches.vertices, patches.faces)
        self.item = SceneItem(mesh, Material(), np.eye(4))

    def codes(self, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
        """(depth, codes) of one view: codes $2·patch + back$ where drawn, depth 1 elsewhere (no culling:
        a patch seen from behind hides what lies beyond it but receives nothing)."""
        from frustum.render.buffers import Scratch
        from frustum.render.stages import Pixels, draw_item

        depth = np.ones((camera.height, camera.width), dtype=np.float32)
        codes = np.zeros((camera.height, camera.width), dtype=np.int32)
        bary = np.zeros((camera.height, camera.width, 2), dtype=np.float32)
        dummy = np.zeros((1, 1, 4), dtype=np.uint8)
        scratch = Scratch()
        draw_item(self.item, camera, False, 0, Pixels(depth, codes, bary, dummy, (dummy, dummy)), scratch)
        scratch.release()
        return depth, codes


def _hemicube_cameras(centre: np.ndarray, normal: np.ndarray, resolution: int, near: float, far: float):
    """The five cameras of the hemicube on a patch: the top face, then the upper halves of the four sides."""
    t1 = _tangent(normal)
    t2 = np.cross(normal, t1)
    half = resolution // 2
    top = Camera(ViewFrame(centre, normal=-normal, up=t1), Frustum(-near, near, -near, near, near, far),
                 resolution, resolution)  # fmt: skip
    sides = [
        Camera(ViewFrame(centre, normal=-d, up=normal), Frustum(-near, near, 0.0, near, near, far), resolution, half)
        for d in (t1, t2, -t1, -t2)
    ]
    return [top, *sides]


def _gather(depth: np.ndarray, codes: np.ndarray, weights: np.ndarray, count: int) -> np.ndarray:
    """Σ of `weights` over the pixels that show each patch's front side: (count,) form factors."""
    seen = depth < 1.0
    seen &= (codes & 1) == 0
    return np.bincount(codes[seen] >> 1, weights=weights[seen], minlength=count)[:count]


def form_factors(
    patches: Patches, source: int, *, hemicube: int = 128, rasterizer: _Rasterizer | None = None
) -> NDArray[np.float64]:
    """(P,) form factors F_source,k from patch `source` to every patch, by the hemicube of `hemicube` pixels a side
    on the patch's centre."""
    raster = rasterizer or _Rasterizer(patches)
    factors = hemicube_form_factors(patches, patches.centre[source], patches.normal[source], hemicube, raster)
    factors[source] = 0.0
    return factors


def hemicube_form_factors(
    patches: Patches, centre: np.ndarray, normal: np.ndarray, hemicube: int, raster: _Rasterizer
) -> NDArray[np.float64]:
    """(P,) form factors from the differential area at `centre` facing `normal` to every patch (the hemicube)."""
    size = float(np.linalg.norm(patches.vertices.max(axis=0) - patches.vertices.min(axis=0)))
    near = 1e-4 * size
    eye = centre + normal * (1e-6 * size)
    top, side = _delta_cache(hemicube)
    total = np.zeros(patches.count)
    for k, camera in enumerate(_hemicube_cameras(eye, normal, hemicube, near, 4.0 * size)):
        depth, codes = raster.codes(camera)
        total += _gather(depth, codes, top if k == 0 else side, patches.count)
    return total


def shooting_groups(patches: Patches, size: float) -> NDArray[np.int64]:
    """(P,) group of each patch: patches of one item, facing the same way (normals within ~15°) and in one cell of
    a grid of `size` shoot together from their area-weighted centre (Cohen et al.'s patches and elements:
    elements receive, the coarser patches shoot)."""
    cell = np.floor(patches.centre / size).astype(np.int64)
    facing = np.round(patches.normal * 4.0).astype(np.int64)
    keys = np.c_[patches.item, facing, cell]
    return np.unique(keys, axis=0, return_inverse=True)[1].reshape(-1)


_DELTAS: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def _delta_cache(resolution: int) -> tuple[np.ndarray, np.ndarray]:
    if resolution not in _DELTAS:
        _DELTAS[resolution] = hemicube_delta_form_factors(resolution)
    return _DELTAS[resolution]


class _Column(NamedTuple):
    """One shooting group's form factors: ``far`` (P,) from each patch centre to the group's area, 0 for the
    ``near`` receivers (R,), which keep ``per_member`` (R, M) factors to each of the group's ``members`` (M,)."""

    far: np.ndarray
    near: np.ndarray
    per_member: np.ndarray
    members: np.ndarray


class _RayFactors:
    """Form factors from every patch centre to a shooting group's area (``form_factors="ray"``), one column per group
    computed on its first shot and kept: the unoccluded factor to each quarter of the group (exact, per triangle,
    ``raster.form_factors``) times whether a shadow ray from the receiver reaches that quarter's representative
    point (the member centroid nearest the quarter's centre) — Wallace, Elmquist & Haines' receiver-side factors
    with four samples of the source. Receivers nearer the group than its size keep one factor per member, so they
    receive each member's own unshot radiosity rather than the group's mean (grouping errs only near the group)."""

    def __init__(self, patches: Patches, members: list[np.ndarray]) -> None:
        from frustum.raster import rays

        self.patches = patches
        self.members = members
        self.triangles = patches.vertices[patches.faces]
        self.index = rays.build(self.triangles)
        size = float(np.linalg.norm(patches.vertices.max(axis=0) - patches.vertices.min(axis=0)))
        self.offset = 1e-6 * size
        self.origins = patches.centre + patches.normal * self.offset
        self.columns: dict[int, _Column] = {}

    def gain(self, group: int, unshot: np.ndarray) -> np.ndarray:
        """(P, 3) $Σ_j F_k,j ΔB_j$ over the group's members j: what each patch k receives (before ρ_k) when the
        group shoots the unshot radiosity `unshot` (P, 3)."""
        if group not in self.columns:
            self.columns[group] = self._compute(self.members[group])
        far, near, per_member, members = self.columns[group]
        area = self.patches.area[members]
        mean = (unshot[members] * area[:, None]).sum(axis=0) / area.sum()
        received = far[:, None] * mean
        received[near] += per_member @ unshot[members]
        return received

    def _compute(self, members: np.ndarray) -> _Column:
        from frustum.raster import rays
        from frustum.raster.form_factors import point_group_factors, point_triangle_factors

        patches = self.patches
        quarter, representative = _quarters(patches, members)
        order = np.argsort(quarter, kind="stable")
        members, quarter = members[order], quarter[order]
        pieces = representative.shape[0]
        first = np.searchsorted(quarter, np.arange(pieces + 1)).astype(np.int64)
        edges, edge_first = _boundaries(patches.faces[members], quarter, pieces)
        triangles = np.ascontiguousarray(self.triangles[members])
        facing = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
        unoccluded = np.zeros((patches.count, pieces))
        planes = _planes(patches, members, first)
        point_group_factors(patches.centre, patches.normal, triangles, facing, first,
                            np.ascontiguousarray(patches.vertices[edges]), edge_first, planes, unoccluded)  # fmt: skip
        visible = unoccluded > 0.0
        receiver, piece = np.nonzero(visible)
        if receiver.size:
            target = patches.centre[representative] + patches.normal[representative] * self.offset
            origins = self.origins[receiver]
            visible[receiver, piece] = ~rays.any_hits(self.index, origins, target[piece] - origins, 0.0, 1.0)
        far = (unoccluded * visible).sum(axis=1)
        corners = triangles.reshape(-1, 3)
        low, high = corners.min(axis=0), corners.max(axis=0)
        reach = float(np.linalg.norm(high - low))
        gap = np.linalg.norm(np.maximum(np.maximum(low - patches.centre, patches.centre - high), 0.0), axis=1)
        near = np.flatnonzero((gap < reach) & visible.any(axis=1))
        per_member = np.zeros((near.shape[0], members.shape[0]))
        if near.size:
            point_triangle_factors(np.ascontiguousarray(patches.centre[near]),
                                   np.ascontiguousarray(patches.normal[near]), triangles,
                                   np.arange(members.shape[0], dtype=np.int64), per_member)  # fmt: skip
            per_member *= visible[near][:, quarter]
            far[near] = 0.0
        return _Column(far, near, per_member, members)


def _planes(patches: Patches, members: np.ndarray, first: np.ndarray) -> np.ndarray:
    """(Q, 4) plane (m, d), m·x = d, of each piece ``members[first[q]:first[q + 1]]`` whose patches all lie on one
    plane with one normal (to 1e-12 of the scene's size); NaN rows for the others."""
    planes = np.full((first.shape[0] - 1, 4), np.nan)
    size = float(np.abs(patches.vertices).max()) or 1.0
    for q in range(planes.shape[0]):
        mine = members[first[q] : first[q + 1]]
        m = patches.normal[mine[0]]
        d = float(m @ patches.centre[mine[0]])
        corners = patches.vertices[patches.faces[mine]].reshape(-1, 3)
        if np.abs(patches.normal[mine] - m).max() <= 1e-12 and np.abs(corners @ m - d).max() <= 1e-12 * size:
            planes[q, :3], planes[q, 3] = m, d
    return planes


def _boundaries(faces: np.ndarray, piece: np.ndarray, pieces: int) -> tuple[np.ndarray, np.ndarray]:
    """The boundary edges of each piece of a group: ((E, 2) vertex pairs running as in their triangles, sorted by
    piece; (pieces + 1,) offsets). An edge is on the boundary when its reverse is not an edge of the same piece."""
    directed = np.stack([faces, np.roll(faces, -1, axis=1)], axis=2).reshape(-1, 2)  # (3T, 2)
    owner = np.repeat(piece, 3)
    keys = np.c_[owner, directed]
    reverse = np.c_[owner, directed[:, ::-1]]
    forward = {tuple(k) for k in keys.tolist()}
    boundary = np.array([tuple(k) not in forward for k in reverse.tolist()], dtype=bool)
    edges = directed[boundary]
    first = np.searchsorted(owner[boundary], np.arange(pieces + 1)).astype(np.int64)
    return edges, first


def _quarters(patches: Patches, members: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The members of a group split in (up to) four quarters by the medians of their centroids along the group's two
    widest principal directions: ((M,) quarter of each member, numbered from 0, (Q,) representative patch of each
    quarter: the member whose centroid lies nearest the quarter's area-weighted centre)."""
    centres = patches.centre[members]
    if members.shape[0] < 4:
        return np.arange(members.shape[0], dtype=np.int64), members.copy()
    spread = centres - centres.mean(axis=0)
    axes = np.linalg.svd(spread, full_matrices=False)[2][:2]
    along = spread @ axes.T  # (M, 2)
    key = (along[:, 0] > np.median(along[:, 0])).astype(np.int64) * 2 + (along[:, 1] > np.median(along[:, 1]))
    labels, subset = np.unique(key, return_inverse=True)
    subset = subset.reshape(-1).astype(np.int64)
    representative = np.empty(labels.shape[0], dtype=np.int64)
    area = patches.area[members]
    for q in range(labels.shape[0]):
        mine = subset == q
        middle = (centres[mine] * area[mine, None]).sum(axis=0) / area[mine].sum()
        representative[q] = members[mine][np.argmin(np.linalg.norm(centres[mine] - middle, axis=1))]
    return subset, representative


# --- light sources -------------------------------------------------------------------------------------------------

_SAMPLES = np.array([[1 / 3, 1 / 3, 1 / 3], [2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])
"""Barycentric points of a patch where the direct light is evaluated (the centre and one near each corner)."""


def _light_views(light: Any, patches: Patches, resolution: int) -> list[Camera]:
    """The depth-buffer views from a light: six cube faces (point, spot) or one orthographic view (directional)."""
    low, high = patches.vertices.min(axis=0), patches.vertices.max(axis=0)
    size = float(np.linalg.norm(high - low))
    if isinstance(light, DirectionalLight):
        centre = 0.5 * (low + high)
        radius = 0.5 * size * 1.01
        direction = np.asarray(light.direction, dtype=np.float64)
        eye = centre - direction * 2.0 * radius
        return [Camera(ViewFrame(eye, normal=-direction, up=_tangent(direction)),
                       Orthographic(2.0 * radius, 0.5 * radius, 3.5 * radius),
                       resolution, resolution)]  # fmt: skip
    position = np.asarray(light.position, dtype=np.float64)
    far = 2.0 * (size + float(np.linalg.norm(position - 0.5 * (low + high))))
    near = 1e-4 * far
    axes = np.eye(3)
    views = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            look = sign * axes[axis]
            up = axes[(axis + 1) % 3]
            views.append(Camera(ViewFrame(position, normal=-look, up=up), Frustum(-near, near, -near, near, near, far),
                                resolution, resolution))  # fmt: skip
    return views


def _visible_fraction(light: Any, patches: Patches, raster: _Rasterizer, resolution: int) -> np.ndarray:
    """(P,) fraction of the four sample points of each patch the light's depth-buffer views show on that patch."""
    count = patches.count
    corners = patches.vertices[patches.faces]  # (P, 3, 3)
    points = np.einsum("sk,pkd->psd", _SAMPLES, corners).reshape(-1, 3)  # (P·4, 3)
    owner = np.repeat(np.arange(count), _SAMPLES.shape[0])
    lit = np.zeros(points.shape[0], dtype=bool)
    for camera in _light_views(light, patches, resolution):
        depth, codes = raster.codes(camera)
        clip = np.c_[points, np.ones(len(points))] @ np.asarray(camera.clip_from_world).T
        w = clip[:, 3]
        inside = (w > 0) & (np.abs(clip[:, 0]) <= w) & (np.abs(clip[:, 1]) <= w) & (np.abs(clip[:, 2]) <= w)
        idx = np.flatnonzero(inside & ~lit)
        ndc = clip[idx, :2] / w[idx, None]
        col = np.clip(((ndc[:, 0] + 1.0) * 0.5 * camera.width).astype(np.int64), 0, camera.width - 1)
        row = np.clip(((1.0 - ndc[:, 1]) * 0.5 * camera.height).astype(np.int64), 0, camera.height - 1)
        # lit where the light's view shows the sample's own patch (an item buffer: no depth bias to tune), or
        # the patch's front within one pixel (the sample may sit on an edge between the patch and its neighbour)
        shown = np.zeros(idx.shape[0], dtype=bool)
        for dr in (0, -1, 1):
            for dc in (0, -1, 1):
                r = np.clip(row + dr, 0, camera.height - 1)
                c = np.clip(col + dc, 0, camera.width - 1)
                code = codes[r, c]
                shown |= (depth[r, c] < 1.0) & ((code >> 1) == owner[idx])
        lit[idx[shown]] = True
    return lit.reshape(count, -1).mean(axis=1)


def _direct_light(light: Any, patches: Patches) -> np.ndarray:
    """(P, 3) f_l · I_l · max(N·L, 0) at each patch centre: the depth buffer's diffuse factor, unshadowed (L and
    the falloff f_l by the one light model, ``shading.light.toward_light``)."""
    intensity = np.asarray(light.color, dtype=np.float64) * light.intensity
    to_light, falloff = toward_light(light, patches.centre)
    ndl = np.maximum(np.einsum("ij,ij->i", patches.normal, to_light), 0.0)
    return (falloff * ndl)[:, None] * intensity


# --- the solver ------------------------------------------------------------------------------------------------------


def radiosity(
    scene: Scene,
    *,
    patch_size: float | None = None,
    hemicube: int = 128,
    tolerance: float = 1e-3,
    max_iterations: int | None = None,
    shooter: float = 4.0,
    progress: Callable[[int, float], None] | None = None,
    form_factors: str = "ray",
) -> RadiosityResult:
    """Solve $B_k = E_k + ρ_k Σ_j B_j F_jk$ for the scene's surfaces by progressive refinement (module docstring).

    Parameters
    ----------
    scene : Scene
        Meshes (their materials give $ρ = diffuse · color$ and $E = emissive · emission$) and lights (each positioned
        light shoots first; ambient lights add nothing: radiosity computes the ambient light).
    patch_size : float, optional
        Longest patch edge in world units; default a twentieth of the scene's bounding-box diagonal.
    hemicube : int
        Pixels along a hemicube's side (even, 8…2048); the form factors' error falls as it grows.
    tolerance : float
        Stop when the unshot power is below this fraction of the emitted power (0 < tolerance < 1).
    max_iterations : int, optional
        Most shots from patch groups (default: 50 per group, which always reaches a residual well below 1e-3 in a
        closed scene with ρ ≤ 0.9 or an open one).
    shooter : float
        Patches shoot in groups of about $shooter × patch_size$ (those of one item facing the same way in one
        grid cell); every patch receives on its own. With ray form factors a group shoots from its whole area,
        and receivers nearer than its size take each member's own unshot radiosity (exact per patch in a closed
        box at any grouping); with the hemicube it shoots from its area-weighted centre. 1 shoots from every patch
        alone (several times slower).
    progress : callable(shots, residual), optional
        Called after each shot (the CLI draws a Rich bar with it).
    form_factors : {"ray", "hemicube"}
        "ray" (default): each receiving patch's form factor to the shooting group's area, exact at the patch
        centre (Lambert's contour formula per triangle) times the fraction of shadow rays to four points of the
        group that nothing blocks (Wallace, Elmquist & Haines 1989); a group's form factor is computed once and
        reused by its later shots. "hemicube": the hemicube on the group's centre (Cohen & Greenberg 1985), the
        textbook method, blotchy on small receivers (aliasing) and near the shooter.

    Returns
    -------
    RadiosityResult

    Raises
    ------
    RadiosityError
        Bad parameters, a scene without surfaces or without light (no emitter and no positioned light), or a
        patch count whose work is over the budget (the message gives the estimate).
    """
    where = "radiosity"
    if not isinstance(scene, Scene):
        raise RadiosityError(f"{where}: scene = {describe(scene)} is not a Scene")
    if isinstance(hemicube, bool) or not isinstance(hemicube, int | np.integer) or not 8 <= hemicube <= 2048 \
            or hemicube % 2:  # fmt: skip
        raise RadiosityError(f"{where}: hemicube = {hemicube!r} is not an even pixel count in 8…2048; e.g. 128")
    tol = as_scalar(tolerance, "tolerance", where=where, error=RadiosityError)
    if not 0.0 < tol < 1.0:
        raise RadiosityError(f"{where}: tolerance = {tol!r} is not in (0, 1); e.g. 1e-3")
    size = default_patch_size(scene) if patch_size is None else as_scalar(patch_size, "patch_size", where=where,
                                                                          error=RadiosityError)  # fmt: skip
    if not size > 0.0:
        raise RadiosityError(f"{where}: patch_size = {size!r} is not a positive length in world units")
    shooter = as_scalar(shooter, "shooter", where=where, error=RadiosityError)
    if not shooter >= 1.0:
        raise RadiosityError(f"{where}: shooter = {shooter!r} is below 1; give a group size in patch sizes >= 1")
    if form_factors not in ("ray", "hemicube"):
        raise RadiosityError(f"{where}: form_factors = {form_factors!r} is not 'ray' or 'hemicube'")
    estimate = _estimated_patches(scene, size)
    pixels = hemicube * hemicube * 3  # the top face and four half sides
    check_memory(estimate * 600.0 + pixels * 16, where=where,
                 cause=f"patch_size = {size:.4g} (about {estimate:.3g} patches)", error=RadiosityError)  # fmt: skip
    work = estimate * estimate * 60.0 if form_factors == "ray" else estimate / shooter**2 * 10.0 * (pixels + estimate)
    # shots grow with the orders of magnitude the unshot power must fall (the estimates above are for 1e-3, three),
    # up to the limit of 50 shots a group (about ten times the shots 1e-3 takes)
    decades = min(-math.log10(tol) / 3.0, 10.0) if max_iterations is None else 1.0
    check_operations(work * max(decades, 1.0), where=where,
                     cause=f"patch_size = {size:.4g} (about {estimate:.3g} patches, hemicube {hemicube}, tolerance "
                           f"{tol:.3g})", error=RadiosityError)  # fmt: skip
    if max_iterations is not None and (isinstance(max_iterations, bool) or not isinstance(max_iterations, int)
                                       or max_iterations < 0):  # fmt: skip
        raise RadiosityError(f"{where}: max_iterations = {max_iterations!r} is not a count >= 0 (or None)")

    patches = patches_of(scene, size)
    count = patches.count
    raster = _Rasterizer(patches)
    reflectance, area = patches.reflectance, patches.area
    radiosity_b = patches.emission.copy()
    unshot = patches.emission.copy()
    shots = 0
    for light in scene.world_lights():
        if isinstance(light, DirectionalLight | PointLight | SpotLight):
            visible = _visible_fraction(light, patches, raster, max(hemicube * 4, 256))
            direct = reflectance * _direct_light(light, patches) * visible[:, None]
            radiosity_b += direct
            unshot += direct
            shots += 1
    emitted = float((unshot.sum(axis=1) * area).sum())
    if not emitted > 0.0:
        raise RadiosityError(
            f"{where}: nothing emits light; give a material emissive color (and emission > 0) or add a "
            "directional, point or spot light"
        )
    group = shooting_groups(patches, shooter * size)
    groups = int(group.max()) + 1
    weight = np.bincount(group, weights=area, minlength=groups)
    centre = np.stack([np.bincount(group, weights=patches.centre[:, k] * area, minlength=groups) for k in range(3)],
                      axis=1) / weight[:, None]  # fmt: skip
    normal = np.stack([np.bincount(group, weights=patches.normal[:, k] * area, minlength=groups) for k in range(3)],
                      axis=1)  # fmt: skip
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    members = np.split(np.argsort(group, kind="stable"), np.cumsum(np.bincount(group, minlength=groups))[:-1])
    limit = 50 * groups if max_iterations is None else max_iterations
    power = np.bincount(group, weights=unshot.sum(axis=1) * area, minlength=groups)
    residual = float(power.sum()) / emitted
    taken = 0
    receiving = _RayFactors(patches, members) if form_factors == "ray" else None
    while residual > tol and taken < limit:
        source = int(np.argmax(power))
        shooting = members[source]
        shot = (unshot[shooting] * area[shooting, None]).sum(axis=0)  # (3,) unshot power of the group
        if receiving is not None:  # F_k,group at each receiver: B_k += ρ_k F_k,group ΔB_group
            gain = receiving.gain(source, unshot) * reflectance
            unshot[shooting] = 0.0
        else:  # F_group,k by the hemicube and reciprocity: B_k += ρ_k F_group,k ΔB_group A_group / A_k
            factors = hemicube_form_factors(patches, centre[source], normal[source], hemicube, raster)
            factors[shooting] = 0.0
            unshot[shooting] = 0.0
            gain = (factors / area)[:, None] * shot * reflectance
        radiosity_b += gain
        unshot += gain
        power = np.bincount(group, weights=unshot.sum(axis=1) * area, minlength=groups)
        residual = float(power.sum()) / emitted
        taken += 1
        if progress is not None:
            progress(taken, residual)
    display = _display(patches, radiosity_b, unshot)
    return RadiosityResult(_lit_scene(patches, display), count, radiosity_b, shots + taken, residual, patches)


def _display(patches: Patches, radiosity_b: np.ndarray, unshot: np.ndarray) -> np.ndarray:
    """B plus Cohen's ambient term $ρ_k · R · Σ ΔB_j A_j / Σ A_j$ with $R = 1 / (1 − ρ_avg)$."""
    area = patches.area
    total = area.sum()
    rho_avg = (patches.reflectance * area[:, None]).sum(axis=0) / total
    ambient = (unshot * area[:, None]).sum(axis=0) / total / np.maximum(1.0 - rho_avg, 1e-6)
    return radiosity_b + patches.reflectance * ambient


def _lit_scene(patches: Patches, display: np.ndarray) -> Scene:
    """One mesh per scene item with per-vertex radiosity: each vertex takes the area-weighted mean of the patches
    around it whose normals agree with its patch's (within 30°), so colors do not bleed across creases."""
    scene = Scene()
    for index in np.unique(patches.item):
        chosen = np.flatnonzero(patches.item == index)
        faces = patches.faces[chosen]
        normals = patches.normal[chosen]
        # one output vertex per (vertex, smooth group): group normals by a coarse direction key
        corner_vertex = faces.reshape(-1)
        corner_face = np.repeat(np.arange(chosen.shape[0]), 3)
        key_normal = np.round(normals[corner_face] * 2.0).astype(np.int64)  # 30°-ish bins of direction
        keys = np.c_[corner_vertex, key_normal]
        unique, inverse = np.unique(keys, axis=0, return_inverse=True)
        inverse = inverse.reshape(-1)
        weights = patches.area[chosen][corner_face]
        color_sum = np.zeros((unique.shape[0], 3))
        np.add.at(color_sum, inverse, display[chosen][corner_face] * weights[:, None])
        weight_sum = np.bincount(inverse, weights=weights, minlength=unique.shape[0])
        colors = np.clip(color_sum / weight_sum[:, None], 0.0, 1.0)
        normal_sum = np.zeros((unique.shape[0], 3))
        np.add.at(normal_sum, inverse, normals[corner_face] * weights[:, None])
        normal_sum /= np.linalg.norm(normal_sum, axis=1, keepdims=True)
        mesh = Mesh(patches.vertices[unique[:, 0]], inverse.reshape(-1, 3), vertex_normals=normal_sum,
                    vertex_colors=colors)  # fmt: skip
        scene.add(mesh, Material(color=(1.0, 1.0, 1.0)), name=f"radiosity_{int(index)}")
    return scene
