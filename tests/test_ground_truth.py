"""Ground-truth buffers (``frustum.render.ground_truth``), labels and ``frustum.annotate``: ids never blended,
amodal masks against each item rendered alone, object coordinates against ``position``, flow and keypoints against
OpenCV's ``projectPoints``, occlusion against the next frame's own depth buffer."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from frustum import Camera, DirectionalLight, FrustumError, Material, Node, Scene, annotate, render, translate
from frustum.batch.cameras import OPENCV_FROM_OPENGL, intrinsics, metric_depth
from frustum.geometry.primitives import box, icosphere, torus
from frustum.render.ground_truth import DEPTH_TOLERANCE
from frustum.scenefile import load_scene
from frustum.transforms import rotate, rotate_y

cv2 = pytest.importorskip("cv2")

WIDTH, HEIGHT = 64, 48


def _scene(offsets=((0.0, 0.0, 0.0), (0.35, 0.1, 0.6), (-0.7, 0.0, -0.3))) -> Scene:
    scene = Scene(lights=[DirectionalLight((0.2, -1.0, -0.6))])
    scene.add(icosphere(0.45, 3), Material(color=(0.9, 0.2, 0.1)), translate(*offsets[0]), name="ball", label="ball")
    scene.add(box((0.5, 0.5, 0.5)), Material(), translate(*offsets[1]) @ rotate_y(0.4), name="cube", label="cube")
    group = scene.add(Node("shelf", label="furniture"))
    scene.add(torus(0.3, 0.1), Material(), translate(*offsets[2]), name="ring", parent=group)  # inherits furniture
    return scene


def _camera(eye=(0.3, 0.8, 3.2)) -> Camera:
    return Camera.look_at(eye, (0.0, 0.0, 0.0), width=WIDTH, height=HEIGHT)


def _opencv(camera: Camera):
    """K (pixel centres at integers) and world → OpenCV camera of a frustum camera."""
    pinhole = intrinsics(camera)
    k = np.array([[pinhole["fx"], 0, pinhole["cx"] - 0.5], [0, pinhole["fy"], pinhole["cy"] - 0.5], [0, 0, 1]])
    return k, OPENCV_FROM_OPENGL @ np.asarray(camera.view_matrix)


def _project(points_world: np.ndarray, camera: Camera) -> np.ndarray:
    k, camera_from_world = _opencv(camera)
    rvec, _ = cv2.Rodrigues(camera_from_world[:3, :3])
    pixels, _ = cv2.projectPoints(points_world.reshape(-1, 1, 3), rvec, camera_from_world[:3, 3], k, None)
    return pixels.reshape(-1, 2)


# --- labels -------------------------------------------------------------------------------------------------------


def test_labels_are_inherited_and_listed_in_first_seen_order():
    scene = _scene()
    assert scene.labels == ["ball", "cube", "furniture"]
    assert scene.item_paths() == ["ball", "cube", "shelf/ring"]
    assert scene.item_labels() == ["ball", "cube", "furniture"]
    unlabelled = Scene()
    unlabelled.add(icosphere(0.5, 1))
    assert unlabelled.labels == [] and unlabelled.item_labels() == [None] and unlabelled.item_paths() == ["#0"]


def test_scene_file_labels():
    loaded = load_scene(
        """
[camera]
eye = [0, 0, 3]
target = [0, 0, 0]
[[nodes]]
name = "table"
label = "furniture"
geometry = { type = "box" }
[[nodes.children]]
name = "leg"
geometry = { type = "box" }
[[nodes]]
name = "mug"
label = "mug"
geometry = { type = "uv_sphere" }
"""
    )
    assert loaded.scene.labels == ["furniture", "mug"]
    assert loaded.scene.item_labels() == ["furniture", "furniture", "mug"]


@pytest.mark.parametrize("label", [3, "", ["mug"]])
def test_a_label_that_is_not_a_string_is_refused(label):
    with pytest.raises(FrustumError, match=r"label = .* is not a class name"):
        Node("x", label=label)
    with pytest.raises(FrustumError, match="label"):
        Scene().add(icosphere(0.5, 1), label=label)


# --- instance, semantic: no blending --------------------------------------------------------------------------------


def test_semantic_ids_are_the_class_ids_of_the_instances():
    scene = _scene()
    frame = render(scene, _camera(), buffers=("instance", "semantic"))
    assert frame.object_id is None and frame.position is None  # only what was asked for
    table = np.array([0, 1, 2, 3])  # background, ball, cube, ring (furniture)
    np.testing.assert_array_equal(frame.semantic, table[frame.instance + 1])
    assert set(np.unique(frame.instance)) == {-1, 0, 1, 2}
    both = render(scene, _camera(), buffers=("object_id", "instance"))
    np.testing.assert_array_equal(both.object_id, both.instance)


def test_supersampled_ids_are_never_blended():
    scene = _scene()
    camera = _camera()
    frame = render(scene, camera, buffers=("instance", "semantic"), samples=16)
    big = render(scene, Camera(camera.frame, camera.projection, WIDTH * 4, HEIGHT * 4), buffers=("object_id",))
    blocks = big.object_id.reshape(HEIGHT, 4, WIDTH, 4).transpose(0, 2, 1, 3).reshape(HEIGHT, WIDTH, 16)
    # every id in the masks is an item of the scene (or the background), and one of the pixel's own 16 samples
    assert set(np.unique(frame.instance)) <= {-1, 0, 1, 2}
    assert set(np.unique(frame.semantic)) <= {0, 1, 2, 3}
    assert (blocks == frame.instance[..., None]).any(axis=2).all()
    # along every boundary between two objects, the ids on either side are those objects' (no third id between)
    left, right = frame.instance[:, :-1], frame.instance[:, 1:]
    boundary = (left != right) & (left >= 0) & (right >= 0)
    assert boundary.any()
    for r, c in zip(*np.nonzero(boundary), strict=True):
        near = set(blocks[r, c]) | set(blocks[r, c + 1])
        assert {left[r, c], right[r, c]} <= near
    agree = (blocks == blocks[..., :1]).all(axis=2)
    single = render(scene, camera, buffers=("instance",))
    np.testing.assert_array_equal(frame.instance[agree], single.instance[agree])
    assert agree.mean() > 0.8


def test_supersampled_depth_reports_the_sample_the_ids_come_from():
    scene = _scene()
    camera = _camera()
    frame = render(scene, camera, buffers=("instance", "object_coords"), samples=16)
    big = render(scene, Camera(camera.frame, camera.projection, WIDTH * 4, HEIGHT * 4),
                 buffers=("object_id", "position"))  # fmt: skip
    np.testing.assert_array_equal(frame.instance, big.object_id[2::4, 2::4])
    np.testing.assert_array_equal(frame.depth, big.depth[2::4, 2::4])  # the same sample, not the block's nearest
    plain = render(scene, camera, samples=16)
    assert (plain.depth <= frame.depth).all() and (plain.depth < frame.depth).any()  # without ground truth: nearest
    assert frame.object_id is None and frame.position is None  # implied by the ground truth, not asked for


# --- amodal masks and visibility ------------------------------------------------------------------------------------


def test_an_item_alone_has_its_instance_mask_as_amodal_mask():
    scene = Scene(lights=[DirectionalLight((0, -1, -1))])
    scene.add(torus(0.6, 0.2), Material(), rotate((1, 0, 0), 1.0), name="ring")
    for samples in (1, 4):
        frame = render(scene, _camera(), buffers=("instance", "amodal"), samples=samples)
        np.testing.assert_array_equal(frame.amodal[0], frame.instance == 0)
        assert frame.visibility[0] == 1.0


@settings(max_examples=12, deadline=None, derandomize=True)
@given(st.lists(st.tuples(*[st.floats(-0.8, 0.8)] * 3), min_size=3, max_size=3))
def test_amodal_masks_hold_the_visible_pixels_and_equal_each_item_alone(offsets):
    scene = _scene(tuple(offsets))
    camera = _camera()
    frame = render(scene, camera, buffers=("instance", "amodal"))
    assert frame.amodal.shape == (3, HEIGHT, WIDTH)
    for k, (path, item) in enumerate(zip(scene.item_paths(), scene.items, strict=True)):
        visible = frame.instance == k
        assert not (visible & ~frame.amodal[k]).any()  # amodal ⊇ visible
        total = frame.amodal[k].sum()
        if total:
            assert frame.visibility[k] == pytest.approx(visible.sum() / total)
        else:
            assert math.isnan(frame.visibility[k])
        alone = Scene(lights=scene.lights)
        alone.add(item.mesh, item.material, item.world_from_model, name=path.replace("/", "_"))
        np.testing.assert_array_equal(render(alone, camera, buffers=("instance",)).instance == 0, frame.amodal[k])


def test_an_item_outside_the_view_has_nan_visibility():
    scene = _scene(((0, 0, 0), (30.0, 0, 0), (0, 0, -40.0)))
    frame = render(scene, _camera(), buffers=("amodal",))
    assert frame.visibility[0] == 1.0 and math.isnan(frame.visibility[1]) and not frame.amodal[1].any()


# --- object coordinates and NOCS ------------------------------------------------------------------------------------


def test_object_coordinates_map_to_the_world_positions():
    scene = _scene()
    frame = render(scene, _camera(), buffers=("instance", "object_coords", "nocs", "position"), samples=4)
    drawn = frame.instance >= 0
    assert np.isnan(frame.object_coords[~drawn]).all() and not np.isnan(frame.object_coords[drawn]).any()
    for k, item in enumerate(scene.items):
        rows = frame.instance == k
        model = frame.object_coords[rows].astype(np.float64)
        world = model @ item.world_from_model[:3, :3].T + item.world_from_model[:3, 3]
        np.testing.assert_allclose(world, frame.position[rows], atol=1e-5)
        low, high = item.mesh.bounds
        expected = (model - (low + high) / 2) / np.linalg.norm(high - low) + 0.5
        np.testing.assert_allclose(frame.nocs[rows], expected, atol=1e-6)
        assert (frame.nocs[rows] >= 0).all() and (frame.nocs[rows] <= 1).all()


# --- flow -----------------------------------------------------------------------------------------------------------


def _moved(scene: Scene, rng: np.random.Generator) -> Scene:
    """The same scene with every item turned and moved a little (node paths unchanged)."""
    moved = Scene(lights=scene.lights)
    for path, item in zip(scene.item_paths(), scene.items, strict=True):
        motion = translate(*rng.uniform(-0.15, 0.15, 3)) @ rotate(rng.normal(size=3), rng.uniform(-0.3, 0.3))
        parent = moved.add(Node("shelf", label="furniture")) if path.startswith("shelf/") else None
        moved.add(item.mesh, item.material, motion @ item.world_from_model, name=path.split("/")[-1], parent=parent)
    return moved


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_flow_is_the_reprojection_of_the_object_coordinates(seed):
    rng = np.random.default_rng(seed)
    scene, camera = _scene(), _camera()
    following, next_camera = _moved(scene, rng), _camera(eye=np.add((0.3, 0.8, 3.2), rng.uniform(-0.3, 0.3, 3)))
    frame = render(scene, camera, buffers=("instance", "object_coords", "flow"), next=(following, next_camera))
    nxt = render(following, next_camera)
    next_depth = metric_depth(nxt.depth, next_camera)
    checked = 0
    for k, (item, later) in enumerate(zip(scene.items, following.items, strict=True)):
        rows = np.nonzero(frame.instance == k)
        model = frame.object_coords[rows].astype(np.float64)
        now = _project(model @ item.world_from_model[:3, :3].T + item.world_from_model[:3, 3], camera)
        world_next = model @ later.world_from_model[:3, :3].T + later.world_from_model[:3, 3]
        then = _project(world_next, next_camera)
        np.testing.assert_allclose(frame.flow[rows], then - now, atol=1e-3)
        # occlusion: the point's OpenCV depth against the next frame's metric depth at its pixel
        _, camera_from_world = _opencv(next_camera)
        z = world_next @ camera_from_world[2, :3] + camera_from_world[2, 3]
        u, v = np.floor(then[:, 0] + 0.5).astype(int), np.floor(then[:, 1] + 0.5).astype(int)
        inside = (u >= 0) & (u < WIDTH) & (v >= 0) & (v < HEIGHT) & (z > 0)
        hidden = ~inside
        surface = next_depth[v[inside], u[inside]]
        hidden[inside] = (surface > 0) & (z[inside] > surface * (1 + DEPTH_TOLERANCE))  # background: nothing in front
        agree = hidden == frame.flow_occluded[rows]
        assert agree.all(), np.flatnonzero(~agree)
        checked += rows[0].size
    assert checked > 100
    assert np.isnan(frame.flow[frame.instance < 0]).all()


def test_a_static_scene_and_camera_give_zero_flow():
    scene, camera = _scene(), _camera()
    frame = render(scene, camera, buffers=("instance", "flow"), next=(scene, camera))
    drawn = frame.instance >= 0
    assert (frame.flow[drawn] == 0).all()
    assert frame.flow_occluded[drawn].mean() < 0.01


def test_flow_of_an_item_missing_from_the_next_scene_is_nan():
    scene, camera = _scene(), _camera()
    following = Scene()
    following.add(icosphere(0.45, 3), transform=translate(0.1, 0, 0), name="ball")
    frame = render(scene, camera, buffers=("instance", "flow"), next=(following, camera))
    assert not np.isnan(frame.flow[frame.instance == 0]).any()
    assert np.isnan(frame.flow[frame.instance == 1]).all() and frame.flow_occluded[frame.instance == 1].all()


def test_next_scenes_that_cannot_be_matched_are_refused():
    scene, camera = _scene(), _camera()
    twins = Scene()
    twins.add(icosphere(0.45, 2), name="ball")
    twins.add(icosphere(0.45, 2), name="ball")
    with pytest.raises(FrustumError, match="two meshes at node path 'ball'"):
        render(scene, camera, buffers=("flow",), next=(twins, camera))
    stranger = Scene()
    stranger.add(icosphere(0.45, 2), name="pebble")
    with pytest.raises(FrustumError, match=r"no item at the node paths.*'ball'.*'pebble'"):
        render(scene, camera, buffers=("flow",), next=(stranger, camera))
    with pytest.raises(FrustumError, match="without next"):
        render(scene, camera, buffers=("flow",))
    with pytest.raises(FrustumError, match="is not a \\(Scene, Camera\\) pair"):
        render(scene, camera, buffers=("flow",), next=(scene,))
    with pytest.raises(FrustumError, match="surface mode"):
        render(scene, camera, buffers=("instance",), mode="wireframe")


# --- annotate -------------------------------------------------------------------------------------------------------


def test_annotations_project_keypoints_like_opencv():
    scene, camera = _scene(), _camera()
    frame = render(scene, camera, buffers=("instance", "amodal"))
    points = np.array([[0.0, 0.45, 0.0], [0.0, 0.0, 0.45], [0.3, -0.2, 0.2], [0.0, 0.0, -0.45]])
    records = annotate(frame, scene, camera, keypoints={"ball": points, "cube": points[:2] * 0.5})
    assert [r["name"] for r in records] == ["ball", "cube", "shelf/ring"]
    assert [r["class_id"] for r in records] == [1, 2, 3]
    k_matrix, camera_from_world = _opencv(camera)
    for k, (record, item, model) in enumerate(zip(records, scene.items, (points, points[:2] * 0.5, None), strict=True)):
        expected_pose = camera_from_world @ item.world_from_model
        np.testing.assert_allclose(record["pose"], expected_pose, atol=1e-12)
        low, high = item.mesh.bounds
        corners = np.array([[(low, high)[i & 1][0], (low, high)[i >> 1 & 1][1], (low, high)[i >> 2 & 1][2]]
                            for i in range(8)])  # fmt: skip
        rvec, _ = cv2.Rodrigues(expected_pose[:3, :3])
        projected, _ = cv2.projectPoints(corners, rvec, expected_pose[:3, 3], k_matrix, None)
        np.testing.assert_allclose(record["bbox_3d"], projected.reshape(-1, 2), atol=1e-3)
        assert record["px_count_visible"] == (frame.instance == k).sum()
        assert record["px_count_all"] == frame.amodal[k].sum()
        if model is None:
            assert "keypoints" not in record
            continue
        projected, _ = cv2.projectPoints(model, rvec, expected_pose[:3, 3], k_matrix, None)
        np.testing.assert_allclose(record["keypoints"][:, :2], projected.reshape(-1, 2), atol=1e-3)
    flags = records[0]["keypoints"][:, 2]
    assert flags[1] == 2 and flags[3] == 1  # the front of the ball is seen, its back hidden


def test_annotation_boxes_are_those_of_the_masks():
    scene, camera = _scene(), _camera()
    frame = render(scene, camera, buffers=("instance", "amodal"))
    for k, record in enumerate(annotate(frame, scene, camera)):
        rows, columns = np.nonzero(frame.instance == k)
        x, y, w, h = record["bbox_visible"]
        assert (x, y, x + w - 1, y + h - 1) == (columns.min(), rows.min(), columns.max(), rows.max())
        rows, columns = np.nonzero(frame.amodal[k])
        x, y, w, h = record["bbox_amodal"]
        assert (x, y, x + w - 1, y + h - 1) == (columns.min(), rows.min(), columns.max(), rows.max())


@pytest.mark.parametrize(
    ("keypoints", "match"),
    [
        (np.zeros((4, 2)), "not an \\(M, 3\\) array"),
        ({"ball": [[0, 0, 0, 0]]}, "not an \\(M, 3\\) array"),
        ({"teapot": np.zeros((2, 3))}, "neither a label nor a node path"),
        ([np.zeros((2, 3))] * 2, "lists 2 arrays for 3 items"),
        ([[0.0, np.nan, 0.0]], "finite"),
    ],
)
def test_keypoints_of_the_wrong_shape_are_refused(keypoints, match):
    scene, camera = _scene(), _camera()
    frame = render(scene, camera, buffers=("instance", "amodal"))
    with pytest.raises(FrustumError, match=match):
        annotate(frame, scene, camera, keypoints=keypoints)


def test_annotate_needs_the_masks():
    scene, camera = _scene(), _camera()
    with pytest.raises(FrustumError, match="buffers=\\('instance', 'amodal'\\)"):
        annotate(render(scene, camera), scene, camera)


def test_ids_filled_beside_the_fast_kernels_equal_the_general_kernels():
    """Object ids alone keep the fast shading kernels (ids filled from the face codes); with normals the general
    kernel writes them: the same ids and the same color bytes."""
    scene, camera = _scene(), _camera()
    fast = render(scene, camera, buffers=("object_id",))
    general = render(scene, camera, buffers=("object_id", "normals"))
    np.testing.assert_array_equal(fast.object_id, general.object_id)
    np.testing.assert_array_equal(fast.color, general.color)
    assert set(np.unique(fast.object_id)) == {-1, 0, 1, 2}


@pytest.mark.parametrize("method", ["scan-line", "bsp", "ray-casting", "ray-tracing"])
def test_every_method_with_object_ids_gives_the_ground_truth(method):
    scene, camera = _scene(), _camera()
    wanted = ("instance", "semantic", "amodal", "object_coords")
    reference = render(scene, camera, buffers=wanted)
    frame = render(scene, camera, method=method, buffers=wanted)
    same = frame.instance == reference.instance
    assert same.mean() > 0.99
    np.testing.assert_array_equal(frame.amodal, reference.amodal)
    both = same & (frame.instance >= 0) & ~np.isnan(frame.object_coords[..., 0])
    assert both.sum() > 0.9 * (frame.instance >= 0).sum()
    np.testing.assert_allclose(frame.object_coords[both], reference.object_coords[both], atol=5e-3)


def test_amodal_masks_are_held_to_the_memory_budget():
    from frustum import budget

    scene, camera = Scene(), _camera()
    ball = icosphere(0.1, 1)
    for i in range(40):
        scene.add(ball, transform=translate(0.05 * i - 1.0, 0.0, 0.0), name=f"ball{i}")
    with budget(bytes=100_000), pytest.raises(FrustumError, match="amodal masks of 40 items at 64 x 48"):
        render(scene, camera, buffers=("amodal",))
