"""Octrees: building, measures, set operations against numpy, the octree visible-surface method against the
depth buffer, ray queries and Scene.pick against brute force, and bad input."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

import frustum
from frustum import (
    Camera,
    DirectionalLight,
    FrustumError,
    GeometryError,
    Material,
    Mesh,
    Octree,
    Orthographic,
    Perspective,
    Scene,
    box,
    icosphere,
    render,
    render_octree,
    rotate_x,
    rotate_y,
    torus,
    translate,
)
from frustum.geometry.fractals.solids import _menger_cells
from frustum.geometry.octree import TEXTBOOK_OCTANTS, morton_decode, morton_encode
from testdata import DATA, closed_bunny

UNIT = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]
CUBE = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]


def _random_solid(seed: int, n: int = 16) -> np.ndarray:
    """A dense (n, n, n) bool array with structure at several scales (so nodes merge at several levels)."""
    rng = np.random.default_rng(seed)
    coarse = rng.random((4, 4, 4)) < 0.4
    grid = np.repeat(np.repeat(np.repeat(coarse, n // 4, 0), n // 4, 1), n // 4, 2)
    return grid ^ (rng.random((n, n, n)) < 0.08)


# --- storage and numbering -------------------------------------------------------------------------------


def test_morton_codes_round_trip_and_children_follow_x_plus_2y_plus_4z():
    rng = np.random.default_rng(0)
    ijk = rng.integers(0, 2**20, size=(1000, 3))
    assert np.array_equal(morton_decode(morton_encode(ijk)), ijk)
    parent = morton_encode([[3, 5, 6]])[0]
    for o in range(8):
        child = morton_decode([(int(parent) << 3) | o])[0]
        assert child.tolist() == [6 + (o & 1), 10 + ((o >> 1) & 1), 12 + ((o >> 2) & 1)]
    # textbook: front (z high) octants 0-3, back 4-7, same (x, y) quadrant order
    assert [int(TEXTBOOK_OCTANTS[x + 2 * y + 4 * 1]) for y in (0, 1) for x in (0, 1)] == [0, 1, 2, 3]
    assert [int(TEXTBOOK_OCTANTS[x + 2 * y]) for y in (0, 1) for x in (0, 1)] == [4, 5, 6, 7]


def test_from_voxels_round_trips_and_stores_maximal_nodes():
    voxels = _random_solid(1)
    tree = Octree.from_voxels(voxels, UNIT)
    assert np.array_equal(tree.to_voxels(), voxels)
    assert tree.full_cell_count == voxels.sum()
    assert tree.volume == voxels.sum() / 16**3
    # a full cube is one node at the root; an empty region has none
    assert Octree.from_voxels(np.ones((8, 8, 8), bool), UNIT).level_counts.tolist() == [[1, 0], [0, 0], [0, 0], [0, 0]]
    assert Octree.from_voxels(np.zeros((8, 8, 8), bool), UNIT).node_count == 0


def test_deep_surface_octree_stays_small():
    sphere = Octree.from_function(lambda x, y, z: x * x + y * y + z * z - 0.6**2, CUBE, 9)
    # a 512^3 dense array would be 128 MiB; the linear octree holds about the surface cells only
    assert sphere.nbytes < 16 * 2**20
    assert abs(sphere.volume - 4 / 3 * math.pi * 0.6**3) < 2e-3


# --- volumes ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "f, exact",
    [
        (lambda x, y, z: x * x + y * y + z * z - 0.7**2, 4 / 3 * math.pi * 0.7**3),
        (
            lambda x, y, z: (x / 0.9) ** 2 + (y / 0.5) ** 2 + ((z - 0.1) / 0.3) ** 2 - 1.0,
            4 / 3 * math.pi * 0.9 * 0.5 * 0.3,
        ),
    ],
    ids=["sphere", "ellipsoid"],
)
def test_sampled_volume_converges_inside_volume_bounds(f, exact):
    errors, widths = [], []
    for depth in range(2, 9):
        tree = Octree.from_function(f, CUBE, depth)
        low, high = tree.volume_bounds
        assert low <= exact <= high, (depth, low, exact, high)
        assert low <= tree.volume <= high
        errors.append(abs(tree.volume - exact))
        widths.append(high - low)
    assert all(b < a for a, b in itertools.pairwise(widths))  # the bracket halves with each level
    assert errors[-1] < 2e-3 * exact and errors[-1] < errors[0]


def test_box_aligned_with_cells_is_exact():
    mesh = box((0.5, 0.25, 0.75), center=(0.25, 0.125 + 0.25, 0.375))
    tree = Octree.from_mesh(mesh, 5, bounds=UNIT)
    assert tree.volume == 0.5 * 0.25 * 0.75
    expected = np.zeros((32, 32, 32), bool)
    expected[0:16, 8:16, 0:24] = True
    assert np.array_equal(tree.to_voxels(), expected)
    implicit = Octree.from_function(
        lambda x, y, z: np.maximum.reduce(
            [np.abs(x - 0.25) - 0.25, np.abs(y - 0.375) - 0.125, np.abs(z - 0.375) - 0.375]
        ),
        UNIT,
        5,
    )
    # cell-aligned faces: every finest cell is inside or outside, decided exactly
    assert implicit.volume == 0.5 * 0.25 * 0.75


def test_from_mesh_sphere_converges_to_mesh_volume():
    mesh = icosphere(1.0, 3)
    for depth in (4, 6):
        tree = Octree.from_mesh(mesh, depth)
        low, high = tree.volume_bounds
        assert low <= mesh.volume <= high
    assert abs(tree.volume - mesh.volume) < 0.01 * mesh.volume


def test_from_mesh_region_inside_the_solid_is_one_full_node_whatever_the_winding():
    ball = icosphere(2.0, 2)
    for mesh in (ball, ball.flipped()):
        inner = Octree.from_mesh(mesh, 3, bounds=[[-0.5] * 3, [0.5] * 3])
        assert inner.level_counts[0].tolist() == [1, 0] and inner.volume == 1.0
        assert Octree.from_mesh(mesh, 4) == Octree.from_mesh(ball, 4)


def _closed_bunny() -> Mesh:
    """The Stanford bunny with its 5 bottom holes closed by fans from each hole's centroid (``testdata``)."""
    closed = closed_bunny()
    assert closed.is_watertight
    return closed


@pytest.mark.parametrize("name", ["bunny", "torus"])
def test_occupancy_matches_trimesh_voxelize_and_fill_away_from_the_surface(name):
    mesh = _closed_bunny() if name == "bunny" else torus(1.0, 0.35, 48, 24)
    depth = 6
    extent = float((mesh.bounds[1] - mesh.bounds[0]).max())
    pitch = extent / 56.0
    # trimesh voxel centres sit at integer multiples of the pitch: align our cells with them
    lo = (np.floor(mesh.bounds[0] / pitch) - 3.5) * pitch
    bounds = [lo, lo + pitch * 2**depth]
    tree = Octree.from_mesh(mesh, depth, bounds=bounds)
    ours = tree.to_voxels()
    shell = trimesh.voxel.creation.voxelize(trimesh.Trimesh(mesh.vertices, mesh.faces, process=False), pitch)
    filled = shell.copy().fill()
    theirs = np.zeros_like(ours)
    band = np.zeros_like(ours)
    for grid, points in ((theirs, filled.points), (band, shell.points)):
        ijk = np.floor((points - lo) / pitch).astype(int)
        grid[ijk[:, 0], ijk[:, 1], ijk[:, 2]] = True
    from scipy.ndimage import binary_dilation

    # cells within one cell of the surface (trimesh's surface voxels, dilated by one) are left out
    away = ~binary_dilation(band, structure=np.ones((3, 3, 3), bool))
    agree = (ours == theirs)[away].mean()
    assert theirs[away].sum() > 1000  # the comparison covers a real interior
    assert agree >= 0.999, agree


def test_open_mesh_is_refused_with_its_boundary_edge_count_or_taken_as_a_shell():
    data = trimesh.load(DATA / "bunny" / "bun_zipper_res4.ply", process=False, force="mesh")
    bunny = Mesh(np.asarray(data.vertices), np.asarray(data.faces))
    open_edges = int((np.unique(np.sort(bunny.welded().faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1),
                                axis=0, return_counts=True)[1] == 1).sum())  # fmt: skip
    with pytest.raises(GeometryError, match=rf"open \({open_edges} boundary edges\).*shell=True"):
        Octree.from_mesh(bunny, 4)
    shell = Octree.from_mesh(bunny, 5, shell=True)
    # every vertex lies in (or on the face of) a shell cell
    probe = bunny.vertices[np.unique(bunny.faces)]
    assert shell.contains(probe).mean() > 0.99
    assert 0 < shell.full_cell_count < 0.2 * 8**5 and not shell.boundary.size < shell.full_cell_count


# --- fractals -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("level", [0, 1, 2, 3])
def test_menger_sponge_has_20_to_the_n_full_finest_cells(level):
    tree = Octree.menger_sponge(level, size=2.0)
    assert tree.full_cell_count == 20**level
    assert tree.cell_size == pytest.approx(2.0 / 3**level)
    assert tree.volume == pytest.approx(8.0 * (20 / 27) ** level)
    voxels = tree.to_voxels()
    cells = _menger_cells(level)
    assert voxels[cells[:, 0], cells[:, 1], cells[:, 2]].all() and voxels.sum() == 20**level


def test_sierpinski_tetrahedron_keeps_four_octants_per_level():
    tree = Octree.sierpinski_tetrahedron(4)
    assert tree.full_cell_count == 4**4 and tree.level_counts[:, 1].tolist() == [1, 4, 16, 64, 0]
    ijk = morton_decode(tree.full[4])
    # at every level the kept octant has an even number of high halves: octants 0, 3, 5, 6
    for bit in range(4):
        assert (((ijk >> bit) & 1).sum(axis=1) % 2 == 0).all()
    # every kept cube's centre lies in the regular tetrahedron (0,0,0), (1,1,0), (1,0,1), (0,1,1)
    corners = np.array([[0, 0, 0], [1, 1, 0], [1, 0, 1], [0, 1, 1]], dtype=float)
    centres = (ijk + 0.5) / 16
    barycentric = np.linalg.solve(np.vstack([corners.T, np.ones(4)]), np.vstack([centres.T, np.ones(len(ijk))]))
    assert (barycentric >= -1e-12).all()


# --- set operations -----------------------------------------------------------------------------------------


@settings(max_examples=25)
@given(st.integers(0, 2**31), st.integers(0, 2**31))
def test_set_operations_equal_numpy_boolean_operations(seed_a, seed_b):
    a_vox, b_vox = _random_solid(seed_a), _random_solid(seed_b)
    a, b = Octree.from_voxels(a_vox, UNIT), Octree.from_voxels(b_vox, UNIT)
    for result, expected in ((a | b, a_vox | b_vox), (a & b, a_vox & b_vox), (a - b, a_vox & ~b_vox)):
        assert np.array_equal(result.to_voxels(), expected)
        assert result == Octree.from_voxels(expected, UNIT)  # canonical: equal sets, identical arrays
        for mine, canonical in zip(result.full, Octree.from_voxels(expected, UNIT).full, strict=True):
            assert np.array_equal(mine, canonical)
    assert np.array_equal(a.complement().to_voxels(), ~a_vox)


@settings(max_examples=25)
@given(st.integers(0, 2**31), st.integers(0, 2**31))
def test_set_identities(seed_a, seed_b):
    a, b = Octree.from_voxels(_random_solid(seed_a), UNIT), Octree.from_voxels(_random_solid(seed_b), UNIT)
    empty = Octree.from_voxels(np.zeros((16, 16, 16), bool), UNIT)
    assert a | a == a and a & a == a
    assert (a & empty).is_empty and (a - a).is_empty
    assert a | empty == a
    assert (a | b).complement() == a.complement() & b.complement()  # De Morgan within the region
    assert (a & b).complement() == a.complement() | b.complement()
    assert a - b == a & b.complement()
    assert a | b == b | a and a & b == b & a


def test_set_operations_mix_depths_and_moves_by_whole_cells_are_exact():
    a_vox = _random_solid(7)
    a = Octree.from_voxels(a_vox, UNIT)
    coarse_vox = _random_solid(8, 8)
    coarse = Octree.from_voxels(coarse_vox, UNIT)
    mixed = a | coarse
    assert mixed.depth == 4
    assert np.array_equal(mixed.to_voxels(), a_vox | np.kron(coarse_vox, np.ones((2, 2, 2))).astype(bool))
    moved = a.shifted((3, -2, 5))
    expected = np.zeros_like(a_vox)
    expected[3:16, 0:14, 5:16] = a_vox[0:13, 2:16, 0:11]
    assert np.array_equal(moved.to_voxels(), expected)


def test_transformed_resamples_a_cell_move_exactly():
    a = Octree.from_voxels(_random_solid(9), UNIT)
    assert a.transformed(translate(2 / 16, 0.0, 0.0)) == a.shifted((2, 0, 0))


# --- conversions --------------------------------------------------------------------------------------------


def test_to_mesh_is_closed_outward_and_encloses_the_octree_volume():
    sphere = Octree.from_function(lambda x, y, z: x * x + y * y + z * z - 0.8**2, CUBE, 5)
    hollow = sphere - Octree.from_function(lambda x, y, z: x * x + y * y + z * z - 0.5**2, CUBE, 5)
    for tree in (sphere, hollow):
        mesh = tree.to_mesh()
        assert mesh.is_watertight
        assert mesh.volume == pytest.approx(tree.volume, rel=1e-12)
    smooth = sphere.to_mesh(smooth=True)
    assert smooth.is_watertight and smooth.volume > 0
    assert smooth.volume == pytest.approx(4 / 3 * math.pi * 0.8**3, rel=0.05)


def test_from_points_marks_the_cells_that_hold_points():
    rng = np.random.default_rng(3)
    points = rng.random((500, 3)) * 0.999
    tree = Octree.from_points(points, 4, bounds=UNIT)
    expected = np.zeros((16, 16, 16), bool)
    ijk = np.floor(points * 16).astype(int)
    expected[ijk[:, 0], ijk[:, 1], ijk[:, 2]] = True
    assert np.array_equal(tree.to_voxels(), expected)
    assert tree.contains(points).all()


# --- the octree visible-surface method ----------------------------------------------------------------------


def _csg_solid() -> Octree:
    ball = Octree.from_function(lambda x, y, z: x * x + y * y + z * z - 0.8**2, CUBE, 5)
    bite = Octree.from_function(lambda x, y, z: (x - 0.5) ** 2 + (y - 0.5) ** 2 + (z - 0.5) ** 2 - 0.5**2, CUBE, 5)
    slab = Octree.from_function(lambda x, y, z: np.abs(y + 0.2) - 0.15, CUBE, 5)
    return (ball - bite) - slab


# The depth buffer snaps corners to 1/256 pixel, so its depth is off by up to |∇z|/512 (∇z per pixel); the
# perspective camera stands back (~16 units, narrow field, near 0.5) so that this stays well below 1e-6.
@pytest.mark.parametrize("projection, distance", [(Perspective(math.pi / 12, 0.5, 100.0), 4.0),
                                                   (Orthographic(3.0, 0.1, 100.0), 1.0)],
                         ids=["perspective", "parallel"])  # fmt: skip
def test_octree_method_equals_depth_buffer_of_to_mesh(projection, distance):
    tree = _csg_solid()
    lights = [DirectionalLight((-0.4, -0.6, -1.0))]
    for eye in ((2.2, 1.7, 2.9), (-2.5, -1.2, 1.9)):
        eye = tuple(distance * c for c in eye)
        camera = Camera.look_at(eye, (0.0, 0.0, 0.0), projection=projection, width=200, height=160)
        frame = render_octree(tree, camera, lights=lights)
        scene = Scene(lights=lights)
        scene.add(tree.to_mesh())
        reference = render(scene, camera, shading="flat")
        ours, theirs = frame.depth < 1.0, reference.depth < 1.0
        assert (ours == theirs).mean() >= 0.999
        both = ours & theirs
        close = np.abs(frame.depth[both].astype(np.float64) - reference.depth[both]) <= 1e-6
        assert close.mean() >= 0.999  # edge pixels lying exactly on a cell edge may take the other face
        assert both.sum() > 2000


def test_octree_nodes_in_a_scene_are_drawn_picked_and_cut_as_their_cell_faces():
    from frustum import cutaway

    tree = Octree.from_voxels(np.ones((4, 4, 4), bool), UNIT)
    scene = Scene()
    node = scene.add(tree, name="cells")
    assert "octree of depth 2" in repr(node)
    camera = Camera.look_at((0.5, 0.5, 3.0), (0.5, 0.5, 0.5), width=32, height=32)
    pick = scene.pick(camera, 16.0, 16.0)
    assert pick is not None and pick.point[2] == pytest.approx(1.0)
    cut = cutaway(scene, plane=((0.5, 0.5, 0.5), (0.0, 0.0, 1.0)))
    assert cut.items[0].mesh.bounds[1][2] == pytest.approx(0.5)


def test_render_method_octree_draws_the_scene_octrees_and_keeps_the_nearest():
    tree = _csg_solid()
    scene = Scene(lights=[DirectionalLight((0.0, 0.0, -1.0))])
    scene.add(tree, Material((0.9, 0.3, 0.2)))
    scene.add(tree, Material((0.2, 0.3, 0.9)), translate(1.2, 0.0, -1.0) @ rotate_y(0.7) @ rotate_x(-0.4))
    camera = Camera.look_at((0.0, 0.5, 4.0), (0.4, 0.0, 0.0), width=160, height=120)
    frame = render(scene, camera, method="octree")
    alone = Scene(lights=scene.lights)
    alone.add(tree.to_mesh(), Material((0.9, 0.3, 0.2)))
    alone.add(tree.to_mesh(), Material((0.2, 0.3, 0.9)), translate(1.2, 0.0, -1.0) @ rotate_y(0.7) @ rotate_x(-0.4))
    reference = render(alone, camera, shading="flat")
    assert ((frame.depth < 1) == (reference.depth < 1)).mean() >= 0.999
    # each face orientation is shaded once: at most 6 colors per octree (2 octrees here) where cells are seen
    seen = frame.color[frame.depth < 1][:, :3]
    assert 3 <= np.unique(seen, axis=0).shape[0] <= 12
    with pytest.raises(FrustumError, match=r"method = 'ray' is unknown"):
        render(scene, camera, method="ray")


def test_octree_method_prunes_covered_nodes():
    from frustum.visibility.octree import draw_octree_into, octree_face_colors

    solid = Octree.from_function(lambda x, y, z: x * x + y * y + z * z - 0.9**2, CUBE, 7)
    camera = Camera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), width=64, height=64)
    color = np.zeros((64, 64, 4), np.uint8)
    depth = np.ones((64, 64), np.float32)
    written = np.zeros((64, 64), bool)
    faces = octree_face_colors(solid, Material(), [], np.eye(4), camera.frame.eye)
    visited = draw_octree_into(solid, camera, np.eye(4), faces, color, depth, written)
    # without pruning every partial node's 8 children would be visited; the covered back half is skipped
    assert visited < 0.6 * (1 + 8 * solid.level_counts[:, 1].sum())


# --- ray queries and picking --------------------------------------------------------------------------------


def _slab_hits(boxes: np.ndarray, origins: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Brute force: nearest entry t >= 0 of each ray into any box (inf if none)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / directions
        t0 = (boxes[None, :, 0] - origins[:, None]) * inv[:, None]
        t1 = (boxes[None, :, 1] - origins[:, None]) * inv[:, None]
    near = np.nanmax(np.minimum(t0, t1), axis=2)
    far = np.nanmin(np.maximum(t0, t1), axis=2)
    near = np.maximum(near, 0.0)
    t = np.where(near <= far, near, np.inf)
    return t.min(axis=1)


def test_ray_hits_equal_brute_force_ray_box_tests():
    tree = _csg_solid()
    rng = np.random.default_rng(5)
    origins = rng.normal(size=(300, 3)) * 0.3 + rng.choice([-3.0, 3.0], size=(300, 3))
    targets = rng.uniform(-0.9, 0.9, size=(300, 3))
    directions = targets - origins
    hits = tree.ray_hits(origins, directions)
    expected = _slab_hits(tree.leaf_boxes(), origins, directions)
    assert np.array_equal(hits.hit, np.isfinite(expected))
    assert np.allclose(hits.distance[hits.hit], expected[hits.hit], rtol=0, atol=1e-9)
    assert hits.hit.sum() > 100
    # the leaf reported holds the hit point
    boxes = tree.leaf_boxes()
    levels, codes = tree.leaves()
    for i in np.flatnonzero(hits.hit)[:50]:
        k = np.flatnonzero((levels == hits.level[i]) & (codes == hits.code[i]))[0]
        assert (boxes[k, 0] - 1e-9 <= hits.point[i]).all() and (hits.point[i] <= boxes[k, 1] + 1e-9).all()
    inside = tree.ray_hits([0.0, 0.0, -0.6], [1.0, 0.0, 0.0])
    assert inside.hit and inside.distance == 0.0


def _brute_force_pick(scene: Scene, origin: np.ndarray, direction: np.ndarray):
    best = (np.inf, None, -1)
    for index, item in enumerate(scene.items):
        m = item.world_from_model
        tri = item.mesh.vertices[item.mesh.faces] @ m[:3, :3].T + m[:3, 3]
        e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        p = np.cross(direction, e2)
        det = e1 @ p if e1.ndim == 1 else np.einsum("ij,ij->i", e1, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = origin - tri[:, 0]
            u = np.einsum("ij,ij->i", s, p) / det
            q = np.cross(s, e1)
            v = (q @ direction) / det
            t = np.einsum("ij,ij->i", e2, q) / det
        ok = (det != 0) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= 0)
        if ok.any():
            j = int(np.flatnonzero(ok)[np.argmin(t[ok])])
            if t[j] < best[0]:
                best = (float(t[j]), index, j)
    return best


def test_pick_equals_brute_force_over_all_triangles():
    scene = Scene()
    scene.add(icosphere(1.0, 3))
    scene.add(torus(0.8, 0.25), transform=translate(1.5, 0.3, -0.5))
    scene.add(box((0.6, 0.6, 0.6)), transform=translate(-1.4, -0.2, 0.3))
    camera = Camera.look_at((0.3, 0.8, 3.4), (0.0, 0.0, 0.0), width=120, height=90)
    rng = np.random.default_rng(2)
    found = 0
    for x, y in rng.uniform([0, 0], [120, 90], size=(200, 2)):
        pick = scene.pick(camera, x, y)
        ray = camera.ray((x, y))
        t, index, face = _brute_force_pick(scene, ray.origin, ray.direction)
        if index is None:
            assert pick is None
            continue
        found += 1
        assert pick is not None and pick.item.mesh is scene.items[index].mesh and pick.face == face
        assert pick.distance == pytest.approx(t, abs=1e-9)
        assert np.allclose(pick.point, ray.origin + t * ray.direction, atol=1e-9)
    assert found > 40
    assert Scene().pick(camera, 10, 10) is None


def test_pick_agrees_with_the_rendered_object_id():
    scene = Scene()
    scene.add(icosphere(1.0, 3))
    scene.add(box((0.8, 0.8, 0.8)), transform=translate(0.9, 0.0, 0.8))
    camera = Camera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), width=64, height=48)
    frame = render(scene, camera, buffers=("object_id",))
    ids = [item.mesh for item in scene.items]
    for row, column in [(24, 32), (24, 44), (10, 10), (30, 38)]:
        pick = scene.pick(camera, column + 0.5, 48 - row - 0.5)
        expected = frame.object_id[row, column]
        assert (pick is None) == (expected < 0)
        if pick is not None:
            assert ids.index(pick.item.mesh) == expected


# --- bad input ----------------------------------------------------------------------------------------------


def test_depth_over_the_memory_budget_names_estimate_budget_and_parameter():
    message = r"depth = 12 needs about .* over the memory budget of 64\.0 MiB.*set_budget"
    with frustum.budget(bytes="64M"), pytest.raises(GeometryError, match=message):
        Octree.from_function(lambda x, y, z: x, CUBE, 12)
    with pytest.raises(GeometryError, match=r"depth = 16 needs about"):
        Octree.from_function(lambda x, y, z: x, CUBE, 16)
    with frustum.budget(bytes="1M"), pytest.raises(GeometryError, match=r"Octree.to_voxels: depth = 7 needs about"):
        Octree.from_voxels(np.ones((4, 4, 4), bool), UNIT).to_voxels(7)


def test_set_operations_on_different_regions_are_refused():
    a = Octree.from_voxels(np.ones((4, 4, 4), bool), UNIT)
    b = Octree.from_voxels(np.ones((4, 4, 4), bool), [[0, 0, 0], [2, 2, 2]])
    with pytest.raises(GeometryError, match=r"Octree.union: other.bounds = .* differs .* same region"):
        a | b
    with pytest.raises(GeometryError, match=r"other = 3 is not an Octree"):
        a.intersection(3)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: Octree.from_function(lambda x, y, z: x, [[0, 0, np.nan], [1, 1, 1]], 3), r"bounds = .* is not finite"),
        (lambda: Octree.from_function(lambda x, y, z: x, [[0, 0, 0], [1, 1, np.inf]], 3), r"is not finite"),
        (lambda: Octree.from_voxels(np.ones((4, 4, 4), bool), [[0, 0, 0], [1, 2, 1]]), r"is not a cube"),
        (lambda: Octree.from_voxels(np.ones((3, 3, 3), bool), UNIT), r"n a power of two"),
        (lambda: Octree.from_voxels(np.ones((4, 4, 4)), UNIT), r"dtype float64; expected bool"),
        (lambda: Octree.from_function(lambda x, y, z: x, CUBE, -1), r"depth = -1 is below 0"),
        (lambda: Octree.from_function(lambda x, y, z: x, CUBE, 2.5), r"depth = 2.5 is not an integer"),
        (lambda: Octree.from_function(lambda x, y, z: x, CUBE, 21), r"depth = 21 is above 20"),
        (lambda: Octree.from_function(lambda x, y, z: x[:3], CUBE, 2), r"f returned shape \(3,\)"),
        (lambda: Octree.from_function(lambda x, y, z: np.full_like(x, np.inf), CUBE, 2), r"is not finite"),
        (lambda: Octree.from_function(3, CUBE, 2), r"f = 3 is not callable"),
        (lambda: Octree.from_mesh("mesh", 3), r"mesh = 'mesh' is not a Mesh"),
        (lambda: Octree.from_points([[0, 0, np.nan]], 3), r"points\[0\] = .* is not finite"),
        (lambda: Octree.from_voxels(np.ones((2, 2, 2), bool), UNIT).shifted((1.5, 0, 0)), r"is not 3 integers"),
        (lambda: Octree.from_voxels(np.ones((2, 2, 2), bool), UNIT).ray_hits([0, 0, 0], [0, 0, 0]), r"zero length"),
    ],
)
def test_bad_input_raises_geometry_error(call, message):
    with pytest.raises(GeometryError, match=message):
        call()


def test_render_octree_and_pick_reject_bad_arguments():
    tree = Octree.from_voxels(np.ones((2, 2, 2), bool), UNIT)
    camera = Camera.look_at((0, 0, 3), (0, 0, 0), width=8, height=8)
    with pytest.raises(FrustumError, match=r"octree = 'x' is not an Octree"):
        render_octree("x", camera)
    with pytest.raises(FrustumError, match=r"background = .* is not an RGBA color"):
        render_octree(tree, camera, background=(2, 0, 0, 1))
    with pytest.raises(FrustumError, match=r"camera = 1 is not a Camera"):
        Scene().pick(1, 0, 0)
    with pytest.raises(FrustumError, match=r"x = nan is not finite"):
        Scene().pick(camera, float("nan"), 0)


# --- scene files --------------------------------------------------------------------------------------------


def test_scene_file_octree_geometry_and_method(tmp_path: Path):
    from frustum import load_scene_file

    text = """
[render]
size = [64, 48]
method = "octree"

[camera]
eye = [3.0, 2.0, 3.0]

[[nodes]]
geometry = { type = "octree", depth = 4, source = { type = "box", size = [1.0, 1.0, 1.0] } }
"""
    path = tmp_path / "scene.toml"
    path.write_text(text)
    loaded = load_scene_file(path)
    tree = loaded.scene.octrees[0].mesh
    assert isinstance(tree, Octree) and tree.depth == 4 and tree.volume == pytest.approx(1.0)
    assert loaded.options["method"] == "octree"
    frame = render(loaded.scene, loaded.cameras[0], **loaded.options)
    assert (frame.depth < 1).sum() > 100
    # the depth buffer draws the same node as its cell faces
    assert loaded.scene.items[0].mesh.face_count == tree.surface.face_count


@pytest.mark.parametrize(
    "geometry, message",
    [
        ('{ type = "octree", depth = 4 }', r"scene.toml:\d+: nodes\[0\].geometry.source is missing"),
        ('{ type = "octree", depth = 40, source = { type = "box" } }', r"nodes\[0\].geometry.depth = 40"),
        ('{ type = "octree", source = { type = "koch_snowflake", level = 1 } }', r"is not a solid"),
        ('{ type = "octree", source = { type = "plane" } }', r"boundary edges"),
        ('{ type = "octree", source = { type = "box" }, colour = 1 }', r"colour"),
    ],
)
def test_scene_file_octree_errors_name_file_line_and_key(tmp_path: Path, geometry: str, message: str):
    from frustum import SceneFileError, load_scene_file

    path = tmp_path / "scene.toml"
    path.write_text(f"[camera]\neye = [3.0, 2.0, 3.0]\n\n[[nodes]]\ngeometry = {geometry}\n")
    with pytest.raises(SceneFileError, match=message):
        load_scene_file(path)
    path.write_text('[render]\nmethod = "ray"\n\n[camera]\neye = [3.0, 2.0, 3.0]\n')
    with pytest.raises(SceneFileError, match=r"render.method = 'ray' is unknown|render.method = 'ray'"):
        load_scene_file(path)
