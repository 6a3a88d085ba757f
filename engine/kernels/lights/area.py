"""Area lamps, SQUARE / RECTANGLE / DISK / ELLIPSE (`engine.lights.AreaLightModel`).

Strategy, a function of the shading point only (`_uses_solid_angle`): uniform in
the spherical rectangle when the edges are perpendicular (C_SR_OK), the solid angle is
at least SOLID_ANGLE_MIN and the point is farther than IN_PLANE_REL x (lx + ly) from the
light's plane; uniform by area otherwise (concentric disk map for the round shapes).
"""
from __future__ import annotations

import math

from ...lights import IN_PLANE_REL, SOLID_ANGLE_MIN
from ..jit import kernel
from .pack import (C_AREA, C_AX, C_AY, C_CENTER, C_INV, C_LX, C_LY, C_NORMAL, C_RAD,
                   C_ROUND, C_SR_OK)
from .spherical_rectangle import sample_spherical_rectangle, spherical_rectangle
from ..warp import concentric_disk, safe_unit

INF = math.inf


@kernel(allocates=False)
def _uses_solid_angle(lamps, k, z, omega):
    return omega >= SOLID_ANGLE_MIN and z > IN_PLANE_REL * (lamps[k, C_LX] + lamps[k, C_LY])


@kernel(allocates=False)
def sample_area(lamps, k, px, py, pz, u0, u1):
    """A sample of area lamp k from one point: (wix, wiy, wiz, dist, r, g, b, pdf, delta)."""
    use = False
    x0 = x1 = y0 = y1 = zs = z = cos_k = sin_k = omega = 0.0
    if lamps[k, C_SR_OK] != 0.0:
        x0, x1, y0, y1, zs, z, cos_k, sin_k, omega = spherical_rectangle(lamps, k, px, py,
                                                                          pz)
        use = _uses_solid_angle(lamps, k, z, omega)
    if use:
        ox, oy, oz = sample_spherical_rectangle(lamps, k, x0, x1, y0, y1, zs, z, cos_k,
                                                sin_k, omega, u0, u1)
    else:
        if lamps[k, C_ROUND] != 0.0:
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
    else:
        pdf = dist * dist / (lamps[k, C_AREA] * cos_l)
    return (wx, wy, wz, dist, lamps[k, C_RAD], lamps[k, C_RAD + 1], lamps[k, C_RAD + 2],
            pdf, False)


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
    s = qx * lamps[k, C_INV] + qy * lamps[k, C_INV + 1] + qz * lamps[k, C_INV + 2]
    u = qx * lamps[k, C_INV + 3] + qy * lamps[k, C_INV + 4] + qz * lamps[k, C_INV + 5]
    if lamps[k, C_ROUND] != 0.0:
        inside = s * s + u * u <= 1.0
    else:
        inside = abs(s) <= 1.0 and abs(u) <= 1.0
    if inside:
        return t, r, g, b
    return INF, r, g, b


@kernel(allocates=False)
def pdf_area(lamps, k, px, py, pz, wix, wiy, wiz, t):
    """The solid-angle pdf of sample_area(p) producing wi, the light hit at
    distance t (0 when t is not finite or wi grazes the light)."""
    cos_l = abs(wix * lamps[k, C_NORMAL] + wiy * lamps[k, C_NORMAL + 1]
                + wiz * lamps[k, C_NORMAL + 2])
    ok = cos_l > 0.0 and math.isfinite(t)
    out = t * t / (lamps[k, C_AREA] * cos_l) if ok else 0.0
    if ok and lamps[k, C_SR_OK] != 0.0:
        _, _, _, _, _, z, _, _, omega = spherical_rectangle(lamps, k, px, py, pz)
        if _uses_solid_angle(lamps, k, z, omega):
            out = 1.0 / omega
    return out
