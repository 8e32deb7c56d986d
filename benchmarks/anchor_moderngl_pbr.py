"""OpenGL glTF metallic–roughness anchor: a bench scene shaded by a standard glTF PBR fragment shader (the BRDF of
glTF 2.0 Appendix B: GGX, height-correlated Smith visibility, Schlick Fresnel, the metallic mix), one directional
light and image-based light (nine SH irradiance coefficients, a prefiltered cube map per roughness level, the
split-sum BRDF table as a 2-D texture), in Mesa llvmpipe through moderngl (the pattern of
``../shared/bench/anchor_moderngl.py``).

    python benchmarks/anchor_moderngl_pbr.py --scene PATH.npz [--frames 10] [--warmup 2]

The environment (``bench_environment``), the material (``PBR_MATERIAL``) and the light (the scene's ``light_dir``,
``LIGHT_LUX``) are the ones ``bench_render.py --pbr`` gives frustum; the maps and the table are frustum's
``shading.ibl`` precomputation (input data, as a viewer loads them), the cube faces sampled from its
latitude–longitude maps. Per frame: clear, draw, glFinish, readback of color (RGBA8) and depth (float32). Prints
one JSON object with the median ``frame_ms`` and the GL renderer.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time

import numpy as np
from _anchor_camera import scene_camera

PBR_MATERIAL = {"metallic": 0.6, "roughness": 0.45}
LIGHT_LUX = 3.0
CUBE_SIZE = 64

VERTEX = """
#version 330 core
uniform mat4 u_mvp;
in vec3 in_position;
in vec3 in_normal;
out vec3 v_world;
out vec3 v_normal;
void main() {
    v_world = in_position;
    v_normal = in_normal;
    gl_Position = u_mvp * vec4(in_position, 1.0);
}
"""
FRAGMENT = """
#version 330 core
const float PI = 3.14159265358979;
uniform vec3 u_eye;
uniform vec3 u_light_dir;
uniform float u_lux;
uniform vec3 u_base_color;
uniform float u_metallic;
uniform float u_roughness;
uniform vec3 u_sh[9];
uniform samplerCube u_env_low;
uniform samplerCube u_env_high;
uniform float u_level_t;
uniform sampler2D u_table;
in vec3 v_world;
in vec3 v_normal;
out vec4 f_color;
float D_GGX(float nh, float a) { float a2 = a * a; float d = nh * nh * (a2 - 1.0) + 1.0; return a2 / (PI * d * d); }
float V_GGX(float nl, float nv, float a) {
    float a2 = a * a;
    float t = nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2);
    return t > 0.0 ? 0.5 / t : 0.0;
}
vec3 irradiance(vec3 n) {
    return u_sh[0] * 0.282095 + 0.488603 * (u_sh[1] * n.y + u_sh[2] * n.z + u_sh[3] * n.x)
         + 1.092548 * (u_sh[4] * n.x * n.y + u_sh[5] * n.y * n.z + u_sh[7] * n.x * n.z)
         + u_sh[6] * 0.315392 * (3.0 * n.z * n.z - 1.0) + u_sh[8] * 0.546274 * (n.x * n.x - n.y * n.y);
}
void main() {
    vec3 n = normalize(v_normal);
    vec3 v = normalize(u_eye - v_world);
    vec3 l = u_light_dir;
    vec3 h = normalize(l + v);
    float nl = dot(n, l), nv = dot(n, v), nh = dot(n, h), vh = dot(v, h);
    float a = u_roughness * u_roughness;
    vec3 base = u_base_color;
    vec3 color = vec3(0.0);
    if (nl > 0.0) {
        float w = pow(1.0 - abs(vh), 5.0);
        float spec = V_GGX(nl, nv, a) * D_GGX(max(nh, 0.0), a);
        float fd = 0.04 + 0.96 * w;
        vec3 dielectric = (1.0 - fd) * base / PI + fd * spec;
        vec3 metal = spec * (base + (1.0 - base) * w);
        color += mix(dielectric, metal, u_metallic) * u_lux * nl;
    }
    vec2 ab = texture(u_table, vec2(clamp(u_roughness, 0.0, 1.0), clamp(nv, 0.0, 1.0))).rg;
    vec3 f0 = mix(vec3(0.04), base, u_metallic);
    float s = 1.0 - a;
    vec3 r = reflect(-v, n);
    vec3 rd = mix(n, r, s * (sqrt(s) + a));
    vec3 prefiltered = mix(texture(u_env_low, rd).rgb, texture(u_env_high, rd).rgb, u_level_t);
    color += (f0 * ab.x + ab.y) * prefiltered
           + (1.0 - u_metallic) * (1.0 - (0.04 * ab.x + ab.y)) * base * max(irradiance(n), vec3(0.0));
    f_color = vec4(clamp(color, 0.0, 1.0), 1.0);
}
"""


def bench_environment():
    """The benchmark's surroundings: a sky (bluish, brighter up) with a warm lobe, 64 × 128 texels (equirect)."""
    import frustum

    theta = (np.arange(64) + 0.5) / 64 * math.pi
    phi = ((np.arange(128) + 0.5) / 128 - 0.5) * 2 * math.pi
    t, p = np.meshgrid(theta, phi, indexing="ij")
    sky = np.stack([0.3 + 0.5 * np.cos(t) ** 2, 0.4 + 0.4 * np.cos(t), 0.8 + 0.2 * np.cos(t)], axis=-1)
    sun = np.exp(-((t - 0.9) ** 2 + (p - 0.6) ** 2) / 0.15)[..., None] * np.array([3.0, 2.2, 1.2])
    return frustum.EnvironmentMap((np.maximum(sky, 0.05) + sun).astype(np.float32))


def _cube_faces(equirect: np.ndarray, size: int) -> list[np.ndarray]:
    """The six OpenGL cube faces (+x, −x, +y, −y, +z, −z) of a latitude–longitude map, bilinear samples."""
    import frustum

    environment = frustum.EnvironmentMap(equirect)
    s = (np.arange(size) + 0.5) / size * 2 - 1
    sc, tc = np.meshgrid(s, s)  # rows: t down
    faces = []
    for axis in ((1, -tc, -sc), (-1, -tc, sc), (sc, 1, tc), (sc, -1, -tc), (sc, -tc, 1), (-sc, -tc, -1)):
        d = np.stack([np.broadcast_to(np.asarray(c, dtype=float), sc.shape) for c in axis], axis=-1)
        faces.append(environment.lookup(d.reshape(-1, 3)).reshape(size, size, 3).astype(np.float32))
    return faces


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scene", required=True)
    parser.add_argument("--frames", type=int, default=10)
    parser.add_argument("--warmup", type=int, default=2)
    args = parser.parse_args(argv)

    import moderngl

    from frustum.shading.ibl import ROUGHNESS_LEVELS, image_lighting

    sc, w, h, mvp = scene_camera(args.scene)
    eye = sc["eye"].astype(float)

    lighting = image_lighting(bench_environment())
    level = PBR_MATERIAL["roughness"] * (len(ROUGHNESS_LEVELS) - 1)
    low = min(int(level), len(ROUGHNESS_LEVELS) - 2)

    ctx = moderngl.create_standalone_context(require=330, backend="egl")
    prog = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
    prog["u_mvp"].write(mvp.T.copy().tobytes())
    prog["u_eye"].value = tuple(float(x) for x in eye)
    prog["u_light_dir"].value = tuple(float(x) for x in sc["light_dir"])
    prog["u_lux"].value = LIGHT_LUX
    prog["u_base_color"].value = tuple(float(x) for x in sc["base_color"])
    prog["u_metallic"].value = PBR_MATERIAL["metallic"]
    prog["u_roughness"].value = PBR_MATERIAL["roughness"]
    prog["u_sh"].write(lighting.sh.astype(np.float32).tobytes())
    prog["u_level_t"].value = level - low
    cubes = []
    for k, location in ((low, 0), (low + 1, 1)):
        cube = ctx.texture_cube((CUBE_SIZE, CUBE_SIZE), 3, dtype="f4")
        for face, image in enumerate(_cube_faces(lighting.prefiltered[k], CUBE_SIZE)):
            cube.write(face, image.tobytes())
        cube.filter = (moderngl.LINEAR, moderngl.LINEAR)
        cube.use(location=location)
        cubes.append(cube)
    prog["u_env_low"].value, prog["u_env_high"].value = 0, 1
    table = np.ascontiguousarray(lighting.table, dtype=np.float32)  # rows n·v, columns roughness
    lut = ctx.texture((table.shape[1], table.shape[0]), 2, table.tobytes(), dtype="f4")
    lut.filter = (moderngl.LINEAR, moderngl.LINEAR)
    lut.repeat_x = lut.repeat_y = False
    lut.use(location=2)
    prog["u_table"].value = 2
    vbo_p = ctx.buffer(sc["vertices"])
    vbo_n = ctx.buffer(sc["normals"])
    ibo = ctx.buffer(sc["faces"])
    vao = ctx.vertex_array(prog, [(vbo_p, "3f", "in_position"), (vbo_n, "3f", "in_normal")], index_buffer=ibo,
                           index_element_size=4)  # fmt: skip
    fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer((w, h), 4, dtype="f1")],
                          depth_attachment=ctx.depth_renderbuffer((w, h)))  # fmt: skip
    ctx.enable(moderngl.DEPTH_TEST | moderngl.CULL_FACE)
    ctx.depth_func = "<"
    ctx.front_face = "ccw"
    background = tuple(float(x) for x in sc["background"])
    color = np.empty((h, w, 4), np.uint8)
    depth = np.empty((h, w), np.float32)

    def frame() -> None:
        fbo.use()
        fbo.clear(*background, depth=1.0)
        vao.render(moderngl.TRIANGLES)
        ctx.finish()
        fbo.read_into(color, components=4, dtype="f1")
        fbo.read_into(depth, attachment=-1, dtype="f4")

    for _ in range(args.warmup):
        frame()
    times = []
    for _ in range(args.frames):
        t0 = time.perf_counter()
        frame()
        times.append((time.perf_counter() - t0) * 1e3)
    print(json.dumps({"renderer": ctx.info.get("GL_RENDERER"), "width": w, "height": h,
                      "frame_ms": statistics.median(times), "covered": int((depth < 1.0).sum())}))  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
