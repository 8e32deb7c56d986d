"""frustum: the classical 3D graphics pipeline, faithful, inspectable and fast, rendering headless on any machine.

Conventions (``docs/conventions.md``): column vectors ($P' = M @ P$), radians, right-handed world and view
coordinates with the camera looking down −z, left-handed normalized device coordinates [−1, 1]³.

Every public name is listed once, in ``__init__.pyi`` (the stub editors and type checkers read), and loaded on
first use by ``lazy_loader`` (SPEC 1): ``import frustum`` imports no module of the package, so it stays fast and
never imports Numba; ``dir(frustum)`` shows every name.
"""

__version__ = "0.1.0"

import lazy_loader as _lazy

_getattr, _dir, _names = _lazy.attach_stub(__name__, __file__)

_SUBMODULES = frozenset({"budgets", "camera", "clipping", "errors", "frame", "geometry", "projection", "quaternion",
                         "scene", "shading", "steps", "transforms"})  # fmt: skip
"""The submodules the stub lists (``frustum.geometry`` works after ``import frustum``; ``frustum.steps``, the
teaching layer, loads on first use): not in ``__all__``."""

__all__ = [name for name in _names if name not in _SUBMODULES and name != "Viewer"] + ["__version__"]
"""Every public name but ``Viewer`` (it needs the viewer extra, anywidget), so ``from frustum import *`` works
without it."""


def __getattr__(name: str) -> object:
    if name not in _names:
        raise AttributeError(f"module 'frustum' has no attribute {name!r}")
    return _getattr(name)


def __dir__() -> list[str]:
    return sorted(set(_names) | set(__all__))
