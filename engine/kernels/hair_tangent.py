"""The fibre direction a Hair BSDF shades about (engine/kernels/bsdf/hair.py), as Cycles
takes it (kernel/svm/closure.h, the Hair BSDF closure): on a strand, the spline's
tangent dP/du at the hit (towards the tip); on a triangle, its second edge dP/dv =
p2 - p0 in the world (Cycles' triangle_dPdudv), where the node's Offset is dropped.

`write` puts it into a material row's per-hit columns, in the shading frame of the
normal n, before principled.setup reads the row. The integrators call it only for a
material with a Hair BSDF (row[P_HAIR] = 1)."""
from __future__ import annotations

import math

from .bsdf.params import P_HAIR_CURVE, P_HAIR_T
from .curve_hit import curve_point, is_curve
from .frame import to_local
from .jit import kernel
from .surface import rebuild_at_time


@kernel(allocates=False)
def _second_edge(geometry, prim, inst, time):
    """p2 - p0 of triangle `prim` placed as its hit was (its place `inst`, at `time`):
    its corners are the hits at barycentrics (0, 0) and (0, 1)."""
    p0 = rebuild_at_time(geometry, prim, inst, 0.0, 0.0, 0.0, 0.0, 1.0, time)
    p2 = rebuild_at_time(geometry, prim, inst, 0.0, 1.0, 0.0, 0.0, 1.0, time)
    return p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]


@kernel(allocates=False)
def write(geometry, prim, inst, u, v, time, nx, ny, nz, row):
    """Write the fibre's unit tangent at the hit (local to the frame of n) and whether
    the hit is on a strand into row[P_HAIR_T:P_HAIR_T + 3] and row[P_HAIR_CURVE]."""
    C = geometry[15]
    strand = is_curve(C, prim)
    if strand:
        _, _, _, _, tx, ty, tz = curve_point(C, prim - C.span[0], u)
    else:
        tx, ty, tz = _second_edge(geometry, prim, inst, time)
    ln = math.sqrt(tx * tx + ty * ty + tz * tz)
    if ln > 0.0 and ln < math.inf:
        tx, ty, tz = tx / ln, ty / ln, tz / ln
    else:
        tx, ty, tz = 0.0, 0.0, 1.0            # a degenerate edge: along the normal (no light)
    lx, ly, lz = to_local(tx, ty, tz, nx, ny, nz)
    row[P_HAIR_T] = lx
    row[P_HAIR_T + 1] = ly
    row[P_HAIR_T + 2] = lz
    row[P_HAIR_CURVE] = 1.0 if strand else 0.0
