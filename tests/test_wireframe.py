"""Wireframe lines and points (``render(..., mode=...)``, ``raster/lines.py``) against a slow reference.

The reference below shares no code with the kernel. It follows the rules written in the ``raster/lines.py``
docstring: clip = M·[x, y, z, 1] row by row as ((m0·x + m1·y) + m2·z) + m3; edges collected in a Python set;
clipping by the public ``frustum.clip_lines`` (tested on its own in ``test_clipping.py``); window
``x = (x_c/w)·(W/2) + W/2`` snapped to ``floor(x·256 + 0.5)``; then **every** column (or row) of the image is
tested for a pixel centre inside the closed major-axis span, the covered row found with exact ``Fraction``
arithmetic, and the depth ``z_a + (z_b − z_a)·t`` compared as float32 with "less", line after line.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
import trimesh
from tests.reference_raster import placed

from frustum import Camera, FrustumError, Orthographic, Perspective, clip_lines
from frustum.clipping import VIEW_VOLUME_PLANES
from frustum.geometry import Mesh
from frustum.raster import lines
from frustum.render import mesh_edges, render
from frustum.scene import Scene
from frustum.shading import DirectionalLight, Material

WIDTH, HEIGHT = 48, 32
BACKGROUND = (26 / 255, 26 / 255, 31 / 255, 1.0)


# --- the slow reference -----------------------------------------------------------------------------------


def _reference_edges(faces: np.ndarray) -> set[tuple[int, int]]:
    edges = set()
    for face in np.asarray(faces).tolist():
        for k in range(3):
            a, b = face[k], face[(k + 1) % 3]
            edges.add((min(a, b), max(a, b)))
    return edges


def _reference_clip(item, camera) -> np.ndarray:
    matrix = camera.clip_from_world @ np.asarray(item.world_from_model, dtype=np.float64)
    points = np.asarray(item.mesh.vertices, dtype=np.float64)
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    return np.stack([((matrix[k, 0] * x + matrix[k, 1] * y) + matrix[k, 2] * z) + matrix[k, 3] for k in range(4)], 1)


def _window(point: np.ndarray, width: int, height: int) -> tuple[int, int, float]:
    x, y, z, w = (float(v) for v in point)
    snap_x = math.floor(((x / w) * (width / 2.0) + width / 2.0) * 256.0 + 0.5)
    snap_y = math.floor(((y / w) * (height / 2.0) + height / 2.0) * 256.0 + 0.5)
    return snap_x, snap_y, (z / w) * 0.5 + 0.5


def _plot(depth, color, i, j, z, rgba):
    """Window pixel (i, j), y up; the buffers are top row first."""
    row = depth.shape[0] - 1 - j
    if np.float32(z) < depth[row, i]:
        depth[row, i] = np.float32(z)
        color[row, i] = rgba


def _reference_line(depth, color, a, b, rgba):
    """Pixels of one snapped segment a → b = (X, Y, z): one per column (row) whose centre lies in the span."""
    height, width = depth.shape
    (xa, ya, za), (xb, yb, zb) = a, b
    if xa == xb and ya == yb:
        return
    x_major = abs(xb - xa) >= abs(yb - ya)
    if not x_major:  # work in (major, minor) = (y, x)
        xa, ya, xb, yb = ya, xa, yb, xb
        width, height = height, width
    if xb < xa:
        xa, ya, za, xb, yb, zb = xb, yb, zb, xa, ya, za
    for i in range(width):
        centre = 256 * i + 128
        if not xa <= centre <= xb:
            continue
        minor = Fraction(ya) + Fraction((yb - ya) * (centre - xa), xb - xa)  # exact height at the centre
        j = min(math.floor(minor / 256), height - 1)
        if j < 0:
            continue
        z = za + (zb - za) * ((centre - xa) / (xb - xa))
        if x_major:
            _plot(depth, color, i, j, z, rgba)
        else:
            _plot(depth, color, j, i, z, rgba)


def _rgba(material: Material) -> np.ndarray:
    return np.array([math.floor(float(c) * 255.0 + 0.5) for c in material.color] + [255], dtype=np.uint8)


def reference_lines(scene, camera, mode, background=BACKGROUND):
    """(color, depth) of ``render(scene, camera, mode=mode)`` by the rules of the module docstring."""
    width, height = camera.width, camera.height
    depth = np.ones((height, width), dtype=np.float32)
    color = np.empty((height, width, 4), dtype=np.uint8)
    color[:, :] = [math.floor(v * 255.0 + 0.5) for v in background]
    for item in scene.items:
        clip = _reference_clip(item, camera)
        rgba = _rgba(item.material)
        if mode == "points":
            x, y, z, w = clip.T
            inside = (w + x >= 0) & (w - x >= 0) & (w + y >= 0) & (w - y >= 0) & (w + z >= 0) & (w - z >= 0)
            for v in np.flatnonzero(inside):
                snap_x, snap_y, z_w = _window(clip[v], width, height)
                i, j = min(snap_x // 256, width - 1), min(snap_y // 256, height - 1)
                if i >= 0 and j >= 0:
                    _plot(depth, color, i, j, z_w, rgba)
            continue
        edges = sorted(_reference_edges(item.mesh.faces))
        if not edges:
            continue
        pairs = np.array(edges)
        clipped = clip_lines(clip[pairs[:, 0]], clip[pairs[:, 1]])
        for k in np.flatnonzero(clipped.keep):
            a = _window(clipped.starts[k], width, height)
            b = _window(clipped.ends[k], width, height)
            _reference_line(depth, color, a, b, rgba)
    return color, depth


# --- scenes -----------------------------------------------------------------------------------------------


def cube() -> Mesh:
    box = trimesh.creation.box(extents=(1.4, 1.4, 1.4))
    return Mesh(box.vertices, box.faces)


def tetrahedron() -> Mesh:
    return Mesh([[0.0, 1.0, 0.0], [-0.9, -0.5, 0.6], [0.9, -0.5, 0.6], [0.0, -0.5, -0.9]],
                [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])  # fmt: skip


def ground() -> Mesh:
    """A big quad under the camera: it crosses the near plane and reaches behind the eye."""
    return Mesh(
        [[-20.0, -1.2, -20.0], [20.0, -1.2, -20.0], [20.0, -1.2, 20.0], [-20.0, -1.2, 20.0]], [[0, 2, 1], [0, 3, 2]]
    )


def perspective_camera() -> Camera:
    return Camera.look_at(
        (1.4, 1.1, 3.0), (0.1, 0.0, 0.0), (0, 1, 0), projection=Perspective(1.0, 0.3, 30.0), width=WIDTH, height=HEIGHT
    )


def scenes() -> dict[str, Scene]:
    return {
        "cube": placed(Scene(), cube(), material=Material(color=(0.9, 0.6, 0.2))),
        "tetrahedron": placed(Scene(), tetrahedron(), material=Material(color=(0.2, 0.8, 0.4))),
        "three items": placed(
            placed(
                placed(Scene(), cube(), material=Material(color=(0.9, 0.6, 0.2))),
                tetrahedron(),
                material=Material(color=(0.2, 0.8, 0.4)),
                transform=np.diag([1.2, 1.2, 1.2, 1.0]),
            ),
            ground(),
            material=Material(color=(0.5, 0.5, 1.0)),
        ),
    }


# --- tests ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["cube", "tetrahedron", "three items"])
@pytest.mark.parametrize("mode", ["wireframe", "points"])
def test_lines_and_points_equal_reference_byte_for_byte(name, mode):
    scene, camera = scenes()[name], perspective_camera()
    frame = render(scene, camera, mode=mode, background=BACKGROUND)
    color, depth = reference_lines(scene, camera, mode)
    drawn = (frame.depth < 1.0).sum()
    assert drawn >= (4 if mode == "points" else 40)  # not vacuous: lines or points do land in the image
    assert frame.color.shape == (HEIGHT, WIDTH, 4) and frame.depth.dtype == np.float32
    np.testing.assert_array_equal(frame.depth, depth)
    np.testing.assert_array_equal(frame.color, color)


def _draw(starts_window, ends_window, z=(0.5, 0.5)) -> np.ndarray:
    """Draw segments given in window coordinates (w = 1) straight through the kernel; returns the depth buffer."""
    view = np.array([WIDTH / 2.0, HEIGHT / 2.0])
    points = []
    for (x0, y0), (x1, y1) in zip(starts_window, ends_window, strict=True):
        points.append([(x0 - view[0]) / view[0], (y0 - view[1]) / view[1], 2.0 * z[0] - 1.0, 1.0])
        points.append([(x1 - view[0]) / view[0], (y1 - view[1]) / view[1], 2.0 * z[1] - 1.0, 1.0])
    clip = np.array(points)
    edges = np.arange(clip.shape[0], dtype=np.int64).reshape(-1, 2)
    depth = np.ones((HEIGHT, WIDTH), dtype=np.float32)
    color = np.zeros((HEIGHT, WIDTH, 4), dtype=np.uint8)
    red = np.array([255, 0, 0, 255], dtype=np.uint8)
    lines.draw_lines(
        clip, np.zeros(len(clip)), edges, np.array(VIEW_VOLUME_PLANES), view, lines.line_style(red), depth, color
    )
    return depth


def _covered(depth: np.ndarray) -> set[tuple[int, int]]:
    """Covered pixels as window (i, j), y up."""
    rows, cols = np.nonzero(depth < 1.0)
    return {(int(c), int(HEIGHT - 1 - r)) for r, c in zip(rows, cols, strict=True)}


def test_horizontal_line_covers_each_column_whose_centre_it_spans():
    # from pixel centre (2.5, 10.5) to (20.5, 10.5): columns 2..20 of window row 10, both ends included
    assert _covered(_draw([(2.5, 10.5)], [(20.5, 10.5)])) == {(i, 10) for i in range(2, 21)}
    # ends off the centres: centres 2.5 .. 20.5 lie in [2.2, 20.9]; height 10.9 lies in row 10
    assert _covered(_draw([(20.9, 10.9)], [(2.2, 10.9)])) == {(i, 10) for i in range(2, 21)}


def test_vertical_line_covers_each_row_whose_centre_it_spans():
    assert _covered(_draw([(5.5, 3.5)], [(5.5, 25.5)])) == {(5, j) for j in range(3, 26)}
    assert _covered(_draw([(5.0, 25.7)], [(5.0, 3.6)])) == {(5, j) for j in range(4, 26)}  # x = 5.0 is in column 5


def test_diagonal_line_covers_one_pixel_per_column():
    assert _covered(_draw([(1.5, 1.5)], [(9.5, 9.5)])) == {(i, i) for i in range(1, 10)}


def test_line_depth_is_linear_in_screen_space():
    depth = _draw([(0.5, 4.5)], [(10.5, 4.5)], z=(0.2, 0.7))
    row = depth[HEIGHT - 1 - 4, :11]
    expected = (0.2 + (0.7 - 0.2) * (np.arange(11) / 10)).astype(np.float32)
    np.testing.assert_allclose(row, expected, atol=1e-6)  # the ends' z_w went through 2z − 1 and back


def test_line_reaching_behind_the_eye_is_clipped_not_wrapped():
    # eye at the origin looking down −z; the segment runs from 5 in front of the eye to 5 behind it
    camera = Camera.look_at(
        (0, 0, 0), (0, 0, -1), (0, 1, 0), projection=Perspective(1.0, 0.5, 30.0), width=WIDTH, height=HEIGHT
    )
    segment = Mesh([[0.6, -0.4, -5.0], [0.6, -0.4, 5.0], [0.6, -0.4, 5.0 + 1e-3]], [[0, 1, 2]])
    behind = Mesh([[-1.0, 0.5, 2.0], [1.0, 0.5, 3.0], [0.0, -0.5, 4.0]], [[0, 1, 2]])
    scene = Scene()
    scene.add(segment, material=Material(color=(1, 1, 1)))
    scene.add(behind, material=Material(color=(1, 0, 0)))
    frame = render(scene, camera, mode="wireframe")
    covered = _covered(frame.depth)
    # window column of the far end (0.6, −0.4, −5): x_ndc = (0.6 / 5) / (tan(fovy/2)·aspect), x_w = 24·x_ndc + 24
    start_x = int((0.6 / 5.0) / (math.tan(0.5) * WIDTH / HEIGHT) * (WIDTH / 2) + WIDTH / 2)
    assert len(covered) > 5
    # the visible part runs from the far end toward the near plane: right and down of its start; a wrapped
    # (unclipped, divided by w < 0) line would also light pixels left of the centre and above it
    assert all(i >= start_x - 1 and j <= HEIGHT // 2 for i, j in covered)
    assert (frame.color[frame.depth < 1.0][:, :3] == 255).all()  # nothing of the triangle behind the eye
    color, depth = reference_lines(scene, camera, "wireframe", background=(0, 0, 0, 1))
    np.testing.assert_array_equal(frame.depth, depth)
    np.testing.assert_array_equal(frame.color, color)


def _ortho_pair(near_first: bool) -> tuple[Scene, Camera]:
    """The same triangle at two depths seen along −z by an orthographic camera: identical window x, y."""
    vertices = np.array([[-12.3, -7.1, 0.0], [14.2, -5.6, 0.0], [1.7, 9.4, 0.0]])
    lift = np.array([0.0, 0.0, 2.0])
    near = Mesh(vertices + lift, [[0, 1, 2]])
    far = Mesh(vertices - lift, [[0, 1, 2]])
    items = [(near, (0.0, 1.0, 0.0)), (far, (1.0, 0.0, 0.0))]
    scene = Scene()
    for mesh, rgb in items if near_first else items[::-1]:
        scene.add(mesh, material=Material(color=rgb))
    camera = Camera.look_at(
        (0, 0, 10), (0, 0, 0), (0, 1, 0), projection=Orthographic(HEIGHT, 1.0, 20.0), width=WIDTH, height=HEIGHT
    )
    return scene, camera


@pytest.mark.parametrize("near_first", [True, False])
def test_line_behind_a_nearer_line_is_hidden(near_first):
    scene, camera = _ortho_pair(near_first)
    frame = render(scene, camera, mode="wireframe")
    lit = frame.depth < 1.0
    assert lit.sum() > 40
    assert (frame.color[lit] == [0, 255, 0, 255]).all()  # only the near (green) item shows
    near_only = render(placed(Scene(), scene.items[0 if near_first else 1].mesh), camera, mode="wireframe")
    np.testing.assert_array_equal(frame.depth, near_only.depth)
    color, depth = reference_lines(scene, camera, "wireframe", background=(0, 0, 0, 1))
    np.testing.assert_array_equal(frame.color, color)
    np.testing.assert_array_equal(frame.depth, depth)


@pytest.mark.parametrize(("mesh", "edge_count"), [(cube(), 18), (tetrahedron(), 6)])
def test_an_edge_shared_by_two_faces_is_drawn_once(mesh, edge_count):
    edges = mesh_edges(mesh.faces)
    assert edges.shape == (edge_count, 2) and edges.dtype == np.int64  # V − E + F = 2, each edge in two faces
    assert {tuple(e) for e in edges.tolist()} == _reference_edges(mesh.faces)
    assert (edges[:, 0] < edges[:, 1]).all()


def test_drawing_an_edge_twice_changes_nothing():
    """Depth "less": a second pass over the same line never rewrites a pixel (so drawn-once is also safe)."""
    once = _draw([(2.2, 3.1)], [(30.7, 20.9)], z=(0.3, 0.6))
    twice = _draw([(2.2, 3.1), (30.7, 20.9)], [(30.7, 20.9), (2.2, 3.1)], z=(0.3, 0.6))
    assert _covered(once) == _covered(twice)


@pytest.mark.parametrize("mode", ["wireframe", "points"])
def test_lines_and_points_are_deterministic(mode):
    scene, camera = scenes()["three items"], perspective_camera()
    frames = [render(scene, camera, mode=mode) for _ in range(3)]
    for frame in frames[1:]:
        assert frame.color.tobytes() == frames[0].color.tobytes()
        assert frame.depth.tobytes() == frames[0].depth.tobytes()


def test_lines_ignore_lights_and_culling():
    scene, camera = scenes()["cube"], perspective_camera()
    lights = [DirectionalLight(direction=(0, -1, 0))]
    lit = placed(Scene(lights=lights), cube(), material=Material(color=(0.9, 0.6, 0.2)))
    a = render(scene, camera, mode="wireframe")
    b = render(lit, camera, mode="wireframe", shading="phong", cull_back_faces=True)
    c = render(lit, camera, mode="wireframe", shading=None, cull_back_faces=False)
    assert a.color.tobytes() == b.color.tobytes() == c.color.tobytes()


@pytest.mark.parametrize("mode", ["wires", "Surface", None, 3])
def test_render_rejects_unknown_mode(mode):
    scene, camera = scenes()["cube"], perspective_camera()
    with pytest.raises(FrustumError, match=r"mode = .* is unknown; expected one of 'surface', 'wireframe', 'points'"):
        render(scene, camera, mode=mode)
