"""Where the tests' reference data lives: ``tests/data/`` inside the repository (sources and licences in
``tests/data/README.md``). Every test reads it through ``DATA``; no test names a path outside the repository."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from frustum import Mesh

DATA = Path(__file__).resolve().parent / "data"


def closed_bunny() -> Mesh:
    """The Stanford bunny (``bun_zipper.ply``, welded) with each boundary loop (its 5 bottom holes) closed by a fan
    from the loop's centroid: a watertight solid (the octree's tests and ``benchmarks/bench_octree.py``)."""
    import numpy as np
    import trimesh

    from frustum import Mesh

    data = trimesh.load(DATA / "bunny" / "bun_zipper.ply", process=False, force="mesh")
    mesh = Mesh(np.asarray(data.vertices), np.asarray(data.faces)).welded()
    faces = mesh.faces
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).tolist()
    present = set(map(tuple, directed))
    following = {a: b for a, b in directed if (b, a) not in present}
    vertices, extra, count = [mesh.vertices], [], mesh.vertex_count
    while following:
        loop, a = [], next(iter(following))
        while a in following:
            loop.append(a)
            a = following.pop(a)
        vertices.append(mesh.vertices[loop].mean(axis=0)[None])
        extra += [(loop[(i + 1) % len(loop)], loop[i], count) for i in range(len(loop))]
        count += 1
    return Mesh(np.concatenate(vertices), np.concatenate([faces, np.array(extra)]))
