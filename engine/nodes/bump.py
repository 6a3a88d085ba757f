"""The Bump node, as Cycles evaluates it (svm_node_set_bump, Blender 5): its Height is
computed three times, at the hit and at the hit moved by a pixel step in x and in y
scaled by Filter Width, and the normal is bent by the differences. Opcodes 420-439.

  BUMP_ENTER out, save, axis, filter_width   the hit row's surface fields (the first
                                             context.N_DIFF) saved to registers
                                             save.. and moved by filter_width x their
                                             differential (axis 0: x, 1: y)
  BUMP_LEAVE out, save                       the saved fields put back
  BUMP_NORMAL out, normal, strength, distance, filter_width, dx, dy
                                             the bent normal; dx, dy: the height's
                                             changes over the two offset steps;
                                             distance negative when inverted

The exporter emits the Height's nodes between BUMP_ENTER and BUMP_LEAVE once per axis
(outputs of the same nodes, computed at the moved hit; nested bumps nest), then once
more at the hit. `out` of ENTER and LEAVE is an unused register.

The normal (Mikkelsen's surface gradient): with the surface steps dPdx and dPdy (the
unscaled differentials of the position), Rx = dPdy x N, Ry = N x dPdx,
det = dPdx . Rx and the gradient g = dx Rx + dy Ry, the bent normal is
normalize(filter_width |det| N - distance sign(det) g), blended towards N by Strength
(clamped at 0); N itself when that vanishes (no footprint, no height change)."""
from __future__ import annotations

import math

from ..kernels.jit import kernel
from .context import H_DX, H_DY, H_P, N_DIFF

BUMP_ENTER = 420
BUMP_LEAVE = 421
BUMP_NORMAL = 422


@kernel
def bent_normal(hit, nx, ny, nz, strength, distance, width, dhx, dhy):
    """Cycles' bump normal for the input normal n (see the module's docstring)."""
    ax, ay, az = hit[H_DX + H_P], hit[H_DX + H_P + 1], hit[H_DX + H_P + 2]
    bx, by, bz = hit[H_DY + H_P], hit[H_DY + H_P + 1], hit[H_DY + H_P + 2]
    rxx, rxy, rxz = by * nz - bz * ny, bz * nx - bx * nz, bx * ny - by * nx
    ryx, ryy, ryz = ny * az - nz * ay, nz * ax - nx * az, nx * ay - ny * ax
    det = ax * rxx + ay * rxy + az * rxz
    s = distance * (1.0 if det >= 0.0 else -1.0)
    k = width * abs(det)
    x = k * nx - s * (dhx * rxx + dhy * ryx)
    y = k * ny - s * (dhx * rxy + dhy * ryy)
    z = k * nz - s * (dhx * rxz + dhy * ryz)
    ln = math.sqrt(x * x + y * y + z * z)
    if not ln > 0.0 or not math.isfinite(ln):
        return nx, ny, nz
    strength = max(strength, 0.0)
    x = strength * x / ln + (1.0 - strength) * nx
    y = strength * y / ln + (1.0 - strength) * ny
    z = strength * z / ln + (1.0 - strength) * nz
    ln = math.sqrt(x * x + y * y + z * z)
    if not ln > 0.0:
        return nx, ny, nz
    return x / ln, y / ln, z / ln


@kernel(allocates=False)
def execute(ins, regs, hit):
    code, out = ins[0], ins[1]
    if code == BUMP_ENTER:
        save, block, width = ins[2], H_DX if ins[3] == 0 else H_DY, regs[ins[4]]
        for k in range(N_DIFF):
            regs[save + k] = hit[k]
            hit[k] += width * hit[block + k]
    elif code == BUMP_LEAVE:
        save = ins[2]
        for k in range(N_DIFF):
            hit[k] = regs[save + k]
    elif code == BUMP_NORMAL:
        n = ins[2]
        regs[out], regs[out + 1], regs[out + 2] = bent_normal(
            hit, regs[n], regs[n + 1], regs[n + 2], regs[ins[3]], regs[ins[4]],
            regs[ins[5]], regs[ins[6]], regs[ins[7]])
