"""Scalar versions of the `engine.warp` maps (disk, hemisphere, sphere, cone), and the
small NumPy-semantics helpers the kernels share (clip, sign, safe_unit).

Each function computes the same floating-point operations, in the same order, as its
vectorised original in `engine.warp`, so the compiled samplers give
the NumPy reference's values (bit for bit where both use the same libm).
"""
from __future__ import annotations

import math

from .jit import kernel

PI = math.pi
TWO_PI = 2.0 * math.pi
INV_PI = 1.0 / math.pi


@kernel
def max0(x):
    """np.maximum(x, 0.0) for one float (NaN stays NaN, as in NumPy)."""
    return 0.0 if x < 0.0 else x


@kernel
def clip01(x):
    """np.clip(x, 0, 1) for one float (NaN stays NaN)."""
    if x < 0.0:
        return 0.0
    if x > 1.0:
        return 1.0
    return x


@kernel
def clip(x, lo, hi):
    """np.clip(x, lo, hi) = minimum(maximum(x, lo), hi), NaN propagating."""
    if x < lo:
        x = lo
    if x > hi:
        x = hi
    return x


@kernel
def sign(x):
    """np.sign for one float: -1, 0 or 1 (NaN stays NaN)."""
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return x * 0.0          # 0 for +-0, NaN for NaN


@kernel
def safe_unit(x, y, z):
    """(unit vector, length), (0, 0, 1) for a zero vector."""
    n = math.sqrt(x * x + y * y + z * z)
    if n > 0.0:
        return x / n, y / n, z / n, n
    return 0.0, 0.0, 1.0, n


@kernel
def concentric_disk(u0, u1):
    """engine.warp.concentric_disk (Shirley-Chiu) for one point."""
    a = 2.0 * u0 - 1.0
    b = 2.0 * u1 - 1.0
    if abs(a) > abs(b):
        r = a
        phi = (PI / 4.0) * (b / a)
    else:
        r = b
        phi = (PI / 2.0) - (PI / 4.0) * (a / (1.0 if b == 0.0 else b))
    if a == 0.0 and b == 0.0:
        r = 0.0
    return r * math.cos(phi), r * math.sin(phi)


@kernel
def cosine_hemisphere(u0, u1):
    """engine.warp.cosine_hemisphere: a cosine-weighted direction about +Z (Malley's
    method); pdf cos(theta) / pi."""
    dx, dy = concentric_disk(u0, u1)
    z = math.sqrt(max(0.0, 1.0 - (dx * dx + dy * dy)))
    return dx, dy, z


@kernel
def uniform_sphere(u0, u1):
    """engine.warp.uniform_sphere for one point; pdf 1 / (4 pi)."""
    z = 1.0 - 2.0 * u0
    r = math.sqrt(max0(1.0 - z * z))
    phi = TWO_PI * u1
    return r * math.cos(phi), r * math.sin(phi), z


@kernel
def cone_from_one_minus_cos(u0, u1, one_minus_cos_max):
    """A uniform direction in the cone about +Z
    with 1 - cos(theta_max) given; also returns 1 - cos(theta) of the direction."""
    omz = u0 * one_minus_cos_max
    sin_t = math.sqrt(max0(omz * (2.0 - omz)))
    phi = TWO_PI * u1
    return sin_t * math.cos(phi), sin_t * math.sin(phi), 1.0 - omz, omz


@kernel
def smoothstep01(x):
    x = clip01(x)
    return x * x * (3.0 - 2.0 * x)
