"""Point clouds and Gaussian splats in the ground truth (``object_id``, ``instance``, ``semantic``, ``amodal``,
``object_coords``, ``annotate``, the COCO and BOP datasets) and ``frustum.load`` of point and splat files.

Point objects follow the meshes: ids ``len(scene.items) + i`` for the i-th entry of ``Scene.point_clouds``; a
splat pixel belongs to the set of its median splat (the one that brings the accumulated alpha to ½ or more),
computed here per pixel from the 3DGS equations (``tests/test_splats.py``'s reference), without tiles."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from tests.test_splats import HEIGHT, WIDTH, random_camera, random_splats, screen_gaussians

from frustum import Camera, GaussianSplats, Perspective, PointCloud, annotate, load, load_parts, render
from frustum.errors import GeometryError, OutputError
from frustum.geometry import Mesh
from frustum.output.annotations import mask_box
from frustum.scene import Scene
from frustum.shading import Material
from frustum.transforms import translate

PLANE = Mesh([[-3, -3, -1], [3, -3, -1], [3, 3, -1], [-3, 3, -1]], [[0, 1, 2], [0, 2, 3]])


def camera(width: int = 96, height: int = 72) -> Camera:
    return Camera.look_at((0.3, 0.2, 4.0), (0, 0, 0), (0, 1, 0), projection=Perspective(0.8, 0.5, 20.0),
                          width=width, height=height)  # fmt: skip


def spheres_scene() -> tuple[Scene, np.ndarray, np.ndarray]:
    """A labelled floor, then a cloud of sphere impostors (moved by a transform) labelled 'scan'."""
    rng = np.random.default_rng(3)
    centers = rng.uniform(-0.8, 0.8, size=(12, 3)) * (1.0, 1.0, 0.3)
    radii = rng.uniform(0.1, 0.25, size=12)
    scene = Scene()
    scene.add(PLANE, Material(color=(0.3, 0.3, 0.3)), name="floor", label="floor")
    scene.add(PointCloud(centers, radii=radii), transform=translate(0.1, -0.1, 0.2), style="sphere", name="scan",
              label="scan")  # fmt: skip
    return scene, centers, radii


def test_point_clouds_are_objects_of_instance_semantic_and_amodal():
    scene, centers, radii = spheres_scene()
    cam = camera()
    frame = render(scene, cam, buffers=("object_id", "instance", "semantic", "amodal", "object_coords", "nocs",
                                        "position"))  # fmt: skip
    assert scene.labels == ["floor", "scan"] and scene.point_labels() == ["scan"] and scene.point_paths() == ["scan"]
    drawn = frame.depth < 1
    alone = Scene()
    alone.add(PointCloud(centers, radii=radii), transform=translate(0.1, -0.1, 0.2), style="sphere")
    cloud_alone = render(alone, cam).depth < 1
    # the cloud is in front of the floor: its pixels are object 1, class 2; the floor's the rest
    np.testing.assert_array_equal(frame.instance == 1, cloud_alone)
    np.testing.assert_array_equal(frame.object_id, frame.instance)
    np.testing.assert_array_equal(frame.semantic, np.where(frame.instance == 1, 2, np.where(drawn, 1, 0)))
    assert frame.amodal.shape == (2, cam.height, cam.width)
    np.testing.assert_array_equal(frame.amodal[1], cloud_alone)
    assert frame.visibility[1] == 1.0 and 0.0 < frame.visibility[0] < 1.0
    # a sphere pixel's object coordinates lie on one of the spheres, in the cloud's model coordinates
    points = frame.object_coords[frame.instance == 1].astype(np.float64)
    distance = np.abs(np.linalg.norm(points[:, None] - centers[None], axis=2) - radii[None]).min(axis=1)
    assert np.median(distance) < 1e-3 and distance.max() < 2e-2  # float32 depth at grazing pixels
    # the "position" buffer holds the spheres' world points there (the points pass writes them), the floor's elsewhere
    world = frame.position[frame.instance == 1].astype(np.float64) - (0.1, -0.1, 0.2)
    np.testing.assert_allclose(world, points, atol=1e-5)
    assert np.abs(frame.position[frame.instance == 0][:, 2] + 1.0).max() < 1e-5
    low, high = np.asarray(PointCloud(centers).bounds)
    nocs = (points - 0.5 * (low + high)) / np.linalg.norm(high - low) + 0.5
    np.testing.assert_allclose(frame.nocs[frame.instance == 1], nocs, atol=1e-5)


def test_supersampled_point_ids_and_amodal_keep_the_middle_sample():
    scene, *_ = spheres_scene()
    cam = camera(48, 36)
    frame = render(scene, cam, samples=4, buffers=("instance", "amodal"))
    big = Camera.look_at((0.3, 0.2, 4.0), (0, 0, 0), (0, 1, 0), projection=Perspective(0.8, 0.5, 20.0), width=96,
                         height=72)  # fmt: skip
    ids = render(scene, big, buffers=("object_id",)).object_id
    np.testing.assert_array_equal(frame.instance, ids[1::2, 1::2])
    np.testing.assert_array_equal(frame.amodal[1], (ids == 1)[1::2, 1::2])


def median_sets(sets: list[GaussianSplats], cam: Camera) -> np.ndarray:
    """(H, W): per pixel centre, the index of the set whose splat brings 1 − T from below ½ to ½ or more, front to
    back over all sets together (3DGS §6, no tiles); −1 where 1 − T stays below ½."""
    gaussians = sorted(((g, s) for s, splats in enumerate(sets) for g in screen_gaussians(splats, cam)),
                       key=lambda entry: entry[0][0])  # fmt: skip
    cols, rows = np.meshgrid(np.arange(WIDTH) + 0.5, np.arange(HEIGHT) + 0.5)
    transmittance = np.ones((HEIGHT, WIDTH))
    result = np.full((HEIGHT, WIDTH), -1)
    for (_z, mean, cov, opacity, _c), index in gaussians:
        conic = np.linalg.inv(cov)
        dx, dy = cols - mean[0], rows - mean[1]
        power = -0.5 * (conic[0, 0] * dx * dx + 2 * conic[0, 1] * dx * dy + conic[1, 1] * dy * dy)
        alpha = np.minimum(0.99, opacity * np.exp(power))
        use = alpha >= 1 / 255
        after = np.where(use, transmittance * (1 - alpha), transmittance)
        result[(transmittance > 0.5) & (after <= 0.5)] = index
        transmittance = after
    return result


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_splat_pixel_is_the_set_of_its_median_splat_where_alpha_reaches_one_half(seed):
    cam = random_camera(seed, inside=False)
    sets = [random_splats(seed, 25, 1), random_splats(seed + 100, 25, 0)]
    scene = Scene()
    for i, splats in enumerate(sets):
        scene.add(splats, name=f"set{i}", label=f"class{i}")
    frame = render(scene, cam, buffers=("instance", "semantic", "normals"))
    expected = median_sets(sets, cam)
    assert (expected >= 0).sum() > 50
    assert (frame.instance == expected).mean() >= 0.99  # T within float rounding of ½ decides a few pixels
    np.testing.assert_array_equal(frame.semantic, frame.instance + 1)  # classes 1, 2 in set order; 0 background
    assert not frame.normals[frame.instance >= 0].any()  # splats have no surface normal


def test_splats_over_a_mesh_keep_the_mesh_id_where_their_alpha_stays_below_one_half():
    rng = np.random.default_rng(5)
    count = 40
    splats = GaussianSplats(rng.uniform(-0.6, 0.6, size=(count, 3)), np.full((count, 3), 0.08),
                            np.tile([1.0, 0.0, 0.0, 0.0], (count, 1)), rng.uniform(0.1, 0.9, count),
                            rng.normal(size=(count, 1, 3)))  # fmt: skip
    scene = Scene()
    scene.add(PLANE, name="floor")
    scene.add(splats, name="fog")
    cam = camera()
    frame = render(scene, cam, buffers=("instance", "amodal", "position"))
    alone = Scene()
    alone.add(splats)
    alpha = render(alone, cam, background=(0, 0, 0, 0)).color[..., 3] / 255.0
    # the splats lie in front of the floor: the set's id exactly where its alpha reaches ½ (bytes: ±1/255)
    sure = np.abs(alpha - 0.5) > 1.5 / 255
    np.testing.assert_array_equal((frame.instance == 1)[sure], (alpha >= 0.5)[sure])
    floor = Scene()
    floor.add(PLANE)
    under = render(floor, cam, buffers=("object_id",)).object_id  # 0 on the floor, −1 beside it
    np.testing.assert_array_equal(frame.instance[sure & (alpha < 0.5)], under[sure & (alpha < 0.5)])
    assert (under[sure & (alpha < 0.5)] == 0).sum() > 100
    # world points: the floor's (z = −1) under faint splats, the expected depth's among the splats where they own it
    assert np.abs(frame.position[frame.instance == 0][:, 2] + 1.0).max() < 1e-5
    owned = frame.position[frame.instance == 1]
    assert np.isfinite(owned).all() and np.abs(owned).max() < 0.6 + 3 * 0.08 + 1e-3
    np.testing.assert_array_equal(frame.amodal[1][sure], (alpha >= 0.5)[sure])


def test_annotate_and_coco_and_bop_take_point_objects(tmp_path):
    from frustum import render_dataset

    scene, *_ = spheres_scene()
    cam = camera()
    frame = render(scene, cam, buffers=("instance", "amodal"))
    records = annotate(frame, scene, cam)
    assert [(r["name"], r["kind"], r["label"], r["class_id"]) for r in records] == [
        ("floor", "mesh", "floor", 1), ("scan", "points", "scan", 2)]  # fmt: skip
    assert records[1]["bbox_visible"] == mask_box(frame.instance == 1) != [0, 0, 0, 0]
    assert records[1]["px_count_visible"] == records[1]["px_count_all"] == frame.amodal[1].sum()
    pytest.importorskip("pycocotools")
    result = render_dataset(scene, tmp_path / "coco", cameras=[cam], format="coco", executor="serial",
                            progress=False)  # fmt: skip
    assert result.ok
    coco = json.loads((tmp_path / "coco" / "annotations.json").read_text())
    assert sorted(a["category_id"] for a in coco["annotations"]) == [1, 2]
    scan = next(a for a in coco["annotations"] if a["category_id"] == 2)
    assert scan["area"] == frame.amodal[1].sum() and scan["bbox"] == records[1]["bbox_visible"]
    # BOP: a BOP object is a mesh model; the cloud occludes but is not annotated
    result = render_dataset(scene, tmp_path / "bop", cameras=[cam], format="bop", executor="serial", progress=False)
    assert result.ok
    truth = json.loads((tmp_path / "bop" / "train" / "000000" / "scene_gt.json").read_text())
    assert [entry["obj_id"] for entry in truth["0"]] == [1]
    assert sorted(p.name for p in (tmp_path / "bop" / "models").glob("*.ply")) == ["obj_000001.ply"]
    only_points = Scene()
    only_points.add(PLANE, name="floor")
    only_points.add(PointCloud([[0.0, 0.0, 0.0]]), name="scan", label="scan")
    with pytest.raises(OutputError, match=r"needs labels.*a BOP object is a mesh model.*none on its meshes"):
        render_dataset(only_points, tmp_path / "bop2", cameras=[cam], format="bop", executor="serial", progress=False)


def _point_ply(path, count=30, extra=""):
    rng = np.random.default_rng(0)
    with open(path, "w") as file:
        file.write(f"ply\nformat ascii 1.0\nelement vertex {count}\nproperty float x\nproperty float y\n"
                   f"property float z\n{extra}end_header\n")  # fmt: skip
        for point in rng.uniform(-1, 1, size=(count, 3)):
            file.write(" ".join(f"{v:f}" for v in point) + "\n")
    return path


def test_load_refuses_point_and_splat_files_naming_their_loaders(tmp_path):
    from tests.testdata import DATA

    from frustum import load_points

    cloud = _point_ply(tmp_path / "cloud.ply")
    for function in (load, load_parts):
        with pytest.raises(GeometryError, match=r"PLY without faces.*frustum\.load_points\(path\)"):
            function(cloud)
    assert load_points(cloud).point_count == 30
    torus = DATA / "splats" / "torus.ply"
    with pytest.raises(GeometryError, match=r"3D Gaussian splats.*GaussianSplats\.load\(path\)"):
        load(torus)
    assert GaussianSplats.load(torus).count > 0


def test_the_render_command_draws_a_ply_without_faces(tmp_path):
    from PIL import Image

    from frustum.app.cli import main

    cloud = _point_ply(tmp_path / "cloud.ply", count=400)
    out = tmp_path / "cloud.png"
    main(["render", str(cloud), "-o", str(out), "--size", "64x48"])
    image = np.asarray(Image.open(out))
    assert image.shape[:2] == (48, 64)
    assert len(np.unique(image.reshape(-1, image.shape[2]), axis=0)) > 2  # points drawn over the background
    assert math.isfinite(float(image.mean()))
