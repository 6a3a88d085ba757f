"""The part of a ray's segment that a light can reach, for sampling distances towards it
(kernels/equiangular.py), as Cycles clips its equiangular segments
(volume_valid_direct_ray_segment): a spot lamp lights only the inside of its cone, an
area lamp only the half-space in front of it. Sampling over the whole segment is just
as unbiased, but in a spot beam seen from the side, or along a ray that runs to
infinity through a world volume, most distances would land where the lamp gives nothing,
and the beam renders as noise.

The range only has to contain every point the light reaches, so it is conservative:

- a spot's cone is widened by CONE_MARGIN radians, and for a sphere or disc spot (radius
  r) its apex is moved back along the axis by r / sin(half angle), so that the cone
  holds the whole lamp and every ray leaving it within the cone's angle (DRT weighs each
  ray by its own direction from the lamp: lights/point.py); a cone of half angle
  90 degrees or more is not clipped;
- an area lamp's plane is moved back by MARGIN times its size.

Point lamps, emissive triangles, suns and the world are not clipped.
"""
from __future__ import annotations

import math

from ..jit import kernel
from .light_set import lamp_row
from .pack import (C_AX, C_AXIS, C_AY, C_CENTER, C_COS_HALF, C_IS_SPOT, C_NORMAL, C_POS,
                   C_RADIUS, C_TYPE, LAMP_SLICES, LAMPS, T_AREA, T_DISC, T_POINT, T_SPHERE)

CONE_MARGIN = 1e-3      # radians added to a spot's half angle
MARGIN = 1e-6           # an area lamp's plane moved back, relative to its size
_WIDEST = 0.5 * math.pi - 2e-3      # half angles beyond this are not clipped


@kernel(allocates=False)
def lit_range(L, k, ox, oy, oz, dx, dy, dz, t0, t1, time):
    """The interval of [t0, t1] (t1 may be infinite) where light entry k may light the
    points o + t d: (lo, hi), with lo > hi when nowhere."""
    lamps = L[LAMPS]
    if k < 0 or k >= lamps.shape[0]:
        return t0, t1
    kind = lamps[k, C_TYPE]
    sliced, row = lamp_row(L, k, time)
    table = L[LAMP_SLICES] if sliced else lamps
    if (kind == T_POINT or kind == T_SPHERE or kind == T_DISC) and table[row, C_IS_SPOT] != 0.0:
        half = math.acos(min(max(table[row, C_COS_HALF], -1.0), 1.0)) + CONE_MARGIN
        if half >= _WIDEST:
            return t0, t1
        ax, ay, az = table[row, C_AXIS], table[row, C_AXIS + 1], table[row, C_AXIS + 2]
        back = table[row, C_RADIUS] / math.sin(half) if kind != T_POINT else 0.0
        return cone_range(table[row, C_POS] - ax * back, table[row, C_POS + 1] - ay * back,
                          table[row, C_POS + 2] - az * back, ax, ay, az, math.cos(half),
                          ox, oy, oz, dx, dy, dz, t0, t1)
    if kind == T_AREA:
        # emission along -normal: the points x with (x - c) . n < 0
        nx, ny, nz = table[row, C_NORMAL], table[row, C_NORMAL + 1], table[row, C_NORMAL + 2]
        size = 0.0
        for c in range(3):
            size += abs(table[row, C_AX + c]) + abs(table[row, C_AY + c])
        h = ((ox - table[row, C_CENTER]) * nx + (oy - table[row, C_CENTER + 1]) * ny
             + (oz - table[row, C_CENTER + 2]) * nz) - MARGIN * size
        s = dx * nx + dy * ny + dz * nz
        return half_space_range(h, s, t0, t1)
    return t0, t1


@kernel(allocates=False)
def half_space_range(h, s, t0, t1):
    """The interval of [t0, t1] where h + s t < 0."""
    if s == 0.0:
        return (t0, t1) if h < 0.0 else (1.0, 0.0)
    t_cross = -h / s
    if s > 0.0:
        return t0, min(t1, t_cross)
    return max(t0, t_cross), t1


@kernel(allocates=False)
def _in_cone(px, py, pz, ax, ay, az, cos_half, ox, oy, oz, dx, dy, dz, t):
    vx, vy, vz = ox + dx * t - px, oy + dy * t - py, oz + dz * t - pz
    along = vx * ax + vy * ay + vz * az
    return along >= 0.0 and along * along >= cos_half * cos_half * (vx * vx + vy * vy
                                                                    + vz * vz)


@kernel(allocates=False)
def cone_range(px, py, pz, ax, ay, az, cos_half, ox, oy, oz, dx, dy, dz, t0, t1):
    """The interval of [t0, t1] inside the cone of apex p, unit axis a and half angle
    acos(cos_half) < 90 degrees (convex, so a line meets it in one interval): the
    quadratic's roots and the apex plane's crossing cut [t0, t1] into pieces, and each
    piece is in or out as its midpoint is."""
    vx, vy, vz = ox - px, oy - py, oz - pz
    va = vx * ax + vy * ay + vz * az
    da = dx * ax + dy * ay + dz * az
    c2 = cos_half * cos_half
    qa = da * da - c2 * (dx * dx + dy * dy + dz * dz)
    qb = 2.0 * (va * da - c2 * (vx * dx + vy * dy + vz * dz))
    qc = va * va - c2 * (vx * vx + vy * vy + vz * vz)
    # up to three cut points inside (t0, t1); a missing one stays t0 (an empty piece)
    c1 = c2 = c3 = t0
    if qa != 0.0:
        disc = qb * qb - 4.0 * qa * qc
        if disc >= 0.0:
            r = math.sqrt(disc)
            q = -0.5 * (qb + r if qb >= 0.0 else qb - r)       # without cancellation
            root = q / qa
            if t0 < root < t1:
                c1 = root
            root = qc / q if q != 0.0 else t0
            if t0 < root < t1:
                c2 = root
    elif qb != 0.0 and t0 < -qc / qb < t1:
        c1 = -qc / qb
    if da != 0.0 and t0 < -va / da < t1:
        c3 = -va / da
    c1, c2 = min(c1, c2), max(c1, c2)
    c2, c3 = min(c2, c3), max(c2, c3)
    c1, c2 = min(c1, c2), max(c1, c2)
    lo, hi = 1.0, 0.0
    a = t0
    for i in range(4):
        b = c1 if i == 0 else (c2 if i == 1 else (c3 if i == 2 else t1))
        if b > a:
            mid = 0.5 * (a + b) if math.isfinite(b) else a + max(1.0, abs(a))
            if _in_cone(px, py, pz, ax, ay, az, cos_half, ox, oy, oz, dx, dy, dz, mid):
                if lo > hi:
                    lo = a
                hi = b
            a = b
    return lo, hi
