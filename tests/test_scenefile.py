"""Scene files: every example renders, the validator reports every planted error at its line, fuzzing only ever
raises FrustumError, and the built scene matches the Python API (transforms against trimesh's builders)."""

from __future__ import annotations

import contextlib
import json
import math
import re
import textwrap
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from frustum import Camera, FrustumError, Orthographic, SceneFileError, rotate_y
from frustum.scenefile import (
    EXAMPLES_DIR,
    GEOMETRY_TYPES,
    PROJECTIONS,
    SCHEMA_PATH,
    TRANSFORM_STEPS,
    explain_scene_file,
    load_scene,
    load_scene_file,
    render_examples,
    render_scene_file,
)
from frustum.scenefile.loader import _load_scene
from frustum.scenefile.report import _key_lines

EXAMPLES = sorted(EXAMPLES_DIR.glob("*.toml"))
SMALL = (48, 36)

CAMERA = """
[camera]
eye = [0.0, 0.0, 5.0]
"""


def _scene_text(body: str) -> str:
    return textwrap.dedent(body).lstrip("\n")


def _problems(text: str, tmp_path: Path) -> list[str]:
    file = tmp_path / "scene.toml"
    file.write_text(_scene_text(text), encoding="utf-8")
    with pytest.raises(SceneFileError) as caught:
        load_scene_file(file)
    message = str(caught.value)
    assert message.startswith(str(file))
    return getattr(caught.value, "problems", [message])


# --- the gallery --------------------------------------------------------------------------------------------


def test_gallery_has_an_example_per_seed_topic() -> None:
    names = {path.stem for path in EXAMPLES}
    for topic in (
        "transformations", "projections", "clipping", "depth_cueing", "hidden_lines", "exploded_assembly",
        "cutaway_assembly", "stereo_anaglyph", "curves", "teapot", "fractal_landscape", "quaternion_julia",
    ):  # fmt: skip
        assert topic in names


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_every_example_renders(path: Path, tmp_path: Path) -> None:
    written = render_scene_file(path, tmp_path / "out.png", size=SMALL)
    from PIL import Image

    image = np.asarray(Image.open(written))
    columns = max(1, image.shape[1] // SMALL[0])
    assert image.shape[0] in (SMALL[1], 2 * SMALL[1]) and image.shape[1] == columns * SMALL[0]
    # something was drawn: more than one color in the picture
    assert np.unique(image.reshape(-1, 4), axis=0).shape[0] > 1


def test_examples_validate_against_the_json_schema() -> None:
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    for path in EXAMPLES:
        errors = [error.message for error in validator.iter_errors(tomllib.loads(path.read_text(encoding="utf-8")))]
        assert errors == [], path.name


def test_schema_lists_every_geometry_type() -> None:
    schema = json.loads(SCHEMA_PATH.read_text(encoding="utf-8"))
    assert schema["$defs"]["geometry"]["properties"]["type"]["enum"] == sorted(GEOMETRY_TYPES)


def test_schema_rejects_what_the_loader_rejects_by_structure() -> None:
    jsonschema = pytest.importorskip("jsonschema")
    validator = jsonschema.Draft202012Validator(json.loads(SCHEMA_PATH.read_text(encoding="utf-8")))
    good = {
        "camera": {"eye": [0, 0, 5]},
        "nodes": [{"geometry": {"type": "box"}, "transform": [{"translate": [1, 0, 0]}]}],
    }
    assert list(validator.iter_errors(good)) == []
    for bad in (
        {"camera": {"eye": [0, 0, 5], "fov_deg": 3}},
        {"camera": {"eye": [0, 0, 5]}, "nodes": [{"transform": [{"rotate_y": 30}]}]},
        {"camera": {"eye": [0, 0, 5]}, "render": {"size": [-1, 10]}},
        {"nodes": []},
    ):
        assert list(validator.iter_errors(bad)), bad


def test_render_examples_writes_one_png_per_example(tmp_path: Path) -> None:
    folder = tmp_path / "gallery"
    folder.mkdir()
    for name in ("teapot", "curves"):
        (folder / f"{name}.toml").write_text((EXAMPLES_DIR / f"{name}.toml").read_text())
    written = render_examples(tmp_path / "out", SMALL, examples_dir=folder)
    assert sorted(p.name for p in written) == ["curves.png", "teapot.png"]
    assert all(p.is_file() for p in written)


def test_render_examples_without_scene_files_raises(tmp_path: Path) -> None:
    with pytest.raises(FrustumError, match="holds no"):
        render_examples(tmp_path / "out", SMALL, examples_dir=tmp_path)


# --- outputs ----------------------------------------------------------------------------------------------


def test_render_scene_file_writes_svg_pdf_and_gif(tmp_path: Path) -> None:
    source = EXAMPLES_DIR / "hidden_lines.toml"
    outputs = [tmp_path / "a.svg", tmp_path / "a.pdf", tmp_path / "a.gif"]
    scene = tmp_path / "scene.toml"
    scene.write_text(source.read_text() + "\n[animation]\nframes = 3\nfps = 10\n")
    written = render_scene_file(scene, outputs, size=SMALL)
    assert written == outputs
    assert outputs[0].read_text().lstrip().startswith("<?xml")
    assert outputs[1].read_bytes().startswith(b"%PDF")
    from PIL import Image

    with Image.open(outputs[2]) as gif:
        assert gif.n_frames == 3


def test_render_scene_file_default_output_is_out_folder_next_to_the_file(tmp_path: Path) -> None:
    scene = tmp_path / "small.toml"
    scene.write_text((EXAMPLES_DIR / "teapot.toml").read_text())
    assert render_scene_file(scene, size=SMALL) == tmp_path / "out" / "small.png"


def test_render_scene_file_uses_output_files(tmp_path: Path) -> None:
    scene = tmp_path / "small.toml"
    scene.write_text((EXAMPLES_DIR / "teapot.toml").read_text() + '\n[output]\nfiles = ["pics/a.png"]\n')
    assert render_scene_file(scene, size=SMALL) == [tmp_path / "pics" / "a.png"]


def test_render_scene_file_rejects_an_unknown_suffix(tmp_path: Path) -> None:
    with pytest.raises(FrustumError, match=r"\.jpg"):
        render_scene_file(EXAMPLES_DIR / "teapot.toml", tmp_path / "a.jpg", size=SMALL)


def test_unreadable_scene_file_raises_scene_file_error(tmp_path: Path) -> None:
    with pytest.raises(SceneFileError, match="cannot be read"):
        load_scene_file(tmp_path / "missing.toml")


def test_size_override_changes_every_camera(tmp_path: Path) -> None:
    scene_file = load_scene_file(EXAMPLES_DIR / "projections.toml").resized((40, 30))
    assert [(c.width, c.height) for c in scene_file.cameras] == [(40, 30)] * 3
    frame = scene_file.render()
    assert frame.color.shape == (30, 120, 4)


# --- built scene agrees with the Python API ---------------------------------------------------------------


def test_transform_steps_match_trimesh_builders() -> None:
    trimesh_transformations = pytest.importorskip("trimesh.transformations")
    text = _scene_text(
        CAMERA
        + """
        [[nodes]]
        geometry = { type = "box" }
        transform = [
          { translate = [1.0, 2.0, 3.0] },
          { rotate_deg = 30, axis = [1.0, 1.0, 0.0], point = [0.5, 0.0, -1.0] },
          { scale = [2.0, 3.0, 0.5], fixed = [1.0, 1.0, 1.0] },
          { reflect = [0.0, 0.0, 1.0], point = [0.0, 0.0, 2.0] },
          { shear = "z", a = 0.5, b = -0.25, ref = 1.0 },
          { quaternion = [0.9238795, 0.0, 0.3826834, 0.0] },
        ]
        """
    )
    matrix = load_scene(text).scene.items[0].world_from_model
    tt = trimesh_transformations
    first = tt.translation_matrix([1.0, 2.0, 3.0])
    rotation = tt.rotation_matrix(math.radians(30), [1.0, 1.0, 0.0], [0.5, 0.0, -1.0])
    scaling = tt.translation_matrix([1, 1, 1]) @ np.diag([2.0, 3.0, 0.5, 1.0]) @ tt.translation_matrix([-1, -1, -1])
    mirror = tt.reflection_matrix([0.0, 0.0, 2.0], [0.0, 0.0, 1.0])
    shear = np.eye(4)
    shear[0, 2], shear[1, 2], shear[0, 3], shear[1, 3] = 0.5, -0.25, -0.5, 0.25
    quaternion = tt.quaternion_matrix([0.9238795, 0.0, 0.3826834, 0.0])
    expected = quaternion @ shear @ mirror @ scaling @ rotation @ first
    # 1e-6: the quaternion literal has 7 digits; everything else is exact to round-off
    np.testing.assert_allclose(matrix, expected, atol=1e-6)


def test_degrees_in_files_become_radians() -> None:
    text = _scene_text(CAMERA + '[[nodes]]\ngeometry = { type = "box" }\ntransform = [{ rotate_y_deg = 90 }]\n')
    np.testing.assert_allclose(load_scene(text).scene.items[0].world_from_model, rotate_y(math.pi / 2), atol=1e-15)


def test_nested_children_compose_parent_first() -> None:
    text = _scene_text(
        CAMERA
        + """
        [[nodes]]
        name = "parent"
        transform = [{ translate = [1.0, 0.0, 0.0] }]

        [[nodes.children]]
        name = "child"
        geometry = { type = "box" }
        transform = [{ scale = 2.0 }]
        """
    )
    scene = load_scene(text).scene
    expected = np.diag([2.0, 2.0, 2.0, 1.0])
    expected[0, 3] = 1.0
    np.testing.assert_allclose(scene.items[0].world_from_model, expected)
    assert scene.find("parent/child").geometry is not None


@pytest.mark.parametrize("projection", [p for p in PROJECTIONS if p != "frustum"])
def test_every_projection_keeps_the_target_at_the_image_centre(projection: str) -> None:
    extra = {"dimetric": "ratio = 0.8\n", "trimetric": "rotation_y_deg = 30\nrotation_x_deg = 20\n",
             "oblique": "alpha_deg = 50\n"}.get(projection, "")  # fmt: skip
    text = f'[camera]\neye = [3.0, 2.0, 6.0]\ntarget = [0.5, 0.2, -0.3]\nprojection = "{projection}"\n{extra}'
    camera = load_scene(text).camera
    window = camera.project(np.array([[0.5, 0.2, -0.3]]))[0]
    # parallel projections pivot / place their view plane at the target distance by default
    np.testing.assert_allclose(window[:2], [camera.width / 2, camera.height / 2], atol=1e-9)


def test_multiview_camera_matches_camera_multiview() -> None:
    scene_file = load_scene('[camera]\nview = "top"\ndistance = 7.0\nheight = 3.0\n')
    expected = Camera.multiview("top", Orthographic(3.0, 0.1, 100.0), distance=7.0, width=480, height=360)
    np.testing.assert_allclose(scene_file.camera.view_matrix, expected.view_matrix, atol=1e-12)
    np.testing.assert_allclose(scene_file.camera.projection_matrix, expected.projection_matrix, atol=1e-12)


def test_stereo_camera_is_built_from_the_camera_table() -> None:
    scene_file = load_scene_file(EXAMPLES_DIR / "stereo_anaglyph.toml")
    stereo = scene_file.stereo
    assert stereo.layout == "anaglyph" and stereo.anaglyph_method == "dubois"
    left, right = stereo.camera.eyes
    np.testing.assert_allclose(np.linalg.norm(right - left), 0.25)


def test_explain_scene_file_traces_a_point_to_where_the_camera_projects_it() -> None:
    pytest.importorskip("frustum.trace")
    path = EXAMPLES_DIR / "teapot.toml"
    trace = explain_scene_file(path, (0.5, 1.0, 0.2))
    camera = load_scene_file(path).camera
    np.testing.assert_allclose(trace.window[0], camera.project(np.array([[0.5, 1.0, 0.2]]))[0], atol=1e-9)
    assert "Viewport" in str(trace)


def test_curve_is_a_polyline_through_the_curve_points_with_its_control_polygon() -> None:
    bezier = pytest.importorskip("bezier")
    text = _scene_text(
        CAMERA
        + """
        [[nodes]]
        [nodes.geometry]
        type = "bezier_curve"
        control_points = [[0, 0], [1, 2], [3, 1], [4, 0]]
        samples = 11
        control_polygon = true
        control_markers = true
        """
    )
    polylines = load_scene(text).scene.polylines
    assert len(polylines) == 3
    curve, polygon, markers = (item.mesh for item in polylines)
    oracle = bezier.Curve.from_nodes(np.array([[0.0, 1.0, 3.0, 4.0], [0.0, 2.0, 1.0, 0.0]]))
    expected = oracle.evaluate_multi(np.linspace(0.0, 1.0, 11)).T
    # 1e-12: de Casteljau (bezier) and frustum's evaluation differ only by round-off
    np.testing.assert_allclose(curve.points[:, :2], expected, atol=1e-12)
    np.testing.assert_allclose(polygon.points[:, :2], [[0, 0], [1, 2], [3, 1], [4, 0]])
    assert markers.markers and not polygon.markers


def test_curve_with_a_radius_is_a_tube_inside_the_convex_hull() -> None:
    text = _scene_text(
        CAMERA
        + """
        [[nodes]]
        geometry.type = "bezier_curve"
        geometry.control_points = [[0, 0], [1, 2], [2, 0]]
        geometry.radius = 0.02
        geometry.control_polygon = true
        """
    )
    scene = load_scene(text).scene
    assert len(scene.items) == 2
    curve_bounds = scene.items[0].mesh.bounds
    # the Bezier curve stays in the convex hull of its control polygon (plus the tube radius 0.02)
    assert curve_bounds[0][1] >= -0.02 - 1e-12 and curve_bounds[1][1] <= 2.0 + 0.02


def test_mesh_file_is_relative_to_the_scene_file(tmp_path: Path) -> None:
    from frustum.geometry.primitives import box

    box((1.0, 2.0, 3.0)).save(tmp_path / "part.ply")
    scene_text = CAMERA + '[[nodes]]\ngeometry = { type = "mesh", path = "part.ply" }\n'
    (tmp_path / "s.toml").write_text(_scene_text(scene_text))
    mesh = load_scene_file(tmp_path / "s.toml").scene.items[0].mesh
    np.testing.assert_allclose(mesh.bounds[1] - mesh.bounds[0], [1.0, 2.0, 3.0])


# --- the key-line scanner -------------------------------------------------------------------------------


def test_key_lines_follow_tables_arrays_of_tables_and_multiline_values() -> None:
    text = _scene_text(
        '''
        title = """a "quoted" [not a table]
        second line"""   # comment [x]
        [camera]
        eye = [0, 0, 5]  # trailing [comment]
        "odd key".inner = 1

        [[nodes]]
        name = 'first'
        [[nodes.children]]
        name = "child"
        [[nodes]]
        transform = [
          { translate = [1, 0, 0] },

          # a comment line inside the array
          { rotate_y_deg = 30 },
        ]
        geometry.type = "box"
        '''
    )
    lines = _key_lines(text)
    assert lines[("title",)] == 1
    assert lines[("camera", "eye")] == 4
    assert lines[("camera", "odd key", "inner")] == 5
    assert lines[("nodes", 0, "name")] == 8
    assert lines[("nodes", 0, "children", 0, "name")] == 10
    assert lines[("nodes", 1, "transform", 0, "translate")] == 13
    assert lines[("nodes", 1, "transform", 1, "rotate_y_deg")] == 16
    assert lines[("nodes", 1, "geometry", "type")] == 18


# --- the bad-file corpus: every planted error, at its line --------------------------------------------------

BAD_SCENES: list[tuple[str, str, list[tuple[int, str]]]] = [
    (
        "unknown top-level key",
        """
        titel = "x"
        [camera]
        eye = [0.0, 0.0, 5.0]
        """,
        [(1, "titel = 'x' is not a known key; did you mean 'title'?")],
    ),
    (
        "unknown camera key",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        fov_deg = 40
        """,
        [(3, "camera.fov_deg = 40 is not a known key; did you mean 'fovy_deg'?")],
    ),
    (
        "wrong type for a vector",
        """
        [camera]
        eye = "0, 0, 5"
        """,
        [(2, "camera.eye = '0, 0, 5' is not 3 numbers; give [x, y, z]")],
    ),
    (
        "negative image size",
        """
        [render]
        size = [-320, 240]
        [camera]
        eye = [0.0, 0.0, 5.0]
        """,
        [(2, "render.size = (-320.0, 240.0) is not two positive integer pixel counts")],
    ),
    (
        "up parallel to the view direction",
        """
        [camera]
        eye = [0.0, 5.0, 0.0]
        target = [0.0, 0.0, 0.0]
        up = [0.0, 2.0, 0.0]
        """,
        [(4, "camera.up = (0.0, 2.0, 0.0) is parallel to the view direction (0.0, -1.0, 0.0)")],
    ),
    (
        "missing mesh file",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]

        [[nodes]]
        name = "bunny"
        geometry = { type = "mesh", path = "no_such_bunny.ply" }
        """,
        [(6, "nodes[0].geometry.path = 'no_such_bunny.ply' does not exist")],
    ),
    (
        "NaN coordinate",
        """
        [camera]
        eye = [0.0, 0.0, nan]
        """,
        [(2, "camera.eye = (0.0, 0.0, nan) is not finite")],
    ),
    (
        "infinite geometry parameter",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[nodes]]
        geometry = { type = "sphere", radius = inf }
        """,
        [(4, "nodes[0].geometry.radius = inf is not finite")],
    ),
    (
        "malformed TOML",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        eye = [1.0, 0.0, 5.0]
        """,
        [(3, "is not valid TOML: Cannot overwrite a value (at line 3")],
    ),
    (
        "unknown geometry type",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[nodes]]
        geometry = { type = "dodecahedron" }
        """,
        [(4, "nodes[0].geometry.type = 'dodecahedron' is unknown")],
    ),
    (
        "unknown geometry parameter",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[nodes]]
        geometry = { type = "box", sise = [1.0, 1.0, 1.0] }
        """,
        [(4, "nodes[0].geometry.sise = (1.0, 1.0, 1.0) is not a parameter of box; did you mean 'size'?")],
    ),
    (
        "radians where degrees are required",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[lights]]
        type = "spot"
        position = [0.0, 3.0, 0.0]
        direction = [0.0, -1.0, 0.0]
        inner_angle = 0.3
        """,
        [(7, "lights[0].inner_angle = 0.3 is an angle in radians; scene files take degrees: write inner_angle_deg")],
    ),
    (
        "unknown transformation step",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[nodes]]
        geometry = { type = "box" }
        transform = [{ rotate_y = 30 }]
        """,
        [(5, "nodes[0].transform[0].rotate_y = 30 is not a known key; did you mean 'rotate_y_deg'?")],
    ),
    (
        "two operations in one step",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[nodes]]
        geometry = { type = "box" }
        transform = [{ translate = [1.0, 0.0, 0.0], rotate_x_deg = 5 }]
        """,
        [(5, "nodes[0].transform[0] = {'translate': [1.0, 0.0, 0.0], 'rotate_x_deg': 5} names 2 operations")],
    ),
    (
        "zero scale factor",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[nodes]]
        geometry = { type = "box" }
        transform = [{ scale = [1.0, 0.0, 1.0] }]
        """,
        [(5, "nodes[0].transform[0].scale = (1.0, 0.0, 1.0) has a zero factor")],
    ),
    (
        "undefined material",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[nodes]]
        material = "steel"
        geometry = { type = "box" }
        """,
        [(4, "nodes[0].material = 'steel' names no material; define it under [materials.steel]")],
    ),
    (
        "color out of range",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [materials.red]
        color = [1.5, 0.0, 0.0]
        """,
        [(4, "materials.red.color = (1.5, 0.0, 0.0) is not accepted: Material: color")],
    ),
    (
        "unknown light type",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[lights]]
        type = "area"
        """,
        [(4, "lights[0].type = 'area' is unknown; expected one of 'ambient', 'directional', 'point', 'spot'")],
    ),
    (
        "misspelled render mode",
        """
        [render]
        mode = "wirefrme"
        [camera]
        eye = [0.0, 0.0, 5.0]
        """,
        [(2, "render.mode = 'wirefrme' is unknown; did you mean 'wireframe'?")],
    ),
    (
        "samples not a square, boolean as string",
        """
        [render]
        samples = 2
        cull_back_faces = "yes"
        [camera]
        eye = [0.0, 0.0, 5.0]
        """,
        [(2, "render.samples = 2 is not a square"), (3, "render.cull_back_faces = 'yes' is not a boolean")],
    ),
    (
        "no camera",
        """
        [[nodes]]
        geometry = { type = "box" }
        """,
        [(1, "camera is missing; add a [camera] table")],
    ),
    (
        "eye equals target",
        """
        [camera]
        eye = [1.0, 2.0, 3.0]
        target = [1.0, 2.0, 3.0]
        """,
        [(2, "camera.eye = (1.0, 2.0, 3.0) equals target")],
    ),
    (
        "frustum projection without its window",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        projection = "frustum"
        left = -1.0
        right = 1.0
        """,
        [(1, "camera.bottom is missing"), (1, "camera.top is missing")],
    ),
    (
        "projection parameter that does not apply",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        alpha_deg = 45
        """,
        [(3, "camera.alpha_deg = 45 does not apply to projection = 'perspective'")],
    ),
    (
        "view preset conflicts with eye",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        view = "front"
        """,
        [(3, "camera.view = 'front' conflicts with eye")],
    ),
    (
        "runaway tessellation",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[nodes]]
        geometry = { type = "uv_sphere", segments = 1000000000 }
        """,
        [(4, "nodes[0].geometry.segments = 1000000000 is too large")],
    ),
    (
        "nodes is not a list of tables",
        """
        nodes = 5
        [camera]
        eye = [0.0, 0.0, 5.0]
        """,
        [(1, "nodes = 5 is not a list of tables")],
    ),
    (
        "error inside a multi-line transform list and a nested child",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]

        [[nodes]]
        name = "parent"
        transform = [
          { translate = [1.0, 0.0, 0.0] },
          { rotate_x_deg = "ninety" },
        ]

        [[nodes.children]]
        name = "fine"
        geometry = { type = "box" }

        [[nodes.children]]
        name = "bad child"
        geometry = { type = "torus", minor_radius = -0.5 }
        """,
        [
            (8, "nodes[0].transform[1].rotate_x_deg = 'ninety' is not a number"),
            (17, "nodes[0].children[1].geometry.minor_radius = -0.5 is not accepted"),
        ],
    ),
    (
        "camera and cameras together, cutaway with two cuts, unknown output suffix",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]

        [[cameras]]
        eye = [0.0, 0.0, 5.0]

        [cutaway]
        plane_point = [0.0, 0.0, 0.0]
        plane_normal = [1.0, 0.0, 0.0]
        box_min = [0.0, 0.0, 0.0]
        box_max = [1.0, 1.0, 1.0]

        [output]
        files = ["render.jpg"]
        """,
        [
            (4, "cameras = '[[cameras]]' conflicts with [camera]"),
            (7, "cutaway = {"),
            (14, "output.files[0] = 'render.jpg' has an unknown suffix"),
        ],
    ),
    (
        "CSG operand with a bad nested transform",
        """
        [camera]
        eye = [0.0, 0.0, 5.0]
        [[nodes]]
        [nodes.geometry]
        type = "difference"
        operands = [
          { type = "box" },
          { type = "box", transform = [{ scale = [1.0, 0.0, 1.0] }] },
        ]
        """,
        [(8, "nodes[0].geometry.operands[1].transform[0].scale = (1.0, 0.0, 1.0) has a zero factor")],
    ),
    (
        "many errors at once, in line order",
        """
        [render]
        size = [0, 10]
        shading = "phng"
        [camera]
        eye = [0.0, 0.0, 5.0]
        fovy_deg = 200
        [[lights]]
        type = "directional"
        direction = [0.0, 0.0, 0.0]
        [[nodes]]
        geometry = { type = "box", size = [1.0, -1.0, 1.0] }
        """,
        [
            (2, "render.size = (0.0, 10.0)"),
            (3, "render.shading = 'phng' is unknown; did you mean 'phong'?"),
            (6, "camera.fovy_deg = 200 is out of range"),
            (9, "lights[0].direction = (0.0, 0.0, 0.0) is not accepted"),
            (11, "nodes[0].geometry.size = (1.0, -1.0, 1.0) is not accepted"),
        ],
    ),
]


@pytest.mark.parametrize(("text", "expected"), [case[1:] for case in BAD_SCENES], ids=[c[0] for c in BAD_SCENES])
def test_validator_reports_every_planted_error_at_its_line(text: str, expected: list, tmp_path: Path) -> None:
    problems = _problems(text, tmp_path)
    prefix = str(tmp_path / "scene.toml")
    assert len(problems) == len(expected), problems
    for line, fragment in expected:
        matching = [p for p in problems if p.startswith(f"{prefix}:{line}: ") and fragment in p]
        assert matching, (line, fragment, problems)
    # every problem names what would be valid after a semicolon
    assert all(";" in problem for problem in problems)


def test_bad_corpus_has_at_least_twenty_cases() -> None:
    assert len(BAD_SCENES) >= 20


def test_problems_come_in_line_order(tmp_path: Path) -> None:
    problems = _problems(BAD_SCENES[-1][1], tmp_path)
    lines = [int(re.match(r".*?:(\d+): ", p).group(1)) for p in problems]
    assert lines == sorted(lines)


def test_dictionary_input_reports_without_line_numbers() -> None:
    with pytest.raises(SceneFileError, match=r"^<scene>: camera\.eye = 'x' is not 3 numbers"):
        load_scene({"camera": {"eye": "x"}})


def test_missing_geometry_module_is_reported_as_not_available(monkeypatch: pytest.MonkeyPatch) -> None:
    import frustum.scenefile as scenefile

    monkeypatch.setitem(scenefile.GEOMETRY_TYPES, "gizmo", ("mesh", "frustum.geometry.no_such_module", "gizmo"))
    with pytest.raises(SceneFileError, match="gizmo' is not available in this version"):
        load_scene({"camera": {"eye": [0, 0, 5]}, "nodes": [{"geometry": {"type": "gizmo"}}]})


# --- fuzzing: only FrustumError or success -----------------------------------------------------------------

_scalars = st.one_of(
    st.integers(-5, 50),
    st.floats(allow_nan=True, allow_infinity=True, width=32),
    st.sampled_from(["", "x", "xy", "front", "box", "y"]),
    st.booleans(),
)
_numbers = st.floats(-4.0, 4.0, allow_nan=False)
_vectors = st.one_of(st.lists(_numbers, min_size=0, max_size=4), _scalars)
_values = st.one_of(_scalars, _vectors, st.lists(st.lists(_numbers, min_size=2, max_size=3), max_size=5))

_geometry = st.fixed_dictionaries(
    {"type": st.sampled_from([*sorted(GEOMETRY_TYPES), "blob"])},
    optional={
        key: _values
        for key in ("radius", "size", "radii", "s1", "s2", "control_points", "points", "grid", "degree", "c",
                    "path", "samples", "control_polygon", "style", "hurst", "seed", "sise")
    }
    | {
        "segments": st.integers(-2, 24),
        "level": st.integers(-1, 2),
        "resolution": st.one_of(st.integers(-1, 10), st.lists(st.integers(-1, 8), max_size=3)),
    },
)  # fmt: skip
_step = st.dictionaries(
    st.sampled_from([*TRANSFORM_STEPS, "axis", "point", "fixed", "a", "b", "ref", "rotate_y"]), _values, max_size=3
)
_node = st.fixed_dictionaries(
    {},
    optional={
        "name": st.sampled_from(["a", "b/c", ""]) | _scalars,
        "geometry": _geometry | _scalars,
        "material": st.sampled_from(["m", "missing"]) | st.dictionaries(st.sampled_from(["color", "opacity"]), _values),
        "transform": st.lists(_step, max_size=3) | _scalars,
        "children": st.lists(st.fixed_dictionaries({}, optional={"geometry": _geometry}), max_size=2),
    },
)
_camera = st.fixed_dictionaries(
    {},
    optional={
        key: _values
        for key in ("eye", "target", "up", "fovy_deg", "near", "far", "height", "distance", "azimuth_deg",
                    "elevation_deg", "alpha_deg", "phi_deg", "ratio", "left", "right", "bottom", "top", "fov")
    }
    | {
        "projection": st.sampled_from([*PROJECTIONS, "fisheye"]),
        "view": st.sampled_from(["front", "top", "iso"]),
        "stereo": st.dictionaries(st.sampled_from(["eye_separation", "layout", "convergence_distance"]), _values),
    },
)  # fmt: skip
_scenes = st.fixed_dictionaries(
    {"camera": st.one_of(st.just({"eye": [0.0, 1.0, 5.0]}), _camera)},
    optional={
        "materials": st.dictionaries(st.sampled_from(["m", "n"]), st.dictionaries(st.sampled_from(["color", "x"]),
                                                                                  _values)),
        "lights": st.lists(st.dictionaries(st.sampled_from(["type", "direction", "position", "intensity"]),
                                           _values | st.sampled_from(["ambient", "point", "spot", "directional"])),
                           max_size=2),
        "nodes": st.lists(_node, max_size=3) | _scalars,
        "render": st.dictionaries(st.sampled_from(["size", "mode", "shading", "samples", "background", "depth_cue",
                                                   "line_width", "columns"]), _values),
        "exploded": st.dictionaries(st.sampled_from(["factor", "center", "node"]), _values),
        "cutaway": st.dictionaries(st.sampled_from(["plane_point", "plane_normal", "box_min", "box_max", "ghost"]),
                                   _values),
        "output": st.dictionaries(st.sampled_from(["files"]), _values),
    },
)  # fmt: skip


@pytest.mark.filterwarnings("ignore:Generating overly large repr")
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(_scenes)
def test_fuzzed_scene_dictionaries_raise_only_frustum_errors(data: dict) -> None:
    try:
        scene_file = load_scene(data)
    except FrustumError:
        return
    with contextlib.suppress(FrustumError):
        scene_file.resized((16, 12)).render()


_coordinate = st.floats(-3.0, 3.0, allow_nan=False)
_point = st.lists(_coordinate, min_size=3, max_size=3)
_polygon = st.lists(st.lists(_coordinate, min_size=3, max_size=3), min_size=1, max_size=5)
_sane_geometry = st.one_of(
    st.fixed_dictionaries({"type": st.just("box"), "size": st.lists(st.floats(-0.5, 2.0), min_size=3, max_size=3)}),
    st.fixed_dictionaries(
        {"type": st.just("uv_sphere")},
        optional={"radius": st.floats(-0.5, 2.0), "segments": st.integers(-1, 12), "rings": st.integers(-1, 8)},
    ),
    st.fixed_dictionaries({"type": st.just("torus"), "major_radius": st.floats(-0.5, 2.0),
                           "minor_radius": st.floats(-0.5, 1.0)}),
    st.fixed_dictionaries({"type": st.just("superellipsoid"), "s1": st.floats(-0.5, 3.0), "s2": st.floats(0.1, 3.0),
                           "segments": st.integers(3, 10), "rings": st.integers(2, 6)}),
    st.fixed_dictionaries({"type": st.just("teapot"), "resolution": st.integers(0, 3)}),
    st.fixed_dictionaries(
        {"type": st.sampled_from(["bezier_curve", "bspline_curve"]), "control_points": _polygon},
        optional={"samples": st.integers(0, 16), "control_polygon": st.booleans(), "radius": st.floats(-0.1, 0.3),
                  "degree": st.integers(0, 4), "sides": st.integers(2, 8)},
    ),
    st.fixed_dictionaries({"type": st.just("terrain"), "level": st.integers(0, 3), "hurst": st.floats(-0.5, 1.5),
                           "seed": st.integers(0, 3), "size": st.floats(-1.0, 4.0)}),
    st.fixed_dictionaries({"type": st.just("menger_sponge"), "level": st.integers(-1, 1)}),
    st.fixed_dictionaries({"type": st.just("quaternion_julia"), "resolution": st.integers(2, 10),
                           "c": st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4)}),
    st.fixed_dictionaries({"type": st.just("bezier_surface"),
                           "grid": st.lists(st.lists(_point, min_size=2, max_size=3), min_size=2, max_size=3),
                           "resolution": st.lists(st.integers(0, 6), min_size=2, max_size=2)}),
    st.fixed_dictionaries({"type": st.just("lsystem"), "preset": st.sampled_from(["koch", "plant", "dragon"]),
                           "level": st.integers(0, 3)}),
)  # fmt: skip
_sane_step = st.one_of(
    st.builds(lambda v: {"translate": v}, _point),
    st.builds(lambda a: {"rotate_x_deg": a}, st.floats(-360, 360)),
    st.builds(lambda a, axis, p: {"rotate_deg": a, "axis": axis, "point": p}, st.floats(-360, 360), _point, _point),
    st.builds(lambda s, f: {"scale": s, "fixed": f}, st.lists(st.floats(-2, 2), min_size=3, max_size=3), _point),
    st.builds(lambda n: {"reflect": n}, st.sampled_from(["xy", "yz", "zx"]) | _point),
    st.builds(lambda ax, a, b: {"shear": ax, "a": a, "b": b}, st.sampled_from(["x", "y", "z"]), _coordinate,
              _coordinate),
    st.builds(lambda q: {"quaternion": q}, st.lists(st.floats(-1, 1), min_size=4, max_size=4)),
)  # fmt: skip
_sane_camera = st.fixed_dictionaries(
    {"eye": _point, "projection": st.sampled_from([p for p in PROJECTIONS if p != "frustum"])},
    optional={"target": _point, "up": _point, "fovy_deg": st.floats(1, 179), "near": st.floats(-1, 2),
              "far": st.floats(0.5, 50), "height": st.floats(-1, 5), "ratio": st.floats(0.1, 1.4)},
)  # fmt: skip
_sane_scenes = st.fixed_dictionaries(
    {
        "camera": _sane_camera,
        "nodes": st.lists(st.fixed_dictionaries({"geometry": _sane_geometry},
                                                optional={"transform": st.lists(_sane_step, max_size=3)}),
                          min_size=1, max_size=3),
        "lights": st.just([{"type": "directional", "direction": [-1.0, -1.0, -1.0]}]),
    },
    optional={
        "render": st.fixed_dictionaries({}, optional={"mode": st.sampled_from(["surface", "wireframe", "points",
                                                                               "hidden-line", "surface+edges"]),
                                                      "shading": st.sampled_from(["phong", "flat", "depth"]),
                                                      "samples": st.sampled_from([1, 4]),
                                                      "cull_back_faces": st.booleans()}),
        "exploded": st.fixed_dictionaries({"factor": st.floats(-1.0, 2.0)}),
        "cutaway": st.fixed_dictionaries({"plane_point": _point, "plane_normal": _point}, optional={
            "cap": st.booleans(), "ghost": st.floats(0.0, 1.0)}),
    },
)  # fmt: skip


@pytest.mark.filterwarnings("ignore:Generating overly large repr")
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(_sane_scenes)
def test_fuzzed_plausible_scenes_load_and_render_or_raise_frustum_errors(data: dict) -> None:
    test_fuzzed_scene_dictionaries_raise_only_frustum_errors.hypothesis.inner_test(data)


# --- the key-line scanner against a tiny TOML writer --------------------------------------------------------


def _toml_key(key: str) -> str:
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else json.dumps(key)


def _toml_value(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items()) + " }"
    return "[" + ", ".join(_toml_value(v) for v in value) + "]"


def _is_table_array(value: object) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def _write_toml(data: dict, prefix: tuple = (), out: list | None = None, lines: dict | None = None) -> tuple:
    """TOML text of `data` and the line each key path is written on (what _key_lines must find)."""
    out = [] if out is None else out
    lines = {} if lines is None else lines
    header = ".".join(_toml_key(str(p)) for p in prefix if isinstance(p, str))
    for key, value in data.items():
        if not isinstance(value, dict) and not _is_table_array(value):
            out.append(f"{_toml_key(key)} = {_toml_value(value)}")
            lines[(*prefix, key)] = len(out)
    for key, value in data.items():
        if isinstance(value, dict):
            out.append(f"[{header + '.' if header else ''}{_toml_key(key)}]")
            lines[(*prefix, key)] = len(out)
            _write_toml(value, (*prefix, key), out, lines)
    for key, value in data.items():
        if _is_table_array(value):
            for index, item in enumerate(value):
                out.append(f"[[{header + '.' if header else ''}{_toml_key(key)}]]")
                lines[(*prefix, key, index)] = len(out)
                _write_toml(item, (*prefix, key, index), out, lines)
    return "\n".join(out) + "\n", lines


_toml_keys = st.sampled_from(["a", "b", "key-1", "with space", "dotted.key", "x_deg", "é"])
_toml_scalars = st.one_of(
    st.booleans(), st.integers(-5, 5), st.floats(-3, 3, allow_nan=False), st.text("ab[]#=\"'{},\\", max_size=4)
)
_toml_tables = st.recursive(
    st.dictionaries(_toml_keys, _toml_scalars | st.lists(_toml_scalars, max_size=3), max_size=3),
    lambda inner: st.dictionaries(_toml_keys, inner | st.lists(inner, min_size=1, max_size=2), max_size=3),
    max_leaves=12,
)


@settings(max_examples=80, deadline=None)
@given(_toml_tables)
def test_key_lines_find_every_key_the_writer_wrote(data: dict) -> None:
    text, expected = _write_toml(data)
    assert tomllib.loads(text) == data  # the writer is right
    lines = _key_lines(text)
    for path, line in expected.items():
        assert lines.get(path) == line, (path, text)


# --- every registered geometry type builds ----------------------------------------------------------------

_GRID = [[[i, j, (i - 1.5) * (j - 1.5) / 4] for j in range(4)] for i in range(4)]
_POLYGON = [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 0.0, 0.0], [3.0, 1.0, 0.0]]
_MINIMAL_GEOMETRY = {
    "bezier_surface": {"grid": _GRID, "resolution": [4, 4]},
    "bspline_surface": {"grid": _GRID, "resolution": [4, 4]},
    "nurbs_surface": {"grid": _GRID, "weights": [[1.0] * 4] * 4, "resolution": [4, 4]},
    "bezier_curve": {"control_points": _POLYGON},
    "bspline_curve": {"control_points": _POLYGON},
    "nurbs_curve": {"control_points": _POLYGON, "weights": [1.0, 2.0, 2.0, 1.0]},
    "cubic_spline": {"points": _POLYGON},
    "catmull_rom": {"points": _POLYGON},
    "cardinal_spline": {"points": _POLYGON, "tension": 0.5},
    "terrain": {"level": 2, "seed": 0},
    "menger_sponge": {"level": 1},
    "octree": {"depth": 3, "source": {"type": "box"}},
    "sierpinski_tetrahedron": {"level": 1},
    "koch_snowflake": {"level": 1},
    "hilbert_curve_3d": {"level": 1},
    "quaternion_julia": {"resolution": 8},
    "lsystem": {"preset": "koch", "level": 1},
    "teapot": {"resolution": 2},
    "teacup": {"resolution": 2},
    "teaspoon": {"resolution": 2},
    **{
        operation: {
            "operands": [
                {"type": "box"},
                {
                    "type": "uv_sphere",
                    "radius": 0.6,
                    "segments": 12,
                    "rings": 6,
                    "transform": [{"translate": [0.5] * 3}],
                },
            ]
        }
        for operation in ("union", "difference", "intersection")
    },
}


# file types need a file: mesh here elsewhere, point_cloud and splats through examples/points_*.toml and splats.toml
@pytest.mark.parametrize("kind", sorted(set(GEOMETRY_TYPES) - {"mesh", "point_cloud", "splats"}))
def test_every_geometry_type_builds_and_renders(kind: str) -> None:
    geometry = {"type": kind, **_MINIMAL_GEOMETRY.get(kind, {})}
    scene_file = load_scene({"camera": {"eye": [2.0, 3.0, 6.0]}, "nodes": [{"geometry": geometry}]})
    placed = scene_file.scene.items + getattr(scene_file.scene, "polylines", [])
    assert len(placed) == 1
    frame = scene_file.resized((24, 18)).render()
    assert frame.color.shape == (18, 24, 4)


def test_render_view_sheet_writes_an_svg_drawing(tmp_path: Path) -> None:
    pytest.importorskip("frustum.output.sheet")
    from frustum.scenefile import render_view_sheet

    written = render_view_sheet(EXAMPLES_DIR / "multiview.toml", tmp_path / "sheet.svg", ("front", "top", "iso"))
    text = written.read_text()
    assert text.startswith("<?xml") and 'width="420mm"' in text


def test_explain_without_a_point_traces_every_vertex() -> None:
    pytest.importorskip("frustum.trace")
    trace = explain_scene_file(EXAMPLES_DIR / "hidden_lines.toml")
    assert len(trace.parts) == 3


def test_the_format_sample_in_the_docs_loads() -> None:
    docs = Path(__file__).resolve().parents[1] / "docs" / "topics.md"
    sample = re.search(r"```toml\n(.*?)```", docs.read_text(encoding="utf-8"), re.S)
    assert sample is not None
    scene_file = load_scene(sample.group(1))
    assert scene_file.stereo is not None and scene_file.outputs


def test_outputs_outside_the_folder_are_refused_only_when_they_would_be_written(tmp_path):
    outside = ["../out.png", "/tmp/frustum-absolute.png"]  # outside: refused (test_self_contained)
    data = {"camera": {"eye": [0, 0, 5], "target": [0, 0, 0]}, "nodes": [{"geometry": {"type": "uv_sphere"}}],
            "output": {"files": [outside[0], "inside.png", outside[1]]}}  # fmt: skip
    with pytest.raises(SceneFileError) as info:
        load_scene(data, base_dir=tmp_path)
    assert str(info.value).count("is outside the scene file's folder") == 2
    loaded = _load_scene(data, base_dir=tmp_path, check_outputs=False)  # the caller writes elsewhere (-o)
    assert loaded.outputs == (tmp_path / "inside.png",)
    data["output"]["files"].append("bad.xyz")  # a malformed entry stays an error either way
    with pytest.raises(SceneFileError, match="has an unknown suffix"):
        _load_scene(data, base_dir=tmp_path, check_outputs=False)
