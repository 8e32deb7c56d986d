"""The octree scene of ``examples/octree.toml`` drawn twice, side by side: by the octree visible-surface method
(front-to-back octants, each pixel written once) and by the depth buffer (the octree's cell faces,
``Octree.to_mesh``, flat-shaded). The two agree pixel for pixel in coverage and depth (``tests/test_octree.py``).

    python examples/octree.py [OUT] [--width W] [--height H]      (default OUT: docs/gallery/octree.png)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image

import frustum as fr

HERE = Path(__file__).resolve().parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default=str(HERE.parent / "docs" / "gallery" / "octree.png"))
    parser.add_argument("--width", type=int, default=240)
    parser.add_argument("--height", type=int, default=180)
    args = parser.parse_args()
    scene_file = fr.load_scene_file(HERE / "octree.toml").resized((args.width, args.height))
    camera = scene_file.cameras[0]
    background = scene_file.options["background"]
    by_octree = fr.render(scene_file.scene, camera, method="octree", background=background)
    by_depth_buffer = fr.render(scene_file.scene, camera, shading="flat", background=background)
    Image.fromarray(np.concatenate([by_octree.color, by_depth_buffer.color], axis=1), mode="RGBA").save(args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
