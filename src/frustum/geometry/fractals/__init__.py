"""Fractals: deterministic self-similar curves and solids, iterated function systems, fractal terrain.

Every generator takes a ``level`` (the number of refinement steps, 0 = the initiator) and refuses, before
allocating anything, a level whose output would exceed the memory budget (``frustum.set_budget``,
``FRUSTUM_MAX_BYTES``, ``--max-bytes``; default 8 GiB) or the per-call override ``max_bytes=``: the
``GeometryError`` states the bytes needed, the budget and how to raise it. Random fractals
take a ``seed`` (``numpy.random.default_rng``): same seed, same bytes.

Curves are returned as (N, 3) float64 polylines (2D curves lie in the plane z = 0); solids as a ``Mesh``.

The package: ``curves`` (Koch, Cantor, Sierpinski, Hilbert, Peano), ``solids`` (Sierpinski tetrahedron, Menger
sponge), ``ifs`` (iterated function systems), ``terrain`` (random fractals) and ``checks`` (the budget and
argument checks they share).

References
----------
[HB 15] "Fractal-Geometry Methods": "The Fractal Dimension", "Geometric Construction of Deterministic
Self-Similar Fractals", "Affine Fractal-Construction Methods", "Random Midpoint-Displacement Methods".
[seed] "Fractals", "Fractal dimension".
"""

from frustum.geometry.fractals.checks import DEFAULT_MAX_BYTES
from frustum.geometry.fractals.curves import (
    cantor_set,
    hilbert_curve,
    hilbert_curve_3d,
    koch_curve,
    koch_snowflake,
    peano_curve,
    sierpinski_triangle,
    similarity_dimension,
)
from frustum.geometry.fractals.ifs import IFS, barnsley_fern, sierpinski_ifs
from frustum.geometry.fractals.solids import menger_sponge, sierpinski_tetrahedron
from frustum.geometry.fractals.terrain import fbm_terrain, fractal_coastline, heightfield_mesh

__all__ = [
    "DEFAULT_MAX_BYTES",
    "IFS",
    "barnsley_fern",
    "cantor_set",
    "fbm_terrain",
    "fractal_coastline",
    "heightfield_mesh",
    "hilbert_curve",
    "hilbert_curve_3d",
    "koch_curve",
    "koch_snowflake",
    "menger_sponge",
    "peano_curve",
    "sierpinski_ifs",
    "sierpinski_tetrahedron",
    "sierpinski_triangle",
    "similarity_dimension",
]
