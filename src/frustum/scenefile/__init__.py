"""TOML scene files: a camera, lights, materials and a node hierarchy, validated with every error reported at once.

A scene file is read with the standard library's ``tomllib`` and checked completely before anything is
rendered: each problem becomes one line $file:line: key = value problem; what is valid$ and all of them are
raised together as one ``SceneFileError`` (its ``problems`` attribute lists the lines). ``tomllib`` reports no
positions for keys, so ``report._key_lines`` scans the TOML text once and maps every key path (``nodes[1].transform[0]
.rotate_y_deg``) to the line it is written on.

Conventions of the format (``docs/topics.md`` has a tour, ``scene.schema.json`` the JSON Schema):

- Angles are degrees, in keys ending ``_deg`` ($fovy_deg = 45$, $rotate_y_deg = 30$); the Python API they
  feed takes radians. Lengths are world units; colors are linear RGB(A) in [0, 1].
- A node's ``transform`` is a list of named steps applied first to last ($world_from_model = compose(*steps)$,
  column vectors): ``translate``, ``rotate_x_deg`` / ``rotate_y_deg`` / ``rotate_z_deg``, ``rotate_deg`` about
  ``axis`` through ``point``, ``scale`` (one factor or three) about ``fixed``, ``reflect`` (``"xy"``, ``"yz"``,
  ``"zx"`` or a normal) through ``point``, ``shear`` (axis with ``a``, ``b``, ``ref``), ``quaternion`` ``[w, x, y,
  z]`` and ``matrix`` (4x4 rows).
- Geometry parameters are checked against the building function's own signature (``inspect.signature``), so a
  keyword argument that a geometry function gains later works in scene files at once.
- Paths (mesh files, outputs) are relative to the scene file's folder. Output files named in ``[output]
  files`` must stay inside that folder (no ``..`` escape, no absolute path, no symlink pointing out): rendering
  an untrusted scene file cannot write anywhere else. The command line's ``-o`` goes wherever the user says.
- Hostile input is refused early, with ``file:line``: files over ``MAX_SCENE_FILE_BYTES`` (16 MiB), arrays or
  tables nested deeper than ``_MAX_NESTING`` (64), dotted keys of more than 64 parts; keys and values are quoted
  in messages with control characters escaped.

References
----------
[HB 9] "Composite Three-Dimensional Transformations"; [HB 10] "The Three-Dimensional Viewing Pipeline";
[seed] "3D Viewing parameter (how 3D object displays at 2D)".
"""

from frustum.scenefile.camera import PROJECTIONS
from frustum.scenefile.commands import (
    EXAMPLES_DIR,
    explain_method,
    explain_scene_file,
    render_examples,
    render_scene_file,
    render_view_sheet,
)
from frustum.scenefile.geometry import GEOMETRY_TYPES
from frustum.scenefile.loader import (
    ALLOW_READ_VARIABLE,
    MAX_SCENE_FILE_BYTES,
    SCHEMA_PATH,
    SceneFile,
    load_scene,
    load_scene_file,
)
from frustum.scenefile.outputs import OUTPUT_SUFFIXES
from frustum.scenefile.transforms import TRANSFORM_STEPS

__all__ = [
    "ALLOW_READ_VARIABLE",
    "EXAMPLES_DIR",
    "GEOMETRY_TYPES",
    "MAX_SCENE_FILE_BYTES",
    "OUTPUT_SUFFIXES",
    "PROJECTIONS",
    "SCHEMA_PATH",
    "TRANSFORM_STEPS",
    "SceneFile",
    "explain_method",
    "explain_scene_file",
    "load_scene",
    "load_scene_file",
    "render_examples",
    "render_scene_file",
    "render_view_sheet",
]
