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
  DISP_ENTER out, save, part                 a Displacement and Bump material's bump
                                             on the undisplaced surface, as Cycles
                                             evaluates it (svm_node_enter_bump_eval):
                                             part 0 saves the hit's position, object
                                             coordinates and position steps (12
                                             registers from save) and puts the
                                             undisplaced point's in their place
                                             (context.H_UNDISPLACED); part 1, before the
                                             normal, the undisplaced position steps
                                             (Cycles' texture offsets move by the
                                             surface's own steps, its bump normal takes
                                             the undisplaced ones)
  DISP_LEAVE out, save                       all put back
  BUMP_NORMAL_OBJECT out, (as BUMP_NORMAL)   BUMP_NORMAL worked out in the object's space
                                             (the normal and the steps taken there, the
                                             result brought back as a normal): Cycles'
                                             bump of a Displacement and Bump material
  DISP_OBJECT_VECTOR out, normal, height     the Displacement node in Object space:
                                             M normalize(M^T normal) x height, a world
                                             vector (M: context.H_OBJ_MATRIX)

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
from .context import H_DX, H_DY, H_OBJ_MATRIX, H_OBJECT, H_P, H_UNDISPLACED, N_DIFF

BUMP_ENTER = 420
BUMP_LEAVE = 421
BUMP_NORMAL = 422
DISP_ENTER = 423
DISP_LEAVE = 424
BUMP_NORMAL_OBJECT = 425
DISP_OBJECT_VECTOR = 426


@kernel(inline="always")
def _swapped(i):
    """The hit-row column that undisplaced field i (0..11) stands in for."""
    group, k = i // 3, i % 3
    base = (H_P, H_OBJECT, H_DX + H_P, H_DY + H_P)[group]
    return base + k


@kernel(allocates=False)
def bent_normal(hit, nx, ny, nz, strength, distance, width, dhx, dhy):
    """Cycles' bump normal for the input normal n (see the module's docstring)."""
    return _bent(hit[H_DX + H_P], hit[H_DX + H_P + 1], hit[H_DX + H_P + 2], hit[H_DY + H_P],
                 hit[H_DY + H_P + 1], hit[H_DY + H_P + 2], nx, ny, nz, strength, distance,
                 width, dhx, dhy)


@kernel(inline="always")
def _m(hit, r, c):
    return hit[H_OBJ_MATRIX + 3 * r + c]


@kernel(allocates=False)
def _times(hit, x, y, z, transpose):
    """M v, or M^T v."""
    if transpose:
        return (_m(hit, 0, 0) * x + _m(hit, 1, 0) * y + _m(hit, 2, 0) * z,
                _m(hit, 0, 1) * x + _m(hit, 1, 1) * y + _m(hit, 2, 1) * z,
                _m(hit, 0, 2) * x + _m(hit, 1, 2) * y + _m(hit, 2, 2) * z)
    return (_m(hit, 0, 0) * x + _m(hit, 0, 1) * y + _m(hit, 0, 2) * z,
            _m(hit, 1, 0) * x + _m(hit, 1, 1) * y + _m(hit, 1, 2) * z,
            _m(hit, 2, 0) * x + _m(hit, 2, 1) * y + _m(hit, 2, 2) * z)


@kernel(allocates=False)
def _cofactor_times(hit, x, y, z, transpose):
    """cof(M) v, or cof(M)^T v (cof(M) = det(M) M^-T: M^-T v and M^-1 v up to det)."""
    c00 = _m(hit, 1, 1) * _m(hit, 2, 2) - _m(hit, 1, 2) * _m(hit, 2, 1)
    c01 = _m(hit, 1, 2) * _m(hit, 2, 0) - _m(hit, 1, 0) * _m(hit, 2, 2)
    c02 = _m(hit, 1, 0) * _m(hit, 2, 1) - _m(hit, 1, 1) * _m(hit, 2, 0)
    c10 = _m(hit, 0, 2) * _m(hit, 2, 1) - _m(hit, 0, 1) * _m(hit, 2, 2)
    c11 = _m(hit, 0, 0) * _m(hit, 2, 2) - _m(hit, 0, 2) * _m(hit, 2, 0)
    c12 = _m(hit, 0, 1) * _m(hit, 2, 0) - _m(hit, 0, 0) * _m(hit, 2, 1)
    c20 = _m(hit, 0, 1) * _m(hit, 1, 2) - _m(hit, 0, 2) * _m(hit, 1, 1)
    c21 = _m(hit, 0, 2) * _m(hit, 1, 0) - _m(hit, 0, 0) * _m(hit, 1, 2)
    c22 = _m(hit, 0, 0) * _m(hit, 1, 1) - _m(hit, 0, 1) * _m(hit, 1, 0)
    if transpose:
        return (c00 * x + c10 * y + c20 * z, c01 * x + c11 * y + c21 * z,
                c02 * x + c12 * y + c22 * z)
    return (c00 * x + c01 * y + c02 * z, c10 * x + c11 * y + c12 * z,
            c20 * x + c21 * y + c22 * z)


@kernel(allocates=False)
def _unit(x, y, z):
    ln = math.sqrt(x * x + y * y + z * z)
    if not ln > 0.0:
        return x, y, z
    return x / ln, y / ln, z / ln


@kernel(allocates=False)
def _det(hit):
    c0, c1, c2 = _cofactor_times(hit, 1.0, 0.0, 0.0, True)
    return _m(hit, 0, 0) * c0 + _m(hit, 0, 1) * c1 + _m(hit, 0, 2) * c2


@kernel(allocates=False)
def bent_normal_object(hit, nx, ny, nz, strength, distance, width, dhx, dhy):
    """`bent_normal` worked out in the object's space, as Cycles' Bump with
    use_object_space: the normal into object space (M^T n, normalised), the steps by
    M^-1, the bent normal back as a normal (M^-T, normalised)."""
    det = _det(hit)
    if det == 0.0:
        return bent_normal(hit, nx, ny, nz, strength, distance, width, dhx, dhy)
    tx, ty, tz = _times(hit, nx, ny, nz, True)
    ox, oy, oz = _unit(tx, ty, tz)
    ax, ay, az = _cofactor_times(hit, hit[H_DX + H_P], hit[H_DX + H_P + 1],
                                 hit[H_DX + H_P + 2], True)
    bx, by, bz = _cofactor_times(hit, hit[H_DY + H_P], hit[H_DY + H_P + 1],
                                 hit[H_DY + H_P + 2], True)
    x, y, z = _bent(ax / det, ay / det, az / det, bx / det, by / det, bz / det, ox, oy, oz,
                    strength, distance, width, dhx, dhy)
    wx, wy, wz = _cofactor_times(hit, x, y, z, False)
    if det < 0.0:
        wx, wy, wz = -wx, -wy, -wz
    return _unit(wx, wy, wz)


@kernel(allocates=False)
def displacement_object(hit, nx, ny, nz, h):
    """The Displacement node in Object space: M normalize(M^T n) h (world)."""
    tx, ty, tz = _times(hit, nx, ny, nz, True)
    ox, oy, oz = _unit(tx, ty, tz)
    return _times(hit, ox * h, oy * h, oz * h, False)


@kernel(allocates=False)
def _bent(ax, ay, az, bx, by, bz, nx, ny, nz, strength, distance, width, dhx, dhy):
    """Cycles' bump normal for the input normal n and surface steps a (x), b (y)."""
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
    elif code == DISP_ENTER:
        save, part = ins[2], ins[3]
        for i in range(6 * part, 6 * part + 6):
            c = _swapped(i)
            if part == 0:
                regs[save + i] = hit[c]
                regs[save + 6 + i] = hit[_swapped(6 + i)]
            hit[c] = hit[H_UNDISPLACED + i]
    elif code == DISP_LEAVE:
        save = ins[2]
        for i in range(12):
            hit[_swapped(i)] = regs[save + i]
    elif code == BUMP_NORMAL:
        n = ins[2]
        regs[out], regs[out + 1], regs[out + 2] = bent_normal(
            hit, regs[n], regs[n + 1], regs[n + 2], regs[ins[3]], regs[ins[4]],
            regs[ins[5]], regs[ins[6]], regs[ins[7]])
    elif code == BUMP_NORMAL_OBJECT:
        n = ins[2]
        regs[out], regs[out + 1], regs[out + 2] = bent_normal_object(
            hit, regs[n], regs[n + 1], regs[n + 2], regs[ins[3]], regs[ins[4]],
            regs[ins[5]], regs[ins[6]], regs[ins[7]])
    elif code == DISP_OBJECT_VECTOR:
        n = ins[2]
        regs[out], regs[out + 1], regs[out + 2] = displacement_object(
            hit, regs[n], regs[n + 1], regs[n + 2], regs[ins[3]])
