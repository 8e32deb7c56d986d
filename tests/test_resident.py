"""The resident render process (``frustum.app.resident``), started on purpose: nothing is left behind unasked; once
started, a plain ``frustum render FILE -o OUT`` handed to it writes the same bytes and prints the same lines with
the same exit status as a render in its own process; it is never a queue (busy: the command renders itself), Ctrl-C
kills the work, a caller of other environment or limits renders itself, its socket shrugs off hostile requests,
and there is one per user and installation."""

from __future__ import annotations

import contextlib
import json
import os
import resource
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil
import pytest

from frustum.app import resident
from testdata import DATA

pytestmark = pytest.mark.skipif(not hasattr(socket, "SO_PEERCRED") or sys.platform != "linux",
                                reason="the resident render process is Linux only (SO_PEERCRED)")  # fmt: skip

BUNNY = DATA / "bunny" / "bun_zipper_res4.ply"
ROOT = Path(__file__).resolve().parents[1]
ANNOUNCED = "started a resident render process (pid "


@pytest.fixture
def runtime(monkeypatch):
    """A private runtime folder of its own with no FRUSTUM_RESIDENT setting (the default); every resident process
    started in it is stopped at the end. A scratch folder directly in the system's temporary folder, not pytest's
    deeper tmp_path: a socket's path holds < 108 bytes."""
    folder = Path(tempfile.mkdtemp(prefix="fr-"))
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(folder))
    monkeypatch.delenv("FRUSTUM_RESIDENT", raising=False)
    yield folder
    resident.stop()
    for process in _residents(folder):
        with contextlib.suppress(psutil.Error):
            process.kill()
    shutil.rmtree(folder, ignore_errors=True)


def _residents(folder: Path) -> list[psutil.Process]:
    """Resident processes started in `folder` (their command line names it) and their request children."""
    found = []
    for process in psutil.process_iter(["cmdline"]):
        with contextlib.suppress(psutil.Error):
            if any(str(folder) in part for part in process.info["cmdline"] or ()):
                found.append(process)
    return found


def _program(*arguments: str, cwd: Path, env: dict[str, str] | None = None, **options) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "frustum", *arguments], cwd=cwd, capture_output=True, text=True,
                          timeout=300, check=False, env=env, **options)  # fmt: skip


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


def _start(tmp_path: Path, env: dict[str, str] | None = None, **options) -> subprocess.CompletedProcess:
    """``frustum resident start`` (it returns once the resident answers)."""
    started = _program("resident", "start", cwd=tmp_path, env=env, **options)
    assert started.returncode == 0, started.stderr
    return started


def _render(tmp_path: Path, name: str, env: dict[str, str] | None = None, size: str = "96x72"):
    return _program("render", str(BUNNY), "-o", name, "--size", size, cwd=tmp_path, env=env)


def test_by_default_no_command_leaves_a_process_behind(runtime, tmp_path):
    before = {process.pid for process in psutil.Process().children(recursive=True)}
    ok = _render(tmp_path, "a.png")
    failed = _program("render", "missing.ply", "-o", "b.png", cwd=tmp_path)
    assert ok.returncode == 0 and ok.stderr == "" and failed.returncode == 1
    time.sleep(0.5)
    assert _residents(runtime) == [] and resident.status() == []
    assert {process.pid for process in psutil.Process().children(recursive=True)} <= before
    assert not (runtime / "frustum").exists()


def test_started_on_purpose_it_is_used_and_says_so_once(runtime, tmp_path):
    own = _render(tmp_path, "own.png")
    started = _start(tmp_path)
    assert started.stderr.count(ANNOUNCED) == 1 and started.stdout == ""
    assert [entry["requests"] for entry in resident.status()] == [0]
    (tmp_path / "sub").mkdir()
    handed = _render(tmp_path, "sub/second.png")
    assert handed.returncode == 0, handed.stderr
    assert _served() == 1, "the render did not go to the resident process"
    assert handed.stdout == "wrote sub/second.png\n" and handed.stderr == own.stderr == ""
    assert (tmp_path / "own.png").read_bytes() == (tmp_path / "sub" / "second.png").read_bytes()
    assert oct((tmp_path / "sub" / "second.png").stat().st_mode & 0o777) == oct(0o666 & ~_umask())
    ignored = _render(tmp_path, "third.png", env={**os.environ, "FRUSTUM_RESIDENT": "0"})
    assert ignored.returncode == 0 and _served() == 1
    again = _start(tmp_path)
    assert ANNOUNCED not in again.stderr and "already running" in again.stdout
    assert len(resident.status()) == 1


def test_frustum_resident_1_starts_one_after_a_successful_render_only(runtime, tmp_path):
    env = {**os.environ, "FRUSTUM_RESIDENT": "1"}
    failed = _program("render", "missing.ply", "-o", "x.png", cwd=tmp_path, env=env)
    assert failed.returncode == 1 and ANNOUNCED not in failed.stderr
    time.sleep(0.5)
    assert _residents(runtime) == []
    first = _render(tmp_path, "first.png", env=env)
    assert first.returncode == 0 and first.stderr.count(ANNOUNCED) == 1
    assert _wait_for(lambda: len(resident.status()) == 1), "no resident render process answered"
    second = _render(tmp_path, "second.png", env=env)
    assert second.returncode == 0 and second.stderr == "" and _served() == 1
    assert (tmp_path / "first.png").read_bytes() == (tmp_path / "second.png").read_bytes()


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@pytest.mark.parametrize(
    ("arguments", "status"),
    [
        (["render", "missing.ply", "-o", "x.png"], 1),
        (["render", str(BUNNY), "-o", "x.png", "--size", "0x5"], 2),
        (["render", str(BUNNY), "-o", "own.png/x.png"], 1),
        (["render", str(BUNNY), "-o", "x.png", "--shadows", "maybe"], 1),
    ],
)
def test_errors_are_the_same_through_a_resident_process(runtime, tmp_path, arguments, status):
    (tmp_path / "own.png").write_bytes(b"")
    own = _program(*arguments, cwd=tmp_path)
    _start(tmp_path)
    handed = _program(*arguments, cwd=tmp_path)
    assert _served() == 1
    assert handed.returncode == own.returncode == status
    assert handed.stderr == own.stderr and handed.stderr.startswith("error: ") and handed.stdout == own.stdout == ""
    assert len(resident.status()) == 1, "the resident process must survive a failed request"


def _busy_with_a_large_render(tmp_path: Path) -> tuple[subprocess.Popen, dict]:
    """A client whose 8192² render of the full-size bunny the resident's child is doing; the resident's status."""
    client = subprocess.Popen([sys.executable, "-m", "frustum", "render", str(BUNNY.with_name("bun_zipper.ply")),
                               "-o", "big.png", "--size", "8192x8192"], cwd=tmp_path, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)  # fmt: skip
    assert _wait_for(lambda: any(entry.get("busy") for entry in resident.status()), 60), "never busy"
    return client, resident.status()[0]


def test_busy_it_says_so_at_once_and_the_second_command_renders_itself(runtime, tmp_path):
    _start(tmp_path)
    client, _ = _busy_with_a_large_render(tmp_path)
    request = {"render": {"scene": str(BUNNY), "output": ["x.png"], "size": None, "up": None, "shadows": None},
               "fingerprint": resident.fingerprint(), **resident.conditions()}  # fmt: skip
    reply, seconds = _ask_raw(next(runtime.glob("frustum/*.sock")), json.dumps(request).encode() + b"\n")
    assert json.loads(reply) == {"refused": "busy"} and seconds < 1.0
    second = _render(tmp_path, "second.png")
    assert second.returncode == 0 and second.stdout == "wrote second.png\n" and second.stderr == ""
    if client.poll() is None:  # the first is still being drawn: the second did not wait for it
        assert _served() == 1
    client.kill()
    client.communicate(timeout=60)


def test_ctrl_c_kills_the_work_and_the_next_command_starts_at_once(runtime, tmp_path):
    own = _render(tmp_path, "own.png")
    _start(tmp_path)
    client, entry = _busy_with_a_large_render(tmp_path)
    child = psutil.Process(entry["child"])
    client.send_signal(signal.SIGINT)
    stdout, stderr = client.communicate(timeout=60)
    assert client.returncode == 130
    assert stderr == "error: interrupted (Ctrl-C); no output file was written or changed\n" and stdout == ""
    assert _wait_for(lambda: not child.is_running() or child.status() == psutil.STATUS_ZOMBIE, 5), "work goes on"
    parent = psutil.Process(entry["pid"])
    cpu = sum(parent.cpu_times()[:2])
    time.sleep(1.0)
    assert sum(parent.cpu_times()[:2]) - cpu < 0.2, "the resident still works"
    assert sorted(path.name for path in tmp_path.iterdir()) == ["own.png"], "a partial or whole file was left"
    assert not resident.status()[0]["busy"]
    after = _render(tmp_path, "after.png")
    assert after.returncode == 0 and _served() == 2
    assert own.returncode == 0 and (tmp_path / "after.png").read_bytes() == (tmp_path / "own.png").read_bytes()


def test_status_and_stop_see_a_busy_resident(runtime, tmp_path):
    _start(tmp_path)
    client, entry = _busy_with_a_large_render(tmp_path)
    listed = _program("resident", "status", cwd=tmp_path)
    assert "rendering now" in listed.stdout, listed.stdout
    stopped = _program("resident", "stop", cwd=tmp_path)
    assert stopped.stdout == "stopped 1 resident render process(es)\n"
    assert _wait_for(lambda: not psutil.pid_exists(entry["pid"]) and not psutil.pid_exists(entry["child"]), 10)
    client.kill()  # it renders the command itself now (the resident went away before answering)
    client.communicate(timeout=60)
    assert _residents(runtime) == []


def test_other_environment_or_limits_render_themselves_and_a_new_one_replaces_the_old(runtime, tmp_path):
    base = {**os.environ, "OMP_NUM_THREADS": "1"}
    _start(tmp_path, env=base)
    pid = resident.status()[0]["pid"]
    same = _render(tmp_path, "same.png", env=base)
    assert same.returncode == 0 and _served() == 1
    other = _render(tmp_path, "other.png", env={**base, "OMP_NUM_THREADS": "2"})
    assert other.returncode == 0 and other.stderr == "" and _served() == 1, "served under another OMP_NUM_THREADS"
    applied = _render(tmp_path, "applied.png", env={**base, "PWD": "/elsewhere", "COLUMNS": "7"})
    assert applied.returncode == 0 and _served() == 2

    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    limit = 64 * 2**30 if soft == resource.RLIM_INFINITY else soft // 2

    def limited() -> None:  # ulimit -v
        resource.setrlimit(resource.RLIMIT_AS, (limit, hard))

    under = _program("render", str(BUNNY), "-o", "limited.png", "--size", "96x72", cwd=tmp_path, env=base,
                     preexec_fn=limited)  # fmt: skip
    assert under.returncode == 0 and _served() == 2, "served under other resource limits"
    # FRUSTUM_RESIDENT=1 under another environment: its own render, then a new resident replaces the old one
    replaced = _render(tmp_path, "replaced.png", env={**base, "OMP_NUM_THREADS": "2", "FRUSTUM_RESIDENT": "1"})
    assert replaced.returncode == 0 and replaced.stderr.count(ANNOUNCED) == 1
    assert _wait_for(lambda: [entry["pid"] for entry in resident.status()] not in ([], [pid]), 120)
    assert _wait_for(lambda: not psutil.pid_exists(pid), 10), "the old resident is still running"
    assert len(resident.status()) == 1 and len([p for p in _residents(runtime) if p.pid != os.getpid()]) == 1
    pictures = {(tmp_path / name).read_bytes() for name in ("same.png", "other.png", "applied.png", "limited.png",
                                                               "replaced.png")}  # fmt: skip
    assert len(pictures) == 1


def _ask_raw(path: Path, data: bytes, wait: float = 5.0) -> tuple[bytes, float]:
    """Send `data` (and nothing more) and read the reply until the resident closes the connection."""
    with socket.socket(socket.AF_UNIX) as connection:
        connection.settimeout(wait)
        connection.connect(str(path))
        start = time.monotonic()
        reply = b""
        with contextlib.suppress(BrokenPipeError, ConnectionResetError):  # a request too long is cut off
            if data:
                connection.sendall(data)
            while chunk := connection.recv(65536):
                reply += chunk
        return reply, time.monotonic() - start


@pytest.mark.parametrize(
    "data",
    [b"not json\n", b"[" * 60000 + b"\n", b'{"render": {"scene": "x"}, "umask": 1e400}\n',
     b'{"render": {"scene": 5}, "cwd": "/"}\n', b'{"render": {"scene": "x"}, "cwd": 3}\n', b"x" * (1 << 21),
     b'{"status": true', b""],
    ids=["not-json", "nested", "huge-number", "bad-scene", "bad-cwd", "too-long", "cut-off", "silent"],
)  # fmt: skip
def test_hostile_requests_get_an_error_or_a_timeout_and_the_resident_goes_on(runtime, tmp_path, data):
    _start(tmp_path)
    path = next(runtime.glob("frustum/*.sock"))
    reply, seconds = _ask_raw(path, data)
    assert seconds <= 1.5
    if reply:
        assert "error" in json.loads(reply.decode())
    assert len(resident.status()) == 1
    handed = _render(tmp_path, "after.png")
    assert handed.returncode == 0 and _served() == 1


def test_it_exits_when_idle_and_on_stop(runtime, tmp_path, monkeypatch):
    monkeypatch.setenv("FRUSTUM_RESIDENT_IDLE_S", "1")
    _start(tmp_path)
    assert _wait_for(lambda: not resident.status() and not list(runtime.glob("frustum/*.sock")), 30)
    monkeypatch.setenv("FRUSTUM_RESIDENT_IDLE_S", "600")
    _start(tmp_path)
    listed = _program("resident", "status", cwd=tmp_path)
    assert listed.returncode == 0 and "0 renders served" in listed.stdout
    stopped = _program("resident", "stop", cwd=tmp_path)
    assert stopped.stdout == "stopped 1 resident render process(es)\n"
    assert _wait_for(lambda: not list(runtime.glob("frustum/*.sock")) and not _residents(runtime), 30)
    assert _program("resident", "status", cwd=tmp_path).stdout == "no resident render process is running\n"


def test_turned_off_or_an_unsafe_folder_means_no_resident_process(runtime, tmp_path, monkeypatch):
    monkeypatch.setenv("FRUSTUM_RESIDENT", "0")
    result = _render(tmp_path, "a.png")
    assert result.returncode == 0 and not (runtime / "frustum").exists()
    monkeypatch.setenv("FRUSTUM_RESIDENT", "1")
    (runtime / "frustum").mkdir(mode=0o755)
    os.chmod(runtime / "frustum", 0o755)  # open to other users: never used
    result = _render(tmp_path, "b.png")
    assert result.returncode == 0 and list((runtime / "frustum").iterdir()) == []
    assert resident._paths(create=True) is None and resident.handed({"scene": "x"}) is None
    assert _program("resident", "start", cwd=tmp_path).returncode == 1


def test_only_the_same_user_is_served(monkeypatch):
    left, right = socket.socketpair(socket.AF_UNIX)
    with left, right:
        assert resident._same_user(left)
        monkeypatch.setattr(os, "getuid", lambda: os.geteuid() + 1)
        assert not resident._same_user(left)


def test_the_fingerprint_follows_sources_and_installed_packages(tmp_path, monkeypatch):
    package = tmp_path / "frustum"
    package.mkdir()
    (package / "a.py").write_text("x = 1\n")
    first = resident.fingerprint(package)
    assert len(first) == 16 and first == resident.fingerprint(package)
    (package / "a.py").write_text("x = 22\n")
    assert resident.fingerprint(package) != first
    site = tmp_path / "lib" / "site-packages"
    site.mkdir(parents=True)
    monkeypatch.setattr(sys, "path", [*sys.path, str(site)])
    before = resident.fingerprint(package)
    (site / "numba-9.9.dist-info").mkdir()  # what pip install leaves
    os.utime(site, ns=(time.time_ns(), time.time_ns() + 10**9))
    assert resident.fingerprint(package) != before


def test_what_differs_is_named():
    own = resident.conditions()
    assert resident.difference(own, resident.conditions()) is None
    theirs = json.loads(json.dumps({**own, "env": {**own["env"], "OMP_NUM_THREADS": "3", "PWD": "/x"}}))
    assert resident.difference(own, theirs) == "the environment variable OMP_NUM_THREADS differs"
    limits = {**own["limits"], "RLIMIT_AS": [1 << 30, own["limits"]["RLIMIT_AS"][1]]}
    assert resident.difference(own, {**own, "limits": limits}) == "the resource limits (ulimit) differ"
    assert resident.difference(own, {**own, "affinity": [*own["affinity"], 4096]}) == "the CPU affinity differs"


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
    _start(tmp_path)
    assert [path.read_text() for path in runtime.glob("frustum/*.log")] in ([], [""]), "the warm-up reported"
