"""Moved to ``frustum.visibility.hidden_lines`` (hidden-line removal; docs/architecture.md): this path re-exports it."""

from frustum.visibility.hidden_lines import *  # noqa: F403
from frustum.visibility.hidden_lines import __all__ as __all__
