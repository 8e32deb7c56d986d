"""Writes the public API snapshot that ``tests/test_public_api.py`` compares against:
``python tests/data/capture_public_api.py tests/data/public_api.json`` (only for a deliberate API change)."""

import inspect
import json
import sys


def signature(obj):
    try:
        return str(inspect.signature(obj))
    except (TypeError, ValueError):
        return None


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
