"""Surface detail beyond texture maps: Blinn's bump mapping and tangent-space normal maps.

Both change only the *shading* normal (the geometry stays flat), per pixel, from the mesh's texture coordinates
[HB "Adding Surface Detail": bump mapping, frame mapping]:

* **Bump map** (Blinn 1978): a height field B(u, v) (the image's gray value in [0, 1] times ``bump_scale``, in
  world units) displaces the surface along its normal, $P'(u, v) = P + B N/|N|$; to first order the displaced
  surface's normal is

    $$N' = N + (B_u (N × P_v) − B_v (N × P_u)) / |N|,   N = P_u × P_v$$

    with $P_u = ∂P/∂u$, $P_v = ∂P/∂v$ from the mesh's UVs (``tangent_frames``) and $B_u$, $B_v$ the height's
    gradient in texture space (central differences on the image, one-sided at its edges, scaled by its size and
    sampled bilinearly as textures are: ``height_gradient``). With a smooth-shaded mesh the interpolated unit
    normal n stands for $N/|N|$ and $|N| = |P_u × P_v|$.

* **Normal map**: each texel stores a unit normal in the surface's tangent frame, $n_t = (255·rgb − 128) / 127$
  clamped to [−1, 1] (8-bit values b as (b − 128)/127: 128 is exactly 0 and 255 is 1, so a "flat" map of
  (128, 128, 255) is exactly (0, 0, 1); glTF's $2·b/255 − 1$ differs by at most 0.008), in the
  OpenGL convention (+x along the tangent T = P_u, +y along the bitangent = P_v: "green up", as glTF's
  ``normalTexture``); $N' = normalize(T̂ n_t.x + B̂ n_t.y + n n_t.z)$ with T̂ made perpendicular to n
  (Gram–Schmidt) and $B̂ = ±(n × T̂)$, the sign that of the UV layout's handedness.

The renderer evaluates them per pixel in Phong shading only: flat shading lights each face once and Gouraud
shading each vertex once, so a per-pixel normal has nowhere to go there (documented as a no-op).

References
----------
[HB] "Adding Surface Detail" (bump mapping, frame mapping); Blinn, "Simulation of Wrinkled Surfaces", SIGGRAPH
1978; Lengyel, "Computing Tangent Space Basis Vectors for an Arbitrary Mesh" (2001); glTF 2.0 §3.9.3
(normalTexture, tangent space).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["bumped_normals", "height_gradient", "mapped_normals", "tangent_frames"]


def tangent_frames(
    vertices: ArrayLike, faces: ArrayLike, uvs: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(P_u, P_v) per vertex, (N, 3) float64 each: ∂P/∂u and ∂P/∂v of the faces around each vertex, averaged.

    Per face with edges $e1 = P1 − P0$, $e2 = P2 − P0$ and UV differences (Δu1, Δv1), (Δu2, Δv2):
    $P_u = (e1 Δv2 − e2 Δv1) / det$, $P_v = (e2 Δu1 − e1 Δu2) / det$, $det = Δu1 Δv2 − Δu2 Δv1$.
    Faces with a degenerate UV triangle (det = 0) add nothing; a vertex with no other face gets zeros.
    """
    p = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    t = np.asarray(uvs, dtype=np.float64)
    e1, e2 = p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]
    d1, d2 = t[f[:, 1]] - t[f[:, 0]], t[f[:, 2]] - t[f[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    ok = det != 0.0
    inverse = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)[:, None]
    p_u = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * inverse
    p_v = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * inverse
    sum_u = np.zeros_like(p)
    sum_v = np.zeros_like(p)
    count = np.zeros(p.shape[0])
    for k in range(3):
        np.add.at(sum_u, f[:, k], p_u)
        np.add.at(sum_v, f[:, k], p_v)
        np.add.at(count, f[:, k], ok.astype(np.float64))
    count = np.maximum(count, 1.0)[:, None]
    return sum_u / count, sum_v / count


def _gray(image: NDArray[np.float32]) -> NDArray[np.float64]:
    """A texture (H, W, 4) float32 as heights (H, W): the mean of its RGB."""
    return image[..., :3].astype(np.float64).mean(axis=-1)


def _bilinear_wrapped(values: NDArray[np.float64], u: NDArray, v: NDArray) -> NDArray[np.float64]:
    """Bilinear samples of an (H, W[, C]) image at texture coordinates (u, v), repeating, v = 0 the bottom row —
    the renderer's texture lookup (``raster.shade._sample``) in NumPy."""
    height, width = values.shape[:2]
    x = (u - np.floor(u)) * width - 0.5
    y = (1.0 - (v - np.floor(v))) * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = x - x0, y - y0
    i0, j0 = x0.astype(np.int64) % width, y0.astype(np.int64) % height
    i1, j1 = (i0 + 1) % width, (j0 + 1) % height
    if values.ndim == 3:
        fx, fy = fx[:, None], fy[:, None]
    top = values[j0, i0] * (1.0 - fx) + values[j0, i1] * fx
    bottom = values[j1, i0] * (1.0 - fx) + values[j1, i1] * fx
    return top * (1.0 - fy) + bottom * fy


def height_gradient(
    image: NDArray[np.float32], scale: float, u: ArrayLike, v: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(B_u, B_v) at texture coordinates (u, v): the gradient of $B = scale · gray(image)$ in texture space.

    Central differences on the image (one-sided at its borders, so a linear ramp has the same slope everywhere),
    $B_u = scale · W · ∂gray/∂column$, $B_v = −scale · H · ∂gray/∂row$ (rows run down, v up), sampled bilinearly.
    """
    gray = _gray(image)
    height, width = gray.shape
    d_row = np.gradient(gray, axis=0) if height > 1 else np.zeros_like(gray)
    d_col = np.gradient(gray, axis=1) if width > 1 else np.zeros_like(gray)
    both = np.stack([d_col * (scale * width), -d_row * (scale * height)], axis=-1)
    sampled = _bilinear_wrapped(both, np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
    return sampled[:, 0], sampled[:, 1]


def _unit(vectors: NDArray[np.float64]) -> NDArray[np.float64]:
    length = np.sqrt((vectors * vectors).sum(axis=-1, keepdims=True))
    return vectors / np.where(length > 0.0, length, 1.0)


def bumped_normals(
    normal: ArrayLike, p_u: ArrayLike, p_v: ArrayLike, b_u: ArrayLike, b_v: ArrayLike
) -> NDArray[np.float64]:
    """(N, 3) unit normals of the bumped surface: $N' = |N| n + B_u (n × P_v) − B_v (n × P_u)$, $|N| = |P_u × P_v|$
    (Blinn's formula with $n = N/|N|$ the unit shading normal)."""
    n = _unit(np.asarray(normal, dtype=np.float64))
    pu, pv = np.asarray(p_u, dtype=np.float64), np.asarray(p_v, dtype=np.float64)
    size = np.linalg.norm(np.cross(pu, pv), axis=-1, keepdims=True)
    bumped = size * n + np.asarray(b_u)[:, None] * np.cross(n, pv) - np.asarray(b_v)[:, None] * np.cross(n, pu)
    return _unit(np.where(size > 0.0, bumped, n))


def mapped_normals(normal: ArrayLike, p_u: ArrayLike, p_v: ArrayLike, texel: ArrayLike) -> NDArray[np.float64]:
    """(N, 3) unit normals from tangent-space normal-map texels (N, 3) in [0, 1] (OpenGL convention, +y = P_v)."""
    n = _unit(np.asarray(normal, dtype=np.float64))
    pu, pv = np.asarray(p_u, dtype=np.float64), np.asarray(p_v, dtype=np.float64)
    tangent = _unit(pu - n * (n * pu).sum(axis=-1, keepdims=True))
    side = np.cross(n, tangent)
    handed = np.where((side * pv).sum(axis=-1, keepdims=True) < 0.0, -1.0, 1.0)
    bitangent = side * handed
    t = np.clip((255.0 * np.asarray(texel, dtype=np.float64) - 128.0) / 127.0, -1.0, 1.0)
    mapped = tangent * t[:, 0:1] + bitangent * t[:, 1:2] + n * t[:, 2:3]
    no_frame = (np.linalg.norm(pu, axis=-1) == 0.0)[:, None]
    return _unit(np.where(no_frame, n, mapped))
