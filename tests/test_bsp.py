"""BSP tree and painter's depth sort: back-to-front order checked against a depth buffer, pixel by pixel.

The oracle is a tiny numpy z-buffer written here: each triangle is rasterized at pixel centers (inclusive
edge test) with its window depth interpolated linearly in screen space (exact for window depth, an affine
function of the window position over a planar polygon), and the nearest triangle's id kept. The painter
fills each returned fragment, in order, with the same pixel rule and overwrites. Both see the same
``Camera.project`` window coordinates. A pixel where two faces are exactly equally near (coincident faces in
the bunny) may show either.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum import Camera, CameraError, GeometryError, Mesh, Oblique, Orthographic, Perspective
from frustum.transforms import apply, translate
from frustum.visibility.bsp import BSPTree
from frustum.visibility.depth_sort import DepthOrder, depth_sort
from testdata import DATA

WIDTH, HEIGHT = 120, 90
AGREEMENT = 0.995  # of the pixels the depth buffer covers; misses are pixels on the lines where triangles meet


def perspective_camera() -> Camera:
    return Camera.look_at((0.4, 0.3, 4.0), (0, 0, 0), (0, 1, 0), Perspective(0.9, 0.5, 20.0), WIDTH, HEIGHT)


def orthographic_camera() -> Camera:
    return Camera.look_at((1.0, 0.8, 5.0), (0, 0, 0), (0, 1, 0), Orthographic(3.0, 0.5, 20.0), WIDTH, HEIGHT)


def _pixel_grid(low: np.ndarray, high: np.ndarray):
    x0, y0 = max(math.floor(low[0] - 0.5), 0), max(math.floor(low[1] - 0.5), 0)
    x1, y1 = min(math.ceil(high[0] - 0.5), WIDTH - 1), min(math.ceil(high[1] - 0.5), HEIGHT - 1)
    if x1 < x0 or y1 < y0:
        return None
    px, py = np.meshgrid(np.arange(x0, x1 + 1) + 0.5, np.arange(y0, y1 + 1) + 0.5)
    return px, py


def _inside(window: np.ndarray, px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """Pixel centers inside a convex window polygon (either winding), edges included."""
    x, y = window[:, 0], window[:, 1]
    crosses = [
        (x[(i + 1) % len(x)] - x[i]) * (py - y[i]) - (y[(i + 1) % len(x)] - y[i]) * (px - x[i]) for i in range(len(x))
    ]
    stack = np.array(crosses)
    return (stack >= -1e-9).all(axis=0) | (stack <= 1e-9).all(axis=0)


def _triangle_depths(triangle: np.ndarray, camera: Camera, px: np.ndarray, py: np.ndarray):
    """Window depth of the triangle's plane at pixel centers and whether each center is inside (edges too)."""
    window = camera.project(triangle)
    (x0, y0), (x1, y1), (x2, y2) = window[:, :2]
    area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    if area == 0.0:
        return np.full(px.shape, np.inf), np.zeros(px.shape, dtype=bool)
    b1 = ((px - x0) * (y2 - y0) - (x2 - x0) * (py - y0)) / area
    b2 = ((x1 - x0) * (py - y0) - (px - x0) * (y1 - y0)) / area
    b0 = 1.0 - b1 - b2
    return b0 * window[0, 2] + b1 * window[1, 2] + b2 * window[2, 2], (b0 >= 0) & (b1 >= 0) & (b2 >= 0)


def depth_buffer(triangles: np.ndarray, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) id of the nearest triangle at each pixel center (y up, −1 where none) and its depth."""
    ids = np.full((HEIGHT, WIDTH), -1)
    depth = np.full((HEIGHT, WIDTH), np.inf)
    for index, triangle in enumerate(triangles):
        window = camera.project(triangle)
        grid = _pixel_grid(window.min(axis=0), window.max(axis=0))
        if grid is None:
            continue
        px, py = grid
        z, inside = _triangle_depths(triangle, camera, px, py)
        rows, cols = (py - 0.5).astype(int), (px - 0.5).astype(int)
        closer = inside & (z < depth[rows, cols])
        depth[rows[closer], cols[closer]] = z[closer]
        ids[rows[closer], cols[closer]] = index
    return ids, depth


def painted_ids(fragments, camera: Camera) -> np.ndarray:
    """(H, W) id of the last fragment painted over each pixel center, −1 where none."""
    ids = np.full((HEIGHT, WIDTH), -1)
    for polygon, label in fragments:
        window = camera.project(polygon)
        grid = _pixel_grid(window.min(axis=0), window.max(axis=0))
        if grid is None:
            continue
        px, py = grid
        inside = _inside(window, px, py)
        ids[(py[inside] - 0.5).astype(int), (px[inside] - 0.5).astype(int)] = label
    return ids


def agreement(fragments, triangles, camera) -> float:
    """Fraction of the depth buffer's covered pixels where the painter shows the nearest triangle.

    A pixel where the painted triangle is exactly as near as the depth buffer's (coincident faces: either is
    right, the depth buffer keeps the first drawn, the painter the last) counts as agreeing.
    """
    expected, depth = depth_buffer(triangles, camera)
    covered = expected >= 0
    assert covered.sum() > 500  # the scene fills a good part of the image
    painted = painted_ids(fragments, camera)
    agree = painted == expected
    for row, column in np.argwhere(covered & ~agree & (painted >= 0)):
        z, _ = _triangle_depths(triangles[painted[row, column]], camera, column + 0.5, row + 0.5)
        agree[row, column] = abs(z - depth[row, column]) <= 1e-12
    return float(agree[covered].mean())


def random_soup(seed: int, count: int = 24) -> np.ndarray:
    """`count` random triangles of moderate size in [−1, 1]³: many overlap, some pierce each other."""
    rng = np.random.default_rng(seed)
    centers = rng.uniform(-0.8, 0.8, (count, 1, 3))
    return centers + rng.uniform(-0.6, 0.6, (count, 3, 3))


def cyclic_triangles() -> np.ndarray:
    """Three long triangles around a triangle-shaped hole, each lying over the next at one crossing.

    Triangle 0 runs along y = −1 from x = −L (z = −h, wide base) to x = +L (z = +h, apex); 1 and 2 are it
    turned by 120° and 240° about z. At each corner of the hole the rising end of one passes over the low end
    of the next: 0 over 1, 1 over 2, 2 over 0. No order of the whole triangles paints this correctly.
    """
    length, half_width, height = 2.0 * math.sqrt(3.0), 0.45, 0.6
    base = np.array(
        [[-length, -1.0 - half_width, -height], [-length, -1.0 + half_width, -height], [length, -1.0, height]]
    )
    turns = []
    for k in range(3):
        angle = 2 * math.pi * k / 3
        rotation = np.array([[math.cos(angle), -math.sin(angle), 0], [math.sin(angle), math.cos(angle), 0], [0, 0, 1]])
        turns.append(base @ rotation.T)
    return np.array(turns) * 0.6


def test_the_three_triangles_really_overlap_cyclically():
    # the test of the test: every order of the whole triangles disagrees with the depth buffer somewhere
    triangles = cyclic_triangles()
    camera = orthographic_camera()
    for permutation in itertools.permutations(range(3)):
        whole = [(triangles[i], i) for i in permutation]
        assert agreement(whole, triangles, camera) < 0.99


@pytest.mark.parametrize("camera_kind", ["perspective", "orthographic"])
def test_bsp_order_of_cyclic_triangles_matches_the_depth_buffer(camera_kind):
    triangles = cyclic_triangles()
    camera = perspective_camera() if camera_kind == "perspective" else orthographic_camera()
    tree = BSPTree(list(triangles))
    if camera_kind == "perspective":
        fragments = tree.back_to_front(eye=camera.frame.eye)
    else:
        fragments = tree.back_to_front(direction=camera.frame.direction)
    assert tree.fragment_count > 3  # the cycle can only be painted after a split
    assert agreement(fragments, triangles, camera) >= AGREEMENT


@pytest.mark.parametrize("camera_kind", ["perspective", "orthographic"])
def test_depth_sort_of_cyclic_triangles_matches_the_depth_buffer(camera_kind):
    triangles = cyclic_triangles()
    camera = perspective_camera() if camera_kind == "perspective" else orthographic_camera()
    result = depth_sort(list(triangles), camera)
    assert isinstance(result, DepthOrder)
    assert result.split_count >= 1 and result.unresolved_count == 0
    assert len(result.fragments) == 3 + result.split_count
    assert agreement(result.fragments, triangles, camera) >= AGREEMENT


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("camera_kind", ["perspective", "orthographic"])
def test_bsp_order_of_random_soups_matches_the_depth_buffer(seed, camera_kind):
    triangles = random_soup(seed)
    camera = perspective_camera() if camera_kind == "perspective" else orthographic_camera()
    tree = BSPTree(list(triangles))
    eye_or_direction = (
        {"eye": camera.frame.eye} if camera_kind == "perspective" else {"direction": camera.frame.direction}
    )
    fragments = tree.back_to_front(**eye_or_direction)
    assert len(fragments) == tree.fragment_count >= len(triangles)
    # the test of the test: painting the triangles in their given order is visibly wrong
    assert agreement([(t, i) for i, t in enumerate(triangles)], triangles, camera) < 0.95
    print(f"BSP, seed {seed}: {len(triangles)} triangles -> {tree.fragment_count} fragments, {tree.node_count} nodes")
    assert agreement(fragments, triangles, camera) >= AGREEMENT


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("camera_kind", ["perspective", "orthographic"])
def test_depth_sort_of_random_soups_matches_the_depth_buffer(seed, camera_kind):
    triangles = random_soup(seed)
    camera = perspective_camera() if camera_kind == "perspective" else orthographic_camera()
    result = depth_sort(list(triangles), camera)
    assert result.unresolved_count == 0 and result.clipped_count == 0 and result.degenerate_count == 0
    print(f"depth sort, seed {seed}: {len(triangles)} triangles -> {len(result.fragments)} fragments")
    assert agreement(result.fragments, triangles, camera) >= AGREEMENT


def test_oblique_cameras_order_by_their_projection_direction():
    # an oblique projection's lines are not along the view-plane normal: camera= finds their direction
    triangles = random_soup(4)
    camera = Camera.look_at((0.5, 0.4, 5.0), (0, 0, 0), (0, 1, 0), Oblique(0.9, 0.5, 3.5, 0.5, 9.5), WIDTH, HEIGHT)
    tree = BSPTree(triangles)
    assert agreement(tree.back_to_front(camera=camera), triangles, camera) >= AGREEMENT
    assert agreement(depth_sort(triangles, camera).fragments, triangles, camera) >= AGREEMENT
    perspective = perspective_camera()
    np.testing.assert_array_equal(
        tree.back_to_front_indices(camera=perspective), tree.back_to_front_indices(eye=perspective.frame.eye)
    )


def test_one_tree_serves_every_viewpoint():
    triangles = random_soup(5)
    tree = BSPTree(list(triangles))
    for azimuth in (0.0, 2.0, 4.0):
        camera = Camera.orbit((0, 0, 0), 4.0, azimuth, 0.3, Perspective(0.9, 0.5, 20.0), WIDTH, HEIGHT)
        assert agreement(tree.back_to_front(eye=camera.frame.eye), triangles, camera) >= AGREEMENT


def test_convex_meshes_become_single_cells_and_paint_correctly():
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.9)
    mesh = Mesh(np.asarray(sphere.vertices), np.asarray(sphere.faces))
    camera = perspective_camera()
    tree = BSPTree.from_mesh(mesh)
    assert (tree.node_count, tree.fragment_count, tree.split_count) == (1, mesh.face_count, 0)
    triangles = mesh.vertices[mesh.faces]
    assert agreement(tree.back_to_front(eye=camera.frame.eye), triangles, camera) >= AGREEMENT
    # two spheres, one partly hiding the other: the root splits them apart, each side is a cell
    near_sphere = translate(0.8, 0.5, 2.0)  # 2.2 apart: no contact
    both = np.concatenate([triangles, apply(near_sphere, mesh.vertices)[mesh.faces]])
    tree = BSPTree(both)
    assert tree.node_count < 10 and tree.fragment_count == len(both)
    for fragments in (tree.back_to_front(eye=camera.frame.eye), depth_sort(both, camera).fragments):
        assert agreement(fragments, both, camera) >= AGREEMENT


def test_bsp_and_depth_sort_paint_the_bunny_like_the_depth_buffer():
    bunny = trimesh.load(DATA / "bunny" / "bun_zipper_res4.ply", process=False, force="mesh")
    mesh = Mesh(np.asarray(bunny.vertices), np.asarray(bunny.faces))
    triangles = mesh.vertices[mesh.faces]
    center, size = mesh.bounds.mean(axis=0), float(np.linalg.norm(np.ptp(mesh.bounds, axis=0)))
    tree = BSPTree.from_mesh(mesh)
    print(f"bunny: {mesh.face_count} triangles -> {tree.fragment_count} BSP fragments, {tree.node_count} nodes")
    for projection in (Perspective(0.8, 0.1 * size, 10 * size), Orthographic(0.9 * size, 0.1 * size, 10 * size)):
        eye = center + np.array([0.3, 0.4, 1.0]) * 1.2 * size
        camera = Camera.look_at(eye, center, (0, 1, 0), projection, WIDTH, HEIGHT)
        assert agreement(tree.back_to_front(camera=camera), triangles, camera) >= AGREEMENT
        assert agreement(depth_sort(triangles, camera).fragments, triangles, camera) >= AGREEMENT


def test_from_mesh_places_the_triangles_and_labels_them_by_face():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])  # a tetrahedron, outward normals
    tree = BSPTree.from_mesh(Mesh(vertices, faces), world_from_model=np.diag([2.0, 2.0, 2.0, 1.0]))
    fragments = tree.back_to_front(eye=(3.0, 3.0, 3.0))
    assert sorted(label for _, label in fragments) == [0, 1, 2, 3]
    assert tree.fragment_count == 4  # a convex polyhedron never splits
    by_label = {label: polygon for polygon, label in fragments}
    np.testing.assert_allclose(by_label[3], 2.0 * vertices[faces[3]])
    assert [label for _, label in fragments][-1] == 3  # the face toward the eye is painted last


def test_coplanar_polygons_share_one_node():
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    flipped = square[::-1] + np.array([2.0, 0.0, 0.0])  # same plane, facing the other way
    tree = BSPTree([square, flipped, square + np.array([0.0, 0.0, 1.0])])
    assert tree.node_count == 2 and tree.fragment_count == 3
    assert [label for _, label in tree.back_to_front(eye=(0.5, 0.5, 5.0))][-1] == 2
    assert tree.back_to_front(eye=(0.5, 0.5, -5.0))[0][1] == 2


def test_large_polygons_are_stored_in_pieces_of_at_most_eight_corners():
    angles = np.linspace(0.0, 2 * np.pi, 12, endpoint=False)
    dodecagon = np.column_stack([np.cos(angles), np.sin(angles), 0.1 * np.cos(angles)])  # planar, tilted
    piercing = np.array([[-0.5, -0.2, -1.0], [0.5, -0.2, -1.0], [0.0, 0.3, 1.0]])
    tree = BSPTree([dodecagon, piercing], ids=[7, 9])
    fragments = tree.back_to_front(eye=(0.2, 0.1, 4.0))
    assert max(len(polygon) for polygon, _ in fragments) <= 8 and tree.split_count >= 1
    assert len(tree.fragments) == len(tree.ids) == tree.fragment_count
    for label, source in ((7, dodecagon), (9, piercing)):
        parts = [polygon for polygon, i in fragments if i == label]
        assert sum(_area(part) for part in parts) == pytest.approx(_area(source), rel=1e-12)


def test_degenerate_polygons_are_skipped_and_counted():
    good = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
    collinear = np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2]], dtype=float)
    repeated = np.array([[1, 1, 1], [1, 1, 1], [1, 1, 1]], dtype=float)
    tree = BSPTree([good, collinear, repeated])
    assert (tree.degenerate_count, tree.fragment_count) == (2, 1)
    result = depth_sort([good, collinear, repeated], perspective_camera())
    assert result.degenerate_count == 2 and len(result.fragments) == 1


def test_empty_input():
    tree = BSPTree([])
    assert (tree.node_count, tree.fragment_count) == (0, 0)
    assert tree.back_to_front(direction=(0, 0, -1)) == []
    assert depth_sort([], perspective_camera()).fragments == []


def test_depth_sort_clips_polygons_by_the_near_plane():
    camera = perspective_camera()
    eye = np.asarray(camera.frame.eye)
    crossing = eye + np.array([[-1, -1, -3.0], [1, -1, -3.0], [0, 1, 3.0]])  # reaches behind the eye
    behind = eye + np.array([[-1, -1, 1.0], [1, -1, 1.0], [0, 1, 1.0]])
    result = depth_sort([crossing, behind], camera)
    assert result.clipped_count == 2 and len(result.fragments) == 1
    window = camera.project(result.fragments[0][0])
    assert np.isfinite(window).all() and window[:, 2].min() >= -1e-9  # nothing in front of the near plane


def test_building_is_deterministic():
    triangles = list(random_soup(3))
    first = BSPTree(triangles).back_to_front(eye=(0.3, 0.2, 4.0))
    second = BSPTree(triangles).back_to_front(eye=(0.3, 0.2, 4.0))
    assert [label for _, label in first] == [label for _, label in second]
    assert b"".join(p.tobytes() for p, _ in first) == b"".join(p.tobytes() for p, _ in second)


# --- properties ------------------------------------------------------------------------------------------

coordinate = st.floats(min_value=-1.0, max_value=1.0, allow_nan=False, allow_infinity=False)
corners = st.tuples(coordinate, coordinate, coordinate)
soups = st.lists(st.lists(corners, min_size=3, max_size=3), min_size=1, max_size=8)


def _area(polygon: np.ndarray) -> float:
    return float(np.linalg.norm(0.5 * np.cross(polygon, np.roll(polygon, -1, axis=0)).sum(axis=0)))


def _assert_fragments_tile(triangles: np.ndarray, fragments: list, diagonal: float) -> np.ndarray:
    """Each (polygon, label) fragment lies in its source triangle's plane, and the fragments of each triangle add
    up to its area; returns which triangles are kept (area above (1e-9 · diagonal)²)."""
    areas = np.zeros(len(triangles))
    for polygon, label in fragments:
        areas[label] += _area(polygon)
        triangle = triangles[label]
        normal = np.cross(triangle[1] - triangle[0], triangle[2] - triangle[0])
        normal /= np.linalg.norm(normal)
        # 1e-9: fragments are interpolated along edges of the triangle, so they stay in its plane to round-off
        assert np.abs((polygon - triangle[0]) @ normal).max() <= 1e-9 * max(1.0, diagonal / (2 * _area(triangle)))
    expected = np.array([_area(t) for t in triangles])
    kept = expected > (1e-9 * diagonal) ** 2
    # slivers below (1e-9 · diagonal)² are dropped when cut off: areas agree to that, times the splits
    np.testing.assert_allclose(areas[kept], expected[kept], rtol=1e-9, atol=1e-15 + len(fragments) * 1e-17)
    return kept


@settings(max_examples=60)
@given(soups)
def test_bsp_fragments_tile_their_source_polygon(soup):
    triangles = np.array(soup, dtype=float)
    # the skip rule of BSPTree: area <= (1e-9 · diagonal)²
    diagonal = float(np.linalg.norm(triangles.reshape(-1, 3).max(axis=0) - triangles.reshape(-1, 3).min(axis=0)))
    expected_skips = sum(_area(t) <= (1e-9 * diagonal) ** 2 for t in triangles)
    tree = BSPTree(list(triangles))
    fragments = tree.back_to_front(eye=(0.1, 0.2, 5.0))
    assert tree.degenerate_count == expected_skips
    assert len(fragments) == tree.fragment_count
    _assert_fragments_tile(triangles, fragments, diagonal)


@settings(max_examples=40)
@given(soups)
def test_depth_sort_fragments_tile_their_source_polygon(soup):
    triangles = np.array(soup, dtype=float)
    diagonal = float(np.linalg.norm(triangles.reshape(-1, 3).max(axis=0) - triangles.reshape(-1, 3).min(axis=0)))
    result = depth_sort(list(triangles), perspective_camera())
    assert result.clipped_count == 0 and result.unresolved_count == 0
    kept = _assert_fragments_tile(triangles, result.fragments, diagonal)
    assert result.degenerate_count == int((~kept).sum())


# --- bad input -------------------------------------------------------------------------------------------


def test_bad_polygons_raise_geometry_error_naming_them():
    good = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    with pytest.raises(GeometryError, match=r"polygons\[1\] has 2 vertices"):
        BSPTree([good, [[0, 0, 0], [1, 0, 0]]])
    with pytest.raises(GeometryError, match=r"polygons\[0\]\[2\] = \(0\.0, nan, 0\.0\) is not finite"):
        BSPTree([[[0, 0, 0], [1, 0, 0], [0, np.nan, 0]]])
    with pytest.raises(GeometryError, match=r"polygons\[0\] has shape \(3, 2\)"):
        depth_sort([[[0, 0], [1, 0], [0, 1]]], perspective_camera())
    with pytest.raises(GeometryError, match=r"ids = \(1\.0, 2\.0\)"):
        BSPTree([good], ids=[1, 2])
    with pytest.raises(GeometryError, match="polygons = 7 is not a sequence"):
        BSPTree(7)
    with pytest.raises(GeometryError, match="mesh = 'cube' is not a Mesh"):
        BSPTree.from_mesh("cube")


def test_bad_viewer_raises_camera_error_naming_it():
    tree = BSPTree([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]])
    with pytest.raises(CameraError, match="eye = None, direction = None and camera = None; give exactly one"):
        tree.back_to_front()
    with pytest.raises(CameraError, match="give exactly one"):
        tree.back_to_front(eye=(0, 0, 1), direction=(0, 0, -1))
    with pytest.raises(CameraError, match="camera = 'side' is not a Camera"):
        tree.back_to_front(camera="side")
    with pytest.raises(CameraError, match=r"direction = \(0\.0, 0\.0, 0\.0\) has zero length"):
        tree.back_to_front(direction=(0, 0, 0))
    with pytest.raises(CameraError, match=r"eye = .*inf"):
        tree.back_to_front(eye=(0, 0, np.inf))
    with pytest.raises(CameraError, match="camera = 'front' is not a Camera"):
        depth_sort([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], "front")
