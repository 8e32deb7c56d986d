"""Output: frames and drawings to files (PNG, SVG, GIF, MP4) and to Jupyter."""
