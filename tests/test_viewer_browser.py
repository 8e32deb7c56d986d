"""``frustum serve`` in a real browser: headless Chromium (Debian's package) driven by Playwright.

One server for the module (starting Chromium and the server costs a few seconds), then: the page loads and
draws, a drag changes the picture, the matrix panel equals the Python camera (both forms), a click shows the
trace, pointer-to-frame latency (measured in the page, printed), scene-file errors appear on the page and go
away, a missing file says why, malformed WebSocket messages are ignored, and a second server on the same port
fails with a clear error.
"""

from __future__ import annotations

import base64
import io
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from frustum.viewer import CameraControl

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]
LATENCY_LIMIT_MS = 500.0
"""A guard against gross regressions (a full-size render per pointer move takes seconds), not a timing target:
the measured latency is printed (about 20–50 ms on a quiet 2-core machine, 130 ms with the machine loaded to
11), and a timed assertion at the target would fail on a busy or slower machine (issue 29: no flaky test)."""

pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="chromium is not installed (.ci/run installs Debian's chromium package)"
)


def _scene_text() -> str:
    text = (ROOT / "examples" / "teapot.toml").read_text()
    return text.replace("size = [480, 360]", "size = [800, 600]")


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    folder = tmp_path_factory.mktemp("serve")
    scene = folder / "scene.toml"
    scene.write_text(_scene_text())
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
    log = folder / "serve.log"  # a file, not a pipe: a full pipe would block the server
    with log.open("w") as stderr:
        process = subprocess.Popen(
            [sys.executable, "-m", "frustum", "serve", str(scene), "--port", "0"],
            stdout=subprocess.PIPE,
            stderr=stderr,
            text=True,
            env=env,
        )
    line = process.stdout.readline()
    match = re.search(r"http://\S+", line)
    if match is None:
        process.kill()
        pytest.fail(f"frustum serve printed no URL: {line!r} {log.read_text()!r}")
    yield {"url": match.group(0), "scene": scene, "process": process, "env": env}
    process.terminate()
    process.wait(timeout=30)
    print(f"\nfrustum serve's log:\n{log.read_text()}")


@pytest.fixture(scope="module")
def browser():
    playwright_sync = pytest.importorskip("playwright.sync_api")
    with playwright_sync.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        yield browser
        browser.close()


@pytest.fixture(scope="module")
def page(server, browser):
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    page.goto(server["url"])
    # the first frame waits for the kernels (compiled once, cached afterwards)
    page.wait_for_function("window.frustumViewer && window.frustumViewer.frames >= 1", timeout=300_000)
    yield page
    page.close()


def _pixels(page) -> np.ndarray:
    """(H, W, 4) uint8 of the canvas, read back as a PNG (a data URL is far quicker than a pixel array)."""
    url = page.evaluate("document.querySelector('.fv-canvas').toDataURL('image/png')")
    with Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))) as image:
        return np.asarray(image.convert("RGBA"))


def _wait_for_rest_frame(page, after: int) -> None:
    page.wait_for_function(
        f"window.frustumViewer.frames > {after} && window.frustumViewer.quality === 'rest'", timeout=120_000
    )


def _panel_matrices(page) -> dict[str, np.ndarray]:
    cells = page.evaluate(
        """() => Array.from(document.querySelectorAll('.fv-matrices table')).map(t => ({
            name: t.dataset.matrix, form: t.dataset.form,
            values: Array.from(t.querySelectorAll('td')).map(td => [Number(td.dataset.value), td.textContent])}))"""
    )
    result = {}
    for table in cells:
        values = np.array([float(v) for v, _ in table["values"]]).reshape(4, 4)
        shown = np.array([float(text) for _, text in table["values"]]).reshape(4, 4)
        # the text shows 5 significant digits of the same numbers
        assert np.allclose(shown, values, rtol=1e-4, atol=1e-9)
        result[table["name"]] = (table["form"], values)
    return result


def test_page_loads_and_draws_the_teapot(page):
    pixels = _pixels(page)
    assert pixels.shape == (600, 800, 4)
    background = np.array([38, 43, 56])  # round(255 * (0.15, 0.17, 0.22))
    covered = np.any(np.abs(pixels[:, :, :3].astype(int) - background) > 8, axis=2).mean()
    assert 0.05 < covered < 0.9
    assert page.locator(".fv-error").is_hidden()


def test_drag_changes_the_picture_and_the_panel_matches_the_camera(page):
    before = _pixels(page)
    azimuth = page.evaluate("window.frustumViewer.state.camera.azimuth")
    frames = page.evaluate("window.frustumViewer.frames")
    page.mouse.move(300, 300)
    page.mouse.down()
    for k in range(1, 11):
        page.mouse.move(300 + 12 * k, 300 + 3 * k)
    page.mouse.up()
    page.wait_for_function(
        f"window.frustumViewer.frames > {frames} && window.frustumViewer.drawn.quality === 'rest' && "
        f"window.frustumViewer.drawn.camera.azimuth !== {azimuth!r}",
        timeout=120_000,
    )
    after = _pixels(page)
    assert np.mean(before != after) > 0.01
    state = page.evaluate("window.frustumViewer.state")
    assert state["camera"]["azimuth"] != pytest.approx(azimuth)
    camera = CameraControl.from_state(state["camera"]).camera()
    panel = _panel_matrices(page)
    expected = {"view": camera.view_matrix, "projection": camera.projection_matrix, "viewport": camera.viewport_matrix}
    for name, matrix in expected.items():
        form, values = panel[name]
        assert form == "column"
        np.testing.assert_allclose(values, matrix, rtol=0, atol=1e-12)
    page.check(".fv-rowform")
    panel = _panel_matrices(page)
    for name, matrix in expected.items():
        form, values = panel[name]
        assert form == "row"
        np.testing.assert_allclose(values, matrix.T, rtol=0, atol=1e-12)
    page.uncheck(".fv-rowform")


def test_click_shows_the_trace_of_the_picked_point(page):
    box = page.locator(".fv-canvas").bounding_box()
    border = page.evaluate("document.querySelector('.fv-canvas').clientLeft")
    page.locator(".fv-canvas").focus()
    page.keyboard.press("0")  # reset: the teapot is at the center
    page.mouse.click(box["x"] + border + 400, box["y"] + border + 300)
    page.wait_for_function("window.frustumViewer.pick !== null", timeout=60_000)
    pick = page.evaluate("window.frustumViewer.pick")
    assert pick["hit"]
    stages = page.locator(".fv-stage")
    assert stages.count() == 9
    assert "region code 000000 (inside)" in page.locator('.fv-stage[data-stage="clipping"]').inner_text()
    window = [
        float(v)
        for v in page.locator('.fv-stage[data-stage="viewport"] .fv-point').get_attribute("data-point").split(",")
    ]
    assert window[0] == pytest.approx(400.5, abs=1e-6) and window[1] == pytest.approx(299.5, abs=1e-6)


def test_pointer_to_frame_latency(page):
    page.locator(".fv-canvas").focus()
    page.keyboard.press("0")
    page.evaluate("window.frustumViewer.latencies.length = 0")
    box = page.locator(".fv-canvas").bounding_box()
    x0, y0 = box["x"] + 200, box["y"] + 300
    page.mouse.move(x0, y0)
    page.mouse.down()
    samples = 40
    for k in range(1, samples + 1):
        page.mouse.move(x0 + 4 * k, y0)
        page.wait_for_function(f"window.frustumViewer.latencies.length >= {k}", timeout=60_000)
    page.mouse.up()
    latencies = page.evaluate("window.frustumViewer.latencies")
    warm = latencies[5:]  # the first frames of a drag warm the half-size buffers
    median = statistics.median(warm)
    print(f"\nviewer latency, pointer event to frame drawn (teapot 800x600, drag frames 400x300): "
          f"median {median:.1f} ms, min {min(warm):.1f} ms, max {max(warm):.1f} ms over {len(warm)} moves")  # fmt: skip
    assert median <= LATENCY_LIMIT_MS


def test_scene_file_errors_appear_on_the_page_and_go_away(page, server):
    scene: Path = server["scene"]
    good = scene.read_text()
    broken = good.replace("fovy_deg = 40", 'fovy_deg = "wide"')
    line = next(k for k, text in enumerate(broken.splitlines(), 1) if "fovy_deg" in text)
    time.sleep(0.05)  # a new modification time even on coarse-grained file systems
    scene.write_text(broken)
    banner = page.locator(".fv-error")
    banner.wait_for(state="visible", timeout=30_000)
    assert f"scene.toml:{line}: camera.fovy_deg" in banner.inner_text()
    scene.unlink()
    page.wait_for_function("document.querySelector('.fv-error').textContent.includes('cannot be read')", timeout=30_000)
    frames = page.evaluate("window.frustumViewer.frames")
    scene.write_text(good)
    banner.wait_for(state="hidden", timeout=30_000)
    _wait_for_rest_frame(page, frames)


def test_malformed_socket_messages_are_ignored(page, server):
    from websockets.sync.client import connect

    url = server["url"].replace("http://", "ws://") + "ws"
    with connect(url, open_timeout=30, max_size=None) as ws:
        replies = []
        for message in (
            "not json",
            json.dumps({"type": "pointer", "action": "down", "x": 1e300, "y": 5, "button": 0}),
            json.dumps({"type": "wheel", "delta": "a lot"}),
            json.dumps({"type": "key", "key": "Delete"}),
            b"\x00\x01 binary",
        ):
            ws.send(message)
            while True:  # skip the greeting (error banner state, state, frame)
                data = ws.recv(timeout=60)
                length = int.from_bytes(data[:4], "big")
                header = json.loads(data[4 : 4 + length])
                if header["type"] == "ignored":
                    replies.append(header)
                    break
        assert len(replies) == 5
    # the server is still serving the page
    assert server["process"].poll() is None


def test_second_server_on_the_same_port_fails_clearly(server):
    port = server["url"].rstrip("/").rsplit(":", 1)[1]
    result = subprocess.run(
        [sys.executable, "-m", "frustum", "serve", str(server["scene"]), "--port", port],
        capture_output=True,
        text=True,
        env=server["env"],
        timeout=120,
    )
    assert result.returncode == 1
    assert f"port = {port} on 127.0.0.1 is already in use" in result.stderr


_FAKE_KERNEL = """async (esm) => {
  const url = URL.createObjectURL(new Blob([esm], { type: "text/javascript" }));
  const module = await import(url);
  window.sent = [];
  const listeners = [];
  const model = {
    send: (m) => window.sent.push(JSON.stringify(m)), on: (name, cb) => listeners.push(cb), off: () => {},
  };
  window.deliver = ([content, data]) => {
    const buffers = data ? [new DataView(Uint8Array.from(atob(data), (c) => c.charCodeAt(0)).buffer)] : [];
    for (const cb of listeners) cb(content, buffers);
  };
  const el = document.getElementById("widget");
  module.default.render({ model, el });
  window.frustumViewer = el.frustumViewer;
}"""


def test_widget_front_end_draws_frames_and_sends_events(browser):
    """The anywidget ESM in a page, with a stand-in for the kernel: Python answers what the page sends."""
    pytest.importorskip("anywidget")
    import frustum

    scene_file = frustum.load_scene_file(ROOT / "examples" / "teapot.toml")
    camera = frustum.Camera(scene_file.camera.frame, scene_file.camera.projection, 160, 120)
    viewer = frustum.Viewer(scene_file.scene, camera, options=scene_file.options, rest_samples=1)
    outbox = []
    viewer.send = lambda content, buffers=None: outbox.append((content, buffers))
    page = browser.new_page()
    page.set_content(f"<style>{viewer._css}</style><div id='widget'></div>")
    page.evaluate(_FAKE_KERNEL, viewer._esm)

    def pump() -> None:  # the kernel's side: handle what the page sent, deliver the replies
        for text in page.evaluate("window.sent.splice(0)"):
            viewer._on_message(viewer, json.loads(text), [])
        for content, buffers in outbox:
            data = base64.b64encode(buffers[0]).decode() if buffers else None
            page.evaluate("(message) => window.deliver(message)", [content, data])
        outbox.clear()

    pump()  # the page said hello: state and a rest frame
    assert page.evaluate("window.frustumViewer.frames") == 1
    panel = _panel_matrices(page)
    np.testing.assert_allclose(panel["view"][1], viewer.camera.view_matrix, rtol=0, atol=1e-12)
    box = page.locator(".fv-canvas").bounding_box()
    border = page.evaluate("document.querySelector('.fv-canvas').clientLeft")
    x0, y0 = box["x"] + border + 40, box["y"] + border + 60
    azimuth = viewer.session.control.azimuth
    page.mouse.move(x0, y0)
    page.mouse.down()
    page.mouse.move(x0 + 30, y0)
    pump()
    page.mouse.up()
    pump()
    assert viewer.session.control.azimuth == pytest.approx(azimuth - 30 * 0.01, abs=1e-9)
    assert page.evaluate("window.frustumViewer.quality") == "rest"
    np.testing.assert_allclose(_panel_matrices(page)["view"][1], viewer.camera.view_matrix, rtol=0, atol=1e-12)
    page.close()


def test_wheel_zooms_and_settles_on_a_rest_frame(page):
    canvas = page.locator(".fv-canvas")
    canvas.focus()
    page.keyboard.press("0")
    page.wait_for_function("window.frustumViewer.state.zoom === 1")
    box = canvas.bounding_box()
    page.mouse.move(box["x"] + 400, box["y"] + 300)
    frames = page.evaluate("window.frustumViewer.frames")
    for _ in range(3):
        page.mouse.wheel(0, -100)  # three notches toward the user
    # the wheel frames are drawn small, then (250 ms after the last turn) the full frame, always last
    page.wait_for_function(
        f"window.frustumViewer.frames > {frames} && window.frustumViewer.drawn.quality === 'rest' && "
        "Math.abs(window.frustumViewer.drawn.zoom - 1.331) < 1e-9",
        timeout=120_000,
    )
    frames = page.evaluate("window.frustumViewer.frames")
    page.wait_for_timeout(500)  # nothing comes after the rest frame
    log = "\n".join(page.evaluate("window.frustumViewer.log.slice(-20)"))
    assert page.evaluate("window.frustumViewer.frames") == frames, log
    assert page.evaluate("window.frustumViewer.drawn.zoom") == pytest.approx(1.1**3, rel=1e-9)


def test_controls_change_the_projection_and_the_panel_follows(page):
    frames = page.evaluate("window.frustumViewer.frames")
    page.select_option('select[data-control="projection"]', "orthographic")
    page.wait_for_function(
        f"window.frustumViewer.frames > {frames} && window.frustumViewer.drawn.quality === 'rest' && "
        "window.frustumViewer.state.controls.projection === 'orthographic'",
        timeout=60_000,
    )
    _, projection = _panel_matrices(page)["projection"]
    np.testing.assert_array_equal(projection[3], [0.0, 0.0, 0.0, 1.0])  # parallel: no division by depth
    frames = page.evaluate("window.frustumViewer.frames")
    page.check('input[data-control="depth_cue"]')
    page.select_option('select[data-control="mode"]', "hidden-line")
    page.wait_for_function(
        f"window.frustumViewer.frames > {frames + 1} && window.frustumViewer.state.controls.mode === 'hidden-line'"
        " && window.frustumViewer.state.controls.depth_cue === true",
        timeout=60_000,
    )
    page.click(".fv-reset")
    page.wait_for_function("window.frustumViewer.state.controls.projection === 'perspective'", timeout=60_000)
    page.select_option('select[data-control="mode"]', "surface")
    page.uncheck('input[data-control="depth_cue"]')


def test_steps_panel_records_the_view_and_steps_through_it(page):
    """The steps panel: pick a visible-surface method, record it on the current view, step with the buttons and
    the slider; the figures are Python's ``Steps.figure`` of that view; a later drag marks the record stale."""
    page.locator(".fv-canvas").focus()
    page.keyboard.press("0")
    page.wait_for_function("window.frustumViewer.state.zoom === 1", timeout=60_000)
    page.click(".fv-steps summary")
    methods = page.eval_on_selector_all(".fv-steps-method option", "options => options.map(o => o.value)")
    assert methods == ["depth-buffer", "scan-line", "warnock", "a-buffer", "ray-casting"]
    page.select_option(".fv-steps-method", "scan-line")
    page.click(".fv-steps-record")
    page.wait_for_function(
        "window.frustumViewer.steps && window.frustumViewer.steps.algorithm === 'scan-line'", timeout=300_000
    )
    record = page.evaluate("window.frustumViewer.steps")
    assert "error" not in record, record.get("error")
    assert record["size"] == [64, 48] and record["camera"] == page.evaluate("window.frustumViewer.state.camera")
    count = len(record["figures"])
    assert count == len(record["titles"]) > 2
    assert page.locator(".fv-steps-nav").is_visible()
    figure = page.locator(".fv-steps-figure svg title")
    assert figure.text_content() == f"Scan-line method: step 1 of {count}: {record['titles'][0]}"
    assert page.locator(".fv-steps-status").get_attribute("data-stale") == "false"
    page.click(".fv-steps-next")
    assert figure.text_content().startswith(f"Scan-line method: step 2 of {count}: ")
    assert page.evaluate("window.frustumViewer.stepIndex") == 1
    page.click(".fv-steps-prev")
    page.click(".fv-steps-prev")  # stays at the first step
    assert page.evaluate("window.frustumViewer.stepIndex") == 0
    page.locator(".fv-steps-slider").fill(str(count - 1))
    assert figure.text_content() == f"Scan-line method: step {count} of {count}: {record['titles'][-1]}"
    assert f"{count} / {count}" in page.locator(".fv-steps-counter").inner_text()
    # the figure drawn is Python's figure of that step (the browser's SVG serialization of it)
    assert page.evaluate("document.querySelector('.fv-steps-figure').dataset.step") == str(count - 1)
    assert page.evaluate("document.querySelector('.fv-steps-figure').innerHTML.length") > 1000
    # the view changes: the record says it belongs to an earlier view
    page.evaluate("window.scrollTo(0, 0)")  # the figure scrolled the page: the whole picture in view again
    box = page.locator(".fv-canvas").bounding_box()
    frames = page.evaluate("window.frustumViewer.frames")
    page.mouse.move(box["x"] + 300, box["y"] + 300)
    page.mouse.down()
    for k in range(1, 6):
        page.mouse.move(box["x"] + 300 + 15 * k, box["y"] + 300)
    page.mouse.up()
    _wait_for_rest_frame(page, frames)
    page.wait_for_function("document.querySelector('.fv-steps-status').dataset.stale === 'true'", timeout=60_000)
    assert "record again" in page.locator(".fv-steps-status").inner_text()
    page.select_option(".fv-steps-method", "warnock")
    page.click(".fv-steps-record")
    page.wait_for_function(
        "window.frustumViewer.steps.algorithm === 'warnock' && "
        "document.querySelector('.fv-steps-status').dataset.stale === 'false'",
        timeout=300_000,
    )
    assert ": step 1 of " in page.locator(".fv-steps-figure svg title").text_content()
    page.keyboard.press("Escape")
    page.locator(".fv-canvas").focus()
    page.keyboard.press("0")
