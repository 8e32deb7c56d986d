"""Checks of scene-file values, each adding its problem to the report and returning ``_BAD``: tables and lists of
tables, numbers, vectors, colors, choices, booleans; and ``_call``, a building function called with a table's keys
checked against its own signature (``_deg`` keys converted to radians)."""

from __future__ import annotations

import difflib
import functools
import importlib
import inspect
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from frustum.errors import FrustumError
from frustum.scenefile.report import _BAD, _path_text, _Report

_MAX_INTEGER_PARAMETER = 100_000
"""Largest integer geometry parameter (segments, resolution, ...): guards against runaway tessellation."""


_ANGLE_PARAMETERS = frozenset(
    {"angle", "fovy", "alpha", "phi", "rotation_x", "rotation_y", "crease_angle", "inner_angle", "outer_angle",
     "azimuth", "elevation", "start", "end", "spread"}
)  # fmt: skip
"""Radian parameters of the Python API: scene files must give them in degrees, as ``<name>_deg``."""


_DEGREE_PARAMETERS = frozenset({"LSystem.angle", "union.sharp_angle", "difference.sharp_angle",
                                "intersection.sharp_angle"})  # fmt: skip
"""Parameters the Python API itself takes in degrees: ``<name>_deg`` passes through unconverted."""


def _unknown_keys(report: _Report, path: tuple, table: Mapping, allowed: Sequence[str]) -> None:
    for key in table:
        if key not in allowed:
            close = difflib.get_close_matches(str(key), allowed, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            report.add(
                (*path, key), table[key], "is not a known key", f"{hint}expected one of {', '.join(sorted(allowed))}"
            )


def _table(report: _Report, path: tuple, value: Any, what: str = "a table") -> dict | Any:
    if not isinstance(value, Mapping):
        report.add(path, value, f"is not {what}", f"write it as a TOML table ([{_path_text(path)}] or {{ ... }})")
        return _BAD
    return dict(value)


def _table_list(report: _Report, path: tuple, value: Any) -> list:
    if not isinstance(value, list) or not all(isinstance(item, Mapping) for item in value):
        report.add(path, value, "is not a list of tables", f"write each entry as [[{_path_text(path)}]]")
        return []
    return value


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _number(
    report: _Report,
    path: tuple,
    value: Any,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    integer: bool = False,
) -> Any:
    """A finite number (an integer when asked) in [low, high] ((low, high] when `low_open`)."""
    kind = "an integer" if integer else "a number"
    if (integer and (not isinstance(value, int) or isinstance(value, bool))) or not _is_number(value):
        report.add(path, value, f"is not {kind}", f"give {kind}")
        return _BAD
    if not math.isfinite(value):
        report.add(path, value, "is not finite", f"give a finite {kind[2:] if integer else 'number'}")
        return _BAD
    below = low is not None and (value <= low if low_open else value < low)
    if below or (high is not None and value > high):
        left = "(" if low_open else "["
        lower = "-inf" if low is None else f"{low:g}"
        upper = "inf" if high is None else f"{high:g}"
        bounds = f"{left}{lower}, {upper}]"
        report.add(path, value, "is out of range", f"expected {kind} in {bounds}")
        return _BAD
    return value


def _vector(report: _Report, path: tuple, value: Any, count: int = 3, what: str = "x, y, z") -> Any:
    if not isinstance(value, list) or len(value) != count or not all(_is_number(v) for v in value):
        report.add(path, value, f"is not {count} numbers", f"give [{what}]")
        return _BAD
    if not all(math.isfinite(v) for v in value):
        report.add(path, value, "is not finite", f"give {count} finite numbers [{what}]")
        return _BAD
    return [float(v) for v in value]


def _color(report: _Report, path: tuple, value: Any, alpha: bool = False) -> Any:
    counts = (3, 4) if alpha else (3,)
    shape = "[r, g, b] or [r, g, b, a]" if alpha else "[r, g, b]"
    if not isinstance(value, list) or len(value) not in counts or not all(_is_number(v) for v in value):
        report.add(path, value, "is not a color", f"give {shape} with components in [0, 1]")
        return _BAD
    if not all(math.isfinite(v) and 0.0 <= v <= 1.0 for v in value):
        report.add(path, value, "has components outside [0, 1]", f"give {shape} with components in [0, 1]")
        return _BAD
    return [float(v) for v in value]


def _choice(report: _Report, path: tuple, value: Any, choices: Sequence[str]) -> Any:
    if not isinstance(value, str) or value not in choices:
        close = difflib.get_close_matches(str(value), choices, n=1) if isinstance(value, str) else []
        hint = f"did you mean {close[0]!r}? " if close else ""
        report.add(path, value, "is unknown", f"{hint}expected one of {', '.join(repr(c) for c in choices)}")
        return _BAD
    return value


def _boolean(report: _Report, path: tuple, value: Any) -> Any:
    if not isinstance(value, bool):
        report.add(path, value, "is not a boolean", "give true or false")
        return _BAD
    return value


def _plain(value: Any) -> Any:
    """TOML values as the Python API wants them (lists of numbers stay lists; numpy converts them)."""
    return value


def _check_plain_value(report: _Report, path: tuple, value: Any) -> bool:
    """Reject NaN/inf anywhere in a parameter, and integers large enough to make tessellation run away."""
    if isinstance(value, bool | str):
        return True
    if isinstance(value, float) and not math.isfinite(value):
        report.add(path, value, "is not finite", "give a finite number")
        return False
    if isinstance(value, int) and abs(value) > _MAX_INTEGER_PARAMETER:
        report.add(path, value, "is too large", f"give an integer of magnitude <= {_MAX_INTEGER_PARAMETER}")
        return False
    if isinstance(value, list):
        return all(_check_plain_value(report, (*path, i), v) for i, v in enumerate(value))
    if isinstance(value, Mapping):
        report.add(path, value, "is a table", "give a number, a string, a boolean or a list of numbers")
        return False
    return True


_SIGNATURES: dict[Any, inspect.Signature | None] = {}


def _signature(function: Callable) -> inspect.Signature | None:
    """``inspect.signature``, cached (it is slow, and a large scene file calls the same builders 10⁴ times)."""
    key = getattr(function, "__func__", function)  # bound methods: one entry per function
    if isinstance(key, functools.partial):  # made per call: not worth a cache entry
        try:
            return inspect.signature(key)
        except (TypeError, ValueError):  # pragma: no cover
            return None
    if key not in _SIGNATURES:
        try:
            _SIGNATURES[key] = inspect.signature(key)
        except (TypeError, ValueError):  # pragma: no cover - builtins without signatures
            _SIGNATURES[key] = None
    signature = _SIGNATURES[key]
    if signature is not None and key is not function:  # a bound method: drop `self`
        signature = signature.replace(parameters=list(signature.parameters.values())[1:])
    return signature


def _call(
    report: _Report,
    path: tuple,
    function: Callable,
    params: Mapping[str, Any],
    *,
    label: str,
    skip: Sequence[str] = (),
) -> Any:
    """``function(**params)`` with keys checked against its signature; `_deg` keys converted to radians."""
    signature = _signature(function)
    accepted = {
        name: p
        for name, p in (signature.parameters.items() if signature else ())
        if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and name not in ("self", "cls", "max_bytes")
    }
    valid_keys = sorted(f"{n}_deg" if n in _ANGLE_PARAMETERS and f"{label}.{n}" not in _DEGREE_PARAMETERS else n
                        for n in accepted)  # fmt: skip
    kwargs: dict[str, Any] = {}
    ok = True
    for key, value in params.items():
        if key in skip:
            continue
        key_text = str(key)
        name = key_text[:-4] if key_text.endswith("_deg") else key_text
        native_degrees = f"{label}.{name}" in _DEGREE_PARAMETERS
        if name not in accepted or (name in _ANGLE_PARAMETERS and not native_degrees and name == key_text):
            if name in accepted:
                report.add((*path, key), value, "is an angle in radians", f"scene files take degrees: write {name}_deg")
            else:
                close = difflib.get_close_matches(key_text, valid_keys, n=1)
                hint = f"did you mean {close[0]!r}? " if close else ""
                report.add(
                    (*path, key), value, f"is not a parameter of {label}",
                    f"{hint}expected {', '.join(valid_keys) or 'no parameters'}",
                )  # fmt: skip
            ok = False
            continue
        if key_text.endswith("_deg") and not (name in _ANGLE_PARAMETERS or native_degrees):
            report.add((*path, key), value, "is not an angle", f"write {name} without _deg")
            ok = False
            continue
        if not _check_plain_value(report, (*path, key), value):
            ok = False
            continue
        if key_text.endswith("_deg") and not native_degrees:
            if not _is_number(value):
                report.add((*path, key), value, "is not a number", "give an angle in degrees")
                ok = False
                continue
            value = math.radians(value)
        kwargs[name] = _plain(value)
    missing = False
    for name, parameter in accepted.items():
        if parameter.default is parameter.empty and name not in kwargs and name not in params:
            key = f"{name}_deg" if name in _ANGLE_PARAMETERS and f"{label}.{name}" not in _DEGREE_PARAMETERS else name
            if key not in params:
                report.missing((*path, key), f"{label} needs {key}")
            missing = True
    if missing:
        return _BAD
    cacheable = ok and getattr(function, "__module__", "") in _DETERMINISTIC_MODULES
    key = (function, repr(sorted(kwargs.items()))) if cacheable else None
    if key is not None and key in report.built:  # the same primitive again: share the immutable result
        return report.built[key]
    try:  # even after a bad key: the function's own checks may find more problems in the other values
        built = function(**kwargs)
    except FrustumError as error:
        report.refused(path, dict(params), error)
        return _BAD
    except (TypeError, ValueError, ArithmeticError, IndexError, MemoryError) as error:
        report.refused(path, dict(params), error)
        return _BAD
    if key is not None:
        report.built[key] = built
    return built if ok else _BAD


_DETERMINISTIC_MODULES = frozenset({"frustum.geometry.primitives", "frustum.geometry.quadrics", "frustum.shading"})
"""Builders whose results depend only on their arguments and are immutable: a scene file of 10⁴ equal spheres
builds one Mesh and shares it (``_call``)."""


def _resolve(report: _Report, path: tuple, kind: str, module: str, attribute: str) -> Any:
    try:
        return getattr(importlib.import_module(module), attribute)
    except (ImportError, AttributeError):
        report.add(path, kind, "is not available in this version", f"{module}.{attribute} is missing")
        return _BAD


def _input_file(report: _Report, path: tuple, name: Any, *, what: str) -> Any:
    """The file a scene file names as input (a mesh, an image), resolved against its folder: a regular file inside
    that folder, or inside one the user allowed (``load_scene(..., allow_read=[...])``, ``--allow-read PATH``),
    once symbolic links are followed; else a problem on `report` and ``_BAD``.

    Inputs are confined as outputs are: a scene file that names ``../../etc/passwd`` or ``/home/x/secret.png``
    cannot make a service that renders users' scene files show the server's files."""
    from pathlib import Path

    from frustum._files import file_kind

    if not isinstance(name, str) or not name or "\0" in name:
        report.add(path, name, "is not a file name", f"give the path of {what}, relative to the scene file's folder")
        return _BAD
    base = Path(getattr(report, "base", "."))
    try:
        file = (base / name).resolve()
        roots = [base.resolve(), *(Path(root).resolve() for root in getattr(report, "allow_read", ()))]
    except (OSError, RuntimeError, ValueError):  # a symbolic-link loop
        report.add(path, name, "cannot be resolved (a symbolic-link loop?)", f"give {what} inside the scene's folder")
        return _BAD
    if not any(file.is_relative_to(root) for root in roots):
        report.add(path, name, f"lies outside the scene file's folder ({file})",
                   f"give {what} inside {str(roots[0])!r}, or allow its folder: load_scene(..., allow_read=[...]) "
                   "or --allow-read PATH")  # fmt: skip
        return _BAD
    if not file.is_file():
        problem = f"is not a regular file ({file_kind(file)})" if file.exists() else "does not exist"
        report.add(path, name, f"{problem} (looked for {file})", f"give {what} relative to the scene file's folder")
        return _BAD
    return file
