"""Kept so that ``frustum.environment`` still imports: the module is now ``frustum.shading.environment``."""

from frustum.shading.environment import *  # noqa: F403
from frustum.shading.environment import __all__  # noqa: F401
