"""The fibre direction hair closures shade about, as Cycles takes it (kernel/svm/closure.h):
on a strand, the spline's tangent dP/du at the hit (towards the tip); on a triangle,
the Hair BSDF's second edge dP/dv = p2 - p0 in the world (Cycles' triangle_dPdudv; the
node's Offset is dropped there), the Principled Hair BSDF's first edge dP/du = p1 - p0.
The Principled Hair BSDF also reads the geometric normal (for where across the fibre
the view meets it) and, when its Random socket is unlinked, the strand's Random.

`write` puts them into a material row's per-hit columns, in the shading frame of the
normal n, before principled.setup reads the row. The integrators call it only for a
material with a hair closure (row[P_HAIR] = 1)."""
from __future__ import annotations

import math

from .bsdf.params import (P_CHIANG, P_CHIANG_NG, P_CHIANG_OWN_RANDOM, P_CHIANG_RANDOM,
                          P_CHIANG_T, P_HAIR_CURVE, P_HAIR_T)
from .curve_hit import curve_point, is_curve
from .frame import to_local
from .jit import kernel
from .surface import rebuild_at_time


@kernel(allocates=False)
def _edges(geometry, prim, inst, time):
    """p1 - p0 and p2 - p0 of triangle `prim` placed as its hit was (its place `inst`,
    at `time`): its corners are the hits at barycentrics (0, 0), (1, 0) and (0, 1)
    (one call site of the rebuild, which is large, for the compiler to inline)."""
    x0 = y0 = z0 = ax = ay = az = bx = by = bz = 0.0
    for k in range(3):
        p = rebuild_at_time(geometry, prim, inst, 1.0 if k == 1 else 0.0,
                            1.0 if k == 2 else 0.0, 0.0, 0.0, 1.0, time)
        if k == 0:
            x0, y0, z0 = p[0], p[1], p[2]
        elif k == 1:
            ax, ay, az = p[0] - x0, p[1] - y0, p[2] - z0
        else:
            bx, by, bz = p[0] - x0, p[1] - y0, p[2] - z0
    return ax, ay, az, bx, by, bz


@kernel(allocates=False)
def _unit(tx, ty, tz):
    ln = math.sqrt(tx * tx + ty * ty + tz * tz)
    if ln > 0.0 and ln < math.inf:
        return tx / ln, ty / ln, tz / ln
    return 0.0, 0.0, 0.0


@kernel(allocates=False)
def _put(row, k, tx, ty, tz, nx, ny, nz):
    """The unit tangent t, local to the frame of n, into row[k:k + 3] (along the normal,
    where no light reaches it, for a degenerate edge)."""
    if tx == 0.0 and ty == 0.0 and tz == 0.0:
        tx, ty, tz = nx, ny, nz
    row[k], row[k + 1], row[k + 2] = to_local(tx, ty, tz, nx, ny, nz)


@kernel(allocates=False)
def write(geometry, prim, inst, u, v, time, nx, ny, nz, row):
    """Write the per-hit hair columns for the hit's shading normal n: the Hair BSDF's
    tangent and whether the hit is on a strand; the Principled Hair BSDF's tangent and
    the geometric normal p1 - p0 x p2 - p0 as they are (on the back of a triangle
    layers.setup turns both round, as Cycles does) and the strand's Random. (The caller
    passes nothing more: six more arguments to this call made the whole vertex loop of
    a Cornell box without hair 70 % slower, measured: 5.2-5.6 s against 3.0-3.3 s.)"""
    C = geometry[15]
    strand = is_curve(C, prim)
    ax = ay = az = bx = by = bz = 0.0      # the fibre: Cycles' dPdu, dPdv
    if strand:
        _, _, _, _, ax, ay, az = curve_point(C, prim - C.span[0], u)
        bx, by, bz = ax, ay, az
    else:
        ax, ay, az, bx, by, bz = _edges(geometry, prim, inst, time)
    row[P_HAIR_CURVE] = 1.0 if strand else 0.0
    tx, ty, tz = _unit(bx, by, bz)
    _put(row, P_HAIR_T, tx, ty, tz, nx, ny, nz)
    if row[P_CHIANG] + row[P_CHIANG + 1] + row[P_CHIANG + 2] > 0.0:
        tx, ty, tz = _unit(ax, ay, az)
        _put(row, P_CHIANG_T, tx, ty, tz, nx, ny, nz)
        if strand:                   # a strand's normal is its shading normal
            row[P_CHIANG_NG], row[P_CHIANG_NG + 1], row[P_CHIANG_NG + 2] = 0.0, 0.0, 1.0
        else:
            gx, gy, gz = _unit(ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx)
            _put(row, P_CHIANG_NG, gx, gy, gz, nx, ny, nz)
        if row[P_CHIANG_OWN_RANDOM] != 0.0 and strand:     # else the socket's value
            row[P_CHIANG_RANDOM + 2] = C.info[prim - C.span[0], 3]
