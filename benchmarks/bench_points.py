"""Point clouds and Gaussian splats at 1080p (issue 47).

    python benchmarks/bench_points.py                 # both, medians of 3 warm frames
    python benchmarks/bench_points.py --only points   # (a) only

(a) 1 M coloured points drawn as 1-pixel squares (``style="square", point_size=1``, unlit) at 1920 × 1080 by
``frustum.render``, against Mesa llvmpipe's ``GL_POINTS`` (moderngl, ``gl_PointSize = 1``, depth test, the same
points and camera) measured in the same run. Both frames count the same work: clear, draw, finish and read colour
(RGBA8) and depth back (frustum returns them as its Frame). Target: frustum / llvmpipe <= 0.5.

(b) 1 M generated Gaussian splats at 1920 × 1080, seconds per warm frame (target: <= 2 s per frame on the 2-core
machine), two scenes:
  "surfaces": splats lying on surfaces as a trained 3DGS scene's do (a sphere of radius 0.8, a torus and a ground
  square seen from 4 units): flat Gaussians (σ 3–12 mm along the surface, 1 mm across it, so 1–4 pixels), turned
  into the surface, opacities uniform in [0.5, 1], SH degree 1, colours by position;
  "fog": the worst case, every splat seen through every other: random positions in a 2 × 2 × 2 box, log-scales
  uniform in [−7, −5] (σ 1–7 mm), random rotations, opacities uniform in [0.2, 1] (few pixels reach T < 1e-4).

Compile time is reported separately (the first frame of each). Prints one line per measurement and the ratio.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time

import numpy as np

WIDTH, HEIGHT = 1920, 1080
COUNT = 1_000_000


def camera():
    from frustum import Camera, Perspective

    return Camera.look_at((0.0, 0.0, 4.0), (0, 0, 0), (0, 1, 0), projection=Perspective(math.radians(45), 0.5, 20.0),
                          width=WIDTH, height=HEIGHT)  # fmt: skip


CPU_SECONDS: list[float] = []
"""Process CPU seconds (all threads) of each timed call of the last ``median_time``: on a loaded machine the wall
time measures the neighbours too, the CPU time much less so."""


def median_time(function, frames: int = 3) -> tuple[float, float]:
    """(first call seconds, median of `frames` later calls); their CPU seconds in ``CPU_SECONDS``."""
    start = time.perf_counter()
    function()
    first = time.perf_counter() - start
    times = []
    CPU_SECONDS.clear()
    for _ in range(frames):
        start, cpu = time.perf_counter(), time.process_time()
        function()
        times.append(time.perf_counter() - start)
        CPU_SECONDS.append(time.process_time() - cpu)
    return first, statistics.median(times)


def bench_points() -> None:
    from frustum import PointCloud, Scene, render

    rng = np.random.default_rng(0)
    points = rng.uniform(-1.0, 1.0, size=(COUNT, 3)) * (1.5, 0.8, 1.0)
    colors = rng.integers(0, 256, size=(COUNT, 3), dtype=np.uint8)
    scene = Scene()
    scene.add(PointCloud(points, colors), style="square", point_size=1)
    cam = camera()
    first, ours = median_time(lambda: render(scene, cam, shading="none"))
    print(f"(a) frustum 1M points 1px 1080p: first {first * 1e3:.0f} ms, warm median {ours * 1e3:.1f} ms "
          f"(CPU {statistics.median(CPU_SECONDS) * 1e3:.0f} ms)")
    theirs = gl_points(points, colors, cam)
    if theirs is not None:
        print(f"(a) llvmpipe GL_POINTS 1M 1px 1080p: warm median {theirs * 1e3:.1f} ms (clear+draw+finish+readback)")
        print(f"(a) ratio frustum / llvmpipe = {ours / theirs:.2f} (target <= 0.5)")


def gl_points(points: np.ndarray, colors: np.ndarray, cam) -> float | None:
    try:
        import moderngl

        ctx = moderngl.create_standalone_context(require=330, backend="egl")
    except Exception as error:  # no moderngl or no EGL here
        print(f"(a) llvmpipe: not available ({error})")
        return None
    print(f"(a) GL_RENDERER: {ctx.info['GL_RENDERER']}")
    program = ctx.program(
        vertex_shader="""
        #version 330 core
        uniform mat4 u_clip_from_world;
        in vec3 in_position;
        in vec3 in_color;
        out vec3 v_color;
        void main() {
            gl_Position = u_clip_from_world * vec4(in_position, 1.0);
            gl_PointSize = 1.0;
            v_color = in_color;
        }
        """,
        fragment_shader="""
        #version 330 core
        in vec3 v_color;
        out vec4 f_color;
        void main() { f_color = vec4(v_color, 1.0); }
        """,
    )
    program["u_clip_from_world"].write(np.asarray(cam.clip_from_world, dtype="f4").T.tobytes())
    vao = ctx.vertex_array(program, [(ctx.buffer(points.astype("f4")), "3f", "in_position"),
                                     (ctx.buffer(colors), "3f1", "in_color")])  # fmt: skip
    fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer((WIDTH, HEIGHT), 4, dtype="f1")],
                          depth_attachment=ctx.depth_renderbuffer((WIDTH, HEIGHT)))  # fmt: skip
    fbo.use()
    ctx.enable(moderngl.DEPTH_TEST | moderngl.PROGRAM_POINT_SIZE)
    color = np.empty((HEIGHT, WIDTH, 4), dtype=np.uint8)
    depth = np.empty((HEIGHT, WIDTH), dtype=np.float32)

    def frame() -> None:
        fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        vao.render(moderngl.POINTS)
        ctx.finish()
        fbo.read_into(color, components=4, dtype="f1")
        fbo.read_into(depth, components=1, attachment=-1, dtype="f4")

    frame()
    _, median = median_time(frame)
    ctx.release()
    return median


def surface_splats(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Positions and unit normals of COUNT points on a sphere, a torus and a ground square (a third each)."""
    third = COUNT // 3
    sphere = rng.normal(size=(third, 3))
    sphere /= np.linalg.norm(sphere, axis=1, keepdims=True)
    phi, theta = rng.uniform(0, 2 * np.pi, size=(2, third))
    ring = np.c_[np.cos(phi), np.sin(phi), np.zeros(third)]
    tube = np.cos(theta)[:, None] * ring + np.sin(theta)[:, None] * np.array([0.0, 0.0, 1.0])
    rest = COUNT - 2 * third
    ground = np.c_[rng.uniform(-2, 2, rest), np.full(rest, -1.0), rng.uniform(-2, 2, rest)]
    positions = np.r_[sphere * 0.8 + (-0.6, 0.0, 0.0), (ring * 0.7 + tube * 0.25) @ np.diag([1.0, 0.3, 1.0])
                      + (0.9, 0.0, -0.3), ground]  # fmt: skip
    normals = np.r_[sphere, tube, np.tile([0.0, 1.0, 0.0], (rest, 1))]
    return positions, normals


def bench_splats() -> None:
    from frustum import GaussianSplats, Scene, render

    rng = np.random.default_rng(1)
    sh = np.zeros((COUNT, 4, 3), dtype=np.float32)
    sh[:, 1:, :] = rng.normal(size=(COUNT, 3, 3)) * 0.1
    positions, normals = surface_splats(rng)
    sh[:, 0, :] = (np.clip(positions * 0.3 + 0.5, 0, 1) - 0.5) / 0.28209479177387814
    # the Gaussian's z axis along the normal: the rotation taking (0, 0, 1) to n (half-way quaternion)
    half = normals + np.array([0.0, 0.0, 1.0])
    half /= np.maximum(np.linalg.norm(half, axis=1, keepdims=True), 1e-12)
    rotations = np.c_[half[:, 2], np.cross([0.0, 0.0, 1.0], half)]
    rotations[np.linalg.norm(rotations, axis=1) < 1e-9] = (0.0, 1.0, 0.0, 0.0)  # n = −z: a half turn about x
    scales = np.c_[np.exp(rng.uniform(np.log(0.003), np.log(0.012), size=(COUNT, 2))), np.full(COUNT, 0.001)]
    scenes = {
        "surfaces": GaussianSplats(positions, scales, rotations, rng.uniform(0.5, 1.0, size=COUNT), sh),
        "fog": GaussianSplats(rng.uniform(-1.0, 1.0, size=(COUNT, 3)), np.exp(rng.uniform(-7.0, -5.0, size=(COUNT, 3))),
                              rng.normal(size=(COUNT, 4)), rng.uniform(0.2, 1.0, size=COUNT), sh),
    }  # fmt: skip
    cam = camera()
    for name, splats in scenes.items():
        scene = Scene()
        scene.add(splats)
        first, median = median_time(lambda scene=scene: render(scene, cam))
        print(f"(b) frustum 1M splats 1080p, {name}: first {first:.2f} s, warm median {median:.2f} s/frame "
              f"(CPU {statistics.median(CPU_SECONDS):.2f} s on all threads; target <= 2 s per frame)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", choices=("points", "splats"))
    args = parser.parse_args()
    print(f"load average {os.getloadavg()}, cores {os.cpu_count()}")
    if args.only != "splats":
        bench_points()
    if args.only != "points":
        bench_splats()
    print(f"load average {os.getloadavg()}")


if __name__ == "__main__":
    main()
