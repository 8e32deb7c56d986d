"""Interactive viewing: the ``Viewer`` Jupyter widget and ``frustum serve`` ("at scale", docs/architecture.md).

``interaction`` (the camera-interaction model) and ``session`` (one view's state and message protocol) are plain
Python; ``widget`` needs the ``viewer`` extra's anywidget and ``server`` its Starlette and uvicorn, imported only
when used.
"""

from __future__ import annotations

from typing import Any

from frustum.viewer.interaction import (
    KEYS,
    ORBIT_RADIANS_PER_PIXEL,
    PRESETS,
    PROJECTIONS,
    ZOOM_PER_NOTCH,
    CameraControl,
)
from frustum.viewer.session import CONTROLS, MODES, SHADINGS, ViewerSession

__all__ = [
    "CONTROLS",
    "KEYS",
    "MODES",
    "ORBIT_RADIANS_PER_PIXEL",
    "PRESETS",
    "PROJECTIONS",
    "SHADINGS",
    "ZOOM_PER_NOTCH",
    "CameraControl",
    "Viewer",
    "ViewerSession",
    "serve",
]


def __getattr__(name: str) -> Any:
    if name == "Viewer":
        try:
            from frustum.viewer.widget import Viewer
        except ImportError as error:
            from frustum.errors import FrustumError

            raise FrustumError(
                f"Viewer: needs the viewer extra ({error.name} is missing); pip install 'frustum[viewer]'"
            ) from None
        return Viewer
    if name == "serve":
        from frustum.viewer.server import serve

        return serve
    raise AttributeError(f"module 'frustum.viewer' has no attribute {name!r}")
