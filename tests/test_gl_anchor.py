"""Per-pixel Phong and Blinn-Phong with several colored lights against OpenGL (Mesa llvmpipe through moderngl).

The GLSL below is written from the textbook formula, independently of ``raster/shade.py``. It runs where
moderngl and an EGL driver are available and the test skips cleanly elsewhere (CI machines without Mesa).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from tests.reference_raster import placed

from frustum import Camera, Perspective
from frustum.geometry import Mesh
from frustum.render import render
from frustum.scene import Scene
from frustum.shading import AmbientLight, DirectionalLight, Material, PointLight, SpotLight
from gl_frames import draw_and_read, gl_context

moderngl = pytest.importorskip("moderngl")

VERTEX = """
#version 330 core
uniform mat4 u_clip_from_world;
in vec3 in_position;
in vec3 in_normal;
out vec3 v_world;
out vec3 v_normal;
void main() {
    v_world = in_position;
    v_normal = in_normal;
    gl_Position = u_clip_from_world * vec4(in_position, 1.0);
}
"""

FRAGMENT = """
#version 330 core
uniform vec3 u_eye;
uniform vec3 u_color;
uniform vec3 u_ambient_light;
uniform float u_ka, u_kd, u_ks, u_shininess;
uniform int u_phong;              // 1: (R.V)^n, 0: (N.H)^n
uniform int u_count;
uniform vec4 u_kind_color[4];     // kind (0 directional, 1 point, 2 spot), I_l
uniform vec3 u_position[4];
uniform vec3 u_direction[4];      // toward the light (directional) or the cone axis (spot)
uniform vec3 u_attenuation[4];
uniform vec2 u_cone[4];           // cos inner, cos outer
in vec3 v_world;
in vec3 v_normal;
out vec4 f_color;
void main() {
    vec3 N = normalize(v_normal);
    vec3 V = normalize(u_eye - v_world);
    vec3 D = u_ka * u_ambient_light;
    vec3 S = vec3(0.0);
    for (int k = 0; k < u_count; ++k) {
        float kind = u_kind_color[k].x;
        vec3 L;
        float f = 1.0;
        if (kind == 0.0) {
            L = u_direction[k];
        } else {
            vec3 offset = u_position[k] - v_world;
            float d = length(offset);
            L = offset / d;
            f = 1.0 / (u_attenuation[k].x + u_attenuation[k].y * d + u_attenuation[k].z * d * d);
            if (kind == 2.0) {
                float c = dot(-L, u_direction[k]);
                f *= clamp((c - u_cone[k].y) / (u_cone[k].x - u_cone[k].y), 0.0, 1.0);
            }
        }
        float ndl = dot(N, L);
        if (ndl <= 0.0) continue;
        float spec = u_phong == 1 ? pow(max(dot(2.0 * ndl * N - L, V), 0.0), u_shininess)
                                  : pow(max(dot(N, normalize(L + V)), 0.0), u_shininess);
        vec3 I = u_kind_color[k].yzw;
        D += u_kd * f * ndl * I;
        S += u_ks * f * spec * I;
    }
    f_color = vec4(clamp(u_color * D + S, 0.0, 1.0), 1.0);
}
"""

WIDTH, HEIGHT = 160, 120
LIGHTS = [
    AmbientLight(color=(0.3, 0.3, 0.5), intensity=0.6),
    DirectionalLight(direction=(-0.3, -0.6, -0.7), color=(1.0, 0.95, 0.8), intensity=0.7),
    PointLight(position=(1.5, 1.2, 1.5), color=(0.3, 0.6, 1.0), intensity=1.5, attenuation=(1.0, 0.1, 0.05)),
    SpotLight(
        position=(-1.5, 2.0, 1.0),
        direction=(0.5, -1.0, -0.3),
        color=(1.0, 0.3, 0.2),
        intensity=2.0,
        inner_angle=math.radians(15),
        outer_angle=math.radians(35),
    ),
]
MATERIAL = Material(color=(0.75, 0.6, 0.45), ambient=0.15, diffuse=0.8, specular=0.5, shininess=24)


def scene_and_camera():
    sphere = trimesh.creation.icosphere(subdivisions=4)
    mesh = Mesh(sphere.vertices, sphere.faces, vertex_normals=sphere.vertex_normals)
    camera = Camera.look_at((0.3, 0.8, 3.4), (0, 0, 0), (0, 1, 0), projection=Perspective(0.9, 0.5, 20.0),
                            width=WIDTH, height=HEIGHT)  # fmt: skip
    return placed(Scene(lights=LIGHTS), mesh, MATERIAL), mesh, camera


def gl_render(mesh: Mesh, camera: Camera, phong: bool) -> np.ndarray:
    ctx = gl_context()
    program = ctx.program(vertex_shader=VERTEX, fragment_shader=FRAGMENT)
    program["u_clip_from_world"].write(np.asarray(camera.clip_from_world, dtype="f4").T.tobytes())
    program["u_eye"].value = tuple(float(c) for c in camera.frame.eye)
    program["u_color"].value = tuple(float(c) for c in MATERIAL.color)
    program["u_ambient_light"].value = tuple(float(c) for c in LIGHTS[0].color * LIGHTS[0].intensity)
    for name, value in (("u_ka", MATERIAL.ambient), ("u_kd", MATERIAL.diffuse), ("u_ks", MATERIAL.specular),
                        ("u_shininess", MATERIAL.shininess)):  # fmt: skip
        program[name].value = float(value)
    program["u_phong"].value = int(phong)
    others = LIGHTS[1:]
    program["u_count"].value = len(others)
    kinds, positions, directions, attenuations, cones = [], [], [], [], []
    for light in others:
        intensity = tuple(float(c) for c in light.color * light.intensity)
        if isinstance(light, DirectionalLight):
            kinds.append((0.0, *intensity))
            positions.append((0.0, 0.0, 0.0))
            directions.append(tuple(float(c) for c in light.to_light))
            attenuations.append((1.0, 0.0, 0.0))
            cones.append((1.0, 0.0))
        else:
            kinds.append((1.0 if isinstance(light, PointLight) else 2.0, *intensity))
            positions.append(tuple(float(c) for c in light.position))
            attenuations.append(tuple(float(c) for c in light.attenuation))
            if isinstance(light, SpotLight):
                directions.append(tuple(float(c) for c in light.direction))
                cones.append((math.cos(light.inner_angle), math.cos(light.outer_angle)))
            else:
                directions.append((0.0, 0.0, 0.0))
                cones.append((1.0, 0.0))
    for name, rows, width in (("u_kind_color", kinds, 4), ("u_position", positions, 3), ("u_direction", directions, 3),
                              ("u_attenuation", attenuations, 3), ("u_cone", cones, 2)):  # fmt: skip
        padded = list(rows) + [(0.0,) * width] * (4 - len(rows))
        program[name].write(np.asarray(padded, dtype="f4").tobytes())
    vao = ctx.vertex_array(
        program,
        [(ctx.buffer(mesh.vertices.astype("f4")), "3f", "in_position"),
         (ctx.buffer(mesh.vertex_normals.astype("f4")), "3f", "in_normal")],
        index_buffer=ctx.buffer(mesh.faces.astype("i4")), index_element_size=4,
    )  # fmt: skip
    return draw_and_read(ctx, vao, moderngl.TRIANGLES, moderngl.DEPTH_TEST | moderngl.CULL_FACE, WIDTH, HEIGHT)


@pytest.mark.parametrize("specular", ["blinn-phong", "phong"])
def test_phong_shading_with_several_lights_matches_opengl(specular):
    scene, mesh, camera = scene_and_camera()
    expected = gl_render(mesh, camera, phong=specular == "phong")
    frame = render(scene, camera, specular=specular, background=(0, 0, 0, 1))
    ours, theirs = frame.depth < 1.0, (expected[..., :3] != 0).any(axis=2)
    assert (ours == theirs).mean() >= 0.999
    both = ours & theirs
    difference = np.abs(frame.color[..., :3].astype(int) - expected[..., :3].astype(int)).max(axis=2)
    assert (difference[both] <= 1).mean() >= 0.995
