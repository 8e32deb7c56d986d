"""``[[particles]]`` and ``[[cloth]]``: particle systems and mass-spring cloth, with their emitters, forces and
colliders, placed in the scene (and run to their first frame)."""

from __future__ import annotations

import functools
import importlib
from typing import Any

from frustum.errors import FrustumError
from frustum.scene import Scene
from frustum.scenefile.checks import _call, _choice, _table, _table_list
from frustum.scenefile.lights_materials import _material_reference
from frustum.scenefile.report import _BAD, _bad, _Report

_EMITTERS = {"point": "PointEmitter", "line": "LineEmitter", "disk": "DiskEmitter", "sphere": "SphereEmitter"}


_FORCES = {"gravity": "Gravity", "drag": "Drag", "wind": "Wind", "vortex": "Vortex", "attractor": "Attractor"}


_COLLIDERS = {"plane": "PlaneCollider", "sphere": "SphereCollider"}


_PARTICLE_KEYS = ("emitter", "forces", "colliders", "style", "blending")


_CLOTH_KEYS = ("material", "colliders", "name")


def _typed(report: _Report, path: tuple, value: Any, kinds: dict[str, str]) -> Any:
    """``{ type = "...", ... }`` → the simulation class of that type built from the other keys."""
    params = _table(report, path, value)
    if params is _BAD:
        return _BAD
    kind = params.pop("type", None)
    if kind not in kinds:
        report.add((*path, "type"), kind, "is unknown" if kind is not None else "is missing",
                   f"expected one of {', '.join(repr(k) for k in kinds)}")  # fmt: skip
        return _BAD
    simulation = importlib.import_module("frustum.simulation")
    return _call(report, path, getattr(simulation, kinds[kind]), params, label=kinds[kind])


def _typed_list(report: _Report, path: tuple, value: Any, kinds: dict[str, str]) -> Any:
    if not isinstance(value, list):
        report.add(path, value, "is not a list of tables", "write e.g. [{ type = ... }, ...]")
        return _BAD
    built = [_typed(report, (*path, i), item, kinds) for i, item in enumerate(value)]
    return _BAD if any(item is _BAD for item in built) else built


def _simulations(report: _Report, data: dict, scene: Scene, materials: dict) -> None:
    """``[[particles]]`` (a ParticleSystem with its emitter, forces, colliders, style, blending) and ``[[cloth]]``
    (``frustum.cloth`` with its material and colliders) added to `scene`; ``[animation].warmup`` steps them."""
    if "particles" not in data and "cloth" not in data:
        return  # nothing to simulate: frustum.simulation is not loaded
    simulation = importlib.import_module("frustum.simulation")
    for i, entry in enumerate(_table_list(report, ("particles",), data.get("particles", []))):
        path, params = ("particles", i), dict(entry)
        if "emitter" not in params:
            report.missing((*path, "emitter"), "give an emitter = { type = 'point', position = [x, y, z] }")
            continue
        emitter = _typed(report, (*path, "emitter"), params["emitter"], _EMITTERS)
        forces = _typed_list(report, (*path, "forces"), params.get("forces", []), _FORCES)
        colliders = _typed_list(report, (*path, "colliders"), params.get("colliders", []), _COLLIDERS)
        style = _choice(report, (*path, "style"), params.get("style", "sprites"), ("sprites", "points", "streaks"))
        blending = _choice(report, (*path, "blending"), params.get("blending", "additive"), ("additive", "alpha"))
        if _bad(emitter, forces, colliders, style, blending):
            continue
        build = functools.partial(simulation.ParticleSystem, emitter=emitter, forces=forces, colliders=colliders)
        system = _call(report, path, build, params, label="ParticleSystem", skip=_PARTICLE_KEYS)
        if system is not _BAD:
            scene.add_particles(system, style=style, blending=blending)
    for i, entry in enumerate(_table_list(report, ("cloth",), data.get("cloth", []))):
        path, params = ("cloth", i), dict(entry)
        material = _material_reference(report, (*path, "material"), params["material"], materials) \
            if "material" in params else None  # fmt: skip
        colliders = _typed_list(report, (*path, "colliders"), params.get("colliders", []), _COLLIDERS)
        name = params.get("name", "")
        if not isinstance(name, str):
            report.add((*path, "name"), name, "is not a string", "give a node name in quotes")
            continue
        if _bad(material, colliders):
            continue
        build = functools.partial(simulation.cloth, colliders=colliders)
        system = _call(report, path, build, params, label="cloth", skip=_CLOTH_KEYS)
        if system is not _BAD:
            scene.add_mass_spring(system, material, name=name)


def _warm_up(report: _Report, scene: Scene, animation: dict) -> None:
    """Step the simulations ``[animation].warmup`` seconds (in steps of $1/(fps·substeps)$) before any frame."""
    warmup = animation.get("warmup", 0.0)
    if not warmup or not (scene.particle_layers or scene.mass_springs):
        return
    step_scene = importlib.import_module("frustum.output.simulate").step_scene
    dt = 1.0 / (animation.get("fps", 12.0) * animation.get("substeps", 1))
    try:
        step_scene(scene, dt, round(warmup / dt))
    except FrustumError as error:
        report.refused(("animation", "warmup"), warmup, error)
