"""Moved to ``frustum.visibility.bsp`` and ``frustum.visibility.depth_sort`` (docs/architecture.md): this path
re-exports them."""

from frustum.visibility.bsp import BSPTree
from frustum.visibility.depth_sort import DepthOrder, depth_sort

__all__ = ["BSPTree", "DepthOrder", "depth_sort"]
