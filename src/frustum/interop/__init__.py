"""Other programs' scenes rendered by frustum, unchanged: pyrender scenes (``frustum.interop.pyrender``) and
trimesh scenes (``frustum.interop.trimesh``). Their packages are imported only to read their objects."""
