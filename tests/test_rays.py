"""The ray-query index (``raster.rays``) and ``Scene.intersect`` / ``Scene.occluded`` against Embree (``embreex``).

Embree works in float32: the geometry and rays given to both are float32 numbers (exactly representable in
float64), so both see the same triangles and rays; frustum intersects in float64, Embree in float32, so the
distances agree to float32 rounding and hits may differ only where a ray passes within rounding of an edge.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum import (
    Camera,
    DirectionalLight,
    FrustumError,
    Material,
    Mesh,
    RayHits,
    Scene,
    load,
    reflect,
    rotate_y,
    scale,
    translate,
    uv_sphere,
)
from frustum.raster import rays

embree_scene = pytest.importorskip("embreex.rtcore_scene")
embree_mesh = pytest.importorskip("embreex.mesh_construction")

DATA = Path(__file__).parent / "data"
BUNNY = DATA / "bunny" / "bun_zipper_res2.ply"


def f32(values: np.ndarray) -> np.ndarray:
    return np.asarray(values, dtype=np.float32).astype(np.float64)


def embree(triangles: np.ndarray):
    scene = embree_scene.EmbreeScene()
    embree_mesh.TriangleMesh(scene, np.ascontiguousarray(triangles, dtype=np.float32))
    return scene


def embree_hits(scene, origins: np.ndarray, directions: np.ndarray) -> dict:
    out = scene.run(origins.astype(np.float32), directions.astype(np.float32), output=1)
    return {"t": np.where(out["primID"] >= 0, out["tfar"].astype(np.float64), np.inf), "face": out["primID"],
            "u": out["u"].astype(np.float64), "v": out["v"].astype(np.float64)}  # fmt: skip


def embree_occluded(scene, origins: np.ndarray, directions: np.ndarray, t_max: np.ndarray) -> np.ndarray:
    out = scene.run(origins.astype(np.float32), directions.astype(np.float32),
                    dists=np.asarray(t_max, dtype=np.float32), query="OCCLUDED")  # fmt: skip
    return out != -1


def near_edge(triangles: np.ndarray, face: np.ndarray, u: np.ndarray, v: np.ndarray,
              directions: np.ndarray) -> np.ndarray:  # fmt: skip
    """Whether each hit lies within float32 rounding of its triangle's edges: 1e-6 of the scene's size, over the
    cosine of the incidence angle (weight w_i of corner i times the height over the opposite edge = distance)."""
    tri = triangles[np.maximum(face, 0)]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    double_area = np.linalg.norm(normal, axis=1)
    weights = np.stack([1.0 - u - v, u, v], axis=1)
    opposite = np.stack([np.linalg.norm(tri[:, (i + 2) % 3] - tri[:, (i + 1) % 3], axis=1) for i in range(3)], axis=1)
    distance = (weights * double_area[:, None] / np.maximum(opposite, 1e-300)).min(axis=1)
    cosine = np.abs(np.einsum("ij,ij->i", normal, directions)) / np.maximum(
        double_area * np.linalg.norm(directions, axis=1), 1e-300
    )
    return (face >= 0) & (distance * np.maximum(cosine, 1e-3) <= 1e-6 * np.abs(triangles).max())


def edge_on(triangles: np.ndarray, face: np.ndarray, directions: np.ndarray, angle: float = 1e-4) -> np.ndarray:
    tri = triangles[np.maximum(face, 0)]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    cosine = np.abs(np.einsum("ij,ij->i", normal, directions))
    cosine /= np.linalg.norm(normal, axis=1) * np.linalg.norm(directions, axis=1)
    return (face >= 0) & (cosine < angle)


def assert_same_first_hits(triangles: np.ndarray, origins: np.ndarray, directions: np.ndarray) -> dict:
    """frustum's index and Embree agree: the same hit or miss and triangle, the same point up to float32, except for
    rays within float32 rounding of an edge (where a neighbour, at the same t, may win) — at most 0.5 %."""
    index = rays.build(triangles)
    ours = rays.closest_hits(index, origins, directions)
    theirs = embree_hits(embree(triangles), origins, directions)
    both = (ours.face >= 0) & (theirs["face"] >= 0)
    hit_differs = (ours.face >= 0) != (theirs["face"] >= 0)
    face_differs = both & (ours.face != theirs["face"])
    # near an edge, or edge-on (the ray within 1e-4 radians of the hit triangle's plane: a grazing ray along a
    # face, where float32 and float64 arithmetic may each see the face or not)
    ours_edge = near_edge(triangles, ours.face, ours.uv[:, 0], ours.uv[:, 1], directions)
    ours_edge |= edge_on(triangles, ours.face, directions)
    theirs_edge = near_edge(triangles, theirs["face"], theirs["u"], theirs["v"], directions)
    theirs_edge |= edge_on(triangles, theirs["face"], directions)
    # a hit one side misses grazes an edge on the other side
    assert (ours_edge | theirs_edge)[hit_differs].all()
    # another triangle: a tie (the bunny has coincident duplicate faces) or at an edge, at the same t: frustum's
    # own test of Embree's triangle meets it at frustum's t
    for r in np.flatnonzero(face_differs & ~(ours_edge | theirs_edge)):
        other = rays.closest_hits(rays.build(triangles[[theirs["face"][r]]]), origins[[r]], directions[[r]])
        assert other.t[0] == pytest.approx(ours.t[r], rel=1e-12)
    same = both & ~face_differs
    # Embree's t is float32 arithmetic on float32 coordinates: the hit points agree within 1e-6 of the scene's
    # size (its coordinates' rounding), divided by the cosine of the incidence angle (the error along the ray
    # grows as 1/cos at grazing incidence). (t within 1e-6 relative fails for Embree's float32 t near the origin.)
    tri = triangles[ours.face[same]]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(directions[same], axis=1)
    cosine = np.abs(np.einsum("ij,ij->i", normal, directions[same])) / (np.linalg.norm(normal, axis=1) * length)
    error = np.abs(ours.t[same] - theirs["t"][same]) * length
    assert (error * cosine <= 1e-6 * np.abs(triangles).max()).all()
    assert hit_differs.mean() + face_differs.mean() <= 5e-3
    return {"hits": int(both.sum()), "rays": origins.shape[0], "differ": int(hit_differs.sum() + face_differs.sum())}


def assert_same_occlusion(triangles: np.ndarray, origins: np.ndarray, directions: np.ndarray, t_max: np.ndarray):
    """``any_hits`` equals Embree's occlusion query except where the first hit (frustum's or Embree's) lies at
    t_max up to rounding or within rounding of an edge — at most 0.1 %; and it equals ``closest.t < t_max``."""
    index = rays.build(triangles)
    ours = rays.any_hits(index, origins, directions, 0.0, t_max)
    scene = embree(triangles)
    theirs = embree_occluded(scene, origins, directions, t_max)
    closest = rays.closest_hits(index, origins, directions)
    first = embree_hits(scene, origins, directions)
    assert np.array_equal(ours, closest.t < t_max)
    differ = ours != theirs
    limit = 1e-6 * np.maximum(t_max, 1.0)
    at_limit = (np.abs(closest.t - t_max) <= limit) | (np.abs(first["t"] - t_max) <= limit)
    edge = near_edge(triangles, closest.face, closest.uv[:, 0], closest.uv[:, 1], directions)
    edge |= near_edge(triangles, first["face"], first["u"], first["v"], directions)
    assert (at_limit | edge)[differ].all()
    assert differ.mean() <= 1e-3
    assert ours.any() and not ours.all()


def bunny_triangles() -> np.ndarray:
    mesh = load(BUNNY)
    return f32(mesh.vertices[mesh.faces])


def sphere_triangles(segments: int, rings: int) -> np.ndarray:
    mesh = uv_sphere(1.0, segments, rings)
    return f32(mesh.vertices[mesh.faces])


def camera_rays(centre: np.ndarray, radius: float, n: int, rng: np.random.Generator):
    eye = centre + radius * np.array([0.4, 0.5, 2.6])
    xs, ys = np.meshgrid(np.linspace(-1.2, 1.2, n), np.linspace(-1.2, 1.2, n))
    target = centre + radius * np.stack([xs.ravel(), ys.ravel(), rng.normal(size=n * n) * 0.1], axis=1)
    origins = np.broadcast_to(eye, target.shape)
    return f32(origins), f32(target - origins)


def inside_rays(centre: np.ndarray, radius: float, count: int, rng: np.random.Generator):
    origins = centre + rng.normal(size=(count, 3)) * radius * 0.05
    return f32(origins), f32(rng.normal(size=(count, 3)))


def grazing_rays_sphere(count: int, rng: np.random.Generator):
    """Rays passing at distance 0.999…1.001 from the centre of a unit sphere: tangent to it."""
    direction = rng.normal(size=(count, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    side = np.cross(direction, rng.normal(size=(count, 3)))
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    distance = rng.uniform(0.99, 1.001, count)
    origins = side * distance[:, None] - 3.0 * direction
    return f32(origins), f32(direction)


def test_bunny_first_hits_equal_embree() -> None:
    rng = np.random.default_rng(7)
    tri = bunny_triangles()
    corners = tri.reshape(-1, 3)
    centre = 0.5 * (corners.min(axis=0) + corners.max(axis=0))
    radius = float(np.abs(corners - centre).max())
    o, d = camera_rays(centre, radius, 160, rng)
    found = assert_same_first_hits(tri, o, d)
    assert found["hits"] > 10_000
    o, d = inside_rays(centre, radius, 20_000, rng)
    found = assert_same_first_hits(tri, o, d)
    assert found["hits"] > 15_000
    # grazing: through the centre of a face at 0.06° to 0.6° from its plane
    faces = rng.integers(0, tri.shape[0], 20_000)
    a, b, c = tri[faces, 0], tri[faces, 1], tri[faces, 2]
    normal = np.cross(b - a, c - a)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    along = (b - a) / np.linalg.norm(b - a, axis=1, keepdims=True)
    angle = rng.uniform(1e-3, 1e-2, (faces.shape[0], 1)) * rng.choice([-1.0, 1.0], (faces.shape[0], 1))
    d = np.cos(angle) * along + np.sin(angle) * normal
    o, d = f32((a + b + c) / 3.0 - 3.0 * radius * 0.05 * d), f32(d)
    assert_same_first_hits(tri, o, d)


def test_fine_sphere_first_hits_equal_embree() -> None:
    rng = np.random.default_rng(11)
    tri = sphere_triangles(1000, 500)  # 998,000 triangles
    assert tri.shape[0] > 990_000
    o, d = camera_rays(np.zeros(3), 1.0, 100, rng)
    assert assert_same_first_hits(tri, o, d)["hits"] > 5_000
    o, d = inside_rays(np.zeros(3), 1.0, 10_000, rng)
    assert assert_same_first_hits(tri, o, d)["hits"] == 10_000  # closed: every ray from inside hits
    o, d = grazing_rays_sphere(10_000, rng)
    assert_same_first_hits(tri, o, d)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), count=st.integers(1, 3000), spread=st.floats(0.01, 3.0))
def test_random_triangle_soups_equal_embree(seed: int, count: int, spread: float) -> None:
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-1.0, 1.0, (count, 1, 3))
    tri = f32(centres + rng.normal(size=(count, 3, 3)) * spread * 0.3)
    origins = f32(rng.uniform(-3.0, 3.0, (2000, 3)))
    directions = f32(rng.normal(size=(2000, 3)))
    assert_same_first_hits(tri, origins, directions)
    t_max = f32(rng.uniform(0.0, 4.0, 2000))
    index = rays.build(tri)
    ours = rays.any_hits(index, origins, directions, 0.0, t_max)
    if ours.any() and not ours.all():
        assert_same_occlusion(tri, origins, directions, t_max)
    else:  # a soup too small or sparse for both outcomes: still equal to the first hit before t_max
        assert np.array_equal(ours, rays.closest_hits(index, origins, directions).t < t_max)


def test_occlusion_equals_embree_bunny_and_sphere() -> None:
    rng = np.random.default_rng(5)
    tri = bunny_triangles()
    corners = tri.reshape(-1, 3)
    low, high = corners.min(axis=0), corners.max(axis=0)
    origins = f32(rng.uniform(low - 0.02, high + 0.02, (30_000, 3)))
    targets = f32(rng.uniform(low - 0.02, high + 0.02, (30_000, 3)))
    assert_same_occlusion(tri, origins, targets - origins, np.ones(30_000))
    assert_same_occlusion(tri, origins, f32(rng.normal(size=(30_000, 3))), f32(rng.uniform(0, 0.2, 30_000)))
    tri = sphere_triangles(200, 100)
    origins = f32(rng.uniform(-1.5, 1.5, (30_000, 3)))
    targets = f32(rng.uniform(-1.5, 1.5, (30_000, 3)))
    assert_same_occlusion(tri, origins, targets - origins, np.ones(30_000))


def test_same_hits_as_testing_every_triangle() -> None:
    """The index finds exactly the hit of testing every triangle with the same arithmetic (``brute_force``): the
    same t bits and the same triangle (ties to the lowest index), on the bunny and on a soup of small triangles.
    (It replaced the comparison with the former Morton-order index, ``raster.bvh``, removed.)"""
    rng = np.random.default_rng(3)
    for tri in (bunny_triangles(), f32(rng.normal(size=(5000, 1, 3)) + rng.normal(size=(5000, 3, 3)) * 0.1)):
        corners = tri.reshape(-1, 3)
        centre = corners.mean(axis=0)
        o = centre + rng.normal(size=(6000, 3)) * np.abs(corners - centre).max()
        d = rng.normal(size=(6000, 3))
        new = rays.closest_hits(rays.build(tri), o, d)
        face, t = brute_force(tri, o, d, with_t=True)
        assert np.array_equal(new.face, face)
        assert np.array_equal(new.t, t)
        assert 0.05 < (face >= 0).mean() < 0.95


def test_build_is_the_same_on_any_number_of_threads() -> None:
    from frustum.raster._jit import set_threads

    tri = sphere_triangles(400, 200)  # above the parallel cut-off
    try:
        set_threads(1)
        one = rays.build(tri)
        set_threads(3)
        three = rays.build(tri)
    finally:
        set_threads(None)
    for a, b in zip(one, three, strict=True):
        assert np.array_equal(a, b)
    assert one.depth < 40 and one.nodes < tri.shape[0]


def brute_force(triangles: np.ndarray, origins: np.ndarray, directions: np.ndarray, with_t: bool = False):
    """The first hit's triangle of each ray by testing every triangle (Möller–Trumbore, the index's arithmetic in
    its order): the least t >= 0, ties to the lowest index; with `with_t` also its t (inf for a miss). Rays in
    pieces of at most 2**22 ray–triangle pairs."""
    piece = max(1, 2**22 // triangles.shape[0])
    if origins.shape[0] > piece:
        parts = [brute_force(triangles, origins[k : k + piece], directions[k : k + piece], True)
                 for k in range(0, origins.shape[0], piece)]  # fmt: skip
        face, t = np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])
        return (face, t) if with_t else face
    a = triangles[None, :, 0]
    e1, e2 = triangles[None, :, 1] - a, triangles[None, :, 2] - a
    d = directions[:, None]
    p = np.stack([d[..., 1] * e2[..., 2] - d[..., 2] * e2[..., 1], d[..., 2] * e2[..., 0] - d[..., 0] * e2[..., 2],
                  d[..., 0] * e2[..., 1] - d[..., 1] * e2[..., 0]], axis=-1)  # fmt: skip
    det = e1[..., 0] * p[..., 0] + e1[..., 1] * p[..., 1] + e1[..., 2] * p[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = origins[:, None] - a
        u = (s[..., 0] * p[..., 0] + s[..., 1] * p[..., 1] + s[..., 2] * p[..., 2]) * inv
        q = np.stack([s[..., 1] * e1[..., 2] - s[..., 2] * e1[..., 1], s[..., 2] * e1[..., 0] - s[..., 0] * e1[..., 2],
                      s[..., 0] * e1[..., 1] - s[..., 1] * e1[..., 0]], axis=-1)  # fmt: skip
        v = (d[..., 0] * q[..., 0] + d[..., 1] * q[..., 1] + d[..., 2] * q[..., 2]) * inv
        t = (e2[..., 0] * q[..., 0] + e2[..., 1] * q[..., 1] + e2[..., 2] * q[..., 2]) * inv
    hit = (det != 0.0) & (u >= 0.0) & (u <= 1.0) & (v >= 0.0) & (u + v <= 1.0) & (t >= 0.0)
    t = np.where(hit, t, np.inf)
    face = np.where(hit.any(axis=1), t.argmin(axis=1), -1)
    return (face, t.min(axis=1)) if with_t else face


def test_degenerate_inputs() -> None:
    # one triangle; identical triangles (every centre the same); a flat, axis-aligned soup
    one = rays.build(np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]]))
    hit = rays.closest_hits(one, np.array([[0.2, 0.2, 1.0], [2.0, 2.0, 1.0]]), np.array([[0, 0, -1.0], [0, 0, -1]]))
    assert hit.t.tolist() == [1.0, np.inf] and hit.face.tolist() == [0, -1]
    same = rays.build(np.repeat(np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]]), 50, axis=0))
    hit = rays.closest_hits(same, np.array([[0.2, 0.2, 1.0]]), np.array([[0, 0, -1.0]]))
    assert hit.face.tolist() == [0]  # a tie: the lowest index
    rng = np.random.default_rng(0)
    flat = rng.uniform(0, 1, (3000, 3, 3))
    flat[:, :, 2] = 0.0
    index = rays.build(flat)
    o = np.column_stack([rng.uniform(0, 1, (500, 2)), np.ones(500)])
    hits = rays.closest_hits(index, o, np.tile([0.0, 0.0, -1.0], (500, 1)))
    # every hit is at t = 1 up to rounding: the least t, ties to the lowest index, over all triangles
    brute = brute_force(flat, o, np.tile([0.0, 0.0, -1.0], (500, 1)))
    assert np.array_equal(hits.face, brute) and (hits.face >= 0).mean() > 0.9


# --- Scene.intersect / Scene.occluded ---------------------------------------------------------------------------


def two_item_scene() -> Scene:
    scene = Scene(lights=[DirectionalLight((0, 0, -1))])
    scene.add(Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=int)))  # an item with no faces: still numbered
    scene.add(uv_sphere(1.0, 48, 24), Material(), transform=translate(-1.5, 0, 0))
    mirrored = translate(1.5, 0, 0) @ reflect((1, 0, 0)) @ scale(0.5, 0.5, 0.5)
    scene.add(uv_sphere(1.0, 48, 24), Material(), transform=mirrored)
    return scene


def test_intersect_fields() -> None:
    scene = two_item_scene()
    origins = np.array([[-1.5, 0.0, 5.0], [1.5, 0.1, 5.0], [0.0, 0.0, 5.0], [-1.5, 0.0, 0.0]])
    hits = scene.intersect(origins, np.array([0.0, 0.0, -2.0]))
    assert isinstance(hits, RayHits)
    assert hits.item.tolist() == [1, 2, -1, 1]
    assert hits.t[2] == np.inf and np.isnan(hits.point[2]).all() and hits.face[2] == -1
    assert hits.t[0] == pytest.approx(2.0, abs=1e-2)  # t in units of the direction's length (2)
    np.testing.assert_allclose(hits.point[[0, 1, 3]], origins[[0, 1, 3]] + hits.t[[0, 1, 3], None] * [0, 0, -2.0])
    items = scene.items
    for r in (0, 1, 3):
        item = items[hits.item[r]]
        model = np.asarray(item.world_from_model)
        corners = item.mesh.vertices[item.mesh.faces[hits.face[r]]] @ model[:3, :3].T + model[:3, 3]
        np.testing.assert_allclose(hits.barycentrics[r] @ corners, hits.point[r], atol=1e-12)
        assert hits.barycentrics[r].sum() == pytest.approx(1.0)
        centre = model[:3, 3]
        radial = (hits.point[r] - centre) / np.linalg.norm(hits.point[r] - centre)
        assert hits.normal[r] @ radial > 0.99  # geometric normal: outward (front side), reflected item included
        assert hits.shading_normal[r] @ radial > 0.9999  # interpolated vertex normals: the sphere's normal
        assert np.linalg.norm(hits.normal[r]) == pytest.approx(1.0)
    assert hits.back.tolist() == [False, False, False, True]  # from inside the sphere: its back


def test_intersect_matches_pick_and_cache() -> None:
    scene = two_item_scene()
    camera = Camera.look_at((0, 0.3, 6), (0, 0, 0), (0, 1, 0), width=64, height=48)
    picked = scene.pick(camera, 20.5, 24.5)
    ray = camera.ray((20.5, 24.5))
    hits = scene.intersect(ray.origin, ray.direction)
    assert picked is not None and picked.face == hits.face[0] and picked.distance == hits.t[0]
    index = scene._triangle_index()[1]
    scene.intersect(ray.origin, ray.direction)
    assert scene._triangle_index()[1] is index  # built once
    scene.root.children[1].transform = rotate_y(0.3) @ translate(-1.5, 0, 0)
    assert scene._triangle_index()[1] is not index  # rebuilt when a transform changes


def test_occluded() -> None:
    scene = two_item_scene()
    origins = np.array([[-1.5, 0.0, 5.0], [-1.5, 0.0, 5.0], [0.0, 0.0, 5.0]])
    directions = np.array([[0.0, 0.0, -1.0]] * 3)
    assert scene.occluded(origins, directions, 3.0).tolist() == [False, False, False]
    assert scene.occluded(origins, directions, 4.5).tolist() == [True, True, False]
    assert scene.occluded(origins, directions, [4.5, 3.0, np.inf]).tolist() == [True, False, False]
    hits = scene.intersect(origins, directions)
    assert scene.occluded(origins, directions, np.where(np.isfinite(hits.t), hits.t, 1.0)).tolist() == [False] * 3
    assert Scene().occluded(origins, directions, 1.0).tolist() == [False] * 3
    assert Scene().intersect(origins, directions).item.tolist() == [-1] * 3


def test_bad_ray_input() -> None:
    scene = two_item_scene()
    with pytest.raises(FrustumError, match=r"Scene.intersect: origins = .* is not \(N, 3\)"):
        scene.intersect(np.zeros((2, 2)), np.ones((2, 3)))
    with pytest.raises(FrustumError, match="directions has a value that is not finite"):
        scene.intersect(np.zeros(3), [0.0, np.nan, 1.0])
    with pytest.raises(FrustumError, match=r"directions\[1\] is zero"):
        scene.intersect(np.zeros(3), [[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    with pytest.raises(FrustumError, match="2 origins and 3 directions"):
        scene.intersect(np.zeros((2, 3)), np.ones((3, 3)))
    with pytest.raises(FrustumError, match=r"t_max = .* below 0 or NaN"):
        scene.occluded(np.zeros(3), [0.0, 0.0, 1.0], -1.0)
    with pytest.raises(FrustumError, match=r"t_max = .* one number per ray \(1\)"):
        scene.occluded(np.zeros(3), [0.0, 0.0, 1.0], [1.0, 2.0])
    with pytest.raises(FrustumError, match="t_max = 'far' is not a number"):
        scene.occluded(np.zeros(3), [0.0, 0.0, 1.0], "far")
    with pytest.raises(FrustumError, match=r"fields has 'normals'; expected names from \('t', 'item'"):
        scene.intersect(np.zeros(3), [0.0, 0.0, 1.0], fields=("t", "normals"))
    with pytest.raises(FrustumError, match=r"fields = .* is not a non-empty list"):
        scene.intersect(np.zeros(3), [0.0, 0.0, 1.0], fields=[])


def test_intersect_field_subsets_equal_the_full_columns() -> None:
    """``fields=`` computes the columns asked for, each equal to the full call's (NaN where it is NaN), the
    others None; and the shading normals equal the textbook blend $(M₃⁻¹)ᵀ·Σ wᵢ·Nᵢ$, normalized."""
    scene = two_item_scene()
    rng = np.random.default_rng(2)
    origins = rng.uniform(-3.0, 3.0, (3000, 3)) * [1.0, 1.0, 0.2] + [0.0, 0.0, 4.0]
    origins[::4] = rng.uniform(-1.0, 1.0, (750, 3)) * 0.3 + [-1.5, 0.0, 0.0]  # inside a sphere: its back
    directions = rng.uniform(-1.0, 1.0, (3000, 3)) * [2.5, 1.2, 1.0] - origins
    full = scene.intersect(origins, directions)
    assert 0.1 < (full.item >= 0).mean() < 0.9 and full.back.dtype == bool
    for fields in (("t", "item", "face"), ("point",), ("shading_normal", "back"), ("barycentrics", "normal"),
                   ("face", "t"), "item"):  # fmt: skip
        subset = scene.intersect(origins, directions, fields=fields)
        names = (fields,) if isinstance(fields, str) else fields
        for name in RayHits._fields:
            if name in names:
                np.testing.assert_array_equal(getattr(subset, name), getattr(full, name))
            else:
                assert getattr(subset, name) is None
    items = scene.items
    rows = np.flatnonzero(full.item >= 0)
    for r in rows[:200]:
        item = items[full.item[r]]
        corners = item.mesh.faces[full.face[r]]
        blended = full.barycentrics[r] @ item.mesh.vertex_normals[corners]
        expected = blended @ np.linalg.inv(np.asarray(item.world_from_model)[:3, :3])
        np.testing.assert_allclose(full.shading_normal[r], expected / np.linalg.norm(expected), atol=1e-12)
    empty = Scene().intersect(origins[:3], directions[:3], fields=("t", "back"))
    assert empty.t.tolist() == [np.inf] * 3 and empty.back.tolist() == [False] * 3 and empty.item is None


def binary_hits(index: rays.Index, origins: np.ndarray, directions: np.ndarray, skip: np.ndarray | None = None,
                cull: bool = False, t_min: float = 0.0, t_max: float = np.inf) -> np.ndarray:  # fmt: skip
    """(N, 5) t, row, u, v, back of each ray by the binary tree's traversal (``rays._closest``, which
    ``cast_pixels`` and the step-by-step view use), one ray at a time."""
    stack, entry = np.empty(index.depth + 2, dtype=np.int64), np.empty(index.depth + 2)
    mask = np.empty(0, dtype=np.uint8) if skip is None else skip
    return np.array([rays._closest(index.boxes, index.links, index.triangles, index.order, mask, *o, *d, t_min, t_max,
                                   int(cull), stack, entry)[:5] for o, d in zip(origins, directions, strict=True)])


def assert_wide_equals_binary(index: rays.Index, origins: np.ndarray, directions: np.ndarray, **options) -> None:
    wide = rays.closest_hits(index, origins, directions, options.get("t_min", 0.0), options.get("t_max", np.inf),
                             options.get("skip"), options.get("cull", False))  # fmt: skip
    binary = binary_hits(index, origins, directions, **options)
    assert np.array_equal(wide.t, binary[:, 0])  # the same bits
    assert np.array_equal(wide.row, binary[:, 1].astype(np.int64))
    assert np.array_equal(wide.uv, binary[:, 2:4]) and np.array_equal(wide.back, binary[:, 4].astype(np.uint8))


def test_wide_traversal_gives_the_binary_traversals_hits_to_the_byte() -> None:
    """The four-wide tree's traversal (boxes four at a time, children sorted by entry) and the binary tree's
    (the nearer child first) find the same hit, bit for bit, with masks, culling and t ranges; the wide tree
    holds every triangle once and its boxes contain their children's."""
    rng = np.random.default_rng(9)
    tri = bunny_triangles()
    index = rays.build(tri)
    corners = tri.reshape(-1, 3)
    centre = 0.5 * (corners.min(axis=0) + corners.max(axis=0))
    radius = float(np.abs(corners - centre).max())
    o, d = camera_rays(centre, radius, 40, rng)
    assert_wide_equals_binary(index, o, d)
    o, d = inside_rays(centre, radius, 1500, rng)
    assert_wide_equals_binary(index, o, d)
    skip = (rng.random(tri.shape[0]) < 0.3).astype(np.uint8)
    assert_wide_equals_binary(index, o, d, skip=skip, cull=True, t_min=0.01 * radius, t_max=0.5 * radius)
    faces = rng.integers(0, tri.shape[0], 1500)  # through the corners and edges of faces: ties
    point = tri[faces, rng.integers(0, 3, 1500)] * 0.5 + tri[faces, rng.integers(0, 3, 1500)] * 0.5
    d = f32(rng.normal(size=(1500, 3)))
    assert_wide_equals_binary(index, f32(point - d), d)
    links = index.wide_links
    leaves = links[links < 0]
    codes = ~leaves
    assert np.sort(np.concatenate([np.arange(c >> 3, (c >> 3) + (c & 7)) for c in codes])).tolist() == list(
        range(tri.shape[0]))
    assert ((codes & 7) <= rays.LEAF_WIDE).all()
    for node in range(links.shape[0]):  # children inside their parent's slot of the node above
        for c in range(rays.WIDTH):
            child = links[node, c]
            if child >= 0:
                inner = index.wide_boxes[child]
                assert (inner[:3].min(axis=1) >= index.wide_boxes[node, :3, c]).all()
                assert (inner[3:].max(axis=1) <= index.wide_boxes[node, 3:, c]).all()


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), count=st.integers(1, 400), spread=st.floats(0.01, 3.0))
def test_wide_traversal_equals_binary_on_soups(seed: int, count: int, spread: float) -> None:
    rng = np.random.default_rng(seed)
    tri = f32(rng.uniform(-1.0, 1.0, (count, 1, 3)) + rng.normal(size=(count, 3, 3)) * spread * 0.3)
    if rng.random() < 0.3:  # coincident triangles: every tie
        tri = np.repeat(tri[:1], count, axis=0)
    index = rays.build(tri)
    origins, directions = f32(rng.uniform(-3.0, 3.0, (300, 3))), f32(rng.normal(size=(300, 3)))
    directions[::7, rng.integers(0, 3)] = 0.0  # axis-parallel rays: infinite inverse directions
    assert_wide_equals_binary(index, origins, directions)
    single = rays.build(tri, leaf_wide=1)  # one triangle a leaf: the same hits to the byte
    assert (single.wide_links < 0).sum() >= (index.wide_links < 0).sum()
    for a, b in zip(rays.closest_hits(single, origins, directions), rays.closest_hits(index, origins, directions),
                    strict=True):
        assert a.tobytes() == b.tobytes()
    t_max = f32(rng.uniform(0.0, 4.0, 300))
    assert np.array_equal(rays.any_hits(index, origins, directions, 0.0, t_max),
                          rays.closest_hits(index, origins, directions).t < t_max)  # fmt: skip


def test_vector_slab_test_equals_the_scalar_one() -> None:
    """``_slab4``'s LLVM vector code gives the bytes of its scalar form (``_slab4_scalar``), empty slots, rays
    parallel to a slab (an infinite inverse) and origins on a box's plane (0·∞ = NaN) included."""
    from numba import njit

    @njit
    def vector(boxes, node, nx, ny, nz, ox, oy, oz, ix, iy, iz, t_min, reach, near):
        rays._slab4(boxes, node, nx, ny, nz, ox, oy, oz, ix, iy, iz, t_min, reach, near)

    rng = np.random.default_rng(4)
    low = rng.integers(-4, 4, (50, 3, 4)).astype(np.float32)
    boxes = np.concatenate([low, low + rng.integers(0, 3, (50, 3, 4))], axis=1)
    boxes[::5, :3, 1], boxes[::5, 3:, 1] = np.inf, -np.inf  # an empty slot
    for _ in range(2000):
        node = int(rng.integers(0, 50))
        o = rng.integers(-5, 5, 3).astype(np.float64) + rng.choice([0.0, 0.5], 3)
        inverse = np.where(rng.random(3) < 0.2, np.inf, rng.normal(size=3))
        inverse = np.where(rng.random(3) < 0.5, inverse, -inverse)
        rows = [a if inverse[a] >= 0.0 else a + 3 for a in range(3)]
        reach = float(rng.choice([np.inf, 3.0, 0.5]))
        ours, theirs = np.empty(4), np.empty(4)
        vector(boxes, node, *rows, *o, *inverse, 0.0, reach, ours)
        with np.errstate(invalid="ignore"):  # 0·∞
            rays._slab4_scalar(boxes, node, *rows, *o, *inverse, 0.0, reach, theirs)
        assert np.array_equal(ours, theirs, equal_nan=True)
