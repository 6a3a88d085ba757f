"""Area lamps, SQUARE / RECTANGLE / DISK / ELLIPSE (`engine.lights.AreaLightModel`).

Strategy, a function of the shading point only (`_uses_solid_angle`): uniform in
the spherical rectangle when the edges are perpendicular (C_SR_OK), the solid angle is
at least SOLID_ANGLE_MIN and the point is farther than IN_PLANE_REL x (lx + ly) from the
light's plane; uniform by area otherwise (concentric disk map for the round shapes).

A lamp with a Spread below 180 degrees (half angle h) emits from each point into the
cone of half angle h about its -Z only, weighted by Cycles' soft-box grid (`spread_
factor`). From a point p at height z over the lamp's plane only the disc of radius z tan
h about p's foot can light p, so sampling and its pdf keep to the box about that disc,
clipped to the lamp (`spread_window`, Cycles' area_light_spread_clamp_light): its
spherical rectangle, or uniform by area in it (a round lamp rejects the box's points
outside the ellipse: a sample of no light).
"""
from __future__ import annotations

import math

from ...lights import IN_PLANE_REL, SOLID_ANGLE_MIN
from ..jit import kernel
from .pack import (C_AREA, C_AX, C_AY, C_CENTER, C_INV, C_LX, C_LY, C_NORMAL,
                   C_NORM_SPREAD, C_RAD, C_ROUND, C_SR_OK, C_TAN_SPREAD)
from .spherical_rectangle import sample_spherical_rectangle, spherical_rectangle
from ..warp import concentric_disk, safe_unit

INF = math.inf


@kernel(allocates=False)
def _uses_solid_angle(lamps, k, z, omega):
    return omega >= SOLID_ANGLE_MIN and z > IN_PLANE_REL * (lamps[k, C_LX] + lamps[k, C_LY])


@kernel(allocates=False)
def spread_factor(lamps, k, wx, wy, wz):
    """The Spread's weight of the light lamp k sends to a receiver that sees it along
    the unit direction w: max(tan h - tan a, 0) times the normalisation, a the angle
    between the light's way out (-w) and the lamp's axis (-Z, so cos a = w . Z); 1
    without a Spread."""
    tan_h = lamps[k, C_TAN_SPREAD]
    if tan_h == 0.0:
        return 1.0
    nx, ny, nz = lamps[k, C_NORMAL], lamps[k, C_NORMAL + 1], lamps[k, C_NORMAL + 2]
    cos_a = wx * nx + wy * ny + wz * nz
    if not cos_a > 0.0:
        return 0.0
    cx, cy, cz = wy * nz - wz * ny, wz * nx - wx * nz, wx * ny - wy * nx
    tan_a = math.sqrt(cx * cx + cy * cy + cz * cz) / cos_a
    return max((tan_h - tan_a) * lamps[k, C_NORM_SPREAD], 0.0)


@kernel(allocates=False)
def spread_window(lamps, k, px, py, pz):
    """The part of lamp k that can light p under its Spread, in the lamp's (s, t)
    coordinates ([-1, 1]^2 over its parallelogram): (s_lo, s_hi, t_lo, t_hi), the box
    about the disc of radius z tan h around p's foot on the lamp's plane, clipped to the
    lamp; s_lo > s_hi when p is behind the lamp or the box misses it."""
    nx, ny, nz = lamps[k, C_NORMAL], lamps[k, C_NORMAL + 1], lamps[k, C_NORMAL + 2]
    vx = lamps[k, C_CENTER] - px
    vy = lamps[k, C_CENTER + 1] - py
    vz = lamps[k, C_CENTER + 2] - pz
    z = vx * nx + vy * ny + vz * nz                 # p's height in front of the lamp
    if not z > 0.0:
        return 1.0, -1.0, 1.0, -1.0
    r = z * lamps[k, C_TAN_SPREAD]
    # the foot, relative to the centre: -(v - z n)
    qx, qy, qz = z * nx - vx, z * ny - vy, z * nz - vz
    s_lo, s_hi = _window_side(lamps, k, 0, qx, qy, qz, nx, ny, nz, r)
    t_lo, t_hi = _window_side(lamps, k, 1, qx, qy, qz, nx, ny, nz, r)
    return s_lo, s_hi, t_lo, t_hi


@kernel(allocates=False)
def _window_side(lamps, k, axis, qx, qy, qz, nx, ny, nz, r):
    """The range of lamp k's coordinate `axis` (0: s, 1: t) over the disc of radius r
    about the in-plane point q (relative to the centre), clipped to [-1, 1]: the
    coordinate is q . row of the inverse frame, so the disc spans r times the row's
    length in the lamp's plane either side."""
    ix = lamps[k, C_INV + 3 * axis]
    iy = lamps[k, C_INV + 3 * axis + 1]
    iz = lamps[k, C_INV + 3 * axis + 2]
    centre = qx * ix + qy * iy + qz * iz
    dn = ix * nx + iy * ny + iz * nz
    ux, uy, uz = ix - dn * nx, iy - dn * ny, iz - dn * nz
    half = r * math.sqrt(ux * ux + uy * uy + uz * uz)
    return max(centre - half, -1.0), min(centre + half, 1.0)


@kernel(allocates=False)
def _window_area(lamps, k, s_lo, s_hi, t_lo, t_hi):
    """The area of the window [s_lo, s_hi] x [t_lo, t_hi] of lamp k's parallelogram."""
    whole = lamps[k, C_AREA] * (4.0 / math.pi if lamps[k, C_ROUND] != 0.0 else 1.0)
    return whole * 0.25 * (s_hi - s_lo) * (t_hi - t_lo)


@kernel(allocates=False)
def sample_area(lamps, k, px, py, pz, u0, u1):
    """A sample of area lamp k from one point: (wix, wiy, wiz, dist, r, g, b, pdf, delta)."""
    spread = lamps[k, C_TAN_SPREAD] != 0.0
    s_lo, s_hi, t_lo, t_hi = -1.0, 1.0, -1.0, 1.0
    if spread:
        s_lo, s_hi, t_lo, t_hi = spread_window(lamps, k, px, py, pz)
        if not (s_hi > s_lo and t_hi > t_lo):
            return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, False
    use = False
    x0 = x1 = y0 = y1 = zs = z = cos_k = sin_k = omega = 0.0
    if lamps[k, C_SR_OK] != 0.0:
        x0, x1, y0, y1, zs, z, cos_k, sin_k, omega = spherical_rectangle(
            lamps, k, px, py, pz, s_lo, s_hi, t_lo, t_hi)
        use = _uses_solid_angle(lamps, k, z, omega)
    if use:
        ox, oy, oz = sample_spherical_rectangle(lamps, k, x0, x1, y0, y1, zs, z, cos_k,
                                                sin_k, omega, u0, u1)
    else:
        if spread:
            s0, s1 = s_lo + u0 * (s_hi - s_lo), t_lo + u1 * (t_hi - t_lo)
            if lamps[k, C_ROUND] != 0.0 and s0 * s0 + s1 * s1 > 1.0:
                return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, False
        elif lamps[k, C_ROUND] != 0.0:
            s0, s1 = concentric_disk(u0, u1)
        else:
            s0, s1 = 2.0 * u0 - 1.0, 2.0 * u1 - 1.0
        ox = lamps[k, C_CENTER] - px + s0 * lamps[k, C_AX] + s1 * lamps[k, C_AY]
        oy = lamps[k, C_CENTER + 1] - py + s0 * lamps[k, C_AX + 1] + s1 * lamps[k, C_AY + 1]
        oz = lamps[k, C_CENTER + 2] - pz + s0 * lamps[k, C_AX + 2] + s1 * lamps[k, C_AY + 2]
    wx, wy, wz, dist = safe_unit(ox, oy, oz)
    nx, ny, nz = lamps[k, C_NORMAL], lamps[k, C_NORMAL + 1], lamps[k, C_NORMAL + 2]
    cos_l = wx * nx + wy * ny + wz * nz           # > 0 on the emitting (-Z) side
    side = ((lamps[k, C_CENTER] - px) * nx + (lamps[k, C_CENTER + 1] - py) * ny
            + (lamps[k, C_CENTER + 2] - pz) * nz)
    if not (cos_l > 0.0 and dist > 0.0 and side > 0.0):
        return wx, wy, wz, dist, 0.0, 0.0, 0.0, 0.0, False
    if use:
        pdf = 1.0 / omega
    elif spread:
        pdf = dist * dist / (_window_area(lamps, k, s_lo, s_hi, t_lo, t_hi) * cos_l)
    else:
        pdf = dist * dist / (lamps[k, C_AREA] * cos_l)
    f = spread_factor(lamps, k, wx, wy, wz) if spread else 1.0
    return (wx, wy, wz, dist, lamps[k, C_RAD] * f, lamps[k, C_RAD + 1] * f,
            lamps[k, C_RAD + 2] * f, pdf, False)


@kernel(allocates=False)
def _lamp_coords(lamps, k, qx, qy, qz):
    """(s, t): the in-plane offset q from lamp k's centre in its coordinates ([-1, 1]^2
    over its parallelogram, the unit disc for the round shapes)."""
    return (qx * lamps[k, C_INV] + qy * lamps[k, C_INV + 1] + qz * lamps[k, C_INV + 2],
            qx * lamps[k, C_INV + 3] + qy * lamps[k, C_INV + 4] + qz * lamps[k, C_INV + 5])


@kernel(allocates=False)
def intersect_area(lamps, k, ox, oy, oz, dx, dy, dz):
    """Where one ray meets area lamp k: (t or inf, r, g, b); only the emitting
    side (rays travelling along the light's +Z) hits."""
    nx, ny, nz = lamps[k, C_NORMAL], lamps[k, C_NORMAL + 1], lamps[k, C_NORMAL + 2]
    cx, cy, cz = lamps[k, C_CENTER], lamps[k, C_CENTER + 1], lamps[k, C_CENTER + 2]
    r, g, b = lamps[k, C_RAD], lamps[k, C_RAD + 1], lamps[k, C_RAD + 2]
    denom = dx * nx + dy * ny + dz * nz
    if not denom > 0.0:
        return INF, r, g, b
    t = ((cx - ox) * nx + (cy - oy) * ny + (cz - oz) * nz) / denom
    if not t > 0.0:
        return INF, r, g, b
    tq = t if math.isfinite(t) else 0.0
    qx = ox + dx * tq - cx
    qy = oy + dy * tq - cy
    qz = oz + dz * tq - cz
    s, u = _lamp_coords(lamps, k, qx, qy, qz)
    if lamps[k, C_ROUND] != 0.0:
        inside = s * s + u * u <= 1.0
    else:
        inside = abs(s) <= 1.0 and abs(u) <= 1.0
    if inside:
        if lamps[k, C_TAN_SPREAD] != 0.0:
            f = spread_factor(lamps, k, dx, dy, dz)
            return t, r * f, g * f, b * f
        return t, r, g, b
    return INF, r, g, b


@kernel(allocates=False)
def pdf_area(lamps, k, px, py, pz, wix, wiy, wiz, t):
    """The solid-angle pdf of sample_area(p) producing wi, the light hit at
    distance t (0 when t is not finite or wi grazes the light)."""
    cos_l = abs(wix * lamps[k, C_NORMAL] + wiy * lamps[k, C_NORMAL + 1]
                + wiz * lamps[k, C_NORMAL + 2])
    ok = cos_l > 0.0 and math.isfinite(t)
    if not ok:
        return 0.0
    s_lo, s_hi, t_lo, t_hi = -1.0, 1.0, -1.0, 1.0
    area = lamps[k, C_AREA]
    if lamps[k, C_TAN_SPREAD] != 0.0:
        s_lo, s_hi, t_lo, t_hi = spread_window(lamps, k, px, py, pz)
        qx = px + wix * t - lamps[k, C_CENTER]
        qy = py + wiy * t - lamps[k, C_CENTER + 1]
        qz = pz + wiz * t - lamps[k, C_CENTER + 2]
        s, u = _lamp_coords(lamps, k, qx, qy, qz)
        if not (s_lo <= s <= s_hi and t_lo <= u <= t_hi):
            return 0.0                   # outside the window: never sampled from p
        area = _window_area(lamps, k, s_lo, s_hi, t_lo, t_hi)
    out = t * t / (area * cos_l)
    if lamps[k, C_SR_OK] != 0.0:
        _, _, _, _, _, z, _, _, omega = spherical_rectangle(lamps, k, px, py, pz, s_lo,
                                                            s_hi, t_lo, t_hi)
        if _uses_solid_angle(lamps, k, z, omega):
            out = 1.0 / omega
    return out
