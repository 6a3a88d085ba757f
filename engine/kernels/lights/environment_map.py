"""The world's environment map as compiled scalar kernels: its lookup, direction sampling
and pdf (the model and the formulas: `engine.environment_map`'s module docstring; the
2D distribution: `engine.piecewise_2d`'s), on the L[ENV_MAP:] fields of the packed light
set (`pack.py`)."""
from __future__ import annotations

import math

from ..cdf_search import last_at_most
from ..jit import kernel
from ..textures import texture_rgba
from .pack import (ENV_CONDITIONAL, ENV_CONDITIONAL_GUIDE, ENV_MAP, ENV_MARGINAL,
                   ENV_MARGINAL_GUIDE, ENV_PIXELS, ENV_TEXTURE, M_ABS_DET, M_HAS, M_IDENTITY,
                   M_CAMERA, M_INVERSE, M_MATRIX, M_STRENGTH)

PI = math.pi
TWO_PI = 2.0 * math.pi
TWO_PI_SQUARED = 2.0 * math.pi * math.pi
INF = math.inf


@kernel(allocates=False)
def has_map(L):
    return L[ENV_MAP][M_HAS] != 0.0


@kernel(allocates=False)
def direction_to_uv(x, y, z):
    """engine.environment_map.direction_to_uv for one direction (any length > 0)."""
    theta = math.atan2(math.hypot(x, y), z)
    return 0.5 - math.atan2(y, x) / TWO_PI, 1.0 - theta / PI


@kernel(allocates=False)
def uv_to_direction(u, v):
    """engine.environment_map.uv_to_direction: (x, y, z, sin theta)."""
    phi = PI - TWO_PI * u
    theta = PI * (1.0 - v)
    s = math.sin(theta)
    return s * math.cos(phi), s * math.sin(phi), math.cos(theta), s


@kernel(allocates=False)
def _apply(m, base, x, y, z):
    """The 3x3 row-major matrix m[base:base + 9] times (x, y, z)."""
    return (m[base] * x + m[base + 1] * y + m[base + 2] * z,
            m[base + 3] * x + m[base + 4] * y + m[base + 5] * z,
            m[base + 6] * x + m[base + 7] * y + m[base + 8] * z)


@kernel(allocates=False)
def _to_map(L, x, y, z):
    params = L[ENV_MAP]
    if params[M_IDENTITY] != 0.0:
        return x, y, z
    return _apply(params, M_MATRIX, x, y, z)


@kernel(allocates=False)
def map_radiance(L, dx, dy, dz):
    """The map's radiance along one direction: (r, g, b)."""
    return texture_radiance(L, 0, dx, dy, dz)


@kernel(allocates=False)
def seen_by_camera(L, dx, dy, dz):
    """What a camera ray sees of the map along one direction: the camera's own image
    where the world shows the camera another background (M_CAMERA), else the map's."""
    return texture_radiance(L, 1 if L[ENV_MAP][M_CAMERA] != 0.0 else 0, dx, dy, dz)


@kernel(allocates=False)
def texture_radiance(L, index, dx, dy, dz):
    """Image `index` of L[ENV_TEXTURE] along one direction, times the map's strength."""
    params = L[ENV_MAP]
    mx, my, mz = _to_map(L, dx, dy, dz)
    u, v = direction_to_uv(mx, my, mz)
    r, g, b, _ = texture_rgba((L[ENV_PIXELS], L[ENV_TEXTURE]), index, u, v)
    return (r * params[M_STRENGTH], g * params[M_STRENGTH + 1], b * params[M_STRENGTH + 2])


@kernel(allocates=False)
def invert_cdf(cdf, u, guide):
    """The inverse of one CDF row at u: (cell, offset in [0, 1]); the search
    starts from the row's guide (kernels.cdf_search), the same cell as a full search."""
    n = cdf.shape[0] - 1
    i = min(max(last_at_most(cdf, u, guide), 0), n - 1)
    lo = cdf[i]
    width = cdf[i + 1] - lo
    off = (u - lo) / width if width > 0.0 else 0.0
    return i, min(max(off, 0.0), 1.0)


@kernel(allocates=False)
def grid(L):
    """(H, W): the map's rows and columns, as its CDFs hold them."""
    return L[ENV_MARGINAL].shape[0] - 1, L[ENV_CONDITIONAL].shape[1] - 1


@kernel(allocates=False)
def cell_pdf(L, r, c):
    """The density in (u, v) of cell (r, c) (engine.piecewise_2d's module docstring)."""
    marginal = L[ENV_MARGINAL]
    cond = L[ENV_CONDITIONAL]
    h, w = grid(L)
    return (h * (marginal[r + 1] - marginal[r])) * (w * (cond[r, c + 1] - cond[r, c]))


@kernel(allocates=False)
def sample_map(L, u0, u1):
    """A direction sampled from the map: (wx, wy, wz, solid-angle pdf; 0 = none)."""
    h, w = grid(L)
    r, dv = invert_cdf(L[ENV_MARGINAL], u0, L[ENV_MARGINAL_GUIDE])
    c, du = invert_cdf(L[ENV_CONDITIONAL][r], u1, L[ENV_CONDITIONAL_GUIDE][r])
    mx, my, mz, sin_t = uv_to_direction((c + du) / w, (r + dv) / h)
    pdf = cell_pdf(L, r, c) / (TWO_PI_SQUARED * sin_t) if sin_t > 0.0 else 0.0
    params = L[ENV_MAP]
    if params[M_IDENTITY] != 0.0:
        return mx, my, mz, pdf
    x, y, z = _apply(params, M_INVERSE, mx, my, mz)
    n = math.sqrt(x * x + y * y + z * z)
    return x / n, y / n, z / n, pdf * (params[M_ABS_DET] * n ** 3)


@kernel(allocates=False)
def pdf_map(L, dx, dy, dz):
    """The solid-angle pdf with which `sample_map` produces one unit direction."""
    h, w = grid(L)
    params = L[ENV_MAP]
    mx, my, mz = _to_map(L, dx, dy, dz)
    n = math.sqrt(mx * mx + my * my + mz * mz)
    sin_t = math.hypot(mx, my) / n
    if not sin_t > 0.0:
        return 0.0
    u, v = direction_to_uv(mx, my, mz)
    c = min(max(int(math.floor((u % 1.0) * w)), 0), w - 1)
    r = min(max(int(math.floor(v * h)), 0), h - 1)
    pdf = cell_pdf(L, r, c) / (TWO_PI_SQUARED * sin_t)
    if params[M_IDENTITY] != 0.0:
        return pdf
    return pdf * (params[M_ABS_DET] / n ** 3)


@kernel(allocates=False)
def sample_environment_map(L, u0, u1):
    """The map as a light, sampled: (wix, wiy, wiz, inf, r, g, b, pdf, delta)."""
    wx, wy, wz, pdf = sample_map(L, u0, u1)
    r, g, b = 0.0, 0.0, 0.0
    if pdf > 0.0:
        r, g, b = map_radiance(L, wx, wy, wz)
    return wx, wy, wz, INF, r, g, b, pdf, False
