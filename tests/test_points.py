"""Point clouds: the square style against OpenGL's GL_POINTS (Mesa llvmpipe through moderngl), sphere impostors
against the analytic ray–sphere intersection, lighting, depth against meshes, eye-dome lighting and the readers
(PLY through trimesh, COLMAP through pycolmap)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from frustum import Camera, Perspective, PointCloud, load_points, render
from frustum.errors import GeometryError
from frustum.geometry import Mesh
from frustum.render import eye_dome
from frustum.scene import Scene
from frustum.shading import DirectionalLight, Material, illuminate
from gl_frames import draw_and_read, gl_context

WIDTH, HEIGHT = 160, 120


def camera(eye=(0.2, 0.3, 4.0)) -> Camera:
    return Camera.look_at(eye, (0, 0, 0), (0, 1, 0), projection=Perspective(0.8, 0.5, 20.0), width=WIDTH,
                          height=HEIGHT)  # fmt: skip


def cloud_points(count: int = 400, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.0, 1.0, size=(count, 3)) * (1.2, 0.9, 1.0)


def window(points: np.ndarray, cam: Camera) -> np.ndarray:
    """(N, 4) window x, y (y up, pixel centres at +0.5), depth and clip w, in float64 (the textbook path)."""
    h = np.c_[points, np.ones(len(points))] @ np.asarray(cam.clip_from_world).T
    w = h[:, 3]
    return np.c_[(h[:, 0] / w + 1) * WIDTH / 2, (h[:, 1] / w + 1) * HEIGHT / 2, (h[:, 2] / w + 1) / 2, w]


def expected_squares(points: np.ndarray, cam: Camera, size: float) -> np.ndarray:
    """The pixel-centre rule of GL_POINTS: pixel centres in [x − s/2, x + s/2) × [y − s/2, y + s/2)."""
    mask = np.zeros((HEIGHT, WIDTH), dtype=bool)
    cols = np.arange(WIDTH) + 0.5
    rows_y = np.arange(HEIGHT) + 0.5
    for x, y, z, _w in window(points, cam):
        if not (0 < x < WIDTH and 0 < y < HEIGHT and 0 <= z <= 1):
            continue
        inside_x = (cols >= x - size / 2) & (cols < x + size / 2)
        inside_y = (rows_y >= y - size / 2) & (rows_y < y + size / 2)
        mask |= (inside_y[::-1, None] & inside_x[None, :])  # row 0 is the top (window y = H − 1)
    return mask


def gl_points(points: np.ndarray, cam: Camera, size: float) -> np.ndarray:
    ctx = gl_context()
    moderngl = pytest.importorskip("moderngl")
    program = ctx.program(
        vertex_shader="""
        #version 330 core
        uniform mat4 u_clip_from_world;
        uniform float u_size;
        in vec3 in_position;
        void main() { gl_Position = u_clip_from_world * vec4(in_position, 1.0); gl_PointSize = u_size; }
        """,
        fragment_shader="#version 330 core\nout vec4 f_color;\nvoid main() { f_color = vec4(1.0); }\n",
    )
    program["u_clip_from_world"].write(np.asarray(cam.clip_from_world, dtype="f4").T.tobytes())
    program["u_size"].value = float(size)
    vao = ctx.vertex_array(program, [(ctx.buffer(points.astype("f4")), "3f", "in_position")])
    flags = moderngl.DEPTH_TEST | moderngl.PROGRAM_POINT_SIZE
    return draw_and_read(ctx, vao, moderngl.POINTS, flags, WIDTH, HEIGHT)[:, :, 0] > 0


def unambiguous(points: np.ndarray, cam: Camera, size: float) -> np.ndarray:
    """The points none of whose square edges lies within 1/128 pixel of a row or column of pixel centres: GL snaps
    window positions to 1/256 pixel (llvmpipe: 8 subpixel bits) in float32, which decides those edges either way."""
    records = window(points, cam)
    edges = np.c_[records[:, 0] - size / 2, records[:, 0] + size / 2, records[:, 1] - size / 2,
                  records[:, 1] + size / 2] - 0.5  # fmt: skip
    return points[(np.abs(edges - np.round(edges)) > 1 / 128).all(axis=1)]


@pytest.mark.parametrize("size", [1, 3, 5])
def test_square_points_cover_the_pixels_gl_points_covers(size):
    cam = camera()
    points = unambiguous(cloud_points(), cam, size)
    scene = Scene()
    scene.add(PointCloud(points), style="square", point_size=size)
    frame = render(scene, cam, shading="none")
    ours = frame.depth < 1.0
    rule = expected_squares(points, cam, size)
    assert ours.sum() > 100 * size  # something drawn
    assert np.array_equal(ours, rule)  # the rule written above, exactly
    assert np.array_equal(ours, gl_points(points, cam, size))


def test_square_points_take_their_colors_over_the_material_color():
    points = np.array([[0.0, 0.0, 0.0], [0.5, 0.2, 0.0]])
    cloud = PointCloud(points, colors=np.array([[1.0, 0.5, 0.25], [0.0, 1.0, 0.0]]))
    scene = Scene()
    scene.add(cloud, Material(color=(1.0, 0.5, 1.0)), style="square", point_size=3)
    cam = camera((0.0, 0.0, 4.0))
    frame = render(scene, cam)  # no normals: drawn in their colors, unlit
    x, y, _, _ = window(points, cam)[0]
    row, col = HEIGHT - 1 - math.floor(y), math.floor(x)
    assert frame.color[row, col, :3].tolist() == [255, 128, 64]


def test_disk_points_cover_pixel_centres_within_half_the_size():
    points = np.array([[0.1, -0.05, 0.0]])
    cam = camera((0.0, 0.0, 4.0))
    scene = Scene()
    scene.add(PointCloud(points), style="disk", point_size=9)
    frame = render(scene, cam)
    x, y, _, _ = window(points, cam)[0]
    cols, rows = np.meshgrid(np.arange(WIDTH) + 0.5, HEIGHT - 1 - np.arange(HEIGHT) + 0.5)
    expected = (cols - x) ** 2 + (rows - y) ** 2 <= 4.5**2
    assert np.array_equal(frame.depth < 1, expected)


def spheres() -> tuple[np.ndarray, np.ndarray]:
    centers = np.array([[0.0, 0.0, 0.0], [0.8, 0.4, -0.5], [-0.7, -0.3, 0.6], [0.3, -0.6, 1.2]])
    return centers, np.array([0.5, 0.35, 0.3, 0.15])


def analytic_spheres(cam: Camera, centers: np.ndarray, radii: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) window depth of the nearest ray–sphere hit per pixel centre (1 where none) and (H, W, 3) the hit."""
    fovy, near, far = cam.projection.fovy, cam.projection.near, cam.projection.far
    tan = math.tan(fovy / 2)
    cols, rows = np.meshgrid(np.arange(WIDTH) + 0.5, np.arange(HEIGHT) + 0.5)
    x_ndc, y_ndc = 2 * cols / WIDTH - 1, 1 - 2 * rows / HEIGHT
    frame = cam.frame
    directions = (x_ndc[..., None] * tan * WIDTH / HEIGHT * frame.u + y_ndc[..., None] * tan * frame.v - frame.n)
    eye = np.asarray(frame.eye)
    best = np.full((HEIGHT, WIDTH), np.inf)
    for center, radius in zip(centers, radii, strict=True):
        oc = eye - center
        a = (directions * directions).sum(-1)
        b = (directions * oc).sum(-1)
        c = oc @ oc - radius * radius
        disc = b * b - a * c
        t = np.where(disc >= 0, (-b - np.sqrt(np.maximum(disc, 0))) / a, np.inf)
        best = np.minimum(best, t)
    hit = eye + best[..., None] * directions
    distance = best  # the view-axis distance: directions have −n component 1
    z_ndc = (far + near) / (far - near) - 2 * far * near / ((far - near) * distance)
    depth = np.where(np.isfinite(best), (z_ndc + 1) / 2, 1.0)
    return depth, hit


def test_sphere_impostors_have_the_depth_of_the_analytic_ray_sphere_intersection():
    centers, radii = spheres()
    cam = camera()
    light = DirectionalLight(direction=(-0.4, -0.5, -1.0))
    material = Material(color=(0.8, 0.6, 0.4), specular=0.3, shininess=16)
    scene = Scene(lights=[light])
    scene.add(PointCloud(centers, radii=radii), material, style="sphere")
    frame = render(scene, cam, buffers=("normals",))
    depth, hit = analytic_spheres(cam, centers, radii)
    ours, theirs = frame.depth < 1, depth < 1
    assert (ours != theirs).sum() <= 0.002 * theirs.sum()  # grazing rays at the silhouettes only
    both = ours & theirs
    np.testing.assert_allclose(frame.depth[both], depth[both], rtol=1e-5)
    # shaded with the true normal of the hit point: the classical model's colour there, and that normal written
    rows, cols = np.nonzero(both)
    for row, col in list(zip(rows, cols, strict=True))[:: max(1, len(rows) // 60)]:
        point = hit[row, col]
        index = int(np.argmin(np.abs(np.linalg.norm(point - centers, axis=1) - radii)))
        normal = (point - centers[index]) / radii[index]
        expected = np.floor(illuminate(material, [light], point, normal, cam.frame.eye) * 255 + 0.5)
        assert np.abs(frame.color[row, col, :3].astype(int) - expected).max() <= 1
        np.testing.assert_allclose(frame.normals[row, col], normal, atol=1e-4)


def test_points_are_depth_tested_against_meshes_and_have_object_ids():
    plane = Mesh([[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]], [[0, 1, 2], [0, 2, 3]])
    points = np.array([[-0.5, 0.0, 0.5], [0.5, 0.0, -0.5]])  # one in front of the plane, one behind
    scene = Scene()
    scene.add(plane, Material(color=(0.2, 0.2, 0.2)))
    scene.add(PointCloud(points, colors=[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), style="square", point_size=5)
    cam = camera((0.0, 0.0, 4.0))
    frame = render(scene, cam, shading="none", buffers=("object_id",))
    records = window(points, cam)
    front = HEIGHT - 1 - math.floor(records[0, 1]), math.floor(records[0, 0])
    back = HEIGHT - 1 - math.floor(records[1, 1]), math.floor(records[1, 0])
    assert frame.color[front][:3].tolist() == [255, 0, 0] and frame.object_id[front] == 1
    assert frame.color[back][:3].tolist() == [51, 51, 51] and frame.object_id[back] == 0
    assert frame.object_id.max() == 1
    assert frame.depth[front] == pytest.approx(records[0, 2], abs=1e-7)


def test_surfels_are_disks_in_the_plane_of_their_normals():
    # a surfel facing the camera is a disk of its radius: its image is the circle of the sphere's silhouette
    cam = camera((0.0, 0.0, 4.0))
    scene = Scene()
    scene.add(PointCloud([[0.0, 0.0, 0.0]], normals=[[0.0, 0.0, 1.0]], radii=[0.5]), style="surfel")
    facing = (render(scene, cam).depth < 1).sum()
    edge_on = Scene()
    edge_on.add(PointCloud([[0.0, 0.0, 0.0]], normals=[[1.0, 0.0, 0.0]], radii=[0.5]), style="surfel")
    tilted = Scene()
    tilted.add(PointCloud([[0.0, 0.0, 0.0]], normals=[[0.0, 1.0, 1.0]], radii=[0.5]), style="surfel")
    focal = HEIGHT / 2 / math.tan(0.4)
    assert facing == pytest.approx(math.pi * (0.5 * focal / 4.0) ** 2, rel=0.03)
    assert (render(edge_on, cam).depth < 1).sum() <= 2 * 0.5 * focal / 4.0 * 2
    assert (render(tilted, cam).depth < 1).sum() == pytest.approx(facing / math.sqrt(2), rel=0.05)


def test_eye_dome_lighting_darkens_by_the_formula_and_leaves_flat_regions():
    # two squares of points at different depths, the nearer one over part of the farther one
    grid = np.stack(np.meshgrid(np.linspace(-1, 1, 120), np.linspace(-1, 1, 120)), -1).reshape(-1, 2)
    far_square = np.c_[grid, np.full(len(grid), -0.5)]
    near_square = np.c_[grid * 0.4, np.full(len(grid), 0.5)]
    scene = Scene()
    scene.add(PointCloud(np.r_[far_square, near_square]), style="square", point_size=2)
    cam = camera((0.0, 0.0, 4.0))
    plain = render(scene, cam, shading="none")
    shaded = render(scene, cam, shading="none", eye_dome=True, eye_dome_strength=0.5)
    response = eye_dome.obscurance(plain.depth, np.asarray(cam.projection_matrix))
    expected = np.floor(plain.color[..., :3] * np.exp(-150.0 * response)[..., None] + 0.5)
    assert np.array_equal(shaded.color[..., :3], expected.astype(np.uint8))
    assert (response > 0.05).sum() > 100  # the farther square darkens around the nearer one's silhouette
    assert np.array_equal(shaded.depth, plain.depth)


# --- readers ---------------------------------------------------------------------------------------------------


def test_ply_without_faces_matches_trimesh(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    rng = np.random.default_rng(3)
    vertices = rng.normal(size=(50, 3))
    colors = rng.integers(0, 256, size=(50, 4), dtype=np.uint8)
    path = tmp_path / "cloud.ply"
    trimesh.PointCloud(vertices, colors=colors).export(path)
    cloud = load_points(path)
    reread = trimesh.load(path)
    np.testing.assert_array_equal(cloud.points, np.asarray(reread.vertices))
    np.testing.assert_allclose(cloud.colors, np.asarray(reread.colors) / 255.0)
    from_object = PointCloud.from_trimesh(reread)
    np.testing.assert_array_equal(from_object.points, cloud.points)
    np.testing.assert_allclose(from_object.colors, cloud.colors)


def test_ascii_ply_with_normals_and_radius(tmp_path):
    path = tmp_path / "scan.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
                    "property float nx\nproperty float ny\nproperty float nz\nproperty float radius\n"
                    "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
                    "0 0 0 0 0 2 0.5 255 0 0\n1 2 3 0 1 0 0.25 0 0 255\n")  # fmt: skip
    cloud = load_points(path)
    np.testing.assert_array_equal(cloud.points, [[0, 0, 0], [1, 2, 3]])
    np.testing.assert_array_equal(cloud.normals, [[0, 0, 1], [0, 1, 0]])
    np.testing.assert_array_equal(cloud.radii, [0.5, 0.25])
    np.testing.assert_array_equal(cloud.colors, [[1, 0, 0], [0, 0, 1]])


def test_text_point_formats(tmp_path):
    (tmp_path / "a.xyz").write_text("# x y z r g b\n0 0 0 255 0 0\n1 1 1 0 255 0\n")
    (tmp_path / "b.pts").write_text("2\n0 0 0 -1200 10 20 30\n1 2 3 -800 255 255 255\n")
    (tmp_path / "c.csv").write_text("0.5,0.5,0.5\n1,2,3\n")
    a, b, c = (load_points(tmp_path / name) for name in ("a.xyz", "b.pts", "c.csv"))
    np.testing.assert_array_equal(a.colors, [[1, 0, 0], [0, 1, 0]])
    np.testing.assert_array_equal(b.points, [[0, 0, 0], [1, 2, 3]])
    np.testing.assert_allclose(b.colors[0], np.array([10, 20, 30]) / 255)
    np.testing.assert_array_equal(c.points, [[0.5, 0.5, 0.5], [1, 2, 3]])
    assert c.colors is None


def test_colmap_points3d_match_pycolmap(tmp_path):
    pycolmap = pytest.importorskip("pycolmap")
    reconstruction = pycolmap.Reconstruction()
    rng = np.random.default_rng(5)
    for _ in range(20):
        reconstruction.add_point3D(rng.normal(size=3), pycolmap.Track(), rng.integers(0, 256, 3).astype(np.uint8))
    reconstruction.write_text(str(tmp_path))
    from_text = load_points(tmp_path)
    from_object = PointCloud.from_colmap(pycolmap.Reconstruction(str(tmp_path)))
    ids = sorted(reconstruction.points3D)
    expected = np.array([reconstruction.points3D[i].xyz for i in ids])
    np.testing.assert_allclose(from_text.points, expected, rtol=1e-12)
    np.testing.assert_allclose(from_object.points, expected, rtol=1e-12)
    np.testing.assert_allclose(from_text.colors, np.array([reconstruction.points3D[i].color for i in ids]) / 255)


def test_point_file_errors_name_the_problem(tmp_path):
    with pytest.raises(GeometryError, match="does not exist"):
        load_points(tmp_path / "missing.ply")
    (tmp_path / "x.obj").write_text("v 0 0 0\n")
    with pytest.raises(GeometryError, match=r"unknown suffix '\.obj'"):
        load_points(tmp_path / "x.obj")
    (tmp_path / "bad.xyz").write_text("0 0 0\n1 1\n")
    with pytest.raises(GeometryError, match="rows of different lengths"):
        load_points(tmp_path / "bad.xyz")
    (tmp_path / "short.ply").write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 10\n"
                                         b"property float x\nproperty float y\nproperty float z\nend_header\n"
                                         + b"\0" * 24)  # fmt: skip
    with pytest.raises(GeometryError, match="truncated"):
        load_points(tmp_path / "short.ply")
    header = b"ply\nformat binary_little_endian 1.0\nelement vertex 100000000\n"
    (tmp_path / "huge.ply").write_bytes(header + b"property float x\nproperty float y\nproperty float z\nend_header\n")
    with pytest.raises(GeometryError, match="over the memory budget"):
        load_points(tmp_path / "huge.ply")


def test_point_cloud_and_style_checks():
    with pytest.raises(GeometryError, match=r"colors\[1\]"):
        PointCloud([[0, 0, 0], [1, 1, 1]], colors=[[0, 0, 0], [2, 0, 0]])
    with pytest.raises(GeometryError, match=r"radii\[0\]"):
        PointCloud([[0, 0, 0]], radii=[0.0])
    scene = Scene()
    cloud = PointCloud([[0, 0, 0]])
    with pytest.raises(GeometryError, match="style = 'cubes' is unknown"):
        scene.add(cloud, style="cubes")
    with pytest.raises(GeometryError, match="no normals"):
        scene.add(cloud, style="surfel")
    with pytest.raises(GeometryError, match="point_size is for 'square' and 'disk'"):
        scene.add(cloud, style="sphere", point_size=3)
    with pytest.raises(GeometryError, match="not both"):
        scene.add(cloud, point_size=3, radius=0.1)


def test_point_cloud_is_immutable_and_transforms():
    points = np.array([[1.0, 0.0, 0.0]])
    cloud = PointCloud(points, normals=[[0.0, 0.0, 2.0]], radii=0.5)
    assert points.flags.writeable and not cloud.points.flags.writeable
    moved = cloud.transformed(np.diag([2.0, 2.0, 2.0, 1.0]))
    np.testing.assert_allclose(moved.points, [[2.0, 0.0, 0.0]])
    np.testing.assert_allclose(moved.normals, [[0.0, 0.0, 1.0]])
    np.testing.assert_allclose(moved.radii, [1.0])


# --- commands --------------------------------------------------------------------------------------------------


def test_commands_render_and_describe_point_and_splat_files(tmp_path):
    import subprocess
    import sys

    from tests.testdata import DATA

    rng = np.random.default_rng(2)
    points = rng.normal(size=(3000, 3)) * (1.0, 0.6, 0.4)
    (tmp_path / "scan.xyz").write_text("\n".join(" ".join(f"{v:.6f}" for v in p) + " 200 120 40" for p in points))

    def run(*arguments: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "frustum", *arguments], capture_output=True, text=True,
                              timeout=600, check=False, cwd=tmp_path)  # fmt: skip

    result = run("render", "scan.xyz", "-o", "scan.png", "--size", "96x72")
    assert result.returncode == 0, result.stderr
    from PIL import Image

    image = np.asarray(Image.open(tmp_path / "scan.png"))
    drawn = (image[..., :3] != 0).any(axis=2)
    assert 0.05 < drawn.mean() < 0.9  # framed: the cloud fills part of the picture
    assert len(np.unique(image[drawn][:, 0])) > 5  # eye-dome lighting shades the one color of the scan
    result = run("render", str(DATA / "splats" / "torus.ply"), "-o", "torus.png", "--size", "96x72")
    assert result.returncode == 0, result.stderr
    info = run("info", str(DATA / "splats" / "torus.ply"))
    assert "3D Gaussian splats" in info.stdout and "512" in info.stdout
    info = run("info", "scan.xyz")
    assert "point cloud" in info.stdout and "3000" in info.stdout
    missing = run("render", "nothing.xyz", "-o", "x.png")
    assert missing.returncode != 0 and "Traceback" not in missing.stderr
