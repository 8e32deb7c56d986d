"""``frustum serve SCENE.toml``: the viewer as a page on localhost, frames over a WebSocket, reloading on save.

Built on Starlette + uvicorn (the ``viewer`` extra): a WebSocket server written on the standard library would
need its own handshake, framing, masking and ping handling, which these two small, well-kept packages already
get right. The page is one HTML document with the same JavaScript as the Jupyter widget; every message to the
page is binary: a 4-byte big-endian header length, the JSON header, then the frame's RGBA bytes (if any).

The scene file is checked every ``POLL_SECONDS``; when its modification time or size changes it is loaded
again. A file that does not exist or does not load leaves the last good scene on the page with the error
($file:line: key = value problem; valid$) above it; the next good save clears it.

Other web pages cannot drive the viewer (cross-site WebSocket hijacking, DNS rebinding): every page and
WebSocket request must name this server in its ``Host`` header (``127.0.0.1``, ``localhost`` or ``::1`` on a
loopback address; the ``--host`` name and the bound address otherwise; on a wildcard address ``0.0.0.0`` / ``::``
also any IP literal and this machine's name) and, when the browser sends an ``Origin``, that origin must be the
server's own (or one given with ``--allow-origin``); others get ``403 Forbidden`` and a log line. Served on a
non-loopback address the server also wants a random token in the URL (``?token=...``, printed at start, as
Jupyter does) unless ``--no-token`` is given.

Every message is handled inside one guard: a message that is not JSON, nested deeper than
``MAX_MESSAGE_DEPTH`` (checked before parsing), longer than ``MAX_MESSAGE_CHARS``, binary, or that fails in
any other way is ignored with a log line, and the connection stays open (a message over uvicorn's frame limit
of ``MAX_FRAME_BYTES`` is closed by the WebSocket layer itself, code 1009). Renders go one at a time per server
(a queue, first come first served), and each frame's memory is counted against the work budget together with
the frames still on their way to other pages; a frame over it is refused with the message shown on the page.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import ipaddress
import json
import logging
import re
import secrets
import socket
import struct
import threading
import urllib.parse
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from frustum._arrays import describe, escape_control
from frustum.budgets import format_bytes, get_budget
from frustum.errors import FrustumError
from frustum.scenefile import SceneFile, load_scene_file
from frustum.viewer.session import ViewerSession

__all__ = [
    "MAX_FRAME_BYTES",
    "MAX_MESSAGE_CHARS",
    "MAX_MESSAGE_DEPTH",
    "POLL_SECONDS",
    "Access",
    "SceneSource",
    "WorkLedger",
    "choose_token",
    "is_loopback",
    "make_app",
    "open_socket",
    "page",
    "parse_message",
    "serve",
]

POLL_SECONDS = 0.2
"""How often the scene file's modification time is checked."""
MAX_MESSAGE_CHARS = 64 * 1024
"""Longest page message handled (characters); the viewer's messages are under 200."""
MAX_MESSAGE_DEPTH = 8
"""Deepest nesting of arrays and objects in a page message (the viewer's messages have depth 1)."""
MAX_FRAME_BYTES = 1024 * 1024
"""uvicorn's WebSocket frame limit: longer frames are closed by the WebSocket layer (code 1009)."""
_LOG_LINES_PER_CONNECTION = 20
"""Ignored messages logged per connection; later ones are counted, not logged (a flood cannot fill the log)."""

log = logging.getLogger("frustum.serve")
_STATIC = Path(__file__).with_name("static")
_PAGE_ADAPTER = """
const viewerElement = document.getElementById("viewer");
const token = new URLSearchParams(location.search).get("token");
const socketUrl = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws"
  + (token ? "?token=" + encodeURIComponent(token) : "");
const handlers = [];
const waiting = [];
const ws = new WebSocket(socketUrl);
ws.binaryType = "arraybuffer";
const api = mountViewer(viewerElement, {
  send: (m) => { if (ws.readyState === 1) ws.send(JSON.stringify(m)); else waiting.push(m); },
  listen: (h) => handlers.push(h),
});
window.frustumViewer = api;
const banner = viewerElement.querySelector(".fv-error");
ws.onopen = () => {
  ws.send(JSON.stringify({ type: "hello" }));
  for (const m of waiting.splice(0)) ws.send(JSON.stringify(m));
};
ws.onmessage = (event) => {
  const length = new DataView(event.data).getUint32(0);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(event.data, 4, length)));
  const bytes = event.data.byteLength > 4 + length ? new Uint8Array(event.data, 4 + length) : null;
  for (const h of handlers) h(header, bytes);
};
ws.onclose = () => { banner.hidden = false; banner.textContent = "connection to frustum serve closed"; };
"""


def page(title: str) -> str:
    """The HTML page: the viewer's CSS and JavaScript inline, and the WebSocket adapter."""
    css = (_STATIC / "viewer.css").read_text(encoding="utf-8")
    script = (_STATIC / "viewer.js").read_text(encoding="utf-8") + _PAGE_ADAPTER
    safe_title = title.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>{safe_title} · frustum</title>
<style>body {{ margin: 12px; }} h1 {{ font: 600 15px system-ui, sans-serif; margin: 0 0 8px; }}
{css}</style></head>
<body><h1>{safe_title}</h1><div id="viewer"></div>
<script type="module">
{script}
</script></body></html>
"""


class SceneSource:
    """The scene file and its last good load: ``check()`` reloads it when it changes on disk.

    ``scene_file`` is the last good ``SceneFile`` (None until one loads), ``error`` the message of the last
    failed load (None when the latest version loaded), ``version`` counts the changes seen.
    """

    def __init__(self, path: str | Path, *, up: str = "y") -> None:
        self.path = Path(path)
        self.up = up  # a mesh file's up axis (load_scene_file)
        self.scene_file: SceneFile | None = None
        self.error: str | None = None
        self.version = 0
        self._stamp: tuple[int, int] | str | None = "unread"
        self._lock = threading.Lock()

    def _current_stamp(self) -> tuple[int, int] | None:
        try:
            status = self.path.stat()
        except OSError:
            return None
        return (status.st_mtime_ns, status.st_size)

    def check(self) -> bool:
        """Load the file again if its modification time or size changed; True if anything changed."""
        with self._lock:
            stamp = self._current_stamp()
            if stamp == self._stamp:
                return False
            self._stamp = stamp
            try:
                scene_file = load_scene_file(self.path, up=self.up)
                if scene_file.camera is None:
                    raise FrustumError(
                        f"{self.path}: has [[cameras]] (several views); frustum serve shows one [camera]"
                    )
            except FrustumError as error:
                self.error = str(error)
            else:
                self.scene_file, self.error = scene_file, None
            self.version += 1
            return True


def _pack(header: dict[str, Any], data: bytes | None = None) -> bytes:
    encoded = json.dumps(header).encode("utf-8")
    return struct.pack(">I", len(encoded)) + encoded + (data or b"")


# --- who may connect ------------------------------------------------------------------------------------------

_HOST_HEADER = re.compile(r"^[A-Za-z0-9._\-]+(:[0-9]{1,5})?$|^\[[0-9A-Fa-f:.]+\](:[0-9]{1,5})?$")


def _name(text: str) -> str:
    """A host name or IP literal in one spelling: lower case, no brackets, no trailing dot."""
    return text.strip().strip("[]").rstrip(".").lower()


def _ip(name: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address | None:
    try:
        return ipaddress.ip_address(name)
    except ValueError:
        return None


def is_loopback(host: str) -> bool:
    """True for ``localhost`` and loopback addresses (127.0.0.0/8, ::1): only this machine can connect."""
    name = _name(host)
    address = _ip(name)
    return name == "localhost" or (address is not None and address.is_loopback)


class Access:
    """Who may use a server listening on `host` (bound to address `bound`, port `port`).

    ``refusal(scope)`` returns why an ASGI request is refused, or None: its ``Host`` header must name this
    server (see the module docstring), its ``Origin`` (when sent) must be the server's own or one of
    `allow_origins` (``"*"`` allows every origin), and with a `token` its URL must carry ``?token=<token>``.
    """

    def __init__(
        self, host: str, port: int, bound: str | None = None, *, allow_origins: Any = (), token: str | None = None
    ) -> None:
        self.port = port
        self.token = token
        self.origins = frozenset(str(origin).strip().rstrip("/").lower() for origin in allow_origins)
        bound_name = _name(bound if bound is not None else host)
        self.names = {_name(host), bound_name}
        address = _ip(bound_name)
        self.any_ip = address is not None and address.is_unspecified
        if is_loopback(host) or is_loopback(bound_name) or self.any_ip:
            self.names |= {"localhost", "127.0.0.1", "::1"}
        if self.any_ip:
            with contextlib.suppress(OSError):
                self.names |= {_name(socket.gethostname()), _name(socket.getfqdn())}

    def _named(self, name: str) -> bool:
        return name in self.names or (self.any_ip and _ip(name) is not None)

    def host_allowed(self, value: str | None) -> bool:
        """True if a ``Host`` header value names this server (its port, when given, must be the server's)."""
        if value is None or not _HOST_HEADER.match(value):
            return False
        parts = urllib.parse.urlsplit("//" + value)
        try:
            port = parts.port
        except ValueError:
            return False
        return parts.hostname is not None and (port is None or port == self.port) and self._named(_name(parts.hostname))

    def origin_allowed(self, origin: str) -> bool:
        """True if a page of `origin` may use the server: its own origin, or one given with ``--allow-origin``."""
        normal = origin.strip().rstrip("/").lower()
        if "*" in self.origins or normal in self.origins:
            return True
        parts = urllib.parse.urlsplit(normal)
        if parts.scheme not in ("http", "https") or parts.hostname is None or parts.path or parts.query:
            return False
        try:
            port = parts.port
        except ValueError:
            return False
        port = port if port is not None else (443 if parts.scheme == "https" else 80)
        return port == self.port and self._named(_name(parts.hostname))

    def refusal(self, scope: Mapping[str, Any]) -> str | None:
        """Why the ASGI request `scope` is refused, or None if it may proceed."""
        headers: dict[str, list[str]] = {}
        for key, value in scope.get("headers", ()):
            headers.setdefault(key.decode("latin-1").lower(), []).append(value.decode("latin-1"))
        hosts = headers.get("host", [])
        if len(hosts) != 1 or not self.host_allowed(hosts[0]):
            shown = hosts[0] if len(hosts) == 1 else hosts
            return f"Host {shown!r} is not this server's address ({', '.join(sorted(self.names))}, port {self.port})"
        origins = headers.get("origin", [])
        if len(origins) > 1 or (origins and not self.origin_allowed(origins[0])):
            return (
                f"Origin {origins[0] if len(origins) == 1 else origins!r} is not this server's page; a page that "
                "embeds the viewer on purpose is allowed with --allow-origin"
            )
        if self.token is not None:
            query = urllib.parse.parse_qs(scope.get("query_string", b"").decode("latin-1"))
            given = query.get("token", [""])[-1]
            if not secrets.compare_digest(given.encode("utf-8"), self.token.encode("utf-8")):
                return "the URL's token is missing or wrong; open the URL frustum serve printed (with ?token=...)"
        return None


class _Guarded:
    """ASGI middleware: requests that ``Access`` refuses get 403 Forbidden (WebSocket: refused handshake)."""

    def __init__(self, app: Any, access: Access) -> None:
        self.app, self.access = app, access
        self.state = app.state

    async def __call__(self, scope: Any, receive: Any, send: Any) -> None:
        kind = scope["type"]
        if kind in ("http", "websocket"):
            problem = self.access.refusal(scope)
            if problem is not None:
                client = scope.get("client") or ("?", 0)
                what = "WebSocket" if kind == "websocket" else scope.get("method", "request")
                log.warning("refused %s %r from %s:%s (403 Forbidden): %s", what, scope.get("path"), client[0],
                            client[1], problem)  # fmt: skip
                if kind == "http":
                    body = f"403 Forbidden: {problem}\n".encode()
                    await send({"type": "http.response.start", "status": 403,
                                "headers": [(b"content-type", b"text/plain; charset=utf-8"),
                                            (b"content-length", str(len(body)).encode())]})  # fmt: skip
                    await send({"type": "http.response.body", "body": body})
                else:
                    await receive()  # websocket.connect; a close before accept is a 403 answer to the handshake
                    await send({"type": "websocket.close", "code": 1008})
                return
        await self.app(scope, receive, send)


# --- messages and work --------------------------------------------------------------------------------------

_JSON_SPECIAL = re.compile(r'[\[\]{}"\\]')


def parse_message(text: Any) -> tuple[Any, str | None]:
    """(message, None) for a page message's text, or (None, why it is ignored).

    The nesting depth is counted before ``json.loads`` runs (brackets inside strings do not count), so a
    message such as ``"[" * 100000`` never reaches the recursive parser.
    """
    if not isinstance(text, str):
        return None, "a binary message (the viewer sends JSON text)"
    if len(text) > MAX_MESSAGE_CHARS:
        return None, f"a message of {len(text)} characters, over the {MAX_MESSAGE_CHARS} allowed"
    depth, in_string, skip = 0, False, -1
    for match in _JSON_SPECIAL.finditer(text):
        at = match.start()
        if at < skip:
            continue
        char = text[at]
        if in_string:
            if char == "\\":
                skip = at + 2
            elif char == '"':
                in_string = False
        elif char == '"':
            in_string = True
        elif char in "[{":
            depth += 1
            if depth > MAX_MESSAGE_DEPTH:
                return None, f"a message nested deeper than {MAX_MESSAGE_DEPTH} levels"
        elif char in "]}":
            depth -= 1
    try:
        return json.loads(text), None
    except (ValueError, RecursionError) as error:
        return None, f"not JSON ({str(error)[:80]})"


class WorkLedger:
    """The server's work arrays across every page, counted against the work budget (``frustum.budgets``).

    ``held`` counts frames on their way to pages (``hold``, also counted in ``sending``) and the frame being
    rendered (``admit``);
    ``retained`` what the renderer keeps for its next call (``frustum.release_memory`` frees it). ``admit``
    refuses a frame whose estimate does not fit beside them, after freeing the retained arrays if that helps.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.held = 0
        self.sending = 0
        self.retained = 0

    @contextlib.contextmanager
    def admit(self, nbytes: int, cause: str) -> Any:
        """Reserve `nbytes` for a render while the block runs; FrustumError if the budget cannot hold them."""
        limit = get_budget().bytes
        with self._lock:
            if self.held + self.retained + nbytes > limit and self.retained:
                from frustum.render import release_memory

                release_memory()
                self.retained = 0
            if self.held + nbytes > limit:
                others = f" beside {format_bytes(self.held)} of frames on their way to pages" if self.held else ""
                raise FrustumError(
                    f"frustum serve: {cause} needs about {format_bytes(nbytes)}{others}, over the memory budget of "
                    f"{format_bytes(limit)}; make the scene file's size smaller, or raise the budget with "
                    "--max-bytes or FRUSTUM_MAX_BYTES"
                )
            self.held += nbytes
        try:
            yield
        finally:
            with self._lock:
                self.held -= nbytes
                self.retained = max(self.retained, nbytes)

    @contextlib.contextmanager
    def hold(self, nbytes: int) -> Any:
        """Count `nbytes` (a message being sent) while the block runs."""
        with self._lock:
            self.held += nbytes
            self.sending += nbytes
        try:
            yield
        finally:
            with self._lock:
                self.held -= nbytes
                self.sending -= nbytes


class _Connection:
    """One page's log of ignored messages: the first ``_LOG_LINES_PER_CONNECTION`` are logged, then counted."""

    def __init__(self, client: Any) -> None:
        self.client = f"{client[0]}:{client[1]}" if client else "?"
        self.ignored = 0

    def ignore(self, why: str) -> None:
        self.ignored += 1
        if self.ignored <= _LOG_LINES_PER_CONNECTION:
            log.warning("ignored a message from %s: %s", self.client, escape_control(why))
            if self.ignored == _LOG_LINES_PER_CONNECTION:
                log.warning("further ignored messages from %s are not logged", self.client)


def make_app(
    source: SceneSource,
    poll_seconds: float = POLL_SECONDS,
    *,
    access: Access | None = None,
    rest_samples: int = 4,
) -> Any:
    """The Starlette application: ``/`` the page, ``/ws`` the viewer's WebSocket; with `access`, requests it
    refuses get 403. One render at a time across its pages, counted in one ``WorkLedger``."""
    from starlette.applications import Starlette
    from starlette.responses import HTMLResponse
    from starlette.routing import Route, WebSocketRoute
    from starlette.websockets import WebSocket, WebSocketDisconnect

    render_turn = asyncio.Lock()  # one render at a time per server; asyncio.Lock wakes waiters in order
    ledger = WorkLedger()

    async def index(_request: Any) -> HTMLResponse:
        return HTMLResponse(page(f"frustum serve {source.path}"))

    async def viewer_socket(websocket: WebSocket) -> None:
        await websocket.accept()
        inbox: asyncio.Queue[Any] = asyncio.Queue()
        connection = _Connection(websocket.scope.get("client"))

        async def read() -> None:
            try:
                while True:
                    message = await websocket.receive()
                    if message["type"] == "websocket.disconnect":
                        break
                    text = message.get("text")
                    await inbox.put(text if text is not None else message.get("bytes", b""))
            except (WebSocketDisconnect, RuntimeError):
                pass
            await inbox.put(None)

        async def send_all(replies: list[tuple[dict[str, Any], bytes | None]]) -> None:
            for header, data in replies:
                packed = _pack(header, data)
                with ledger.hold(len(packed) + len(data or b"")):
                    await websocket.send_bytes(packed)

        def answer(session: ViewerSession, messages: list[Any]) -> list[tuple[dict[str, Any], bytes | None]]:
            """session.replies inside the guard: whatever fails is logged and answered as ignored."""
            try:
                return session.replies(messages)
            except Exception as error:  # the guard: no message may end the connection
                connection.ignore(f"{type(error).__name__}: {error}"[:200])
                return [({"type": "ignored"}, None)]

        reader = asyncio.create_task(read())
        session: ViewerSession | None = None
        seen = -1
        try:
            while True:
                if source.version != seen:  # a new load (or a new error): show it, keep the view
                    first, seen = seen == -1, source.version
                    loaded = source.scene_file
                    if loaded is not None:
                        if session is None:
                            session = ViewerSession(loaded.scene, loaded.camera, loaded.options,
                                                    rest_samples=rest_samples)  # fmt: skip
                            session.work = ledger.admit
                        else:
                            session.set_scene(loaded.scene, loaded.camera, loaded.options)
                        session.error = source.error
                    await websocket.send_bytes(_pack({"type": "error", "message": source.error}))
                    if session is not None and not first:  # the first frame answers the page's hello
                        async with render_turn:
                            replies = await asyncio.to_thread(answer, session, [{"type": "rest"}])
                        await send_all(replies)
                try:
                    text = await asyncio.wait_for(inbox.get(), poll_seconds)
                except TimeoutError:
                    continue
                # wait for the render turn, then take what arrived meanwhile too; send after the turn, so a page
                # that reads slowly holds its frame (counted in the ledger), not the other pages' renders
                async with render_turn:
                    texts = [text]
                    while not inbox.empty():  # coalesce what arrived while other frames rendered
                        texts.append(inbox.get_nowait())
                    if None in texts:
                        return
                    messages = []
                    for item in texts:
                        message, problem = parse_message(item)
                        if problem is not None:
                            connection.ignore(problem)
                        messages.append(message)
                    if session is None:
                        replies = [({"type": "ignored"}, None)]
                    else:
                        replies = await asyncio.to_thread(answer, session, messages)
                await send_all(replies)
        except (WebSocketDisconnect, RuntimeError):
            return
        finally:
            reader.cancel()

    async def watch() -> None:
        while True:
            await asyncio.to_thread(source.check)
            await asyncio.sleep(poll_seconds)

    @contextlib.asynccontextmanager
    async def lifespan(_app: Any) -> Any:
        task = asyncio.create_task(watch())
        try:
            yield
        finally:
            task.cancel()

    app = Starlette(routes=[Route("/", index), WebSocketRoute("/ws", viewer_socket)], lifespan=lifespan)
    app.state.ledger = ledger
    return app if access is None else _Guarded(app, access)


def open_socket(host: str, port: int) -> socket.socket:
    """A listening TCP socket on (host, port) (port 0: any free port); FrustumError if the port is taken."""
    where = "serve"
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise FrustumError(f"{where}: port = {describe(port)} is not a TCP port; expected an integer in [0, 65535]")
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as error:
        raise FrustumError(f"{where}: host = {host!r} cannot be resolved ({error}); use 127.0.0.1 or 0.0.0.0") from None
    family, kind, protocol, _, address = infos[0]
    sock = socket.socket(family, kind, protocol)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind(address)
        sock.listen(64)
    except OSError as error:
        sock.close()
        if error.errno == errno.EADDRINUSE:
            raise FrustumError(
                f"{where}: port = {port} on {host} is already in use; choose another with --port (0 picks a free "
                "one) or stop the program listening there"
            ) from None
        raise FrustumError(
            f"{where}: cannot listen on {host}:{port} ({error.strerror}); check --host and --port"
        ) from None
    sock.setblocking(False)
    return sock


def choose_token(host: str, token: str | bool | None = None) -> str | None:
    """The URL token a server on `host` wants: `token` itself if a string; a random one if True, or if None and
    `host` is not a loopback address (as Jupyter does); none if False (``--no-token``)."""
    if isinstance(token, str):
        if not token or not token.isprintable() or len(token) > 256:
            raise FrustumError(f"serve: token = {token!r} is not a usable token; give 1 to 256 printable characters")
        return token
    if token is True or (token is None and not is_loopback(host)):
        return secrets.token_urlsafe(24)
    return None


def serve(
    path: str | Path,
    host: str = "127.0.0.1",
    port: int = 8000,
    *,
    ready: Callable[[str], None] | None = None,
    allow_origins: Any = (),
    token: str | bool | None = None,
    started: Callable[[Any], None] | None = None,
    up: str = "y",
) -> None:
    """Serve the viewer of scene file `path` at http://host:port/ until interrupted.

    Parameters
    ----------
    path : str or Path
        A TOML scene file with one ``[camera]``; it may be missing or broken at first (the page says why).
    host : str
        Interface to listen on: 127.0.0.1 (this machine only) by default; 0.0.0.0 serves every interface.
    port : int
        TCP port; 0 picks a free one.
    ready : callable, optional
        Called with the page's URL (with ``?token=...`` when one is wanted) once the socket listens.
    allow_origins : iterable of str
        Origins (``"https://example.org:8443"``) of pages allowed to embed the viewer besides its own;
        ``"*"`` allows every page (only for a deliberate setup: any web page could then drive the viewer).
    token : str, bool or None
        The token the URL must carry: None (default) a random one on a non-loopback `host`, none on loopback;
        True always a random one; False none (``--no-token``); a string that token.
    started : callable, optional
        Called with the ``uvicorn.Server`` before it runs (its ``should_exit = True`` stops it).
    up : "y" or "z"
        A mesh file's up axis (``load_scene_file``; glTF is always y-up).

    Raises
    ------
    FrustumError
        If the ``viewer`` extra is missing, or the port is in use or cannot be bound.
    """
    try:
        import starlette  # noqa: F401
        import uvicorn
    except ImportError as error:
        raise FrustumError(
            f"serve: needs the viewer extra ({error.name} is missing); pip install 'frustum[viewer]'"
        ) from None
    if isinstance(allow_origins, str):
        allow_origins = (allow_origins,)
    choose_token(host, token if isinstance(token, str) else False)  # a bad token string fails before binding
    source = SceneSource(path, up=up)
    sock = open_socket(host, port)
    bound = sock.getsockname()
    url_token = choose_token(bound[0] if is_loopback(bound[0]) else host, token)  # e.g. a name for 127.0.1.1
    if not logging.getLogger().hasHandlers() and not log.handlers:  # refusals and ignored messages on stderr
        handler = logging.StreamHandler()
        handler.setFormatter(logging.Formatter("frustum serve: %(message)s"))
        log.addHandler(handler)
    shown = f"[{bound[0]}]" if ":" in bound[0] else bound[0]
    access = Access(host, bound[1], bound[0], allow_origins=tuple(allow_origins), token=url_token)
    source.check()
    config = uvicorn.Config(make_app(source, access=access), log_level="warning", ws="auto", lifespan="on",
                            ws_max_size=MAX_FRAME_BYTES, proxy_headers=False)  # fmt: skip
    server = uvicorn.Server(config)
    if started is not None:
        started(server)
    if ready is not None:
        query = "" if url_token is None else "?token=" + urllib.parse.quote(url_token, safe="")
        ready(f"http://{shown}:{bound[1]}/{query}")
    try:
        server.run(sockets=[sock])
    finally:
        sock.close()
