"""Point, spot, sphere and soft-falloff disc lamps (`engine.lights.PointLightModel`).

Kinds (pack.T_*): T_POINT (delta point or spot), T_SPHERE (radius > 0: the uniform cone
the sphere subtends, uniform sphere from inside), T_DISC (radius > 0 with soft_falloff: a
disc facing the shaded point, sampled uniformly by area). Every function takes the lamp
table and the lamp's row k.

A spot's cone weighs each ray by its own direction from the lamp (Cycles' spot_light
attenuation of -D), so the cone's edge crosses a sphere lamp seen up close, in a mirror
say; no cone inside a sphere lamp, as in Cycles.
"""
from __future__ import annotations

import math

from ..frame import basis as orthonormal_basis
from ..jit import kernel
from ..warp import (PI, TWO_PI, concentric_disk, cone_from_one_minus_cos, max0, safe_unit,
                    smoothstep01, uniform_sphere)
from .pack import (C_AXIS, C_COS_HALF, C_INTENSITY, C_IS_SPOT, C_POS, C_RAD, C_RADIUS,
                   C_SMOOTH, C_TYPE, T_DISC, T_POINT)

INF = math.inf


@kernel(allocates=False)
def spot_factor(lamps, k, dx, dy, dz):
    """The spot cone's smoothstep falloff for the direction (dx, dy, dz) from the light."""
    if lamps[k, C_IS_SPOT] == 0.0:
        return 1.0
    c = dx * lamps[k, C_AXIS] + dy * lamps[k, C_AXIS + 1] + dz * lamps[k, C_AXIS + 2]
    cos_half = lamps[k, C_COS_HALF]
    smooth = lamps[k, C_SMOOTH]
    if smooth > 0.0:
        return smoothstep01((c - cos_half) / smooth)
    return 1.0 if c > cos_half else 0.0


@kernel(allocates=False)
def sphere_one_minus_cos(radius, d2):
    """1 - cos(theta_max) of the cone a sphere lamp subtends, without cancellation."""
    sin2 = radius * radius / (1e-300 if d2 < 1e-300 else d2)
    if sin2 > 1.0:
        sin2 = 1.0
    return sin2 / (1.0 + math.sqrt(1.0 - sin2))


@kernel(allocates=False)
def _sample_delta(lamps, k, wx, wy, wz, dist_c, d2):
    ok = d2 > 0.0
    okf = 1.0 if ok else 0.0
    den = d2 if ok else 1.0
    s = spot_factor(lamps, k, -wx, -wy, -wz) * okf
    r = lamps[k, C_INTENSITY] / den * s
    g = lamps[k, C_INTENSITY + 1] / den * s
    b = lamps[k, C_INTENSITY + 2] / den * s
    return wx, wy, wz, dist_c, r, g, b, okf, True


@kernel(allocates=False)
def _sample_disc(lamps, k, px, py, pz, u0, u1, ax, ay, az, dist_c):
    radius = lamps[k, C_RADIUS]
    tx, ty, tz, bx, by, bz = orthonormal_basis(ax, ay, az)
    s0, s1 = concentric_disk(u0, u1)
    s0 = s0 * radius
    s1 = s1 * radius
    qx = lamps[k, C_POS] + s0 * tx + s1 * bx
    qy = lamps[k, C_POS + 1] + s0 * ty + s1 * by
    qz = lamps[k, C_POS + 2] + s0 * tz + s1 * bz
    wx, wy, wz, dist = safe_unit(qx - px, qy - py, qz - pz)
    cos_l = abs(wx * ax + wy * ay + wz * az)
    area = PI * (radius * radius)
    ok = dist > 0.0 and cos_l > 0.0 and dist_c > 0.0
    pdf = dist * dist / (area * cos_l) if ok else 0.0
    s = spot_factor(lamps, k, -wx, -wy, -wz) * (1.0 if ok else 0.0)   # the ray's own
    return (wx, wy, wz, dist, lamps[k, C_RAD] * s, lamps[k, C_RAD + 1] * s,
            lamps[k, C_RAD + 2] * s, pdf, False)


@kernel(allocates=False)
def sample_point(lamps, k, px, py, pz, u0, u1):
    """A sample of point, spot, sphere or disc lamp k from one point:
    (wix, wiy, wiz, dist, r, g, b, pdf, delta), pdf in solid angle (1 for a delta)."""
    tox = lamps[k, C_POS] - px
    toy = lamps[k, C_POS + 1] - py
    toz = lamps[k, C_POS + 2] - pz
    d2 = tox * tox + toy * toy + toz * toz
    ax, ay, az, dist_c = safe_unit(tox, toy, toz)
    kind = lamps[k, C_TYPE]
    if kind == T_POINT:
        return _sample_delta(lamps, k, ax, ay, az, dist_c, d2)
    if kind == T_DISC:
        return _sample_disc(lamps, k, px, py, pz, u0, u1, ax, ay, az, dist_c)
    r = lamps[k, C_RADIUS]
    s = 1.0                                 # inside the sphere: no cone (Cycles)
    if d2 <= r * r:                         # inside the sphere: uniform sphere
        wx, wy, wz = uniform_sphere(u0, u1)
        ocx = px - lamps[k, C_POS]
        ocy = py - lamps[k, C_POS + 1]
        ocz = pz - lamps[k, C_POS + 2]
        bb = ocx * wx + ocy * wy + ocz * wz
        cc = (ocx * ocx + ocy * ocy + ocz * ocz) - r * r
        dist = -bb + math.sqrt(max0(bb * bb - cc))
        pdf = 1.0 / (4.0 * PI)
    else:
        om = sphere_one_minus_cos(r, d2)
        lx, ly, lz, omz = cone_from_one_minus_cos(u0, u1, om)
        tx, ty, tz, bx, by, bz = orthonormal_basis(ax, ay, az)
        wx = lx * tx + ly * bx + lz * ax
        wy = lx * ty + ly * by + lz * ay
        wz = lx * tz + ly * bz + lz * az
        sin2 = omz * (2.0 - omz)
        proj = dist_c * lz
        dist = proj - math.sqrt(max0(r * r - d2 * sin2))
        pdf = 1.0 / (TWO_PI * (1e-300 if om < 1e-300 else om))
        s = spot_factor(lamps, k, -wx, -wy, -wz)
    dist = max0(dist)
    return (wx, wy, wz, dist, lamps[k, C_RAD] * s, lamps[k, C_RAD + 1] * s,
            lamps[k, C_RAD + 2] * s, pdf, False)


@kernel(allocates=False)
def intersect_point(lamps, k, ox, oy, oz, dx, dy, dz):
    """Where one ray meets sphere or disc lamp k: (t or inf, r, g, b)."""
    if lamps[k, C_TYPE] == T_POINT:
        return INF, 0.0, 0.0, 0.0
    px, py, pz = lamps[k, C_POS], lamps[k, C_POS + 1], lamps[k, C_POS + 2]
    radius = lamps[k, C_RADIUS]
    ax, ay, az, dist_c = safe_unit(px - ox, py - oy, pz - oz)
    # the cone along the ray's own direction, as Cycles (not the centre's; none inside)
    inside = lamps[k, C_TYPE] != T_DISC and dist_c * dist_c <= radius * radius
    s = 1.0 if inside else spot_factor(lamps, k, -dx, -dy, -dz)
    r, g, b = lamps[k, C_RAD] * s, lamps[k, C_RAD + 1] * s, lamps[k, C_RAD + 2] * s
    if lamps[k, C_TYPE] == T_DISC:
        den = dx * ax + dy * ay + dz * az
        if not (den > 0.0 and dist_c > 0.0):
            return INF, r, g, b
        t = dist_c / den
        qx = ox + dx * t - px
        qy = oy + dy * t - py
        qz = oz + dz * t - pz
        if qx * qx + qy * qy + qz * qz <= radius * radius:
            return t, r, g, b
        return INF, r, g, b
    ocx, ocy, ocz = ox - px, oy - py, oz - pz
    bb = ocx * dx + ocy * dy + ocz * dz
    cc = (ocx * ocx + ocy * ocy + ocz * ocz) - radius * radius
    disc = bb * bb - cc
    if not disc >= 0.0:
        return INF, r, g, b
    sq = math.sqrt(disc)
    t0 = -bb - sq
    t1 = -bb + sq
    if t0 > 0.0:
        return t0, r, g, b
    if t1 > 0.0:
        return t1, r, g, b
    return INF, r, g, b


@kernel(allocates=False)
def pdf_point(lamps, k, px, py, pz, wix, wiy, wiz, t):
    """The solid-angle pdf of sampling wi (light hit at distance t)."""
    kind = lamps[k, C_TYPE]
    if kind == T_POINT:
        return 0.0
    tox = lamps[k, C_POS] - px
    toy = lamps[k, C_POS + 1] - py
    toz = lamps[k, C_POS + 2] - pz
    d2 = tox * tox + toy * toy + toz * toz
    r = lamps[k, C_RADIUS]
    if kind == T_DISC:
        ax, ay, az, dist_c = safe_unit(tox, toy, toz)
        cos_l = abs(wix * ax + wiy * ay + wiz * az)
        if cos_l > 0.0 and dist_c > 0.0:
            return t * t / (PI * (r * r) * cos_l)
        return 0.0
    if d2 <= r * r:
        return 1.0 / (4.0 * PI)
    om = sphere_one_minus_cos(r, d2)
    return 1.0 / (TWO_PI * (1e-300 if om < 1e-300 else om))
