"""Compile every kernel ahead of time: ``frustum warmup`` (or ``frustum.warmup()``).

Numba compiles each kernel the first time it runs and keeps the machine code in its on-disk cache, so only the
first render in a new environment pays for compilation (about 8 s of CPU for the README example, more for the
modes it does not use). ``warmup`` runs one small task per family of kernels — the surface paths (the fast
directional shader, the general shader with textures, vertex colors, point and spot lights, depth cueing,
transparency and extra buffers, Gouraud and flat), the line and point modes, clipping of faces that cross the view
volume, exact hidden lines, the fractal generators, and the visible-surface methods of ``render(..., method=...)``
— in parallel processes, each filling the shared cache.
"""

from __future__ import annotations

import importlib
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from frustum.app.runtime import exit_with_parent

__all__ = ["WarmupReport", "warmup"]


@dataclass(frozen=True)
class WarmupReport:
    """What ``warmup`` did: kernels compiled (0 when the cache already held them all), processes, seconds."""

    kernels: int
    processes: int
    seconds: float

    def __str__(self) -> str:
        if self.kernels == 0:
            return f"all kernels were already compiled ({self.seconds:.1f} s to check, {self.processes} processes)"
        return f"compiled {self.kernels} kernels in {self.seconds:.1f} s ({self.processes} processes)"


def _api() -> SimpleNamespace:
    """The public names the tasks use, from their own modules (the interface layer imports downward only)."""
    names = {}
    for module in ("camera", "clipping", "geometry", "projection", "render", "render.radiosity", "scene", "shading",
                   "shading.environment", "transforms", "output.svg"):  # fmt: skip
        loaded = importlib.import_module(f"frustum.{module}")  # (``from frustum import render`` is the function)
        names.update({name: getattr(loaded, name) for name in loaded.__all__})
    return SimpleNamespace(**names)


def _scene(light: str = "directional", **mesh_options: object):  # type: ignore[no-untyped-def]
    fr = _api()

    lights = {
        "directional": [fr.DirectionalLight(direction=(-0.3, -0.6, -1.0))],
        "all": [fr.AmbientLight(intensity=0.3), fr.DirectionalLight(direction=(0, -1, -1)),
                fr.PointLight((2, 3, 4)), fr.SpotLight((0, 3, 3), (0, -1, -1))],
    }[light]
    scene = fr.Scene(lights=lights)
    sphere = fr.uv_sphere(1.0, 16, 8)
    if mesh_options:
        sphere = fr.Mesh(sphere.vertices, sphere.faces, sphere.vertex_normals, **mesh_options)
    scene.add(sphere, fr.Material(color=(0.8, 0.5, 0.2)), fr.rotate_y(0.3))
    return scene


def _camera(eye: tuple[float, float, float] = (0.0, 1.0, 4.0)):  # type: ignore[no-untyped-def]
    fr = _api()

    return fr.Camera.look_at(eye, (0, 0, 0), (0, 1, 0), projection=fr.Perspective(fovy=0.8, near=0.1, far=20),
                             width=48, height=32)  # fmt: skip


def _surfaces_fast() -> None:
    fr = _api()

    scene = fr.Scene(lights=[fr.DirectionalLight(direction=(0, -1, -1))])
    scene.add(fr.uv_sphere(1.0, 16, 8), fr.Material(color=(0.8, 0.5, 0.2)))
    fr.render(scene, _camera())
    fr.render(scene, _camera(), samples=4, cull_back_faces=False)
    fr.render(scene, _camera((0.0, 0.0, 0.5)))  # the eye inside the sphere: faces crossing the view volume
    scene.add(fr.uv_sphere(0.5, 8, 4), fr.Material(), fr.translate(1.5, 0, 0))  # two meshes: stage by stage
    fr.render(scene, _camera())
    # float32 vertices and normals (mesh files, GPU-style buffers, the benchmark's scenes): their own specializations
    sphere = fr.uv_sphere(1.0, 16, 8)
    compact = fr.Scene(lights=[fr.DirectionalLight(direction=(0, -1, -1))])
    compact.add(fr.Mesh(sphere.vertices.astype(np.float32), sphere.faces, sphere.vertex_normals.astype(np.float32)),
                fr.Material(color=(0.8, 0.5, 0.2)))  # fmt: skip
    fr.render(compact, _camera())
    fr.render(compact, _camera((0.0, 0.0, 0.5)))
    # a moved mesh: world points and normals computed (NumPy below render.KERNEL_MIN_VERTICES vertices, kernels
    # above), so the tile pipeline's specialization for computed rather than the mesh's own arrays
    large = fr.uv_sphere(1.0, 260, 256)  # 67,075 vertices
    compact = fr.Mesh(large.vertices.astype(np.float32), large.faces, large.vertex_normals.astype(np.float32))
    for mesh in (large, compact):
        moved = fr.Scene(lights=[fr.DirectionalLight(direction=(0, -1, -1))])
        moved.add(mesh, fr.Material(color=(0.8, 0.5, 0.2)), fr.rotate_y(0.3))
        fr.render(moved, _camera())


def _surfaces_general() -> None:
    fr = _api()

    scene = _scene("all")
    camera = _camera()
    fr.render(scene, camera, cull_back_faces=False)
    fr.render(scene, camera, depth_cue=fr.DepthCue(near=2, far=6), buffers=("normals", "object_id"))
    texture = np.linspace(0, 1, 4 * 4 * 4, dtype=np.float32).reshape(4, 4, 4)
    textured = fr.Scene(lights=[fr.PointLight((2, 3, 4))])
    sphere = fr.uv_sphere(1.0, 16, 8)
    colors = np.abs(sphere.vertex_normals)
    textured.add(fr.Mesh(sphere.vertices, sphere.faces, uvs=sphere.uvs, vertex_colors=colors),
                 fr.Material(texture=texture, opacity=0.5))  # fmt: skip
    fr.render(textured, camera)


def _surfaces_interpolated() -> None:
    fr = _api()

    scene, camera = _scene("all"), _camera()
    for shading in ("gouraud", "flat", "normals", "depth", "none"):
        fr.render(scene, camera, shading=shading)


def _lines() -> None:
    fr = _api()

    scene, camera = _scene(), _camera()
    scene.add(fr.Polyline([[0, 0, 0], [1, 1, 0], [1, 2, 1]]), fr.Material(color=(1, 1, 0)))
    for mode in ("wireframe", "points", "hidden-line", "surface+edges"):
        fr.render(scene, camera, mode=mode, depth_cue=fr.DepthCue(near=2, far=6) if mode == "wireframe" else None)
    fr.render(scene, camera, mode="hidden-line", hidden="dashed")


def _vector() -> None:
    fr = _api()

    scene, camera = _scene(), _camera()
    fr.render_svg(scene, camera, hidden="dashed")
    fr.clip_polygon([[0, 0, 0, 1], [2, 0, 0, 1], [0, 2, 0, 1]])
    fr.clip_line([-2, 0, 0, 1], [2, 0.5, 0, 1])


def _fractals() -> None:
    fr = _api()

    fr.mandelbrot(width=8, height=8, max_iter=8)
    fr.julia(-0.8 + 0.156j, width=8, height=8, max_iter=8)
    fr.quaternion_julia(resolution=4, max_iter=4)
    fr.barnsley_fern().chaos_game(200, seed=0)
    fr.CLASSIC_LSYSTEMS["koch"].path(1)


def _visibility_methods() -> None:
    fr = _api()

    scene = _scene()
    camera = _camera()
    for method in fr.VISIBILITY_METHODS:
        if method != "depth-buffer":
            fr.render(scene, camera, method=method)
    fr.render(scene, camera, stats=True)


def _volumes() -> None:
    fr = _api()

    volume = fr.head_phantom(12)
    camera = _camera((0.0, 0.5, 3.0))
    for mode in ("composite", "mip", "isosurface"):
        scene = fr.Scene(lights=[fr.DirectionalLight(direction=(0, -1, -1))])
        scene.add_volume(volume, mode=mode, transform=fr.scale(1.5, 1.5, 1.5))
        if mode == "composite":  # two overlapping composite volumes: the merged kernel
            scene.add_volume(volume, transform=fr.translate(0.2, 0, 0) @ fr.scale(1.5, 1.5, 1.5))
        fr.render(scene, camera)


def _points_and_splats() -> None:
    fr = _api()

    camera = _camera()
    rng = np.random.default_rng(0)
    points = rng.uniform(-1, 1, size=(50, 3))
    for style in ("square", "disk", "sphere", "surfel"):
        scene = fr.Scene(lights=[fr.DirectionalLight(direction=(0, -1, -1))])
        cloud = fr.PointCloud(points, rng.random((50, 3)), normals=rng.normal(size=(50, 3)))
        scene.add(cloud, style=style, **({"radius": 0.05} if style in ("sphere", "surfel") else {}))
        fr.render(scene, camera, eye_dome=style == "square")
    splats = fr.GaussianSplats(points, np.full((50, 3), 0.05), rng.normal(size=(50, 4)), np.full(50, 0.5),
                               np.zeros((50, 4, 3), dtype=np.float32))  # fmt: skip
    scene = fr.Scene()
    scene.add(splats)
    fr.render(scene, camera)


def _shadows() -> None:
    fr = _api()

    camera = _camera()
    for light in (fr.DirectionalLight(direction=(-0.3, -1, -0.5)), fr.PointLight((1, 3, 2)),
                  fr.SpotLight((0, 3, 2), (0, -1, -0.6))):  # fmt: skip
        scene = fr.Scene(lights=[light])
        scene.add(fr.uv_sphere(0.6, 16, 8), fr.Material(color=(0.8, 0.5, 0.2)), fr.translate(0, 0.3, 0))
        scene.add(fr.box((4.0, 0.1, 4.0)), fr.Material(), fr.translate(0, -0.5, 0))
        for shadows in (True, "ray"):
            fr.render(scene, camera, shadows=shadows, buffers=("shadow",))
    one = fr.Scene(lights=[fr.DirectionalLight(direction=(-0.3, -1, -0.5))])
    one.add(fr.uv_sphere(0.6, 16, 8), fr.Material(color=(0.8, 0.5, 0.2)))
    fr.render(one, camera, shadows=True)  # one mesh: the fused tile path


def _physically_based_and_ground_truth() -> None:
    fr = _api()

    sky = np.linspace(0.0, 1.0, 16 * 32 * 3, dtype=np.float32).reshape(16, 32, 3)
    scene = fr.Scene(lights=[fr.DirectionalLight(direction=(0, -1, -1))], environment=fr.EnvironmentMap(sky))
    scene.add(fr.uv_sphere(1.0, 16, 8), fr.Material(color=(0.8, 0.5, 0.2), model="pbr", metallic=1.0,
                                                     roughness=0.3), label="ball")  # fmt: skip
    scene.add(fr.uv_sphere(0.5, 8, 4), fr.Material(model="pbr"), fr.translate(1.2, 0, 0), label="small")
    camera = _camera()
    fr.render(scene, camera, shading="pbr", tone_map="aces")
    fr.render(scene, camera, buffers=("instance", "semantic", "amodal", "object_coords", "nocs", "flow"),
              next=(scene, _camera((0.1, 1.0, 4.0))), samples=4)  # fmt: skip


def _rays_and_radiosity() -> None:
    fr = _api()

    scene = _scene("all")
    origins = np.tile((0.0, 0.0, 4.0), (8, 1))
    directions = np.tile((0.0, 0.0, -1.0), (8, 1))
    scene.intersect(origins, directions)
    scene.intersect(origins, directions, fields=("t", "item", "face"))
    scene.occluded(origins, directions, np.full(8, 10.0))
    fr.render(scene, _camera(), method="ray-tracing")
    room = fr.Scene()
    room.add(fr.box((2.0, 2.0, 2.0)).flipped(), fr.Material(color=(0.7, 0.7, 0.7)))
    room.add(fr.box((0.4, 0.05, 0.4)), fr.Material(emissive=(1, 1, 1)), fr.translate(0, 0.9, 0))
    fr.radiosity(room, patch_size=0.5)
    fr.radiosity(room, patch_size=0.5, form_factors="hemicube", hemicube=16)


def _pyrender_scenes() -> None:
    from frustum.interop import pyrender_shading

    fr = _api()

    scene, camera = _scene(), _camera()
    frame = fr.render(scene, camera, shading="none", buffers=("normals", "object_id"))
    items = np.array([[0.8, 0.5, 0.2, 0.0, 0.5, 0.0, 0.0, 0.0, pyrender_shading.MODE_CONSTANT, 1.0]])
    light = (pyrender_shading.LIGHT_DIRECTIONAL, np.ones(3), np.zeros(3), np.array([0.0, -1.0, -1.0]), 0.0, 0.0, -1)
    pyrender_shading.shade(frame, camera, items, [light], (0.1, 0.1, 0.1), True)


TASKS: dict[str, Callable[[], None]] = {
    "surfaces (general shader)": _surfaces_general,
    "surfaces (fast path, supersampling, clipping)": _surfaces_fast,
    "surfaces (Gouraud, flat, inspection modes)": _surfaces_interpolated,
    "lines and points": _lines,
    "hidden lines and clipping": _vector,
    "fractals": _fractals,
    "visible-surface methods (scan-line, area subdivision, painter, ray casting, A-buffer)": _visibility_methods,
    "volume ray casting (composite, merged, MIP, isosurface)": _volumes,
    "point clouds and Gaussian splats": _points_and_splats,
    "shadows (maps of every light, the fused tile path, shadow rays)": _shadows,
    "physically based shading and ground-truth buffers": _physically_based_and_ground_truth,
    "ray queries, ray tracing and radiosity": _rays_and_radiosity,
    "pyrender scenes (pyrender's light model)": _pyrender_scenes,
}
"""The families of kernels ``warmup`` compiles, each by running small examples of what uses them."""


FIRST_PICTURE: tuple[tuple[str, str, str], ...] = (
    ("frustum.raster.tiles", "fill_tiles",
     "(Array(int32, 2, 'C', True, aligned=True), Array(uint8, 1, 'C', False, aligned=True), "
     "Array(int32, 2, 'C', False, aligned=True), Array(int64, 1, 'C', False, aligned=True), "
     "Array(int32, 1, 'C', False, aligned=True), Array(int32, 1, 'C', False, aligned=True), "
     "Array(int64, 1, 'C', False, aligned=True), Array(int64, 2, 'C', False, aligned=True), "
     "Array(int64, 1, 'C', False, aligned=True), Array(int64, 1, 'C', False, aligned=True), "
     "Array(int64, 2, 'C', False, aligned=True), Array(int32, 1, 'C', False, aligned=True), int64, int64)"),
    ("frustum.raster.shade", "shade_pixels_phong",
     "(Array(float32, 2, 'C', False, aligned=True), Array(int32, 2, 'C', False, aligned=True), "
     "Array(float32, 3, 'C', False, aligned=True), Array(int32, 2, 'C', True, aligned=True), "
     "Array(float64, 2, 'C', False, aligned=True), Array(float64, 2, 'C', False, aligned=True), "
     "Array(float64, 1, 'C', False, aligned=True), Array(float64, 2, 'C', False, aligned=True), "
     "Array(int64, 1, 'C', False, aligned=True), Array(uint8, 3, 'C', False, aligned=True), int64, int64)"),
    ("frustum.raster.lines", "draw_lines",
     "(Array(float64, 2, 'C', False, aligned=True), Array(float64, 1, 'C', False, aligned=True), "
     "Array(int64, 2, 'C', True, aligned=True), Array(float64, 2, 'C', True, aligned=True), "
     "Array(float64, 1, 'C', False, aligned=True), Array(float64, 1, 'C', False, aligned=True), "
     "Array(float32, 2, 'C', False, aligned=True), Array(uint8, 3, 'C', False, aligned=True))"),
)  # fmt: skip
"""Kernels of the README's first picture (``frustum render examples/teapot.toml``: Phong-shaded surfaces and
depth-tested lines) that a second process compiles while the renderer compiles the others
(``compile_in_background``), as ``(module, kernel, argument types)``, in the order the render needs them. The
renderer itself compiles ``project_vertices``, ``count_tiles`` and ``rasterize_tiles`` (about 6 s of CPU) while
the child compiles these three (about 6 s); each compiled kernel goes to the cache, where the renderer's first call
finds it. ``tests/test_cold_start.py`` checks that these are the types the README render calls them with."""


def compile_in_background(plan: tuple[tuple[str, str, str], ...] = FIRST_PICTURE):  # type: ignore[no-untyped-def]
    """Start compiling `plan`'s kernels in a second process (``frustum.raster._background``); the running child,
    or None where nothing was started (a warm cache, one core, ``FRUSTUM_BACKGROUND_COMPILE=0``)."""
    from frustum.raster import _background

    return _background.start(plan)


def _run(name: str) -> int:
    """Run one task in this process; return how many kernels it compiled (outermost compilations)."""
    from numba.core import event

    compiled = []

    class Count(event.Listener):
        def __init__(self) -> None:
            self.depth = 0

        def on_start(self, ev: event.Event) -> None:
            self.depth += 1

        def on_end(self, ev: event.Event) -> None:
            self.depth -= 1
            if self.depth == 0:
                compiled.append(1)

    with event.install_listener("numba:compile", Count()):
        TASKS[name]()
    return len(compiled)


def warmup(processes: int | None = None) -> WarmupReport:
    """Compile every kernel frustum has into Numba's on-disk cache, `processes` at a time (default: the cores)."""
    import concurrent.futures  # here, not at the top: a plain render imports this module (compile_in_background)
    import multiprocessing

    processes = max(1, min(processes or os.cpu_count() or 1, len(TASKS)))
    start = time.perf_counter()
    context = multiprocessing.get_context("spawn")  # fresh interpreters: no threads or half-loaded state copied
    with concurrent.futures.ProcessPoolExecutor(processes, mp_context=context, initializer=exit_with_parent,
                                                initargs=(os.getpid(),)) as pool:  # fmt: skip
        counts = list(pool.map(_run, TASKS))
    return WarmupReport(sum(counts), processes, time.perf_counter() - start)
