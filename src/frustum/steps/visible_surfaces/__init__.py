"""Visible surfaces, step by step: the nine methods of the chapter, recorded from the production code.

``object_space``: back-face detection, the BSP tree, the depth sort; ``image_space``: the depth buffer, area
subdivision (Warnock), the scan line, the A-buffer; ``rays``: ray casting; ``octrees``: the octree method. They
share the chapter's example scenes (``image_space.default_scene``) and the figure helpers of ``steps``.

References: [HB 16] "Visible-Surface Detection Methods"; [seed] "Back-face detection", "BSP trees",
"Depth-buffer method".
"""

from frustum.steps.visible_surfaces.image_space import (
    a_buffer,
    area_subdivision,
    default_scene,
    default_transparent_scene,
    depth_buffer,
    scan_line,
)
from frustum.steps.visible_surfaces.object_space import (
    HOUSE_FACES,
    back_faces,
    bsp_tree,
    default_depth_sort_scene,
    default_walls,
    depth_sort,
)
from frustum.steps.visible_surfaces.octrees import default_octree, octree
from frustum.steps.visible_surfaces.rays import ray_casting, traced_closest

__all__ = [
    "HOUSE_FACES", "a_buffer", "area_subdivision", "back_faces", "bsp_tree", "default_depth_sort_scene",
    "default_octree", "default_scene", "default_transparent_scene", "default_walls", "depth_buffer", "depth_sort",
    "octree", "ray_casting", "scan_line", "traced_closest",
]  # fmt: skip
