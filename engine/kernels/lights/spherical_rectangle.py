"""The spherical rectangle an area lamp subtends from a point, one point at a time:
its solid angle and the area-preserving sampling map (Urena, Fajardo, King 2013), in a
cancellation-free form.

Local frame: x, y along the rectangle's edges (lengths lx, ly) from its corner c,
z = x cross y; with (x0, y0, z') = (c - p) in that frame, the rectangle is
[x0, x1] x [y0, y1] at height z' (x1 = x0 + lx, y1 = y0 + ly); z = |z'|.

Solid angle omega = g0 + g1 + g2 + g3 - 2 pi with the interior angles g_i at the
corners, here as atan2(|n_i x n_j|, -n_i . n_j) of the edge-plane normals, which
simplifies to  g = atan2(z |v|, s x y)  at a corner v = (x, y, z) with the sign s
alternating (+, -, +, -) over (x1, y0), (x1, y1), (x0, y1), (x0, y0): exact even
when z -> 0 or omega -> 0 (acos of a dot product would lose half the digits). The
angles are added as arguments of the complex numbers c = s x y + i z |v|: omega is
the argument of c0 c1 c2 c3 (one atan2, taken in [0, 2 pi); an argument just below 0
is rounding, a solid angle of 0), and the map's starting angle k = 2 pi - g2 - g3
enters through its cosine and sine, those of the conjugate of c2 c3.

Sampling u -> (xu, yv) (the paper's eqs. with cancellation-free rewrites):
  k = 2 pi - g2 - g3,  au = u0 omega + k  (cos and sin of au from those of u0 omega
  and of k),
  N = cos(au) b0 - b1,  D = sin(au),  b0 = -y0 / sqrt(y0^2 + z^2),
  b1 = y1 / sqrt(y1^2 + z^2),  1 - b0^2 = z^2 / (y0^2 + z^2),
  xu = sign(N) z D / sqrt(N^2 - (1 - b0^2) D^2)   [= -cu z0 / sqrt(1 - cu^2) of the
       paper with cu = sign(fu) / sqrt(fu^2 + b0^2), fu = N / D; no division by D]
  dd = sqrt(xu^2 + z^2), h_i = y_i / sqrt(dd^2 + y_i^2), hv = h0 + u1 (h1 - h0),
  yv = hv dd / sqrt((1 - hv)(1 + hv)),  with 1 -+ hv interpolated from 1 -+ h_i, each
  computed without cancellation.
Both steps are continuous and monotonic in u; the result is uniform in solid angle.

(Four atan2, a cos and a sin before 2026-11-26; the results agree to 1e-11 relative.)
"""
from __future__ import annotations

import math

from ...lights import SOLID_ANGLE_WRAP
from ..jit import kernel
from .pack import C_CORNER, C_LX, C_LY, C_XH, C_YH, C_ZH
from ..warp import TWO_PI, clip, sign


@kernel(allocates=False)
def _corner(x, y, z, z2, s):
    """The corner's angle as a complex number (real, imaginary), any length."""
    return s * x * y, z * math.sqrt(x * x + y * y + z2)


@kernel(allocates=False)
def _times(ar, ai, br, bi):
    """a b, scaled so that its larger part is 1 (the argument is all that counts)."""
    r, i = ar * br - ai * bi, ar * bi + ai * br
    m = max(abs(r), abs(i))
    if m > 0.0:
        return r / m, i / m
    return 1.0, 0.0


@kernel(allocates=False)
def spherical_rectangle(lamps, k, px, py, pz, s_lo, s_hi, t_lo, t_hi):
    """The part [s_lo, s_hi] x [t_lo, t_hi] of lamp k's rectangle (its (s, t)
    coordinates, [-1, 1] over the whole lamp) seen from p, in its local frame:
    (x0, x1, y0, y1, z_signed, z, cos k, sin k, solid_angle), k the map's starting
    angle."""
    dx = lamps[k, C_CORNER] - px
    dy = lamps[k, C_CORNER + 1] - py
    dz = lamps[k, C_CORNER + 2] - pz
    x0 = dx * lamps[k, C_XH] + dy * lamps[k, C_XH + 1] + dz * lamps[k, C_XH + 2]
    y0 = dx * lamps[k, C_YH] + dy * lamps[k, C_YH + 1] + dz * lamps[k, C_YH + 2]
    zs = dx * lamps[k, C_ZH] + dy * lamps[k, C_ZH + 1] + dz * lamps[k, C_ZH + 2]
    z = abs(zs)
    x1 = x0 + 0.5 * (s_hi + 1.0) * lamps[k, C_LX]
    y1 = y0 + 0.5 * (t_hi + 1.0) * lamps[k, C_LY]
    x0 = x0 + 0.5 * (s_lo + 1.0) * lamps[k, C_LX]
    y0 = y0 + 0.5 * (t_lo + 1.0) * lamps[k, C_LY]
    z2 = z * z
    c0r, c0i = _corner(x1, y0, z, z2, 1.0)
    c1r, c1i = _corner(x1, y1, z, z2, -1.0)
    c2r, c2i = _corner(x0, y1, z, z2, 1.0)
    c3r, c3i = _corner(x0, y0, z, z2, -1.0)
    ar, ai = _times(c0r, c0i, c1r, c1i)                  # g0 + g1
    br, bi = _times(c2r, c2i, c3r, c3i)                  # g2 + g3
    sr, si = _times(ar, ai, br, bi)                      # the sum of all four
    omega = math.atan2(si, sr)                           # omega, modulo 2 pi
    if omega < 0.0:
        omega = omega + TWO_PI if omega < SOLID_ANGLE_WRAP else 0.0
    norm = math.sqrt(br * br + bi * bi)                  # k = 2 pi - (g2 + g3)
    return x0, x1, y0, y1, zs, z, br / norm, -bi / norm, omega


@kernel(allocates=False)
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
def sample_spherical_rectangle(lamps, k, x0, x1, y0, y1, zs, z, cos_k, sin_k, omega, u0,
                               u1):
    """SphericalRectangle.sample: the offset from p to a point of the rectangle, uniform
    in the solid angle it subtends."""
    z2 = z * z
    r00 = math.sqrt(y0 * y0 + z2)
    r01 = math.sqrt(y1 * y1 + z2)
    b0 = -y0 / (r00 if r00 > 0.0 else 1.0)
    b1 = y1 / (r01 if r01 > 0.0 else 1.0)
    b0c2 = z2 / (r00 * r00 if r00 > 0.0 else 1.0)         # 1 - b0^2
    cu, su = math.cos(u0 * omega), math.sin(u0 * omega)   # the angle k + u0 omega
    num = (cu * cos_k - su * sin_k) * b0 - b1
    den = su * cos_k + cu * sin_k
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
