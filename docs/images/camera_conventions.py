"""Draws camera_conventions.svg (docs/camera-conventions.md): the camera axes of OpenGL and OpenCV, and where
each convention puts the pixel centres. Run: python docs/images/camera_conventions.py (needs matplotlib)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.patches import FancyArrowPatch, Polygon, Rectangle

OUT = Path(__file__).with_suffix(".svg")
# a fixed oblique drawing of 3-D axes: x to the right, y up, z toward the viewer (down-left on the page)
PROJECT = {"x": (1.0, 0.0), "y": (0.0, 1.0), "z": (-0.55, -0.45)}


def _arrow(ax, start, end, color, label, offset=(0.06, 0.06)):
    ax.add_patch(FancyArrowPatch(start, end, arrowstyle="-|>", mutation_scale=14, lw=1.8, color=color))
    ax.text(end[0] + offset[0], end[1] + offset[1], label, color=color, fontsize=11)


def _camera(ax, title, axes, note):
    """A camera body at the origin, its three axes and its viewing direction."""
    ax.set_title(title, fontsize=11)
    body = Polygon([(-0.18, -0.12), (0.18, -0.12), (0.18, 0.12), (-0.18, 0.12)], closed=True, color="0.85")
    ax.add_patch(body)
    colors = {"x": "tab:red", "y": "tab:green", "z": "tab:blue"}
    for name, sign in axes.items():  # the camera's +axis drawn along the page's ±axis
        dx, dy = PROJECT[name]
        _arrow(ax, (0, 0), (sign * dx, sign * dy), colors[name], f"+{name}")
    dx, dy = PROJECT["z"]
    s = -1.0  # both look into the page
    ax.add_patch(FancyArrowPatch((0, 0), (1.6 * s * dx, 1.6 * s * dy), arrowstyle="-|>", mutation_scale=12,
                                 lw=1.0, ls="--", color="0.3"))  # fmt: skip
    ax.text(1.6 * s * dx + 0.08, 1.6 * s * dy + 0.02, "looking", color="0.3", fontsize=9)
    ax.text(-1.1, -1.45, note, fontsize=9, va="top")
    ax.set_xlim(-1.3, 1.9)
    ax.set_ylim(-1.6, 1.3)
    ax.set_aspect("equal")
    ax.axis("off")


def _pixels(ax):
    """A 3 x 2 pixel image: frustum's window (y up, centres at +0.5), continuous u, v (COLMAP, nerfstudio,
    pyrender, frustum's K: v down, centres at +0.5) and OpenCV's pixel indices (centres at integers)."""
    ax.set_title("pixel coordinates of a 3 × 2 image", fontsize=11)
    for i in range(3):
        for j in range(2):
            ax.add_patch(Rectangle((i, j), 1, 1, fill=False, lw=1.0, color="0.4"))
            ax.plot(i + 0.5, j + 0.5, "o", color="0.2", ms=3)
    ax.annotate("", xy=(3.4, 2.0), xytext=(0.0, 2.0), arrowprops=dict(arrowstyle="-|>", color="tab:purple"))
    ax.annotate("", xy=(0.0, -0.4), xytext=(0.0, 2.0), arrowprops=dict(arrowstyle="-|>", color="tab:purple"))
    ax.text(3.45, 2.0, "u", color="tab:purple")
    ax.text(0.05, -0.55, "v", color="tab:purple")
    ax.text(0.55, 1.52, "(0.5, 0.5)", fontsize=8)
    ax.annotate("", xy=(3.4, 0.0), xytext=(0.0, 0.0), arrowprops=dict(arrowstyle="-|>", color="tab:orange"))
    ax.annotate("", xy=(-0.0, 2.4), xytext=(0.0, 0.0), arrowprops=dict(arrowstyle="-|>", color="tab:orange"))
    ax.text(3.45, -0.2, "x_w", color="tab:orange")
    ax.text(-0.35, 2.45, "y_w", color="tab:orange")
    ax.text(0.55, 0.3, "(0.5, 0.5)", fontsize=8, color="tab:orange")
    ax.text(
        -0.3, -0.9,
        "purple: K's u, v (COLMAP, nerfstudio, pyrender, frustum):\n  top-left pixel centre (0.5, 0.5)\n"
        "OpenCV: the same u, v, but pixel centres at integers:\n  top-left pixel (0, 0)\n"
        "orange: frustum's window x, y (y up), centres at +0.5",
        fontsize=9, va="top",
    )  # fmt: skip
    ax.set_xlim(-0.6, 4.0)
    ax.set_ylim(-2.6, 2.8)
    ax.set_aspect("equal")
    ax.axis("off")


def main() -> None:
    figure, axes = plt.subplots(1, 3, figsize=(12, 4.2))
    _camera(axes[0], "OpenGL axes\n(frustum, nerfstudio, Blender, pyrender)", {"x": 1, "y": 1, "z": 1},
            "x right, y up, looking down −z\nconvention=\"opengl\"")  # fmt: skip
    _camera(axes[1], "OpenCV axes\n(COLMAP, cv2)", {"x": 1, "y": -1, "z": -1},
            "x right, y down, looking down +z\nconvention=\"opencv\" (the default)\n"
            "camera_cv = diag(1, −1, −1) · camera_gl")  # fmt: skip
    _pixels(axes[2])
    figure.tight_layout()
    figure.savefig(OUT, metadata={"Date": None})
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
