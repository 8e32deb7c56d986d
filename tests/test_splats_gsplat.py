"""Splats against gsplat's PyTorch reference functions (``gsplat.cuda._torch_impl``), where they import on the CPU.

gsplat's rasterizer is CUDA; its pure-PyTorch reference functions cover the projection
(``_quat_scale_to_covar_preci``, ``_fully_fused_projection``: EWA with the 0.3-pixel dilation) and the colour
(``_spherical_harmonics``), and run on a CPU build of torch. Its compositing reference (``_rasterize_to_pixels``)
calls the CUDA kernel ``rasterize_to_indices_in_range`` and ``accumulate`` needs nerfacc's CUDA scan, so the
compositing here is the rule of gsplat's CUDA kernel written in the test: front to back by camera depth,
$α = min(0.99, o·exp(−σ))$, skipped below 1/255, stop before T < 1e-4. Skipped when torch or gsplat is missing
(neither is a dependency of frustum: ``pip install torch gsplat``).

gsplat, like the 3DGS code, clamps the centre to 1.3 × the field of view before taking the Jacobian (for splats far
outside the image); frustum does not, so the projection is compared on splats whose centres lie inside that
limit."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tests.test_splats import HEIGHT, WIDTH, camera_axes, item, random_camera, random_splats

from frustum import Camera, GaussianSplats, render
from frustum.raster import splats as kernels
from frustum.render.splats import project, splat_layer
from frustum.scene import Scene

torch = pytest.importorskip("torch")
reference = pytest.importorskip("gsplat.cuda._torch_impl")


def gsplat_projection(splats: GaussianSplats, cam: Camera) -> dict[str, np.ndarray]:
    """gsplat's per-splat 2-D mean (x right, y down, pixel centres at +0.5), conic, camera depth, radius and colour."""
    rotation, translation, fx, fy = camera_axes(cam)
    viewmat = np.eye(4)
    viewmat[:3, :3], viewmat[:3, 3] = rotation, translation
    ks = np.array([[fx, 0.0, WIDTH / 2], [0.0, fy, HEIGHT / 2], [0.0, 0.0, 1.0]])
    t = torch.float64
    means = torch.tensor(splats.positions, dtype=t)
    covars, _ = reference._quat_scale_to_covar_preci(torch.tensor(splats.rotations, dtype=t),
                                                     torch.tensor(splats.scales, dtype=t), True, False)  # fmt: skip
    radii, means2d, depths, conics, _ = reference._fully_fused_projection(
        means, covars, torch.tensor(viewmat[None], dtype=t), torch.tensor(ks[None], dtype=t), WIDTH, HEIGHT,
        eps2d=0.3, near_plane=cam.projection.near, far_plane=cam.projection.far,
    )  # fmt: skip
    eye = torch.tensor(np.asarray(cam.frame.eye), dtype=t)
    degree = round(math.sqrt(splats.sh.shape[1])) - 1
    colors = reference._spherical_harmonics(degree, means - eye, torch.tensor(splats.sh, dtype=t))
    colors = torch.clamp_min(colors + 0.5, 0.0)  # gsplat.rendering.rasterization's SH colour
    camera_points = splats.positions @ rotation.T + translation
    tan_x, tan_y = 0.5 * WIDTH / fx, 0.5 * HEIGHT / fy
    unclamped = (np.abs(camera_points[:, 0] / camera_points[:, 2]) < tan_x * 1.3) & (
        np.abs(camera_points[:, 1] / camera_points[:, 2]) < tan_y * 1.3)  # fmt: skip
    return {"mean": means2d[0].numpy(), "conic": conics[0].numpy(), "depth": depths[0].numpy(),
            "radius": radii[0].numpy(), "color": colors.numpy(), "unclamped": unclamped}  # fmt: skip


def composite(g: dict[str, np.ndarray], opacities: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(H, W, 3) Σ cᵢαᵢTᵢ and (H, W) T of gsplat's projected splats (its CUDA kernel's rule, module docstring)."""
    cols, rows = np.meshgrid(np.arange(WIDTH) + 0.5, np.arange(HEIGHT) + 0.5)
    color = np.zeros((HEIGHT, WIDTH, 3))
    transmittance = np.ones((HEIGHT, WIDTH))
    active = np.ones((HEIGHT, WIDTH), dtype=bool)
    for k in np.argsort(g["depth"], kind="stable"):
        if not g["radius"][k].any():
            continue
        a, b, c = g["conic"][k]
        dx, dy = cols - g["mean"][k, 0], rows - g["mean"][k, 1]
        sigma = 0.5 * (a * dx * dx + c * dy * dy) + b * dx * dy
        alpha = np.minimum(0.99, opacities[k] * np.exp(-sigma))
        use = active & (sigma >= 0) & (alpha >= 1 / 255)
        after = transmittance * (1 - alpha)
        stop = use & (after < 1e-4)
        active &= ~stop
        use &= ~stop
        color += np.where(use[..., None], g["color"][k] * (alpha * transmittance)[..., None], 0.0)
        transmittance = np.where(use, after, transmittance)
    return color, transmittance


@pytest.mark.parametrize("seed, degree", [(11, 0), (12, 1), (13, 2), (14, 3), (15, 3)])
def test_splats_match_gsplats_torch_reference(seed, degree):
    splats = random_splats(seed, 40, degree)
    cam = random_camera(seed, inside=False)
    g = gsplat_projection(splats, cam)
    records = project([item(splats)], cam)
    drawn = (records[:, kernels.F_RADIUS] > 0) & (g["radius"].max(axis=1) > 0) & g["unclamped"]
    assert drawn.sum() >= 10
    # per splat: the 2-D mean, the screen covariance Σ' (image axes) and the view-dependent colour
    mean = np.c_[records[:, kernels.F_X], HEIGHT - records[:, kernels.F_Y]]
    np.testing.assert_allclose(mean[drawn], g["mean"][drawn], rtol=0, atol=1e-9)
    a, b, c = g["conic"][drawn].T
    det = a * c - b * b
    theirs = np.c_[c / det, -b / det, a / det]  # Σ' = conic⁻¹
    np.testing.assert_allclose(records[drawn, kernels.F_COV : kernels.F_COV + 3], theirs, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(records[drawn, kernels.F_COLOR : kernels.F_COLOR + 3], g["color"][drawn], atol=1e-12)
    # the frame: colour within 3/255 on >= 99 % of the pixels, alpha within 1e-3
    expected_color, expected_t = composite(g, splats.opacities)
    scene = Scene()
    scene.add(splats)
    frame = render(scene, cam, background=(0, 0, 0, 0))
    expected_bytes = np.floor(np.clip(expected_color, 0, 1) * 255 + 0.5)
    assert (np.abs(frame.color[..., :3].astype(int) - expected_bytes).max(axis=2) <= 3).mean() >= 0.99
    layer = splat_layer([item(splats)], cam)
    assert (np.abs(layer.transmittance - expected_t) <= 1e-3).mean() >= 0.99
