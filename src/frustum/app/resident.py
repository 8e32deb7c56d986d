"""The resident render process, started on purpose: a plain ``frustum render FILE -o OUT`` handed to a warm process.

A warm one-command render spends most of its time starting up: Python imports NumPy (~0.1 s) and Numba (~0.2 s),
and Numba sets up its compiler's target (~0.15 s) before it can load a single cached kernel. For an interactive
loop of renders (an editor that re-renders on save), a resident process that has done all that once hands each
command's work to a fresh child of itself (``os.fork``: warm at once) and the command takes about 0.1 s. For many
files at once, ``frustum render a.ply b.stl -o out/{stem}.png`` in one process is the better tool.

**Opt-in.** No command starts one unless asked: ``frustum resident start`` does, and so does a successful plain
render with ``FRUSTUM_RESIDENT=1`` in the environment; either says so once on stderr ("started a resident render
process (pid N); `frustum resident stop` ends it"). Once one runs, plain renders of the same user and installation
use it; ``FRUSTUM_RESIDENT=0`` makes a command ignore it. ``frustum resident status`` lists it (busy or not),
``frustum resident stop`` ends it (and the render it is doing).

How it stays exact, private and out of the way:

- **One per user and installation** (the Python executable and frustum's folder name the socket). A request
  carries the installation's fingerprint (frustum's source files by name, size and time, the site-packages
  folders' times: an edited file or an installed package changes it); a resident of another fingerprint refuses
  and the command renders itself. A resident started anew (``start``) replaces the one of the socket: never two.
- **The caller's environment and limits.** The request carries the caller's full environment, umask, working
  folder, resource limits (``ulimit``), CPU affinity, cgroup and nice value. The resident refuses (the command then
  renders in its own process) when any of them but the umask, the folder and the variables of ``APPLIED`` differs
  from what it started with: a variable read once at start-up (``OMP_NUM_THREADS``, ``NUMBA_*``) could change the
  result, and a Slurm job's limits must apply to its work. The request's child takes the caller's environment,
  umask and folder.
- **Never a queue.** One request at a time: a second command while one renders gets "busy" at once and renders in
  its own process. Status and stop are answered at once, busy or not.
- **Ctrl-C stops the work.** The request's child is killed (SIGTERM: it removes its partial output files, as the
  program does) when the client is interrupted or goes away; the next command starts at once.
- **Hardened socket.** The socket lives in a folder only the user can enter (``$XDG_RUNTIME_DIR/frustum``, else
  ``<temporary folder>/frustum-<uid>``, mode 0700, refused when someone else's or open to others); a connection
  is served only when its peer runs as the same user (``SO_PEERCRED``); a request must arrive within
  ``REQUEST_TIMEOUT_S`` and fit ``MAX_REQUEST_BYTES``; anything malformed (not JSON, nested too deeply, numbers out
  of range, fields of the wrong type) gets an error reply, and an unexpected failure is written to the log beside
  the socket (kept across starts up to ``MAX_LOG_BYTES``), never ending the process.
- **Gone when idle**: after ``IDLE_S`` seconds without a request (``FRUSTUM_RESIDENT_IDLE_S``). Linux only
  (``SO_PEERCRED``, ``fork``); elsewhere every render runs in its own process.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import signal
import socket
import struct
import sys
import time
from pathlib import Path
from typing import Any

from frustum.app.resident_identity import (  # noqa: F401 - the resident's identity, named here as before the split
    APPLIED,
    APPLIED_PREFIXES,
    _installation,
    _package_dir,
    _paths,
    _private_folder,
    conditions,
    difference,
    enabled,
    fingerprint,
    setting,
    wanted,
)
from frustum.app.runtime import INTERRUPTED_MESSAGE, INTERRUPTED_STATUS

__all__ = ["IDLE_S", "enabled", "fingerprint", "handed", "setting", "start", "status", "stop", "wanted"]

IDLE_S = 600.0
"""Seconds a resident process waits for the next request before it exits (``FRUSTUM_RESIDENT_IDLE_S``)."""

MAX_REQUEST_BYTES = 1 << 20
"""Largest request line a resident process reads (a command line, a folder name and an environment)."""

REQUEST_TIMEOUT_S = 1.0
"""Seconds a connection has to deliver its request line; a silent one is closed then."""

ACCEPT_TIMEOUT_S = 2.0
"""Seconds a command waits for the resident to accept or refuse its request before rendering itself."""

MAX_LOG_BYTES = 1 << 20
"""A resident's log (beside its socket) is emptied at start only when it has grown past this size."""

def _send(connection: socket.socket, message: dict[str, Any]) -> None:
    connection.sendall(json.dumps(message).encode() + b"\n")


def _connect(path: Path, timeout: float | None = None) -> socket.socket | None:
    client = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    client.settimeout(timeout)
    try:
        client.connect(os.fspath(path))
    except OSError:
        client.close()
        return None
    return client


def _decode(line: bytes) -> dict[str, Any] | None:
    """One message: a JSON object, or None (not JSON, nested too deeply, not an object)."""
    try:
        message = json.loads(line)
    except (ValueError, RecursionError, UnicodeDecodeError):
        return None
    return message if isinstance(message, dict) else None


class _Lines:
    """The messages of one connection, a JSON object a line."""

    def __init__(self, connection: socket.socket) -> None:
        self.connection = connection
        self.buffer = b""

    def next(self) -> dict[str, Any] | None:
        """The next message, or None when the other end closed (or sent what is not a message)."""
        while b"\n" not in self.buffer:
            chunk = self.connection.recv(65536)
            if not chunk:
                return None
            self.buffer += chunk
            if len(self.buffer) > MAX_REQUEST_BYTES and b"\n" not in self.buffer:
                return None
        line, _, self.buffer = self.buffer.partition(b"\n")
        return _decode(line)


# --- the client: the ``frustum`` program ---------------------------------------------------------------------


def handed(request: dict[str, Any]) -> int | None:
    """Hand a plain render `request` (``_program.plain_render``) to this installation's resident process, print
    what it prints, and return its exit status; None when none took it (none runs, ``FRUSTUM_RESIDENT=0``, busy,
    another fingerprint or environment): the program renders in its own process then."""
    if not enabled() or setting() == "off":
        return None
    paths = _paths()
    if paths is None or not paths[0].exists():
        return None
    connection = _connect(paths[0], timeout=ACCEPT_TIMEOUT_S)
    if connection is None:
        return None
    message = {"render": {key: [str(path) for path in value] if key == "output" else value
                          for key, value in request.items()},
               "fingerprint": fingerprint(), **conditions()}  # fmt: skip
    with connection:
        lines = _Lines(connection)
        try:
            _send(connection, message)
            reply = lines.next()  # "accepted" or "refused", within ACCEPT_TIMEOUT_S
        except OSError:
            return None
        if reply is None or "accepted" not in reply:
            return None
        connection.settimeout(None)
        while True:
            try:
                reply = lines.next()
            except KeyboardInterrupt:
                return _cancel(connection, lines)
            except OSError:
                reply = None
            if reply is None:
                return None  # the resident stopped before answering (``frustum resident stop``): render here
            if "exit" in reply:
                return int(reply["exit"])
            stream = sys.stderr if reply.get("stream") == "err" else sys.stdout
            stream.write(str(reply.get("text", "")))
            stream.flush()


def _cancel(connection: socket.socket, lines: _Lines) -> int:
    """Ctrl-C while the resident works: it kills the request's child (which removes its partial outputs); wait
    for that (2 s at most)."""
    with contextlib.suppress(OSError, KeyboardInterrupt):
        _send(connection, {"cancel": True})
        connection.settimeout(2.0)
        while (reply := lines.next()) is not None and "exit" not in reply:
            pass
    sys.stderr.write(f"error: {INTERRUPTED_MESSAGE}\n")
    sys.stderr.flush()
    return INTERRUPTED_STATUS


def running() -> dict[str, Any] | None:
    """What this installation's resident process answers to "status", or None when none answers."""
    paths = _paths()
    if paths is None:
        return None
    return _ask(paths[0], {"status": True})


def start(announce: bool = True, wait: bool = False) -> int | None:
    """Start this installation's resident process in the background (its own session, no terminal), replacing one
    of another fingerprint or environment; its pid, or None when none was started (unsupported, unsafe folder,
    or one of this very state already runs). `announce`: say so on stderr. `wait`: return once it answers."""
    if not enabled():
        return None
    paths = _paths(create=True)
    if paths is None:
        return None
    answer = _ask(paths[0], {"status": True})
    if answer is not None and answer.get("fingerprint") == fingerprint() and \
            difference(answer["conditions"], conditions()) is None:  # fmt: skip
        return None
    _write_plan(paths[0].with_suffix(".plan"))
    code = ("import os, sys; del sys.path[0]; sys.path.insert(0, sys.argv[4]); os.chdir(sys.argv[1]); "
            "from frustum.app.resident import serve; serve(sys.argv[2], sys.argv[3], sys.argv[5])")  # fmt: skip
    arguments = [sys.executable, "-c", code, str(paths[0].parent), str(paths[0]), str(paths[1]),
                 str(_package_dir().parent), str(_package_dir())]  # fmt: skip
    log = paths[0].with_suffix(".log")
    with contextlib.suppress(OSError):
        if log.stat().st_size > MAX_LOG_BYTES:
            log.unlink()
    actions = [(os.POSIX_SPAWN_OPEN, 0, os.devnull, os.O_RDONLY, 0),
               (os.POSIX_SPAWN_OPEN, 1, os.devnull, os.O_WRONLY, 0),
               (os.POSIX_SPAWN_OPEN, 2, os.fspath(log), os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)]  # fmt: skip
    try:
        pid = os.posix_spawn(sys.executable, arguments, dict(os.environ), file_actions=actions, setsid=True)
    except OSError:
        return None
    if announce:
        sys.stderr.write(f"started a resident render process (pid {pid}); `frustum resident stop` ends it\n")
        sys.stderr.flush()
    if wait:
        end = time.monotonic() + 120.0
        while time.monotonic() < end:
            answer = _ask(paths[0], {"status": True})
            if answer is not None and answer.get("pid") == pid:
                break
            with contextlib.suppress(ChildProcessError):
                if os.waitpid(pid, os.WNOHANG)[0] == pid:
                    return None
            time.sleep(0.05)
    return pid


def _kernels_in_use() -> list[list[str]]:
    """[module, name, signature] of every frustum kernel this process has compiled or loaded: what a resident
    process started now should load (from the cache) before its first request."""
    if "numba" not in sys.modules:
        return []
    from numba.core.dispatcher import Dispatcher

    found = []
    for module_name, module in list(sys.modules.items()):
        if not module_name.startswith("frustum.raster") or module is None:
            continue
        for name, value in list(vars(module).items()):
            kernel = value if isinstance(value, Dispatcher) else getattr(value, "__dict__", {}).get("kernel")
            if isinstance(kernel, Dispatcher) and getattr(kernel, "__module__", None) == module_name:
                texts = [repr(tuple(signature)) for signature in list(kernel.overloads)]
                # literal arguments mark helpers compiled into their callers (no call from Python loads them)
                found += [[module_name, name, text] for text in texts if "Literal[" not in text]
    return found


def _write_plan(path: Path) -> None:
    """Write ``_kernels_in_use`` to `path` (atomically: two programs may start a resident process at once); no
    plan (a ``frustum resident start``) leaves the previous one."""
    kernels = _kernels_in_use()
    if not kernels:
        return
    with contextlib.suppress(OSError):
        temporary = path.with_name(f"{path.name}.{os.getpid()}")
        temporary.write_text(json.dumps(kernels))
        os.replace(temporary, path)


def status() -> list[dict[str, Any]]:
    """What this user's resident processes answer (pid, requests served, busy, seconds idle, installation), one
    dictionary each; an empty list when none runs."""
    return [reply for reply in _ask_all({"status": True}) if reply]


def stop() -> int:
    """Ask every resident process of this user to exit (a busy one stops its render first); how many did."""
    return sum(1 for reply in _ask_all({"stop": True}) if reply)


def _ask(path: Path, message: dict[str, Any]) -> dict[str, Any] | None:
    connection = _connect(path, timeout=5.0)
    if connection is None:
        return None
    with connection:
        try:
            _send(connection, message)
            return _Lines(connection).next()
        except OSError:
            return None


def _ask_all(message: dict[str, Any]) -> list[dict[str, Any] | None]:
    folder = _private_folder(create=False)
    if folder is None:
        return []
    return [_ask(path, message) for path in sorted(folder.glob("render-*.sock"))]


# --- the resident process -------------------------------------------------------------------------------------


class _Relay(io.TextIOBase):
    """``sys.stdout`` / ``sys.stderr`` of a request's child: text goes to the client."""

    def __init__(self, connection: socket.socket, stream: str) -> None:
        self.connection, self.stream = connection, stream

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        if text:
            with contextlib.suppress(OSError):
                _send(self.connection, {"stream": self.stream, "text": text})
        return len(text)

    @property
    def encoding(self) -> str:
        return "utf-8"


def _request(message: dict[str, Any]) -> dict[str, Any]:
    """A render request as ``_program.plain_render`` makes it, and its conditions, checked field by field (a
    ValueError naming the field otherwise)."""
    fields = message.get("render")
    if not isinstance(fields, dict):
        raise ValueError("a resident render request has no render fields")
    request: dict[str, Any] = {}
    for key in ("scene", "size", "up", "shadows"):
        value = fields.get(key)
        if value is not None and not isinstance(value, str):
            raise ValueError(f"a resident render request has a bad {key!r}")
        request[key] = value
    outputs = fields.get("output") or []
    if not isinstance(request["scene"], str) or not isinstance(outputs, list) or not all(
            isinstance(item, str) for item in outputs):  # fmt: skip
        raise ValueError("a resident render request names no scene or bad outputs")
    request["output"] = [Path(item) for item in outputs]
    env, limits, affinity = message.get("env"), message.get("limits"), message.get("affinity")
    if not isinstance(env, dict) or not all(isinstance(k, str) and isinstance(v, str) for k, v in env.items()):
        raise ValueError("a resident render request has a bad environment")
    if not isinstance(limits, dict) or not all(isinstance(v, list) and len(v) == 2 and all(
            type(x) is int for x in v) for v in limits.values()):  # fmt: skip
        raise ValueError("a resident render request has bad resource limits")
    if not isinstance(affinity, list) or not all(type(cpu) is int for cpu in affinity):
        raise ValueError("a resident render request has a bad CPU affinity")
    for key, kind in (("cwd", str), ("cgroup", str), ("fingerprint", str), ("umask", int), ("nice", int)):
        if type(message.get(key)) is not kind:
            raise ValueError(f"a resident render request has a bad {key!r}")
    if not 0 <= message["umask"] <= 0o777:
        raise ValueError("a resident render request has a bad 'umask'")
    return request


def _same_user(connection: socket.socket) -> bool:
    """Whether the process at the other end of `connection` runs as this process's user (``SO_PEERCRED``)."""
    credentials = connection.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, struct.calcsize("3i"))
    _pid, uid, _gid = struct.unpack("3i", credentials)
    return uid == os.getuid()


class _Child:
    """The forked child doing one request, its client connection and the pipe it reports its exit status on."""

    def __init__(self, pid: int, connection: socket.socket, status_pipe: int) -> None:
        self.pid, self.connection, self.status_pipe = pid, connection, status_pipe
        self.lines = _Lines(connection)

    def signal(self, number: int) -> None:
        """Send `number` to the child's process group (it and what it started, ffmpeg), else to the child."""
        try:
            os.killpg(self.pid, number)
        except OSError:
            with contextlib.suppress(OSError):
                os.kill(self.pid, number)

    def stop(self) -> int:
        """Kill the child (SIGTERM: it removes its partial files; SIGKILL after 2 s) and reap it; its status."""
        self.signal(signal.SIGTERM)
        end = time.monotonic() + 2.0
        while time.monotonic() < end:
            done, code = os.waitpid(self.pid, os.WNOHANG)
            if done:
                return os.waitstatus_to_exitcode(code)
            time.sleep(0.01)
        self.signal(signal.SIGKILL)
        return os.waitstatus_to_exitcode(os.waitpid(self.pid, 0)[1])

    def close(self) -> None:
        with contextlib.suppress(OSError):
            os.close(self.status_pipe)
        self.connection.close()


class _Server:
    def __init__(self, listener: socket.socket, package: str) -> None:
        self.listener = listener
        self.package = package
        self.fingerprint = fingerprint()
        self.conditions = conditions()
        self.requests = 0
        self.started = time.time()
        self.last = time.monotonic()
        self.child: _Child | None = None
        self.pending: dict[socket.socket, tuple[float, bytearray]] = {}

    def idle_s(self) -> float:
        setting = os.environ.get("FRUSTUM_RESIDENT_IDLE_S")
        try:
            return max(0.1, float(setting)) if setting else IDLE_S
        except ValueError:
            return IDLE_S

    def loop(self) -> None:
        import select

        idle = self.idle_s()
        while True:
            now = time.monotonic()
            deadlines = [deadline for deadline, _ in self.pending.values()]
            if self.child is None:
                deadlines.append(self.last + idle)
            timeout = max(0.0, min(deadlines) - now) if deadlines else None
            watched: list[Any] = [self.listener, *self.pending]
            if self.child is not None:
                watched += [self.child.connection, self.child.status_pipe]
            readable, _, _ = select.select(watched, [], [], timeout)
            try:
                if self.serve(readable):
                    return
            except Exception:  # one connection's trouble never ends the process: written to the log
                import traceback

                traceback.print_exc()
                sys.stderr.flush()
            if self.child is None and not self.pending and time.monotonic() >= self.last + idle:
                return

    def serve(self, readable: list[Any]) -> bool:
        """Handle what `readable` holds; True when told to stop."""
        if self.listener in readable:
            with contextlib.suppress(OSError):
                connection, _ = self.listener.accept()
                if _same_user(connection):
                    connection.setblocking(False)
                    self.pending[connection] = (time.monotonic() + REQUEST_TIMEOUT_S, bytearray())
                else:
                    connection.close()
        if self.child is not None and self.child.status_pipe in readable:
            self.finish()
        elif self.child is not None and self.child.connection in readable:
            self.cancel()
        for connection in [c for c in self.pending if c in readable]:
            buffer = self.pending[connection][1]
            try:
                chunk = connection.recv(65536)
            except BlockingIOError:
                continue
            except OSError:
                chunk = b""
            buffer += chunk
            if b"\n" in buffer or not chunk or len(buffer) > MAX_REQUEST_BYTES:
                del self.pending[connection]
                if self.answer(connection, bytes(buffer).partition(b"\n")[0] if b"\n" in buffer else None):
                    return True
        now = time.monotonic()
        for connection in [c for c, (deadline, _) in self.pending.items() if deadline <= now]:
            del self.pending[connection]
            self.reply(connection, {"error": f"no request within {REQUEST_TIMEOUT_S:g} s"})
        return False

    def reply(self, connection: socket.socket, message: dict[str, Any]) -> None:
        with contextlib.suppress(OSError):
            connection.settimeout(REQUEST_TIMEOUT_S)
            _send(connection, message)
        connection.close()

    def answer(self, connection: socket.socket, line: bytes | None) -> bool:
        """Answer one request line (None: cut off or too long); True for "stop"."""
        message = None if line is None else _decode(line)
        if message is None:
            self.reply(connection, {"error": "a request must be one JSON object on one line"})
            return False
        if message.get("stop") is True:
            if self.child is not None:
                self.child.stop()
                self.child.close()
                self.child = None
            self.reply(connection, {"stopped": os.getpid()})
            return True
        if message.get("status") is True:
            self.reply(connection, {"pid": os.getpid(), "requests": self.requests, "package": self.package,
                                    "busy": self.child is not None, "fingerprint": self.fingerprint,
                                    "child": None if self.child is None else self.child.pid,
                                    "idle_s": round(time.monotonic() - self.last, 1), "started": self.started,
                                    "conditions": self.conditions})  # fmt: skip
            return False
        try:
            request = _request(message)
        except ValueError as error:
            self.reply(connection, {"error": str(error)})
            return False
        refused = "busy" if self.child is not None else None
        if refused is None and message["fingerprint"] != self.fingerprint:
            refused = "another state of the installation (an edited source file or an installed package)"
        refused = refused or difference(self.conditions, message)
        if refused is not None:
            self.reply(connection, {"refused": refused})
            return False
        self.fork(connection, request, message)
        return False

    def fork(self, connection: socket.socket, request: dict[str, Any], message: dict[str, Any]) -> None:
        connection.setblocking(True)
        try:  # before the child exists: its output must come after this on the connection
            _send(connection, {"accepted": os.getpid()})
        except OSError:
            connection.close()
            return
        read_end, write_end = os.pipe()
        pid = os.fork()
        if pid == 0:  # the child: one request, then exit (never back into the loop)
            code = 1
            try:
                os.setpgid(0, 0)
                os.close(read_end)
                self.listener.close()
                for other in self.pending:
                    other.close()
                code = _run_request(connection, request, message)
            finally:
                with contextlib.suppress(OSError):
                    os.write(write_end, str(code).encode())
                os._exit(0)
        os.close(write_end)
        with contextlib.suppress(OSError):  # also here: the child may not have run yet when a cancel comes
            os.setpgid(pid, pid)
        self.requests += 1
        self.last = time.monotonic()
        self.child = _Child(pid, connection, read_end)

    def finish(self) -> None:
        """The child reported its status (or died): reap it, tell the client."""
        child = self.child
        assert child is not None
        try:
            text = os.read(child.status_pipe, 64)
        except OSError:
            text = b""
        os.waitpid(child.pid, 0)
        with contextlib.suppress(OSError):
            # a child that died without a status: the client renders the command itself
            if text.strip().isdigit():
                _send(child.connection, {"exit": int(text)})
        child.close()
        self.child = None
        self.last = time.monotonic()

    def cancel(self) -> None:
        """The client of the running request sent "cancel" (Ctrl-C) or went away: kill the work."""
        child = self.child
        assert child is not None
        child.connection.setblocking(False)
        try:
            message = child.lines.next()
        except BlockingIOError:
            return
        except OSError:
            message = None
        finally:
            child.connection.setblocking(True)
        if message is not None and not message.get("cancel"):
            return
        child.stop()
        with contextlib.suppress(OSError):
            _send(child.connection, {"exit": INTERRUPTED_STATUS})
        child.close()
        self.child = None
        self.last = time.monotonic()


def _run_request(connection: socket.socket, request: dict[str, Any], message: dict[str, Any]) -> int:
    """In the request's child: take the caller's environment, umask and folder, run the render as the program
    does, its output to the client; the exit status."""
    import tempfile

    from frustum import _files
    from frustum.app.work import run_render

    signal.signal(signal.SIGTERM, signal.default_int_handler)  # as Ctrl-C: partial files removed, status 130
    os.environ.clear()
    os.environ.update(message["env"])
    tempfile.tempdir = None
    os.umask(message["umask"])
    _files._umask = None
    sys.stdout, sys.stderr = _Relay(connection, "out"), _Relay(connection, "err")
    try:
        os.chdir(message["cwd"])
        return run_render(request)
    except SystemExit as exit_:
        return exit_.code if isinstance(exit_.code, int) else 1
    except BaseException:  # a traceback, as the program prints it
        import traceback

        traceback.print_exc()
        return 1


def _warm_up(plan_path: Path) -> None:
    """Import what a plain render uses and load, from Numba's cache, the kernels of the plan the program that
    started this process left (``_kernels_in_use``), or else those a small mesh render uses (found by rendering
    one in a forked child, which also fills the cache): each request's child then starts warm. Nothing is rendered
    in this process (a kernel call starts threads, and a forked child must not inherit any)."""
    import importlib

    importlib.import_module("frustum.scenefile")
    importlib.import_module("PIL.PngImagePlugin")
    try:
        plan = json.loads(plan_path.read_text())
    except (OSError, ValueError):
        plan = _probe()
    from frustum.raster import _background

    for entry in plan if isinstance(plan, list) else []:
        try:
            module, name, text = entry
            kernel = _background.dispatcher(module, name)
            signature = _background.parse_signature(text)
            if _background._cached(kernel, signature):
                kernel.compile(signature)
        except Exception as error:  # a stale or odd plan entry: the request will load or compile the kernel
            print(f"warm-up: {entry!r}: {error!r}", file=sys.stderr)


def _probe() -> list[Any]:
    """The kernels a small mesh render uses, from a forked child that renders one."""
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:
        try:
            os.close(read_end)
            import frustum

            scene = frustum.Scene(lights=[frustum.DirectionalLight(direction=(-0.3, -0.6, -1.0))])
            sphere = frustum.uv_sphere(1.0, 16, 8)
            scene.add(frustum.Mesh(sphere.vertices.astype("float32"), sphere.faces,
                                   sphere.vertex_normals.astype("float32")))  # fmt: skip
            frustum.render(scene, frustum.Camera.look_at(eye=(0, 1, 4), target=(0, 0, 0), width=64, height=48))
            with os.fdopen(write_end, "w") as pipe:
                pipe.write(json.dumps(_kernels_in_use()))
        finally:
            os._exit(0)
    os.close(write_end)
    with os.fdopen(read_end) as pipe:
        text = pipe.read()
    os.waitpid(pid, 0)
    try:
        return json.loads(text)
    except ValueError:
        return []


def serve(socket_path: str, lock_path: str, package: str) -> None:
    """The resident process (started by ``start``): take over this installation's socket (a resident already on
    it is told to stop), serve requests, exit after ``IDLE_S`` idle seconds or a stop request."""
    import fcntl
    import gc

    if str(_package_dir()) != package:  # another frustum was imported: the fingerprint would not describe it
        return
    lock = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o600)
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        _ask(Path(socket_path), {"stop": True})  # the one of another fingerprint or environment: replaced
        end = time.monotonic() + 10.0
        while True:
            try:
                fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except OSError:
                if time.monotonic() > end:
                    return
                time.sleep(0.05)
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    identity = None
    try:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(socket_path)
        os.umask(0o077)
        listener.bind(socket_path)
        listener.listen(64)
        identity = os.stat(socket_path).st_ino
        _warm_up(Path(socket_path).with_suffix(".plan"))
        from frustum.app.runtime import install_compile_notice

        install_compile_notice()  # the program's words, should a request compile
        gc.collect()
        gc.freeze()
        server = _Server(listener, package)
        signal.signal(signal.SIGTERM, lambda number, frame: sys.exit(0))  # ends the work and tidies up too
        try:
            server.loop()
        finally:
            if server.child is not None:
                server.child.stop()
    finally:
        listener.close()
        with contextlib.suppress(OSError):
            if identity is not None and os.stat(socket_path).st_ino == identity:
                os.unlink(socket_path)
                _tidy(Path(socket_path))
        os.close(lock)


def _tidy(socket_path: Path) -> None:
    """Remove an empty log beside the socket (the lock stays: a resident starting meanwhile may wait on it; the
    plan stays for the next ``frustum resident start``)."""
    log = socket_path.with_suffix(".log")
    with contextlib.suppress(OSError):
        if log.stat().st_size == 0:
            log.unlink()
