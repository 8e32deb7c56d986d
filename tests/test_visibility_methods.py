"""render(method=...): every visible-surface method against the depth buffer; Warnock's relations and exits;
scan-line cyclic overlaps and interpenetration; ray casting through the BVH (view volume, culling, parallel and
oblique cameras, mirrored items, exact ties); the A-buffer against a brute-force per-subsample fragment sort,
against the per-object sort and against 16× supersampling; exact counts on hand-made scenes; bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum import Camera, FrustumError, GeometryError, Oblique, Orthographic, Perspective
from frustum.budgets import budget
from frustum.geometry import Mesh
from frustum.geometry.io import load
from frustum.geometry.teapot import teapot
from frustum.render import RENDER_METHODS, render
from frustum.scene import Scene
from frustum.shading import DirectionalLight, Material
from frustum.transforms import reflect, translate
from frustum.visibility.abuffer import FRAGMENT_BYTES
from testdata import DATA

OPAQUE_METHODS = ["scan-line", "area-subdivision", "depth-sort", "bsp", "ray-casting"]
LIGHT = DirectionalLight(direction=(-0.4, -0.8, -0.5))
BUNNY = DATA / "bunny" / "bun_zipper_res4.ply"


def assert_same_picture(frame, reference, share: float = 0.999) -> None:
    """Coverage identical and colors within ±1 level on at least `share` of the pixels."""
    coverage = ((frame.depth < 1.0) == (reference.depth < 1.0)).mean()
    close = (np.abs(frame.color.astype(int) - reference.color.astype(int)).max(axis=2) <= 1).mean()
    assert coverage >= share, coverage
    assert close >= share, close


def soup(seed: int, count: int = 40) -> Mesh:
    """Random triangles in a box, cutting through each other."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-1.0, 1.0, (count, 1, 3))
    vertices = (centres + rng.normal(0.0, 0.6, (count, 3, 3))).reshape(-1, 3)
    return Mesh(vertices, np.arange(3 * count).reshape(count, 3))


def soup_scene(seed: int) -> tuple[Scene, Camera]:
    scene = Scene(lights=[LIGHT])
    scene.add(soup(seed), material=Material(color=(0.8, 0.5, 0.3)))
    scene.add(soup(seed + 100, 20), material=Material(color=(0.3, 0.6, 0.9)), transform=translate(0.2, 0.1, 0.3))
    camera = Camera.look_at((0.5, 0.8, 4.0), (0.0, 0.0, 0.0), projection=Perspective(0.9, 0.5, 20.0), width=64,
                            height=48)  # fmt: skip
    return scene, camera


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("method", OPAQUE_METHODS)
def test_triangle_soup_matches_depth_buffer(method: str, seed: int) -> None:
    scene, camera = soup_scene(seed)
    reference = render(scene, camera, cull_back_faces=False, stats=True)
    frame = render(scene, camera, cull_back_faces=False, method=method)
    assert_same_picture(frame, reference)
    assert frame.stats["method"] == method
    if method == "ray-casting":  # world-space triangles, unclipped: every one is in the index
        assert frame.stats["indexed_triangles"] == 60 and frame.stats["rays"] == camera.width * camera.height
        assert frame.stats["hits"] == (frame.depth < 1.0).sum()
    else:
        assert frame.stats["triangles"] == reference.stats["triangles"] >= 60


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), count=st.integers(1, 24), two_sided=st.booleans())
def test_image_space_methods_find_the_depth_buffers_surface(seed: int, count: int, two_sided: bool) -> None:
    """Property: on any soup, scan-line, area subdivision and ray casting pick, pixel by pixel, the depth buffer's
    surface."""
    scene = Scene(lights=[LIGHT])
    scene.add(soup(seed, count), material=Material(color=(0.8, 0.5, 0.3)))
    camera = Camera.look_at((0.3, 0.4, 4.0), (0.0, 0.0, 0.0), projection=Perspective(0.9, 0.5, 20.0), width=24,
                            height=20)  # fmt: skip
    reference = render(scene, camera, cull_back_faces=not two_sided)
    for method in ("scan-line", "area-subdivision", "ray-casting"):
        frame = render(scene, camera, cull_back_faces=not two_sided, method=method)
        assert ((frame.depth < 1.0) == (reference.depth < 1.0)).mean() >= 0.99
        close = np.abs(frame.color.astype(int) - reference.color.astype(int)).max(axis=2) <= 1
        assert close.mean() >= 0.99


@pytest.fixture(scope="module")
def bunny_scene() -> tuple[Scene, Camera]:
    mesh = load(BUNNY)
    scene = Scene(lights=[LIGHT])
    scene.add(mesh, material=Material(color=(0.85, 0.8, 0.7)))
    centre = mesh.bounds.mean(axis=0)
    camera = Camera.look_at(centre + np.array([0.05, 0.08, 0.25]), centre, width=64, height=64)
    return scene, camera


@pytest.mark.parametrize("method", ["scan-line", "area-subdivision", "bsp", "ray-casting"])
def test_bunny_matches_depth_buffer(bunny_scene, method: str) -> None:
    scene, camera = bunny_scene
    assert_same_picture(render(scene, camera, method=method), render(scene, camera))


def test_teapot_two_sided_matches_depth_buffer() -> None:
    scene = Scene(lights=[LIGHT])
    scene.add(teapot().tessellate(4), material=Material(color=(0.7, 0.7, 0.9)))
    camera = Camera.look_at((3.0, 4.0, 6.0), (0.0, 1.2, 0.0), width=64, height=48)
    reference = render(scene, camera, cull_back_faces=False)
    for method in ["scan-line", "area-subdivision", "bsp", "ray-casting"]:
        assert_same_picture(render(scene, camera, cull_back_faces=False, method=method), reference)


# --- hand-made scenes: orthographic, pixel-exact coordinates --------------------------------------------------


def flat_camera(size: int = 16) -> Camera:
    """Orthographic view down −z: world x, y in [0, size] map to window x, y (pixels); z in (−10, 0) to depth."""
    half = size / 2.0
    return Camera.look_at((half, half, 10.0), (half, half, 0.0), projection=Orthographic(size, 0.5, 20.0),
                          width=size, height=size)  # fmt: skip


def quad(x0: float, y0: float, x1: float, y1: float, z: float = 0.0) -> Mesh:
    return Mesh([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], [[0, 1, 2], [0, 2, 3]])


def triangle(points) -> Mesh:
    return Mesh(np.asarray(points, dtype=float), [[0, 1, 2]])


def flat_scene(*meshes: Mesh, colors=None, opacity: float = 1.0) -> Scene:
    scene = Scene(lights=[LIGHT])
    for k, mesh in enumerate(meshes):
        color = (0.2 + 0.3 * k % 1.0, 0.5, 0.9 - 0.2 * k) if colors is None else colors[k]
        scene.add(mesh, material=Material(color=color, opacity=opacity))
    return scene


def test_one_quad_counts_are_exact() -> None:
    """A 6×4-pixel quad: scan-line spans are the runs of each triangle per row, edge updates the two
    non-horizontal edges of each triangle per row; the depth buffer's depth tests are its 24 pixels."""
    camera = flat_camera()
    scene = flat_scene(quad(3.0, 5.0, 9.0, 9.0))
    reference = render(scene, camera, method="depth-buffer", stats=True)
    assert reference.stats == {"method": "depth-buffer", "depth_tests": 24, "triangles": 2}
    frame = render(scene, camera, method="scan-line")
    # rows 5..8 (window), columns 3..8; the diagonal (3, 5) → (9, 9) splits each row into two runs
    assert frame.stats["spans"] == 8
    assert frame.stats["edge_updates"] == 2 * 2 * 4
    assert frame.stats["depth_tests"] == 0 and frame.stats["split_spans"] == 0
    assert_same_picture(frame, reference, 1.0)
    buffer = render(scene, camera, method="a-buffer")
    offsets = (np.arange(4) + 0.5) / 4.0
    cut = 0
    for i in range(3, 9):
        for j in range(5, 9):
            x, y = np.meshgrid(i + offsets, j + offsets)
            side = 4.0 * (x - 3.0) - 6.0 * (y - 5.0)  # the diagonal (3, 5) → (9, 9)
            cut += int((side > 0).any() and (side < 0).any())
    assert cut > 0
    assert buffer.stats["fragments"] == 24 + cut  # every pixel once, those the diagonal cuts twice
    assert buffer.stats["pixels_with_fragments"] == 24
    # ray casting: the index is one inner node (the root) whose children are two leaves of one triangle each
    # (both boxes are the quad's box); every ray visits the root and tests the two child boxes, the 24 whose
    # centre lies over the quad enter both leaves (the quad is flat: the second leaf's entry equals the hit's
    # t, a possible tie), 256 + 48 nodes visited, test both triangles, and hit one
    rays = render(scene, camera, method="ray-casting")
    assert rays.stats == {
        "method": "ray-casting", "rays": 256, "hits": 24, "box_tests": 512, "nodes_visited": 304,
        "triangle_tests": 48, "tests_per_ray": 0.188, "indexed_triangles": 2, "bvh_nodes": 1,
    }  # fmt: skip
    assert_same_picture(rays, reference, 1.0)


def test_warnock_empty_and_surrounding_exits() -> None:
    camera = flat_camera()
    empty = render(Scene(lights=[LIGHT]), camera, method="area-subdivision")
    assert empty.stats["areas_per_level"] == [1] and empty.stats["exit_empty"] == 1
    # a quad filling the image (clipping keeps every triangle inside the view volume, so no one triangle
    # surrounds the whole image): the two quarters off its diagonal are each surrounded by one triangle
    front = quad(0.0, 0.0, 16.0, 16.0, 1.0)
    frame = render(flat_scene(front), camera, method="area-subdivision")
    assert frame.stats["areas_per_level"][:2] == [1, 4]
    assert frame.stats["exit_surrounding"] >= 2 and frame.stats["surrounding"] >= 2
    assert (frame.depth < 1.0).all()
    # a surface behind it is hidden by the surrounding surfaces: not one area more is visited
    hidden = flat_scene(front, quad(2.0, 9.0, 6.0, 14.0, -1.0))
    with_hidden = render(hidden, camera, method="area-subdivision")
    assert with_hidden.stats["areas_per_level"] == frame.stats["areas_per_level"]
    assert with_hidden.stats["exit_surrounding"] == frame.stats["exit_surrounding"]
    assert_same_picture(with_hidden, render(hidden, camera), 1.0)
    # the same quad in front of the background quad instead: the areas around it are subdivided
    shown = flat_scene(quad(0.0, 0.0, 16.0, 16.0, -1.0), quad(2.0, 9.0, 6.0, 14.0, 1.0))
    in_front = render(shown, camera, method="area-subdivision")
    assert in_front.stats["areas"] > frame.stats["areas"]
    assert_same_picture(in_front, render(shown, camera), 1.0)


def test_warnock_inside_and_overlapping() -> None:
    camera = flat_camera()
    one = flat_scene(triangle([[1.2, 1.2, 0], [6.7, 1.5, 0], [2.1, 6.6, 0]]))  # in the lower-left quarter
    frame = render(one, camera, method="area-subdivision")
    assert frame.stats["areas_per_level"] == [1] and frame.stats["inside"] == 1 and frame.stats["exit_single"] == 1
    inside = flat_scene(
        triangle([[1.2, 1.2, 0], [6.7, 1.5, 0], [2.1, 6.6, 0]]),
        triangle([[9.2, 9.2, 0], [14.7, 9.5, 0], [10.1, 14.6, 0]]),
    )  # one in the lower-left quarter, one in the upper-right
    frame = render(inside, camera, method="area-subdivision")
    assert frame.stats["areas_per_level"] == [1, 4]
    assert frame.stats["inside"] == 4 and frame.stats["exit_single"] == 2 and frame.stats["exit_empty"] == 2
    assert_same_picture(frame, render(inside, camera), 1.0)
    across = flat_scene(triangle([[2.3, 3.1, 0], [14.2, 6.3, 0], [5.1, 13.7, 0]]), quad(6.5, 1.5, 12.5, 9.5, 0.5))
    frame = render(across, camera, method="area-subdivision")
    assert frame.stats["overlapping"] >= 2
    assert_same_picture(frame, render(across, camera), 1.0)


def test_scan_line_cyclic_overlap_and_interpenetration() -> None:
    camera = flat_camera(24)
    # three bars each over the next and under the previous: no depth order exists
    bars = [
        Mesh([[2, 4, 0], [22, 4, 2], [22, 8, 2], [2, 8, 0]], [[0, 1, 2], [0, 2, 3]]),
        Mesh([[4, 2, 2], [8, 2, 2], [8, 22, 0], [4, 22, 0]], [[0, 1, 2], [0, 2, 3]]),
        Mesh([[20, 2, 0], [20, 22, 2], [15, 22, 2], [15, 2, 0]], [[0, 1, 2], [0, 2, 3]]),
    ]
    cyclic = flat_scene(*bars)
    reference = render(cyclic, camera, cull_back_faces=False)
    for method in OPAQUE_METHODS:
        assert_same_picture(render(cyclic, camera, cull_back_faces=False, method=method), reference, 0.995)
    # two triangles cutting through each other: the visible one changes inside a span
    pierce = flat_scene(
        triangle([[2, 2, -2], [22, 3, 2], [12, 22, 0]]), triangle([[3, 20, -2], [21, 21, 2], [11, 1, 0]])
    )
    reference = render(pierce, camera, cull_back_faces=False)
    frame = render(pierce, camera, cull_back_faces=False, method="scan-line")
    assert frame.stats["split_spans"] > 0
    assert_same_picture(frame, reference, 0.995)


# --- ray casting -------------------------------------------------------------------------------------------


def parallel_cameras() -> list[Camera]:
    eye, target = (0.5, 0.8, 4.0), (0.0, 0.0, 0.0)
    return [
        Camera.look_at(eye, target, projection=Orthographic(3.2, 0.5, 20.0), width=48, height=40),
        Camera.look_at(eye, target, projection=Oblique(math.radians(60.0), math.radians(30.0), 3.2, 0.5, 20.0, -4.1),
                       width=48, height=40),
    ]  # fmt: skip


@pytest.mark.parametrize("cull", [True, False])
def test_ray_casting_with_parallel_and_perspective_cameras_and_a_mirrored_item(cull: bool) -> None:
    """Parallel rays (orthographic, oblique) and rays from the eye; a reflected item (its winding turned
    around: front and back, and the corners the barycentrics weigh, as the depth buffer draws it)."""
    scene, camera = soup_scene(7)
    scene.add(soup(8, 20), material=Material(color=(0.4, 0.9, 0.4)), transform=reflect("yz"))
    for view in [camera, *parallel_cameras()]:
        reference = render(scene, view, cull_back_faces=cull)
        frame = render(scene, view, cull_back_faces=cull, method="ray-casting")
        assert_same_picture(frame, reference)
        assert (frame.depth < 1.0).sum() > 200


def test_ray_casting_culls_back_faces_and_sees_what_lies_behind() -> None:
    """A back face in front of a front face: culled, the ray goes on to the front face (as the depth buffer,
    which never draws it); not culled, the back face is hit and lit two-sided."""
    camera = flat_camera()
    back = Mesh([[2.2, 2.3, 1.0], [2.1, 12.4, 1.0], [12.3, 2.2, 1.0]], [[0, 1, 2]])  # clockwise seen from +z
    scene = flat_scene(back, quad(1.0, 1.0, 10.0, 10.0, -1.0))
    for cull in (True, False):
        reference = render(scene, camera, cull_back_faces=cull)
        frame = render(scene, camera, cull_back_faces=cull, method="ray-casting")
        assert_same_picture(frame, reference, 1.0)
        assert np.abs(frame.depth - reference.depth).max() < 1e-6
    culled = render(scene, camera, method="ray-casting")
    shown = render(scene, camera, cull_back_faces=False, method="ray-casting")
    assert (culled.depth[8, 3] > shown.depth[8, 3]) and culled.stats["hits"] == 81


def test_ray_casting_stops_at_the_near_and_far_planes() -> None:
    """Near and far planes cutting through the soups: hits only inside the view volume, as clipping leaves it."""
    scene, camera = soup_scene(9)
    for near, far in [(3.6, 20.0), (0.5, 4.3), (3.5, 4.6)]:
        view = Camera.look_at(camera.frame.eye, (0.0, 0.0, 0.0), projection=Perspective(0.9, near, far), width=64,
                              height=48)  # fmt: skip
        reference = render(scene, view, cull_back_faces=False)
        frame = render(scene, view, cull_back_faces=False, method="ray-casting")
        assert_same_picture(frame, reference)
        unclipped = render(scene, camera, cull_back_faces=False, method="ray-casting")
        cut = np.abs(frame.color.astype(int) - unclipped.color.astype(int)).max(axis=2) > 2
        assert cut.sum() > 20  # the planes did cut something off
    ortho = Camera.look_at(camera.frame.eye, (0.0, 0.0, 0.0), projection=Orthographic(3.2, 3.7, 4.4), width=48,
                           height=40)  # fmt: skip
    assert_same_picture(render(scene, ortho, method="ray-casting"), render(scene, ortho))


def test_ray_casting_exact_ties_take_the_closed_triangle() -> None:
    """Pixel centres exactly on edges: the depth buffer's top-left rule draws a pixel once, a ray hits a closed
    triangle, so the quad [3.5, 9.5] × [5.5, 9.5] covers its 7×5 centres, not the rule's 6×4 (the difference is
    the right column and the bottom row; generic scenes have no exact ties)."""
    camera = flat_camera()
    scene = flat_scene(quad(3.5, 5.5, 9.5, 9.5))
    reference = render(scene, camera)
    frame = render(scene, camera, method="ray-casting")
    assert (reference.depth < 1.0).sum() == 24 and (frame.depth < 1.0).sum() == 35
    extra = np.argwhere((frame.depth < 1.0) & ~(reference.depth < 1.0))
    assert extra.shape[0] == 11 and set(map(tuple, extra)) == {(r, 9) for r in range(6, 11)} | {
        (10, c) for c in range(3, 10)
    }
    assert ((reference.depth < 1.0) <= (frame.depth < 1.0)).all()


def test_ray_casting_index_is_checked_against_the_budget_and_shared_with_pick() -> None:
    scene, camera = soup_scene(10)
    small = Camera.look_at(camera.frame.eye, (0.0, 0.0, 0.0), projection=camera.projection, width=8, height=6)
    message = r"render: a triangle index \(BVH\) over 60 triangles needs about"
    with budget(bytes=20_000), pytest.raises(GeometryError, match=message):
        render(scene, small, method="ray-casting")
    with budget(bytes=40_000):  # 3·72·60 bytes of world corners, 60·224 + 59·160 of index (raster.rays)
        assert render(scene, small, method="ray-casting").stats["rays"] == 48
    frame = render(scene, camera, method="ray-casting", buffers=("object_id",))
    index = scene._pick_index
    hit = scene.pick(camera, 30.5, 20.5)
    assert scene._pick_index is index  # built once, for both
    assert hit is not None and scene.items[frame.object_id[camera.height - 1 - 20, 30]].mesh is hit.item.mesh


# --- the A-buffer ------------------------------------------------------------------------------------------


def brute_force(scene: Scene, camera: Camera, background=(0.0, 0.0, 0.0)) -> np.ndarray:
    """(H, W, 3) float in [0, 255]: every subsample of a 4×4 grid, every triangle covering it, sorted by depth and
    composited ``α·c + (1 − α)·under`` from the back; unlit base colors (shading=None), the pixel the mean."""
    height, width = camera.height, camera.width
    offsets = (np.arange(4) + 0.5) / 4.0
    xs = (np.arange(width)[:, None] + offsets[None, :]).ravel()
    ys = (np.arange(height)[:, None] + offsets[None, :]).ravel()
    px, py = np.meshgrid(xs, ys)  # (4H, 4W), window y up
    layers = []
    for item in scene.items:
        world = (item.world_from_model[:3, :3] @ item.mesh.vertices.T).T + item.world_from_model[:3, 3]
        window = camera.project(world)
        rgb = 255.0 * np.asarray(item.material.color)
        for face in item.mesh.faces:
            (x0, y0, z0), (x1, y1, z1), (x2, y2, z2) = window[face]
            area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
            b1 = ((px - x0) * (y2 - y0) - (x2 - x0) * (py - y0)) / area
            b2 = ((x1 - x0) * (py - y0) - (px - x0) * (y1 - y0)) / area
            b0 = 1.0 - b1 - b2
            inside = (b0 >= 0) & (b1 >= 0) & (b2 >= 0)
            z = np.where(inside, b0 * z0 + b1 * z1 + b2 * z2, np.inf)
            layers.append((z, rgb, item.material.opacity))
    depth = np.stack([z for z, _, _ in layers])  # (L, 4H, 4W)
    order = np.argsort(-depth, axis=0)  # back to front
    out = np.broadcast_to(255.0 * np.asarray(background), (*px.shape, 3)).copy()
    for rank in range(depth.shape[0]):
        index = order[rank]
        for k, (z, rgb, alpha) in enumerate(layers):
            here = (index == k) & np.isfinite(z)
            out[here] = alpha * rgb + (1.0 - alpha) * out[here]
    out = out[::-1]  # top row first
    return out.reshape(height, 4, width, 4, 3).mean(axis=(1, 3))


def crossing_quads(opacity: float = 0.5) -> Scene:
    """Two transparent quads cutting through each other along x = 8: each is in front on one side."""
    red = Mesh([[2, 3, -2], [14, 3, 2], [14, 13, 2], [2, 13, -2]], [[0, 1, 2], [0, 2, 3]])
    blue = Mesh([[2, 2, 2], [14, 2, -2], [14, 12, -2], [2, 12, 2]], [[0, 1, 2], [0, 2, 3]])
    return flat_scene(red, blue, colors=[(0.9, 0.1, 0.1), (0.1, 0.2, 0.9)], opacity=opacity)


def test_a_buffer_transparency_is_exact_where_the_object_sort_is_wrong() -> None:
    camera = flat_camera()
    scene = crossing_quads()
    reference = brute_force(scene, camera)
    exact = render(scene, camera, shading=None, transparency="a-buffer").color[..., :3].astype(float)
    assert np.abs(exact - reference).max() <= 2.0
    everything = render(scene, camera, shading=None, method="a-buffer").color[..., :3].astype(float)
    assert np.abs(everything - reference).max() <= 2.0
    sorted_per_object = render(scene, camera, shading=None).color[..., :3].astype(float)
    wrong = np.abs(sorted_per_object - reference).max(axis=2) > 20
    assert wrong.sum() >= 20  # one half of the overlap comes out in the wrong order
    assert render(scene, camera, shading=None, transparency="a-buffer").stats["transparent_max_fragments"] >= 2


def test_a_buffer_transparency_over_opaque_surfaces() -> None:
    camera = flat_camera()
    scene = crossing_quads(0.6)
    scene.add(quad(0.0, 0.0, 16.0, 7.0, -1.0), material=Material(color=(0.2, 0.8, 0.2)))
    reference = brute_force(scene, camera)
    frame = render(scene, camera, shading=None, transparency="a-buffer")
    close = np.abs(frame.color[..., :3].astype(float) - reference).max(axis=2) <= 2.0
    assert close.mean() >= 0.97  # opaque silhouettes are tested at the pixel centre only


def test_a_buffer_edges_match_16x_supersampling() -> None:
    scene, camera = soup_scene(3)
    supersampled = render(scene, camera, cull_back_faces=False, samples=16)
    frame = render(scene, camera, cull_back_faces=False, method="a-buffer")
    close = np.abs(frame.color.astype(int) - supersampled.color.astype(int)).max(axis=2) <= 2
    assert close.mean() >= 0.99
    one_sample = render(scene, camera, cull_back_faces=False)
    assert_same_picture(frame, one_sample, 0.0)  # coverage from the centre depth
    assert ((frame.depth < 1.0) == (one_sample.depth < 1.0)).mean() >= 0.999
    assert frame.stats["fragments_per_pixel"] > 1.0


def test_a_buffer_fragments_are_checked_against_the_budget() -> None:
    scene, camera = soup_scene(4)
    camera = Camera.look_at(camera.frame.eye, (0.0, 0.0, 0.0), projection=camera.projection, width=256, height=192)
    fragments = render(scene, camera, method="a-buffer").stats["fragments"]
    needed = fragments * (2 * FRAGMENT_BYTES + 16) + 8 * (256 * 192 + 1)  # what build_fragments estimates
    with budget(bytes=needed - 1), pytest.raises(GeometryError, match=rf"A-buffer of {fragments} fragments"):
        render(scene, camera, method="a-buffer")
    with budget(bytes=needed):
        assert render(scene, camera, method="a-buffer").stats["fragments"] == fragments


# --- bad input ---------------------------------------------------------------------------------------------


def test_unknown_method_lists_the_valid_ones() -> None:
    scene, camera = flat_scene(quad(1, 1, 5, 5)), flat_camera()
    with pytest.raises(
        FrustumError, match="method = 'z-buffer' is unknown; expected one of 'depth-buffer', 'scan-line'"
    ):
        render(scene, camera, method="z-buffer")
    with pytest.raises(FrustumError) as error:
        render(scene, camera, method=3)
    assert all(repr(name) in str(error.value) for name in RENDER_METHODS)
    with pytest.raises(FrustumError, match=r"method = 'path-tracing' is unknown; expected one of .*'ray-casting'"):
        render(scene, camera, method="path-tracing")
    with pytest.raises(FrustumError, match="transparency = 'depth-peeling' is unknown; expected one of 'sort'"):
        render(scene, camera, transparency="depth-peeling")
    with pytest.raises(FrustumError, match="mode = 'wireframe' draws lines"):
        render(scene, camera, mode="wireframe", method="scan-line")
    with pytest.raises(FrustumError, match="stats = 'yes' is not a bool"):
        render(scene, camera, stats="yes")
    with pytest.raises(FrustumError, match="not available with method 'a-buffer'"):
        render(scene, camera, method="a-buffer", buffers=("object_id",))


def test_methods_draw_edges_and_transparent_items_like_the_depth_buffer() -> None:
    scene, camera = soup_scene(5)
    scene.add(quad(-1, -1, 1, 1, 0.5), material=Material(color=(0.9, 0.9, 0.2), opacity=0.5))
    reference = render(scene, camera, mode="surface+edges")
    assert reference.stats is None
    for method in ["scan-line", "area-subdivision", "ray-casting"]:
        assert_same_picture(render(scene, camera, mode="surface+edges", method=method), reference, 0.995)
    assert math.isfinite(render(scene, camera, method="scan-line", samples=4).stats["spans"])


# --- frustum explain --method ----------------------------------------------------------------------------------

SCENE_FILE = """
[camera]
eye = [0.5, 0.8, 4.0]
target = [0.0, 0.0, 0.0]

[render]
size = [48, 32]

[[lights]]
type = "directional"
direction = [-0.3, -1.0, -0.5]

[[nodes]]
geometry = { type = "torus", major_radius = 1.0, minor_radius = 0.3, major_segments = 12, minor_segments = 6 }
"""


def test_explain_method_prints_the_counts(tmp_path, capsys) -> None:
    from frustum.app.cli import main

    path = tmp_path / "ball.toml"
    path.write_text(SCENE_FILE)
    main(["explain", str(path), "--method", "scan-line"])
    lines = dict(line.split(None, 1) for line in capsys.readouterr().out.splitlines() if line.strip())
    assert lines["method"] == "scan-line" and int(lines["spans"]) > 0 and int(lines["edge_updates"]) > 0
    main(["explain", str(path), "--method", "area-subdivision"])
    lines = dict(line.split(None, 1) for line in capsys.readouterr().out.splitlines() if line.strip())
    assert lines["areas_per_level"].startswith("[1, 4,")
    main(["explain", str(path), "--method", "ray-casting"])
    lines = dict(line.split(None, 1) for line in capsys.readouterr().out.splitlines() if line.strip())
    assert int(lines["rays"]) == 48 * 32 and 0 < int(lines["hits"]) < int(lines["rays"])
    assert int(lines["triangle_tests"]) > 0 and int(lines["nodes_visited"]) > 0
    with pytest.raises(SystemExit) as exit_info:
        main(["explain", str(path), "--method", "z-buffer"])
    err = capsys.readouterr().err
    assert exit_info.value.code == 1 and "expected one of 'depth-buffer', 'scan-line'" in err


def test_scene_file_render_method_and_transparency(tmp_path) -> None:
    from frustum.errors import SceneFileError
    from frustum.scenefile import load_scene_file

    path = tmp_path / "ball.toml"
    path.write_text(
        SCENE_FILE.replace("size = [48, 32]", 'size = [48, 32]\nmethod = "scan-line"\ntransparency = "a-buffer"')
    )
    scene_file = load_scene_file(path)
    assert scene_file.options["method"] == "scan-line" and scene_file.options["transparency"] == "a-buffer"
    frame = render(scene_file.scene, scene_file.cameras[0], **scene_file.options)
    assert frame.stats["method"] == "scan-line"
    assert_same_picture(frame, render(scene_file.scene, scene_file.cameras[0]))
    path.write_text(SCENE_FILE.replace("size = [48, 32]", 'size = [48, 32]\nmethod = "ray-casting"'))
    assert load_scene_file(path).options["method"] == "ray-casting"
    path.write_text(SCENE_FILE.replace("size = [48, 32]", 'size = [48, 32]\nmethod = "path-tracing"'))
    with pytest.raises(SceneFileError, match=r"ball.toml:8: render.method = 'path-tracing' .*'ray-casting'"):
        load_scene_file(path)


def test_polylines_are_drawn_as_lines_against_each_methods_depth() -> None:
    """Items a surface method cannot fill (curves as Polyline) are converted: drawn as lines, depth-tested against
    whatever depth the chosen method found, as the depth buffer draws them."""
    from frustum.geometry import Polyline

    camera = flat_camera()
    scene = flat_scene(quad(2.0, 2.0, 12.0, 12.0, 0.0))
    scene.add(Polyline([[1.0, 7.0, 1.0], [15.0, 7.0, -1.0]]), material=Material(color=(1.0, 1.0, 0.0)))
    reference = render(scene, camera)
    for method in ("scan-line", "area-subdivision", "bsp", "a-buffer", "ray-casting"):
        frame = render(scene, camera, method=method)
        yellow = (frame.color[..., 0] == 255) & (frame.color[..., 1] == 255) & (frame.color[..., 2] == 0)
        expected = (reference.color[..., 0] == 255) & (reference.color[..., 1] == 255) & (reference.color[..., 2] == 0)
        assert yellow.sum() > 4 and (yellow == expected).all(), method


def test_octrees_are_drawn_by_every_method_as_their_cell_faces() -> None:
    """A placed Octree is, for the mesh methods, its cell faces (``Scene.items``): each method draws them as the
    depth buffer does; ``method="octree"`` is the octree method itself."""
    from frustum.geometry import Octree

    solid = Octree.from_function(lambda x, y, z: x * x + y * y + z * z - 0.8**2, ((-1, -1, -1), (1, 1, 1)), 3)
    scene = Scene(lights=[LIGHT])
    scene.add(solid, material=Material(color=(0.8, 0.5, 0.3)))
    camera = Camera.look_at((1.5, 2.0, 3.0), (0.0, 0.0, 0.0), width=48, height=40)
    reference = render(scene, camera)
    assert (reference.depth < 1.0).sum() > 100
    for method in ("scan-line", "area-subdivision", "bsp", "ray-casting"):
        assert_same_picture(render(scene, camera, method=method), reference)


def test_parallel_methods_give_the_same_bytes_and_counts_on_any_number_of_threads() -> None:
    from frustum.raster._jit import set_threads

    scene, camera = soup_scene(6)
    scene.add(quad(-1, -1, 1, 1, 0.3), material=Material(color=(0.9, 0.9, 0.2), opacity=0.5))
    try:
        results = []
        for count in (1, 3, 7):
            set_threads(count)
            methods = ("scan-line", "a-buffer", "ray-casting")
            results.append([render(scene, camera, method=m, transparency="a-buffer") for m in methods])
    finally:
        set_threads(None)
    for frames in results[1:]:
        for frame, first in zip(frames, results[0], strict=True):
            assert frame.color.tobytes() == first.color.tobytes() and frame.depth.tobytes() == first.depth.tobytes()
            assert frame.stats == first.stats
