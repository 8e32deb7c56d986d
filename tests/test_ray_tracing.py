"""``render(..., method="ray-tracing")`` and ``ray_path``: the depth buffer's picture without mirrors or glass, a
plane mirror equals the camera reflected in it, refraction against the optics formulas, shadows, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from frustum import (
    AmbientLight,
    Camera,
    DirectionalLight,
    FrustumError,
    Material,
    Orthographic,
    PointLight,
    Scene,
    ShadingError,
    SpotLight,
    box,
    budget,
    plane,
    ray_path,
    render,
    rotate_x,
    translate,
    uv_sphere,
)


def still_life(mirror: bool = False) -> Scene:
    scene = Scene(lights=[DirectionalLight((-0.3, -1.0, -0.5)), AmbientLight(intensity=0.3),
                          PointLight((2.0, 4.0, 3.0), attenuation=(1.0, 0.05, 0.01)),
                          SpotLight((0.0, 5.0, 0.0), (0.0, -1.0, 0.0))])  # fmt: skip
    scene.add(uv_sphere(1.0, 48, 24), Material(color=(0.9, 0.3, 0.2)), transform=translate(-1.2, 1.0, 0.0))
    shiny = Material(color=(0.9, 0.9, 0.9), shininess=7.5)  # a non-integral exponent: libm's pow
    scene.add(uv_sphere(1.0, 48, 24), shiny, transform=translate(1.2, 1.0, 0.0))
    scene.add(box((1.0, 0.6, 0.8)), Material(color=(0.2, 0.4, 0.9)), transform=translate(0.0, 0.3, 1.5))
    # the ground: z from −2 to 4 (nothing behind the mirror)
    scene.add(plane((8.0, 6.0), (8, 6)), Material(color=(0.4, 0.8, 0.4)), transform=translate(0, 0, 1) @ FLOOR)
    if mirror:  # a mirror standing at z = −2, facing +z
        scene.add(plane((6.0, 4.0)), Material(reflectivity=1.0), transform=translate(0.0, 2.0, -2.0))
    return scene


FLOOR = rotate_x(-math.pi / 2)
"""The plane primitive (in z = 0, facing +z) laid flat, facing +y."""


CAMERA = Camera.look_at((0.5, 3.0, 7.0), (0.0, 0.7, 0.0), (0.0, 1.0, 0.0), width=160, height=120)


@pytest.mark.parametrize("specular", ["blinn-phong", "phong"])
def test_without_mirrors_or_glass_equals_the_depth_buffer(specular: str) -> None:
    scene = still_life()
    for camera, samples in ((CAMERA, 1), (Camera.look_at((3.0, 2.0, 5.0), (0, 0.5, 0), width=64, height=48), 4)):
        reference = render(scene, camera, specular=specular, samples=samples, background=(0.1, 0.2, 0.3, 1.0))
        traced = render(scene, camera, method="ray-tracing", shadows=False, specular=specular, samples=samples,
                        background=(0.1, 0.2, 0.3, 1.0))  # fmt: skip
        covered = reference.depth < 1.0
        assert ((traced.depth < 1.0) == covered).mean() >= 0.999
        difference = np.abs(traced.color.astype(int) - reference.color.astype(int)).max(axis=-1)
        assert (difference <= 1).mean() >= 0.999
        assert (np.abs(traced.depth - reference.depth) < 1e-5).mean() >= 0.999
    stats = render(scene, CAMERA, method="ray-tracing", shadows=False).stats
    assert stats["primary_rays"] == 160 * 120 and stats["shadow_rays"] == 0 and stats["reflected_rays"] == 0
    assert stats["depth_reached"] == 0


def test_buffers_and_volumes_follow_the_primary_rays() -> None:
    scene = still_life()
    reference = render(scene, CAMERA, buffers=("object_id", "normals"))
    traced = render(scene, CAMERA, method="ray-tracing", shadows=False, buffers=("object_id", "normals"))
    assert (traced.object_id == reference.object_id).mean() >= 0.999
    same = (traced.object_id == reference.object_id) & (reference.object_id >= 0)
    assert np.abs(traced.normals[same] - reference.normals[same]).max() < 3e-3  # float64 vs the kernel's float32


def test_plane_mirror_equals_the_reflected_camera() -> None:
    """Inside the mirror's image the ray-traced picture is the depth buffer's picture seen by the camera reflected
    in the mirror's plane (z = −2), flipped left to right (a reflection reverses handedness)."""
    scene = still_life(mirror=True)
    traced = render(scene, CAMERA, method="ray-tracing", shadows=False, buffers=("object_id",))
    mirror_item = len(scene.items) - 1
    in_mirror = traced.object_id == mirror_item
    assert in_mirror.sum() > 2000

    def reflect_point(p: np.ndarray) -> np.ndarray:
        q = np.array(p, dtype=float)
        q[2] = -4.0 - q[2]
        return q

    eye, target = reflect_point(CAMERA.frame.eye), reflect_point(np.array([0.0, 0.7, 0.0]))
    reflected = Camera.look_at(eye, target, (0.0, 1.0, 0.0), width=160, height=120)
    without = still_life()
    reference = render(without, reflected)
    seen = reference.color[:, ::-1]
    difference = np.abs(traced.color.astype(int) - seen.astype(int)).max(axis=-1)[in_mirror]
    assert (difference <= 2).mean() >= 0.99


def _glass(ior: float) -> Material:
    return Material(color=(1.0, 1.0, 1.0), opacity=0.0, ior=ior)


def test_slab_shifts_a_ray_sideways() -> None:
    """A slab of thickness d and index n shifts a ray at incidence θ by d·sin θ·(1 − cos θ / √(n² − sin² θ))."""
    d, n = 0.5, 1.5
    for theta in (0.2, 0.5, 0.9, 1.2):
        scene = Scene(lights=[DirectionalLight((0.0, -1.0, 0.0))])
        scene.add(box((40.0, d, 40.0)), _glass(n))
        eye = np.array([-6.0 * math.sin(theta), 6.0 * math.cos(theta), 0.0])
        camera = Camera.look_at(eye, (0.0, 0.0, 0.0), (0.0, 0.0, -1.0), width=33, height=33)
        path = ray_path(scene, camera, 16.5, 16.5, max_depth=3, shadows=False)
        first = path[0]
        assert first.kind == "primary" and first.item == 0
        inside = next(s for s in path if s.kind == "refracted" and s.depth == 1)
        outside = next(s for s in path if s.kind == "refracted" and s.depth == 2)
        incoming = first.direction / np.linalg.norm(first.direction)
        np.testing.assert_allclose(outside.direction, incoming, atol=1e-12)  # leaves parallel to where it came from
        # Snell inside: sin θ_t = sin θ / n
        assert math.asin(math.hypot(inside.direction[0], inside.direction[2])) == pytest.approx(
            math.asin(math.sin(theta) / n), rel=1e-9
        )
        offset = outside.origin - first.point
        shift = np.linalg.norm(offset - (offset @ incoming) * incoming)
        expected = d * math.sin(theta) * (1.0 - math.cos(theta) / math.sqrt(n * n - math.sin(theta) ** 2))
        assert shift == pytest.approx(expected, rel=1e-6)


def test_ball_lens_focus() -> None:
    """A glass ball of radius R and index n focuses paraxial rays at f = n·R / (2(n − 1)) from its centre."""
    radius = 1.0
    for n in (1.5, 1.8):
        scene = Scene(lights=[DirectionalLight((0.0, -1.0, 0.0))])
        scene.add(uv_sphere(radius, 512, 256), _glass(n))  # axis through the equator, where the facets are even
        camera = Camera.look_at((0.0, 0.0, 10.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0),
                                projection=Orthographic(0.2, 0.1, 100.0), width=101, height=101)  # fmt: skip
        crossings = []
        for x in (50.5 + 2.0, 50.5 + 3.0, 50.5 - 2.5):  # heights h = 0.004 … 0.006 R
            path = ray_path(scene, camera, x, 50.5, max_depth=2, shadows=False)
            out = next(s for s in path if s.kind == "refracted" and s.depth == 2)
            # where the exit ray crosses the axis (x = 0)
            s = -out.origin[0] / out.direction[0]
            crossings.append(-(out.origin[2] + s * out.direction[2]))
        focus = n * radius / (2.0 * (n - 1.0))
        assert np.allclose(crossings, focus, rtol=2e-3), (crossings, focus)


def test_total_internal_reflection_beyond_the_critical_angle() -> None:
    """Inside glass, a ray meeting the surface beyond asin(1/n) is reflected totally; below it, it leaves."""
    n = 1.5
    critical = math.asin(1.0 / n)
    for angle, total in ((critical - 0.02, False), (critical + 0.02, True), (1.0, True)):
        scene = Scene(lights=[DirectionalLight((0.0, -1.0, 0.0))])
        scene.add(box((40.0, 40.0, 40.0)), _glass(n))  # the camera inside it
        direction = np.array([math.sin(angle), math.cos(angle), 0.0])  # toward the top face (y = 20)
        eye = np.array([0.0, 10.0, 0.0])
        camera = Camera.look_at(eye, eye + direction, (0.0, 0.0, 1.0), width=33, height=33)
        path = ray_path(scene, camera, 16.5, 16.5, max_depth=1, shadows=False, cull_back_faces=False)
        first = path[0]
        assert first.item == 0 and first.point[1] == pytest.approx(20.0)
        kinds = {s.kind: s for s in path[1:]}
        if total:
            assert set(kinds) == {"reflected"} and kinds["reflected"].total_internal_reflection
            assert kinds["reflected"].weight == pytest.approx(1.0)
            np.testing.assert_allclose(kinds["reflected"].direction, direction * [1.0, -1.0, 1.0], atol=1e-12)
        else:
            assert set(kinds) == {"refracted"}
            sine = kinds["refracted"].direction[0] / np.linalg.norm(kinds["refracted"].direction)
            assert sine == pytest.approx(n * math.sin(angle), rel=1e-9)


def test_shadows() -> None:
    material = Material(color=(0.5, 0.5, 0.5), ambient=0.2, diffuse=0.8, specular=0.0)
    scene = Scene(lights=[DirectionalLight((0.0, -1.0, 0.0))])
    scene.add(uv_sphere(0.5, 32, 16), material, transform=translate(0.0, 1.5, 0.0))
    scene.add(plane((10.0, 10.0)), material, transform=FLOOR)
    camera = Camera.look_at((4.0, 3.0, 0.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), width=96, height=96)
    lit = render(scene, camera, method="ray-tracing", shadows=False)
    shadowed = render(scene, camera, method="ray-tracing")
    default = render(scene, camera, method="ray-tracing", shadows=None)
    assert np.array_equal(shadowed.color, default.color)
    ray = scene.intersect(*_pixel_rays(camera))
    on_plane = ray.item == 1
    start = np.where(on_plane[:, None], ray.point + 1e-9 * ray.normal, 0.0)
    blocked = scene.occluded(start, np.array([0.0, 1.0, 0.0]), np.inf) & on_plane
    assert blocked.sum() > 50
    rows, cols = np.divmod(np.flatnonzero(blocked), camera.width)
    image = camera.height - 1 - rows
    ambient_only = math.floor(0.5 * 0.2 * 255.0 + 0.5)
    assert (shadowed.color[image, cols, :3] == ambient_only).mean() >= 0.99
    assert (lit.color[image, cols, :3] > ambient_only + 50).all()
    unlit_elsewhere = on_plane & ~blocked
    rows, cols = np.divmod(np.flatnonzero(unlit_elsewhere), camera.width)
    image = camera.height - 1 - rows
    assert (np.abs(shadowed.color[image, cols].astype(int) - lit.color[image, cols]) <= 1).mean() >= 0.99
    # cast_shadows=False: no shadow rays for the light
    unshadowed = Scene(lights=[DirectionalLight((0.0, -1.0, 0.0), cast_shadows=False)])
    for item in scene.items:
        unshadowed.add(item.mesh, item.material, transform=item.world_from_model)
    off = render(unshadowed, camera, method="ray-tracing")
    assert np.array_equal(off.color, lit.color) and off.stats["shadow_rays"] == 0


def _pixel_rays(camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    j, i = np.divmod(np.arange(camera.width * camera.height), camera.width)
    origins, directions = [], []
    for x, y in zip(i + 0.5, j + 0.5, strict=True):
        ray = camera.ray((x, y))
        origins.append(ray.origin)
        directions.append(ray.direction)
    return np.array(origins), np.array(directions)


def test_ray_tracing_counts_and_depth_limit() -> None:
    scene = still_life(mirror=True)
    shallow = render(scene, CAMERA, method="ray-tracing", max_depth=0)
    deep = render(scene, CAMERA, method="ray-tracing", max_depth=3)
    assert shallow.stats["reflected_rays"] == 0 and shallow.stats["depth_reached"] == 0
    assert deep.stats["reflected_rays"] > 2000 and deep.stats["depth_reached"] >= 1
    assert deep.stats["shadow_rays"] > 0


def test_bad_input() -> None:
    scene = still_life()
    camera = Camera.look_at((0, 0, 5), (0, 0, 0), width=16, height=12)
    for depth in (-1, 65, 2.5, True, "5"):
        with pytest.raises(FrustumError, match=r"max_depth = .* is not an integer in \[0, 64\]"):
            render(scene, camera, method="ray-tracing", max_depth=depth)
    for ior in (0.0, -1.5, float("nan"), float("inf")):
        with pytest.raises(ShadingError, match=r"ior = .* is not (a )?finite"):
            Material(ior=ior)
    for reflectivity in (-0.1, 1.5):
        with pytest.raises(ShadingError, match=r"reflectivity = .* is (negative|above 1)"):
            Material(reflectivity=reflectivity)
    with pytest.raises(ShadingError, match="cast_shadows = 'yes' is not a bool"):
        PointLight((0, 1, 0), cast_shadows="yes")
    with pytest.raises(FrustumError, match="shadows = 'soft' is not None, False, True or 'ray'"):
        render(scene, camera, method="ray-tracing", shadows="soft")
    with pytest.raises(FrustumError, match="method 'ray-tracing' draws mode 'surface' with shading 'phong'"):
        render(scene, camera, method="ray-tracing", shading="flat")
    with pytest.raises(FrustumError, match=r"ray_path: max_depth = 99 is not an integer in \[0, 64\]"):
        ray_path(scene, camera, 1.0, 1.0, max_depth=99)
    # the work budget: rays × levels
    with budget(operations=10**6), pytest.raises(FrustumError, match=r"ray tracing 16 x 12 pixels x \(max_depth"):
        render(scene, camera, method="ray-tracing", max_depth=64)
    with budget(operations=10**6):
        render(scene, camera, method="ray-tracing", max_depth=1, shadows=False)


def test_empty_scene_and_background() -> None:
    camera = Camera.look_at((0, 0, 5), (0, 0, 0), width=16, height=12)
    frame = render(Scene(), camera, method="ray-tracing", background=(0.2, 0.4, 0.6, 0.5))
    assert (frame.color == [51, 102, 153, 128]).all() and (frame.depth == 1.0).all()
    path = ray_path(Scene(), camera, 8.0, 6.0)
    assert len(path) == 1 and path[0].t == math.inf and path[0].item == -1


def test_scene_file_and_explain(tmp_path, capsys) -> None:
    from pathlib import Path

    from frustum.app.cli import main
    from frustum.errors import SceneFileError
    from frustum.scenefile import load_scene_file

    example = Path(__file__).parents[1] / "examples" / "ray_tracing.toml"
    loaded = load_scene_file(example)
    assert loaded.options["method"] == "ray-tracing" and loaded.options["max_depth"] == 6
    assert loaded.options["shadows"] is True
    materials = {item.material.reflectivity for item in loaded.scene.items}
    assert materials == {0.0, 0.85, 0.08} and {item.material.ior for item in loaded.scene.items} == {1.0, 1.5}
    text = example.read_text().replace("max_depth = 6", "max_depth = 65")
    (tmp_path / "checkerboard.ply").write_bytes((example.parent / "checkerboard.ply").read_bytes())
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    with pytest.raises(SceneFileError, match=r"bad.toml:\d+: render.max_depth = 65"):
        load_scene_file(bad)
    bad.write_text(example.read_text().replace("ior = 1.5", "ior = 0.0"))
    with pytest.raises(SceneFileError, match=r"materials.glass.*ior = 0.0"):
        load_scene_file(bad)
    small = tmp_path / "small.toml"
    small.write_text(example.read_text().replace("size = [480, 360]", "size = [40, 30]").replace("samples = 4", ""))
    (tmp_path / "checkerboard.ply").write_bytes((example.parent / "checkerboard.ply").read_bytes())
    main(["explain", str(small), "--method", "ray-tracing"])
    lines = dict(line.split(None, 1) for line in capsys.readouterr().out.splitlines() if line.strip())
    assert lines["method"] == "ray-tracing" and int(lines["primary_rays"]) == 40 * 30
    assert int(lines["shadow_rays"]) > 0 and int(lines["reflected_rays"]) > 0 and int(lines["refracted_rays"]) > 0
    assert 1 <= int(lines["depth_reached"]) <= 6
