"""Ctrl-C (issue 17): SIGINT to ``frustum turntable`` (GIF and MP4) and to a long render exits with status 130
within about a second, and leaves no partial file and no clobbered one."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

EXIT_LIMIT_S = 3.0  # "within about a second", with slack for a loaded CI machine


def _start(*arguments: str, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "frustum", *arguments], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True, env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )  # fmt: skip


def _interrupt(process: subprocess.Popen) -> tuple[float, str]:
    """Send SIGINT; return the seconds until the process exits and its stderr."""
    sent = time.perf_counter()
    process.send_signal(signal.SIGINT)
    try:
        _, stderr = process.communicate(timeout=60)
    except subprocess.TimeoutExpired:  # pragma: no cover - the failure this test exists for
        process.kill()
        process.communicate()
        pytest.fail("the command ignored SIGINT for 60 s")
    return time.perf_counter() - sent, stderr


def _wait_for(predicate, timeout: float = 120.0) -> None:
    end = time.perf_counter() + timeout
    while not predicate():
        if time.perf_counter() > end:  # pragma: no cover
            pytest.fail("the command did not start writing in time")
        time.sleep(0.05)


@pytest.fixture(scope="module")
def mesh_file(tmp_path_factory) -> Path:
    from frustum.geometry import icosphere
    from frustum.geometry.io import save

    return save(icosphere(1.0, 3), tmp_path_factory.mktemp("mesh") / "ball.obj")


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_ctrl_c_stops_a_turntable_and_keeps_the_old_file(mesh_file, tmp_path, suffix):
    if suffix == ".mp4":
        pytest.importorskip("imageio_ffmpeg")
    target = tmp_path / f"spin{suffix}"
    target.write_bytes(b"the old animation")
    process = _start("turntable", str(mesh_file), "-o", str(target), "--frames", "100000", "--size", "128x128",
                     cwd=tmp_path)  # fmt: skip
    _wait_for(lambda: any(p.name.endswith(".part" + suffix) for p in tmp_path.iterdir()) or process.poll() is not None)
    time.sleep(0.5)  # frames are being rendered and encoded
    elapsed, stderr = _interrupt(process)
    assert process.returncode == 130, stderr
    assert elapsed < EXIT_LIMIT_S
    assert stderr.strip().splitlines()[-1] == "error: interrupted (Ctrl-C); no output file was written or changed"
    assert target.read_bytes() == b"the old animation"
    assert sorted(p.name for p in tmp_path.iterdir()) == [target.name]


def test_ctrl_c_while_starting_up_is_not_swallowed(mesh_file, tmp_path):
    target = tmp_path / "early.gif"
    process = _start("turntable", str(mesh_file), "-o", str(target), "--frames", "100000", "--size", "64x64",
                     cwd=tmp_path)  # fmt: skip
    time.sleep(0.4)  # imports (numpy, trimesh's optional imports that catch BaseException) are still running
    _, stderr = _interrupt(process)
    assert process.returncode in (130, -signal.SIGINT), stderr  # -SIGINT: interrupted before main() started
    assert list(tmp_path.iterdir()) == []


def test_ctrl_c_stops_a_long_render_inside_a_kernel(tmp_path):
    scene = tmp_path / "slow.toml"
    scene.write_text(
        '[camera]\neye = [0, 0, 4]\ntarget = [0, 0, 0]\n\n[[nodes]]\n'
        'geometry = { type = "quaternion_julia", resolution = 400, max_iter = 300 }\n'  # 1.9e10 iterations
    )  # fmt: skip
    target = tmp_path / "slow.png"
    target.write_bytes(b"the old picture")
    process = _start("render", str(scene), "-o", str(target), cwd=tmp_path)
    time.sleep(4.0)  # well inside the escape-time kernel (minutes of work)
    assert process.poll() is None, "the render finished before it could be interrupted"
    elapsed, stderr = _interrupt(process)
    assert process.returncode == 130, stderr
    assert elapsed < EXIT_LIMIT_S
    assert target.read_bytes() == b"the old picture"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["slow.png", "slow.toml"]
