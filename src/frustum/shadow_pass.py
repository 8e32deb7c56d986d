"""Moved to ``frustum.render.shadows.fractions`` (the shadow pass; docs/architecture.md): this path re-exports it."""

from frustum.render.shadows.fractions import *  # noqa: F403
from frustum.render.shadows.fractions import __all__ as __all__
