"""The renderer against the slow reference rasterizer; top-left rule, near plane, determinism, bad input."""

from __future__ import annotations

import io
import math

import numba
import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image
from tests.reference_raster import placed, reference_render

from frustum import Camera, CameraError, FrustumError, GeometryError, Orthographic, Perspective, clip_triangles
from frustum.errors import ShadingError
from frustum.frame import Frame
from frustum.geometry import Mesh
from frustum.raster.vertices import transform_vertices
from frustum.render import bin_item, render
from frustum.render.buffers import block_min as _block_min
from frustum.render.buffers import resolve_color
from frustum.render.stages import item_matrices as _item_matrices
from frustum.scene import Scene, SceneItem
from frustum.shading import DirectionalLight, Material
from frustum.transforms import apply_homogeneous, rotate_y, translate
from frustum.visibility import backface_mask

BACKGROUND = (26 / 255, 26 / 255, 31 / 255, 1.0)
LIGHT = DirectionalLight(direction=(-0.4, -0.8, -0.5))


def sphere_mesh(subdivisions: int = 1, radius: float = 1.0) -> Mesh:
    sphere = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    return Mesh(sphere.vertices, sphere.faces, vertex_normals=sphere.vertex_normals)


def open_cylinder() -> Mesh:
    """An open tube (no caps): its inside shows through the ends, so back faces are visible."""
    tube = trimesh.creation.cylinder(radius=0.6, height=1.6, sections=12)
    keep = np.abs(tube.face_normals[:, 2]) < 0.5  # drop the caps
    return Mesh(tube.vertices, tube.faces[keep])


def small_scene() -> tuple[Scene, Camera]:
    """Two items (one moved and turned), a ground quad crossing the near plane and reaching behind the eye."""
    scene = Scene(lights=[LIGHT])
    scene.add(sphere_mesh(1), material=Material(color=(0.8, 0.5, 0.3)))
    scene.add(
        open_cylinder(), material=Material(color=(0.3, 0.6, 0.9)), transform=translate(1.6, 0.2, -0.5) @ rotate_y(0.7)
    )
    ground = Mesh(
        [[-20.0, -1.2, -20.0], [20.0, -1.2, -20.0], [20.0, -1.2, 20.0], [-20.0, -1.2, 20.0]], [[0, 2, 1], [0, 3, 2]]
    )
    scene.add(ground, material=Material(color=(0.5, 0.7, 0.4), specular=0.0))
    camera = Camera.look_at(
        (0.4, 0.9, 3.2), (0.3, 0.0, 0.0), (0, 1, 0), projection=Perspective(1.0, 0.3, 30.0), width=48, height=36
    )
    return scene, camera


@pytest.mark.parametrize("shading", ["phong", None])
@pytest.mark.parametrize("cull", [True, False])
def test_render_equals_reference_byte_for_byte(shading, cull):
    scene, camera = small_scene()
    frame = render(scene, camera, shading=shading, background=BACKGROUND, cull_back_faces=cull)
    color, depth = reference_render(scene, camera, shading=shading, background=BACKGROUND, cull_back_faces=cull)
    assert frame.color.shape == (36, 48, 4) and frame.depth.dtype == np.float32
    assert (frame.depth < 1.0).mean() > 0.5  # the scene fills most of the image: the test is not vacuous
    np.testing.assert_array_equal(frame.depth, depth)
    np.testing.assert_array_equal(frame.color, color)


def test_two_sided_lighting_shows_the_inside_of_an_open_surface():
    scene = placed(Scene(lights=[LIGHT]), open_cylinder(), material=Material(color=(0.3, 0.6, 0.9)))
    camera = Camera.look_at(
        (0.0, 0.0, 3.0), (0, 0, 0), (0, 1, 0), projection=Perspective(0.9, 0.5, 10.0), width=40, height=40
    )
    culled = render(scene, camera, cull_back_faces=True)
    both = render(scene, camera, cull_back_faces=False)
    seen_through = (culled.depth == 1.0) & (both.depth < 1.0)
    assert seen_through.sum() > 20  # the tube's inner wall, visible through its open end
    color, depth = reference_render(scene, camera, cull_back_faces=False)
    np.testing.assert_array_equal(both.color, color)
    np.testing.assert_array_equal(both.depth, depth)


# --- the top-left rule ---------------------------------------------------------------------------------------


def window_camera(width: int = 48, height: int = 40) -> Camera:
    """Orthographic camera whose world x, y are window x, y (y up): pixel centres at half-integers."""
    eye = (width / 2, height / 2, 10.0)
    return Camera.look_at(
        eye,
        (width / 2, height / 2, 0.0),
        (0, 1, 0),
        projection=Orthographic(height, 1.0, 20.0),
        width=width,
        height=height,
    )


def coverage(points, faces, camera) -> np.ndarray:
    """(H, W) bool coverage of one mesh, flat shading, no culling surprises (faces are counter-clockwise)."""
    scene = placed(Scene(), Mesh(points, faces))
    return render(scene, camera, shading=None).depth < 1.0


def test_two_triangles_sharing_an_edge_cover_every_pixel_once():
    camera = window_camera()
    # a quad with corners on pixel centres, so whole rows and columns of centres lie exactly on its edges
    quad = [[8.5, 4.5, 0.0], [40.5, 4.5, 0.0], [40.5, 30.5, 0.0], [8.5, 30.5, 0.0]]
    first = coverage(quad, [[0, 1, 2]], camera)
    second = coverage(quad, [[0, 2, 3]], camera)
    assert not (first & second).any()  # no double hits on the shared diagonal
    expected = np.zeros((40, 48), dtype=bool)
    # top-left rule: the left edge x = 8.5 and the top edge y = 30.5 are in, right and bottom edges out
    for j in range(5, 31):
        expected[40 - 1 - j, 8:40] = True
    np.testing.assert_array_equal(first | second, expected)


def test_fan_around_a_vertex_covers_every_pixel_once():
    camera = window_camera()
    centre = [24.5, 20.5, 0.0]
    ring = [[24.5 + 12 * math.cos(a), 20.5 + 12 * math.sin(a), 0.0] for a in np.linspace(0, 2 * math.pi, 13)[:-1]]
    ring += [[36.5, 20.5, 0.0], [24.5, 32.5, 0.0], [12.5, 8.5, 0.0]]  # exact centres among them
    ring = sorted(ring, key=lambda p: math.atan2(p[1] - 20.5, p[0] - 24.5))
    points = [centre, *ring]
    faces = [[0, 1 + k, 1 + (k + 1) % len(ring)] for k in range(len(ring))]
    hits = np.zeros((40, 48), dtype=np.int64)
    for face in faces:
        hits += coverage(points, [face], camera)
    assert hits.max() == 1  # no pixel twice
    np.testing.assert_array_equal(hits == 1, coverage(points, faces, camera))  # no gaps: the union is the fan
    assert hits[40 - 1 - 20, 24] == 1  # the shared centre vertex itself is covered exactly once


def _fixed(low: int, high: int) -> st.SearchStrategy[int]:
    """A window coordinate in 1/256 pixel: anywhere, or on a pixel centre (edges through centres: E = 0)."""
    return st.one_of(st.integers(low, high), st.integers(low // 256, high // 256).map(lambda i: 256 * i + 128))


@settings(max_examples=100, deadline=None)
@given(corners=st.lists(st.tuples(_fixed(-2000, 30000), _fixed(-2000, 12000)), min_size=3, max_size=3),
       fan=st.integers(3, 9))  # fmt: skip
def test_wide_and_thin_triangles_cover_exactly_the_centres_the_edge_functions_say(corners, fan):
    """Rows wider than ``triangles.NARROW`` find their covered span from the edge functions (float estimate,
    integer correction): the coverage equals the brute-force top-left rule at every centre (the reference's, for
    a triangle clipped at the image border), and a fan of such triangles around a point covers each centre of
    their union once."""
    camera = window_camera(112, 44)
    points = np.array([[x / 256.0, y / 256.0, 0.0] for x, y in corners])  # about on the 1/256 grid
    scene = placed(Scene(), Mesh(points, [[0, 1, 2]]))
    binned = bin_item(scene.items[0], camera, False)
    covered = render(scene, camera, shading=None, cull_back_faces=False).depth < 1.0
    if binned.vertex_codes.any():  # partly outside the image: clipped into records, against the reference
        _, depth = reference_render(scene, camera, shading=None, cull_back_faces=False)
        np.testing.assert_array_equal(covered, depth < 1.0)
        return
    snapped = binned.win_int.astype(np.int64)  # as the renderer snapped them
    (ux, uy), (vx, vy) = snapped[1] - snapped[0], snapped[2] - snapped[0]
    area = ux * vy - uy * vx
    order = [0, 1, 2] if area > 0 else [0, 2, 1]
    px = (256 * np.arange(112) + 128)[None, :]
    py = (256 * np.arange(44) + 128)[::-1, None]  # top row first
    inside = np.full((44, 112), area != 0)
    for a, b in ((order[1], order[2]), (order[2], order[0]), (order[0], order[1])):
        (ax, ay), (bx, by) = snapped[a], snapped[b]
        edge = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
        inside &= edge >= 0 if (by - ay < 0 or (by == ay and bx - ax < 0)) else edge > 0
    np.testing.assert_array_equal(covered, inside)
    centre = np.array([56.0, 22.0, 0.0]) + (points.mean(axis=0) % 1.0)
    ring = [centre + np.array([60 * math.cos(t), 20 * math.sin(t), 0.0]) for t in np.linspace(0, 2 * math.pi, fan + 1)]
    rim = np.array([centre, *ring[:-1]])
    faces = [[0, 1 + k, 1 + (k + 1) % fan] for k in range(fan)]
    hits = sum(coverage(rim, [face], camera).astype(np.int64) for face in faces)
    assert hits.max() <= 1
    np.testing.assert_array_equal(hits == 1, coverage(rim, faces, camera))


def test_span_of_an_edge_along_a_row_is_exact_where_the_float_estimate_rounds_wrong():
    """``triangles._span`` against the brute-force columns k with ``e − step·k >= bias``, at e exactly on and one
    away from every multiple of the step (where (e − bias)/step estimated in float64 can round across an
    integer), for steps of both signs, big and small, and windows that clip the span."""
    from frustum.raster.triangles import _span

    columns = np.arange(40)
    rounding = [-75, -77, -91, -93, -99, -105, 75, 91]  # m·step·fl(1/step) lands above m (m = 7, 3): ceil/floor off
    for step in [*range(-300 * 256, 301 * 256, 37 * 256 + 3), *rounding, -768, 768, -(2**20) - 256, 2**20 + 256, 0]:
        for bias in (0, 1):
            for m in (-3, 0, 1, 3, 7, 17, 39, 45):
                for e in {m * step + d for d in (-1, 0, 1)}:
                    for first, last in ((0, 39), (5, 30)):
                        keep = columns[(e - step * columns >= bias) & (columns >= first) & (columns <= last)]
                        low, high = _span(e, step, bias, 1.0 / step if step else 0.0, first, last)
                        if keep.size:
                            assert (low, high) == (keep[0], keep[-1]), (step, bias, e, first, last)
                        else:
                            assert low > high, (step, bias, e, first, last)


# --- near plane and behind the eye ---------------------------------------------------------------------------


def test_ground_reaching_behind_the_eye_stays_below_the_horizon():
    # a level camera above an infinite-looking floor: wrap-around would paint the upper half of the image
    floor = Mesh(
        [[-50.0, -1.0, -50.0], [50.0, -1.0, -50.0], [50.0, -1.0, 50.0], [-50.0, -1.0, 50.0]], [[0, 2, 1], [0, 3, 2]]
    )
    scene = placed(Scene(lights=[LIGHT]), floor)
    camera = Camera.look_at(
        (0.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0, 1, 0), projection=Perspective(1.2, 0.1, 40.0), width=40, height=30
    )
    frame = render(scene, camera, cull_back_faces=True)
    covered = frame.depth < 1.0
    assert not covered[:15].any()  # rows above the horizon (top half, top row first) see only background
    assert covered[-1].all()  # the bottom row is floor right up to the near plane
    assert (frame.depth[covered] >= 0.0).all()
    color, depth = reference_render(scene, camera)
    np.testing.assert_array_equal(frame.depth, depth)
    np.testing.assert_array_equal(frame.color, color)


def test_triangle_entirely_behind_the_eye_draws_nothing():
    behind = Mesh([[-1.0, -1.0, 2.0], [1.0, -1.0, 2.0], [0.0, 1.0, 2.0]], [[0, 1, 2]])
    scene = placed(Scene(lights=[LIGHT]), behind)
    camera = Camera.look_at((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0, 1, 0), width=16, height=16)
    for cull in (True, False):
        assert (render(scene, camera, cull_back_faces=cull).depth == 1.0).all()


# --- fast path against the textbook path ---------------------------------------------------------------------


def test_fast_path_window_coordinates_and_culling_equal_the_textbook_path():
    mesh = sphere_mesh(2, radius=0.8)
    camera = Camera.look_at(
        (0.3, 0.5, 3.0), (0, 0, 0), (0, 1, 0), projection=Perspective(0.9, 0.5, 10.0), width=64, height=48
    )
    item = placed(Scene(), mesh).items[0]
    clip = np.empty((mesh.vertex_count, 4))
    world, normals = np.empty((mesh.vertex_count, 3)), np.empty((mesh.vertex_count, 3))
    codes = np.empty(mesh.vertex_count, dtype=np.int64)
    from frustum.clipping import VIEW_VOLUME_PLANES

    transform_vertices(
        mesh.vertices,
        mesh.vertex_normals,
        _item_matrices(item, camera),
        VIEW_VOLUME_PLANES,
        clip,
        world,
        normals,
        codes,
    )
    # clip coordinates: the textbook apply_homogeneous (round-off of a different summation order only)
    np.testing.assert_allclose(clip, apply_homogeneous(camera.clip_from_world, mesh.vertices), rtol=0, atol=1e-12)
    assert clip_triangles(clip, mesh.faces).faces.shape == mesh.faces.shape  # wholly inside: nothing clipped
    binned = bin_item(item, camera, cull=True)
    np.testing.assert_array_equal(binned.vertex_codes, codes)  # the surface path's vertex stage: same codes
    assert binned.crossing.size == 0 and binned.tri_int.shape[0] == 0
    faces_drawn = np.unique(binned.tile_entries)
    # the kept faces are the front faces of the textbook back-face test, less those whose bounding box holds
    # no pixel centre (setup drops them: they cannot cover a pixel)
    front = np.flatnonzero(~backface_mask(mesh.vertices, mesh.faces, camera, "window"))
    assert np.isin(faces_drawn, front).all()
    window = camera.project(mesh.vertices)
    dropped = window[mesh.faces[np.setdiff1d(front, faces_drawn)]]  # (D, 3, 3)
    low, high = np.floor(dropped.min(axis=1)[:, :2] - 0.5), np.floor(dropped.max(axis=1)[:, :2] - 0.5)
    assert len(dropped) < len(front) // 10 and (low == high).any(axis=1).all()  # no centre strictly inside
    snapped = binned.win_int / 256.0
    assert np.abs(snapped - window[:, :2]).max() <= 0.5 / 256 + 1e-9  # snapping moves a point <= 1/512 px
    np.testing.assert_allclose(binned.win_float[:, 0], window[:, 2], rtol=0, atol=1e-12)  # depth: round-off only


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_line_path_vertex_stage_in_numpy_equals_the_kernel_bit_for_bit(dtype):
    """Lines and edges take their clip coordinates, world points and region codes from NumPy
    (``render.lines.clip_vertices``, no kernel to compile): the kernel's operations in its order, so the same bits."""
    from frustum.clipping import VIEW_VOLUME_PLANES
    from frustum.render import lines as pipeline
    points = (np.random.default_rng(1).normal(size=(2000, 3)) * 3).astype(dtype)
    world_from_model = np.array([[0.9, 0.1, 0.0, 0.3], [-0.1, 0.9, 0.2, -0.4], [0.0, -0.2, 1.1, 0.5], [0, 0, 0, 1.0]])
    camera = Camera.look_at(
        (0.3, 0.5, 3.0), (0, 0, 0), (0, 1, 0), projection=Perspective(0.9, 0.5, 10.0), width=64, height=48
    )
    clip, world, codes = pipeline.clip_vertices(points, world_from_model, camera)
    expected = np.empty((2000, 4)), np.empty((2000, 3)), np.empty((2000, 3)), np.empty(2000, dtype=np.int64)
    item = SceneItem(None, None, world_from_model)
    transform_vertices(points, np.ones((2000, 3)), _item_matrices(item, camera), VIEW_VOLUME_PLANES, expected[0],
                       expected[1], expected[2], expected[3])  # fmt: skip
    assert 0.3 < (codes != 0).mean() < 0.95  # points inside and outside: the codes are exercised
    np.testing.assert_array_equal(clip, expected[0])
    np.testing.assert_array_equal(world, expected[1])
    np.testing.assert_array_equal(codes, expected[3])


def test_crossing_faces_are_clipped_into_records_in_drawing_order():
    """A face crossing the view volume is listed once among the crossing faces and drawn from its clipped
    fan's records, each placed in the tile lists where the face is."""
    mesh = Mesh([[-3.0, -0.5, -2.0], [3.0, -0.5, -2.0], [0.0, 0.8, -2.0], [-0.2, -0.2, -1.5], [0.2, -0.2, -1.5],
                 [0.0, 0.2, -1.5]], [[0, 1, 2], [3, 4, 5]])  # fmt: skip
    camera = Camera.look_at((0, 0, 0), (0, 0, -1), (0, 1, 0), projection=Perspective(0.9, 0.5, 10.0), width=64,
                            height=48)  # fmt: skip
    binned = bin_item(placed(Scene(), mesh).items[0], camera, cull=True)
    assert binned.crossing.tolist() == [0]
    assert binned.tri_int.shape[0] >= 2 and (binned.tri_int[:, 6] // 2 == 0).all()
    for t in range(binned.tile_starts.size - 1):
        entries = binned.tile_entries[binned.tile_starts[t] : binned.tile_starts[t + 1]].tolist()
        if 1 in entries:  # the small face (drawn second) comes after every record of the big one in its tiles
            assert all(e < 0 for e in entries[: entries.index(1)]) and entries[entries.index(1) + 1 :] == []


def _one_mesh_scenes():
    ground = Mesh(
        [[-20.0, -1.2, -20.0], [20.0, -1.2, -20.0], [20.0, -1.2, 20.0], [-20.0, -1.2, 20.0]], [[0, 2, 1], [0, 3, 2]]
    )
    return {
        "sphere": (sphere_mesh(2), np.eye(4)),
        "open tube, turned": (open_cylinder(), translate(0.3, 0.0, 0.5) @ rotate_y(0.7)),
        "ground crossing the near plane": (ground, np.eye(4)),
    }


@pytest.mark.parametrize("name", list(_one_mesh_scenes()))
@pytest.mark.parametrize("cull", [True, False])
@pytest.mark.parametrize("size", [(48, 36), (1100, 40)])  # 1100: three segments of 8 tiles, a partial last tile
def test_one_mesh_tile_pipeline_equals_reference_byte_for_byte(name, cull, size, monkeypatch):
    """A frame of one opaque mesh on the directional fast path is cleared, filled and shaded tile by tile
    (``raster.tiled``): the same bytes as the reference, which shares no rasterizer code with it."""
    from frustum.raster import tiled

    calls = []
    original = tiled.draw_tiles_directional
    monkeypatch.setattr(tiled, "draw_tiles_directional", lambda *args: calls.append(1) or original(*args))
    mesh, transform = _one_mesh_scenes()[name]
    scene = Scene(lights=[LIGHT])
    scene.add(mesh, material=Material(color=(0.8, 0.5, 0.3)), transform=transform)
    camera = Camera.look_at(
        (0.4, 0.9, 3.2), (0.3, 0.0, 0.0), (0, 1, 0), projection=Perspective(0.8, 0.3, 30.0), width=size[0],
        height=size[1],
    )  # fmt: skip
    frame = render(scene, camera, background=BACKGROUND, cull_back_faces=cull)
    color, depth = reference_render(scene, camera, background=BACKGROUND, cull_back_faces=cull)
    assert calls, "the tile pipeline was not used"
    assert (frame.depth < 1.0).any() and (frame.depth == 1.0).any()
    np.testing.assert_array_equal(frame.depth, depth)
    np.testing.assert_array_equal(frame.color, color)


def test_frame_buffers_are_reused_only_when_no_frame_holds_them():
    """``FrameBuffers``: a Frame the caller keeps is never written by the next render; once dropped (and no view
    of it is alive), its buffers serve a later frame."""
    scene = Scene(lights=[LIGHT])
    scene.add(sphere_mesh(2), material=Material(color=(0.8, 0.5, 0.3)))
    camera = Camera.look_at((0, 0, 3.0), (0, 0, 0), (0, 1, 0), width=1024, height=1024)  # 4 MiB: pooled
    other = Camera.look_at((0, 2.0, 2.0), (0, 0, 0), (0, 1, 0), width=1024, height=1024)
    first = render(scene, camera, background=BACKGROUND)
    kept = first.color.copy(), first.depth.copy()
    second = render(scene, other, background=BACKGROUND)  # first is held: new buffers
    assert not np.shares_memory(first.color, second.color) and not np.shares_memory(first.depth, second.depth)
    np.testing.assert_array_equal(first.color, kept[0])
    np.testing.assert_array_equal(first.depth, kept[1])
    row = first.depth[100]  # a view keeps first's depth buffer (and only it) alive
    address = first.color.__array_interface__["data"][0]
    del first
    third = render(scene, other, background=BACKGROUND)
    # first's color buffer is reused (as color or depth: both are 4 MiB); the others are still held
    assert address in (third.color.__array_interface__["data"][0], third.depth.__array_interface__["data"][0])
    for held in (row, second.color, second.depth):
        assert not np.shares_memory(held, third.color) and not np.shares_memory(held, third.depth)
    np.testing.assert_array_equal(row, kept[1][100])
    np.testing.assert_array_equal(third.color, second.color)


# --- determinism ---------------------------------------------------------------------------------------------


def test_identical_bytes_across_runs_and_thread_counts():
    scene, camera = small_scene()
    first = render(scene, camera, background=BACKGROUND)
    again = render(scene, camera, background=BACKGROUND)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        single = render(scene, camera, background=BACKGROUND)
    finally:
        numba.set_num_threads(threads)
    for other in (again, single):
        assert first.color.tobytes() == other.color.tobytes()
        assert first.depth.tobytes() == other.depth.tobytes()


def test_work_arrays_reused_across_calls_and_renders_in_threads_give_the_same_bytes():
    """``Scratch`` hands the previous call's work arrays (uninitialized memory holding another frame) to the next
    call and to repeated meshes of one call; renders in concurrent threads each take their own."""
    import threading

    scene, camera = small_scene()
    scene.add(sphere_mesh(1), material=Material(color=(0.2, 0.9, 0.2)), transform=translate(-1.5, 0.0, -1.0))
    expected = render(scene, camera, background=BACKGROUND)
    other = Camera.look_at((3.0, 1.0, 1.0), (0, 0, 0), (0, 1, 0), width=48, height=36)
    render(scene, other, background=BACKGROUND)  # leaves its arrays (same shapes) in the pool
    results = []

    def worker():
        for _ in range(3):
            results.append(render(scene, camera, background=BACKGROUND))

    threads = [threading.Thread(target=worker) for _ in range(3)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(results) == 9
    for frame in results:
        assert frame.color.tobytes() == expected.color.tobytes()
        assert frame.depth.tobytes() == expected.depth.tobytes()


def test_extra_buffers_are_written_at_every_image_size_even_one_pixel():
    """Asking for normals or object ids takes the general shading kernel whatever the image size (a 1x1 image's
    buffers are the size of the kernels' placeholders, so the choice must not be made by size)."""
    scene = placed(Scene(lights=[LIGHT]), sphere_mesh(2))
    camera = Camera.look_at((0.0, 0.0, 3.0), (0, 0, 0), (0, 1, 0), width=1, height=1)
    frame = render(scene, camera, buffers=("normals", "object_id"))
    assert frame.object_id.tolist() == [[0]]
    np.testing.assert_allclose(frame.normals[0, 0], [0.0, 0.0, 1.0], atol=0.05)


# --- frame and output ----------------------------------------------------------------------------------------


def test_frame_png_round_trip(tmp_path):
    scene, camera = small_scene()
    frame = render(scene, camera)
    path = tmp_path / "out.png"
    frame.save(path)
    np.testing.assert_array_equal(np.asarray(Image.open(path)), frame.color)
    np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(frame._repr_png_()))), frame.color)
    assert not frame.color.flags.writeable and not frame.depth.flags.writeable


def test_frame_save_writes_png_for_any_case_of_the_suffix(tmp_path):
    # Frame.save lets Pillow pick the format from the temporary's suffix (".part.png"): an upper-case ".PNG" too
    color = np.random.default_rng(3).integers(0, 256, size=(5, 7, 4), dtype=np.uint8)
    frame = Frame(color, np.ones((5, 7), np.float32))
    for name in ("upper.PNG", "mixed.Png", "name.with.dots.png"):
        frame.save(tmp_path / name)
        with Image.open(tmp_path / name) as image:
            assert image.format == "PNG" and image.mode == "RGBA"
            np.testing.assert_array_equal(np.asarray(image), color)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mixed.Png", "name.with.dots.png", "upper.PNG"]


def test_frame_save_rejects_other_suffixes(tmp_path):
    frame = Frame(np.zeros((2, 3, 4), np.uint8), np.ones((2, 3), np.float32))
    with pytest.raises(FrustumError, match=r"suffix '\.jpg'"):
        frame.save(tmp_path / "out.jpg")
    with pytest.raises(FrustumError, match="cannot be written"):
        frame.save(tmp_path / "missing" / "out.png")


# --- bad input -----------------------------------------------------------------------------------------------


def test_empty_scene_renders_background_only():
    camera = Camera.look_at((0, 0, 3), (0, 0, 0), (0, 1, 0), width=8, height=6)
    frame = render(Scene(lights=[LIGHT]), camera, background=BACKGROUND)
    assert (frame.color == [26, 26, 31, 255]).all() and (frame.depth == 1.0).all()
    empty_mesh = placed(Scene(lights=[LIGHT]), Mesh(np.empty((0, 3)), np.empty((0, 3), dtype=int)))
    assert (render(empty_mesh, camera).depth == 1.0).all()


def test_bad_meshes_raise_geometry_errors():
    with pytest.raises(GeometryError, match=r"vertices\[1\] = .*nan.* not finite"):
        Mesh([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    with pytest.raises(GeometryError, match=r"faces\[0\] = \[0, 1, 3\] indexes outside the 3 vertices"):
        Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]])


def test_zero_size_image_raises_camera_error():
    with pytest.raises(CameraError, match="width = 0"):
        Camera.look_at((0, 0, 3), (0, 0, 0), (0, 1, 0), width=0, height=10)


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [({"ambient": float("nan")}, "ambient = nan"), ({"shininess": float("inf")}, "shininess = inf"),
     ({"color": (1.0, np.nan, 0.0)}, "color"), ({"diffuse": -1.0}, "negative")],
)  # fmt: skip
def test_bad_material_values_raise(kwargs, fragment):
    with pytest.raises(ShadingError, match=fragment):
        Material(**kwargs)


def test_bad_render_arguments_raise():
    scene, camera = small_scene()
    with pytest.raises(FrustumError, match=r"shading = 'toon' is unknown; expected one of 'phong', 'gouraud'"):
        render(scene, camera, shading="toon")
    with pytest.raises(FrustumError, match="background"):
        render(scene, camera, background=(0, 0, 2, 1))
    with pytest.raises(ShadingError, match="zero length"):
        DirectionalLight(direction=(0, 0, 0))
    with pytest.raises(FrustumError, match="not a Scene"):
        render([], camera)


@pytest.mark.parametrize("shading", ["phong", "flat", "gouraud"])
def test_a_reflected_mesh_keeps_its_front_faces_outward(shading):
    """det(M) < 0 turns the winding around; the renderer swaps it back, so a mirrored box is lit, not culled."""
    from frustum import box, reflect

    camera = Camera.look_at((1.5, 2.0, 5.0), (0, 0, 0), (0, 1, 0), width=64, height=48)
    plain, mirrored = Scene(lights=[LIGHT]), Scene(lights=[LIGHT])
    plain.add(box())
    mirrored.add(box(), transform=reflect("xy"))  # the box is symmetric about z = 0: the same picture
    a, b = render(plain, camera, shading=shading), render(mirrored, camera, shading=shading)
    assert ((a.depth < 1) == (b.depth < 1)).all()  # the mirrored triangulation differs: depths to round-off
    assert np.abs(a.depth - b.depth).max() < 1e-5
    assert (np.abs(a.color.astype(int) - b.color.astype(int)).max(axis=2) <= 1).mean() > 0.999


# --- compact Mesh storage (issue 16, memory) -----------------------------------------------------------------


@pytest.mark.parametrize(
    "options",
    [
        dict(shading="phong"),
        dict(shading="phong", specular="phong"),
        dict(shading="gouraud"),
        dict(shading="flat", buffers=("normals", "object_id")),
        dict(shading="normals"),
        dict(mode="surface+edges"),
        dict(mode="hidden-line"),
        dict(shading="phong", method="scan-line"),
        dict(shading="gouraud", method="depth-sort"),
    ],
    ids=lambda o: ",".join(f"{k}={v}" for k, v in o.items()),
)
def test_a_float32_int32_mesh_renders_the_same_bytes_as_its_float64_int64_copy(options):
    # float32 → float64 is exact: a Mesh keeping float32 vertices must draw exactly what their float64 copy draws
    sphere = trimesh.creation.icosphere(subdivisions=2)
    vertices32 = (sphere.vertices * [1.0, 0.8, 1.2]).astype(np.float32)
    compact = Mesh(vertices32, sphere.faces.astype(np.int32))
    wide = Mesh(vertices32.astype(np.float64), sphere.faces.astype(np.int64))
    assert compact.vertices.dtype == np.float32 and compact.faces.dtype == np.int32
    camera = Camera.look_at((0.4, 0.6, 3.2), (0, 0, 0), (0, 1, 0), projection=Perspective(0.9, 0.5, 10.0),
                            width=96, height=80)  # fmt: skip
    for both in (False, True):  # one opaque mesh (the tiled fast path where it applies), then two items
        frames = []
        for mesh in (compact, wide):
            scene = Scene(lights=[LIGHT])
            scene.add(mesh, Material(color=(0.8, 0.5, 0.3), specular=0.4, shininess=20.0))
            if both:
                scene.add(mesh, Material(color=(0.3, 0.6, 0.9), opacity=0.5), rotate_y(0.3) @ translate(0.9, 0.1, -0.4))
            frames.append(render(scene, camera, background=BACKGROUND, **options))
        np.testing.assert_array_equal(frames[0].color, frames[1].color)
        np.testing.assert_array_equal(frames[0].depth, frames[1].depth)
        for name in ("normals", "object_id"):
            if getattr(frames[1], name) is not None:
                np.testing.assert_array_equal(getattr(frames[0], name), getattr(frames[1], name))


def test_float32_normals_render_within_one_level_of_float64_normals_on_the_same_pixels():
    # float32 normals are stored as the float32 nearest the float64 unit vector: not bit-identical shading, but the
    # same coverage and depth, and colors within one level (the benchmark's tolerance against llvmpipe)
    sphere = trimesh.creation.icosphere(subdivisions=3)
    vertices32 = sphere.vertices.astype(np.float32)
    normals = sphere.vertex_normals * (1.0 + np.arange(len(sphere.vertices)) % 3)[:, None]  # not unit: normalized
    compact = Mesh(vertices32, sphere.faces, vertex_normals=normals.astype(np.float32))
    wide = Mesh(vertices32, sphere.faces, vertex_normals=normals.astype(np.float32).astype(np.float64))
    assert compact.vertex_normals.dtype == np.float32 and wide.vertex_normals.dtype == np.float64
    camera = Camera.look_at((0.4, 0.6, 3.2), (0, 0, 0), (0, 1, 0), projection=Perspective(0.9, 0.5, 10.0),
                            width=160, height=160)  # fmt: skip
    for shading in ("phong", "gouraud"):
        frames = []
        for mesh in (compact, wide):
            scene = Scene(lights=[LIGHT])
            scene.add(mesh, Material(color=(0.8, 0.5, 0.3), specular=0.4, shininess=20.0))
            frames.append(render(scene, camera, shading=shading, background=BACKGROUND))
        np.testing.assert_array_equal(frames[0].depth, frames[1].depth)
        difference = np.abs(frames[0].color.astype(int) - frames[1].color.astype(int)).max(axis=-1)
        assert difference.max() <= 1 and (difference == 0).mean() >= 0.999, shading


# --- supersampling resolve ----------------------------------------------------------------------------------------


def _rounded_block_means(big: np.ndarray, factor: int) -> np.ndarray:
    """Oracle: each s×s block's mean rounded half up, in exact Python fractions, pixel by pixel."""
    from fractions import Fraction

    height, width = big.shape[0] // factor, big.shape[1] // factor
    out = np.zeros((height, width, big.shape[2]), dtype=np.uint8)
    for y in range(height):
        for x in range(width):
            block = big[y * factor : (y + 1) * factor, x * factor : (x + 1) * factor].astype(int)
            for c in range(big.shape[2]):
                out[y, x, c] = math.floor(Fraction(int(block[:, :, c].sum()), factor * factor) + Fraction(1, 2))
    return out


@pytest.mark.parametrize("factor", [1, 2, 3, 4, 5, 16, 17])
def test_resolve_color_is_the_rounded_block_mean(factor):
    # 16 is the last factor summed in uint16 (255·256 + 128 < 2¹⁶); 17 takes the uint32 path
    rng = np.random.default_rng(factor)
    big = rng.integers(0, 256, size=(3 * factor, 4 * factor, 4), dtype=np.uint8)
    big[:factor, :factor] = 255  # a saturated block: the largest sum
    big[:factor, factor : 2 * factor] = 0
    big[factor : 2 * factor, :factor, 0] = 128  # an exact .5 mean for even areas: rounds up
    big[factor, 0, 0] = 127
    resolved = resolve_color(big, factor)
    assert resolved.dtype == np.uint8 and resolved.shape == (3, 4, 4)
    np.testing.assert_array_equal(resolved, _rounded_block_means(big, factor))
    assert (resolved[0, 0] == 255).all() and (resolved[0, 1] == 0).all()


@given(factor=st.integers(1, 4), height=st.integers(1, 5), width=st.integers(1, 5), seed=st.integers(0, 2**32 - 1))
@settings(max_examples=40, deadline=None)
def test_block_min_matches_the_reduction(factor, height, width, seed):
    rng = np.random.default_rng(seed)
    depth = rng.random((height * factor, width * factor), dtype=np.float32)
    depth[rng.random(depth.shape) < 0.3] = np.inf  # background samples
    expected = depth.reshape(height, factor, width, factor).min(axis=(1, 3))
    result = _block_min(depth, factor)
    assert result.dtype == depth.dtype
    np.testing.assert_array_equal(result, expected)


@pytest.mark.parametrize("cull", [True, False])
def test_tile_pipeline_of_a_fine_mesh_equals_reference_byte_for_byte(cull):
    """Triangles of about a pixel, most of whose boxes hold at most 2 × 2 centres (``triangles._fill_tile`` tests
    those four centres as one mask): the same bytes as the reference."""
    from frustum.raster.fixed_point import SUBPIXEL
    from frustum.render import bin_item

    scene = Scene(lights=[LIGHT])
    scene.add(sphere_mesh(5), material=Material(color=(0.8, 0.5, 0.3)))
    camera = Camera.look_at((0.4, 0.9, 3.2), (0.0, 0.0, 0.0), (0, 1, 0), projection=Perspective(0.8, 0.3, 30.0),
                            width=160, height=120)  # fmt: skip
    binned = bin_item(scene.items[0], camera, cull=cull)
    corners = binned.win_int[binned.faces].astype(np.int64)  # (F, 3, 2) snapped window coordinates
    span = (corners.max(axis=1) - corners.min(axis=1)) / SUBPIXEL
    assert (span.max(axis=1) < 2.0).mean() > 0.5  # most boxes are at most 2 x 2 centres: the test is not vacuous
    frame = render(scene, camera, background=BACKGROUND, cull_back_faces=cull)
    color, depth = reference_render(scene, camera, background=BACKGROUND, cull_back_faces=cull)
    assert (frame.depth < 1.0).mean() > 0.3
    np.testing.assert_array_equal(frame.depth, depth)
    np.testing.assert_array_equal(frame.color, color)


def test_clipping_in_one_pass_or_two_gives_the_same_frame(monkeypatch):
    """Faces crossing the view volume are clipped once into ``FAN_MAX`` slots each (``render.stages.ONE_PASS_CLIPPING``
    or fewer of them) or counted first and then written: the same records, the same bytes as the reference."""
    import importlib

    pipeline = importlib.import_module("frustum.render.stages")  # binning reads ONE_PASS_CLIPPING there
    scene, camera = small_scene()  # its ground crosses the near plane
    binned = pipeline.bin_item(scene.items[2], camera, cull=True)
    assert binned.crossing.size and binned.tri_int.shape[0] > binned.crossing.size
    one = render(scene, camera, background=BACKGROUND)
    monkeypatch.setattr(pipeline, "ONE_PASS_CLIPPING", 0)
    again = pipeline.bin_item(scene.items[2], camera, cull=True)
    for name in ("tri_int", "tri_float", "tri_weights", "tile_starts", "tile_entries"):
        np.testing.assert_array_equal(getattr(again, name), getattr(binned, name), err_msg=name)
    two = render(scene, camera, background=BACKGROUND)
    color, depth = reference_render(scene, camera, background=BACKGROUND)
    for frame in (one, two):
        np.testing.assert_array_equal(frame.color, color)
        np.testing.assert_array_equal(frame.depth, depth)


def test_world_attributes_from_numpy_or_the_kernels_give_the_same_frame(monkeypatch):
    """Meshes under ``render.stages.KERNEL_MIN_VERTICES`` vertices get world points and normals from NumPy (no kernel to
    compile), larger ones from ``raster.vertices``: the same operations in order, the same bits."""
    import importlib

    pipeline = importlib.import_module("frustum.render.stages")
    scene, camera = small_scene()  # its tube is moved and turned: world points and normals are transformed
    item = scene.items[1]
    numpy_world, numpy_normals = pipeline.world_attributes(item, pipeline.Scratch())
    assert item.mesh.vertex_count < pipeline.KERNEL_MIN_VERTICES
    first = render(scene, camera, background=BACKGROUND, shading="phong")
    monkeypatch.setattr(pipeline, "KERNEL_MIN_VERTICES", 0)
    kernel_world, kernel_normals = pipeline.world_attributes(item, pipeline.Scratch())
    np.testing.assert_array_equal(numpy_world, kernel_world)
    np.testing.assert_array_equal(numpy_normals, kernel_normals)
    again = render(scene, camera, background=BACKGROUND, shading="phong")
    np.testing.assert_array_equal(first.color, again.color)
    np.testing.assert_array_equal(first.depth, again.depth)
