"""Octrees: solids as linear octrees of Morton codes, their set operations, measures and conversions.

The region is a cube $bounds = (min_corner, max_corner)$ cut `depth` times in halves along x, y and z; a
node at level l (0 = the whole region, `depth` = the finest cells) is one of ``8^l`` cubes of side
``size / 2^l``. Every node is **full** (inside the solid), **empty** (the textbook's "void") or **partial**
(heterogeneous: subdivided into eight children). Finest cells are full or empty.

Storage is array-based, no Python object per node: ``full[l]`` is the sorted ``uint64`` array of the Morton
codes of the maximal full nodes at level l; the partial nodes (every strict ancestor of a full node that is not
itself covered) are derived from it. A node's Morton code interleaves the bits of its integer coordinates
``(i, j, k)`` (x, y, z, each in ``[0, 2^l)``), x in the lowest bit, so the child of code c in octant o is
$8·c + o$ with $o = x + 2y + 4z$ (x, y, z ∈ {0, 1} the child's halves). The tree is canonical: eight full
siblings are always merged into their full parent, so equal sets give identical arrays.

**Octant numbering.** The textbook [HB 15, "Octrees"] numbers the octants of a node 0–3 in the front
(the half toward a viewer on +z) and 4–7 in the back, each face counted like a quadrant: 0 = (x low, y low),
1 = (x high, y low), 2 = (x low, y high), 3 = (x high, y high). So textbook $t = x + 2y + 4(1 − z)$ and
$o = t XOR 4$ (``TEXTBOOK_OCTANTS[o]`` is t).

Besides the full cells an octree built by sampling keeps ``boundary``: the finest cells the surface crossed
(mixed samples, or a triangle touching the cell); their state was decided by one sample near the cell's
centre. ``volume_bounds`` counts them as empty and as full.

The package: ``codes`` (Morton codes and the canonical form), ``tree`` (the ``Octree`` type), ``build``,
``operations`` (set operations and moves), ``meshing`` (voxels and meshes) and ``rays`` (ray queries).

References
----------
[HB 15] "Octrees" (octree encoding, set operations by simultaneous traversal); [HB 16] "Octree Methods"
(visible surfaces); [seed] "General modeling techniques: octrees".
"""

from frustum.geometry.octree.codes import MAX_DEPTH, morton_decode, morton_encode
from frustum.geometry.octree.rays import OctreeHits
from frustum.geometry.octree.tree import TEXTBOOK_OCTANTS, Octree

__all__ = ["MAX_DEPTH", "TEXTBOOK_OCTANTS", "Octree", "OctreeHits", "morton_decode", "morton_encode"]
