"""The resident render process: a plain ``frustum render FILE -o OUT`` handed to a warm process.

A warm one-command render spends most of its time starting up: Python imports NumPy (~0.1 s) and Numba
(~0.2 s), and Numba sets up its compiler's target (~0.15 s) before it can load a single cached kernel — more
than the render itself, and more than F3D's whole process. So the ``frustum`` program (``_program.main``) first
offers a plain render command line to a resident process of the same installation and environment; when one
answers, the program only prints what it says and exits with its status (about 0.1 s in all). When none
answers, the program renders in its own process as before and then starts one in the background
(``start``), for the next command.

How it stays private, exact and out of the way:

- **One per installation and environment.** The socket's name is a fingerprint of the Python executable,
  frustum's source files (name, size, modification time), the site-packages folders (a package installed or
  upgraded changes their time) and the environment variables that change a render (``NUMBA_*``, ``FRUSTUM_*``,
  ``PYTHONPATH``): an edited source file, another package version or another variable means another resident
  process; an old one is never asked again and exits when idle.
- **Private.** The socket lives in a folder only the user can enter (``$XDG_RUNTIME_DIR/frustum``, else
  ``<temporary folder>/frustum-<uid>``; mode 0700, refused when it belongs to someone else or is open to others),
  and a connection is served only when the process at the other end runs as the same user (``SO_PEERCRED``).
- **The same work.** The request is the parsed command line with the client's working folder and umask; the
  resident process runs the function the program runs (``frustum.app.work.render_files``), one request at a time, and
  sends back every line printed and the exit status. Ctrl-C in the client cancels: partial output files are
  removed and no new one is started (``_files.remove_partial_files``), as in the program itself.
- **Gone when idle**: after ``IDLE_S`` seconds without a request (``FRUSTUM_RESIDENT_IDLE_S``), or on
  ``frustum resident stop``. ``FRUSTUM_RESIDENT=0`` turns the whole mechanism off. Linux only (it relies on
  ``SO_PEERCRED``); elsewhere every render runs in its own process.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import socket
import stat
import struct
import sys
import threading
import time
import warnings
from pathlib import Path
from typing import Any

from frustum.app.runtime import INTERRUPTED_MESSAGE, INTERRUPTED_STATUS

__all__ = ["IDLE_S", "enabled", "fingerprint", "handed", "start", "status", "stop"]

IDLE_S = 600.0
"""Seconds a resident process waits for the next request before it exits (``FRUSTUM_RESIDENT_IDLE_S``)."""

MAX_REQUEST_BYTES = 1 << 16
"""Largest request line a resident process reads (a command line and a folder name)."""


_ENV_PREFIXES = ("NUMBA_", "FRUSTUM_")
_ENV_NAMES = ("PYTHONPATH", "PYTHONHASHSEED")
_OWN_ENV = ("FRUSTUM_RESIDENT", "FRUSTUM_RESIDENT_IDLE_S")


def enabled() -> bool:
    """Whether plain renders may go through a resident process: Linux, and ``FRUSTUM_RESIDENT`` not 0/off/no."""
    setting = os.environ.get("FRUSTUM_RESIDENT", "1").strip().lower()
    return sys.platform == "linux" and hasattr(socket, "SO_PEERCRED") and setting not in ("0", "off", "no", "false")


def _package_dir() -> Path:
    """The ``frustum`` package's folder (this module is in its ``app`` package)."""
    return Path(__file__).resolve().parent.parent


class _Digest:
    """Two CRC-32s of what is fed (a name, not a secret: the socket's folder is what keeps it private); zlib
    loads in a fraction of hashlib's time, which counts in a command that takes 0.1 s."""

    def __init__(self) -> None:
        import zlib

        self.crc32, self.low, self.high = zlib.crc32, 0, 0x5EED

    def update(self, data: bytes) -> None:
        self.low, self.high = self.crc32(data, self.low), self.crc32(data[::-1], self.high)

    def hexdigest(self) -> str:
        return f"{self.low:08x}{self.high:08x}"


def fingerprint(package: Path | None = None, environ: dict[str, str] | None = None) -> str:
    """16 hex digits naming the installation and environment a resident process serves (see the module)."""
    package = _package_dir() if package is None else package
    environ = os.environ if environ is None else environ
    digest = _Digest()
    interpreter = os.path.realpath(sys.executable)  # python, python3 and python3.11 of one environment: one process
    digest.update(f"{interpreter}\0{sys.prefix}\0{sys.version}\0{package}\0".encode())
    for folder, folders, files in os.walk(package):
        folders[:] = sorted(name for name in folders if name != "__pycache__")
        for name in sorted(files):
            if name.endswith(".py"):
                info = os.stat(os.path.join(folder, name))
                digest.update(f"{folder}/{name}\0{info.st_size}\0{info.st_mtime_ns}\0".encode())
    for entry in sys.path:  # installing or upgrading a package (NumPy, Numba, Pillow) changes its folder's time
        if os.path.basename(entry) in ("site-packages", "dist-packages") and os.path.isdir(entry):
            digest.update(f"{entry}\0{os.stat(entry).st_mtime_ns}\0".encode())
    for name in sorted(environ):
        if (name.startswith(_ENV_PREFIXES) or name in _ENV_NAMES) and name not in _OWN_ENV:
            value = environ[name]
            if name == "PYTHONPATH":  # relative entries name other folders from another working folder
                value = os.pathsep.join(os.path.abspath(entry) for entry in value.split(os.pathsep) if entry)
            digest.update(f"{name}={value}\0".encode())
    return digest.hexdigest()


def _private_folder(create: bool) -> Path | None:
    """The user's folder for resident sockets, made (mode 0700) when `create`; None when it is missing or unsafe
    (someone else's, a link, or open to other users)."""
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    if runtime and os.path.isabs(runtime):
        base = Path(runtime)
    else:
        import tempfile

        base = Path(tempfile.gettempdir())
    folder = base / ("frustum" if runtime else f"frustum-{os.getuid()}")
    if create:
        with contextlib.suppress(FileExistsError, OSError):
            folder.mkdir(mode=0o700)
    try:
        info = os.lstat(folder)
    except OSError:
        return None
    private = stat.S_ISDIR(info.st_mode) and info.st_uid == os.getuid() and not info.st_mode & 0o077
    return folder if private else None


_FINGERPRINT: list[str] = []


def _paths(create: bool = False) -> tuple[Path, Path] | None:
    """The socket and lock file of this installation's resident process, or None (unsafe folder, long path)."""
    folder = _private_folder(create)
    if folder is None:
        return None
    if not _FINGERPRINT:
        _FINGERPRINT.append(fingerprint())
    name = f"render-{_FINGERPRINT[0]}"
    path = folder / f"{name}.sock"
    if len(os.fsencode(path)) >= 100:  # sockaddr_un holds 108 bytes
        return None
    return path, folder / f"{name}.lock"


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
        try:
            message = json.loads(line)
        except ValueError:
            return None
        return message if isinstance(message, dict) else None


# --- the client: the ``frustum`` program ---------------------------------------------------------------------


def handed(request: dict[str, Any]) -> int | None:
    """Hand a plain render `request` (``_program.plain_render``) to this installation's resident process, print
    what it prints, and return its exit status; None when no resident process took it (run it here then)."""
    if not enabled():
        return None
    paths = _paths()
    if paths is None:
        return None
    connection = _connect(paths[0])
    if connection is None:
        return None
    umask = os.umask(0o022)
    os.umask(umask)
    message = {"render": {key: [str(path) for path in value] if key == "output" else value
                          for key, value in request.items()},
               "cwd": os.getcwd(), "umask": umask}  # fmt: skip
    with connection:
        lines = _Lines(connection)
        try:
            _send(connection, message)
        except OSError:
            return None
        while True:
            try:
                reply = lines.next()
            except KeyboardInterrupt:
                return _cancel(connection, lines)
            except OSError:
                reply = None
            if reply is None:
                return None  # the resident process stopped before answering: the program runs the command itself
            if "exit" in reply:
                return int(reply["exit"])
            stream = sys.stderr if reply.get("stream") == "err" else sys.stdout
            stream.write(str(reply.get("text", "")))
            stream.flush()


def _cancel(connection: socket.socket, lines: _Lines) -> int:
    """Ctrl-C while the resident process works: ask it to drop the partial outputs, wait for it (2 s at most)."""
    with contextlib.suppress(OSError, KeyboardInterrupt):
        _send(connection, {"cancel": True})
        connection.settimeout(2.0)
        while (reply := lines.next()) is not None and "exit" not in reply:
            pass
    sys.stderr.write(f"error: {INTERRUPTED_MESSAGE}\n")
    sys.stderr.flush()
    return INTERRUPTED_STATUS


def start() -> bool:
    """Start this installation's resident process in the background (its own session, no terminal); False when
    it is turned off, the folder is unsafe, or one is already listening."""
    if not enabled():
        return False
    paths = _paths(create=True)
    if paths is None:
        return False
    existing = _connect(paths[0], timeout=1.0)
    if existing is not None:
        existing.close()
        return False
    _write_plan(paths[0].with_suffix(".plan"))
    package_root = str(_package_dir().parent)
    environ = dict(os.environ)
    search = [package_root] + [os.path.abspath(entry) for entry in environ.get("PYTHONPATH", "").split(os.pathsep)
                               if entry]  # fmt: skip
    environ["PYTHONPATH"] = os.pathsep.join(search)
    code = ("import os, sys; os.chdir(sys.argv[1]); del sys.path[0]; "
            "from frustum.app.resident import serve; serve(sys.argv[2], sys.argv[3], sys.argv[4])")  # fmt: skip
    arguments = [sys.executable, "-c", code, str(paths[0].parent), str(paths[0]), str(paths[1]),
                 str(_package_dir())]  # fmt: skip
    log = os.fspath(paths[0].with_suffix(".log"))
    actions = [(os.POSIX_SPAWN_OPEN, 0, os.devnull, os.O_RDONLY, 0),
               (os.POSIX_SPAWN_OPEN, 1, os.devnull, os.O_WRONLY, 0),
               (os.POSIX_SPAWN_OPEN, 2, log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)]  # fmt: skip
    try:
        os.posix_spawn(sys.executable, arguments, environ, file_actions=actions, setsid=True)
    except OSError:
        return False
    return True


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
    """Write ``_kernels_in_use`` to `path` (atomically: two programs may start a resident process at once)."""
    with contextlib.suppress(OSError):
        temporary = path.with_name(f"{path.name}.{os.getpid()}")
        temporary.write_text(json.dumps(_kernels_in_use()))
        os.replace(temporary, path)


def status() -> list[dict[str, Any]]:
    """What every resident process of this user answers (pid, requests served, seconds idle, installation),
    one dictionary each; an empty list when none runs."""
    return [reply for reply in _ask_all({"status": True}) if reply]


def stop() -> int:
    """Ask every resident process of this user to exit; how many did."""
    return sum(1 for reply in _ask_all({"stop": True}) if reply)


def _ask_all(message: dict[str, Any]) -> list[dict[str, Any] | None]:
    folder = _private_folder(create=False)
    if folder is None:
        return []
    replies = []
    for path in sorted(folder.glob("render-*.sock")):
        connection = _connect(path, timeout=5.0)
        if connection is None:
            continue
        with connection:
            try:
                _send(connection, message)
                replies.append(_Lines(connection).next())
            except OSError:
                replies.append(None)
    return replies


# --- the resident process -------------------------------------------------------------------------------------


class _Relay(io.TextIOBase):
    """``sys.stdout`` / ``sys.stderr`` of the resident process while it serves a request: text goes to the client."""

    def __init__(self, connection: socket.socket, stream: str, lock: threading.Lock) -> None:
        self.connection, self.stream, self.lock = connection, stream, lock

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        if text:
            with self.lock, contextlib.suppress(OSError):
                _send(self.connection, {"stream": self.stream, "text": text})
        return len(text)

    @property
    def encoding(self) -> str:
        return "utf-8"


class _Server:
    def __init__(self, listener: socket.socket, package: str) -> None:
        self.listener = listener
        self.package = package
        self.requests = 0
        self.started = time.time()
        self.last = time.monotonic()
        self.home = os.getcwd()

    def idle_s(self) -> float:
        setting = os.environ.get("FRUSTUM_RESIDENT_IDLE_S")
        try:
            return max(0.1, float(setting)) if setting else IDLE_S
        except ValueError:
            return IDLE_S

    def loop(self) -> None:
        idle = self.idle_s()
        while True:
            self.listener.settimeout(max(0.05, idle - (time.monotonic() - self.last)))
            try:
                connection, _ = self.listener.accept()
            except TimeoutError:
                return
            with connection:
                try:
                    if not _same_user(connection):
                        continue
                    connection.settimeout(10.0)
                    lines = _Lines(connection)
                    message = lines.next()
                    connection.settimeout(None)
                    if message is None:
                        continue
                    if message.get("stop"):
                        _send(connection, {"stopped": os.getpid()})
                        return
                    if message.get("status"):
                        _send(connection, {"pid": os.getpid(), "requests": self.requests, "package": self.package,
                                           "idle_s": round(time.monotonic() - self.last, 1),
                                           "started": self.started})  # fmt: skip
                        continue
                    if isinstance(message.get("render"), dict):
                        try:
                            self.render(connection, lines, message)
                        finally:
                            self.last = time.monotonic()  # only renders count as activity, not status calls
                except OSError:
                    pass

    def render(self, connection: socket.socket, lines: _Lines, message: dict[str, Any]) -> None:
        from frustum import _files
        from frustum.app import runtime
        from frustum.app.work import render_files

        self.requests += 1
        lock = threading.Lock()
        outcome: dict[str, Any] = {}
        saved = sys.stdout, sys.stderr
        sys.stdout, sys.stderr = _Relay(connection, "out", lock), _Relay(connection, "err", lock)
        try:
            request = _request(message["render"])
            os.chdir(str(message.get("cwd")))
            os.umask(int(message.get("umask", 0o022)) & 0o777)
            _files._umask = None

            done, wake = socket.socketpair()

            def work() -> None:
                try:
                    outcome["written"] = render_files(Path(request["scene"]), request["output"] or None,
                                                      request["size"], request["up"] or "y",
                                                      request["shadows"])  # fmt: skip
                except BaseException as error:  # reported to the client below, as the program reports it
                    outcome["error"] = error
                finally:
                    wake.send(b"x")

            worker = threading.Thread(target=work, name="frustum-resident-work", daemon=True)
            with done, wake, warnings.catch_warnings():  # warnings shown "once" are shown once per request
                worker.start()
                cancelled = self.watch(connection, lines, worker, done)
                worker.join()
            if cancelled:
                return
            error = outcome.get("error")
            if error is not None and not isinstance(error, runtime.REPORTED):  # a traceback, as the program prints
                import traceback

                sys.stderr.write("".join(traceback.format_exception(error)))
                code = 1
            elif error is not None:
                text, code = runtime.failure(error)
                runtime.say(runtime.error_line(text), sys.stderr)
            else:
                code = 0
                for path in outcome.get("written", []):
                    sys.stdout.write(f"wrote {path}\n")
            with lock:
                _send(connection, {"exit": code})
        except (ValueError, TypeError, OSError) as problem:  # a malformed request or a vanished working folder
            with lock, contextlib.suppress(OSError):
                _send(connection, {"stream": "err", "text": runtime.error_line(runtime.failure(problem)[0]) + "\n"})
                _send(connection, {"exit": 1})
        finally:
            sys.stdout, sys.stderr = saved
            os.chdir(self.home)
            _files.allow_new_files()
            _release_memory()

    def watch(self, connection: socket.socket, lines: _Lines, worker: threading.Thread, done: socket.socket) -> bool:
        """Wait for `worker` (it writes to `done` when it ends); True when the client cancelled (Ctrl-C) or went
        away meanwhile."""
        import select

        from frustum import _files

        connection.settimeout(None)
        while worker.is_alive():
            readable, _, _ = select.select([connection, done], [], [])
            if connection not in readable:
                continue
            try:
                message = lines.next()
            except OSError:
                message = None
            if message is None or message.get("cancel"):
                _files.remove_partial_files()
                with contextlib.suppress(OSError):
                    _send(connection, {"exit": INTERRUPTED_STATUS})
                return True
        return False


def _release_memory() -> None:
    """Between requests: free the work arrays ``render`` keeps between calls and give the freed heap back to the
    system (glibc keeps it otherwise: a resident process serving pictures of changing sizes would grow by the
    largest of them on every thread that drew one)."""
    import ctypes
    import gc

    from frustum.render import release_memory

    gc.collect()  # the request's cycles (frames, meshes) first, so their arrays are free to give back
    release_memory()
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL("libc.so.6").malloc_trim(0)


def _request(fields: Any) -> dict[str, Any]:
    """A render request as ``_program.plain_render`` makes it, checked field by field."""
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
    return request


def _same_user(connection: socket.socket) -> bool:
    """Whether the process at the other end of `connection` runs as this process's user (``SO_PEERCRED``)."""
    credentials = connection.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, struct.calcsize("3i"))
    _pid, uid, _gid = struct.unpack("3i", credentials)
    return uid == os.getuid()


def _warm_up(plan_path: Path) -> None:
    """Import what a plain render uses and load, from Numba's cache, the kernels the program that started this
    process used (its plan, ``_kernels_in_use``): the first request then runs as warm as the next. A kernel the
    cache does not hold is left alone: compiling is the request's business, never the warm-up's."""
    import importlib

    importlib.import_module("frustum.scenefile")
    importlib.import_module("PIL.PngImagePlugin")
    try:
        plan = json.loads(plan_path.read_text())
    except (OSError, ValueError):
        return
    from frustum.raster import _background

    for entry in plan if isinstance(plan, list) else []:
        try:
            module, name, text = entry
            kernel = _background.dispatcher(module, name)
            signature = _background.parse_signature(text)
            if _background._cached(kernel, signature):
                kernel.compile(signature)
        except Exception as error:  # a stale or odd plan entry: the request will load or compile the kernel
            print(f"warm-up: {entry!r}: {error!r}", file=sys.__stderr__)


def serve(socket_path: str, lock_path: str, package: str) -> None:
    """The resident process (started by ``start``): listen on `socket_path` while holding `lock_path`, serve
    requests one at a time, exit after ``IDLE_S`` idle seconds or a stop request."""
    import fcntl
    import gc

    if str(_package_dir()) != package:  # another frustum was imported: the fingerprint would not describe it
        return
    lock = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o600)
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return  # another resident process serves this socket
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
        _Server(listener, package).loop()
    finally:
        listener.close()
        with contextlib.suppress(OSError):
            if identity is not None and os.stat(socket_path).st_ino == identity:
                os.unlink(socket_path)
                _tidy(Path(socket_path))
        os.close(lock)


def _tidy(socket_path: Path) -> None:
    """Remove what a resident process leaves beside its socket: the plan, the lock, an empty log."""
    for suffix in (".plan", ".lock", ".log"):
        path = socket_path.with_suffix(suffix)
        with contextlib.suppress(OSError):
            if suffix != ".log" or path.stat().st_size == 0:
                path.unlink()
