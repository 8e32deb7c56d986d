"""Volumes, transfer functions, the ray caster (against a per-pixel numpy reference) and isosurfaces."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.ndimage import map_coordinates

import frustum as f
from frustum.errors import FrustumError, GeometryError
from frustum.geometry.quadrics import sphere_implicit
from frustum.geometry.volume import TransferFunction, Volume, blobby_volume, fbm_cloud, quaternion_julia_volume
from frustum.render.volumes import TERMINATE

# --- an independent per-pixel reference ---------------------------------------------------------------------


def _reference(volume, tf, mode, camera, *, step, world_from_model=None, level=0.5, shade=False, lights=(),
               material=None, planes=(), under=None, depth=None, sampling="entry"):  # fmt: skip
    """(H, W, 4) uint8 by the textbook recipe, one pixel at a time: rays from ``Camera.unproject``, scipy's
    trilinear ``map_coordinates``, the exact transfer function, samples at segment middles from the entry
    (sampling "entry") or at whole steps from the near plane (sampling "near"), no skipping and no early
    termination (TERMINATE leaves under half a level), ``shading.illuminate`` for shading."""
    h, w = camera.height, camera.width
    world_from_model = np.eye(4) if world_from_model is None else world_from_model
    world_from_grid = world_from_model @ volume.model_from_grid
    grid_from_world = np.linalg.inv(world_from_grid)
    data = volume.data.astype(np.float64)
    limit = np.array(volume.shape, dtype=np.float64) - 1.0
    material = f.Material() if material is None else material
    out = np.tile([0.0, 0.0, 0.0, 1.0], (h, w, 1)) if under is None else under.astype(np.float64) / 255.0
    unit = float(volume.spacing.min())

    def to_grid(points):
        return points @ grid_from_world[:3, :3].T + grid_from_world[:3, 3]

    def sample(u):
        return map_coordinates(data, np.clip(u, 0.0, limit).T, order=1, mode="nearest")

    for row in range(h):
        for column in range(w):
            x, y = column + 0.5, h - 1 - row + 0.5
            near, far = camera.unproject([[x, y, 0.0], [x, y, 1.0]])
            a, b = to_grid(near), to_grid(far)
            d = b - a
            s0, s1 = 0.0, 1.0
            for axis in range(3):
                if d[axis] == 0.0:
                    if not 0.0 <= a[axis] <= limit[axis]:
                        s0, s1 = 1.0, 0.0
                    continue
                t = sorted(((0.0 - a[axis]) / d[axis], (limit[axis] - a[axis]) / d[axis]))
                s0, s1 = max(s0, t[0]), min(s1, t[1])
            for point, normal in planes:  # keep n·(P − p) <= 0
                pa, pb = (near - point) @ normal, (far - point) @ normal
                if pa == pb:
                    if pa > 0:
                        s0, s1 = 1.0, 0.0
                elif pb > pa:
                    s1 = min(s1, pa / (pa - pb))
                else:
                    s0 = max(s0, pa / (pa - pb))
            if depth is not None and depth[row, column] < 1.0:
                q = to_grid(camera.unproject([x, y, float(depth[row, column])]))
                s1 = min(s1, float((q - a) @ d / (d @ d)))
            if not s0 < s1:
                continue
            length = float(np.linalg.norm(volume.model_from_grid[:3, :3] @ d))
            ds = step / length
            if sampling == "near":  # s = 0 is the ray's point on the near plane
                s = np.arange(math.ceil(s0 / ds), math.floor(s1 / ds) + 1) * ds
                count, seg = s.size, np.full(s.size, ds)
                if count == 0:
                    continue
            else:
                count = math.ceil((s1 - s0) / ds)
                last = (s1 - s0) - (count - 1) * ds
                s = np.append(s0 + (np.arange(count - 1) + 0.5) * ds, s0 + (count - 1) * ds + 0.5 * last)
                seg = np.append(np.full(count - 1, ds), last)
            u = a + s[:, None] * d
            values = sample(u)
            view = -(world_from_grid[:3, :3] @ d)
            view /= np.linalg.norm(view)

            def lit(point_grid, base, view=view):
                g = np.array([sample((point_grid + e)[None])[0] - sample((point_grid - e)[None])[0] for e in np.eye(3)])
                normal = -(np.linalg.inv(world_from_grid[:3, :3]).T @ g)
                if not np.linalg.norm(normal) > 1e-12:
                    return base
                if normal @ view < 0:
                    normal = -normal
                world = world_from_grid[:3, :3] @ point_grid + world_from_grid[:3, 3]
                return f.illuminate(material, list(lights), world, normal, camera.frame.eye, base_color=base)

            under_rgba = out[row, column].copy()
            if mode == "composite":
                rgba = tf(values)
                color, acc = np.zeros(3), 0.0
                for i in range(count):
                    alpha = 1.0 - (1.0 - rgba[i, 3]) ** (seg[i] * length / unit)
                    if rgba[i, 3] <= 0.0:
                        continue
                    base = rgba[i, :3]
                    if shade:
                        base = lit(u[i], base)
                    color += (1.0 - acc) * alpha * base
                    acc += (1.0 - acc) * alpha
                result = np.append(color, acc)
            elif mode == "isosurface":
                sv = np.concatenate([[s0], s, [s1]])
                fv = np.concatenate([sample(a[None] + s0 * d[None]), values, sample(a[None] + s1 * d[None])]) - level
                crossing = np.flatnonzero((fv[1:] == 0) | ((fv[1:] > 0) != (fv[:-1] > 0)))
                if crossing.size == 0:
                    continue
                lo, hi, flo = sv[crossing[0]], sv[crossing[0] + 1], fv[crossing[0]]
                for _ in range(40):
                    mid = 0.5 * (lo + hi)
                    fm = sample((a + mid * d)[None])[0] - level
                    if (fm > 0) == (flo > 0) and fm != 0:
                        lo, flo = mid, fm
                    else:
                        hi = mid
                hit = a + 0.5 * (lo + hi) * d
                result = np.append(lit(hit, tf(level)[:3]), 1.0)
            else:
                if mode == "mip":
                    value = values.max()
                elif mode == "minip":
                    value = values.min()
                else:
                    value = (values * seg).sum() / seg.sum()
                rgba = tf(value)
                result = np.append(rgba[3] * rgba[:3], rgba[3])
            out[row, column] = result + (1.0 - result[3]) * under_rgba
    return np.floor(np.clip(out, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)


def _phantom(n=24):
    """A CT-like phantom: an ellipsoidal shell, a dense inner ball and a soft background gradient."""
    axis = np.linspace(-1.0, 1.0, n)
    x, y, z = np.meshgrid(axis, axis, axis, indexing="ij")
    r = np.sqrt((x / 0.9) ** 2 + (y / 0.75) ** 2 + (z / 0.8) ** 2)
    data = 0.15 * (1 - r).clip(0) + 0.6 * np.exp(-((r - 0.8) ** 2) / 0.01)
    data += 0.9 * np.exp(-((x - 0.2) ** 2 + (y + 0.1) ** 2 + z**2) / 0.04)
    return Volume(data, (2.0 / (n - 1),) * 3, (-1.0, -1.0, -1.0))


_TF = TransferFunction([0.0, 0.1, 0.4, 0.7, 1.0], [(0, 0, 0), (0.9, 0.3, 0.1), (1, 0.8, 0.4), (1, 1, 1), (1, 1, 1)],
                       [0.0, 0.0, 0.15, 0.5, 0.9])  # fmt: skip
_LIGHTS = [f.DirectionalLight(direction=(-1.0, -0.5, -1.0)), f.PointLight(position=(2.0, 3.0, 4.0), intensity=0.6)]


def _render(volume, camera, mode, *, step, tf=_TF, shade=None, level=0.5, transform=None, scene=None, planes=(),
            sampling="entry"):  # fmt: skip
    scene = f.Scene(lights=_LIGHTS) if scene is None else scene
    scene.add_volume(volume, tf, mode=mode, step=step, shade=shade, level=level, transform=transform,
                     clip_planes=planes, sampling=sampling)  # fmt: skip
    return f.render(scene, camera)


def _assert_close(image, expected, tolerance=1):
    difference = np.abs(image.astype(int) - expected.astype(int))
    assert difference.max() <= tolerance, (difference.max(), np.argwhere(difference > tolerance)[:5])
    assert (expected[..., :3].sum(axis=-1) > 0).mean() >= 0.1  # the comparison covers a part of the picture


@pytest.mark.parametrize("mode", ["composite", "mip", "minip", "average", "isosurface"])
def test_kernel_equals_reference_within_one_level_in_every_mode(mode):
    volume = _phantom()
    camera = f.Camera.look_at((1.3, 1.0, 1.8), (0.05, 0.0, 0.0), width=26, height=20)
    tf = _TF if mode != "minip" else TransferFunction([0.0, 0.3], [(1, 1, 1), (0.2, 0.4, 1)], [1.0, 0.3])
    frame = _render(volume, camera, mode, step=0.04, tf=tf, level=0.45)
    expected = _reference(volume, tf, mode, camera, step=0.04, level=0.45, shade=mode == "isosurface",
                          lights=_LIGHTS)  # fmt: skip
    _assert_close(frame.color, expected)
    assert (frame.color != frame.color[0, 0]).any()  # the volume is in the picture


@pytest.mark.parametrize("mode", ["composite", "mip", "average", "isosurface"])
def test_near_plane_sampling_equals_reference_in_every_mode(mode):
    volume = _phantom()
    projection = f.Orthographic(height=2.6, near=0.37, far=20.0)
    camera = f.Camera.look_at((1.3, 1.0, 1.8), (0.05, 0.0, 0.0), projection=projection, width=26, height=20)
    frame = _render(volume, camera, mode, step=0.04, level=0.45, shade=mode != "mip", sampling="near")
    expected = _reference(volume, _TF, mode, camera, step=0.04, level=0.45, shade=mode != "mip", lights=_LIGHTS,
                          sampling="near")  # fmt: skip
    _assert_close(frame.color, expected)
    entry = _render(volume, camera, mode, step=0.04, level=0.45, shade=mode != "mip")
    if mode != "isosurface":  # the samples moved: the picture changes (the isosurface's bisection hides it)
        assert (entry.color != frame.color).any()


def test_near_plane_samples_of_a_parallel_camera_lie_on_the_same_planes_for_every_ray():
    # one plane of ones at z = 0 (a hat of half-width 0.05 in z after trilinear interpolation); the MIP along z with
    # step 0.05 sees 1 where a sample lands on the plane, 0.5 where samples straddle it. Near-plane sampling puts the
    # samples at whole steps from the near plane (3 − near from z = 0), the same on every ray; entry sampling at
    # middles of steps from the box's face z = 1, i.e. straddling z = 0, whatever the near plane
    data = np.zeros((9, 9, 41))
    data[:, :, 20] = 1.0
    volume = Volume(data, (0.25, 0.25, 0.05), (-1.0, -1.0, -1.0))
    tf = TransferFunction.preset("grayscale", (0.0, 1.0), opacity=1.0)
    for near, sampling, expected in ((1.0, "near", 255), (1.025, "near", 128), (1.0, "entry", 128),
                                     (1.025, "entry", 128)):  # fmt: skip
        projection = f.Orthographic(height=1.0, near=near, far=10.0)
        camera = f.Camera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), projection=projection, width=6, height=6)
        image = _render(volume, camera, "mip", step=0.05, tf=tf, sampling=sampling).color[..., 0]
        assert (image == expected).all(), (near, sampling, np.unique(image))


def test_shaded_composite_through_a_parallel_camera_and_a_transform_equals_reference():
    volume = _phantom(20)
    projection = f.Orthographic(height=3.2, near=0.1, far=20.0)
    camera = f.Camera.look_at((3.0, -2.0, 4.0), (0.0, 0.0, 0.0), projection=projection, width=22, height=18)
    transform = f.compose(f.scale(1.2, 0.8, 1.0), f.rotate_z(0.4), f.translate(0.1, 0.0, -0.2))
    frame = _render(volume, camera, "composite", step=0.05, shade=True, transform=transform)
    expected = _reference(volume, _TF, "composite", camera, step=0.05, world_from_model=transform, shade=True,
                          lights=_LIGHTS)  # fmt: skip
    _assert_close(frame.color, expected)
    unshaded = _render(volume, camera, "composite", step=0.05, shade=False, transform=transform)
    assert (np.abs(unshaded.color.astype(int) - frame.color.astype(int)) > 8).any()  # the lights did something


def test_a_volume_seen_from_inside_equals_reference():
    volume = _phantom(20)
    camera = f.Camera.look_at((0.3, 0.2, 0.6), (-0.5, 0.0, -1.0), width=20, height=16)  # the eye is in the box
    frame = _render(volume, camera, "composite", step=0.05)
    expected = _reference(volume, _TF, "composite", camera, step=0.05)
    _assert_close(frame.color, expected)
    assert (frame.color[..., :3] > 0).all()  # every ray starts inside the volume


def test_clip_plane_and_cutaway_cut_the_volume_as_the_reference_does():
    volume = _phantom(20)
    camera = f.Camera.look_at((0.4, 1.1, 2.1), (0.0, 0.0, 0.0), width=20, height=16)
    plane = (np.array([0.1, 0.0, 0.0]), np.array([1.0, 0.0, 0.2]) / math.hypot(1.0, 0.2))
    scene = f.Scene(lights=_LIGHTS)
    scene.add_volume(volume, _TF, step=0.05)
    frame = f.render(f.cutaway(scene, plane=plane), camera)
    expected = _reference(volume, _TF, "composite", camera, step=0.05, planes=[plane])
    _assert_close(frame.color, expected)
    whole = f.render(scene, camera)
    assert (np.abs(whole.color.astype(int) - frame.color.astype(int)) > 8).any()  # the cut removed something


def test_mesh_plane_through_a_volume_cuts_every_ray_at_its_depth():
    volume = _phantom(20)
    camera = f.Camera.look_at((0.4, 0.9, 3.0), (0.0, 0.0, 0.0), width=24, height=18)
    wall = f.Mesh([[-3, -3, 0.1], [3, -3, -0.2], [3, 3, -0.2], [-3, 3, 0.1]], [[0, 1, 2], [0, 2, 3]])
    mesh_scene = f.Scene(lights=_LIGHTS)
    mesh_scene.add(wall, f.Material(color=(0.2, 0.5, 0.3)))
    meshes_only = f.render(mesh_scene, camera)
    frame = _render(volume, camera, "composite", step=0.05, scene=mesh_scene)
    expected = _reference(volume, _TF, "composite", camera, step=0.05, under=meshes_only.color,
                          depth=meshes_only.depth)  # fmt: skip
    _assert_close(frame.color, expected)
    np.testing.assert_array_equal(frame.depth, meshes_only.depth)  # composite volumes leave the depth alone
    # without the wall, rays run through the whole box: the image differs where the volume lies behind the wall
    free = _reference(volume, _TF, "composite", camera, step=0.05, under=meshes_only.color)
    assert (np.abs(free.astype(int) - expected.astype(int)) > 4).any()


def test_isosurface_hits_write_depth_and_hide_a_mesh_behind_them():
    volume = blobby_volume([[0.0, 0.0, 0.0]], 0.6, 64)
    camera = f.Camera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), width=17, height=17)
    scene = f.Scene(lights=_LIGHTS)
    scene.add(f.Mesh([[-3, -3, -0.9], [3, -3, -0.9], [3, 3, -0.9], [-3, 3, -0.9]], [[0, 1, 2], [0, 2, 3]]))
    scene.add_volume(volume, TransferFunction.preset("bone", (0, 1)), mode="isosurface", level=0.5)
    frame = f.render(scene, camera)
    # centre pixel: the blob's surface at distance 3 − r, r = 0.6·sqrt(ln 2)
    z_hit = 0.6 * math.sqrt(math.log(2.0))
    hit = camera.unproject([8.5, 8.5, float(frame.depth[8, 8])])
    assert hit[2] == pytest.approx(z_hit, abs=0.01)  # trilinear field on a grid of spacing 0.038
    assert frame.depth[0, 0] == pytest.approx(camera.project([-3.0 * 0.0, 0.0, -0.9])[2], abs=0.05)
    assert frame.depth[8, 8] < frame.depth[0, 0]


def test_mip_of_a_ball_is_exact_at_the_centre_pixel():
    n, peak = 33, 0.8
    axis = np.arange(n) - 16.0
    x, y, z = np.meshgrid(axis, axis, axis, indexing="ij")
    volume = Volume(np.clip(peak * (1.0 - (x * x + y * y + z * z) / 196.0), 0.0, None))
    tf = TransferFunction.preset("grayscale", (0.0, 1.0), opacity=1.0)
    projection = f.Orthographic(height=40.0, near=1.0, far=100.0)
    camera = f.Camera.look_at((16.0, 16.0, 60.0), (16.0, 16.0, 16.0), projection=projection, width=41, height=41)
    # samples at the middles of 65 segments over z in [0, 32]: the 33rd lies on the centre voxel
    frame = _render(volume, camera, "mip", step=32.0 / 65.0, tf=tf)
    assert frame.color[20, 20, 0] == math.floor(peak * 255.0 + 0.5)
    assert (frame.color[:, :, 0] <= frame.color[20, 20, 0]).all()


def test_average_of_a_constant_slab_is_the_constant():
    volume = Volume(np.full((5, 9, 7), 0.4), (0.5, 0.25, 0.3), (-1.0, -1.0, -1.0))
    tf = TransferFunction.preset("grayscale", (0.0, 1.0), opacity=1.0)
    camera = f.Camera.look_at((1.0, 0.7, 2.5), (0.0, 0.0, 0.0), width=20, height=16)
    frame = _render(volume, camera, "average", step=0.07, tf=tf)
    covered = frame.color[..., 0] > 0
    assert covered.sum() > 40
    assert (frame.color[..., 0][covered] == 102).all()  # floor(0.4·255 + 0.5)


def test_opacity_correction_makes_composite_converge_as_the_step_halves():
    volume = _phantom(24)
    camera = f.Camera.look_at((1.5, 1.0, 2.8), (0.0, 0.0, 0.0), width=40, height=32)
    tf = TransferFunction([0.0, 0.2, 1.0], [(1, 0.5, 0.2), (1, 0.8, 0.5), (1, 1, 1)], [0.05, 0.3, 0.95])
    images = [_render(volume, camera, "composite", step=s, tf=tf).color.astype(float) for s in (0.8, 0.4, 0.2, 0.1)]
    differences = [np.abs(images[i] - images[i + 1]).mean() for i in range(3)]
    assert differences[0] > 1.0
    # at least first order (the difference halves with the step); samples at segment middles measure 2.1 and 3.7
    assert differences[0] / differences[1] > 1.7
    assert differences[1] / differences[2] > 1.7


def test_empty_space_skipping_and_termination_do_not_change_the_image():
    volume = _phantom(40)
    camera = f.Camera.look_at((1.9, 1.4, 2.6), (0.0, 0.0, 0.0), width=24, height=20)
    # the same function with a tiny opacity everywhere: no block is empty, so nothing is skipped
    tf_dense = TransferFunction(_TF.values, _TF.colors, np.maximum(_TF.opacities, 1e-9))
    skipped = _render(volume, camera, "composite", step=0.03)
    dense = _render(volume, camera, "composite", step=0.03, tf=tf_dense)
    _assert_close(skipped.color, dense.color)


# --- isosurfaces -------------------------------------------------------------------------------------------


def test_isosurface_of_a_sampled_sphere_matches_area_volume_and_skimage():
    from skimage.measure import marching_cubes

    radius = 0.8
    volume = Volume.from_function(lambda p: sphere_implicit(p, radius), ((-1, -1, -1), (1, 1, 1)), 81)
    mesh = volume.isosurface(1.0, inside="below")  # sphere_implicit is |p|²/r², 1 on the sphere
    import trimesh

    solid = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert solid.volume == pytest.approx(4.0 / 3.0 * math.pi * radius**3, rel=0.01)
    assert solid.area == pytest.approx(4.0 * math.pi * radius**2, rel=0.01)
    assert solid.volume > 0  # outward winding
    verts, faces, _, _ = marching_cubes(np.array(volume.data), 1.0, spacing=tuple(volume.spacing),
                                        gradient_direction="ascent")  # fmt: skip
    np.testing.assert_allclose(mesh.vertices, verts + volume.origin, atol=1e-12)
    np.testing.assert_array_equal(mesh.faces, faces[:, [0, 2, 1]])
    centroid = mesh.vertices.mean(axis=0)
    normals_out = ((mesh.vertex_normals * (mesh.vertices - centroid)).sum(axis=1) > 0).mean()
    assert normals_out > 0.99


def test_isosurface_step_and_dense_inside_keep_outward_winding():
    volume = blobby_volume([[0, 0, 0], [0.7, 0, 0]], 0.5, 40)
    import trimesh

    for step in (1, 2):
        mesh = volume.isosurface(0.5, step=step)
        assert trimesh.Trimesh(mesh.vertices, mesh.faces, process=False).volume > 0


@pytest.mark.parametrize("direction", [np.eye(3), np.diag([-1.0, 1.0, 1.0]), [[0, 1, 0], [1, 0, 0], [0, 0, 1]]])
def test_isosurface_winding_stays_outward_when_the_direction_flips_handedness(direction):
    import trimesh

    base = Volume.from_function(lambda p: sphere_implicit(p, 0.8), ((-1, -1, -1), (1, 1, 1)), 31)
    mesh = Volume(base.data, base.spacing, base.origin, direction=direction).isosurface(1.0, inside="below")
    assert trimesh.Trimesh(mesh.vertices, mesh.faces, process=False).volume > 2.0  # 4/3·π·0.8³ = 2.14


# --- the volume itself -------------------------------------------------------------------------------------


def test_axis_order_data_ijk_lies_at_origin_plus_ijk_times_spacing():
    data = np.zeros((4, 5, 6))
    data[1, 3, 2] = 1.0
    volume = Volume(data, (0.5, 2.0, 3.0), (10.0, 20.0, 30.0))
    point = np.array([10.0 + 1 * 0.5, 20.0 + 3 * 2.0, 30.0 + 2 * 3.0])
    assert volume.sample([point])[0] == 1.0
    assert volume.sample([point + np.array([0.25, 0.0, 0.0])])[0] == pytest.approx(0.5)  # half a voxel along x
    np.testing.assert_allclose(volume.model_from_grid @ [1, 3, 2, 1], [*point, 1.0])
    np.testing.assert_allclose(volume.bounds, [[10, 20, 30], [11.5, 28, 45]])


def test_axis_slice_is_the_data_plane_and_oblique_slice_reproduces_linear_fields():
    rng = np.random.default_rng(0)
    volume = Volume(rng.random((6, 7, 8)), (1.0, 0.5, 2.0), (0, 0, 0))
    np.testing.assert_allclose(volume.slice("y", 1.5), volume.data[:, 3, :], atol=1e-6)
    np.testing.assert_allclose(volume.slice(2, 3.0), 0.5 * (volume.data[:, :, 1] + volume.data[:, :, 2]), atol=1e-6)


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(-3, 3), min_size=4, max_size=4), st.lists(st.floats(-1, 1), min_size=3, max_size=3))
def test_oblique_slice_of_a_linear_field_is_exact(coefficients, normal):
    # trilinear interpolation reproduces linear functions exactly (up to float32 storage of the grid values)
    a, b, c, d = coefficients
    if np.linalg.norm(normal) < 1e-3:
        normal = [0.0, 0.0, 1.0]
    volume = Volume.from_function(lambda p: a * p[:, 0] + b * p[:, 1] + c * p[:, 2] + d, ((0, 0, 0), (2, 3, 4)),
                                  (5, 7, 9))  # fmt: skip
    image = volume.slice(point=(1.0, 1.5, 2.0), normal=normal, size=(1.0, 1.0), resolution=(5, 4))
    n = np.asarray(normal) / np.linalg.norm(normal)
    v = np.eye(3)[int(np.argmin(np.abs(n)))]
    v = v - (v @ n) * n
    v /= np.linalg.norm(v)
    u = np.cross(v, n)
    fa, fb = np.linspace(-0.5, 0.5, 5), np.linspace(-0.5, 0.5, 4)
    points = np.array([1.0, 1.5, 2.0]) + fa[:, None, None] * u + fb[None, :, None] * v
    np.testing.assert_allclose(image, points @ [a, b, c] + d, atol=1e-5 * (1 + abs(a) + abs(b) + abs(c) + abs(d)))


def test_npy_and_nifti_files_load_with_their_placement(tmp_path):
    nibabel = pytest.importorskip("nibabel")
    data = np.arange(3 * 4 * 5, dtype=np.float32).reshape(3, 4, 5)
    np.save(tmp_path / "grid.npy", data)
    loaded = Volume.load(tmp_path / "grid.npy")
    np.testing.assert_array_equal(loaded.data, data)
    affine = np.array([[-2.0, 0, 0, 10.0], [0, 0, 1.5, -4.0], [0, 3.0, 0, 7.0], [0, 0, 0, 1]])
    nibabel.save(nibabel.Nifti1Image(data, affine), tmp_path / "scan.nii.gz")
    scan = Volume.load(tmp_path / "scan.nii.gz")
    np.testing.assert_array_equal(scan.data, data)
    np.testing.assert_allclose(scan.model_from_grid, affine, atol=1e-6)
    np.testing.assert_allclose(scan.spacing, [2.0, 3.0, 1.5])
    # the isosurface of a NIfTI volume lands where the affine puts its voxels
    mesh = scan.isosurface(30.0)
    grid = (mesh.vertices - affine[:3, 3]) @ np.linalg.inv(affine[:3, :3]).T
    assert (grid >= -1e-9).all() and (grid <= np.array(data.shape) - 1 + 1e-9).all()


def test_sources_are_deterministic_and_in_range():
    one, two = fbm_cloud(24, seed=3), fbm_cloud(24, seed=3)
    np.testing.assert_array_equal(one.data, two.data)
    assert one.value_range == (0.0, 1.0)
    assert not np.array_equal(one.data, fbm_cloud(24, seed=4).data)
    julia = quaternion_julia_volume(resolution=20, max_iter=8)
    np.testing.assert_allclose(julia.data, f.quaternion_julia(resolution=20, max_iter=8), rtol=1e-6)
    np.testing.assert_allclose(julia.bounds, [[-1.5] * 3, [1.5] * 3])
    blob = blobby_volume([[0.0, 0.0, 0.0]], 0.5, 21, bounds=((-1, -1, -1), (1, 1, 1)))
    assert blob.data[10, 10, 10] == pytest.approx(1.0)
    assert blob.sample([[0.5, 0.0, 0.0]])[0] == pytest.approx(math.exp(-1.0), rel=1e-6)


# --- transfer functions ------------------------------------------------------------------------------------


def test_transfer_function_is_piecewise_linear_and_its_table_matches():
    tf = TransferFunction([0.0, 2.0, 4.0], [(0, 0, 0), (1, 0.5, 0), (1, 1, 1)], [0.0, 0.5, 1.0], range=(-1.0, 5.0))
    np.testing.assert_allclose(tf([1.0, 3.0, -1.0, 5.0]), [[0.5, 0.25, 0, 0.25], [1, 0.75, 0.5, 0.75],
                                                            [0, 0, 0, 0], [1, 1, 1, 1]])  # fmt: skip
    table = tf.table(7)  # entries at -1, 0, …, 5
    np.testing.assert_allclose(table[:, 3], [0, 0, 0.25, 0.5, 0.75, 1, 1])


def test_colormap_transfer_function_follows_matplotlib():
    matplotlib = pytest.importorskip("matplotlib")
    tf = TransferFunction.colormap("viridis", (10.0, 20.0), opacity=0.5)
    cmap = matplotlib.colormaps["viridis"]
    for fraction in np.array([0, 77, 200, 255]) / 255.0:  # Matplotlib's 256 entries (nearest lookup) exactly
        np.testing.assert_allclose(tf(10.0 + 10.0 * fraction)[:3], cmap(fraction)[:3], atol=1e-12)
    assert tf(15.0)[3] == pytest.approx(0.5)


def test_presets_span_their_range():
    for name in f.TRANSFER_PRESETS:
        tf = TransferFunction.preset(name, (100.0, 300.0))
        assert tf.range == (100.0, 300.0)
        np.testing.assert_allclose(tf(100.0), [0, 0, 0, 0])
        np.testing.assert_allclose(tf(300.0), [1, 1, 1, 1])


# --- bad input ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("call", "fragment"),
    [
        (lambda: Volume(np.zeros((4, 4))), r"data has shape \(4, 4\) \(2D\); expected a 3D array"),
        (lambda: Volume(np.zeros((4, 1, 4))), r"every axis needs at least 2"),
        (lambda: Volume(np.zeros((3, 3, 3)), spacing=(1, np.inf, 1)), r"spacing = .* is not finite"),
        (lambda: Volume(np.zeros((3, 3, 3)), spacing=(1, 0, 1)), r"spacing = .* is not positive"),
        (lambda: Volume([[["a"]]]), r"data = .* is not numeric"),
        (lambda: TransferFunction([0, 2, 1], [(0, 0, 0)] * 3, [0, 1, 1]), r"values\[2\] = 1.0 is not above"),
        (lambda: TransferFunction([0, 1], [(0, 0, 0)] * 2, [0, 1], range=(0.5, 2)), r"values\[0\] = 0.0 is outside"),
        (lambda: TransferFunction([0, 1], [(0, 0, 0), (2, 0, 0)], [0, 1]), r"colors\[1, 0\] = 2.0 is outside \[0, 1\]"),
        (lambda: TransferFunction([0, 1], [(0, 0, 0)] * 2, [0, 1, 1]), r"opacities has shape \(3,\)"),
        (lambda: TransferFunction.preset("plasma-ish", (0, 1)), r"name = 'plasma-ish' is unknown"),
        (lambda: Volume(np.zeros((3, 3, 3))).isosurface(1.0), r"level = 1.0 is outside the data's range"),
        (lambda: Volume.load("/nonexistent/scan.nii"), r"is not a file"),
    ],
)
def test_bad_input_raises_geometry_error_naming_the_value(call, fragment):
    with pytest.raises(GeometryError, match=fragment):
        call()


def test_nan_voxels_are_refused_with_their_index_and_count():
    data = np.zeros((3, 4, 5))
    data[1, 2, 3] = np.nan
    data[2, 2, 2] = np.nan
    with pytest.raises(GeometryError, match=r"data\[1, 2, 3\] = nan is not finite \(2 such voxels\).*nan_to_num"):
        Volume(data)


def test_add_volume_rejects_bad_mode_step_and_transfer_function():
    scene, volume = f.Scene(), Volume(np.zeros((3, 3, 3)))
    with pytest.raises(GeometryError, match=r"mode = 'xray' is unknown; expected one of 'composite'"):
        scene.add_volume(volume, mode="xray")
    with pytest.raises(GeometryError, match=r"step = -1.0 is not positive"):
        scene.add_volume(volume, step=-1.0)
    with pytest.raises(GeometryError, match=r"transfer_function = .* is not a TransferFunction"):
        scene.add_volume(volume, "gray")
    with pytest.raises(GeometryError, match=r"volume = .* is not a Volume"):
        scene.add_volume(np.zeros((3, 3, 3)))
    with pytest.raises(GeometryError, match=r"sampling = 'middle' is unknown; expected one of 'entry', 'near'"):
        scene.add_volume(volume, sampling="middle")


def test_a_step_too_small_for_the_work_budget_raises_with_the_estimate():
    scene = f.Scene()
    scene.add_volume(Volume(np.zeros((64, 64, 64))), step=1e-4)
    camera = f.Camera.look_at((0, 0, 200), (32, 32, 32), width=640, height=480)
    with pytest.raises(FrustumError, match=r"render: a volume of shape \(64, 64, 64\) with step = 0.0001 .* needs "
                                           r"about 3.35e\+11 operations, over the work budget"):  # fmt: skip
        f.render(scene, camera)


def test_termination_threshold_leaves_under_half_a_level():
    assert (1.0 - TERMINATE) * 255.0 < 0.5


# --- scene files -------------------------------------------------------------------------------------------

_VOLUME_SCENE = """
[camera]
eye = [0.0, 0.0, 4.0]
target = [0.0, 0.0, 0.0]
[[volumes]]
source = { type = "blobby", centers = [[0.0, 0.0, 0.0]], radii = 0.5, shape = 24 }
transfer_function = { preset = "fire", range = [0.0, 1.0], opacity = 0.5 }
mode = "mip"
step = 0.05
sampling = "near"
transform = [{ translate = [0.5, 0.0, 0.0] }]
clip_planes = [{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }]
"""


def test_scene_file_volumes_place_a_volume_like_add_volume(tmp_path):
    from frustum.scenefile import load_scene_file

    (tmp_path / "scene.toml").write_text(_VOLUME_SCENE, encoding="utf-8")
    loaded = load_scene_file(tmp_path / "scene.toml")
    (item,) = loaded.scene.volumes
    assert item.mode == "mip" and item.step == 0.05 and item.transfer_function.range == (0.0, 1.0)
    assert item.sampling == "near"
    np.testing.assert_allclose(item.world_from_model[:3, 3], [0.5, 0.0, 0.0])
    np.testing.assert_allclose(item.clip_planes, [[[0, 0, 0], [0, 1, 0]]])
    scene = f.Scene()
    tf = TransferFunction.preset("fire", (0, 1), opacity=0.5)
    scene.add_volume(blobby_volume([[0.0, 0.0, 0.0]], 0.5, 24), tf, mode="mip", step=0.05, sampling="near",
                     transform=f.translate(0.5, 0, 0), clip_planes=[((0, 0, 0), (0, 1, 0))])  # fmt: skip
    np.testing.assert_array_equal(f.render(loaded.scene, loaded.camera).color, f.render(scene, loaded.camera).color)


@pytest.mark.parametrize(
    ("replace", "line", "fragment"),
    [
        ('mode = "mip"', 8, "volumes[0].mode = 'xray' is unknown"),
        ('type = "blobby"', 6, "volumes[0].source.type = 'cloud' is unknown"),
        ('preset = "fire"', 7, "volumes[0].transfer_function.preset = 'lava' is not accepted"),
        ("step = 0.05", 9, "volumes[0].step = -1 is out of range"),
        ("radii = 0.5", 6, "volumes[0].source.radii = -0.5 is not accepted"),
        ('sampling = "near"', 10, "volumes[0].sampling = 'middle' is unknown"),
    ],
)
def test_scene_file_volume_errors_name_file_line_and_key(tmp_path, replace, line, fragment):
    from frustum.errors import SceneFileError
    from frustum.scenefile import load_scene_file

    bad = {'mode = "mip"': 'mode = "xray"', 'type = "blobby"': 'type = "cloud"', 'preset = "fire"': 'preset = "lava"',
           "step = 0.05": "step = -1", "radii = 0.5": "radii = -0.5", 'sampling = "near"': 'sampling = "middle"'
           }[replace]  # fmt: skip
    (tmp_path / "scene.toml").write_text(_VOLUME_SCENE.replace(replace, bad), encoding="utf-8")
    with pytest.raises(SceneFileError) as caught:
        load_scene_file(tmp_path / "scene.toml")
    problems = getattr(caught.value, "problems", [str(caught.value)])
    assert any(p.startswith(f"{tmp_path / 'scene.toml'}:{line}: ") and fragment in p for p in problems), problems


# --- overlapping volumes -----------------------------------------------------------------------------------


def test_overlapping_composite_volumes_mix_sample_by_sample_like_one_volume_holding_both():
    # A on x in [0, 1], B on x in [0.5, 1.5] (same spacing, grids aligned); in the overlap, along the view axis z, A has
    # blobs in front of and behind B's: drawn one after the other the order would be wrong for one of them. The
    # supports never share a cell, and near-plane sampling puts every volume's samples at the same ray parameters,
    # so the two must composite exactly like one volume U = A + B on the union grid.
    h = 0.1
    z = np.arange(11) * h
    a = np.zeros((11, 11, 11))
    b = np.zeros((11, 11, 11))
    a[6:10, 2:9, :4] = 0.5 + 0.4 * z[:4]  # back (z <= 0.3)
    a[6:10, 2:9, 7:] = 0.9  # front (z >= 0.7)
    a[1:4, 2:9, 3:8] = 0.6  # outside B's box
    b[1:5, 2:9, 5] = 0.8  # x = 0.6 … 0.9: the middle (z = 0.5), between A's two
    b[7:10, 2:9, 2:9] = 0.45  # x = 1.2 … 1.4: outside A's box
    union = np.zeros((16, 11, 11))
    union[:11] += a
    union[5:] += b
    tf = TransferFunction([0.0, 0.4, 0.6, 1.0], [(0, 0, 0), (0.2, 0.4, 1.0), (1.0, 0.3, 0.1), (1, 1, 0.6)],
                          [0.0, 0.3, 0.5, 0.7])  # fmt: skip
    projection = f.Orthographic(height=1.4, near=0.5, far=10.0)
    camera = f.Camera.look_at((0.75, 0.5, 3.0), (0.75, 0.5, 0.5), projection=projection, width=28, height=20)
    scene = f.Scene()
    scene.add_volume(Volume(a, (h,) * 3), tf, step=0.03, sampling="near")
    scene.add_volume(Volume(b, (h,) * 3, (0.5, 0.0, 0.0)), tf, step=0.03, sampling="near")
    both = f.render(scene, camera).color
    single = f.Scene()
    single.add_volume(Volume(union, (h,) * 3), tf, step=0.03, sampling="near")
    expected = f.render(single, camera).color
    _assert_close(both, expected)
    # the same union checked pixel by pixel against the numpy reference (so the comparison is not kernel to kernel)
    _assert_close(expected, _reference(Volume(union, (h,) * 3), tf, "composite", camera, step=0.03, sampling="near"))
    # drawn one after the other (each alone, B over A's picture) the middle blob would be wrong
    alone = [f.Scene(), f.Scene()]
    alone[0].add_volume(Volume(a, (h,) * 3), tf, step=0.03, sampling="near")
    alone[1].add_volume(Volume(b, (h,) * 3, (0.5, 0.0, 0.0)), tf, step=0.03, sampling="near")
    first, second = (f.render(s, camera).color.astype(float) / 255.0 for s in alone)
    layered = second + (1.0 - second[..., 3:]) * first
    assert np.abs(layered * 255.0 - expected).max() > 20


def test_composite_volumes_apart_in_depth_merge_to_the_one_over_the_other_picture():
    # B lies wholly in front of A on every ray: the merged rays take all of B's samples, then A's, which is B's
    # picture over A's; entry sampling (the shorter last segment), shading and a clip plane on one of them only
    volume = _phantom(16)
    camera = f.Camera.look_at((0.3, 0.4, 4.2), (0.0, 0.0, 0.0), width=22, height=18)
    plane = ((0.0, 0.3, 0.0), (0.0, 1.0, 0.0))
    placed = [dict(transform=f.translate(0.0, 0.0, -1.2), shade=True, clip_planes=[plane]),
              dict(transform=f.translate(0.3, 0.0, 1.2), shade=True)]  # fmt: skip
    scene = f.Scene(lights=_LIGHTS)
    for options in placed:
        scene.add_volume(volume, _TF, step=0.05, **options)
    clear = (0.0, 0.0, 0.0, 0.0)  # a transparent background keeps each volume's own opacity in the alpha byte
    both = f.render(scene, camera, background=clear).color
    pictures = []
    for options in placed:
        alone = f.Scene(lights=_LIGHTS)
        alone.add_volume(volume, _TF, step=0.05, **options)
        pictures.append(f.render(alone, camera, background=clear).color.astype(float) / 255.0)
    back, front = pictures
    layered = np.floor(np.clip(front + (1.0 - front[..., 3:]) * back, 0.0, 1.0) * 255.0 + 0.5)
    _assert_close(both, layered, tolerance=2)  # two roundings to bytes in the layered picture
    assert (np.abs(front - back) > 0.1).any()
