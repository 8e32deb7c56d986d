"""OpenGL shadow-mapping anchor: a bench scene with one directional light, shadow-mapped the standard way, in Mesa
llvmpipe through moderngl (the pattern of ``../shared/bench/anchor_moderngl.py``).

    python benchmarks/anchor_moderngl_shadows.py --scene PATH.npz [--frames 10] [--warmup 2] [--map-size 2048]

Per frame: (1) a depth-only pass from the light into a DEPTH_COMPONENT24 texture of ``--map-size``² texels (an
orthographic projection fitted to the mesh's bounding sphere, front faces culled against acne, polygon offset
1.1/4.0), (2) the main pass as in the shared anchor (per-pixel Lambert + Blinn-Phong) with the light's terms
multiplied by the lit fraction from a ``sampler2DShadow`` (compare mode LEQUAL, NEAREST) over 2×2 texel taps
(percentage-closer filtering), then glFinish and the readback of color (RGBA8) and depth (float32). The same
frame without shadows (no depth pass, no lookup) is timed too. Prints one JSON object: medians in milliseconds
(``frame_ms``, ``frame_shadowed_ms``, ``depth_pass_ms``), the GL renderer, and the shadowed fraction of covered
pixels. A scene file of several items (``item_face_starts``, ``item_colors``: ``bench_shadows.py``'s ``items_8``)
is drawn one call per item in both passes, each item with its own color.

Needs Mesa's EGL/llvmpipe (Debian: libegl1 libgl1 libegl-mesa0 libgl1-mesa-dri libglx-mesa0 libgbm1) and
``pip install moderngl==5.13.0 glcontext==3.1.0``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time

import numpy as np
from _anchor_camera import look_at, scene_camera

DEPTH_VERTEX = """
#version 330 core
uniform mat4 u_light_mvp;
in vec3 in_position;
void main() { gl_Position = u_light_mvp * vec4(in_position, 1.0); }
"""
DEPTH_FRAGMENT = """
#version 330 core
void main() {}
"""
MAIN_VERTEX = """
#version 330 core
uniform mat4 u_mvp;
uniform mat4 u_light_mvp;
in vec3 in_position;
in vec3 in_normal;
out vec3 v_world;
out vec3 v_normal;
out vec4 v_light;
void main() {
    v_world = in_position;
    v_normal = in_normal;
    v_light = u_light_mvp * vec4(in_position, 1.0);
    gl_Position = u_mvp * vec4(in_position, 1.0);
}
"""
MAIN_FRAGMENT = """
#version 330 core
uniform vec3 u_eye;
uniform vec3 u_light_dir;
uniform vec3 u_base_color;
uniform float u_ambient;
uniform float u_diffuse;
uniform float u_specular;
uniform float u_shininess;
uniform int u_shadows;
uniform sampler2DShadow u_shadow_map;
in vec3 v_world;
in vec3 v_normal;
in vec4 v_light;
out vec4 f_color;
void main() {
    vec3 N = normalize(v_normal);
    vec3 L = u_light_dir;
    vec3 V = normalize(u_eye - v_world);
    float ndl = max(dot(N, L), 0.0);
    vec3 H = normalize(L + V);
    float spec = ndl > 0.0 ? pow(max(dot(N, H), 0.0), u_shininess) : 0.0;
    float lit = 1.0;
    if (u_shadows != 0) {
        vec3 p = v_light.xyz / v_light.w * 0.5 + 0.5;
        lit = 0.25 * (textureOffset(u_shadow_map, p, ivec2(0, 0)) + textureOffset(u_shadow_map, p, ivec2(1, 0))
                      + textureOffset(u_shadow_map, p, ivec2(0, 1)) + textureOffset(u_shadow_map, p, ivec2(1, 1)));
    }
    vec3 c = u_base_color * (u_ambient + lit * u_diffuse * ndl) + vec3(lit * u_specular * spec);
    f_color = vec4(clamp(c, 0.0, 1.0), 1.0);
}
"""


def _ortho(half: float, near: float, far: float) -> np.ndarray:
    m = np.eye(4)
    m[0, 0] = m[1, 1] = 1.0 / half
    m[2, 2] = -2.0 / (far - near)
    m[2, 3] = -(far + near) / (far - near)
    return m


def light_matrix(vertices: np.ndarray, light_dir: np.ndarray) -> np.ndarray:
    """clip_from_world of an orthographic light camera holding the mesh's bounding sphere."""
    centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    radius = float(np.linalg.norm(vertices - centre, axis=1).max())
    eye = centre + light_dir * 2.0 * radius
    up = np.array([0.0, 1.0, 0.0]) if abs(light_dir[1]) < 0.9 else np.array([0.0, 0.0, 1.0])
    return _ortho(radius * 1.01, radius, 3.0 * radius) @ look_at(eye, centre, up)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scene", required=True)
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--warmup", type=int, default=2)
    parser.add_argument("--map-size", type=int, default=2048)
    args = parser.parse_args(argv)

    import moderngl

    sc, w, h, mvp = scene_camera(args.scene)
    light_dir = np.asarray(sc["light_dir"], dtype=np.float64)
    light_mvp = light_matrix(sc["vertices"].astype(np.float64), light_dir).astype(np.float32)

    ctx = moderngl.create_standalone_context(require=330, backend="egl")
    depth_prog = ctx.program(vertex_shader=DEPTH_VERTEX, fragment_shader=DEPTH_FRAGMENT)
    depth_prog["u_light_mvp"].write(light_mvp.T.copy().tobytes())
    prog = ctx.program(vertex_shader=MAIN_VERTEX, fragment_shader=MAIN_FRAGMENT)
    prog["u_mvp"].write(mvp.T.copy().tobytes())
    prog["u_light_mvp"].write(light_mvp.T.copy().tobytes())
    prog["u_eye"].value = tuple(float(x) for x in sc["eye"])
    prog["u_light_dir"].value = tuple(float(x) for x in light_dir)
    prog["u_base_color"].value = tuple(float(x) for x in sc["base_color"])
    for key in ("ambient", "diffuse", "specular", "shininess"):
        prog["u_" + key].value = float(sc[key])
    vbo_p = ctx.buffer(sc["vertices"])
    vbo_n = ctx.buffer(sc["normals"])
    ibo = ctx.buffer(sc["faces"])
    vao = ctx.vertex_array(prog, [(vbo_p, "3f", "in_position"), (vbo_n, "3f", "in_normal")], index_buffer=ibo,
                           index_element_size=4)  # fmt: skip
    depth_vao = ctx.vertex_array(depth_prog, [(vbo_p, "3f", "in_position")], index_buffer=ibo, index_element_size=4)
    shadow_map = ctx.depth_texture((args.map_size, args.map_size))
    shadow_map.compare_func = "<="
    shadow_map.filter = (moderngl.NEAREST, moderngl.NEAREST)
    shadow_map.repeat_x = shadow_map.repeat_y = False
    shadow_fbo = ctx.framebuffer(depth_attachment=shadow_map)
    fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer((w, h), 4, dtype="f1")],
                          depth_attachment=ctx.depth_renderbuffer((w, h)))  # fmt: skip
    ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
    ctx.depth_func = "<"
    ctx.front_face = "ccw"
    background = tuple(float(x) for x in sc["background"])
    color = np.empty((h, w, 4), np.uint8)
    depth = np.empty((h, w), np.float32)

    # several items (a scene file with item_face_starts): one draw call per item, each with its own color
    starts = [int(x) for x in sc.get("item_face_starts", [0, sc["faces"].shape[0]])]
    colors = sc.get("item_colors", np.array([sc["base_color"]] * (len(starts) - 1)))
    ranges = [(3 * starts[k], 3 * (starts[k + 1] - starts[k])) for k in range(len(starts) - 1)]

    def depth_pass() -> None:
        shadow_fbo.use()
        shadow_fbo.clear(depth=1.0)
        ctx.cull_face = "front"  # the back sides go into the map: no acne on the lit sides
        ctx.polygon_offset = (1.1, 4.0)
        for first, count in ranges:
            depth_vao.render(moderngl.TRIANGLES, vertices=count, first=first)
        ctx.polygon_offset = (0.0, 0.0)
        ctx.cull_face = "back"

    def frame(shadows: bool) -> None:
        if shadows:
            depth_pass()
            shadow_map.use(location=0)
            prog["u_shadow_map"].value = 0
        prog["u_shadows"].value = int(shadows)
        fbo.use()
        fbo.clear(*background, depth=1.0)
        for (first, count), item_color in zip(ranges, colors, strict=True):
            prog["u_base_color"].value = tuple(float(x) for x in item_color)
            vao.render(moderngl.TRIANGLES, vertices=count, first=first)
        ctx.finish()
        fbo.read_into(color, components=4, dtype="f1")
        fbo.read_into(depth, attachment=-1, dtype="f4")

    def timed(work) -> list[float]:
        for _ in range(args.warmup):
            work()
        times = []
        for _ in range(args.frames):
            t0 = time.perf_counter()
            work()
            times.append((time.perf_counter() - t0) * 1e3)
        return times

    plain = timed(lambda: frame(False))
    plain_color = color.copy()
    shadowed = timed(lambda: frame(True))
    depth_only = timed(lambda: (depth_pass(), ctx.finish()))
    covered = np.flipud(depth) < 1.0
    darker = color[..., :3].astype(int).sum(axis=2) < plain_color[..., :3].astype(int).sum(axis=2)
    print(json.dumps({
        "renderer": ctx.info.get("GL_RENDERER"), "width": w, "height": h, "map_size": args.map_size,
        "frame_ms": statistics.median(plain), "frame_shadowed_ms": statistics.median(shadowed),
        "depth_pass_ms": statistics.median(depth_only),
        "shadowed_fraction": float(darker.sum() / max(1, covered.sum())),
    }))  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
