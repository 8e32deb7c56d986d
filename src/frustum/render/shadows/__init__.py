"""Shadows, one sub-package: which part of each light reaches each visible point, and the surfaces shaded with it.

``fractions``: the shadow pass (shadow maps drawn from each light, or shadow rays through the scene's BVH); ``passes``:
its place among the surface passes (world points of the drawn pixels, fractions, shading with them, and the
one-mesh tile pipeline with shadow maps). The kernels are ``raster.shadow`` and ``raster.shadow_tiled``.
"""
