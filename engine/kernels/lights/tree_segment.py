"""The light tree's view of a ray segment through a volume (Cycles' `in_volume_segment`
form of the importance, tree.py): a light matters to a segment o + s d, s in [0, t], by
the angle the segment subtends from it (theta_b - theta_a in Conty Estevez and Kulla's
Eq. 4) over its distance to the segment's line, and by the smallest angle between its
emission axis and the directions from it to the segment (`towards_segment`, the paper's
Fig. 8). The equiangular strategy picks its light with this view, before it knows where
on the segment its point will be (kernels/medium_vertex.py).
"""
from __future__ import annotations

import math

from ..frame import unit as _unit
from ..jit import kernel

BIG_T = 1e12              # an infinite segment's far end, for directions towards it


@kernel(allocates=False)
def closest(recv, cx, cy, cz):
    """(s, x, y, z, d): the segment's parameter nearest to c on its line, the point of
    the segment nearest to c (s clamped to [0, t]), and c's distance to the line."""
    ox, oy, oz, dx, dy, dz, t = recv[0], recv[1], recv[2], recv[3], recv[4], recv[5], recv[7]
    s = (cx - ox) * dx + (cy - oy) * dy + (cz - oz) * dz
    sc = min(max(s, 0.0), t)
    lx, ly, lz = cx - ox - dx * s, cy - oy - dy * s, cz - oz - dz * s
    return s, ox + dx * sc, oy + dy * sc, oz + dz * sc, math.sqrt(lx * lx + ly * ly + lz * lz)


@kernel(allocates=False)
def subtended(recv, s, d):
    """theta_d: the angle the segment subtends from a light at distance d from its line,
    nearest to its parameter s (Cycles' form, stable at small angles)."""
    t = recv[7]
    if t == math.inf:
        return math.atan2(s, d) + 0.5 * math.pi
    return math.atan2(t, d - s * ((t - s) / d if d != 0.0 else 0.0))


@kernel(allocates=False)
def towards_segment(recv, cx, cy, cz, ax, ay, az):
    """v: the unit direction from c to a point of the segment that makes the smallest
    angle with the axis a (Cycles' `compute_v`)."""
    ox, oy, oz, dx, dy, dz = recv[0], recv[1], recv[2], recv[3], recv[4], recv[5]
    t = min(recv[7], BIG_T)
    v0x, v0y, v0z = _unit(ox - cx, oy - cy, oz - cz)
    v1x, v1y, v1z = _unit(ox - cx + dx * t, oy - cy + dy * t, oz - cz + dz * t)
    # o1: the unit direction in the plane of v0 and v1, orthogonal to v0
    bx, by, bz = v0y * v1z - v0z * v1y, v0z * v1x - v0x * v1z, v0x * v1y - v0y * v1x
    bx, by, bz = _unit(bx, by, bz)
    o1x, o1y, o1z = by * v0z - bz * v0y, bz * v0x - bx * v0z, bx * v0y - by * v0x
    a0 = v0x * ax + v0y * ay + v0z * az
    a1 = o1x * ax + o1y * ay + o1z * az
    n = math.sqrt(a0 * a0 + a1 * a1)
    cos_phi0 = a0 / n if n > 0.0 else 1.0
    if a1 < 0.0 or n == 0.0 or v0x * v1x + v0y * v1y + v0z * v1z > cos_phi0:
        # the nearest direction to the axis is an end of the segment
        if a0 > v1x * ax + v1y * ay + v1z * az:
            return v0x, v0y, v0z
        return v1x, v1y, v1z
    return (cos_phi0 * v0x + a1 / n * o1x, cos_phi0 * v0y + a1 / n * o1y,
            cos_phi0 * v0z + a1 / n * o1z)


@kernel(allocates=False)
def reaches_front(recv, cx, cy, cz, ax, ay, az):
    """Whether some point of the segment is in front of the plane through c facing a
    (a one-sided lamp lights only what is in front of it)."""
    ox, oy, oz, dx, dy, dz, t = recv[0], recv[1], recv[2], recv[3], recv[4], recv[5], recv[7]
    front = (ox - cx) * ax + (oy - cy) * ay + (oz - cz) * az
    along = dx * ax + dy * ay + dz * az
    return front > 0.0 or along > 0.0 and (t == math.inf or front + along * t > 0.0)
