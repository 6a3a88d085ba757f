"""Surface interactions rebuilt in float64 from Embree's hit, and safe ray origins: the
compiled form of `engine.surface` for static triangles (same formulas, one hit at a
time). See that module for why hit points come from barycentrics and why the ray offset
is relative to the coordinates' magnitude."""
from __future__ import annotations

import math

import numpy as np

from ..surface import RELATIVE_OFFSET
from .frame import dot
from .jit import kernel


@kernel
def rebuild(v0, v1, v2, normal, tri_scale, corner_normals, prim, u, v, dx, dy, dz):
    """The hit of a ray with direction d on static triangle `prim` at barycentrics (u, v).
    corner_normals is (T, 3, 3) float32, or empty for flat shading everywhere.
    Returns (position, geometric normal facing the ray, shading normal on that side,
    front_facing, offset scale)."""
    w = 1.0 - u - v
    px = w * v0[prim, 0] + u * v1[prim, 0] + v * v2[prim, 0]
    py = w * v0[prim, 1] + u * v1[prim, 1] + v * v2[prim, 1]
    pz = w * v0[prim, 2] + u * v1[prim, 2] + v * v2[prim, 2]
    gx, gy, gz = normal[prim, 0], normal[prim, 1], normal[prim, 2]
    front = dot(gx, gy, gz, dx, dy, dz) < 0.0
    sign = 1.0 if front else -1.0
    fx, fy, fz = gx * sign, gy * sign, gz * sign
    sx, sy, sz = fx, fy, fz
    if corner_normals.shape[0] > 0:
        c = corner_normals
        nx = w * np.float64(c[prim, 0, 0]) + u * np.float64(c[prim, 1, 0]) + v * np.float64(c[prim, 2, 0])
        ny = w * np.float64(c[prim, 0, 1]) + u * np.float64(c[prim, 1, 1]) + v * np.float64(c[prim, 2, 1])
        nz = w * np.float64(c[prim, 0, 2]) + u * np.float64(c[prim, 1, 2]) + v * np.float64(c[prim, 2, 2])
        ln = math.sqrt(nx * nx + ny * ny + nz * nz)
        if ln > 1e-12:
            nx, ny, nz = nx / ln, ny / ln, nz / ln
        else:
            nx, ny, nz = gx, gy, gz
        nx, ny, nz = nx * sign, ny * sign, nz * sign
        # a shading normal bent past the geometric one is replaced by it
        if dot(nx, ny, nz, fx, fy, fz) > 0.0:
            sx, sy, sz = nx, ny, nz
    scale = max(max(abs(px), abs(py), abs(pz)), tri_scale[prim])
    return px, py, pz, fx, fy, fz, sx, sy, sz, front, scale


@kernel
def offset_origin(px, py, pz, nx, ny, nz, scale, dx, dy, dz):
    """The origin of a ray leaving p along d: p pushed along n to d's side."""
    side = 1.0 if dot(nx, ny, nz, dx, dy, dz) >= 0.0 else -1.0
    eps = RELATIVE_OFFSET * max(scale, 1e-30) * side
    return px + nx * eps, py + ny * eps, pz + nz * eps


@kernel
def hit_uv(corner_uvs, prim, u, v):
    """Texture coordinates at barycentrics (u, v) of triangle prim, from its corner UVs
    (T, 3, 2) float32; (0, 0) when the scene has none (Cycles' missing UV map)."""
    if corner_uvs.shape[0] == 0:
        return 0.0, 0.0
    w = 1.0 - u - v
    c = corner_uvs
    return (w * np.float64(c[prim, 0, 0]) + u * np.float64(c[prim, 1, 0]) + v * np.float64(c[prim, 2, 0]),
            w * np.float64(c[prim, 0, 1]) + u * np.float64(c[prim, 1, 1]) + v * np.float64(c[prim, 2, 1]))
