"""frustum.batch on a real Ray cluster whose nodes share no disk, and on URL outputs (S3 served by moto).

The cluster runs on this machine: a head node that renders nothing (``ray start --head --num-cpus=0``) and
worker nodes started with ``ray start --address=...`` each inside its own mount namespace (``unshare --mount``)
whose ``/tmp`` is a private tmpfs: a worker node sees neither the driver's output folder (under ``/tmp``) nor
the head's token file, as on separate machines. The head uses token authentication (``RAY_AUTH_MODE=token``);
each worker node gets the token as a file in its own ``/tmp`` (``RAY_AUTH_TOKEN_PATH``), the driver reads the
head's copy. No Ray call is mocked. Every process a test starts is stopped by its process group at the end,
whatever happened (other people's Ray processes on the machine are left alone: no ``ray stop``).

Needs root (mount namespaces); skipped with the reason otherwise.
"""

from __future__ import annotations

import hashlib
import json
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from frustum.batch import render_dataset

psutil = pytest.importorskip("psutil")
pytest.importorskip("ray")
from ray_local_cluster import Cluster, free_port, skip_reason, stop_groups  # noqa: E402
from scene_texts import ball_scene  # noqa: E402

pytestmark = pytest.mark.skipif(skip_reason() is not None, reason=str(skip_reason()))

SCENE = ball_scene("batch cluster test")


@pytest.fixture(scope="module")
def moto(tmp_path_factory):
    """An S3 endpoint on 127.0.0.1 (moto's server mode) with a bucket "frustum"."""
    server = Path(sys.executable).with_name("moto_server")
    pytest.importorskip("s3fs")
    if not server.exists():
        pytest.skip("needs moto[server] (moto_server)")
    port = free_port()
    log = open(tmp_path_factory.mktemp("moto") / "moto.log", "wb")  # noqa: SIM115 - closed below
    process = subprocess.Popen([str(server), "-H", "127.0.0.1", "-p", str(port)], stdout=log,
                               stderr=subprocess.STDOUT, start_new_session=True)  # fmt: skip
    try:
        endpoint = f"http://127.0.0.1:{port}"
        environment = {"AWS_ACCESS_KEY_ID": "testing", "AWS_SECRET_ACCESS_KEY": "testing",
                       "AWS_DEFAULT_REGION": "us-east-1", "AWS_ENDPOINT_URL": endpoint,
                       "FSSPEC_S3_ENDPOINT_URL": endpoint}  # fmt: skip
        deadline = time.monotonic() + 60
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                if time.monotonic() > deadline or process.poll() is not None:
                    raise RuntimeError("moto_server did not start") from None
                time.sleep(0.2)
        fs = _s3(environment)
        fs.mkdir("frustum")
        yield environment
    finally:
        stop_groups([process.pid])
        log.close()


def _s3(environment: dict[str, str]):
    import s3fs

    return s3fs.S3FileSystem(key=environment["AWS_ACCESS_KEY_ID"], secret=environment["AWS_SECRET_ACCESS_KEY"],
                             endpoint_url=environment["AWS_ENDPOINT_URL"], skip_instance_cache=True)  # fmt: skip


@pytest.fixture(scope="module")
def cluster(tmp_path_factory, moto):
    """Head (no CPUs) and worker node "a" (1 CPU, private /tmp); stopped at the end, whatever happened."""
    # a short root: Ray's socket paths must stay under 107 characters
    root = Path(f"/tmp/fr34-{secrets.token_hex(3)}")
    root.mkdir()
    cluster = Cluster(root, moto)
    try:
        cluster.start_head()
        cluster.add_worker("a")
        yield cluster
    finally:
        cluster.stop()
        shutil.rmtree(root, ignore_errors=True)


@pytest.fixture(scope="module")
def scene_path(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("scene") / "scene.toml"
    path.write_text(SCENE)
    return path


def files_of(folder: Path) -> dict[str, bytes]:
    """Every file under `folder` but the run log (its lines hold timings and arrive in completion order)."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and p.name != "manifest.jsonl"}  # fmt: skip


def _dataset(cluster: Cluster, scene: Path, out: str, *arguments: str) -> subprocess.Popen:
    command = [sys.executable, "-m", "frustum", "dataset", str(scene), "--out", out, "--executor", "ray",
               "--address", "auto", "--no-progress", *arguments]  # fmt: skip
    return subprocess.Popen(command, env=cluster.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)  # fmt: skip


def _finish(process: subprocess.Popen, timeout: float = 600) -> tuple[int, str, str]:
    try:
        out, err = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        stop_groups([process.pid])
        out, err = process.communicate()
        pytest.fail(f"the driver ran past {timeout} s:\n{err.decode(errors='replace')[-3000:]}")
    return process.returncode, out.decode(errors="replace"), err.decode(errors="replace")


def _watched(cluster: Cluster, driver: subprocess.Popen, node: str = "a") -> tuple[int, str, str, set[str]]:
    """`_finish`, and the process ids seen on `node` meanwhile (its actors exit when the driver ends)."""
    seen: set[str] = set()
    while driver.poll() is None:
        seen |= {str(p.pid) for p in cluster.processes(node)}
        time.sleep(0.05)
    return (*_finish(driver), seen)


def _workers(log_text: str) -> set[str]:
    return {json.loads(line)["worker"] for line in log_text.splitlines()[1:] if line.strip()}


# --- a folder on the driver's side --------------------------------------------------------------------------------


def test_two_nodes_write_a_complete_dataset_on_the_driver_side(cluster, scene_path, tmp_path) -> None:
    arguments = ["--views", "24", "--layout", "sphere", "--format", "webdataset"]
    render_dataset(scene_path, tmp_path / "serial", views=24, layout="sphere", format="webdataset",
                   executor="serial", progress=False)  # fmt: skip
    code, out, err, node_a = _watched(cluster, _dataset(cluster, scene_path, str(tmp_path / "ray"), *arguments))
    assert code == 0, err
    assert "24 views rendered, 0 skipped" in out
    assert files_of(tmp_path / "ray") == files_of(tmp_path / "serial")
    workers = _workers((tmp_path / "ray/manifest.jsonl").read_text())
    assert workers and {w.rsplit(":", 1)[1] for w in workers} <= node_a  # rendered on the other node
    # the worker node cannot see the folder (its /tmp is its own): the files came through the object store
    raylet = next(p for p in cluster.processes("a") if p.name() == "raylet")
    seen_by_worker = Path("/proc") / str(raylet.pid) / "root" / tmp_path.relative_to("/")
    assert (tmp_path / "ray/images").is_dir() and not seen_by_worker.exists()


def test_workers_writing_a_local_folder_on_two_nodes_is_refused(cluster, scene_path, tmp_path) -> None:
    code, _out, err = _finish(_dataset(cluster, scene_path, str(tmp_path / "ds"), "--views", "3",
                                      "--collect", "workers"))  # fmt: skip
    assert code != 0
    assert "collect = 'workers' with the local path" in err and "a Ray cluster of 2 nodes" in err
    assert "use collect='driver'" in err
    assert not (tmp_path / "ds/images").exists()


# --- URLs ---------------------------------------------------------------------------------------------------------


def test_s3_dataset_written_by_the_workers_with_manifest_and_resume(cluster, moto, scene_path, tmp_path) -> None:
    fs = _s3(moto)
    reference = tmp_path / "serial"
    arguments = ["--views", "12", "--layout", "random", "--format", "nerfstudio"]
    render_dataset(scene_path, reference, views=12, layout="random", format="nerfstudio", executor="serial",
                   progress=False)  # fmt: skip
    url = "s3://frustum/resume"
    code, out, err, node_a = _watched(cluster, _dataset(cluster, scene_path, url, *arguments))
    assert code == 0, err
    written = {p[len("frustum/resume/") :]: fs.cat_file(p) for p in fs.find("frustum/resume")}
    log = written.pop("manifest.jsonl").decode()
    assert written == files_of(reference)  # no manifest.parts left: merged at the end
    assert {w.rsplit(":", 1)[1] for w in _workers(log)} <= node_a  # the worker node wrote to the bucket
    fs.rm("frustum/resume/normals/view_00004.npy")  # a lost object: that view again, the rest skipped
    code, out, err = _finish(_dataset(cluster, scene_path, url, *arguments))
    assert code == 0, err
    assert "1 views rendered, 11 skipped" in out
    assert fs.cat_file("frustum/resume/normals/view_00004.npy") == written["normals/view_00004.npy"]
    code, out, err = _finish(_dataset(cluster, scene_path, url, "--views", "13", "--layout", "random",
                                      "--format", "nerfstudio"))  # fmt: skip
    assert code != 0 and "another configuration (views = 12 → 13)" in err


def test_s3_driver_killed_midway_then_rerun_equals_an_uninterrupted_run(cluster, moto, scene_path, tmp_path) -> None:
    fs = _s3(moto)
    arguments = ["--views", "80", "--layout", "sphere", "--format", "files", "--size", "160x120"]
    render_dataset(scene_path, tmp_path / "serial", views=80, layout="sphere", format="files", size=(160, 120),
                   executor="serial", progress=False)  # fmt: skip
    url = "s3://frustum/killed"
    driver = _dataset(cluster, scene_path, url, *arguments)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and driver.poll() is None:
        if len(fs.glob("frustum/killed/manifest.parts/*.jsonl", refresh=True)) >= 1:
            break
        time.sleep(0.2)
    stop_groups([driver.pid])
    driver.communicate()
    fs.invalidate_cache()
    assert not fs.exists("frustum/killed/cameras.json"), "the first run was not stopped midway"
    code, out, err = _finish(_dataset(cluster, scene_path, url, *arguments))
    assert code == 0, err
    skipped = int(out.split(" skipped")[0].rsplit(" ", 1)[1])
    assert 0 < skipped < 80  # the parts of the killed run's log were read
    written = {p[len("frustum/killed/") :]: fs.cat_file(p) for p in fs.find("frustum/killed")}
    written.pop("manifest.jsonl")
    assert written == files_of(tmp_path / "serial")


def test_file_and_memory_urls_on_the_cluster(cluster, scene_path, tmp_path) -> None:
    """file:// on a file system both nodes share (/dev/shm here) is written by the workers; memory:// (one
    process's) by the driver."""
    render_dataset(scene_path, tmp_path / "serial", views=6, format="colmap", executor="serial", progress=False)
    reference = {k: hashlib.sha256(v).hexdigest() for k, v in files_of(tmp_path / "serial").items()}
    shared = Path(f"/dev/shm/fr34-{secrets.token_hex(4)}")
    try:
        driver = _dataset(cluster, scene_path, f"file://{shared}/ds", "--views", "6", "--format", "colmap")
        code, _out, err, node_a = _watched(cluster, driver)
        assert code == 0, err
        assert files_of(shared / "ds") == files_of(tmp_path / "serial")
        assert {w.rsplit(":", 1)[1] for w in _workers((shared / "ds/manifest.jsonl").read_text())} <= node_a
    finally:
        shutil.rmtree(shared, ignore_errors=True)
    script = (
        "import hashlib, json, sys, fsspec\n"
        "from frustum.batch import render_dataset\n"
        "r = render_dataset(sys.argv[1], 'memory://ds', views=6, format='colmap', executor='ray', address='auto',"
        " progress=False)\n"
        "fs = fsspec.filesystem('memory')\n"
        "print(json.dumps({p[len('/ds/'):]: hashlib.sha256(fs.cat_file(p)).hexdigest() for p in fs.find('/ds')"
        " if not p.endswith('manifest.jsonl')}))\n"
    )
    done = subprocess.run([sys.executable, "-c", script, str(scene_path)], env=cluster.env, capture_output=True,
                          timeout=600)  # fmt: skip
    assert done.returncode == 0, done.stderr.decode(errors="replace")[-3000:]
    assert json.loads(done.stdout.decode().strip().splitlines()[-1]) == reference


# --- faults -------------------------------------------------------------------------------------------------------


def test_worker_node_killed_halfway_the_dataset_still_completes(cluster, scene_path, tmp_path) -> None:
    arguments = ["--views", "160", "--layout", "sphere", "--format", "files", "--size", "240x180"]
    render_dataset(scene_path, tmp_path / "serial", views=160, layout="sphere", format="files", size=(240, 180),
                   executor="serial", progress=False)  # fmt: skip
    cluster.add_worker("b")
    node_b = {str(p.pid) for p in cluster.processes("b")}
    raylet = next(p for p in cluster.processes("b") if p.name() == "raylet")
    log = tmp_path / "ray/manifest.jsonl"
    driver = _dataset(cluster, scene_path, str(tmp_path / "ray"), *arguments)
    deadline = time.monotonic() + 300
    killed_at = None
    while time.monotonic() < deadline and driver.poll() is None:
        node_b |= {str(p.pid) for p in cluster.processes("b")}  # its actor's process, once started
        text = log.read_text() if log.exists() else ""
        if any(w.rsplit(":", 1)[1] in node_b for w in _workers(text)):
            killed_at = text.count("\n") - 1
            raylet.send_signal(signal.SIGKILL)  # the node is lost: its actor and its views in flight with it
            break
        time.sleep(0.05)
    code, out, err = _finish(driver)
    assert killed_at is not None and killed_at < 100, "node b was not killed midway"
    assert code == 0, err
    assert "160 views rendered, 0 skipped" in out and "0 failed" in out
    assert files_of(tmp_path / "ray") == files_of(tmp_path / "serial")
    workers = _workers(log.read_text())
    assert any(w.rsplit(":", 1)[1] in node_b for w in workers)  # both nodes rendered
    assert any(w.rsplit(":", 1)[1] not in node_b for w in workers)


# --- the driver's memory ------------------------------------------------------------------------------------------

MEMORY_SCRIPT = """
import json, os, sys
import psutil
from frustum.batch import RenderJob, dataset_cameras, render_many
from frustum.batch.progress import ViewProgress
from frustum.scenefile import load_scene_file

scene, out, views = sys.argv[1], sys.argv[2], int(sys.argv[3])
camera = load_scene_file(scene).resized((256, 256)).cameras[0]
me = psutil.Process()


def split():  # the RSS's anonymous memory (this process's own) and shared memory (object-store pages it mapped)
    with open(os.path.join(os.sep, "proc", "self", "status")) as status:
        fields = dict(line.split(":", 1) for line in status)
    return {k: int(fields[k].split()[0]) * 1024 for k in ("RssAnon", "RssShmem")}


class Sampled(ViewProgress):
    base = peak = 0
    base_split = peak_split = None

    def advance(self, result):
        super().advance(result)
        for path in result.files.values():  # the disk stays small; the page cache is not the driver's RSS
            os.remove(path)
        rss = me.memory_info().rss
        if self.done == 100:
            Sampled.base, Sampled.base_split = rss, split()
        elif self.done > 100 and rss > Sampled.peak:
            Sampled.peak, Sampled.peak_split = rss, split()


jobs = [RenderJob(key, scene, c, {"color": f"{out}/{key}.png", "depth": f"{out}/{key}.npy",
                                 "normals": f"{out}/{key}.normals.npy", "mask": f"{out}/{key}.mask.png"})
        for key, c in dataset_cameras(camera, views, "sphere")]
bar = Sampled(len(jobs), enabled=False)
results = render_many(jobs, executor="ray", address="auto", collect="driver", progress=bar)
print(json.dumps({"ok": sum(r.ok for r in results), "base_mib": Sampled.base / 2**20,
                  "peak_mib": Sampled.peak / 2**20, "views_per_s": bar.rate,
                  "base": Sampled.base_split, "peak": Sampled.peak_split}))
"""


@pytest.mark.slow
def test_driver_memory_stays_flat_over_2000_views(cluster, scene_path, tmp_path) -> None:
    (tmp_path / "out").mkdir()
    done = subprocess.run([sys.executable, "-c", MEMORY_SCRIPT, str(scene_path), str(tmp_path / "out"), "2000"],
                          env=cluster.env, capture_output=True, timeout=1200)  # fmt: skip
    assert done.returncode == 0, done.stderr.decode(errors="replace")[-3000:]
    report = json.loads(done.stdout.decode().strip().splitlines()[-1])
    mib = {k: {part: value / 2**20 for part, value in report[k].items()} for k in ("base", "peak")}
    print(f"driver RSS after 100 views {report['base_mib']:.1f} MiB (anonymous {mib['base']['RssAnon']:.1f}, "
          f"object-store pages {mib['base']['RssShmem']:.1f}), peak after {report['peak_mib']:.1f} MiB (anonymous "
          f"{mib['peak']['RssAnon']:.1f}, object-store pages {mib['peak']['RssShmem']:.1f}), "
          f"{report['views_per_s']:.1f} views/s")  # fmt: skip
    assert report["ok"] == 2000
    # the issue's bound. Measured at load 4-7 (2 cores): +7, +11 and +20 MiB, no object-store pages. Before the views'
    # files came in pieces inside Ray's task replies (RAY_INLINE_BYTES), the driver read 16 views a task from the
    # object store and every store page it read stayed in its RSS: +54 MiB on a quiet machine, +83 MiB at load 5
    assert report["peak_mib"] - report["base_mib"] <= 50.0
