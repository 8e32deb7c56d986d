"""Modeling: things to draw, in their own (model) coordinates."""

from frustum.geometry.mesh import Mesh
from frustum.geometry.polyline import Polyline

__all__ = ["Mesh", "Polyline"]
