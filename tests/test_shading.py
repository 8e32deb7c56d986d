"""Lights, materials, shading models, depth cueing, render modes and anti-aliasing (``frustum.shading``, ``render``).

Lighting terms are checked against hand-computed values at chosen pixels, one light at a time, and against the
readable one-point ``illuminate`` at every covered pixel of a quad.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from tests.reference_raster import placed

from frustum import Camera, FrustumError, Orthographic, Perspective
from frustum.errors import ShadingError
from frustum.geometry import Mesh, Polyline
from frustum.render import render
from frustum.scene import Node, Scene
from frustum.shading import (
    AmbientLight,
    DepthCue,
    DirectionalLight,
    Material,
    PointLight,
    SpotLight,
    illuminate,
)
from frustum.transforms import rotate_x, translate
from frustum.visibility.hidden_lines import feature_edges
from testdata import DATA

SIZE = 33  # odd: the centre pixel's centre is the world origin under ``ortho_camera``
BLACK = (0.0, 0.0, 0.0, 1.0)
WHITE = (1.0, 1.0, 1.0, 1.0)


def ortho_camera(size: int = SIZE, extent: float = 2.0) -> Camera:
    """Looking down −z from z = 10 at a square of side `extent` around the origin."""
    return Camera.look_at(
        (0, 0, 10), (0, 0, 0), (0, 1, 0), projection=Orthographic(extent, 1.0, 20.0), width=size, height=size
    )


def quad(half: float = 5.0, z: float = 0.0) -> Mesh:
    """A square in the plane z facing +z (toward the camera)."""
    v = [[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]]
    return Mesh(v, [[0, 1, 2], [0, 2, 3]])


def to_bytes(rgb) -> np.ndarray:
    return np.floor(np.clip(np.asarray(rgb, dtype=float), 0, 1) * 255.0 + 0.5).astype(int)


def centre(frame) -> np.ndarray:
    return frame.color[SIZE // 2, SIZE // 2, :3].astype(int)


def world_points(frame, camera: Camera) -> np.ndarray:
    """(H, W, 3) world point of every pixel centre at its depth (the textbook unproject)."""
    rows, cols = np.mgrid[0 : camera.height, 0 : camera.width]
    window = np.column_stack([cols.ravel() + 0.5, camera.height - rows.ravel() - 0.5, frame.depth.ravel()])
    return camera.unproject(window).reshape(camera.height, camera.width, 3)


MATERIAL = Material(color=(0.8, 0.5, 0.3), ambient=0.1, diffuse=0.7, specular=0.4, shininess=16)


# --- each lighting term, by hand --------------------------------------------------------------------------------


def test_ambient_light_alone_gives_ka_times_ia_times_color():
    scene = placed(Scene(lights=[AmbientLight(color=(1.0, 0.5, 0.25), intensity=0.8)]), quad(), MATERIAL)
    frame = render(scene, ortho_camera())
    expected = to_bytes(np.array([0.8, 0.5, 0.3]) * 0.1 * np.array([1.0, 0.5, 0.25]) * 0.8)
    assert (centre(frame) == expected).all()


def test_directional_diffuse_and_blinn_phong_specular_by_hand():
    theta = math.radians(60.0)
    light = DirectionalLight(direction=(0.0, -math.sin(theta), -math.cos(theta)))  # N·L = cos 60° = 0.5
    frame = render(placed(Scene(lights=[light]), quad(), MATERIAL), ortho_camera())
    n_dot_h = 1.5 / math.sqrt(3.0)  # H = normalize(L + V) with V = (0, 0, 1) at the origin
    expected = np.array([0.8, 0.5, 0.3]) * (0.1 + 0.7 * 0.5) + 0.4 * n_dot_h**16
    assert (centre(frame) == to_bytes(expected)).all()
    phong = render(placed(Scene(lights=[light]), quad(), MATERIAL), ortho_camera(), specular="phong")
    r_dot_v = math.cos(theta)  # R = 2(N·L)N − L = (0, −sin θ, cos θ): R·V = cos 60°
    expected = np.array([0.8, 0.5, 0.3]) * (0.1 + 0.7 * 0.5) + 0.4 * r_dot_v**16
    assert (centre(phong) == to_bytes(expected)).all()


def test_point_light_radial_attenuation_by_hand():
    light = PointLight(position=(0, 0, 2.0), color=(1, 1, 1), intensity=3.0, attenuation=(1.0, 0.5, 0.25))
    material = Material(color=(0.5, 0.5, 0.5), ambient=0.0, diffuse=1.0, specular=0.0)
    frame = render(placed(Scene(lights=[light]), quad(), material), ortho_camera())
    f = 1.0 / (1.0 + 0.5 * 2.0 + 0.25 * 4.0)  # d = 2, straight above the origin: N·L = 1
    assert (centre(frame) == to_bytes([0.5 * 3.0 * f] * 3)).all()


def test_spot_light_cone_full_inside_zero_outside_linear_between():
    spot = SpotLight(position=(0, 0, 1.0), direction=(0, 0, -1), inner_angle=math.radians(20),
                     outer_angle=math.radians(40))  # fmt: skip
    material = Material(color=(1, 1, 1), ambient=0.0, diffuse=1.0, specular=0.0)
    camera = ortho_camera(size=101, extent=4.0)
    frame = render(placed(Scene(lights=[spot]), quad(), material), camera)
    points = world_points(frame, camera)
    radius = np.hypot(points[..., 0], points[..., 1])
    alpha = np.arctan(radius)  # angle from the axis seen from the light at height 1
    inside = alpha < math.radians(19)
    outside = alpha > math.radians(41)
    red = frame.color[..., 0].astype(int)
    cos_alpha = np.cos(alpha)
    n_dot_l = cos_alpha  # the quad's normal is the axis
    assert (np.abs(red[inside] - to_bytes(n_dot_l[inside])) <= 1).all()
    assert (red[outside] == 0).all()
    between = ~inside & ~outside
    cos_inner, cos_outer = math.cos(math.radians(20)), math.cos(math.radians(40))
    cone = np.clip((cos_alpha - cos_outer) / (cos_inner - cos_outer), 0, 1)
    assert (np.abs(red[between] - to_bytes(n_dot_l * cone)[between]) <= 1).all()


def test_every_pixel_matches_the_readable_illuminate_with_several_colored_lights():
    lights = [
        AmbientLight(color=(0.2, 0.3, 0.4)),
        DirectionalLight(direction=(0.3, -0.5, -1.0), color=(1.0, 0.9, 0.8), intensity=0.7),
        PointLight(position=(1.0, 1.0, 1.5), color=(0.2, 0.4, 1.0), intensity=2.0, attenuation=(1, 0.2, 0.1)),
        SpotLight(position=(-1, 0, 2.0), direction=(0.4, 0.1, -1), color=(1.0, 0.2, 0.2), intensity=1.5),
    ]
    material = Material(color=(0.7, 0.6, 0.5), emissive=(0.05, 0.0, 0.1))
    camera = ortho_camera(size=41)
    frame = render(placed(Scene(lights=lights), quad(), material), camera)
    points = world_points(frame, camera)
    eye = np.asarray(camera.frame.eye)
    for row in range(0, 41, 5):
        for col in range(0, 41, 5):
            expected = to_bytes(illuminate(material, lights, points[row, col], (0, 0, 1), eye))
            assert np.abs(frame.color[row, col, :3].astype(int) - expected).max() <= 1, (row, col)


def test_lights_riding_nodes_move_with_them():
    light = PointLight(position=(0, 0, 0), attenuation=(1, 0, 0))
    scene = Scene()
    scene.add(quad(), Material(color=(1, 1, 1), ambient=0, diffuse=1, specular=0))
    carrier = scene.add(Node("lamp", transform=translate(3.0, 0.0, 1.0)))
    carrier.add_light(light)
    (moved,) = scene.world_lights()
    assert np.allclose(moved.position, (3.0, 0.0, 1.0))
    frame = render(scene, ortho_camera())
    cos = 1.0 / math.sqrt(10.0)  # at the origin, toward (3, 0, 1)
    assert (centre(frame) == to_bytes([cos] * 3)).all()


# --- shading models ---------------------------------------------------------------------------------------------


def fan(size: int = 5) -> tuple[Mesh, Camera]:
    """A fan of 6 triangles around a centre vertex on a pixel centre, normals bent outward like a dome."""
    angles = np.arange(6) * math.pi / 3
    ring = np.column_stack([size * np.cos(angles), size * np.sin(angles), np.zeros(6)])
    vertices = np.vstack([[0.0, 0.0, 0.0], ring])
    faces = [[0, 1 + k, 1 + (k + 1) % 6] for k in range(6)]
    normals = vertices * [0.35, 0.35, 0.0] + [0, 0, 1.0]
    camera = ortho_camera(size=SIZE, extent=2.2 * size)
    return Mesh(vertices, faces, vertex_normals=normals), camera


def test_gouraud_equals_phong_at_a_vertex_and_differs_inside():
    mesh, camera = fan()
    light = DirectionalLight(direction=(0.0, 0.0, -1.0))
    material = Material(color=(0.5, 0.5, 0.5), specular=0.8, shininess=64)
    scene = placed(Scene(lights=[light]), mesh, material)
    phong, gouraud = render(scene, camera, shading="phong"), render(scene, camera, shading="gouraud")
    assert (np.abs(centre(phong) - centre(gouraud)) <= 1).all()  # the centre vertex sits on the centre pixel
    # the highlight: Phong peaks at the vertex normal (0, 0, 1); Gouraud spreads the corner values, which are dim
    ring = np.ones((SIZE, SIZE), dtype=bool)
    ring[SIZE // 2 - 3 : SIZE // 2 + 4, SIZE // 2 - 3 : SIZE // 2 + 4] = False
    covered = phong.depth < 1.0
    assert np.abs(phong.color[..., 0].astype(int) - gouraud.color[..., 0].astype(int))[covered & ring].max() > 10
    flat = render(scene, camera, shading="flat")
    assert len(np.unique(flat.color[..., 0][covered])) <= 6  # one color per face


def test_normals_and_depth_shading_and_buffers():
    camera = ortho_camera()
    scene = placed(Scene(), quad(z=1.0), Material())
    normals = render(scene, camera, shading="normals", buffers=("normals", "object_id"))
    assert (centre(normals) == to_bytes([0.5, 0.5, 1.0])).all()
    assert np.allclose(normals.normals[SIZE // 2, SIZE // 2], (0, 0, 1))
    assert (normals.object_id == 0).all()
    depth = render(scene, camera, shading="depth")
    d = 10.0 - 1.0  # eye at z = 10, quad at z = 1
    assert (centre(depth) == to_bytes([(20.0 - d) / (20.0 - 1.0)] * 3)).all()


def test_flat_shading_uses_the_face_normal():
    tilt = rotate_x(math.radians(50.0))
    scene = placed(Scene(lights=[DirectionalLight(direction=(0, 0, -1))]), quad(), MATERIAL, tilt)
    frame = render(scene, ortho_camera(), shading="flat")
    normal = tilt[:3, :3] @ [0, 0, 1.0]
    centroid = tilt[:3, :3] @ np.array([-5 / 3, 5 / 3, 0.0])  # face (0, 2, 3), the upper-left half
    expected = illuminate(MATERIAL, [DirectionalLight(direction=(0, 0, -1))], centroid, normal, (0, 0, 10))
    assert (frame.color[2, 2, :3].astype(int) == to_bytes(expected)).all()
    values = {tuple(c) for c in frame.color[frame.depth < 1, :3].tolist()}
    assert len(values) <= 2  # one color per face


def test_vertex_colors_and_opacity_blend():
    front = Mesh(quad().vertices, quad().faces)
    scene = Scene()
    scene.add(quad(z=-1.0), Material(color=(0, 0, 1)))
    scene.add(front, Material(color=(1, 0, 0), opacity=0.25))
    frame = render(scene, ortho_camera(), shading="none")
    assert (centre(frame) == to_bytes([0.25, 0.0, 0.75])).all()
    assert frame.color[SIZE // 2, SIZE // 2, 3] == 255


def test_texture_is_sampled_perspective_correctly():
    texture = np.zeros((2, 2, 3), dtype=np.uint8)
    texture[0, 1] = 255  # top-right texel white
    vertices = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]]
    uvs = [[0, 0], [1, 0], [1, 1], [0, 1]]
    mesh = Mesh(vertices, [[0, 1, 2], [0, 2, 3]], uvs=uvs)
    camera = Camera.look_at((0, -2.5, 2.5), (0, 0, 0), (0, 1, 0), projection=Perspective(0.9, 0.5, 20), width=64,
                            height=64)  # fmt: skip
    frame = render(placed(Scene(), mesh, Material(color=(1, 1, 1), texture=texture)), camera, shading="none")
    points = world_points(frame, camera)
    covered = frame.depth < 1.0
    u, v = (points[..., 0] + 1) / 2, (points[..., 1] + 1) / 2
    # bilinear of the 2x2 texture between the texel centres: x, y in texel units from texel (0, 0)'s centre,
    # row 0 on top (v up); only the top-right texel is white, so the value is x·(1 − y)
    x = u * 2 - 0.5
    y = (1 - v) * 2 - 0.5
    interior = covered & (x > 0) & (x < 1) & (y > 0) & (y < 1)
    assert interior.sum() > 200
    expected = x * (1 - y)
    assert np.abs(frame.color[..., 0][interior] / 255.0 - expected[interior]).max() < 0.02


# --- depth cueing -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("distance", [3.0, 5.0, 7.0, 9.0])
def test_depth_cue_at_near_far_and_between_equals_the_formula(distance):
    cue = DepthCue(near=3.0, far=7.0, min_intensity=0.2, max_intensity=0.9, color=(0.0, 0.0, 1.0))
    scene = placed(Scene(), quad(z=10.0 - distance), Material(color=(1.0, 1.0, 0.0)))
    frame = render(scene, ortho_camera(), shading="none", depth_cue=cue)
    f = min(max(0.2 + 0.7 * (7.0 - distance) / 4.0, 0.2), 0.9)
    assert (centre(frame) == to_bytes([f, f, 1 - f])).all()
    assert np.isclose(cue.factor(distance), f)


def test_depth_cue_applies_to_lines_and_points():
    cue = DepthCue(near=5.0, far=15.0, min_intensity=0.0, max_intensity=1.0)
    line = Polyline([[-0.9, 0.0, 5.0], [0.9, 0.0, -5.0]])  # view distance 5 → 15 from left to right
    frame = render(placed(Scene(), line, Material(color=(1, 1, 1))), ortho_camera(), depth_cue=cue)
    row = frame.color[SIZE // 2, :, 0].astype(int)
    drawn = np.flatnonzero(row)
    assert row[drawn[0]] > 230 and row[drawn[-1]] < 25 and (np.diff(row[drawn]) <= 0).all()


# --- render modes -----------------------------------------------------------------------------------------------


def cube_mesh() -> Mesh:
    box = trimesh.creation.box(extents=(2, 2, 2))
    return Mesh(box.vertices, box.faces)


def test_hidden_line_cube_from_a_corner_shows_exactly_nine_edges():
    camera = Camera.look_at((5, 4, 6), (0, 0, 0), (0, 1, 0), projection=Perspective(0.6, 1, 30), width=160,
                            height=160)  # fmt: skip
    mesh = cube_mesh()
    scene = placed(Scene(), mesh, Material())
    frame = render(scene, camera, mode="hidden-line", background=WHITE)
    edges, _, kinds = feature_edges(mesh.vertices, mesh.faces, camera)
    edges = edges[kinds != 0]
    assert len(edges) == 12
    visible = 0
    for a, b in edges:
        along = np.linspace(0.3, 0.7, 7)[:, None]
        samples = camera.project(mesh.vertices[a] + along * (mesh.vertices[b] - mesh.vertices[a]))
        dark = 0
        for x, y, _ in samples:
            col, row = int(x), camera.height - 1 - int(y)
            patch = frame.color[max(row - 1, 0) : row + 2, max(col - 1, 0) : col + 2, 0]
            dark += int((patch < 128).any())
        assert dark == 7 or dark <= 2  # a hidden edge may cross a visible one in the picture, at one point
        visible += dark == 7
    assert visible == 9
    dashed = render(scene, camera, mode="hidden-line", hidden="dimmed", hidden_color=(1, 0, 0), background=WHITE)
    red = (dashed.color[..., 0] == 255) & (dashed.color[..., 1] == 0)
    assert red.sum() > 50  # the 3 hidden edges, dimmed in the second color


def test_hidden_line_draws_no_back_edge_of_a_sphere_and_matches_the_depth_buffer_rule():
    sphere = trimesh.creation.icosphere(subdivisions=2)
    mesh = Mesh(sphere.vertices, sphere.faces)
    camera = Camera.look_at((0, 0, 4), (0, 0, 0), (0, 1, 0), projection=Perspective(0.8, 1, 10), width=96, height=96)
    scene = placed(Scene(), mesh, Material())
    hidden_line = render(scene, camera, mode="hidden-line", edges="all", edge_color=(1, 1, 1), background=BLACK)
    drawn = hidden_line.color[..., 0] > 0
    # reference: every edge drawn alone with depth, kept where the hidden-line rule passes against the surface depth
    surface = render(scene, camera, shading="none").depth
    lines = render(scene, camera, mode="wireframe").depth
    padded = np.pad(surface, 1, constant_values=0.0)
    neighbourhood = np.max(
        [padded[1:-1, 1:-1], padded[:-2, 1:-1], padded[2:, 1:-1], padded[1:-1, :-2], padded[1:-1, 2:]], axis=0
    )
    reference = (lines < 1.0) & (lines - 1e-5 < neighbourhood)
    assert (drawn == reference).mean() > 0.99
    # no edge whose two faces both face away is drawn: those pixels are exactly the back edges' own pixels
    eye = np.array([0.0, 0.0, 4.0])
    facing = (mesh.face_normals * (eye - mesh.vertices[mesh.faces].mean(axis=1))).sum(axis=1) > 0
    front_faces = Mesh(mesh.vertices, mesh.faces[facing])
    front_lines = render(placed(Scene(), front_faces, Material(color=(1, 1, 1))), camera, mode="wireframe")
    assert (drawn & (front_lines.color[..., 0] == 0)).sum() == 0


def test_surface_plus_edges_draws_edges_over_the_shaded_surface():
    scene = placed(Scene(lights=[DirectionalLight(direction=(-1, -1, -1))]), cube_mesh(), Material(color=(0.2, 0.6, 1)))
    camera = Camera.look_at((5, 4, 6), (0, 0, 0), (0, 1, 0), projection=Perspective(0.6, 1, 30), width=96, height=96)
    plain = render(scene, camera)
    edged = render(scene, camera, mode="surface+edges", edge_color=(1, 0, 0))
    changed = (plain.color != edged.color).any(axis=2)
    assert changed.sum() > 100
    assert (edged.color[changed][:, :3] == (255, 0, 0)).all()


# --- anti-aliasing and output -----------------------------------------------------------------------------------


@pytest.mark.parametrize("samples", [4, 9, 16])
def test_supersampling_half_covered_pixel(samples):
    # the quad's left edge at window x = 10.5 (10 + 2/3 for 3x3) covers half (a third) of pixel column 10's samples
    size, extent = SIZE, 2.0
    scale = extent / size
    edge = 10.5 if samples != 9 else 10 + 2 / 3
    left = (edge - size / 2) * scale
    v = [[left, -5, 0], [5, -5, 0], [5, 5, 0], [left, 5, 0]]
    scene = placed(Scene(), Mesh(v, [[0, 1, 2], [0, 2, 3]]), Material(color=(1, 1, 1)))
    frame = render(scene, ortho_camera(), shading="none", background=BLACK, samples=samples)
    expected = 1 - (edge - 10)
    assert abs(frame.color[SIZE // 2, 10, 0] / 255.0 - expected) <= 1 / 255 + 1e-9
    assert frame.color[SIZE // 2, 9, 0] == 0 and frame.color[SIZE // 2, 11, 0] == 255


def test_srgb_encoding_option():
    scene = placed(Scene(), quad(), Material(color=(0.5, 0.5, 0.5)))
    linear = render(scene, ortho_camera(), shading="none")
    srgb = render(scene, ortho_camera(), shading="none", color_space="srgb")
    assert centre(linear)[0] == 128
    value = 128 / 255
    assert centre(srgb)[0] == (math.floor((1.055 * value ** (1 / 2.4) - 0.055) * 255 + 0.5))


# --- bad input --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("build", "fragment"),
    [
        (lambda: AmbientLight(intensity=-1), "intensity = -1.0 is negative"),
        (lambda: PointLight((0, 0, 0), intensity=-0.5), "intensity = -0.5 is negative"),
        (lambda: PointLight((0, 0, 0), attenuation=(0, 0, 0)), "attenuation"),
        (lambda: SpotLight((0, 0, 0), (0, 0, -1), inner_angle=0.8, outer_angle=0.4), "inner_angle"),
        (lambda: Material(shininess=-2), "shininess = -2.0 is negative"),
        (lambda: Material(opacity=1.5), "opacity = 1.5 is above 1"),
        (lambda: Material(texture=np.zeros((4, 4, 5))), r"texture has shape \(4, 4, 5\)"),
        (lambda: Material(texture=np.full((2, 2, 3), 2.0)), "outside"),
        (lambda: DepthCue(near=5, far=2), "far = 2.0 is not beyond near = 5.0"),
        (lambda: DepthCue(near=1, far=2, min_intensity=0.8, max_intensity=0.5), "min_intensity"),
    ],
)
def test_bad_lights_and_materials_raise_shading_errors(build, fragment):
    with pytest.raises(ShadingError, match=fragment):
        build()


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"mode": "sketch"}, r"mode = 'sketch' is unknown; expected one of 'surface', 'wireframe'"),
        ({"shading": "toon"}, r"shading = 'toon' is unknown; expected one of 'phong', 'gouraud', 'flat'"),
        ({"specular": "cook"}, "specular = 'cook' is unknown"),
        ({"hidden": "dotted"}, "hidden = 'dotted' is unknown"),
        ({"samples": 3}, "samples = 3 is not a perfect square"),
        ({"samples": 0}, "samples = 0 is not a positive integer"),
        ({"filter": "gauss"}, "filter = 'gauss' is unknown"),
        ({"color_space": "p3"}, "color_space = 'p3' is unknown"),
        ({"buffers": ("albedo",)}, "buffers"),
        ({"line_width": 0.5}, "line_width = 0.5 is below 1"),
        ({"edge_color": (2, 0, 0)}, "edge_color"),
        ({"depth_cue": (1, 2)}, "depth_cue"),
        ({"edges": "some"}, "edges = 'some' is unknown"),
    ],
)
def test_bad_render_options_name_the_value_and_the_valid_ones(kwargs, fragment):
    with pytest.raises(FrustumError, match=fragment):
        render(placed(Scene(), quad(), Material()), ortho_camera(), **kwargs)


def test_translate_keeps_flat_quads_unchanged():
    """Sanity: a translated copy renders where the camera says (guards the transform plumbing of shading)."""
    scene = placed(Scene(), quad(half=0.5), Material(color=(1, 1, 1)), translate(0.5, 0.0, 0.0))
    frame = render(scene, ortho_camera(), shading="none")
    x, y, _ = ortho_camera().project([0.5, 0.0, 0.0])
    assert frame.color[SIZE - 1 - int(y), int(x), 0] == 255


SPOT = DATA / "spot" / "spot_triangulated.obj"


def test_spot_renders_with_its_texture_black_and_white_patches():
    from frustum.geometry import load_parts

    (part,) = load_parts(SPOT)
    scene = placed(Scene(), part.mesh, Material(color=(1, 1, 1), texture=part.texture))
    camera = Camera.look_at((2, 1, 2.5), (0, 0.3, 0), (0, 1, 0), width=160, height=120)
    frame = render(scene, camera, shading="none", background=(0, 0, 1, 1))
    covered = frame.depth < 1.0
    gray = frame.color[..., :3][covered].astype(int).mean(axis=1)
    assert (gray < 80).mean() > 0.05 and (gray > 200).mean() > 0.3  # the dark patches of the cow on white


def test_vertex_colors_interpolate_and_multiply_the_material_color():
    v = [[-5.0, -5.0, 0.0], [5.0, -5.0, 0.0], [5.0, 5.0, 0.0], [-5.0, 5.0, 0.0]]
    colors = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])  # red bottom, blue top
    mesh = Mesh(v, [[0, 1, 2], [0, 2, 3]], vertex_colors=colors)
    frame = render(placed(Scene(), mesh, Material(color=(1.0, 1.0, 0.5))), ortho_camera(), shading="none")
    assert (centre(frame) == to_bytes([0.5, 0.0, 0.25])).all()  # halfway up: (0.5, 0, 0.5) × (1, 1, 0.5)
    camera = ortho_camera()
    points = world_points(frame, camera)
    up = (points[..., 1] + 5.0) / 10.0  # fraction of the way from the red to the blue edge
    red = frame.color[..., 0].astype(int)
    assert np.abs(red - to_bytes(1.0 - up)).max() <= 1


def test_the_directional_fast_path_equals_the_general_shading_kernel_bit_for_bit():
    """Blinn-Phong with directional lights only runs ``shade_pixels_directional``; asking for normals forces the
    general ``shade_pixels`` (object ids alone do not: they are filled from the face codes): the same bytes."""
    sphere = trimesh.creation.icosphere(subdivisions=3)
    lights = [
        DirectionalLight((-0.3, -0.6, -0.7), color=(1.0, 0.8, 0.6), intensity=0.9),
        DirectionalLight((0.5, 0.2, -0.4), color=(0.2, 0.3, 1.0)),
        AmbientLight(intensity=0.4),
    ]
    scene = Scene(lights=lights)
    scene.add(Mesh(sphere.vertices, sphere.faces), Material(color=(0.7, 0.5, 0.3), emissive=(0.02, 0.0, 0.05)))
    camera = Camera.look_at((0.5, 0.8, 3.0), (0, 0, 0), (0, 1, 0), width=96, height=72)
    fast = render(scene, camera)
    general = render(scene, camera, buffers=("normals",))  # normals: the general kernel writes them
    assert (fast.color == general.color).all() and (fast.depth == general.depth).all()


def test_the_phong_kernel_for_any_lights_equals_the_general_shading_kernel_bit_for_bit():
    """Per-pixel Phong with point, spot and directional lights and no extras runs ``shade_pixels_phong``; an extra
    buffer that the kernel writes (normals) forces the general ``shade_pixels``: the same bytes, both sides lit."""
    sphere = trimesh.creation.icosphere(subdivisions=3)
    half = sphere.faces[sphere.triangles_center[:, 2] < 0.3]  # open at the top: back faces seen inside
    lights = [
        PointLight((2.0, 1.5, 3.0), color=(1.0, 0.9, 0.8), attenuation=(1.0, 0.1, 0.02)),
        SpotLight((0.0, 3.0, 1.0), (0.0, -1.0, -0.3), inner_angle=0.3, outer_angle=0.6),
        DirectionalLight((-0.3, -0.6, -0.7), intensity=0.5),
        AmbientLight(intensity=0.2),
    ]
    scene = Scene(lights=lights)
    scene.add(Mesh(sphere.vertices, half), Material(color=(0.7, 0.5, 0.3), shininess=20, emissive=(0.02, 0, 0)))
    camera = Camera.look_at((0.5, 2.5, 2.0), (0, 0, 0), (0, 1, 0), width=96, height=72)
    for specular in ("blinn-phong", "phong"):
        fast = render(scene, camera, cull_back_faces=False, specular=specular)
        general = render(scene, camera, cull_back_faces=False, specular=specular, buffers=("normals",))
        assert (fast.color == general.color).all() and (fast.depth == general.depth).all()
        assert (fast.depth < 1).sum() > 1000
