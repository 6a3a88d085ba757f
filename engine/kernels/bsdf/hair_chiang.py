"""Blender's Principled Hair BSDF, Chiang model (Cycles' bsdf_principled_hair_chiang.h,
after Chiang et al. 2016, "A practical and controllable hair and fur model for
production path tracing", itself after d'Eon et al. and pbrt's hair).

A fibre is a rough dielectric cylinder with absorption sigma inside. Light leaves it
after p internal paths: R (p = 0, reflected at the cuticle), TT (through), TRT (one
reflection inside) and the residual TRRT+ of all the rest. Each lobe is a product
        Ap(wo) Mp(theta_i; theta_o tilted by the cuticle's alpha, v_p) Np(phi; h)
of an attenuation Ap (Fresnel F at the entry, transmittance T = exp(-2 sigma cos
gamma_t / cos theta_t) per crossing: A0 = F, A1 = (1-F)^2 T, A2 = A1 T F, A3 = A2 T F /
(1 - T F)), a longitudinal lobe Mp (a von Mises-Fisher-like density in theta of variance
v: R uses the Coat's m0, TT v / 4, TRT and the residual 4 v) and an azimuthal lobe Np (a
logistic of scale s trimmed to [-pi, pi], about the exit azimuth 2 p gamma_t - 2
gamma_o + p pi; the residual is uniform). h in [-1, 1] is where across the fibre's
width the view meets it: gamma_o = asin(h).

Frame (Cycles' local frame): X the fibre's tangent, Y = X x wo normalised (the closure's
N: light with Y.wi < 0 counts as transmission), Z = X x Y; theta is the angle out of the
plane normal to X, phi the azimuth about X from Y towards Z.

As in Cycles: `evaluate` returns the value f |cos| per channel (no cosine to add) and the
pdf = sum_p Ap_energy_p Mp Np with Ap_energy the lobes' luminance shares, which is the
exact density `sample` draws (pick p by Ap_energy, Mp by its closed-form inverse,
Np by the trimmed logistic's inverse, the residual's azimuth uniformly). Sampling needs
three numbers: u_p picks the lobe and is rescaled for Mp's cosine, u_phi for Np, u_ring
for Mp's ring.

`remap` turns the node's Roughness, Radial Roughness and Coat into v, s and m0 with
Cycles' fits (bsdf_hair_chiang_setup); `absorption` turns its colour parametrisations
into sigma (svm closure.h; bsdf_util.h)."""
from __future__ import annotations

import math

from ..jit import kernel
from . import fresnel

TWO_PI = 2.0 * math.pi
SQRT_PI_8 = math.sqrt(math.pi / 8.0)
LN_2PI = math.log(TWO_PI)
LUMINANCE_R, LUMINANCE_G, LUMINANCE_B = 0.2126729, 0.7151522, 0.0721750
# the node's parametrisations (Blender's `parametrization`)
ABSORPTION, MELANIN, COLOR = 0, 1, 2


@kernel(allocates=False)
def _clamp01(x):
    return min(max(x, 0.001), 1.0)


@kernel(allocates=False)
def _variance(r):
    """Cycles' fit from a longitudinal roughness to the variance of Mp."""
    r2 = r * r
    r20 = r2 * r2 * r2 * r2 * r2
    r20 = r20 * r20
    x = 0.726 * r + 0.812 * r2 + 3.7 * r20
    return x * x


@kernel(allocates=False)
def remap(roughness, radial, coat, filter_roughness):
    """(v, s, m0): the variance of TT's neighbours, the logistic scale and the R lobe's
    variance, from the node's Roughness, Radial Roughness and Coat (clamped as Cycles'
    setup) and Filter Glossy's smallest roughness (Cycles' blur: a floor on all three)."""
    rv = _clamp01(roughness)
    rs = _clamp01(radial)
    r0 = _clamp01((1.0 - min(max(coat, 0.0), 1.0)) * rv)
    s2 = rs * rs
    s22 = s2 * s2 * s2 * s2 * s2 * s2 * s2 * s2 * s2 * s2 * s2
    s = (0.265 * rs + 1.194 * s2 + 5.372 * s22) * SQRT_PI_8
    f = max(filter_roughness, 0.0)
    return max(_variance(rv), f), max(s, f), max(_variance(r0), f)


@kernel(allocates=False)
def albedo_roughness_scale(x):
    """Cycles' bsdf_principled_hair_albedo_roughness_scale (a polynomial fit)."""
    return (((((0.245 * x) + 5.574) * x - 10.73) * x + 2.532) * x - 0.215) * x + 5.969


@kernel(allocates=False)
def sigma_from_reflectance(c, radial):
    """The absorption that gives a fibre the colour c (one channel)."""
    k = math.log(max(c, 0.0)) / albedo_roughness_scale(radial) if c > 0.0 else -math.inf
    return k * k


@kernel(allocates=False)
def absorption(mode, cr, cg, cb, melanin, redness, tr, tg, tb, random_color, random,
               radial):
    """sigma per channel for the node's parametrisation: ABSORPTION (c is the absorption
    coefficient), COLOR (c the fibre's colour) or MELANIN (melanin 0..1 remapped as
    -log(1 - m), split into eu- and pheomelanin by its redness, plus the Tint t;
    Random Color scales the melanin by 1 + 2 (random - 1/2) random_color)."""
    if mode == ABSORPTION:
        return cr, cg, cb
    if mode == COLOR:
        return (sigma_from_reflectance(cr, radial), sigma_from_reflectance(cg, radial),
                sigma_from_reflectance(cb, radial))
    rc = min(max(random_color, 0.0), 1.0)
    m = melanin * (1.0 + 2.0 * (random - 0.5) * rc)
    m = -math.log(max(1.0 - m, 0.0001))
    eu = m * (1.0 - redness)
    pheo = m * redness
    return (eu * 0.506 + pheo * 0.343 + sigma_from_reflectance(tr, radial),
            eu * 0.841 + pheo * 0.733 + sigma_from_reflectance(tg, radial),
            eu * 1.653 + pheo * 1.924 + sigma_from_reflectance(tb, radial))


@kernel(allocates=False)
def offset_h(gx, gy, gz, tx, ty, tz, vx, vy, vz):
    """h = (Ng x X) . Z: where across the fibre the view v (towards the viewer) meets
    it, for geometric normal Ng and tangent X (any frame, X unit): -Ng . Y, Y = X x v
    normalised. 0 where v lies along X."""
    yx = ty * vz - tz * vy
    yy = tz * vx - tx * vz
    yz = tx * vy - ty * vx
    ln = math.sqrt(yx * yx + yy * yy + yz * yz)
    if not ln > 0.0:
        return 0.0
    return min(max(-(gx * yx + gy * yy + gz * yz) / ln, -1.0), 1.0)


@kernel(allocates=False)
def _bessel_i0(x):
    x = x * x
    val = 1.0 + 0.25 * x
    pow_x_2i = x * x
    i_fac_2 = 1.0
    pow_4_i = 16.0
    for i in range(2, 10):
        i_fac_2 *= i * i
        newval = val + pow_x_2i / (pow_4_i * i_fac_2)
        if val == newval:
            return val
        val = newval
        pow_x_2i *= x
        pow_4_i *= 4.0
    return val


@kernel(allocates=False)
def _log_bessel_i0(x):
    if x > 12.0:
        return x + 0.5 * (1.0 / (8.0 * x) - LN_2PI - math.log(x))
    return math.log(_bessel_i0(x))


@kernel(allocates=False)
def longitudinal(sin_i, cos_i, sin_o, cos_o, v):
    """Mp: the longitudinal density of variance v (per unit cos theta_i dtheta_i)."""
    inv_v = 1.0 / v
    cos_arg = cos_i * cos_o * inv_v
    sin_arg = sin_i * sin_o * inv_v
    if v <= 0.1:
        return math.exp(_log_bessel_i0(cos_arg) - sin_arg - inv_v + 0.6931
                        + math.log(0.5 * inv_v))
    return math.exp(-sin_arg) * _bessel_i0(cos_arg) / (math.sinh(inv_v) * 2.0 * v)


@kernel(allocates=False)
def _logistic_cdf(x, s):
    arg = -x / s
    if arg > 88.0:
        return 0.0
    return 1.0 / (1.0 + math.exp(arg))


@kernel(allocates=False)
def _wrap(a):
    return (a + math.pi) - TWO_PI * math.floor((a + math.pi) / TWO_PI) - math.pi


@kernel(allocates=False)
def azimuthal(phi, p, s, gamma_o, gamma_t):
    """Np: the logistic of scale s trimmed to [-pi, pi] about lobe p's exit azimuth."""
    x = _wrap(phi - (2.0 * p * gamma_t - 2.0 * gamma_o + p * math.pi))
    e = math.exp(-abs(x) / s)
    val = e / (s * (1.0 + e) * (1.0 + e))
    scale = 1.0 - 2.0 * _logistic_cdf(-math.pi, s)
    return val / scale if scale != 0.0 else 0.0


@kernel(allocates=False)
def _cos_from_sin(s):
    return math.sqrt(max(1.0 - s * s, 0.0))


@kernel(allocates=False)
def _tilted(sin_o, cos_o, alpha):
    """The view's (sin, cos) of theta tilted by -2 alpha (R), alpha (TT), 4 alpha (TRT)."""
    s1 = math.sin(alpha)
    c1 = _cos_from_sin(s1)
    s2 = 2.0 * s1 * c1
    c2 = c1 * c1 - s1 * s1
    s4 = 2.0 * s2 * c2
    c4 = c2 * c2 - s2 * s2
    return (sin_o * c2 - cos_o * s2, abs(cos_o * c2 + sin_o * s2),
            sin_o * c1 + cos_o * s1, abs(cos_o * c1 - sin_o * s1),
            sin_o * c4 + cos_o * s4, abs(cos_o * c4 - sin_o * s4))


@kernel(allocates=False)
def _frame(tx, ty, tz, wox, woy, woz):
    """Y = X x wo and Z = X x Y, normalised (ok False where wo lies along X)."""
    yx = ty * woz - tz * woy
    yy = tz * wox - tx * woz
    yz = tx * woy - ty * wox
    ln = math.sqrt(yx * yx + yy * yy + yz * yz)
    if not ln > 1e-12:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, False
    yx, yy, yz = yx / ln, yy / ln, yz / ln
    zx = ty * yz - tz * yy
    zy = tz * yx - tx * yz
    zz = tx * yy - ty * yx
    ln = math.sqrt(zx * zx + zy * zy + zz * zz)
    return yx, yy, yz, zx / ln, zy / ln, zz / ln, True


@kernel(allocates=False)
def _transmittance(x):
    """exp(-x), 0 for an infinite or undefined optical depth (a black fibre)."""
    return math.exp(-x) if x < 700.0 else 0.0


@kernel(allocates=False)
def _lobes(sin_o, cos_o, h, sr, sg, sb, eta):
    """The view's quantities: gamma_o, gamma_t and the four lobes' attenuation A (rgb)
    and luminance shares E."""
    sin_t = sin_o / eta
    cos_t = _cos_from_sin(sin_t)
    cos_go = _cos_from_sin(h)
    gamma_o = math.asin(min(max(h, -1.0), 1.0))
    sin_gt = h * cos_o / math.sqrt(max(eta * eta - sin_o * sin_o, 1e-12))
    sin_gt = min(max(sin_gt, -1.0), 1.0)
    cos_gt = _cos_from_sin(sin_gt)
    gamma_t = math.asin(sin_gt)
    k = 2.0 * cos_gt / cos_t if cos_t > 0.0 else math.inf
    Tr, Tg, Tb = _transmittance(sr * k), _transmittance(sg * k), _transmittance(sb * k)
    f = fresnel.dielectric(cos_o * cos_go, eta)
    a1 = (1.0 - f) * (1.0 - f)
    r1, g1, b1 = a1 * Tr, a1 * Tg, a1 * Tb
    r2, g2, b2 = r1 * Tr * f, g1 * Tg * f, b1 * Tb * f
    r3 = r2 * (Tr * f / (1.0 - Tr * f) if Tr * f < 1.0 else 0.0)
    g3 = g2 * (Tg * f / (1.0 - Tg * f) if Tg * f < 1.0 else 0.0)
    b3 = b2 * (Tb * f / (1.0 - Tb * f) if Tb * f < 1.0 else 0.0)
    e0 = f
    e1 = LUMINANCE_R * r1 + LUMINANCE_G * g1 + LUMINANCE_B * b1
    e2 = LUMINANCE_R * r2 + LUMINANCE_G * g2 + LUMINANCE_B * b2
    e3 = LUMINANCE_R * r3 + LUMINANCE_G * g3 + LUMINANCE_B * b3
    total = e0 + e1 + e2 + e3
    inv = 1.0 / total if total > 0.0 else 0.0
    return (gamma_o, gamma_t, f, r1, g1, b1, r2, g2, b2, r3, g3, b3,
            e0 * inv, e1 * inv, e2 * inv, e3 * inv)


@kernel(allocates=False)
def _sum(sin_i, cos_i, phi, sin_o, cos_o, alpha, v, s, m0, L):
    """F (rgb) and its luminance-share density at light angles (theta_i, phi)."""
    (gamma_o, gamma_t, f, r1, g1, b1, r2, g2, b2, r3, g3, b3, e0, e1, e2, e3) = L
    a = _tilted(sin_o, cos_o, alpha)
    mn0 = longitudinal(sin_i, cos_i, a[0], a[1], m0) * azimuthal(phi, 0, s, gamma_o, gamma_t)
    mn1 = longitudinal(sin_i, cos_i, a[2], a[3], 0.25 * v) * azimuthal(phi, 1, s, gamma_o,
                                                                        gamma_t)
    mn2 = longitudinal(sin_i, cos_i, a[4], a[5], 4.0 * v) * azimuthal(phi, 2, s, gamma_o,
                                                                       gamma_t)
    mn3 = longitudinal(sin_i, cos_i, sin_o, cos_o, 4.0 * v) / TWO_PI
    Fr = f * mn0 + r1 * mn1 + r2 * mn2 + r3 * mn3
    Fg = f * mn0 + g1 * mn1 + g2 * mn2 + g3 * mn3
    Fb = f * mn0 + b1 * mn1 + b2 * mn2 + b3 * mn3
    return Fr, Fg, Fb, e0 * mn0 + e1 * mn1 + e2 * mn2 + e3 * mn3


@kernel(allocates=False)
def evaluate(tx, ty, tz, h, sr, sg, sb, v, s, m0, alpha, eta, wox, woy, woz, wix, wiy,
             wiz):
    """(F_r, F_g, F_b, pdf) for view wo and light wi (unit vectors, X = t unit): F is
    f |cos theta_i| per unit closure weight, as Cycles' eval returns it."""
    yx, yy, yz, zx, zy, zz, ok = _frame(tx, ty, tz, wox, woy, woz)
    if not ok:
        return 0.0, 0.0, 0.0, 0.0
    sin_o = min(max(tx * wox + ty * woy + tz * woz, -1.0), 1.0)
    cos_o = _cos_from_sin(sin_o)
    phi_o = math.atan2(zx * wox + zy * woy + zz * woz, yx * wox + yy * woy + yz * woz)
    sin_i = min(max(tx * wix + ty * wiy + tz * wiz, -1.0), 1.0)
    cos_i = _cos_from_sin(sin_i)
    phi_i = math.atan2(zx * wix + zy * wiy + zz * wiz, yx * wix + yy * wiy + yz * wiz)
    L = _lobes(sin_o, cos_o, h, sr, sg, sb, eta)
    return _sum(sin_i, cos_i, phi_i - phi_o, sin_o, cos_o, -alpha, v, s, m0, L)


@kernel(allocates=False)
def transmits_to(tx, ty, tz, wox, woy, woz, wix, wiy, wiz):
    """Whether Cycles labels light from wi transmission: Y . wi < 0."""
    yx, yy, yz, _, _, _, ok = _frame(tx, ty, tz, wox, woy, woz)
    return ok and yx * wix + yy * wiy + yz * wiz < 0.0


@kernel(allocates=False)
def sample(tx, ty, tz, h, sr, sg, sb, v, s, m0, alpha, eta, wox, woy, woz, u_p, u_phi,
           u_ring):
    """A light direction for view wo: (wix, wiy, wiz, F_r, F_g, F_b, pdf, p), p the lobe
    drawn (0 = R: a reflection; 1..3: through the fibre, a transmission); pdf 0 where
    no direction (wo along the fibre)."""
    yx, yy, yz, zx, zy, zz, ok = _frame(tx, ty, tz, wox, woy, woz)
    if not ok:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0
    sin_o = min(max(tx * wox + ty * woy + tz * woz, -1.0), 1.0)
    cos_o = _cos_from_sin(sin_o)
    phi_o = math.atan2(zx * wox + zy * woy + zz * woz, yx * wox + yy * woy + yz * woz)
    L = _lobes(sin_o, cos_o, h, sr, sg, sb, eta)
    gamma_o, gamma_t = L[0], L[1]
    e0, e1, e2 = L[12], L[13], L[14]
    z = u_p
    p = 3
    if z < e0:
        p = 0
    elif z - e0 < e1:
        p, z = 1, z - e0
    elif z - e0 - e1 < e2:
        p, z = 2, z - e0 - e1
    else:
        z = z - e0 - e1 - e2
    e = L[12 + p]
    z = z / e if e > 0.0 else 0.0
    vp = m0
    if p == 1:
        vp = 0.25 * v
    elif p >= 2:
        vp = 4.0 * v
    a = _tilted(sin_o, cos_o, -alpha)
    st, ct = sin_o, cos_o
    if p < 3:
        st, ct = a[2 * p], a[2 * p + 1]
    z = min(max(z, 1e-5), 1.0)
    fac = 1.0 + vp * math.log(z + (1.0 - z) * math.exp(-2.0 / vp))
    sin_i = -fac * st + _cos_from_sin(fac) * math.cos(TWO_PI * u_ring) * ct
    sin_i = min(max(sin_i, -1.0), 1.0)
    cos_i = _cos_from_sin(sin_i)
    if p < 3:
        cdf = _logistic_cdf(-math.pi, s)
        x = -s * math.log(1.0 / (u_phi * (1.0 - 2.0 * cdf) + cdf) - 1.0)
        phi = 2.0 * p * gamma_t - 2.0 * gamma_o + p * math.pi + min(max(x, -math.pi),
                                                                    math.pi)
    else:
        phi = TWO_PI * u_phi
    phi_i = phi_o + phi
    Fr, Fg, Fb, pdf = _sum(sin_i, cos_i, phi, sin_o, cos_o, -alpha, v, s, m0, L)
    c, sn = cos_i * math.cos(phi_i), cos_i * math.sin(phi_i)
    wix = c * yx + sn * zx + sin_i * tx
    wiy = c * yy + sn * zy + sin_i * ty
    wiz = c * yz + sn * zz + sin_i * tz
    return wix, wiy, wiz, Fr, Fg, Fb, pdf, p


@kernel(allocates=False)
def albedo(tx, ty, tz, h, sr, sg, sb, v, eta, wox, woy, woz):
    """Cycles' albedo estimate of the closure (the Color passes' value, per channel):
    exp(-sqrt(sigma) scale(v)) + F at the view."""
    sin_o = min(max(tx * wox + ty * woy + tz * woz, -1.0), 1.0)
    f = fresnel.dielectric(_cos_from_sin(sin_o) * _cos_from_sin(h), eta)
    k = albedo_roughness_scale(v)
    return (math.exp(-math.sqrt(max(sr, 0.0)) * k) + f,
            math.exp(-math.sqrt(max(sg, 0.0)) * k) + f,
            math.exp(-math.sqrt(max(sb, 0.0)) * k) + f)
