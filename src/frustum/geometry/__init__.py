"""Modeling: things to draw, in their own (model) coordinates. This issue adds the minimal ``Mesh``."""

from frustum.geometry.mesh import Mesh

__all__ = ["Mesh"]
