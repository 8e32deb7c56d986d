"""Moved to ``frustum.visibility.bsp`` (docs/architecture.md): this path re-exports it."""

from frustum.visibility.bsp import *  # noqa: F403
from frustum.visibility.bsp import __all__ as __all__
