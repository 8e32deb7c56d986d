"""``frustum serve SCENE.toml``: the viewer as a page on localhost, frames over a WebSocket, reloading on save.

Built on Starlette + uvicorn (the ``viewer`` extra): a WebSocket server written on the standard library would
need its own handshake, framing, masking and ping handling, which these two small, well-kept packages already
get right. The page is one HTML document with the same JavaScript as the Jupyter widget; every message to the
page is binary: a 4-byte big-endian header length, the JSON header, then the frame's RGBA bytes (if any).

The scene file is checked every ``POLL_SECONDS``; when its modification time or size changes it is loaded
again. A file that does not exist or does not load leaves the last good scene on the page with the error
(``file:line: key = value problem; valid``) above it; the next good save clears it.
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import json
import socket
import struct
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

from frustum._arrays import describe
from frustum.errors import FrustumError
from frustum.scenefile import SceneFile, load_scene_file
from frustum.viewer.session import ViewerSession

__all__ = ["POLL_SECONDS", "SceneSource", "make_app", "open_socket", "page", "serve"]

POLL_SECONDS = 0.2
"""How often the scene file's modification time is checked."""
_STATIC = Path(__file__).with_name("static")
_PAGE_ADAPTER = """
const viewerElement = document.getElementById("viewer");
const socketUrl = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws";
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

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
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
                scene_file = load_scene_file(self.path)
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


def make_app(source: SceneSource, poll_seconds: float = POLL_SECONDS) -> Any:
    """The Starlette application: ``/`` the page, ``/ws`` the viewer's WebSocket."""
    from starlette.applications import Starlette
    from starlette.responses import HTMLResponse
    from starlette.routing import Route, WebSocketRoute
    from starlette.websockets import WebSocket, WebSocketDisconnect

    async def index(_request: Any) -> HTMLResponse:
        return HTMLResponse(page(f"frustum serve {source.path}"))

    async def viewer_socket(websocket: WebSocket) -> None:
        await websocket.accept()
        inbox: asyncio.Queue[Any] = asyncio.Queue()

        async def read() -> None:
            try:
                while True:
                    message = await websocket.receive()
                    if message["type"] == "websocket.disconnect":
                        break
                    # a binary message is not a viewer message: it reaches the session as one to ignore
                    await inbox.put(message.get("text") or "")
            except (WebSocketDisconnect, RuntimeError):
                pass
            await inbox.put(None)

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
                            session = ViewerSession(loaded.scene, loaded.camera, loaded.options)
                        else:
                            session.set_scene(loaded.scene, loaded.camera, loaded.options)
                        session.error = source.error
                    await websocket.send_bytes(_pack({"type": "error", "message": source.error}))
                    if session is not None and not first:  # the first frame answers the page's hello
                        for header, data in await asyncio.to_thread(session.replies, [{"type": "rest"}]):
                            await websocket.send_bytes(_pack(header, data))
                try:
                    first = await asyncio.wait_for(inbox.get(), poll_seconds)
                except TimeoutError:
                    continue
                texts = [first]
                while not inbox.empty():  # coalesce what arrived while the last frame rendered
                    texts.append(inbox.get_nowait())
                if None in texts:
                    return
                messages = []
                for text in texts:
                    try:
                        messages.append(json.loads(text))
                    except ValueError:
                        messages.append(None)
                if session is None:
                    await websocket.send_bytes(_pack({"type": "ignored"}))
                    continue
                for header, data in await asyncio.to_thread(session.replies, messages):
                    await websocket.send_bytes(_pack(header, data))
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

    return Starlette(routes=[Route("/", index), WebSocketRoute("/ws", viewer_socket)], lifespan=lifespan)


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


def serve(
    path: str | Path,
    host: str = "127.0.0.1",
    port: int = 8000,
    *,
    ready: Callable[[str], None] | None = None,
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
        Called with the page's URL once the socket listens.

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
    source = SceneSource(path)
    sock = open_socket(host, port)
    bound = sock.getsockname()
    shown = f"[{bound[0]}]" if ":" in bound[0] else bound[0]
    source.check()
    config = uvicorn.Config(make_app(source), log_level="warning", ws="auto", lifespan="on")
    server = uvicorn.Server(config)
    if ready is not None:
        ready(f"http://{shown}:{bound[1]}/")
    try:
        server.run(sockets=[sock])
    finally:
        sock.close()
