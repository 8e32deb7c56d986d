"""``Viewer``: the interactive view as a Jupyter widget (anywidget), with a static picture where widgets can't run.

Built on ``anywidget`` rather than ``jupyter_rfb``: the viewer needs a side panel (matrices, the picked point's
trace) and controls next to the picture, which is a small page of its own; anywidget runs that page, the same
JavaScript ``frustum serve`` uses, in JupyterLab, Notebook 7, VS Code and Colab, and carries the frames as binary
message buffers. ``jupyter_rfb`` (built on anywidget) would give a remote frame buffer only, with its own event
schema and throttling, and the panel would still have to be written beside it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import anywidget

from frustum.camera import Camera
from frustum.frame import Frame
from frustum.scene import Scene
from frustum.viewer.session import ViewerSession

__all__ = ["Viewer"]

_STATIC = Path(__file__).with_name("static")
_ADAPTER = """
export default {
  render({ model, el }) {
    const handlers = [];
    const api = mountViewer(el, { send: (m) => model.send(m), listen: (h) => handlers.push(h) });
    const onMessage = (content, buffers) => {
      const view = buffers && buffers.length ? buffers[0] : null;
      const bytes = view ? new Uint8Array(view.buffer, view.byteOffset, view.byteLength) : null;
      for (const h of handlers) h(content, bytes);
    };
    model.on("msg:custom", onMessage);
    model.send({ type: "hello" });
    el.frustumViewer = api;
    return () => model.off("msg:custom", onMessage);
  },
};
"""


class Viewer(anywidget.AnyWidget):
    """Interactive view of `scene` in Jupyter: orbit, pan, zoom, presets, controls and the pipeline panel.

    Left drag orbits, right (or shift) drag pans, the wheel zooms, a click picks the surface point and shows
    its ``frustum.trace``; keys f, t, r, i (or 1, 7, 3, 5) look from the front, top, right and isometric
    presets and 0 resets (``frustum.viewer.interaction`` gives the formulas). The steps panel below records a
    visible-surface method on the current view (``ViewerSession.steps``) and steps through its figures. While
    dragging, frames are rendered at half size with one sample; at rest, at full size with `rest_samples`. Without
    a widget front end (a static notebook render, GitHub, nbconvert) the output shows the rest frame as a PNG.

    Parameters
    ----------
    scene : Scene
    camera : Camera, optional
        Starting camera; its size is the picture's size. Default: a perspective view fitting the scene, 800×600.
    options : dict, optional
        Further ``render`` keywords (e.g. a scene file's ``SceneFile.options``).
    rest_samples : int
        Supersampling of the frame at rest (1, 4, 9, ...).

    Raises
    ------
    FrustumError
        If `scene` is not a Scene or `camera` is not a Camera.
    """

    _esm = (_STATIC / "viewer.js").read_text(encoding="utf-8") + _ADAPTER
    _css = (_STATIC / "viewer.css").read_text(encoding="utf-8")

    def __init__(
        self,
        scene: Scene,
        camera: Camera | None = None,
        *,
        options: dict[str, Any] | None = None,
        rest_samples: int = 4,
    ) -> None:
        session = ViewerSession(scene, camera, options, rest_samples=rest_samples)
        super().__init__()
        self.session = session
        self.on_msg(self._on_message)

    @property
    def camera(self) -> Camera:
        """The camera of the current view (full size)."""
        return self.session.control.camera()

    def frame(self) -> Frame:
        """The current view rendered at rest quality."""
        return self.session.render("rest")

    def _on_message(self, _widget: Any, content: Any, _buffers: Any) -> None:
        for header, data in self.session.replies(content):
            self.send(header, buffers=None if data is None else [data])

    def _repr_mimebundle_(self, **kwargs: Any) -> Any:
        bundle = super()._repr_mimebundle_(**kwargs)
        data, metadata = bundle if isinstance(bundle, tuple) else (bundle, None)
        data = dict(data or {})
        data["image/png"] = self.frame()._repr_png_()
        return data if metadata is None else (data, metadata)
