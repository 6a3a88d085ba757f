"""The kernels' side of shader programs: run a hit's material program and read its
outputs into the Principled parameter row, emission and alpha.

geometry is the compiled path tracer's triangle tuple; its fields 10 and 11 are each
triangle's object (int32, empty when no mesh carries ObjectInfo) and the object table
(context.O_* rows)."""
from __future__ import annotations

from ..kernels.jit import kernel
from .context import fill
from .interpreter import run
from .pack import OUTS

OUT_BASE, OUT_METALLIC, OUT_ROUGHNESS, OUT_EMISSION, OUT_ALPHA = 0, 1, 2, 3, 4


@kernel
def program_hit(T, geometry, m, prim, uu, vv, px, py, pz, gx, gy, gz, nx, ny, nz, dx, dy,
                dz, front, ray, depth, length, hit, regs):
    """Fill the hit row of a hit on triangle prim (material m) and run m's program."""
    tri_object, objects = geometry[10], geometry[11]
    obj = tri_object[prim] if tri_object.shape[0] > 0 else -1
    fill(hit, px, py, pz, nx, ny, nz, gx, gy, gz, dx, dy, dz, uu, vv, front, ray, depth,
         length, objects, obj)
    run(T, m, hit, regs)


@kernel
def apply_rows(T, m, regs, row, P_BASE, P_METALLIC, P_ROUGHNESS):
    """Write the program's base colour, metallic and roughness into the parameter row."""
    outs = T[OUTS]
    r = outs[m, OUT_BASE]
    if r >= 0:
        row[P_BASE] = max(regs[r], 0.0)
        row[P_BASE + 1] = max(regs[r + 1], 0.0)
        row[P_BASE + 2] = max(regs[r + 2], 0.0)
    r = outs[m, OUT_METALLIC]
    if r >= 0:
        row[P_METALLIC] = min(max(regs[r], 0.0), 1.0)
    r = outs[m, OUT_ROUGHNESS]
    if r >= 0:
        row[P_ROUGHNESS] = min(max(regs[r], 0.0), 1.0)


@kernel
def program_emission(T, m, regs, r, g, b):
    """The program's emission, or (r, g, b) when it does not drive it."""
    k = T[OUTS][m, OUT_EMISSION]
    if k < 0:
        return r, g, b
    return regs[k], regs[k + 1], regs[k + 2]


@kernel
def program_alpha(T, m, regs, a):
    """The program's alpha clipped to [0, 1], or a when it does not drive it."""
    k = T[OUTS][m, OUT_ALPHA]
    if k < 0:
        return a
    return min(max(regs[k], 0.0), 1.0)
