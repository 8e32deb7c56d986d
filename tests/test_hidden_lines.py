"""Object-space hidden-line removal (``visibility.hidden_lines``) against hand-computed cases and independent oracles.

Oracles: hand-computed visible segments (a cube from a corner, two boxes, an edge behind a square under a
perspective camera); trimesh's ray–triangle intersector (``trimesh.ray.ray_triangle``, pure numpy, no code
shared) casting a ray from each piece's midpoint toward the viewer; and the renderer's depth buffer, which
must agree with the visible pieces on at least 99 % of the sampled edge points.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum import (
    Axonometric,
    Camera,
    Frustum,
    FrustumError,
    GeometryError,
    Oblique,
    Orthographic,
    Perspective,
    Scene,
    ViewFrame,
    render,
    translate,
)
from frustum.geometry import Mesh, Polyline
from frustum.visibility.hidden_lines import (
    EDGE_BOUNDARY,
    EDGE_CREASE,
    EDGE_LINE,
    EDGE_SILHOUETTE,
    feature_edges,
    remove_hidden_lines,
)
from testdata import DATA


def _box(extents, center=(0.0, 0.0, 0.0)) -> Mesh:
    box = trimesh.creation.box(extents=extents)
    return Mesh(np.asarray(box.vertices) + np.asarray(center, dtype=float), box.faces)


def _pieces(world: np.ndarray) -> set[tuple]:
    """World pieces as a set of sorted endpoint pairs rounded to 1e-9 (order-free comparison)."""
    result = set()
    for a, b in np.round(np.asarray(world), 9) + 0.0:
        result.add(tuple(sorted((tuple(a), tuple(b)))))
    return result


# --- exact cases ------------------------------------------------------------------------------------------


CORNER_CAMERAS = {
    "orthographic": lambda: Camera.look_at((5, 4, 3), (0, 0, 0), (0, 1, 0), Orthographic(6, 0.1, 30), 300, 300),
    "perspective": lambda: Camera.look_at((5, 4, 3), (0, 0, 0), (0, 1, 0), Perspective(1.0, 0.1, 30), 300, 300),
    "isometric": lambda: Camera(
        ViewFrame((0, 0, 10), target=(0, 0, 0), up=(0, 1, 0)), Axonometric.isometric(6, 1, 19), 300, 300
    ),
    "cavalier": lambda: Camera.look_at((0, 0, 10), (0, 0, 0), (0, 1, 0), Oblique.cavalier(8, 1, 19), 300, 300),
    "off-axis frustum": lambda: Camera.look_at(
        (5, 4, 3), (0, 0, 0), (0, 1, 0), Frustum(-0.05, 0.15, -0.12, 0.08, 0.2, 30), 300, 300
    ),
}


@pytest.mark.parametrize("name", sorted(CORNER_CAMERAS))
def test_cube_from_a_corner_has_nine_visible_and_three_hidden_edges(name):
    camera = CORNER_CAMERAS[name]()
    lines = remove_hidden_lines(_box((2, 2, 2)), camera)
    assert lines.edges.shape == (12, 2, 3)  # the face diagonals are coplanar: not drawn
    assert lines.visible.shape == (9, 2, 2) and lines.hidden.shape == (3, 2, 2)
    # every piece is a whole edge, and each edge is either visible or hidden
    assert sorted([*lines.visible_edges, *lines.hidden_edges]) == list(range(12))
    assert _pieces(lines.visible_world) | _pieces(lines.hidden_world) == _pieces(lines.edges)
    # the hidden edges are the three that meet at the corner farthest from the viewer
    hidden_corners = np.round(lines.hidden_world.reshape(-1, 3), 9)
    far_corner, counts = np.unique(hidden_corners, axis=0, return_counts=True)
    assert counts.max() == 3
    view = far_corner[np.argmax(counts)] @ np.asarray(camera.view_matrix)[:3, :3].T + camera.view_matrix[:3, 3]
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    depths = corners @ np.asarray(camera.view_matrix)[:3, :3].T + camera.view_matrix[:3, 3]
    assert view[2] == pytest.approx(depths[:, 2].min(), abs=1e-9)  # most negative z_view: farthest
    # window ends agree with Camera.project
    np.testing.assert_allclose(
        lines.visible.reshape(-1, 2), camera.project(lines.visible_world.reshape(-1, 3))[:, :2], atol=1e-9
    )


def test_two_overlapping_boxes_have_the_hand_computed_visible_segments():
    # A = [0, 2]^3 behind B = [1, 3] x [1, 3] x [3, 4], front view (looking down -z), orthographic
    scene = [_box((2, 2, 2), (1, 1, 1)), _box((2, 2, 1), (2, 2, 3.5))]
    camera = Camera.look_at((1.5, 1.5, 20), (1.5, 1.5, 0), (0, 1, 0), Orthographic(8, 1, 40), 400, 400)
    lines = remove_hidden_lines(scene, camera)
    expected_visible = _pieces([
        # B's front face, all visible
        [(1, 1, 4), (3, 1, 4)], [(3, 1, 4), (3, 3, 4)], [(3, 3, 4), (1, 3, 4)], [(1, 3, 4), (1, 1, 4)],
        # A's front face: bottom and left whole, top and right up to B's outline x = 1 and y = 1
        [(0, 0, 2), (2, 0, 2)], [(0, 0, 2), (0, 2, 2)], [(0, 2, 2), (1, 2, 2)], [(2, 0, 2), (2, 1, 2)],
    ])  # fmt: skip
    expected_hidden = _pieces([
        # the parts of A's front face behind B
        [(1, 2, 2), (2, 2, 2)], [(2, 1, 2), (2, 2, 2)],
        # back faces: under the front faces' outlines
        [(1, 1, 3), (3, 1, 3)], [(3, 1, 3), (3, 3, 3)], [(3, 3, 3), (1, 3, 3)], [(1, 3, 3), (1, 1, 3)],
        [(0, 0, 0), (2, 0, 0)], [(2, 0, 0), (2, 2, 0)], [(2, 2, 0), (0, 2, 0)], [(0, 2, 0), (0, 0, 0)],
    ])  # fmt: skip
    assert _pieces(lines.visible_world) == expected_visible
    assert _pieces(lines.hidden_world) == expected_hidden
    # window: x_w = 200 + 50 (x − 1.5), y_w = 200 + 50 (y − 1.5); the crossing (1, 2) is at (175, 225)
    top = [k for k, piece in enumerate(np.round(lines.visible_world, 9)) if piece[0, 1] == 2 == piece[1, 1]]
    assert len(top) == 1
    np.testing.assert_allclose(sorted(lines.visible[top[0]].tolist()), [[125, 225], [175, 225]], atol=1e-9)


def test_perspective_edge_behind_a_square_is_split_where_the_rays_graze_the_square():
    # eye at the origin looking down -z; the square |x|, |y| <= 1 at z = -5 hides |x| <= 2 of the edge
    # y = 0, z = -10, |x| <= 4 (similar triangles: x/z = 1/5), although its projection is not at half length
    square = Mesh([[-1, -1, -5], [1, -1, -5], [1, 1, -5], [-1, 1, -5]], [[0, 1, 2], [0, 2, 3]])
    sliver = Mesh([[-4, 0, -10], [4, 0, -10], [0, -3, -10]], [[0, 1, 2]])
    camera = Camera.look_at((0, 0, 0), (0, 0, -1), (0, 1, 0), Perspective(1.2, 0.5, 50), 500, 500)
    lines = remove_hidden_lines([square, sliver], camera, edges="boundary")
    on_edge = lambda world: [p for p in _pieces(world) if p[0][1] == 0 == p[1][1]]  # noqa: E731
    assert sorted(on_edge(lines.visible_world)) == [((-4, 0, -10), (-2, 0, -10)), ((2, 0, -10), (4, 0, -10))]
    assert on_edge(lines.hidden_world) == [((-2, 0, -10), (2, 0, -10))]


def test_polylines_are_hidden_by_faces_and_hide_nothing():
    # the same geometry as above, with the edge as a polyline: |x| <= 2 of it lies behind the square
    square = Mesh([[-1, -1, -5], [1, -1, -5], [1, 1, -5], [-1, 1, -5]], [[0, 1, 2], [0, 2, 3]])
    line = Polyline([[-4, 0, -10], [0, 0, -10], [4, 0, -10]])
    # a polyline in front of the square hides none of the square's edges
    veil = Polyline([[-3, 0.5, -2], [3, 0.5, -2], [3, -0.5, -2]], closed=True)
    markers = Polyline([[0, 0, -3]], markers=True)
    camera = Camera.look_at((0, 0, 0), (0, 0, -1), (0, 1, 0), Perspective(1.2, 0.5, 50), 500, 500)
    lines = remove_hidden_lines([square, line, veil, markers], camera, edges="boundary")
    kinds = lines.edge_kinds
    assert np.count_nonzero(kinds == EDGE_LINE) == 2 + 3  # the closed veil has its closing segment
    assert np.array_equal(lines.edge_meshes[kinds == EDGE_LINE], [1, 1, 2, 2, 2])
    on_line = lambda world: sorted(p for p in _pieces(world) if p[0][2] == -10 == p[1][2])  # noqa: E731
    assert on_line(lines.hidden_world) == [((-2, 0, -10), (0, 0, -10)), ((0, 0, -10), (2, 0, -10))]
    assert on_line(lines.visible_world) == [((-4, 0, -10), (-2, 0, -10)), ((2, 0, -10), (4, 0, -10))]
    square_edges = np.flatnonzero(lines.edge_meshes == 0)
    assert np.isin(square_edges, lines.visible_edges).all() and not np.isin(square_edges, lines.hidden_edges).any()


def test_edge_crossing_the_near_plane_keeps_only_the_part_in_front_of_it():
    near = 0.5
    camera = Camera.look_at((0, 0, 0), (0, 0, -1), (0, 1, 0), Perspective(1.2, near, 50), 200, 200)
    # a triangle from behind the eye to in front of it
    mesh = Mesh([[0.1, 0.1, 2.0], [0.2, -0.1, -6.0], [-0.2, 0.0, -6.0]], [[0, 1, 2]])
    lines = remove_hidden_lines(mesh, camera, edges="all")
    assert lines.hidden.shape[0] == 0 and lines.visible.shape[0] == 3
    world = lines.visible_world.reshape(-1, 3)
    assert world[:, 2].max() == pytest.approx(-near, abs=1e-12)  # clipped ends lie on the near plane
    assert np.isfinite(lines.visible).all()
    assert (lines.visible >= -1e-9).all() and (lines.visible <= 200 + 1e-9).all()


def test_piercing_triangles_split_an_edge_where_it_passes_through_a_plane():
    # a vertical square at z = 0 and an edge from z = +2 (in front) to z = −2 (behind) through its middle
    square = Mesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    spike = Mesh([[0.3, 0.2, 2.0], [0.3, 0.2, -2.0], [0.3, 3.0, -2.0]], [[0, 1, 2]])
    camera = Camera.look_at((4, 1, 8), (0, 0, 0), (0, 1, 0), Orthographic(8, 1, 30), 300, 300)
    lines = remove_hidden_lines([square, spike], camera, edges="boundary")
    hidden = [p for p in _pieces(lines.hidden_world) if p[0][:2] == (0.3, 0.2) == p[1][:2]]
    # seen along (4, 1, 8) the square covers the edge from z = 0 (where it pierces) back to x = 0.3 − z/2 = 1
    assert hidden == [((0.3, 0.2, -1.4), (0.3, 0.2, 0.0))]


def test_torus_seen_edge_on_shows_its_front_rings_and_outer_end_circles():
    torus = trimesh.creation.torus(2.0, 0.5, 64, 32)  # axis z, ring radius R = 2, tube radius r = 0.5
    mesh = Mesh(torus.vertices, torus.faces)
    camera = Camera.look_at((10, 0, 0), (0, 0, 0), (0, 0, 1), Orthographic(6, 1, 20), 600, 600)
    lines = remove_hidden_lines(mesh, camera)
    # seen along -x the silhouettes are the top and bottom rings (z = ±r, where the tube's normals turn from
    # +x to -x) and the two meridian circles in the plane x = 0 (ends of the outline): 64 + 64 + 2·32 edges
    middle = lines.edges.mean(axis=1)
    ring = (np.abs(np.abs(lines.edges[:, :, 2]) - 0.5) < 1e-12).all(axis=1)
    meridian = np.abs(lines.edges[:, :, 0]).max(axis=1) < 1e-12 * 2.5  # cos(π/2)·R is round-off, not 0
    assert lines.edges.shape[0] == 192 and np.all(ring ^ meridian)
    # the near half of each ring is visible, the far half lies behind it; the outer halves of the meridian
    # circles are visible, the inner halves lie behind the near half of the tube. Whole edges, exactly.
    expect_visible = np.where(ring, middle[:, 0] > 0, np.abs(middle[:, 1]) > 2.0)
    assert sorted(lines.visible_edges.tolist()) == np.flatnonzero(expect_visible).tolist()
    assert sorted(lines.hidden_edges.tolist()) == np.flatnonzero(~expect_visible).tolist()
    assert _pieces(lines.visible_world) | _pieces(lines.hidden_world) == _pieces(lines.edges)
    # the outline in window units (100 px per unit): |y| <= R + r, |z| <= r
    assert np.abs(lines.visible[:, :, 0] - 300).max() <= 250 + 1e-9
    assert np.abs(lines.visible[:, :, 1] - 300).max() <= 50 + 1e-9
    # the depth buffer agrees on 98 %: here the hidden inner arcs run tangent to the outline for about 10 px
    # at each end, within a pixel of the occluder's silhouette, where a pixel grid cannot decide
    fraction, total = _depth_buffer_agreement([(mesh, np.eye(4))], camera, lines, cull=True)
    assert total > 1000 and fraction >= 0.98


# --- against the depth buffer -----------------------------------------------------------------------------


def _depth_buffer_agreement(placed, camera, lines, cull: bool) -> tuple[float, int]:
    """Fraction of edge pixels where the visible pieces and the renderer's depth buffer agree, and their count.

    Every piece, visible or hidden, is sampled every 0.5 px (window depth is affine along it). A pixel is an
    edge pixel if a sample falls in it; the pieces call it visible if a visible piece's sample does, the depth
    buffer if some sample's depth is at most the largest depth in the 3x3 pixels around it (+ 1e-6 for the
    float32 buffer): a visible edge point lies on the front surface, which the depth field reaches within a
    pixel. Comparing pixels, not samples, lets a hidden edge that projects onto a visible one (a back ring
    under the outline) count as what the picture shows there.
    """
    scene = Scene()
    for mesh, matrix in placed:
        scene.add(mesh, transform=matrix)
    frame = render(scene, camera, shading="none", cull_back_faces=cull)
    depth = np.asarray(frame.depth, dtype=np.float64)
    height, width = depth.shape
    padded = np.pad(depth, 1, mode="edge")
    local_max = np.max([padded[i : i + height, j : j + width] for i in range(3) for j in range(3)], axis=0)
    allowed = local_max + 1e-6
    edge_pixels = np.zeros((height, width), dtype=bool)
    by_pieces = np.zeros((height, width), dtype=bool)
    by_buffer = np.zeros((height, width), dtype=bool)
    for window, depths, is_visible in ((lines.visible, lines.visible_depth, True),
                                       (lines.hidden, lines.hidden_depth, False)):  # fmt: skip
        if not len(window):
            continue
        length = np.linalg.norm(window[:, 1] - window[:, 0], axis=1)
        counts = np.maximum(2, np.ceil(length / 0.5).astype(int))
        owner = np.repeat(np.arange(len(window)), counts)
        t = np.concatenate([(np.arange(n) + 0.5) / n for n in counts])
        points = window[owner, 0] + t[:, None] * (window[owner, 1] - window[owner, 0])
        z = depths[owner, 0] + t * (depths[owner, 1] - depths[owner, 0])
        col = np.clip(np.floor(points[:, 0]).astype(int), 0, width - 1)
        row = np.clip(height - 1 - np.floor(points[:, 1]).astype(int), 0, height - 1)
        edge_pixels[row, col] = True
        if is_visible:
            by_pieces[row, col] = True
        seen = z <= allowed[row, col]
        by_buffer[row[seen], col[seen]] = True
    total = int(edge_pixels.sum())
    return float(np.count_nonzero((by_pieces == by_buffer) & edge_pixels)) / max(total, 1), total


def _assert_agrees_with_depth_buffer(placed, camera, lines, cull: bool) -> None:
    fraction, total = _depth_buffer_agreement(placed, camera, lines, cull)
    assert total > 1000
    assert fraction >= 0.99, fraction


def _noisy_sphere() -> Mesh:
    sphere = trimesh.creation.icosphere(subdivisions=3)
    rng = np.random.default_rng(0)
    return Mesh(sphere.vertices * (1.0 + 0.02 * rng.standard_normal((len(sphere.vertices), 1))), sphere.faces)


def _cad_part() -> list[tuple[Mesh, np.ndarray]]:
    """A bracket of boxes: a base plate, an upright, a rib and a boss (interpenetrating solids)."""
    return [
        (_box((4.0, 0.5, 2.0)), translate(0, -0.25, 0)),
        (_box((0.5, 2.5, 2.0)), translate(-1.75, 1.25, 0)),
        (_box((1.2, 1.2, 0.3)), translate(-1.0, 0.6, 0)),
        (_box((0.8, 0.8, 0.8)), translate(1.2, 0.4, 0.2)),
    ]


@pytest.mark.parametrize("kind", ["perspective", "orthographic"])
def test_visible_pieces_agree_with_the_depth_buffer_on_a_bumpy_sphere(kind):
    projection = Perspective(0.9, 0.5, 20) if kind == "perspective" else Orthographic(3, 0.5, 20)
    camera = Camera.look_at((2.5, 1.5, 3.0), (0, 0, 0), (0, 1, 0), projection, 320, 240)
    placed = [(_noisy_sphere(), np.eye(4))]
    lines = remove_hidden_lines(placed, camera, edges="all")
    _assert_agrees_with_depth_buffer(placed, camera, lines, cull=False)


def test_visible_pieces_agree_with_the_depth_buffer_on_a_cad_part():
    camera = Camera.look_at((4.0, 3.5, 6.0), (0, 0.6, 0), (0, 1, 0), Perspective(0.8, 0.5, 30), 320, 240)
    placed = _cad_part()
    lines = remove_hidden_lines(placed, camera)
    assert lines.hidden.shape[0] > 0
    _assert_agrees_with_depth_buffer(placed, camera, lines, cull=True)


@pytest.mark.parametrize("name", ["bunny", "teapot"])
def test_visible_pieces_agree_with_the_depth_buffer_on_open_scanned_meshes(name):
    # open surfaces: every face hides (no culling) in both methods. All edges: silhouettes alone lie mostly
    # within a pixel of an outline, where a pixel grid cannot decide (the ray-casting test checks them)
    if name == "bunny":
        loaded = trimesh.load(DATA / "bunny" / "bun_zipper_res3.ply", process=False)
        eye_offset = np.array([0.06, 0.05, 0.22])
    else:
        loaded = trimesh.load(DATA / "teapot_n10.obj", process=False)
        eye_offset = np.array([4.0, 3.0, 5.0])
    mesh = Mesh(loaded.vertices, loaded.faces)
    center = (np.asarray(mesh.bounds[0]) + np.asarray(mesh.bounds[1])) / 2
    distance = float(np.linalg.norm(eye_offset))
    projection = Perspective(0.7, 0.05 * distance, 5 * distance)
    camera = Camera.look_at(center + eye_offset, center, (0, 1, 0), projection, 320, 240)
    placed = [(mesh, np.eye(4))]
    lines = remove_hidden_lines(placed, camera, edges="all")
    _assert_agrees_with_depth_buffer(placed, camera, lines, cull=False)


# --- against ray casting (trimesh) ------------------------------------------------------------------------


def _ray_hits(origins, directions, triangles, reach) -> np.ndarray:
    """Naive reference: True where origin + s·direction, 1e-6 < s < reach − 1e-6, hits a triangle.

    Möller–Trumbore against every triangle, in world space (no projection, no grid, no clipping).
    """
    v0 = triangles[:, 0]
    e1, e2 = triangles[:, 1] - v0, triangles[:, 2] - v0
    hits = np.zeros(len(origins), dtype=bool)
    for i, (origin, direction) in enumerate(zip(origins, directions, strict=True)):
        p = np.cross(direction, e2)
        det = (e1 * p).sum(axis=1)
        ok = np.abs(det) > 1e-14
        inverse = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = origin - v0
        u = (s * p).sum(axis=1) * inverse
        q = np.cross(s, e1)
        v = (q * direction).sum(axis=1) * inverse
        t = (e2 * q).sum(axis=1) * inverse
        hits[i] = (ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6) & (t < reach[i] - 1e-6)).any()
    return hits


def _ray_agreement(lines, camera, triangles, perspective: bool) -> tuple[float, int]:
    """Fraction of points at 20 %, 50 % and 80 % of each piece that the rays call what the piece says."""
    agree = total = 0
    for world, expect_hidden in ((lines.visible_world, False), (lines.hidden_world, True)):
        a, b = world[:, 0], world[:, 1]
        points = np.concatenate([a + s * (b - a) for s in (0.2, 0.5, 0.8)])
        if perspective:
            toward = np.asarray(camera.frame.eye) - points
            reach = np.linalg.norm(toward, axis=1)
            toward /= reach[:, None]
        else:
            toward = np.repeat(np.asarray(camera.frame.n)[None, :], len(points), axis=0)
            reach = np.full(len(points), np.inf)
        hidden = _ray_hits(points, toward, triangles, reach)
        agree += int(np.count_nonzero(hidden == expect_hidden))
        total += len(points)
    return agree / max(total, 1), total


def test_silhouettes_and_creases_agree_with_ray_casting_on_a_bumpy_sphere():
    camera = Camera.look_at((2.5, 1.5, 3.0), (0, 0, 0), (0, 1, 0), Perspective(0.9, 0.5, 20), 320, 240)
    mesh = _noisy_sphere()
    lines = remove_hidden_lines(mesh, camera, crease_angle=math.radians(10))
    fraction, total = _ray_agreement(lines, camera, mesh.vertices[mesh.faces], perspective=True)
    assert total > 500 and fraction == 1.0


def test_long_edges_across_a_dense_mesh_agree_with_ray_casting():
    # big triangles behind a finely tessellated sphere: their long edges cross many grid cells and pass in
    # and out behind the sphere's polygonal outline
    sphere = trimesh.creation.icosphere(subdivisions=3)
    rng = np.random.default_rng(3)
    big = rng.uniform(-3.0, 3.0, (6, 3, 3))
    big[:, :, 2] = rng.uniform(-3.0, -2.0, (6, 3))
    meshes = [Mesh(sphere.vertices, sphere.faces), *(Mesh(t, [[0, 1, 2]]) for t in big)]
    camera = Camera.look_at((0.3, 0.2, 4.0), (0, 0, 0), (0, 1, 0), Perspective(1.2, 0.1, 20), 400, 300)
    lines = remove_hidden_lines(meshes, camera, edges="boundary")  # the sphere is closed: only the 18 long edges
    assert len(lines.edges) == 18 and lines.hidden.shape[0] > 6
    triangles = np.concatenate([sphere.vertices[sphere.faces], big])
    fraction, total = _ray_agreement(lines, camera, triangles, perspective=True)
    assert total > 100 and fraction == 1.0


@settings(max_examples=25)
@given(seed=st.integers(0, 2**31 - 1), perspective=st.booleans())
def test_pieces_agree_with_ray_casting_on_random_triangle_soups(seed, perspective):
    rng = np.random.default_rng(seed)
    count = 12
    triangles = rng.uniform(-1.5, 1.5, (count, 1, 3)) + rng.uniform(-1.0, 1.0, (count, 3, 3))
    meshes = [Mesh(triangle, [[0, 1, 2]]) for triangle in triangles]
    projection = Perspective(1.0, 1.0, 40) if perspective else Orthographic(8, 1, 40)
    camera = Camera.look_at((6, 4, 9), (0, 0, 0), (0, 1, 0), projection, 400, 400)
    lines = remove_hidden_lines(meshes, camera, edges="all")
    # the pieces of each edge tile its projection: their window lengths add up to the edge's
    for edge in range(len(lines.edges)):
        ends = camera.project(lines.edges[edge])[:, :2]
        pieces = [*lines.visible[lines.visible_edges == edge], *lines.hidden[lines.hidden_edges == edge]]
        assert sum(np.linalg.norm(p[1] - p[0]) for p in pieces) == pytest.approx(np.linalg.norm(ends[1] - ends[0]))
    # points a fifth of a piece from its ends lie away from the transitions; round-off at near-grazing
    # crossings may flip a point within ~1e-9 of a transition, so allow one in a hundred
    fraction, total = _ray_agreement(lines, camera, triangles, perspective)
    assert fraction >= 0.99 or (total < 100 and fraction >= 1 - 1 / total)


# --- edges and bad input ----------------------------------------------------------------------------------


def test_feature_edges_classifies_boundary_crease_and_silhouette():
    # two triangles folded by 90 degrees along the shared edge (0, 1)
    points = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    faces = [[0, 1, 2], [1, 0, 3]]
    edges, edge_faces, kinds = feature_edges(points, faces, crease_angle=math.radians(80))
    shared = np.flatnonzero((edges == [0, 1]).all(axis=1))[0]
    assert kinds[shared] == EDGE_CREASE
    assert np.count_nonzero(kinds == EDGE_BOUNDARY) == 4
    assert sorted(edge_faces[shared].tolist()) == [0, 1]
    _, _, kinds = feature_edges(points, faces, crease_angle=math.radians(100))
    assert kinds[shared] == 0
    # face 0 has normal +z, face 1 normal +y: from +y and below only face 1 faces the viewer, from +y and
    # above both do
    camera = Camera.look_at((0.3, 5, -3), (0.3, 0.3, 0.3), (0, 0, 1), Orthographic(4, 0.1, 20), 100, 100)
    _, _, kinds = feature_edges(points, faces, camera, crease_angle=math.radians(100))
    assert kinds[shared] == EDGE_SILHOUETTE
    camera = Camera.look_at((0.3, 5, 3), (0.3, 0.3, 0.3), (0, 0, 1), Orthographic(4, 0.1, 20), 100, 100)
    _, _, kinds = feature_edges(points, faces, camera, crease_angle=math.radians(100))
    assert kinds[shared] == 0


def test_empty_input_gives_empty_pieces():
    camera = CORNER_CAMERAS["orthographic"]()
    for meshes in ([], Mesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int))):
        lines = remove_hidden_lines(meshes, camera)
        assert lines.visible.shape == (0, 2, 2) and lines.hidden.shape == (0, 2, 2)
        assert lines.visible_world.shape == (0, 2, 3) and lines.edges.shape == (0, 2, 3)


def test_degenerate_faces_hide_nothing_and_do_not_fail():
    # a zero-area face lying across the cube's front must not hide anything
    cube = _box((2, 2, 2))
    vertices = np.vstack([cube.vertices, [[-3, 0, 3], [3, 0, 3], [0, 0, 3]]])
    faces = np.vstack([cube.faces, [[8, 9, 10]]])
    camera = CORNER_CAMERAS["perspective"]()
    lines = remove_hidden_lines(Mesh(vertices, faces), camera)
    cube_only = remove_hidden_lines(cube, camera)
    assert lines.hidden.shape[0] == 3
    assert _pieces(cube_only.visible_world) <= _pieces(lines.visible_world)


def test_camera_inside_a_closed_mesh_sees_the_inner_walls():
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=3.0)
    camera = Camera.look_at((0.2, 0.1, 0.3), (0, 0, -1), (0, 1, 0), Perspective(1.4, 0.1, 20), 200, 150)
    lines = remove_hidden_lines(Mesh(sphere.vertices, sphere.faces), camera, edges="all")
    assert lines.visible.shape[0] > 0
    assert np.isfinite(lines.visible).all() and np.isfinite(lines.visible_world).all()
    assert (lines.visible[..., 0] >= -1e-9).all() and (lines.visible[..., 0] <= 200 + 1e-9).all()
    assert (lines.visible[..., 1] >= -1e-9).all() and (lines.visible[..., 1] <= 150 + 1e-9).all()
    assert lines.hidden.shape[0] == 0  # a convex room hides none of its own walls from inside


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"camera": "camera"}, FrustumError, r"camera = 'camera' is not a Camera"),
        ({"edges": "outline"}, FrustumError, r"edges = 'outline' is unknown"),
        ({"edges": ["crease", 3]}, FrustumError, r"edges = .* is unknown"),
        ({"crease_angle": -0.5}, FrustumError, r"crease_angle = -0.5 is outside \[0, pi\]"),
        ({"crease_angle": float("nan")}, FrustumError, r"crease_angle = nan is not finite"),
        ({"meshes": "mesh"}, GeometryError, r"meshes = 'mesh' is not a Mesh"),
        ({"meshes": [(_box((1, 1, 1)), np.ones((4, 4)))]}, GeometryError, r"bottom row = \(1.0, 1.0, 1.0, 1.0\)"),
        ({"meshes": [_box((1, 1, 1)), 7]}, GeometryError, r"meshes\[1\] = 7 is not a Mesh"),
    ],
)
def test_remove_hidden_lines_rejects_bad_input(kwargs, error, match):
    arguments = {"meshes": _box((1, 1, 1)), "camera": CORNER_CAMERAS["orthographic"]()}
    arguments.update(kwargs)
    meshes, camera = arguments.pop("meshes"), arguments.pop("camera")
    with pytest.raises(error, match=match):
        remove_hidden_lines(meshes, camera, **arguments)


def test_results_are_read_only_and_deterministic():
    camera = CORNER_CAMERAS["perspective"]()
    first = remove_hidden_lines(_cad_part(), camera)
    second = remove_hidden_lines(_cad_part(), camera)
    for name in ("visible", "hidden", "visible_world", "hidden_world", "visible_edges", "edges"):
        assert np.array_equal(getattr(first, name), getattr(second, name))
        with pytest.raises(ValueError, match="read-only"):
            getattr(first, name)[...] = 0


# --- flat faces split into triangles, split vertices, faces seen edge-on ---------------------------------------


def _plate_and_post() -> tuple[list, trimesh.Trimesh]:
    """A plate whose faces are split into many coplanar triangles and a frustum cylinder (cap rims and the seam
    split into separate vertices), as placed meshes and as one trimesh."""
    from frustum.geometry import cylinder
    from frustum.transforms import rotate_x

    plate = trimesh.creation.box(extents=(60.0, 10.0, 40.0)).subdivide().subdivide()
    post = cylinder(radius=10.0, height=30.0, segments=48)
    place = translate(5.0, 20.0, -4.0) @ rotate_x(-math.pi / 2)
    post_world = trimesh.Trimesh(post.vertices, post.faces).apply_transform(place)
    return [Mesh(plate.vertices, plate.faces), (post, place)], trimesh.util.concatenate([plate, post_world])


def _on_sharp_edge(edges: np.ndarray, part: trimesh.Trimesh) -> np.ndarray:
    """(E,) True where both ends of a world edge lie on one edge between faces more than 1e-3 rad apart (trimesh,
    vertices merged by position): the oracle for "a feature edge of the solid"."""
    merged = part.copy()
    merged.merge_vertices(digits_vertex=9)
    sharp = merged.vertices[merged.face_adjacency_edges[merged.face_adjacency_angles > 1e-3]]
    a, direction = sharp[:, 0], sharp[:, 1] - sharp[:, 0]
    length2 = (direction**2).sum(axis=1)

    def distance(p: np.ndarray) -> np.ndarray:
        t = np.clip(((p - a) * direction).sum(axis=1) / length2, 0.0, 1.0)
        return np.linalg.norm(a + t[:, None] * direction - p, axis=1)

    return np.array([((distance(e[0]) < 1e-9) & (distance(e[1]) < 1e-9)).any() for e in edges])


@pytest.mark.parametrize("view", ["top", "front", "right"])
def test_feature_edges_are_edges_of_the_solid_never_between_coplanar_faces(view):
    meshes, part = _plate_and_post()
    centre = part.bounds.mean(axis=0)
    camera = Camera.multiview(view, Orthographic(100.0, 50.0, 250.0), centre, 150.0, 400, 400)
    lines = remove_hidden_lines(meshes, camera)
    assert lines.edges.shape[0] > 0 and _on_sharp_edge(lines.edges, part).all()
    # a flat face split into triangles, seen face-on or edge-on, has no kind bits on its inner edges
    plate = meshes[0]
    edges, _, kinds = feature_edges(plate.vertices, plate.faces, camera)
    assert _on_sharp_edge(plate.vertices[edges[kinds != 0]], part).all()
    assert (kinds != 0).sum() == 12 * 4  # the box's 12 edges, each split in 4 by two subdivisions


def test_split_vertices_do_not_make_boundaries_and_edge_on_faces_hide_nothing():
    from frustum.geometry import cylinder

    post = cylinder(radius=0.08, height=0.6, segments=12)  # a 12-gon: facets exactly 30 degrees apart
    _, _, kinds = feature_edges(post.vertices, post.faces)
    assert not (kinds & EDGE_BOUNDARY).any()  # closed, though rims and seam are split vertices
    assert (kinds == EDGE_CREASE).sum() == 24  # the two rims; 30 degrees does not exceed crease_angle = 30
    # an isometric view sees two side facets exactly edge-on: both silhouettes are drawn, whole and visible
    frame = ViewFrame((0.0, 0.0, 2.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    camera = Camera(frame, Axonometric(-math.pi / 4, math.asin(math.tan(math.pi / 6)), 1.0, 1.0, 3.0), 500, 500)
    turned = (post, np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0], [0, -1.0, 0, 0], [0, 0, 0, 1.0]]))  # axis along y
    lines = remove_hidden_lines([turned], camera)
    silhouettes = np.flatnonzero(lines.edge_kinds == EDGE_SILHOUETTE)
    assert silhouettes.size == 2 and not np.isin(silhouettes, lines.hidden_edges).any()
    for edge in silhouettes:
        drawn = lines.visible[lines.visible_edges == edge]
        full = np.linalg.norm(camera.project(lines.edges[edge])[1, :2] - camera.project(lines.edges[edge])[0, :2])
        assert np.linalg.norm(drawn[:, 1] - drawn[:, 0], axis=1).sum() == pytest.approx(full, rel=1e-9)


def _kind_lengths(points: np.ndarray, faces: np.ndarray, camera: Camera) -> dict[int, float]:
    edges, _, kinds = feature_edges(points, faces, camera)
    lengths = np.linalg.norm(points[edges[:, 1]] - points[edges[:, 0]], axis=1)
    return {bit: float(lengths[(kinds & bit) != 0].sum()) for bit in (EDGE_BOUNDARY, EDGE_CREASE, EDGE_SILHOUETTE)}


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), azimuth=st.floats(0.0, 2 * math.pi), elevation=st.floats(-1.4, 1.4))
def test_feature_edges_ignore_split_vertices_and_coplanar_subdivision(seed, azimuth, elevation):
    # a random convex polyhedron (trimesh's hull of 12 points), seen from a random direction
    hull = trimesh.convex.convex_hull(np.random.default_rng(seed).normal(size=(12, 3)))
    eye = 6.0 * np.array(
        [math.cos(elevation) * math.sin(azimuth), math.sin(elevation), math.cos(elevation) * math.cos(azimuth)]
    )
    camera = Camera(ViewFrame(eye, (0.0, 0.0, 0.0), (0.0, 1.0, 0.0) if abs(elevation) < 1.3 else (1.0, 0.0, 0.0)),
                    Perspective(0.8, 0.1, 20.0), 200, 200)  # fmt: skip
    reference = _kind_lengths(np.asarray(hull.vertices), np.asarray(hull.faces), camera)
    assert reference[EDGE_BOUNDARY] == 0.0 and reference[EDGE_CREASE] > 0.0
    # every face with its own three vertices (a flat-shaded export): the same edges of the same kinds
    soup = np.asarray(hull.vertices)[np.asarray(hull.faces)].reshape(-1, 3)
    split = _kind_lengths(soup, np.arange(soup.shape[0]).reshape(-1, 3), camera)
    # every face split into four coplanar triangles: no new edges, the old ones in halves (same total length)
    finer = hull.subdivide()
    subdivided = _kind_lengths(np.asarray(finer.vertices), np.asarray(finer.faces), camera)
    for bit, length in reference.items():
        # 1e-9 relative: sums of the same lengths in another order and split in two
        assert split[bit] == pytest.approx(length, rel=1e-9, abs=1e-12)
        assert subdivided[bit] == pytest.approx(length, rel=1e-9, abs=1e-12)
