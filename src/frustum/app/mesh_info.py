"""What ``frustum info`` says of a mesh file (counts, bounds, watertightness, normals), and the mesh loading with
one-line errors that ``info`` and ``turntable`` share."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from frustum.errors import GeometryError
from frustum.geometry import Mesh


def load_mesh(path: Path, where: str) -> Mesh:
    """A mesh file as one Mesh (``frustum.geometry.io.load``, else trimesh), errors as one-line GeometryErrors."""
    if not path.is_file():
        from frustum._files import file_kind

        problem = "does not exist" if not path.exists() else f"is not a regular file ({file_kind(path)})"
        raise GeometryError(f"{where}: mesh = {str(path)!r} {problem}; give a mesh file path")
    try:
        from frustum.geometry.io import load
    except ImportError:  # pragma: no cover - the io module ships with frustum; trimesh directly otherwise
        load = None
    if load is not None:
        return load(path)
    import trimesh

    try:
        loaded = trimesh.load(path, force="mesh")
    except Exception as error:  # trimesh raises many types for unreadable files
        reason = (str(error).strip().splitlines() or [type(error).__name__])[0]
        raise GeometryError(
            f"{where}: mesh = {str(path)!r} cannot be read ({reason}); give a .ply, .obj, .stl, .off or .glb file"
        ) from None
    return Mesh(loaded.vertices, loaded.faces)


def _mesh_facts(mesh: Mesh) -> list[tuple[str, str]]:
    """(name, value) rows of ``frustum info``; topology through trimesh with coincident vertices merged."""
    import trimesh

    rows = [("vertices", f"{mesh.vertex_count}"), ("triangles", f"{mesh.face_count}")]
    if mesh.vertex_count == 0:
        return [*rows, ("bounds", "empty mesh")]
    low, high = mesh.bounds
    rows += [
        ("bounds min", _triple_text(low)),
        ("bounds max", _triple_text(high)),
        ("size", _triple_text(high - low)),
        ("center", _triple_text((low + high) / 2)),
    ]
    if mesh.face_count == 0:
        return [*rows, ("faces", "none (a point cloud)")]
    solid = trimesh.Trimesh(mesh.vertices, mesh.faces, process=True)  # merges coincident vertices
    watertight = bool(solid.is_watertight)
    consistent = bool(solid.is_winding_consistent)
    rows += [
        ("watertight", "yes" if watertight else f"no ({_open_edges(solid)} boundary or non-manifold edges)"),
        ("winding consistent", "yes" if consistent else "no"),
        ("surface area", f"{float(solid.area):.6g}"),
    ]
    if watertight:
        volume = float(solid.volume)
        rows += [("volume", f"{volume:.6g}"), ("Euler characteristic", f"{int(solid.euler_number)}")]
        if consistent:
            rows.append(("face normals", "outward" if volume > 0 else "inward (faces are clockwise from outside)"))
    corners = np.asarray(mesh.vertices, dtype=np.float64)[mesh.faces]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    degenerate = int((np.linalg.norm(cross, axis=1) == 0).sum())
    rows.append(("zero-area triangles", f"{degenerate}"))
    computed = Mesh(mesh.vertices, mesh.faces).vertex_normals
    given = not np.allclose(mesh.vertex_normals, computed, atol=1e-9)
    rows.append(("vertex normals", "from the file" if given else "computed (area-weighted face normals)"))
    unused = mesh.vertex_count - np.unique(mesh.faces).size
    if unused:
        rows.append(("unused vertices", f"{unused}"))
    return rows


def _open_edges(solid: Any) -> int:
    edges = np.sort(solid.edges, axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int((counts != 2).sum())


def _triple_text(values: Sequence[float]) -> str:
    return "(" + ", ".join(f"{float(v):.6g}" for v in values) + ")"


def info_table(mesh: Path) -> Any:
    from rich.table import Table

    facts = point_file_facts(mesh)  # a point cloud's or splat file's counts
    table = Table(title=str(mesh), show_header=False, title_justify="left")
    table.add_column(style="bold")
    table.add_column()
    for name, value in facts if facts is not None else _mesh_facts(load_mesh(mesh, "info")):
        table.add_row(name, value)
    return table


def point_file_facts(path: str | Path) -> list[tuple[str, str]] | None:
    """(name, value) rows for ``frustum info`` of a point or splat file (None for a mesh file)."""
    from frustum.geometry.points import load_points, point_file_kind
    from frustum.geometry.splats import GaussianSplats

    kind = point_file_kind(path)
    if kind is None:
        return None
    if kind == "splats":
        splats = GaussianSplats.load(path)
        low, high = splats.bounds
        return [("kind", "3D Gaussian splats (3DGS PLY)"), ("splats", f"{splats.count}"),
                ("spherical-harmonic degree", f"{splats.degree}"), ("bounds min", _triple_text(low)),
                ("bounds max", _triple_text(high)),
                ("opacity", f"mean {float(splats.opacities.mean()):.3g}" if splats.count else "none")]  # fmt: skip
    cloud = load_points(path)
    low, high = cloud.bounds
    return [("kind", "point cloud"), ("points", f"{cloud.point_count}"), ("bounds min", _triple_text(low)),
            ("bounds max", _triple_text(high)), ("size", _triple_text(high - low)),
            ("colors", "yes" if cloud.colors is not None else "no"),
            ("normals", "yes" if cloud.normals is not None else "no"),
            ("radii", "yes" if cloud.radii is not None else "no")]  # fmt: skip
