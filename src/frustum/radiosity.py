"""Moved to ``frustum.render.radiosity`` (radiosity; docs/architecture.md): this path re-exports it."""

from frustum.render.radiosity import *  # noqa: F403
from frustum.render.radiosity import __all__ as __all__
