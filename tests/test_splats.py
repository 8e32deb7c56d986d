"""Gaussian splats against a per-pixel NumPy reference written here from the 3DGS paper's equations (Kerbl et al.
2023; no tiles, no bounds), one Gaussian's screen covariance by hand, an opaque plane cutting a splat cloud, and
the 3DGS PLY reader.

gsplat's PyTorch reference functions are not compared: gsplat needs PyTorch, which is not a test dependency."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation
from tests.testdata import DATA

from frustum import Camera, GaussianSplats, Perspective, render
from frustum.errors import GeometryError
from frustum.geometry import Mesh
from frustum.geometry.points import PointStyle
from frustum.raster import splats as kernels
from frustum.render.splats import project, splat_layer
from frustum.scene import PointItem, Scene
from frustum.shading import Material

WIDTH, HEIGHT = 48, 36
NEAR, FAR = 0.2, 30.0

# the real spherical harmonics of the 3DGS reference code, degree 0–3 (its ``sh_utils.py`` constants)
C0 = 0.28209479177387814
C1 = 0.4886025119029199
C2 = [1.0925484305920792, -1.0925484305920792, 0.31539156525252005, -1.0925484305920792, 0.5462742152960396]
C3 = [-0.5900435899266435, 2.890611442640554, -0.4570457994644658, 0.3731763325901154, -0.4570457994644658,
      1.445305721320277, -0.5900435899266435]  # fmt: skip


def sh_basis(d: np.ndarray, count: int) -> np.ndarray:
    x, y, z = d
    basis = [C0, -C1 * y, C1 * z, -C1 * x,
             C2[0] * x * y, C2[1] * y * z, C2[2] * (2 * z * z - x * x - y * y), C2[3] * x * z, C2[4] * (x * x - y * y),
             C3[0] * y * (3 * x * x - y * y), C3[1] * x * y * z, C3[2] * y * (4 * z * z - x * x - y * y),
             C3[3] * z * (2 * z * z - 3 * x * x - 3 * y * y), C3[4] * x * (4 * z * z - x * x - y * y),
             C3[5] * z * (x * x - y * y), C3[6] * x * (x * x - 3 * y * y)]  # fmt: skip
    return np.array(basis[:count])


def camera_axes(cam: Camera) -> tuple[np.ndarray, np.ndarray, float, float]:
    """World → camera rotation and translation in 3DGS's axes (x right, y down, z forward), and fx, fy."""
    view = np.asarray(cam.view_matrix)
    flip = np.diag([1.0, -1.0, -1.0])
    fy = HEIGHT / 2 / math.tan(cam.projection.fovy / 2)
    return flip @ view[:3, :3], flip @ view[:3, 3], fy, fy  # square pixels: fx = fy


def screen_gaussians(splats: GaussianSplats, cam: Camera) -> list[tuple]:
    """Per visible splat, sorted front to back: (depth z, mean (u, v), Σ′ (2, 2), opacity, colour (3))."""
    rotation, translation, fx, fy = camera_axes(cam)
    eye = np.asarray(cam.frame.eye)
    result = []
    for k in range(splats.count):
        p = splats.positions[k]
        t = rotation @ p + translation
        z = t[2]
        if not NEAR <= z <= FAR:  # culled: behind the camera, before the near plane or beyond the far one
            continue
        r = Rotation.from_quat(splats.rotations[k], scalar_first=True).as_matrix()
        s = np.diag(splats.scales[k])
        sigma = r @ s @ s.T @ r.T
        j = np.array([[fx / z, 0.0, -fx * t[0] / z**2], [0.0, fy / z, -fy * t[1] / z**2]])
        cov = j @ rotation @ sigma @ rotation.T @ j.T + 0.3 * np.eye(2)
        mean = np.array([fx * t[0] / z + WIDTH / 2, fy * t[1] / z + HEIGHT / 2])
        d = (p - eye) / np.linalg.norm(p - eye)
        color = np.maximum(sh_basis(d, splats.sh.shape[1]) @ splats.sh[k].astype(np.float64) + 0.5, 0.0)
        result.append((z, mean, cov, splats.opacities[k], color))
    result.sort(key=lambda g: g[0])
    return result


def reference(splats: GaussianSplats, cam: Camera, opaque_depth: np.ndarray | None = None):
    """(H, W, 3) Σ cᵢαᵢTᵢ and (H, W) T per pixel centre, all splats front to back (3DGS §6 equations, no tiles)."""
    cols, rows = np.meshgrid(np.arange(WIDTH) + 0.5, np.arange(HEIGHT) + 0.5)
    color = np.zeros((HEIGHT, WIDTH, 3))
    transmittance = np.ones((HEIGHT, WIDTH))
    active = np.ones((HEIGHT, WIDTH), dtype=bool)
    for z, mean, cov, opacity, c in screen_gaussians(splats, cam):
        if opaque_depth is not None:  # window depth of the centre against the opaque surface's
            window_z = ((FAR + NEAR) / (FAR - NEAR) - 2 * FAR * NEAR / ((FAR - NEAR) * z) + 1) / 2
            active &= np.float32(window_z) < opaque_depth
        conic = np.linalg.inv(cov)
        dx, dy = cols - mean[0], rows - mean[1]
        power = -0.5 * (conic[0, 0] * dx * dx + 2 * conic[0, 1] * dx * dy + conic[1, 1] * dy * dy)
        alpha = np.minimum(0.99, opacity * np.exp(power))
        use = active & (alpha >= 1 / 255)
        after = transmittance * (1 - alpha)
        stop = use & (after < 1e-4)
        active &= ~stop
        use &= ~stop
        color += np.where(use[..., None], c * (alpha * transmittance)[..., None], 0.0)
        transmittance = np.where(use, after, transmittance)
    return color, transmittance


def random_splats(seed: int, count: int, degree: int) -> GaussianSplats:
    rng = np.random.default_rng(seed)
    k = (degree + 1) ** 2
    sh = rng.normal(size=(count, k, 3)) * 0.3
    sh[:, 0, :] = rng.normal(size=(count, 3)) * 1.2
    return GaussianSplats(rng.uniform(-1, 1, size=(count, 3)), np.exp(rng.uniform(-3.5, -1.0, size=(count, 3))),
                          rng.normal(size=(count, 4)) + 1e-3, rng.uniform(0.05, 1.0, size=count), sh)  # fmt: skip


def random_camera(seed: int, inside: bool) -> Camera:
    rng = np.random.default_rng(seed + 1)
    if inside:  # among the splats, looking anywhere: some lie behind the camera and are culled
        eye = rng.uniform(-0.3, 0.3, size=3)
        target = eye + rng.normal(size=3)
    else:
        direction = rng.normal(size=3)
        eye = direction / np.linalg.norm(direction) * rng.uniform(2.5, 5.0)
        target = rng.uniform(-0.2, 0.2, size=3)
    up = (0.0, 1.0, 0.0) if abs((target - eye)[1]) < 0.9 * np.linalg.norm(target - eye) else (1.0, 0.0, 0.0)
    return Camera.look_at(eye, target, up, projection=Perspective(math.radians(rng.uniform(40, 80)), NEAR, FAR),
                          width=WIDTH, height=HEIGHT)  # fmt: skip


def item(splats: GaussianSplats) -> PointItem:
    return PointItem(splats, Material(), np.eye(4), PointStyle("splats", None, None))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31), count=st.integers(1, 30), degree=st.integers(0, 3), inside=st.booleans())
def test_splats_match_the_per_pixel_reference(seed, count, degree, inside):
    splats = random_splats(seed, count, degree)
    cam = random_camera(seed, inside)
    expected_color, expected_t = reference(splats, cam)
    layer = splat_layer([item(splats)], cam)
    scene = Scene()
    scene.add(splats)
    frame = render(scene, cam, background=(0, 0, 0, 0))
    expected_bytes = np.floor(np.clip(expected_color, 0, 1) * 255 + 0.5)
    # the bound holds every pixel with α >= 1/255 (raster.splats): left are float32 sums and pixels where the
    # floating-point α lies on either side of 1/255 or T of 1e-4
    assert (np.abs(frame.color[..., :3].astype(int) - expected_bytes).max(axis=2) <= 3).mean() >= 0.99
    assert (np.abs(layer.transmittance - expected_t) <= 1e-3).mean() >= 0.99
    alpha = np.floor((1 - layer.transmittance) * 255 + 0.5)
    assert np.array_equal(frame.color[..., 3], alpha.astype(np.uint8))


def test_one_gaussian_screen_covariance_is_j_w_sigma_wt_jt_plus_dilation():
    splats = GaussianSplats([[0.3, -0.2, 0.4]], [[0.3, 0.05, 0.12]], [[0.9, 0.2, -0.3, 0.25]], [0.7],
                            np.zeros((1, 1, 3)))  # fmt: skip
    cam = Camera.look_at((1.0, 0.5, 3.0), (0, 0, 0), (0, 1, 0), projection=Perspective(0.9, NEAR, FAR),
                         width=WIDTH, height=HEIGHT)  # fmt: skip
    rotation, translation, fx, fy = camera_axes(cam)
    t = rotation @ splats.positions[0] + translation
    j = np.array([[fx / t[2], 0, -fx * t[0] / t[2] ** 2], [0, fy / t[2], -fy * t[1] / t[2] ** 2]])
    w = rotation
    r = Rotation.from_quat(splats.rotations[0], scalar_first=True).as_matrix()
    sigma = r @ np.diag(splats.scales[0] ** 2) @ r.T
    expected = j @ w @ sigma @ w.T @ j.T + 0.3 * np.eye(2)
    record = project([item(splats)], cam)[0]
    a, b, c = record[kernels.F_COV : kernels.F_COV + 3]
    np.testing.assert_allclose([[a, b], [b, c]], expected, rtol=1e-9, atol=1e-12)
    # the conic is its inverse, in window axes (y up: the off-diagonal changes sign)
    conic = record[kernels.F_CONIC : kernels.F_CONIC + 3]
    inverse = np.linalg.inv(expected)
    np.testing.assert_allclose(conic, [inverse[0, 0], -inverse[0, 1], inverse[1, 1]], rtol=1e-9)
    np.testing.assert_allclose(splats.covariances[0], sigma, rtol=1e-12, atol=1e-15)


def test_an_opaque_plane_cuts_a_splat_cloud_where_depth_says():
    splats = random_splats(11, 40, 1)
    cam = Camera.look_at((0.4, 0.3, 4.0), (0, 0, 0), (0, 1, 0), projection=Perspective(0.8, NEAR, FAR), width=WIDTH,
                         height=HEIGHT)  # fmt: skip
    plane = Mesh([[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], [[0, 1, 2], [0, 2, 3]])
    alone = Scene()
    alone.add(plane, Material(color=(0.2, 0.4, 0.6)))
    under = render(alone, cam, shading="none")
    both = Scene()
    both.add(plane, Material(color=(0.2, 0.4, 0.6)))
    both.add(splats)
    frame = render(both, cam, shading="none")
    color, t = reference(splats, cam, under.depth)
    expected = np.floor(np.clip(color + t[..., None] * under.color[..., :3] / 255, 0, 1) * 255 + 0.5)
    assert (np.abs(frame.color[..., :3].astype(int) - expected).max(axis=2) <= 3).mean() >= 0.99
    uncut, _ = reference(splats, cam)
    assert (np.abs(uncut - color).max(axis=2) > 0.05).sum() > 50  # the plane does hide splats behind it
    # where splats contribute the depth is their expected depth, in front of the plane
    seen = frame.depth < under.depth
    assert seen.sum() > 100 and (frame.depth <= under.depth).all()


def test_splats_behind_an_opaque_plane_leave_it_unchanged():
    splats = GaussianSplats([[0.0, 0.0, -1.0]], [[0.4, 0.4, 0.4]], [[1, 0, 0, 0]], [0.9], np.ones((1, 1, 3)))
    cam = Camera.look_at((0, 0, 4.0), (0, 0, 0), (0, 1, 0), projection=Perspective(0.8, NEAR, FAR), width=WIDTH,
                         height=HEIGHT)  # fmt: skip
    plane = Mesh([[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], [[0, 1, 2], [0, 2, 3]])
    alone = Scene()
    alone.add(plane)
    both = Scene()
    both.add(plane)
    both.add(splats)
    assert np.array_equal(render(both, cam).color, render(alone, cam).color)


def test_expected_depth_of_one_opaque_splat_is_its_centre_depth():
    splats = GaussianSplats([[0.0, 0.0, 0.5]], [[0.3, 0.3, 0.3]], [[1, 0, 0, 0]], [1.0], np.ones((1, 1, 3)))
    cam = Camera.look_at((0, 0, 4.0), (0, 0, 0), (0, 1, 0), projection=Perspective(0.8, NEAR, FAR), width=WIDTH,
                         height=HEIGHT)  # fmt: skip
    scene = Scene()
    scene.add(splats)
    frame = render(scene, cam)
    z = 3.5
    window_z = ((FAR + NEAR) / (FAR - NEAR) - 2 * FAR * NEAR / ((FAR - NEAR) * z) + 1) / 2
    seen = frame.depth < 1
    assert seen.sum() > 50
    np.testing.assert_allclose(frame.depth[seen], window_z, rtol=1e-6)


# --- the 3DGS PLY layout -----------------------------------------------------------------------------------------


def test_the_torus_file_loads_as_documented_and_renders():
    splats = GaussianSplats.load(DATA / "splats" / "torus.ply")
    assert splats.count == 512 and splats.degree == 1
    np.testing.assert_allclose(splats.scales[0], [0.12, 0.05, 0.05], rtol=1e-6)
    np.testing.assert_allclose(splats.opacities, 0.8, rtol=1e-6)
    np.testing.assert_allclose(splats.sh[:, 3, 0], 0.3, rtol=1e-6)
    scene = Scene()
    scene.add(splats)
    cam = Camera.look_at((0, -2.5, 2.5), (0, 0, 0), (0, 0, 1), projection=Perspective(0.9, NEAR, FAR), width=WIDTH,
                         height=HEIGHT)  # fmt: skip
    assert (render(scene, cam).depth < 1).mean() > 0.2


def test_save_and_load_round_trip(tmp_path):
    splats = random_splats(3, 20, 3)
    again = GaussianSplats.load(splats.save(tmp_path / "s.ply"))
    np.testing.assert_allclose(again.positions, splats.positions, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(again.scales, splats.scales, rtol=1e-5)
    np.testing.assert_allclose(again.rotations, splats.rotations, atol=1e-6)
    np.testing.assert_allclose(again.opacities, splats.opacities, rtol=1e-5)
    np.testing.assert_array_equal(again.sh, splats.sh)


def test_missing_fields_are_named(tmp_path):
    path = tmp_path / "partial.ply"
    names = ["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "rot_0"]
    header = "ply\nformat binary_little_endian 1.0\nelement vertex 1\n" + "".join(f"property float {n}\n"
                                                                                 for n in names) + "end_header\n"
    path.write_bytes(header.encode() + np.zeros(len(names), dtype="<f4").tobytes())
    with pytest.raises(GeometryError, match="lacks the 3DGS vertex properties scale_2, rot_1, rot_2, rot_3"):
        GaussianSplats.load(path)


def test_a_file_of_1e8_splats_is_refused_before_reading(tmp_path):
    names = ["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2",
             "rot_0", "rot_1", "rot_2", "rot_3"]  # fmt: skip
    path = tmp_path / "huge.ply"  # the header alone: reading the data would fail as truncated, not by the budget
    path.write_text("ply\nformat binary_little_endian 1.0\nelement vertex 100000000\n"
                    + "".join(f"property float {n}\n" for n in names) + "end_header\n")  # fmt: skip
    with pytest.raises(GeometryError, match=r"100000000 vertices.*over the memory budget"):
        GaussianSplats.load(path)


def test_bad_splat_arrays_are_refused():
    with pytest.raises(GeometryError, match="scales"):
        GaussianSplats([[0, 0, 0]], [[0.1, 0.0, 0.1]], [[1, 0, 0, 0]], [0.5], np.zeros((1, 1, 3)))
    with pytest.raises(GeometryError, match="opacities"):
        GaussianSplats([[0, 0, 0]], [[0.1, 0.1, 0.1]], [[1, 0, 0, 0]], [1.5], np.zeros((1, 1, 3)))
    with pytest.raises(GeometryError, match="K = 1, 4, 9 or 16"):
        GaussianSplats([[0, 0, 0]], [[0.1, 0.1, 0.1]], [[1, 0, 0, 0]], [0.5], np.zeros((1, 2, 3)))
    with pytest.raises(GeometryError, match="drawn by their own covariances"):
        Scene().add(random_splats(0, 2, 0), style="sphere")
