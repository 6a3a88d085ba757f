"""An image-based world: an equirectangular environment map seen by escaped rays and
importance-sampled as a light, as Cycles renders an Environment Texture behind a
Background shader.

Direction -> image coordinates (Cycles' direction_to_equirectangular, checked against
Cycles 5.0 renders of a texel-coded image): for a unit vector (x, y, z) in the map's
frame,
    u = 0.5 - atan2(y, x) / (2 pi),     v = 1 - theta / pi,   theta = angle from +Z,
so -X is the image's left and right edge, +X its centre, +Y a quarter from the left,
+Z (up) its top row (v = 1) and -Z its bottom row; the inverse is
phi = pi - 2 pi u, theta = pi (1 - v). The image is read by `engine.textures.Texture`
(Linear or Closest, 8-bit sRGB decoded after interpolation) with REPEAT extension in
both axes, as Cycles' Environment Texture node does (EXTENSION_REPEAT).

Mapping: a 3x3 matrix M (Blender's Mapping node without translation: rotation x scale)
takes a world direction d to the vector M d that the Environment Texture normalises and
looks up. The radiance is strength x image(uv(M d / |M d|)).

Importance sampling: a `PiecewiseConstant2D` over the image's texel grid (cell = texel)
with f = luminance x the row's share of the sphere, cos(pi r / H) - cos(pi (r + 1) / H)
(the integral of sin(theta) over the row). The luminance is that of |texel| x |strength|,
and with Linear interpolation the texels' luminance is first filtered by [1/8, 3/4, 1/8]
in u and in v (wrapping): that is the exact average of the bilinear reconstruction over
the cell, so no cell where the looked-up radiance is non-zero gets pdf 0. A sampled
(u, v) becomes a direction d' in the map's frame with solid-angle pdf
    pdf(d') = pdf_uv(u, v) / (2 pi^2 sin(theta)),
and the world direction is d = M^-1 d' / |M^-1 d'|, whose pdf carries the Jacobian of
d -> M d / |M d|:  d(omega') / d(omega) = |det M| / |M d|^3.

The radiance, the sampling and the pdf are computed by
`engine.kernels.lights.environment_map` (from the arrays pack.py puts in the light set).
"""
from __future__ import annotations

import numpy as np

from .piecewise_2d import PiecewiseConstant2D
from .textures import LUMINANCE, Texture, srgb_to_linear

# |det M| below this (relative to the largest entry cubed) is taken as singular
SINGULAR = 1e-12


def direction_to_uv(d):
    """Equirectangular (u, v) (n, 2) of directions d (n, 3) (any length > 0)."""
    d = np.asarray(d, dtype=np.float64)
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    theta = np.arctan2(np.hypot(x, y), z)
    return np.stack([0.5 - np.arctan2(y, x) / (2.0 * np.pi), 1.0 - theta / np.pi], axis=1)


def uv_to_direction(uv):
    """Unit directions (n, 3) of equirectangular coordinates uv (n, 2), and sin(theta)."""
    uv = np.asarray(uv, dtype=np.float64)
    phi = np.pi - 2.0 * np.pi * uv[:, 0]
    theta = np.pi * (1.0 - uv[:, 1])
    s = np.sin(theta)
    return np.stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)], axis=1), s


def _filter_121(g, axis):
    """[1/8, 3/4, 1/8] along `axis`, wrapping (the bilinear reconstruction's cell mean)."""
    return 0.75 * g + 0.125 * (np.roll(g, 1, axis=axis) + np.roll(g, -1, axis=axis))


def importance(texture: Texture, strength) -> np.ndarray:
    """The function f (H, W) the map's directions are sampled by (see the module doc)."""
    rgb = np.abs(texture.pixels[:, :, :3].astype(np.float64))
    if texture.srgb:
        rgb = srgb_to_linear(rgb)
    g = (rgb * np.abs(np.asarray(strength, np.float64))) @ LUMINANCE
    if texture.interpolation == "Linear":
        g = _filter_121(_filter_121(g, 1), 0)
    h = g.shape[0]
    edges = np.cos(np.pi * np.arange(h + 1) / h)
    return g * (edges[:-1] - edges[1:])[:, None]


class EnvironmentMap:
    """The image-based world's parameters: its texture, strength and mapping, and the
    importance distribution the kernels sample directions from."""

    def __init__(self, texture: Texture, strength=(1.0, 1.0, 1.0), mapping=None):
        self.texture = texture
        self.strength = np.broadcast_to(np.asarray(strength, np.float64), (3,)).copy()
        m = np.eye(3) if mapping is None else np.asarray(mapping, np.float64).reshape(3, 3)
        scale = np.abs(m).max() if np.isfinite(m).all() else 0.0
        det = float(np.linalg.det(m)) if scale > 0 else 0.0
        if not (scale > 0 and abs(det) > SINGULAR * scale ** 3):
            raise ValueError(f"the environment mapping must be an invertible 3x3 matrix, "
                             f"got {m.tolist()}")
        self.matrix = m
        self.inverse = np.linalg.inv(m)
        self.abs_det = abs(det)
        self.identity = bool((m == np.eye(3)).all())
        f = importance(texture, self.strength)
        self.distribution = PiecewiseConstant2D(f)
        # mean luminance over the sphere: sum f x (2 pi / W) / (4 pi)
        self.mean_luminance = float(f.sum() / (2.0 * f.shape[1]))
