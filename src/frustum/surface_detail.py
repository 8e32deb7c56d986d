"""Kept so that ``frustum.surface_detail`` still imports: the module is now ``frustum.shading.surface_detail``."""

from frustum.shading.surface_detail import *  # noqa: F403
from frustum.shading.surface_detail import __all__  # noqa: F401
