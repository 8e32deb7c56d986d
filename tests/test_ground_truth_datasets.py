"""COCO and BOP datasets (``render_dataset(format="coco" | "bop")``) read back by their own readers: pycocotools
for COCO, and for BOP a reader written here from the BOP toolkit's ``docs/bop_datasets_format.md`` (not from the
writer); scene randomisation (``frustum.batch.randomize``) reproducible from its seed and free of interpenetration
(checked with Embree)."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from frustum import Camera, DirectionalLight, FrustumError, Material, Node, Scene, render, render_dataset
from frustum.batch.randomize import cameras_on_shell, drop_on_plane, jitter_lights, jitter_materials
from frustum.errors import OutputError
from frustum.geometry import load
from frustum.geometry.primitives import box, icosphere, plane, torus
from frustum.transforms import rotate_x

coco_module = pytest.importorskip("pycocotools.coco")
mask_module = pytest.importorskip("pycocotools.mask")
trimesh = pytest.importorskip("trimesh")
embree_scene = pytest.importorskip("embreex.rtcore_scene")
embree_mesh = pytest.importorskip("embreex.mesh_construction")

BUNNY = Path(__file__).parent / "data" / "bunny" / "bun_zipper_res4.ply"
WIDTH, HEIGHT = 96, 72


def _objects() -> list[Node]:
    """Four objects of about 100 mm (scene units are metres); the bunny from tests/data."""
    bunny = load(BUNNY)
    low, high = bunny.bounds
    bunny = bunny.transformed(np.diag([*(0.1 / (high - low).max(),) * 3, 1.0]))
    return [
        Node("ball", geometry=icosphere(0.05, 3), material=Material(color=(0.8, 0.2, 0.1)), label="ball"),
        Node("cube", geometry=box((0.08, 0.08, 0.08)), material=Material(color=(0.2, 0.6, 0.9)), label="cube"),
        Node("ring", geometry=torus(0.04, 0.015), material=Material(color=(0.9, 0.8, 0.2)), label="ring"),
        Node("bunny", geometry=bunny, material=Material(color=(0.7, 0.7, 0.7)), label="bunny"),
    ]


def _table(seed: int) -> tuple[Scene, list[Camera]]:
    rng = np.random.default_rng(seed)
    scene = Scene(lights=jitter_lights([DirectionalLight((0.3, -1.0, -0.4))], rng))
    scene.add(plane((0.6, 0.6)), Material(color=(0.5, 0.5, 0.5)), rotate_x(-math.pi / 2), name="floor")
    drop_on_plane(scene, _objects(), rng, area=((-0.12, -0.12), (0.12, 0.12)))
    jitter_materials(scene, rng)
    cameras = cameras_on_shell(rng, 4, (0.0, 0.04, 0.0), radius=(0.45, 0.55), width=WIDTH, height=HEIGHT)
    return scene, cameras


@pytest.fixture(scope="module")
def table():
    return _table(7)


def _buffers(scene, camera):
    return render(scene, camera, buffers=("instance", "amodal"))


def test_coco_annotations_load_in_pycocotools_and_match_the_buffers(table, tmp_path):
    scene, cameras = table
    keypoints = {"ball": [[0.0, 0.05, 0.0], [0.05, 0.0, 0.0]]}
    result = render_dataset(scene, tmp_path, cameras=cameras, format="coco", executor="serial", progress=False,
                            keypoints=keypoints, seed=7)  # fmt: skip
    assert result.ok
    coco = coco_module.COCO(str(tmp_path / "annotations.json"))
    assert [c["name"] for c in coco.loadCats(coco.getCatIds())] == ["ball", "cube", "ring", "bunny"]
    assert len(coco.getImgIds()) == len(cameras)
    annotations = 0
    for image_id, camera in zip(sorted(coco.getImgIds()), cameras, strict=True):
        image = coco.loadImgs(image_id)[0]
        assert Image.open(tmp_path / image["file_name"]).mode == "RGB"
        frame = _buffers(scene, camera)
        for annotation in coco.loadAnns(coco.getAnnIds(imgIds=image_id)):
            item = scene.item_labels().index(coco.loadCats(annotation["category_id"])[0]["name"])
            mask = coco.annToMask(annotation).astype(bool)
            np.testing.assert_array_equal(mask, frame.instance == item)
            assert annotation["area"] == mask.sum() and annotation["iscrowd"] == 0
            np.testing.assert_array_equal(annotation["bbox"], mask_module.toBbox(coco.annToRLE(annotation)))
            if annotation["category_id"] == 1:
                assert annotation["num_keypoints"] == sum(1 for v in annotation["keypoints"][2::3] if v > 0)
            annotations += 1
    assert annotations >= 2 * len(cameras)


def _read_bop(root: Path) -> dict:
    """A BOP scenewise dataset as the format document describes it: JSON files keyed by image id, 16-bit depth
    PNGs scaled by depth_scale to millimetres, masks IMID_GTID.png, PLY models in millimetres."""
    scene_dir = root / "train" / "000000"
    data = {name: json.loads((scene_dir / f"{name}.json").read_text())
            for name in ("scene_camera", "scene_gt", "scene_gt_info")}  # fmt: skip
    data["models_info"] = json.loads((root / "models" / "models_info.json").read_text())
    data["models"] = {int(obj): trimesh.load(root / "models" / f"obj_{int(obj):06d}.ply", process=False)
                      for obj in data["models_info"]}  # fmt: skip
    data["images"] = {}
    for im_id in data["scene_camera"]:
        number = int(im_id)
        count = len(data["scene_gt"][im_id])
        masks = {sub: [np.asarray(Image.open(scene_dir / sub / f"{number:06d}_{g:06d}.png")) > 0 for g in range(count)]
                 for sub in ("mask", "mask_visib")}  # fmt: skip
        data["images"][number] = {
            "rgb": np.asarray(Image.open(scene_dir / "rgb" / f"{number:06d}.png")),
            "depth": np.asarray(Image.open(scene_dir / "depth" / f"{number:06d}.png")).astype(np.float64),
            **masks,
        }
    return data


def test_bop_dataset_read_from_the_format_document(table, tmp_path):
    scene, cameras = table
    result = render_dataset(scene, tmp_path, cameras=cameras, format="bop", executor="serial", progress=False)
    assert result.ok
    bop = _read_bop(tmp_path)
    labelled = [k for k, label in enumerate(scene.item_labels()) if label is not None]
    for obj_id, model in bop["models"].items():
        info = bop["models_info"][str(obj_id)]
        extent = model.vertices.max(axis=0) - model.vertices.min(axis=0)
        np.testing.assert_allclose([info["size_x"], info["size_y"], info["size_z"]], extent, rtol=1e-6)
        assert 50 < info["diameter"] < 200  # objects of about 100 mm
    near_surface = 0
    for number, camera in enumerate(cameras):
        entry = bop["scene_camera"][str(number)]
        k = np.array(entry["cam_K"]).reshape(3, 3)
        image = bop["images"][number]
        depth_mm = image["depth"] * entry["depth_scale"]
        frame = _buffers(scene, camera)
        for gt, (truth, info) in enumerate(zip(bop["scene_gt"][str(number)], bop["scene_gt_info"][str(number)],
                                               strict=True)):  # fmt: skip
            item = labelled[gt]
            assert truth["obj_id"] == scene.labels.index(scene.item_labels()[item]) + 1
            np.testing.assert_array_equal(image["mask"][gt], frame.amodal[item])
            np.testing.assert_array_equal(image["mask_visib"][gt], frame.instance == item)
            assert info["px_count_all"] == image["mask"][gt].sum()
            assert info["px_count_visib"] == image["mask_visib"][gt].sum()
            if info["px_count_all"]:
                assert info["visib_fract"] == pytest.approx(info["px_count_visib"] / info["px_count_all"])
            # back-project the visible pixels' depth with cam_K, into the model by cam_R_m2c, cam_t_m2c
            v, u = np.nonzero(image["mask_visib"][gt] & (depth_mm > 0))
            if u.size == 0:
                continue
            z = depth_mm[v, u]
            camera_points = np.stack([(u - k[0, 2]) / k[0, 0] * z, (v - k[1, 2]) / k[1, 1] * z, z], axis=1)
            rotation = np.array(truth["cam_R_m2c"]).reshape(3, 3)
            model_points = (camera_points - np.array(truth["cam_t_m2c"])) @ rotation  # R^T (p - t), row vectors
            _, distance, _ = trimesh.proximity.closest_point(bop["models"][truth["obj_id"]], model_points)
            assert distance.max() <= 1.0, (truth["obj_id"], distance.max())
            near_surface += u.size
    assert near_surface > 500


def test_a_bop_dataset_needs_labels(tmp_path):
    scene = Scene()
    scene.add(icosphere(0.05, 2), name="ball")
    camera = Camera.look_at((0, 0.2, 0.5), (0, 0, 0), width=32, height=24)
    with pytest.raises(OutputError, match=r"format = 'bop' needs labels.*has none"):
        render_dataset(scene, tmp_path, cameras=[camera], format="bop", executor="serial", progress=False)
    assert not (tmp_path / "manifest.jsonl").exists()  # refused before any view


def test_the_same_seed_gives_the_same_dataset_bytes(tmp_path):
    folders = []
    for run in range(2):
        scene, cameras = _table(11)
        out = tmp_path / f"run{run}"
        assert render_dataset(scene, out, cameras=cameras[:2], format="bop", executor="serial", progress=False,
                              seed=11).ok  # fmt: skip
        folders.append(out)
    files = sorted(p.relative_to(folders[0]) for p in folders[0].rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(folders[1]) for p in folders[1].rglob("*") if p.is_file())
    for relative in files:
        if relative.name == "manifest.jsonl":  # the run log: timings per view
            continue
        assert (folders[0] / relative).read_bytes() == (folders[1] / relative).read_bytes(), relative
    assert json.loads((folders[0] / "manifest.jsonl").read_text().splitlines()[0])["config"]["seed"] == 11
    other, _ = _table(12)
    assert not np.array_equal(other.items[1].world_from_model, _table(11)[0].items[1].world_from_model)


def _edges_hit(a, b) -> bool:
    """Embree: whether an edge of placed mesh a (as a segment) meets a triangle of placed mesh b."""
    tris = b.mesh.vertices[b.mesh.faces] @ b.world_from_model[:3, :3].T + b.world_from_model[:3, 3]
    scene = embree_scene.EmbreeScene()
    embree_mesh.TriangleMesh(scene, np.ascontiguousarray(tris, dtype=np.float32))
    points = a.mesh.vertices @ a.world_from_model[:3, :3].T + a.world_from_model[:3, 3]
    faces = a.mesh.faces
    edges = np.unique(np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1), axis=0)
    origins, directions = points[edges[:, 0]], points[edges[:, 1]] - points[edges[:, 0]]
    out = scene.run(origins.astype(np.float32), directions.astype(np.float32),
                    dists=np.ones(len(edges), dtype=np.float32), query="OCCLUDED")  # fmt: skip
    return bool((out != -1).any())


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_placed_objects_do_not_intersect(seed):
    scene, _ = _table(seed)
    objects = scene.items[1:]  # the floor first
    assert len(objects) == 4
    for item in objects:
        lowest = (item.mesh.vertices @ item.world_from_model[:3, :3].T + item.world_from_model[:3, 3])[:, 1].min()
        assert lowest == pytest.approx(0.0, abs=1e-12)  # resting on the plane
    for i, a in enumerate(objects):
        for b in objects[i + 1 :]:
            assert not _edges_hit(a, b) and not _edges_hit(b, a)


def test_randomisation_refuses_bad_input():
    with pytest.raises(FrustumError, match=r"not a numpy\.random\.Generator"):
        cameras_on_shell(np.random.RandomState(0), 3)
    with pytest.raises(FrustumError, match="not a shell"):
        cameras_on_shell(np.random.default_rng(0), 3, radius=(1.0, 0.5))
    crowded = [Node(f"cube{i}", geometry=box((0.2, 0.2, 0.2))) for i in range(4)]
    with pytest.raises(FrustumError, match="node 'cube1' found no pose"):
        drop_on_plane(Scene(), crowded, np.random.default_rng(0), area=((0, 0), (0.05, 0.05)), attempts=20)


_LABELLED_SCENE = """
[camera]
eye = [0.3, 0.25, 0.4]
target = [0, 0, 0]
[[nodes]]
name = "ball"
label = "ball"
geometry = { type = "uv_sphere", radius = 0.05 }
"""


def test_the_dataset_command_writes_coco_and_refuses_bop_without_labels(tmp_path):
    import subprocess
    import sys

    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(_LABELLED_SCENE)
    command = [sys.executable, "-m", "frustum", "dataset", str(scene_file), "--views", "2", "--size", "48x36",
               "--executor", "serial", "--no-progress"]  # fmt: skip
    done = subprocess.run([*command, "--out", str(tmp_path / "coco"), "--format", "coco"], capture_output=True,
                          text=True, timeout=300, check=False)  # fmt: skip
    assert done.returncode == 0, done.stderr
    coco = coco_module.COCO(str(tmp_path / "coco" / "annotations.json"))
    assert len(coco.getAnnIds()) == 2
    scene_file.write_text(_LABELLED_SCENE.replace('label = "ball"\n', ""))
    refused = subprocess.run([*command, "--out", str(tmp_path / "bop"), "--format", "bop"], capture_output=True,
                             text=True, timeout=300, check=False)  # fmt: skip
    assert refused.returncode != 0 and "Traceback" not in refused.stderr
    assert "needs labels" in refused.stderr and len(refused.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(("format", "where"), [("bop", "process"), ("coco", "url")])
def test_process_workers_and_urls_write_the_same_bytes(format, where, tmp_path):
    """The serial run's files, byte for byte, from worker processes (BOP) and at an fsspec URL (COCO)."""
    fsspec = pytest.importorskip("fsspec")
    scene, cameras = _table(5)
    url = f"memory://h45-{format}/data"
    serial = tmp_path / "serial"
    other = url if where == "url" else tmp_path / "process"
    for out, executor in ((serial, "serial"), (other, "process" if where == "process" else "serial")):
        result = render_dataset(scene, out, cameras=cameras[:2], format=format, progress=False, seed=5,
                                executor=executor, workers=2)  # fmt: skip
        assert result.ok, result.failed
    files = sorted(p.relative_to(serial).as_posix() for p in serial.rglob("*") if p.is_file())
    assert any(name.endswith(("annotations.json", "scene_gt.json")) for name in files)
    memory = fsspec.filesystem("memory")
    for name in files:
        if name == "manifest.jsonl":
            continue
        written = memory.cat_file(f"/h45-{format}/data/{name}") if where == "url" else (other / name).read_bytes()
        assert written == (serial / name).read_bytes(), name
