"""A lesson in a real JupyterLab: the ``Steps`` slider and the ``frustum.Viewer`` widget meet JupyterLab's own
front end (the anywidget and ipywidgets lab extensions), not a stand-in kernel.

The test starts ``jupyter lab`` on 127.0.0.1 (a free port, a random token, a temporary root holding a copy of the
clipping lesson with a ``frustum.Viewer`` cell added), opens the notebook in headless Chromium (Playwright), runs
every cell through JupyterLab's "run all" command and checks, on the page:

- every cell ran without an error output;
- a ``Steps`` slider (the lesson's Cohen–Sutherland record) shows its first figure, and moving the slider or
  pressing "next" shows another step's figure (the slider's script ran: the output is trusted);
- the ``Viewer`` widget draws a frame through the kernel's comm; a drag on it orbits the camera and changes the
  picture; its steps panel records a method of the current view and steps through it.

Every wait is on the page's state (never a fixed sleep), with generous limits: a cold run compiles the render
kernels in the notebook's kernel, and the machine may be loaded. The server is shut down through its API (which
stops the kernel) and any process left of it is ended.
"""

from __future__ import annotations

import base64
import contextlib
import io
import json
import os
import secrets
import shutil
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

ROOT = Path(__file__).resolve().parents[1]
LESSON = ROOT / "docs" / "lessons" / "clipping.ipynb"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--no-first-run"]  # fmt: skip
START_TIMEOUT_S = 240
"""Until the server answers /api/status (a cold start on a loaded 2-core machine takes tens of seconds)."""
RUN_TIMEOUT_MS = 900_000
"""Until every cell has run: a cold cache compiles the render kernels in the kernel (minutes when loaded)."""
PAGE_TIMEOUT_MS = 300_000
"""Until JupyterLab's page, the notebook and its kernel are ready; and for each frame or record asked for."""

VIEWER_CELL = """\
import frustum

scene, camera = steps.visible_surfaces.default_scene()
viewer = frustum.Viewer(scene, frustum.Camera(camera.frame, camera.projection, 320, 240), rest_samples=1)
viewer"""

pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="chromium is not installed (.ci/run installs Debian's chromium package)"
)


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _notebook(folder: Path) -> Path:
    """The clipping lesson, outputs clean, with a cell that shows a ``frustum.Viewer`` added at the end."""
    notebook = json.loads(LESSON.read_text(encoding="utf-8"))
    cell = {
        "cell_type": "code",
        "execution_count": None,
        "id": "frustum-viewer",
        "metadata": {},
        "outputs": [],
        "source": VIEWER_CELL,
    }
    notebook["cells"].append(cell)
    path = folder / "lesson.ipynb"
    path.write_text(json.dumps(notebook, indent=1), encoding="utf-8")
    return path


def _settings(folder: Path) -> Path:
    """User settings: every cell stays in the page (no windowing), no news fetched from the internet."""
    settings = folder / "settings"
    for name, values in {
        "@jupyterlab/notebook-extension/tracker.jupyterlab-settings": {"windowingMode": "none"},
        "@jupyterlab/apputils-extension/notification.jupyterlab-settings": {"fetchNews": "false",
                                                                           "checkForUpdates": False},
    }.items():  # fmt: skip
        path = settings / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(values), encoding="utf-8")
    return settings


def _status(port: int, token: str) -> int | None:
    request = urllib.request.Request(f"http://127.0.0.1:{port}/api/status", headers={"Authorization": f"token {token}"})
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return response.status
    except (urllib.error.URLError, OSError):
        return None


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    # test dependencies (the test extra): a missing one fails the test, it does not skip it
    import anywidget  # noqa: F401
    import jupyterlab  # noqa: F401
    import jupyterlab_widgets  # noqa: F401
    import psutil

    folder = tmp_path_factory.mktemp("lab")
    root = folder / "root"
    root.mkdir()
    notebook = _notebook(root)
    port, token = _free_port(), secrets.token_hex(16)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
    # the user's Jupyter folders stay untouched (the venv's kernel spec and lab extensions are found in sys.prefix)
    folders = {"JUPYTER_CONFIG_DIR": "config", "JUPYTER_DATA_DIR": "data", "JUPYTER_RUNTIME_DIR": "runtime",
               "IPYTHONDIR": "ipython", "JUPYTERLAB_WORKSPACES_DIR": "workspaces"}  # fmt: skip
    for name, sub in folders.items():
        env[name] = str(folder / sub)
    env["JUPYTERLAB_SETTINGS_DIR"] = str(_settings(folder))
    env.pop("JUPYTER_TOKEN", None)
    log = folder / "lab.log"  # a file, not a pipe: a full pipe would block the server
    command = [sys.executable, "-m", "jupyterlab", "--no-browser", "--ServerApp.ip=127.0.0.1",
               f"--ServerApp.port={port}", "--ServerApp.port_retries=0", f"--IdentityProvider.token={token}",
               f"--ServerApp.root_dir={root}", "--LabApp.expose_app_in_browser=True"]  # fmt: skip
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        command.append("--allow-root")  # CI's containers run as root; the server still listens on 127.0.0.1 only
    with log.open("w") as output:
        process = subprocess.Popen(command, stdout=output, stderr=subprocess.STDOUT, env=env, cwd=root)
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while _status(port, token) != 200:
            if process.poll() is not None or time.monotonic() > deadline:
                pytest.fail(f"jupyter lab did not start (exit {process.poll()}):\n{log.read_text()[-4000:]}")
            time.sleep(0.5)
        yield {"url": f"http://127.0.0.1:{port}/lab/tree/{notebook.name}?token={token}", "log": log}
    finally:
        family = []
        with contextlib.suppress(psutil.Error):
            family = psutil.Process(process.pid).children(recursive=True)  # the kernel among them
        request = urllib.request.Request(f"http://127.0.0.1:{port}/api/shutdown", method="POST",
                                         headers={"Authorization": f"token {token}"})  # fmt: skip
        with contextlib.suppress(urllib.error.URLError, OSError):
            urllib.request.urlopen(request, timeout=30).close()  # stops the kernels, then the server
        try:
            process.wait(timeout=60)
        except subprocess.TimeoutExpired:
            process.terminate()
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(timeout=30)
        for child in family:
            with contextlib.suppress(psutil.Error):
                child.kill()
        print(f"\njupyter lab's log (end):\n{log.read_text()[-3000:]}")


@pytest.fixture(scope="module")
def notebook_page(lab):
    playwright_sync = pytest.importorskip("playwright.sync_api")
    with playwright_sync.sync_playwright() as playwright:
        try:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        except playwright_sync.Error as error:
            pytest.skip(f"Chromium ({CHROMIUM}) could not be launched: {str(error).splitlines()[0]}")
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        page.set_default_timeout(PAGE_TIMEOUT_MS)
        page.goto(lab["url"])
        # JupyterLab's page, the notebook's panel and its kernel (started for the notebook's python3 kernelspec)
        page.wait_for_function(
            """() => {
              const app = window.jupyterapp, panel = app && app.shell.currentWidget;
              const kernel = panel && panel.sessionContext && panel.sessionContext.session
                && panel.sessionContext.session.kernel;
              return !!(kernel && kernel.connectionStatus === 'connected' && kernel.status === 'idle'
                && panel.content && panel.content.widgets.length > 0);
            }""",
            timeout=PAGE_TIMEOUT_MS,
        )
        plugins = page.evaluate(
            "(ids) => ids.filter((id) => !window.jupyterapp.hasPlugin(id))",
            ["@jupyter-widgets/jupyterlab-manager:plugin", "anywidget:plugin"],
        )
        assert not plugins, f"JupyterLab has no widget front end {plugins} (jupyterlab_widgets, anywidget)"
        page.evaluate(
            """() => {
              window.runAll = { done: false, result: null, error: null };
              window.jupyterapp.commands.execute('notebook:run-all-cells').then(
                (result) => { window.runAll.result = result; window.runAll.done = true; },
                (error) => { window.runAll.error = String(error); window.runAll.done = true; });
            }"""
        )
        page.wait_for_function("window.runAll.done", timeout=RUN_TIMEOUT_MS, polling=1000)
        yield page
        page.close()
        browser.close()


def _canvas_pixels(page, canvas) -> np.ndarray:
    url = canvas.evaluate("c => c.toDataURL('image/png')")
    with Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1]))) as image:
        return np.asarray(image.convert("RGBA"))


def test_every_cell_runs_without_an_error(notebook_page):
    run = notebook_page.evaluate("window.runAll")
    assert run["error"] is None and run["result"] is not False, run
    outputs = notebook_page.evaluate(
        """() => window.jupyterapp.shell.currentWidget.content.model.sharedModel.cells.map(
                 (cell) => ({ type: cell.cell_type, count: cell.execution_count || null,
                              outputs: cell.cell_type === 'code' ? cell.getOutputs() : [] }))"""
    )
    code = [cell for cell in outputs if cell["type"] == "code"]
    assert len(code) == 4 and all(cell["count"] for cell in code)
    errors = [output for cell in code for output in cell["outputs"] if output["output_type"] == "error"]
    assert not errors, errors
    printed = "".join("".join(output.get("text", "")) for cell in code for output in cell["outputs"]
                      if output.get("name") == "stdout")  # fmt: skip
    assert "True True" in printed  # the lesson's check: Liang–Barsky's u1, u2 equal clip_line's


def test_steps_slider_renders_and_responds(notebook_page):
    page = notebook_page
    steps = page.locator(".jp-OutputArea-output .frustum-steps").first
    steps.scroll_into_view_if_needed()
    count = steps.locator(".frustum-step").count()
    assert count > 2

    def shown() -> list:
        return steps.evaluate(
            """(root) => [Array.from(root.querySelectorAll('.frustum-step'))
                            .filter((d) => d.style.display !== 'none').map((d) => d.dataset.step),
                          root.querySelector('.counter').textContent]"""
        )

    assert shown() == [["0"], f"1 / {count}"]
    first = steps.locator('.frustum-step[data-step="0"] svg title').text_content()
    assert first.startswith("Cohen") and "step 1 of" in first
    steps.locator(".slider").fill(str(count - 1))  # the slider moved: its input event shows that step
    page.wait_for_function(
        "(root) => root.querySelector('.counter').textContent.startsWith(root.querySelectorAll('.frustum-step')"
        ".length + ' / ')",
        arg=steps.element_handle(),
    )
    assert shown() == [[str(count - 1)], f"{count} / {count}"]
    last = steps.locator(f'.frustum-step[data-step="{count - 1}"]')
    assert last.is_visible() and not steps.locator('.frustum-step[data-step="0"]').is_visible()
    assert f"step {count} of {count}" in last.locator("svg title").text_content()
    steps.locator(".prev").click()
    assert shown() == [[str(count - 2)], f"{count - 1} / {count}"]


def test_viewer_widget_renders_and_a_drag_changes_its_picture(notebook_page):
    page = notebook_page
    widget = page.locator(".jp-OutputArea-output .frustum-viewer").first
    widget.scroll_into_view_if_needed()
    canvas = widget.locator(".fv-canvas")
    # the widget's first frame came through the comm: a rest frame of the 320 x 240 camera
    page.wait_for_function(
        "(el) => el.frustumViewer && el.frustumViewer.frames >= 1 && el.frustumViewer.quality === 'rest'",
        arg=widget.element_handle(),
    )
    assert canvas.evaluate("(c) => [c.width, c.height]") == [320, 240]
    before = _canvas_pixels(page, canvas)
    background = before[0, 0, :3].astype(int)
    covered = np.any(np.abs(before[:, :, :3].astype(int) - background) > 8, axis=2).mean()
    assert 0.05 < covered < 0.95  # the scene is drawn
    state = widget.evaluate("(el) => el.frustumViewer.state")
    azimuth, frames = state["camera"]["azimuth"], widget.evaluate("(el) => el.frustumViewer.frames")
    canvas.evaluate("(c) => c.scrollIntoView({ block: 'center' })")  # the whole picture in the notebook's view
    box = canvas.bounding_box()
    x0, y0 = box["x"] + 100, box["y"] + 120
    page.mouse.move(x0, y0)
    page.mouse.down()
    for k in range(1, 9):
        page.mouse.move(x0 + 10 * k, y0 + 2 * k)
    page.mouse.up()
    page.wait_for_function(
        f"(el) => el.frustumViewer.frames > {frames} && el.frustumViewer.drawn.quality === 'rest' && "
        f"el.frustumViewer.drawn.camera.azimuth !== {azimuth!r}",
        arg=widget.element_handle(),
    )
    after = _canvas_pixels(page, canvas)
    assert np.mean(np.any(before != after, axis=2)) > 0.01
    assert widget.evaluate("(el) => el.frustumViewer.state.camera.azimuth") < azimuth  # dragged right: orbit left
    assert widget.locator(".fv-matrices table").count() == 3


def test_viewer_widget_steps_panel_records_through_the_comm(notebook_page):
    widget = notebook_page.locator(".jp-OutputArea-output .frustum-viewer").first
    widget.locator(".fv-steps summary").click()
    widget.locator(".fv-steps-method").select_option("depth-buffer")
    widget.locator(".fv-steps-record").click()
    notebook_page.wait_for_function(
        "(el) => el.frustumViewer.steps && el.frustumViewer.steps.algorithm === 'depth-buffer'",
        arg=widget.element_handle(),
    )
    record = widget.evaluate("(el) => el.frustumViewer.steps")
    assert "error" not in record, record.get("error")
    assert record["size"] == [64, 48] and len(record["figures"]) == 4  # empty buffers, then three surfaces
    assert record["camera"] == widget.evaluate("(el) => el.frustumViewer.state.camera")
    title = widget.locator(".fv-steps-figure svg title")
    assert "step 1 of 4" in title.text_content()
    widget.locator(".fv-steps-next").click()
    assert "step 2 of 4: Surface 1: back slab" in title.text_content()
