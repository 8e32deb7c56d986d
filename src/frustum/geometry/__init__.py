"""Modeling: things to draw, in their own (model) coordinates: meshes, primitives, quadrics and superquadrics,
curves and surfaces, fractals, mesh files and CSG, octrees.

Every public name is listed once, in ``__init__.pyi``, and loaded on first use by ``lazy_loader`` (SPEC 1):
rendering a mesh, a primitive or a patch surface does not import fractals, L-systems, mesh files, CSG, octrees or
volumes.
"""

import lazy_loader as _lazy

_getattr, _dir, _names = _lazy.attach_stub(__name__, __file__)

_SUBMODULES = frozenset({"curves", "mesh", "polyline", "primitives", "quadrics", "surfaces"})
"""The submodules the stub lists (loaded with their first name, as they were): not in ``__all__``."""

__all__ = [name for name in _names if name not in _SUBMODULES]


def __getattr__(name: str) -> object:
    if name not in _names:
        raise AttributeError(f"module 'frustum.geometry' has no attribute {name!r}")
    return _getattr(name)


def __dir__() -> list[str]:
    return sorted(set(_names) | set(__all__))
