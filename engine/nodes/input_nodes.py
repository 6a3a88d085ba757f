"""Input nodes: what the hit is (Texture Coordinate, Geometry, Object Info, UV Map,
Fresnel, Layer Weight, Light Path). Opcodes 0-99.

  IN_HIT3 out, field          a triple of the hit row (context.H_* of its first column)
  IN_HIT1 out, field          one column of the hit row
  IN_RAY_IS out, mask         1 if the ray's kind (context.H_RAY) is in the
                              engine.visibility mask, else 0
  IN_FRESNEL out, ior, normal           Cycles' Fresnel node
  IN_LAYER_FRESNEL out, blend, normal   Layer Weight > Fresnel
  IN_LAYER_FACING out, blend, normal    Layer Weight > Facing
"""
from __future__ import annotations

import math

from ..kernels.jit import kernel
from ..kernels.frame import cross, unit
from .context import (H_BACKFACING, H_GENERATED, H_I, H_N, H_RAY, H_TANGENT,
                      H_TANGENT_SIGN)
from .normal_map import _cofactors

IN_HIT3 = 0
IN_HIT1 = 1
IN_RAY_IS = 2
IN_FRESNEL = 3
IN_LAYER_FRESNEL = 4
IN_LAYER_FACING = 5
IN_TANGENT = 6
TANGENT_RADIAL = 0
TANGENT_UV_MAP = 1


@kernel(allocates=False)
def fresnel_dielectric_cos(cosi, eta):
    """Unpolarised Fresnel reflectance of a dielectric of relative IOR eta at cos(angle)
    cosi (total internal reflection: 1), as Cycles' node functions compute it."""
    c = abs(cosi)
    g = eta * eta - 1.0 + c * c
    if g > 0.0:
        g = math.sqrt(g)
        a = (g - c) / (g + c)
        b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
        return 0.5 * a * a * (1.0 + b * b)
    return 1.0


@kernel(allocates=False)
def _cos_in(regs, hit, n):
    nx, ny, nz = regs[n], regs[n + 1], regs[n + 2]
    ln = math.sqrt(nx * nx + ny * ny + nz * nz)
    if ln > 0.0:
        nx, ny, nz = nx / ln, ny / ln, nz / ln
    return hit[H_I] * nx + hit[H_I + 1] * ny + hit[H_I + 2] * nz


@kernel(allocates=False)
def tangent(hit, kind, axis):
    """The tangent at the hit as Cycles' Tangent node makes it: the UV map's (object
    space; zero where the mesh has none), or radial about `axis` through the generated
    coordinates' centre; taken to the world as a normal is (object_normal_transform: by
    the inverse transpose of the object's matrix) and made perpendicular to the shading
    normal, unit length (zero where it is along the normal)."""
    if kind == TANGENT_UV_MAP:
        if hit[H_TANGENT_SIGN] == 0.0:
            return 0.0, 0.0, 0.0
        x, y, z = hit[H_TANGENT], hit[H_TANGENT + 1], hit[H_TANGENT + 2]
    else:
        gx = hit[H_GENERATED] - 0.5
        gy = hit[H_GENERATED + 1] - 0.5
        gz = hit[H_GENERATED + 2] - 0.5
        if axis == 0:
            x, y, z = 0.0, -gz, gy
        elif axis == 1:
            x, y, z = -gz, 0.0, gx
        else:
            x, y, z = -gy, gx, 0.0
    r0, r1, r2, det = _cofactors(hit)
    if det < 0.0:
        x, y, z = -x, -y, -z
    x, y, z = unit(r0[0] * x + r0[1] * y + r0[2] * z, r1[0] * x + r1[1] * y + r1[2] * z,
                   r2[0] * x + r2[1] * y + r2[2] * z)
    nx, ny, nz = hit[H_N], hit[H_N + 1], hit[H_N + 2]
    cx, cy, cz = cross(x, y, z, nx, ny, nz)
    cx, cy, cz = unit(cx, cy, cz)
    return cross(nx, ny, nz, cx, cy, cz)


@kernel(allocates=False)
def execute(ins, regs, hit):
    code, out = ins[0], ins[1]
    if code == IN_HIT3:
        f = ins[2]
        regs[out], regs[out + 1], regs[out + 2] = hit[f], hit[f + 1], hit[f + 2]
    elif code == IN_HIT1:
        regs[out] = hit[ins[2]]
    elif code == IN_RAY_IS:
        regs[out] = 1.0 if (int(hit[H_RAY]) & ins[2]) != 0 else 0.0
    elif code == IN_FRESNEL:
        eta = max(regs[ins[2]], 1e-5)
        if hit[H_BACKFACING] > 0.0:
            eta = 1.0 / eta
        regs[out] = fresnel_dielectric_cos(_cos_in(regs, hit, ins[3]), eta)
    elif code == IN_LAYER_FRESNEL:
        eta = max(1.0 - regs[ins[2]], 1e-5)
        if hit[H_BACKFACING] <= 0.0:
            eta = 1.0 / eta
        regs[out] = fresnel_dielectric_cos(_cos_in(regs, hit, ins[3]), eta)
    elif code == IN_LAYER_FACING:
        blend = regs[ins[2]]
        f = abs(_cos_in(regs, hit, ins[3]))
        if blend != 0.5:
            blend = min(max(blend, 0.0), 1.0 - 1e-5)
            blend = 2.0 * blend if blend < 0.5 else 0.5 / (1.0 - blend)
            f = f ** blend
        regs[out] = 1.0 - f
    elif code == IN_TANGENT:
        regs[out], regs[out + 1], regs[out + 2] = tangent(hit, ins[2], ins[3])
