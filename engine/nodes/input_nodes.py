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
from .context import H_BACKFACING, H_I, H_RAY

IN_HIT3 = 0
IN_HIT1 = 1
IN_RAY_IS = 2
IN_FRESNEL = 3
IN_LAYER_FRESNEL = 4
IN_LAYER_FACING = 5


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
