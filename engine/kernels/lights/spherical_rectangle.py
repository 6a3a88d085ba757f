"""The spherical rectangle an area lamp subtends from a point, one point at a time
(`engine.lights.SphericalRectangle`, Urena, Fajardo, King 2013, in the cancellation-free
form documented there): its solid angle and the area-preserving sampling map."""
from __future__ import annotations

import math

from ..jit import kernel
from .pack import C_CORNER, C_LX, C_LY, C_XH, C_YH, C_ZH
from ..warp import TWO_PI, clip, max0, sign


@kernel
def _corner_angle(x, y, z, z2, s):
    return math.atan2(z * math.sqrt(x * x + y * y + z2), s * x * y)


@kernel(allocates=False)
def spherical_rectangle(lamps, k, px, py, pz):
    """The rectangle of lamp k seen from p, in its local frame:
    (x0, x1, y0, y1, z_signed, z, k_angle, solid_angle)."""
    dx = lamps[k, C_CORNER] - px
    dy = lamps[k, C_CORNER + 1] - py
    dz = lamps[k, C_CORNER + 2] - pz
    x0 = dx * lamps[k, C_XH] + dy * lamps[k, C_XH + 1] + dz * lamps[k, C_XH + 2]
    y0 = dx * lamps[k, C_YH] + dy * lamps[k, C_YH + 1] + dz * lamps[k, C_YH + 2]
    zs = dx * lamps[k, C_ZH] + dy * lamps[k, C_ZH + 1] + dz * lamps[k, C_ZH + 2]
    z = abs(zs)
    x1 = x0 + lamps[k, C_LX]
    y1 = y0 + lamps[k, C_LY]
    z2 = z * z
    g0 = _corner_angle(x1, y0, z, z2, 1.0)
    g1 = _corner_angle(x1, y1, z, z2, -1.0)
    g2 = _corner_angle(x0, y1, z, z2, 1.0)
    g3 = _corner_angle(x0, y0, z, z2, -1.0)
    ka = TWO_PI - g2 - g3
    omega = max0(g0 + g1 - ka)
    return x0, x1, y0, y1, zs, z, ka, omega


@kernel
def _one_minus_plus(y, dd2):
    """(1 - h, 1 + h) for h = y / sqrt(dd2 + y^2), each without cancellation."""
    r = math.sqrt(dd2 + y * y)
    rs = r if r > 0.0 else 1.0
    small = dd2 / (rs * (rs + abs(y)))            # 1 - |h|, exactly
    large = (rs + abs(y)) / rs                     # 1 + |h|
    if y >= 0.0:
        return small, large
    return large, small


@kernel(allocates=False)
def sample_spherical_rectangle(lamps, k, x0, x1, y0, y1, zs, z, ka, omega, u0, u1):
    """SphericalRectangle.sample: the offset from p to a point of the rectangle, uniform
    in the solid angle it subtends."""
    z2 = z * z
    r00 = math.sqrt(y0 * y0 + z2)
    r01 = math.sqrt(y1 * y1 + z2)
    b0 = -y0 / (r00 if r00 > 0.0 else 1.0)
    b1 = y1 / (r01 if r01 > 0.0 else 1.0)
    b0c2 = z2 / (r00 * r00 if r00 > 0.0 else 1.0)         # 1 - b0^2
    au = u0 * omega + ka
    num = math.cos(au) * b0 - b1
    den = math.sin(au)
    den2 = num * num - b0c2 * den * den
    if den2 > 0.0:
        xu = sign(num) * z * den / math.sqrt(den2)
    else:
        xu = x0 if u0 < 0.5 else x1
    xu = clip(xu, x0, x1)
    dd2 = xu * xu + z2
    om0, op0 = _one_minus_plus(y0, dd2)
    om1, op1 = _one_minus_plus(y1, dd2)
    om = (1.0 - u1) * om0 + u1 * om1                       # 1 - hv
    op = (1.0 - u1) * op0 + u1 * op1                       # 1 + hv
    hv = 0.5 * (op - om)
    prod = om * op
    if prod > 0.0:
        yv = hv * math.sqrt(dd2) / math.sqrt(prod)
    else:
        yv = y1 if hv > 0.0 else y0
    yv = clip(yv, y0, y1)
    ox = xu * lamps[k, C_XH] + yv * lamps[k, C_YH] + zs * lamps[k, C_ZH]
    oy = xu * lamps[k, C_XH + 1] + yv * lamps[k, C_YH + 1] + zs * lamps[k, C_ZH + 1]
    oz = xu * lamps[k, C_XH + 2] + yv * lamps[k, C_YH + 2] + zs * lamps[k, C_ZH + 2]
    return ox, oy, oz
