"""Shadows, one sub-package: which part of each light reaches each visible point, and the surfaces shaded with it.

``fractions``: the shadow pass (shadow maps drawn from each light, or shadow rays through the scene's BVH); ``passes``:
its place among the surface passes (world points of the drawn pixels, fractions, shading with them, and the
tile pipeline with shadow maps); ``merged``: several placed meshes as one world-space mesh, for the one-pass map
fill and the tile pipeline of several items. The kernels are ``raster.shadow`` and ``raster.shadow_tiled``.
"""
