"""The resident render process (``frustum.resident``, issue 36's warm one-command render): a plain
``frustum render FILE -o OUT`` handed to a warm process writes the same bytes and prints the same lines with the
same exit status as a render in its own process; it is private to the user, follows the client's working folder,
honours Ctrl-C, and goes away when idle or told to stop."""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from frustum.app import resident
from testdata import DATA

pytestmark = pytest.mark.skipif(not hasattr(socket, "SO_PEERCRED") or sys.platform != "linux",
                                reason="the resident render process is Linux only (SO_PEERCRED)")  # fmt: skip

BUNNY = DATA / "bunny" / "bun_zipper_res4.ply"
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def runtime(monkeypatch):
    """A private runtime folder of its own, with resident processes on; every resident process started in it is
    stopped at the end. A scratch folder directly in the system's temporary folder, not pytest's deeper tmp_path:
    a socket's path holds < 108 bytes (nothing is read from it but what the test's programs write)."""
    folder = Path(tempfile.mkdtemp(prefix="fr-"))
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(folder))
    monkeypatch.setenv("FRUSTUM_RESIDENT", "1")
    monkeypatch.setattr(resident, "_FINGERPRINT", [])
    yield folder
    resident.stop()
    for pid in _pids(folder):
        with contextlib.suppress(OSError):
            os.kill(pid, signal.SIGKILL)
    shutil.rmtree(folder, ignore_errors=True)


def _pids(folder: Path) -> list[int]:
    """Processes whose command line names `folder` (resident processes started there)."""
    import psutil

    found = []
    for process in psutil.process_iter(["cmdline"]):
        if any(str(folder) in part for part in process.info["cmdline"] or ()):
            found.append(process.pid)
    return found


def _program(*arguments: str, cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "frustum", *arguments], cwd=cwd, capture_output=True, text=True,
                          timeout=300, check=False, env=env)  # fmt: skip


def _wait_for(predicate, seconds: float = 60.0) -> bool:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.05)
    return False


def _served() -> int:
    """Renders served by the resident processes of this test's folder."""
    return sum(entry["requests"] for entry in resident.status())


def _started(tmp_path: Path) -> None:
    """Run one plain render in its own process, which leaves a resident process behind; wait until it answers."""
    first = _program("render", str(BUNNY), "-o", "first.png", "--size", "96x72", cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    assert _wait_for(lambda: len(resident.status()) == 1), "no resident render process answered"


def test_a_resident_process_writes_the_same_bytes_and_lines(runtime, tmp_path):
    _started(tmp_path)
    assert _served() == 0
    (tmp_path / "sub").mkdir()
    handed = _program("render", str(BUNNY), "-o", "sub/second.png", "--size", "96x72", cwd=tmp_path)
    assert handed.returncode == 0, handed.stderr
    assert _served() == 1, "the second render did not go to the resident process"
    own = _program("render", str(BUNNY), "-o", "sub/third.png", "--size", "96x72", cwd=tmp_path,
                   env={**os.environ, "FRUSTUM_RESIDENT": "0"})  # fmt: skip
    assert _served() == 1
    assert handed.stdout == "wrote sub/second.png\n" and own.stdout == "wrote sub/third.png\n"
    assert handed.stderr == own.stderr == ""
    pictures = [(tmp_path / name).read_bytes() for name in ("first.png", "sub/second.png", "sub/third.png")]
    assert pictures[0] == pictures[1] == pictures[2]
    assert oct((tmp_path / "sub" / "second.png").stat().st_mode & 0o777) == oct(0o666 & ~_umask())


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@pytest.mark.parametrize(
    ("arguments", "status"),
    [
        (["render", "missing.ply", "-o", "x.png"], 1),
        (["render", str(BUNNY), "-o", "x.png", "--size", "0x5"], 2),
        (["render", str(BUNNY), "-o", "first.png/x.png"], 1),
        (["render", str(BUNNY), "-o", "x.png", "--shadows", "maybe"], 1),
    ],
)
def test_errors_are_the_same_through_a_resident_process(runtime, tmp_path, arguments, status):
    _started(tmp_path)
    handed = _program(*arguments, cwd=tmp_path)
    own = _program(*arguments, cwd=tmp_path, env={**os.environ, "FRUSTUM_RESIDENT": "0"})
    assert _served() == 1
    assert handed.returncode == own.returncode == status
    assert handed.stderr == own.stderr and handed.stderr.startswith("error: ") and handed.stdout == own.stdout == ""
    assert len(resident.status()) == 1, "the resident process must survive a failed request"


def test_ctrl_c_cancels_and_writes_no_file(runtime, tmp_path):
    _started(tmp_path)
    client = subprocess.Popen([sys.executable, "-m", "frustum", "render", str(BUNNY), "-o", "big.png", "--size",
                               "8192x8192"], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True)  # fmt: skip
    time.sleep(1.5)  # the client hands the command over within ~0.1 s; an 8192² picture takes seconds to encode
    client.send_signal(signal.SIGINT)
    stdout, stderr = client.communicate(timeout=60)
    assert client.returncode == 130
    assert stderr == "error: interrupted (Ctrl-C); no output file was written or changed\n" and stdout == ""
    assert _wait_for(lambda: _served() == 1, 120)  # answers again once the cancelled work has ended
    assert sorted(path.name for path in tmp_path.iterdir()) == ["first.png"], "a partial or whole file was left"
    after = _program("render", str(BUNNY), "-o", "after.png", "--size", "96x72", cwd=tmp_path)
    assert after.returncode == 0 and (tmp_path / "after.png").read_bytes() == (tmp_path / "first.png").read_bytes()


def test_it_exits_when_idle_and_on_stop(runtime, tmp_path, monkeypatch):
    monkeypatch.setenv("FRUSTUM_RESIDENT_IDLE_S", "1")
    _started(tmp_path)
    assert _wait_for(lambda: not resident.status() and not list(runtime.glob("frustum/*.sock")), 30)
    monkeypatch.setenv("FRUSTUM_RESIDENT_IDLE_S", "600")
    _started(tmp_path)
    listed = _program("resident", "status", cwd=tmp_path)
    assert listed.returncode == 0 and "0 renders served" in listed.stdout
    stopped = _program("resident", "stop", cwd=tmp_path)
    assert stopped.stdout == "stopped 1 resident render process(es)\n"
    assert _wait_for(lambda: not list((runtime / "frustum").iterdir()), 30), "left files behind"
    assert _program("resident", "status", cwd=tmp_path).stdout == "no resident render process is running\n"


def test_turned_off_or_an_unsafe_folder_means_no_resident_process(runtime, tmp_path, monkeypatch):
    monkeypatch.setenv("FRUSTUM_RESIDENT", "0")
    result = _program("render", str(BUNNY), "-o", "a.png", "--size", "32x24", cwd=tmp_path)
    assert result.returncode == 0 and not (runtime / "frustum").exists()
    monkeypatch.setenv("FRUSTUM_RESIDENT", "1")
    (runtime / "frustum").mkdir(mode=0o755)
    os.chmod(runtime / "frustum", 0o755)  # open to other users: never used
    result = _program("render", str(BUNNY), "-o", "b.png", "--size", "32x24", cwd=tmp_path)
    assert result.returncode == 0 and list((runtime / "frustum").iterdir()) == []
    assert resident._paths(create=True) is None and resident.handed({"scene": "x"}) is None


def test_only_the_same_user_is_served(monkeypatch):
    left, right = socket.socketpair(socket.AF_UNIX)
    with left, right:
        assert resident._same_user(left)
        monkeypatch.setattr(os, "getuid", lambda: os.geteuid() + 1)
        assert not resident._same_user(left)


def test_a_malformed_request_is_answered_and_the_process_goes_on(runtime, tmp_path):
    _started(tmp_path)
    path = next(runtime.glob("frustum/*.sock"))
    for line in (b"not json\n", b'{"render": {"scene": 5}, "cwd": "/"}\n', b'{"render": {"scene": "x"}, "cwd": 3}\n'):
        with socket.socket(socket.AF_UNIX) as connection:
            connection.settimeout(30)
            connection.connect(str(path))
            connection.sendall(line)
            reply = resident._Lines(connection).next()
            assert reply is None or reply.get("stream") == "err"
    assert len(resident.status()) == 1


def test_the_fingerprint_follows_sources_and_settings(tmp_path):
    package = tmp_path / "frustum"
    package.mkdir()
    (package / "a.py").write_text("x = 1\n")
    environ = {"NUMBA_NUM_THREADS": "2", "HOME": "home-a"}
    first = resident.fingerprint(package, environ)
    assert len(first) == 16 and first == resident.fingerprint(package, dict(environ))
    assert resident.fingerprint(package, {**environ, "HOME": "home-b", "FRUSTUM_RESIDENT_IDLE_S": "5"}) == first
    assert resident.fingerprint(package, {**environ, "NUMBA_NUM_THREADS": "1"}) != first
    assert resident.fingerprint(package, {**environ, "FRUSTUM_MAX_BYTES": "1e9"}) != first
    (package / "a.py").write_text("x = 22\n")
    assert resident.fingerprint(package, environ) != first


def _rss_mib(pid: int) -> float:
    import psutil

    return psutil.Process(pid).memory_info().rss / 2**20


def test_memory_does_not_grow_from_request_to_request(runtime, tmp_path):
    _started(tmp_path)
    pid = resident.status()[0]["pid"]
    spot = DATA / "spot" / "spot_triangulated.obj"
    sizes = []
    for _ in range(16):
        result = _program("render", str(spot), "-o", "spot.png", "--size", "800x600", cwd=tmp_path)
        assert result.returncode == 0, result.stderr
        assert _wait_for(lambda: len(resident.status()) == 1)  # answered: the request's memory is released
        sizes.append(_rss_mib(pid))
    assert _served() == 16
    assert max(sizes[8:]) - sizes[4] < 24, f"resident memory grows: {sizes} MiB"


def test_the_fingerprint_follows_installed_packages(tmp_path, monkeypatch):
    site = tmp_path / "lib" / "site-packages"
    site.mkdir(parents=True)
    monkeypatch.setattr(sys, "path", [*sys.path, str(site)])
    package = tmp_path / "frustum"
    package.mkdir()
    before = resident.fingerprint(package, {})
    (site / "numba-9.9.dist-info").mkdir()  # what pip install leaves
    os.utime(site, ns=(time.time_ns(), time.time_ns() + 10**9))
    assert resident.fingerprint(package, {}) != before


def test_the_warm_up_loads_what_the_program_used_from_the_cache(runtime, tmp_path):
    import frustum
    from frustum.raster import _background

    scene = frustum.Scene(lights=[frustum.DirectionalLight(direction=(0, 0, -1))])
    scene.add(frustum.icosphere(subdivisions=1))
    frustum.render(scene, frustum.Camera.look_at(eye=(0, 0, 4), target=(0, 0, 0), width=32, height=24))
    plan = resident._kernels_in_use()
    assert {"project_vertices", "count_tiles"} <= {name for _, name, _ in plan}
    for module, name, text in plan:
        assert _background._cached(_background.dispatcher(module, name), _background.parse_signature(text))
    _started(tmp_path)
    assert [path.read_text() for path in runtime.glob("frustum/*.log")] == [""], "the warm-up reported a problem"
