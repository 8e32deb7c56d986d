"""frustum: the classical 3D graphics pipeline, faithful, inspectable and fast, rendering headless on any machine.

Conventions (``docs/conventions.md``): column vectors (``P' = M @ P``), radians, right-handed world and view
coordinates with the camera looking down −z, left-handed normalized device coordinates [−1, 1]³.
"""

__version__ = "0.1.0"

from frustum.errors import (
    CameraError,
    ClippingError,
    FrustumError,
    GeometryError,
    OutputError,
    SceneFileError,
    TransformError,
)
from frustum.quaternion import Quaternion, slerp
from frustum.transforms import (
    Step,
    apply,
    apply_homogeneous,
    apply_to_directions,
    apply_to_normals,
    compose,
    invert,
    reflect,
    rotate,
    rotate_steps,
    rotate_x,
    rotate_y,
    rotate_z,
    scale,
    shear,
    swaps_handedness,
    to_row_major,
    translate,
)

__all__ = [
    "CameraError",
    "ClippingError",
    "FrustumError",
    "GeometryError",
    "OutputError",
    "Quaternion",
    "SceneFileError",
    "Step",
    "TransformError",
    "__version__",
    "apply",
    "apply_homogeneous",
    "apply_to_directions",
    "apply_to_normals",
    "compose",
    "invert",
    "reflect",
    "rotate",
    "rotate_steps",
    "rotate_x",
    "rotate_y",
    "rotate_z",
    "scale",
    "shear",
    "slerp",
    "swaps_handedness",
    "to_row_major",
    "translate",
]
