"""The Utah teapot from its 32 Bezier patches, with the control net and a curve with its control polygon.

    python examples/teapot.py teapot.png [--width 640 --height 480]
"""

from __future__ import annotations

import argparse
import math

import frustum
from frustum.geometry import Polyline


def build_scene() -> frustum.Scene:
    """The tessellated teapot (z up in the patch data, turned y up), its control net, and a cubic Bezier."""
    patches = frustum.teapot()
    upright = frustum.rotate_x(-math.pi / 2)
    scene = frustum.Scene(lights=[frustum.DirectionalLight(direction=(-0.4, -1.0, -0.6)), frustum.AmbientLight()])
    scene.add(patches.tessellate(12), frustum.Material(color=(0.85, 0.35, 0.2)), upright, name="teapot")
    scene.add(Polyline.from_segments(patches.control_net()), frustum.Material(color=(0.1, 0.6, 0.9)), upright,
              name="control net")  # fmt: skip
    curve = frustum.BezierCurve([[-3.5, 0.0, 2.0], [-2.5, 2.5, 2.0], [2.5, -1.0, 2.0], [3.5, 1.0, 2.0]])
    scene.add(Polyline.from_curve(curve, tolerance=1e-3), frustum.Material(color=(0.9, 0.75, 0.1)), name="curve")
    scene.add(Polyline.control_polygon(curve), frustum.Material(color=(0.5, 0.5, 0.5)), name="control polygon")
    scene.add(Polyline.control_polygon(curve, markers=True), frustum.Material(color=(0.8, 0.1, 0.1)), name="points")
    return scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output", help="PNG path")
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    args = parser.parse_args()
    camera = frustum.Camera.look_at((5.0, 5.5, 8.0), (0.0, 1.0, 0.0), (0, 1, 0), width=args.width, height=args.height)
    frame = frustum.render(build_scene(), camera, cull_back_faces=False, samples=4, background=(1, 1, 1, 1))
    frame.save(args.output)
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
