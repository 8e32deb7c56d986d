"""The world: a hierarchy of nodes placing geometry with materials, the lights (``scene.graph``), exploded and
cutaway views (``scene.cutaway``).

A node's ``transform`` maps its own (model) coordinates into its parent's; the world transform of a node is
the product down the parent chain, $world_from_model = T_root · … · T_parent · T_node$ (column vectors: the
node's own transform is applied first) [HB 9] "Composite Transformations", [HB 11] "Hierarchical Modeling".
"""

from frustum.scene.cutaway import cutaway, exploded
from frustum.scene.graph import (
    PARTICLE_BLENDING,
    PARTICLE_STYLES,
    Node,
    ParticleLayer,
    Pick,
    Placed,
    RayHits,
    Scene,
    SceneItem,
    VolumeItem,
)

__all__ = [
    "PARTICLE_BLENDING", "PARTICLE_STYLES", "Node", "ParticleLayer", "Pick", "Placed", "RayHits", "Scene",
    "SceneItem", "VolumeItem", "cutaway", "exploded",
]  # fmt: skip
