"""``triangles._fill_tile`` fills a tile's entries in blocks of ``FILL_BLOCK`` (gather, branch-free set-up, ordered
depth tests): tiles holding several blocks, mixing faces drawn from their vertices, back faces and clipped records,
give the reference's bytes."""

from __future__ import annotations

import numpy as np
import pytest
from tests.reference_raster import reference_render
from tests.test_render import BACKGROUND, LIGHT, sphere_mesh

from frustum import Camera, Perspective
from frustum.raster.triangles import FILL_BLOCK
from frustum.render import bin_item, render
from frustum.scene import Scene
from frustum.shading import Material


@pytest.mark.parametrize("cull", [True, False])
def test_tiles_of_several_blocks_with_clipped_records_equal_reference(cull):
    scene = Scene(lights=[LIGHT])
    scene.add(sphere_mesh(5), material=Material(color=(0.8, 0.5, 0.3)))
    camera = Camera.look_at((0.0, 0.3, 1.5), (0.0, 0.0, 0.0), (0, 1, 0), projection=Perspective(1.2, 0.6, 30.0),
                            width=96, height=64)  # fmt: skip
    binned = bin_item(scene.items[0], camera, cull=cull)
    per_tile = np.diff(binned.tile_starts)
    assert per_tile.max() > 2 * FILL_BLOCK  # a tile of three blocks or more: the blocks are exercised
    assert (binned.tile_entries < 0).any()  # clipped records among the entries (the near plane cuts the sphere)
    frame = render(scene, camera, background=BACKGROUND, cull_back_faces=cull)
    color, depth = reference_render(scene, camera, background=BACKGROUND, cull_back_faces=cull)
    assert (frame.depth < 1.0).mean() > 0.3
    np.testing.assert_array_equal(frame.depth, depth)
    np.testing.assert_array_equal(frame.color, color)
