"""Writes the public API snapshot that ``tests/test_public_api.py`` compares against:
``python tests/data/capture_public_api.py tests/data/public_api.json`` (only for a deliberate API change)."""

import inspect
import json
import sys
from pathlib import Path


def signature(obj):
    """The signature as text, and its parameters as [name, kind, default] (default as repr, None when required)."""
    try:
        found = inspect.signature(obj)
    except (TypeError, ValueError):
        return None
    root = str(Path(sys.modules["frustum"].__file__).resolve().parents[2])  # the checkout: not part of the API
    parameters = [
        [p.name, p.kind.name, None if p.default is p.empty else repr(p.default).replace(root, "<root>")]
        for p in found.parameters.values()
    ]
    return {"text": str(found).replace(root, "<root>"), "parameters": parameters}


def describe(module, names):
    """For each name: its kind, its signature when callable, and for a class its public members' signatures."""
    out = {}
    for name in names:
        obj = getattr(module, name)
        entry = {"kind": type(obj).__name__ if not isinstance(obj, type) else "class"}
        if callable(obj):
            entry["signature"] = signature(obj)
        if isinstance(obj, type):
            members = {}
            for member, value in sorted(vars(obj).items()):
                if member.startswith("_") and member not in ("__init__", "__call__"):
                    continue
                if isinstance(value, (staticmethod, classmethod)):
                    value = value.__func__
                if isinstance(value, property):
                    members[member] = "property"
                elif callable(value):
                    members[member] = signature(value)
            entry["members"] = members
        out[name] = entry
    return out


def snapshot():
    import frustum
    import frustum.geometry

    return {
        "frustum.__all__": sorted(frustum.__all__),
        "dir(frustum) public": sorted(n for n in dir(frustum) if not n.startswith("_")),
        "frustum.geometry.__all__": sorted(frustum.geometry.__all__),
        "dir(frustum.geometry) public": sorted(n for n in dir(frustum.geometry) if not n.startswith("_")),
        "frustum": describe(frustum, sorted(set(frustum.__all__) | {"Viewer"} - {"__version__"})),
        "frustum.geometry": describe(frustum.geometry, sorted(frustum.geometry.__all__)),
    }


if __name__ == "__main__":
    with open(sys.argv[1], "w") as file:
        json.dump(snapshot(), file, indent=1, sort_keys=True)
