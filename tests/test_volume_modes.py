"""Volumes outside the surface mode: wireframe / points / hidden-line, every visible-surface method, ``trace`` and
SVG output, each against the per-pixel numpy reference of ``test_volume`` over the picture without the volume."""

from __future__ import annotations

import base64
import io
import re

import numpy as np
import pytest
from PIL import Image
from tests.test_volume import _LIGHTS, _TF, _assert_close, _phantom, _reference

import frustum as f
from frustum.errors import FrustumError
from frustum.geometry.volume import TransferFunction, blobby_volume

_CAMERA = f.Camera.look_at((0.4, 0.9, 3.0), (0.0, 0.0, 0.0), width=24, height=18)
_STEP = 0.05
# a box through the volume (its front half inside the cloud) and a wall behind it
_BOX = f.box((1.2, 0.9, 1.4), (0.1, -0.1, 0.0))
_WALL = f.Mesh([[-3, -3, -0.6], [3, -3, -0.8], [3, 3, -0.8], [-3, 3, -0.6]], [[0, 1, 2], [0, 2, 3]])


def _meshes(materials=((0.2, 0.5, 0.3), (0.9, 0.9, 0.2))) -> f.Scene:
    scene = f.Scene(lights=_LIGHTS)
    scene.add(_WALL, f.Material(color=materials[0]))
    scene.add(_BOX, f.Material(color=materials[1]))
    return scene


def _with_volume(scene: f.Scene, mode: str = "composite", **options) -> f.Scene:
    scene.add_volume(_phantom(20), _TF, mode=mode, step=_STEP, level=0.45, **options)
    return scene


def _expected(under: f.Frame, mode: str = "composite") -> np.ndarray:
    """The reference ray caster over `under`'s colors, every ray stopped at `under`'s depth."""
    return _reference(_phantom(20), _TF, mode, _CAMERA, step=_STEP, level=0.45, under=under.color, depth=under.depth,
                      shade=mode == "isosurface", lights=_LIGHTS)  # fmt: skip


# --- line modes ----------------------------------------------------------------------------------------------


_LINE_CASES = [("wireframe", "composite"), ("points", "composite"), ("wireframe", "isosurface"),
               ("hidden-line", "composite")]  # fmt: skip


@pytest.mark.parametrize(("mode", "volume_mode"), _LINE_CASES)
def test_line_modes_composite_the_volume_over_their_lines_stopped_at_their_depth(mode, volume_mode):
    lines_only = f.render(_meshes(), _CAMERA, mode=mode)
    frame = f.render(_with_volume(_meshes(), volume_mode), _CAMERA, mode=mode)
    expected = _expected(lines_only, volume_mode)
    _assert_close(frame.color, expected)
    drawn = lines_only.depth < 1.0  # line (or point) pixels; in hidden-line mode the invisible surfaces
    assert drawn.sum() >= 6
    changed = np.abs(frame.color.astype(int) - lines_only.color.astype(int)).max(axis=-1) > 8
    assert changed[drawn].any()  # lines (hidden-line: the invisible surfaces) seen through the cloud
    assert mode == "hidden-line" or changed[~drawn].any()  # and the cloud over the background
    # the rays stop at the lines: casting through the whole box (no depth) gives another picture on their pixels
    free = _reference(_phantom(20), _TF, volume_mode, _CAMERA, step=_STEP, level=0.45, under=lines_only.color,
                      shade=volume_mode == "isosurface", lights=_LIGHTS)  # fmt: skip
    assert (np.abs(free.astype(int) - expected.astype(int))[drawn] > 4).any()
    if volume_mode == "composite":
        np.testing.assert_array_equal(frame.depth, lines_only.depth)  # a composite volume writes no depth


@pytest.mark.parametrize("mode", ["surface+edges", "surface"])
def test_surface_modes_cast_the_volume_over_their_edges_and_polylines(mode):
    def scene(volume: bool) -> f.Scene:
        result = _meshes()
        result.add(f.Polyline([[-0.8, 0.5, -0.4], [0.8, 0.6, -0.4]]), f.Material(color=(0.0, 1.0, 0.0)))  # behind cloud
        return _with_volume(result) if volume else result

    without = f.render(scene(False), _CAMERA, mode=mode, edge_color=(1.0, 0.0, 1.0))
    frame = f.render(scene(True), _CAMERA, mode=mode, edge_color=(1.0, 0.0, 1.0))
    _assert_close(frame.color, _expected(without))  # the rays stop at the surfaces and the polyline
    lines = np.all(without.color == (0, 255, 0, 255), axis=-1)
    if mode == "surface+edges":
        lines |= np.all(without.color == (255, 0, 255, 255), axis=-1)
    assert lines.sum() >= 5
    assert (np.abs(frame.color.astype(int) - without.color.astype(int)).max(axis=-1)[lines] > 8).any()  # dimmed


def test_wireframe_line_in_front_of_the_cloud_is_not_covered_and_one_behind_is_dimmed():
    volume = _phantom(20)
    front = f.Polyline([[-1.5, 0.0, 1.4], [1.5, 0.0, 1.4]])  # in front of the box [-1, 1]³ (eye at z = 3)
    back = f.Polyline([[-1.5, 0.3, -1.4], [1.5, 0.3, -1.4]])
    scene = f.Scene(lights=_LIGHTS)
    scene.add(front, f.Material(color=(0.0, 1.0, 0.0)))
    scene.add(back, f.Material(color=(0.0, 1.0, 0.0)))
    lines_only = f.render(scene, _CAMERA, mode="wireframe")
    scene.add_volume(volume, _TF, step=_STEP)
    frame = f.render(scene, _CAMERA, mode="wireframe")
    middle = 0.5 * (_CAMERA.project([0.0, 0.0, 1.4])[2] + _CAMERA.project([0.0, 0.3, -1.4])[2])
    front_pixels = (lines_only.color[..., 1] == 255) & (lines_only.depth < middle)
    back_pixels = (lines_only.color[..., 1] == 255) & (lines_only.depth > middle)
    assert front_pixels.sum() >= 10 and back_pixels.sum() >= 10
    inside = _reference(volume, _TF, "composite", _CAMERA, step=_STEP)[..., :3].sum(axis=-1) > 30  # over the cloud
    np.testing.assert_array_equal(frame.color[front_pixels & inside], lines_only.color[front_pixels & inside])
    assert (frame.color[back_pixels & inside, 1] < 250).all()


def test_points_mode_with_supersampling_draws_the_volume_like_the_surface_mode_where_no_point_is():
    scene = _with_volume(f.Scene(lights=_LIGHTS))
    surface = f.render(scene, _CAMERA, samples=4)
    points = f.render(scene, _CAMERA, mode="points", samples=4)  # no meshes: nothing but the volume
    np.testing.assert_array_equal(points.color, surface.color)


# --- visible-surface methods ----------------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["ray-casting", "a-buffer", "scan-line"])
def test_every_visible_surface_method_ray_casts_the_volume_up_to_its_surfaces(method):
    meshes_only = f.render(_meshes(), _CAMERA, method=method)
    frame = f.render(_with_volume(_meshes()), _CAMERA, method=method)
    _assert_close(frame.color, _expected(meshes_only))
    assert (np.abs(frame.color.astype(int) - meshes_only.color.astype(int)) > 8).any()
    assert frame.stats is not None and frame.stats["method"] == method


def test_a_buffer_composites_a_transparent_item_over_the_volume():
    def scene(volume: bool) -> f.Scene:
        result = _meshes()
        result.add(f.Mesh([[-4, -4, 1.5], [4, -4, 1.5], [4, 4, 1.5], [-4, 4, 1.5]], [[0, 1, 2], [0, 2, 3]]),
                   f.Material(color=(0.2, 0.2, 1.0), opacity=0.5))  # fmt: skip
        return _with_volume(result) if volume else result

    for method, transparency in (("a-buffer", "sort"), ("depth-buffer", "a-buffer")):
        glass_only = f.render(scene(False), _CAMERA, method=method, transparency=transparency)
        frame = f.render(scene(True), _CAMERA, method=method, transparency=transparency)
        sorted_frame = f.render(scene(True), _CAMERA)  # opaque, volume, then the glass blended over both
        difference = np.abs(frame.color.astype(int) - sorted_frame.color.astype(int)).max(axis=-1)
        # where the two compositings agree without the volume (away from the A-buffer's anti-aliased edges)
        agree = np.abs(glass_only.color.astype(int) - f.render(scene(False), _CAMERA).color.astype(int)).max(-1) <= 1
        assert agree.mean() >= 0.7
        assert difference[agree].max() <= 2
        assert (np.abs(frame.color.astype(int) - glass_only.color.astype(int)) > 4).any()  # the volume is seen


def test_octree_method_ray_casts_the_volume_over_the_octrees():
    tree = f.Octree.from_mesh(_BOX, 3)
    scene = f.Scene(lights=_LIGHTS)
    scene.add(tree, f.Material(color=(0.9, 0.9, 0.2)))
    octrees_only = f.render(scene, _CAMERA, method="octree")
    frame = f.render(_with_volume(scene), _CAMERA, method="octree")
    _assert_close(frame.color, _expected(octrees_only))
    assert (np.abs(frame.color.astype(int) - octrees_only.color.astype(int)) > 8).any()


# --- trace ----------------------------------------------------------------------------------------------------


def test_trace_of_a_scene_lists_each_volume_box_and_its_clipping():
    transform = f.compose(f.rotate_z(0.3), f.translate(0.2, 0.0, 0.0))
    scene = _meshes()
    scene.add_volume(_phantom(20), _TF, transform=transform)
    traced = f.trace(scene, _CAMERA)
    assert len(traced.parts) == 3
    part = traced.parts[2]
    assert part.label.startswith("volume 0 (composite, 20x20x20 grid)")
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    np.testing.assert_allclose(part.stage("modeling").points[:, :3], corners, atol=1e-12)
    world = corners @ transform[:3, :3].T + transform[:3, 3]
    np.testing.assert_allclose(part.stage("viewport").points, _CAMERA.project(world), atol=1e-9)
    assert part.triangles is not None and part.triangles.accepted.sum() == 12  # the box is wholly in view
    assert "volume 0" in str(traced) and "12 triangles" in str(traced)


# --- SVG --------------------------------------------------------------------------------------------------------


def _embedded(svg: str) -> np.ndarray:
    """The premultiplied RGBA (float, 0..255) of the SVG's volume image."""
    (data,) = re.findall(r'<g id="volumes"[^>]*><image [^>]*href="data:image/png;base64,([^"]+)"', svg)
    image = np.asarray(Image.open(io.BytesIO(base64.b64decode(data))).convert("RGBA")).astype(np.float64)
    image[..., :3] *= image[..., 3:] / 255.0
    return image


def test_svg_embeds_the_ray_cast_volume_as_an_image_equal_to_the_reference():
    scene = _with_volume(f.Scene(lights=_LIGHTS))
    svg = f.render_svg(scene, _CAMERA)
    expected = _reference(_phantom(20), _TF, "composite", _CAMERA, step=_STEP,
                          under=np.zeros((18, 24, 4), dtype=np.uint8))  # fmt: skip
    image = _embedded(svg)
    assert np.abs(image - expected).max() <= 1.5  # straight alpha in the PNG: C/A rounded, times A again
    assert (expected[..., 3] > 20).sum() >= 30


def test_svg_volume_image_is_stopped_by_faces_and_drawn_over_faces_and_lines():
    scene = _with_volume(_meshes())
    svg = f.render_svg(scene, _CAMERA, fill=True, hidden="dashed", stroke_width=1.0)
    faces_depth = f.render(_meshes(), _CAMERA, cull_back_faces=False).depth
    image = _embedded(svg)
    # over the faces the image is the part of the cloud in front of them (the reference stopped at their depth)
    expected = _reference(_phantom(20), _TF, "composite", _CAMERA, step=_STEP,
                          under=np.zeros((18, 24, 4), dtype=np.uint8), depth=faces_depth)  # fmt: skip
    lines = f.remove_hidden_lines([(i.mesh, i.world_from_model) for i in scene.items], _CAMERA, edges="feature")
    near_line = np.zeros((18, 24), dtype=bool)
    for (x0, y0), (x1, y1) in lines.visible:
        for t in np.linspace(0.0, 1.0, 64):
            near_line[min(int(18 - (y0 + t * (y1 - y0))), 17), min(int(x0 + t * (x1 - x0)), 23)] = True
    away = ~near_line  # where a visible line stops the rays, they end at its depth instead
    assert np.abs(image - expected)[away].max() <= 1.5
    assert away.mean() >= 0.3
    order = [svg.index(key) for key in ('<g id="faces"', '<g id="visible"', '<g id="volumes"')]
    assert order == sorted(order)


def test_svg_raster_of_a_volume_matches_render_over_the_same_background(tmp_path):
    pytest.importorskip("cairosvg")
    scene = _with_volume(f.Scene(lights=_LIGHTS))
    path = f.save_svg(f.render_svg(scene, _CAMERA, background="#336699"), tmp_path / "volume.png")
    rasterized = np.asarray(Image.open(path).convert("RGBA")).astype(int)
    rendered = f.render(scene, _CAMERA, background=(0x33 / 255, 0x66 / 255, 0x99 / 255, 1.0)).color.astype(int)
    assert rasterized.shape == rendered.shape
    assert np.abs(rasterized - rendered).max() <= 2


def test_isosurface_volume_in_svg_is_opaque_where_it_is_hit():
    volume = blobby_volume([[0.0, 0.0, 0.0]], 0.6, 32)
    scene = f.Scene(lights=_LIGHTS)
    scene.add_volume(volume, TransferFunction.preset("bone", (0, 1)), mode="isosurface", level=0.5)
    image = _embedded(f.render_svg(scene, _CAMERA))
    rendered = f.render(scene, _CAMERA)
    hit = rendered.depth < 1.0
    assert hit.sum() >= 10
    assert (image[hit, 3] == 255).all() and (image[~hit, 3] == 0).all()


# --- errors -----------------------------------------------------------------------------------------------------


def test_the_work_budget_of_a_volume_holds_in_line_modes_methods_and_svg():
    scene = f.Scene()
    scene.add_volume(_phantom(20), _TF, step=1e-9)
    calls = (lambda: f.render(scene, _CAMERA, mode="wireframe"), lambda: f.render(scene, _CAMERA, mode="points"),
             lambda: f.render(scene, _CAMERA, method="ray-casting"), lambda: f.render_svg(scene, _CAMERA))  # fmt: skip
    for call in calls:
        with pytest.raises(FrustumError, match=r"render: a volume of shape \(20, 20, 20\) .* needs about"):
            call()


def test_trace_with_a_model_matrix_and_a_scene_with_volumes_is_refused():
    scene = _with_volume(f.Scene())
    with pytest.raises(FrustumError, match=r"model = .* was given with a scene"):
        f.trace(scene, _CAMERA, model=np.eye(4))


def test_svg_volume_image_leaves_a_line_in_front_of_the_cloud_uncovered_and_dims_one_behind():
    volume = _phantom(20)
    scene = f.Scene(lights=_LIGHTS)
    # two lines over the dense part of the cloud (on different rows): one in front of it, one behind it
    scene.add(f.Polyline([[-1.5, 0.575, 1.5], [1.5, 0.575, 1.5]]), f.Material(color=(0.0, 1.0, 0.0)))
    scene.add(f.Polyline([[-1.5, -1.05, -1.5], [1.5, -1.05, -1.5]]), f.Material(color=(0.0, 1.0, 0.0)))
    lines_only = f.render(scene, _CAMERA, mode="wireframe")
    scene.add_volume(volume, _TF, step=_STEP)
    image = _embedded(f.render_svg(scene, _CAMERA))
    cloud = _reference(volume, _TF, "composite", _CAMERA, step=_STEP, under=np.zeros((18, 24, 4), dtype=np.uint8))
    middle = 0.5 * (_CAMERA.project([0.0, 0.575, 1.5])[2] + _CAMERA.project([0.0, -1.05, -1.5])[2])
    front = (lines_only.depth < middle) & (cloud[..., 3] > 10)
    back = (lines_only.depth > middle) & (lines_only.depth < 1.0) & (cloud[..., 3] > 10)
    assert front.sum() >= 5 and back.sum() >= 5
    assert (image[front, 3] == 0).all()  # the rays stop at the line: nothing of the cloud lies in front of it
    assert (image[back, 3] > 10).all()  # the cloud in front of the far line covers it partly


def test_a_drawing_sheet_refuses_a_scene_with_volumes_naming_what_draws_them():
    scene = _with_volume(_meshes())
    with pytest.raises(f.OutputError, match=r"drawing_sheet: scene has 1 volume \(Scene.add_volume\).*render_svg"):
        f.drawing_sheet(scene)
    scene.volumes.clear()
    assert "<svg" in f.drawing_sheet(scene)  # the meshes alone draw
