"""``frustum serve`` against other web pages and hostile messages: a real uvicorn server on 127.0.0.1 and a real
WebSocket client (issue 38: Host/Origin checks, the URL token, one guard around every message, merged picks,
one render at a time and the work budget across pages)."""

from __future__ import annotations

import contextlib
import http.client
import json
import logging
import socket
import sys
import threading
import time
from pathlib import Path

import pytest

import frustum
from frustum.viewer import ViewerSession
from frustum.viewer.server import (
    MAX_MESSAGE_CHARS,
    MAX_MESSAGE_DEPTH,
    Access,
    WorkLedger,
    choose_token,
    parse_message,
    serve,
)

pytest.importorskip("uvicorn")
websockets_client = pytest.importorskip("websockets.sync.client")
from websockets.exceptions import InvalidStatus  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _scene(folder: Path) -> Path:
    text = (ROOT / "examples" / "teapot.toml").read_text()
    assert "size = [480, 360]" in text
    scene = folder / "scene.toml"
    scene.write_text(text.replace("size = [480, 360]", "size = [160, 120]"))
    return scene


@contextlib.contextmanager
def _server(folder: Path, **options):
    """serve() in a thread on 127.0.0.1, port 0: yields (port, url, uvicorn server, work ledger)."""
    got: dict = {}
    ready = threading.Event()

    def on_ready(url: str) -> None:
        got["url"] = url
        ready.set()

    thread = threading.Thread(
        target=serve,
        args=(_scene(folder), "127.0.0.1", 0),
        kwargs=dict(ready=on_ready, started=lambda server: got.setdefault("server", server), **options),
        daemon=True,
    )
    thread.start()
    assert ready.wait(30), "serve did not start"
    server = got["server"]
    deadline = time.monotonic() + 30
    while not server.started and time.monotonic() < deadline:
        time.sleep(0.02)
    port = int(got["url"].split(":")[2].split("/")[0])
    try:
        yield port, got["url"], server, server.config.app.state.ledger
    finally:
        server.should_exit = True
        thread.join(30)


@pytest.fixture(scope="module")
def plain(tmp_path_factory):
    with _server(tmp_path_factory.mktemp("serve")) as running:
        yield running


def _get(port: int, host: str, path: str = "/", origin: str | None = None) -> tuple[int, str]:
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    headers = {"Host": host}
    if origin is not None:
        headers["Origin"] = origin
    connection.request("GET", path, headers=headers)
    response = connection.getresponse()
    body = response.read().decode("utf-8", "replace")
    connection.close()
    return response.status, body


def _connect(port: int, host: str | None = None, origin: str | None = None, query: str = "", **options):
    """A WebSocket to 127.0.0.1:port whose handshake names `host` (a DNS-rebinding page's Host) and `origin`."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    if options.pop("small_buffer", False):  # set before connecting: the TCP window stays small
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.settimeout(30)
    sock.connect(("127.0.0.1", port))
    name = host or f"127.0.0.1:{port}"
    try:
        return websockets_client.connect(
            f"ws://{name}/ws{query}", sock=sock, origin=origin, open_timeout=30, max_size=None, **options
        )
    except BaseException:
        sock.close()
        raise


def _header(data: bytes) -> dict:
    length = int.from_bytes(data[:4], "big")
    return json.loads(data[4 : 4 + length])


def _until(ws, kind: str, timeout: float = 120.0) -> list[dict]:
    """Headers received up to and including the first of type `kind`."""
    seen = []
    deadline = time.monotonic() + timeout
    while True:
        header = _header(ws.recv(timeout=max(0.1, deadline - time.monotonic())))
        seen.append(header)
        if header["type"] == kind:
            return seen


def _greeted(ws) -> None:
    ws.send(json.dumps({"type": "hello"}))
    _until(ws, "frame")


# --- 1. other web pages ---------------------------------------------------------------------------------------


def test_page_request_naming_another_host_is_refused(plain, caplog):
    port = plain[0]
    status, body = _get(port, f"evil.example:{port}")
    assert status == 403 and "is not this server's address" in body
    assert any("refused GET '/'" in r.getMessage() and "evil.example" in r.getMessage() for r in caplog.records)
    for host in (f"127.0.0.1:{port}", f"localhost:{port}", "localhost"):
        status, body = _get(port, host)
        assert status == 200 and "mountViewer" in body, host
    for host in (f"127.0.0.1:{port + 1}", f"127.0.0.1.evil.example:{port}", f"user@127.0.0.1:{port}", ""):
        assert _get(port, host)[0] == 403, host
    assert _get(port, f"127.0.0.1:{port}", origin="http://evil.example")[0] == 403


def test_websocket_from_another_origin_or_host_is_refused(plain, caplog):
    port = plain[0]
    with pytest.raises(InvalidStatus) as refused:
        _connect(port, host=f"evil.example:{port}", origin="http://evil.example")
    assert refused.value.response.status_code == 403
    with pytest.raises(InvalidStatus) as refused:  # a page elsewhere connecting to ws://127.0.0.1:port/ws
        _connect(port, origin="http://evil.example")
    assert refused.value.response.status_code == 403
    with pytest.raises(InvalidStatus):
        _connect(port, origin="null")
    messages = [r.getMessage() for r in caplog.records]
    assert any("refused WebSocket '/ws'" in m and "Origin 'http://evil.example'" in m for m in messages)
    # the server's own page (Origin of its own address) and tools that send no Origin are served
    for origin in (f"http://127.0.0.1:{port}", f"http://localhost:{port}", None):
        with _connect(port, origin=origin) as ws:
            _greeted(ws)


def test_token_and_allowed_origin(tmp_path, caplog):
    with _server(tmp_path, token="s3cret", allow_origins=("http://embed.example:9000",)) as (port, url, _, _):
        assert url.endswith("/?token=s3cret")
        assert _get(port, f"127.0.0.1:{port}")[0] == 403
        assert _get(port, f"127.0.0.1:{port}", "/?token=wrong")[0] == 403
        status, body = _get(port, f"127.0.0.1:{port}", "/?token=s3cret")
        assert status == 200 and 'get("token")' in body  # the page passes its token on to the WebSocket
        with pytest.raises(InvalidStatus):
            _connect(port)
        with _connect(port, query="?token=s3cret", origin="http://embed.example:9000") as ws:
            _greeted(ws)
        with pytest.raises(InvalidStatus):
            _connect(port, query="?token=s3cret", origin="http://embed.example:9001")
    assert any("token is missing or wrong" in r.getMessage() for r in caplog.records)


def test_token_is_random_off_loopback_unless_refused():
    first, second = choose_token("0.0.0.0"), choose_token("0.0.0.0")
    assert first and second and first != second and len(first) >= 32
    assert choose_token("192.168.1.20") is not None and choose_token("::") is not None
    assert choose_token("0.0.0.0", False) is None  # --no-token
    assert choose_token("127.0.0.1") is None and choose_token("localhost") is None and choose_token("::1") is None
    assert choose_token("127.0.0.1", True) is not None


def test_access_rules_for_a_wildcard_and_a_named_address():
    everywhere = Access("0.0.0.0", 8765, "0.0.0.0")
    assert everywhere.host_allowed("192.168.1.20:8765") and everywhere.host_allowed("[fe80::1]:8765")
    assert everywhere.host_allowed("localhost:8765") and not everywhere.host_allowed("evil.example:8765")
    assert everywhere.origin_allowed("http://192.168.1.20:8765") and not everywhere.origin_allowed(
        "http://evil.example"
    )
    named = Access("viewer.lan", 80, "192.168.1.20", allow_origins=["https://notebook.lan/"])
    assert named.host_allowed("viewer.lan") and named.host_allowed("192.168.1.20")
    assert not named.host_allowed("10.0.0.1") and not named.host_allowed("localhost")
    assert named.origin_allowed("http://viewer.lan") and named.origin_allowed("https://NOTEBOOK.lan")
    assert not named.origin_allowed("https://notebook.lan.evil.example")


def test_cli_passes_allow_origin_and_no_token(monkeypatch, tmp_path):
    import frustum.viewer.server as server_module
    from frustum.app.cli import main

    calls = []
    monkeypatch.setattr(server_module, "serve", lambda *args, **kwargs: calls.append((args, kwargs)))
    main(["serve", str(tmp_path / "s.toml"), "--host", "0.0.0.0", "--no-token", "--allow-origin", "http://a:1",
          "--allow-origin", "http://b:2"])  # fmt: skip
    main(["serve", str(tmp_path / "s.toml"), "--host", "0.0.0.0"])
    assert calls[0][1]["token"] is False and calls[0][1]["allow_origins"] == ("http://a:1", "http://b:2")
    assert calls[1][1]["token"] is None and calls[1][1]["allow_origins"] == ()


# --- 2. one guard around every message -------------------------------------------------------------------------


def test_parse_message_limits_depth_before_parsing():
    assert parse_message('{"type": "rest"}') == ({"type": "rest"}, None)
    assert parse_message('{"text": "[[[[[[[[[[[[\\"[["}')[1] is None  # brackets in strings do not nest
    nested = "[" * (MAX_MESSAGE_DEPTH + 1) + "]" * (MAX_MESSAGE_DEPTH + 1)
    assert "nested deeper" in parse_message(nested)[1]
    assert "nested deeper" in parse_message("[" * 60_000)[1]
    assert "over the" in parse_message("[" * 100_000)[1]
    assert "binary" in parse_message(b"\x00")[1]
    assert "not JSON" in parse_message("{'type': 1}")[1]
    assert "not JSON" in parse_message("1" * 5000)[1]  # an integer over Python's digit limit


def test_bad_messages_are_ignored_and_the_connection_stays_open(plain, caplog):
    port = plain[0]
    caplog.set_level(logging.WARNING)
    with _connect(port) as ws:
        _greeted(ws)
        bad = [
            json.dumps({"type": "control", "name": {}, "value": 1}),
            json.dumps({"type": "control", "name": ["shading"], "value": "flat"}),
            json.dumps({"type": {}, "x": []}),
            json.dumps({"type": "key", "key": {"k": 1}}),
            json.dumps({"type": "pick", "x": {}, "y": None}),
            json.dumps({"type": "pointer", "action": ["down"], "x": 1, "y": 1}),
            "[" * 100_000,
            "[" * 60_000,
            '{"a":' * 5000,
            "x" * (MAX_MESSAGE_CHARS + 1),
            "not json",
            b"\x00\x01 binary",
            "[]",
            "null",
        ]
        for message in bad:
            ws.send(message)
            assert _until(ws, "ignored", 60)[-1] == {"type": "ignored"}
        ws.send(json.dumps({"type": "rest", "seq": 7}))
        frame = _until(ws, "frame")[-1]
        assert frame["seq"] == 7 and frame["quality"] == "rest"
    logged = " | ".join(r.getMessage() for r in caplog.records if r.name == "frustum.serve")
    for phrase in ("nested deeper than", "over the 65536 allowed", "not JSON", "binary message"):
        assert phrase in logged, phrase


def test_handler_failure_is_ignored_not_raised(monkeypatch, caplog):
    scene_file = frustum.load_scene_file(ROOT / "examples" / "teapot.toml")
    session = ViewerSession(scene_file.scene, scene_file.camera, rest_samples=1)

    def broken(*args):
        raise TypeError("unhashable type: 'dict'")

    monkeypatch.setattr(session.control, "wheel", broken)
    assert session.replies({"type": "wheel", "delta": 100}) == [({"type": "ignored"}, None)]
    assert "TypeError" in caplog.text


def test_picks_are_merged_latest_wins(plain, monkeypatch):
    port = plain[0]
    original = ViewerSession.pick
    picked = []

    def slow_pick(self, x, y):  # a pick costs a full-size render; 50 ms makes that visible on any machine
        picked.append((x, y))
        time.sleep(0.05)
        return original(self, x, y)

    monkeypatch.setattr(ViewerSession, "pick", slow_pick)
    with _connect(port) as ws:
        _greeted(ws)
        started = time.perf_counter()
        for k in range(1000):
            ws.send(json.dumps({"type": "pick", "x": 20 + k % 100, "y": 30}))
        ws.send(json.dumps({"type": "pick", "x": 80, "y": 61}))
        picks = []
        while True:
            header = _header(ws.recv(timeout=120))
            if header["type"] == "pick":
                picks.append(header)
                if header["pixel"] == [80, 61]:
                    break
        elapsed = time.perf_counter() - started
    print(f"\n1001 picks: {len(picks)} answered in {elapsed:.2f} s")
    assert len(picks) == len(picked) <= 20 and elapsed < 30  # unmerged: 1001 renders, 50 s at least
    assert picks[-1]["hit"]


# --- 3/4. one render at a time, the budget across pages ---------------------------------------------------------


def test_one_render_at_a_time_across_pages(plain, monkeypatch):
    render_module = sys.modules["frustum.render"]

    port = plain[0]
    original = render_module.render
    running, most = [0], [0]
    lock = threading.Lock()

    def counted(*args, **kwargs):
        with lock:
            running[0] += 1
            most[0] = max(most[0], running[0])
        try:
            time.sleep(0.02)
            return original(*args, **kwargs)
        finally:
            with lock:
                running[0] -= 1

    monkeypatch.setattr(render_module, "render", counted)
    frames = []

    def client() -> None:
        with _connect(port) as ws:
            _greeted(ws)
            for seq in range(5):
                ws.send(json.dumps({"type": "rest", "seq": seq}))
                frames.append(_until(ws, "frame")[-1])

    threads = [threading.Thread(target=client) for _ in range(3)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(120)
    assert len(frames) == 15 and most[0] == 1


def test_frame_over_the_budget_is_refused_with_a_message(plain):
    port = plain[0]
    with _connect(port) as ws:
        _greeted(ws)
        with frustum.budget(bytes=1_000_000):  # a 160 x 120 frame x 4 samples needs about 2.0 MB
            ws.send(json.dumps({"type": "rest"}))
            error = _until(ws, "error")[-1]
        assert "frustum serve: a rest frame of 160 x 120 pixels x samples = 4 needs about" in error["message"]
        assert "over the memory budget of 976.6 KiB" in error["message"]
        ws.send(json.dumps({"type": "rest"}))
        assert _until(ws, "frame")[-1]["quality"] == "rest"  # within the budget again: served


def test_frames_held_for_a_slow_page_count_against_another_pages_frame(plain):
    from frustum.viewer.session import frame_bytes

    port, _, _, ledger = plain
    # reads nothing after its greeting: its client stops reading at 4 queued frames; a small TCP window and no
    # compression fill the server's buffers in a few hundred frames
    options = dict(max_queue=4, ping_interval=None, close_timeout=0.5, small_buffer=True, compression=None)
    with _connect(port, **options) as slow:
        _greeted(slow)
        deadline, waiting = time.monotonic() + 60, 0
        while waiting < 5 and time.monotonic() < deadline:  # flood until the server's send waits for the page
            for _ in range(20):
                slow.send(json.dumps({"type": "rest"}))
            time.sleep(0.05)
            waiting = waiting + 1 if ledger.sending > 0 else 0
        assert waiting == 5, "the slow page's frame never waited"
        held = ledger.held
        with _connect(port) as ws:
            _greeted(ws)
            # room for one frame, not for one beside what the slow page holds
            with frustum.budget(bytes=frame_bytes(160, 120, 4) + held // 2):
                ws.send(json.dumps({"type": "rest"}))
                error = _until(ws, "error")[-1]
            assert "of frames on their way to pages" in error["message"]
        slow.close_socket()


def test_work_ledger_counts_held_frames_and_frees_retained_arrays(monkeypatch):
    render_module = sys.modules["frustum.render"]

    released = []
    monkeypatch.setattr(render_module, "release_memory", lambda: released.append(1) or 0)
    ledger = WorkLedger()
    with frustum.budget(bytes=1000):
        with ledger.admit(600, "a frame"):
            assert ledger.held == 600
        assert ledger.held == 0 and ledger.retained == 600
        with ledger.admit(600, "a frame"):  # 600 retained + 600 > 1000: the retained arrays are freed first
            pass
        assert released == [1]
        refused = pytest.raises(frustum.FrustumError, match=r"beside 500 B of frames on their way")
        with ledger.hold(500), refused, ledger.admit(600, "a frame"):
            pass
        assert ledger.held == 0


# --- the steps panel: the same socket, the same access rules -------------------------------------------------


def test_steps_panel_is_served_over_the_guarded_socket_only(tmp_path):
    with _server(tmp_path, token="s3cret") as (port, _, _, _):
        with pytest.raises(InvalidStatus) as refused:  # no token, or another page: no socket, so no steps
            _connect(port)
        assert refused.value.response.status_code == 403
        with pytest.raises(InvalidStatus):
            _connect(port, query="?token=s3cret", origin="http://evil.example")
        with _connect(port, query="?token=s3cret") as ws:
            _greeted(ws)
            ws.send(json.dumps({"type": "steps", "algorithm": "depth-buffer"}))
            answer = _until(ws, "steps")[-1]
            assert answer["algorithm"] == "depth-buffer" and answer["size"] == [64, 48]
            assert len(answer["figures"]) == len(answer["titles"]) == 2  # empty buffers, then the teapot
            assert all(figure.startswith("<svg") for figure in answer["figures"])
            with frustum.budget(bytes=20_000):  # the record of 64 x 48 does not fit: said, not raised
                ws.send(json.dumps({"type": "steps", "algorithm": "depth-buffer"}))
                refused_record = _until(ws, "steps")[-1]
            assert "figures" not in refused_record and "budget" in refused_record["error"]
            ws.send(json.dumps({"type": "steps", "algorithm": "../etc/passwd"}))  # outside: refused
            assert _until(ws, "ignored")[-1] == {"type": "ignored"}
