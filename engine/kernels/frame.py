"""Small vector algebra on (x, y, z) float tuples, and the shading frame.

The frame is the same as `engine.warp.orthonormal_basis` (Duff et al. 2017): the
compiled and the NumPy paths agree on what "local" means.
"""
from __future__ import annotations

import math

from .jit import kernel


@kernel(allocates=False)
def dot(ax, ay, az, bx, by, bz):
    return ax * bx + ay * by + az * bz


@kernel(allocates=False)
def cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@kernel(allocates=False)
def basis(nx, ny, nz):
    """Tangents (t, b) with (t, b, n) right-handed and orthonormal, for unit n."""
    sign = 1.0 if nz >= 0.0 else -1.0
    a = -1.0 / (sign + nz)
    b = nx * ny * a
    return (1.0 + sign * nx * nx * a, sign * b, -sign * nx,
            b, sign + ny * ny * a, -ny)


@kernel(allocates=False)
def to_local(vx, vy, vz, nx, ny, nz):
    tx, ty, tz, bx, by, bz = basis(nx, ny, nz)
    return (vx * tx + vy * ty + vz * tz, vx * bx + vy * by + vz * bz,
            vx * nx + vy * ny + vz * nz)


@kernel(allocates=False)
def to_world(lx, ly, lz, nx, ny, nz):
    tx, ty, tz, bx, by, bz = basis(nx, ny, nz)
    return (lx * tx + ly * bx + lz * nx, lx * ty + ly * by + lz * ny,
            lx * tz + ly * bz + lz * nz)


@kernel(allocates=False)
def length(x, y, z):
    return math.sqrt(x * x + y * y + z * z)


@kernel(allocates=False)
def unit(x, y, z):
    """(x, y, z) scaled to length 1; (0, 0, 0) stays."""
    ln = math.sqrt(x * x + y * y + z * z)
    if ln > 0.0:
        return x / ln, y / ln, z / ln
    return 0.0, 0.0, 0.0
