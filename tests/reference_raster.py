"""A slow, obvious reference rasterizer (pure NumPy and Python loops) for the renderer's byte-exact tests.

It follows the same written rules as ``frustum.render`` (``raster/triangles.py`` docstring) but shares no
rasterizer code with it: every triangle is tested against **every** pixel centre of the image (no bounding
box, no tiles, no incremental edge stepping), the depth test runs triangle after triangle in drawing order,
and shading is a Python loop over pixels. Clipping uses the public textbook function
``frustum.clip_triangles`` (tested on its own in ``test_clipping.py``).

Rules, written out once more (the arithmetic order matters for byte equality):
- clip = M·[x, y, z, 1] row by row as ((m0·x + m1·y) + m2·z) + m3; world likewise; normals by the inverse
  transpose, ((a0·x + a1·y) + a2·z), then divided by their length sqrt((x² + y²) + z²); when the modeling
  transform's 3x3 block is the identity, the Mesh's (unit) normals as stored.
- window x = (x_c / w)·(W/2) + W/2 (y alike), snapped X = floor(x·256 + 0.5); z_w = (z_c / w)·0.5 + 0.5.
- twice the area (X1 − X0)(Y2 − Y0) − (X2 − X0)(Y1 − Y0) in integers; 0: dropped; < 0: culled, or drawn
  with corners 1 and 2 swapped and the back flag set.
- pixel centre (256i + 128, 256j + 128); E_ab = (Xb − Xa)(Yp − Ya) − (Yb − Ya)(Xp − Xa); inside when E >= 0 on
  top/left edges (dy < 0, or dy = 0 and dx < 0) and E > 0 on the others.
- depth on the plane through the drawn corners before the snap, (X_k + r_k, Y_k + s_k, z_k) with the residuals
  r = x·256 − X, s = y·256 − Y, written from the snapped corner 0: float32((z0' + β·(Yp − Y0)) + α·(Xp − X0)) with
  α = −((dy12·z0 + dy20·z1) + dy01·z2)·r and β = ((dx12·z0 + dx20·z1) + dx01·z2)·r, r = 1 / area2,
  z0' = (z0 − α·r0) − β·s0, where d_ab = float(B − A) + (residual_b − residual_a) and area2 = dx01·(float(Y2 − Y0) +
  (s2 − s0)) − dy01·(float(X2 − X0) + (r2 − r0)); a sliver (area2·A < A²/2, A the snapped corners' integer area2)
  takes the snapped corners (residuals 0) instead; test "less"; weights g_k = E_k / w_k, r = 1 / Σ g_k,
  b_k = g_k·r, mapped onto the source face through the clip weights, stored as float32.
"""

from __future__ import annotations

import math

import numpy as np

from frustum import clip_triangles


def placed(scene, mesh, material=None, transform=None):
    """``scene.add(mesh, material, transform)`` and return the scene (``Scene.add`` returns the new node)."""
    scene.add(mesh, material=material, transform=transform)
    return scene


def _rows(matrix: np.ndarray, points: np.ndarray, count: int, affine: bool) -> np.ndarray:
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    out = np.empty((points.shape[0], count))
    for k in range(count):
        value = (matrix[k, 0] * x + matrix[k, 1] * y) + matrix[k, 2] * z
        out[:, k] = value + matrix[k, 3] if affine else value
    return out


def _snap(value: float) -> int:
    return math.floor(value * 256.0 + 0.5)


def _top_left(dx: int, dy: int) -> bool:
    return dy < 0 or (dy == 0 and dx < 0)


def reference_render(scene, camera, shading="phong", background=(0, 0, 0, 1), cull_back_faces=True):
    """(color (H, W, 4) uint8, depth (H, W) float32), top row first, by the rules of the module docstring."""
    width, height = camera.width, camera.height
    depth = np.ones((height, width), dtype=np.float32)
    owner = np.full((height, width), -1, dtype=np.int64)  # index into `drawn` of the visible surface
    bary = np.zeros((height, width, 2), dtype=np.float32)
    drawn = []  # (item, face, back) per rasterized triangle
    # pixel centres in fixed point, window rows bottom-up, then flipped to top row first at the end
    px = (256 * np.arange(width, dtype=np.int64) + 128)[None, :]
    py = (256 * np.arange(height, dtype=np.int64) + 128)[:, None]
    per_item = []
    for item_index, item in enumerate(scene.items):
        mesh = item.mesh
        model = np.asarray(item.world_from_model)
        clip = _rows(camera.clip_from_world @ model, mesh.vertices, 4, True)
        world = _rows(model, mesh.vertices, 3, True)
        normals = _rows(np.linalg.inv(model[:3, :3]).T, mesh.vertex_normals, 3, False)
        lengths = np.sqrt(
            (normals[:, 0] * normals[:, 0] + normals[:, 1] * normals[:, 1]) + normals[:, 2] * normals[:, 2]
        )
        normals = normals / lengths[:, None]
        if np.array_equal(model[:3, :3], np.eye(3)):  # the Mesh's normals are unit already: used as stored
            normals = mesh.vertex_normals
        per_item.append((world, normals))
        if mesh.face_count == 0:
            continue
        clipped = clip_triangles(clip, mesh.faces)
        n_input = mesh.vertex_count
        for t in range(clipped.faces.shape[0]):
            source = int(clipped.face_sources[t])
            corners = []
            for index in clipped.faces[t]:
                position = clipped.vertices[index]
                if index < n_input:  # a surviving corner of the source face: one-hot weights
                    weight = (mesh.faces[source] == index).astype(np.float64)
                else:
                    weight = clipped.new_vertex_weights[index - n_input]
                w = position[3]
                x_w = (position[0] / w) * (width / 2.0) + width / 2.0
                y_w = (position[1] / w) * (height / 2.0) + height / 2.0
                x, y = _snap(x_w), _snap(y_w)
                corners.append((x, y, (position[2] / w) * 0.5 + 0.5, 1.0 / w, weight, x_w * 256.0 - x, y_w * 256.0 - y))
            (x0, y0, *_), (x1, y1, *_), (x2, y2, *_) = corners
            area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
            if area == 0:
                continue
            back = area < 0
            if back:
                if cull_back_faces:
                    continue
                corners = [corners[0], corners[2], corners[1]]
                area = -area
            drawn.append((item_index, source, back))
            _fill(corners, area, len(drawn) - 1, px, py, depth, owner, bary)
    color = np.empty((height, width, 4), dtype=np.uint8)
    color[:, :] = [math.floor(v * 255.0 + 0.5) for v in background]
    for j in range(height):
        for i in range(width):
            if owner[j, i] >= 0:
                item_index, face, back = drawn[owner[j, i]]
                item = scene.items[item_index]
                world, normals = per_item[item_index]
                color[j, i] = _shade(item, scene, camera, shading, face, back, bary[j, i], world, normals)
    return color[::-1].copy(), depth[::-1].copy()


def _fill(corners, area, index, px, py, depth, owner, bary):
    (x0, y0, z0, q0, w0, r0, s0), (x1, y1, z1, q1, w1, r1, s1), (x2, y2, z2, q2, w2, r2, s2) = corners
    e = []
    inside = np.ones(depth.shape, dtype=bool)
    for (ax, ay), (bx, by) in (((x1, y1), (x2, y2)), ((x2, y2), (x0, y0)), ((x0, y0), (x1, y1))):
        dx, dy = bx - ax, by - ay
        edge = dx * (py - ay) - dy * (px - ax)  # (H, W) int64, exact
        inside &= edge >= 0 if _top_left(dx, dy) else edge > 0
        e.append(edge.astype(np.float64))
    dx = (float(x2 - x1) + (r2 - r1), float(x0 - x2) + (r0 - r2), float(x1 - x0) + (r1 - r0))
    dy = (float(y2 - y1) + (s2 - s1), float(y0 - y2) + (s0 - s2), float(y1 - y0) + (s1 - s0))
    unsnapped = dx[2] * (float(y2 - y0) + (s2 - s0)) - dy[2] * (float(x2 - x0) + (r2 - r0))
    if unsnapped * area < 0.5 * float(area) * float(area):  # a sliver: the snapped corners' plane
        dx = (float(x2 - x1), float(x0 - x2), float(x1 - x0))
        dy = (float(y2 - y1), float(y0 - y2), float(y1 - y0))
        unsnapped, r0, s0 = float(area), 0.0, 0.0
    reciprocal = 1.0 / unsnapped
    alpha = -((dy[0] * z0 + dy[1] * z1) + dy[2] * z2) * reciprocal
    beta = ((dx[0] * z0 + dx[1] * z1) + dx[2] * z2) * reciprocal
    z0 = (z0 - alpha * r0) - beta * s0
    z = ((z0 + beta * (py - y0).astype(np.float64)) + alpha * (px - x0).astype(np.float64)).astype(np.float32)
    visible = inside & (z < depth)
    g0, g1, g2 = e[0] * q0, e[1] * q1, e[2] * q2
    with np.errstate(invalid="ignore", divide="ignore"):  # pixels outside have no meaningful weights
        reciprocal = 1.0 / ((g0 + g1) + g2)
        b0, b1, b2 = g0 * reciprocal, g1 * reciprocal, g2 * reciprocal
    depth[visible] = z[visible]
    owner[visible] = index
    for k in range(2):
        value = ((b0 * w0[1 + k] + b1 * w1[1 + k]) + b2 * w2[1 + k]).astype(np.float32)
        bary[..., k][visible] = value[visible]


def _byte(value: float) -> int:
    return math.floor(min(max(value, 0.0), 1.0) * 255.0 + 0.5)


def _power(x, n):
    """x**n as the renderer takes it: integral n in [0, 1024] by repeated squaring (lowest bit first)."""
    # kept twice on purpose: the same loop as src/frustum/raster/power.py:textbook_power (this reference shares no
    # code with the renderer)
    if n != math.floor(n) or not 0 <= n <= 1024:
        return x**n
    e, r = int(n), 1.0
    while e > 0:
        if e & 1:
            r *= x
        x *= x
        e >>= 1
    return r


def _shade(item, scene, camera, shading, face, back, weights, world, normals):
    material = item.material
    if shading in (None, "none"):
        return [*(_byte(float(c)) for c in material.color), 255]
    a, b, c = item.mesh.faces[face]
    u1, u2 = float(weights[0]), float(weights[1])
    u0 = (1.0 - u1) - u2
    p = [(u0 * world[a, k] + u1 * world[b, k]) + u2 * world[c, k] for k in range(3)]
    n = [(u0 * normals[a, k] + u1 * normals[b, k]) + u2 * normals[c, k] for k in range(3)]
    length = math.sqrt((n[0] * n[0] + n[1] * n[1]) + n[2] * n[2])
    sign = -1.0 if back else 1.0
    n = [sign * v / length for v in n]
    light = [-float(v) for v in scene.lights[0].direction]
    eye = [float(v) for v in camera.frame.eye]
    v = [eye[k] - p[k] for k in range(3)]
    length = math.sqrt((v[0] * v[0] + v[1] * v[1]) + v[2] * v[2])
    v = [x / length for x in v]
    h = [light[k] + v[k] for k in range(3)]
    length = math.sqrt((h[0] * h[0] + h[1] * h[1]) + h[2] * h[2])
    h = [x / length for x in h]
    ndl = max((n[0] * light[0] + n[1] * light[1]) + n[2] * light[2], 0.0)
    spec = _power(max((n[0] * h[0] + n[1] * h[1]) + n[2] * h[2], 0.0), material.shininess) if ndl > 0.0 else 0.0
    rgb = [
        float(material.color[k]) * (material.ambient + material.diffuse * ndl) + material.specular * spec
        for k in range(3)
    ]
    return [*(_byte(x) for x in rgb), 255]
