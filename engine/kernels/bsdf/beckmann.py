"""The Beckmann microfacet distribution, scalar: D, Smith masking and visible-normal
sampling, for the nodes that offer it (Glossy, Glass and Refraction BSDF; Blender's
default for the Refraction BSDF). The GGX twin of each function is in microfacet.py;
distribution.py picks one of the two per closure.

Formulas (alpha = roughness^2, isotropic, clamped as GGX's; directions in the local
frame, normal = +Z):
  * D(h) = exp(-tan^2 t / alpha^2) / (pi alpha^2 cos^4 t) (Beckmann 1963; Walter et al.
    2007 eq. 25), written as exp(-s^2 / (alpha^2 z^2)) / (pi alpha^2 z^4) with
    s^2 = h_x^2 + h_y^2, z = h_z: no tangent, zero for z <= 0.
  * Smith Lambda of a direction with a = cot t / alpha (Walter eq. 27 integrated; Heitz
    2014 eq. 69): Lambda = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)). It is the
    masking of the sampler below, so the pdf uses it exactly.
  * The value of the BSDF uses the rational approximation of Lambda Cycles evaluates
    (Walter et al. 2007, below eq. 27: 0 for a >= 1.6, else
    (1 - 1.259 a + 0.396 a^2) / (3.535 a + 2.181 a^2)), so that DRT renders what Cycles
    renders; it is within 0.32% of the exact G1 = 1 / (1 + Lambda) at every angle
    (tests/test_beckmann.py measures it). Estimators stay unbiased for that value: the
    weight is f / pdf with the exact pdf of the sampler.
  * Both Lambdas are carried as |z| Lambda, which stays finite at grazing angles
    (|z| Lambda -> alpha s / (2 sqrt(pi)) exactly, alpha s / 3.535 approximated), so
    G1 / |z| = 1 / (|z| + |z| Lambda) and G2 / (|zo| |zi|) = 1 / (|zo| |zi| + |zi| |zo|
    Lambda_o + |zo| |zi| Lambda_i) never divide by zero.
  * Visible normals (Heitz & d'Eon 2014, "Importance Sampling Microfacet-Based BSDFs
    using the Distribution of Visible Normals"): stretch wo to alpha = 1, sample the
    visible slope (x, y): y is Gaussian (x and y are independent for Beckmann), and x
    has the density (cot t - x) exp(-x^2) on x < cot t; its CDF in b = erf(x) is
    (1 + b + K exp(-erfinv(b)^2)) / (1 + erf(cot t) + K exp(-cot^2 t)), K = tan t /
    sqrt(pi) (Jakob 2014, "An Improved Visible Normal Sampling Routine for the Beckmann
    Distribution"), inverted here by safeguarded Newton steps to double precision; then
    rotate to wo's azimuth, unstretch, and turn the slope into a normal.
"""
from __future__ import annotations

import math

from ..jit import kernel
from .microfacet import clamp_alpha     # the same clamp as GGX's

INV_PI = 1.0 / math.pi
SQRT_PI = math.sqrt(math.pi)
INV_SQRT_PI = 1.0 / SQRT_PI
TWO_PI = 2.0 * math.pi
ONE_MINUS_EPS = 1.0 - 2.0 ** -53


@kernel
def erfinv(y):
    """Inverse error function in double precision, for y in (-1, 1) (clamped inside):
    Winitzki's closed form (about 2e-3 relative) polished by Halley steps on
    erf(x) - y, written with erfc in the tails so they keep their digits."""
    y = min(max(y, -ONE_MINUS_EPS), ONE_MINUS_EPS)
    if y == 0.0:
        return 0.0
    w = math.log((1.0 - y) * (1.0 + y))
    c = 2.0 / (math.pi * 0.147) + 0.5 * w
    x = math.sqrt(max(math.sqrt(c * c - w / 0.147) - c, 0.0))
    if y < 0.0:
        x = -x
    for _ in range(4):
        # f = erf(x) - y, accurate where erf(x) is near +-1
        if y < -0.5:
            f = math.erfc(-x) - (1.0 + y)
        elif y > 0.5:
            f = (1.0 - y) - math.erfc(x)
        else:
            f = math.erf(x) - y
        fp = 2.0 * INV_SQRT_PI * math.exp(-x * x)
        if not fp > 0.0:
            break
        dx = f / fp
        x = x - dx / (1.0 + x * dx)
        if abs(dx) <= 1e-15 * max(abs(x), 1.0):
            break
    return x


@kernel
def D(hx, hy, hz, alpha):
    """Beckmann normal distribution (1/sr) of the unit half vector h; zero for h_z <= 0."""
    if not hz > 0.0:
        return 0.0
    a = clamp_alpha(alpha)
    a2 = a * a
    z2 = hz * hz
    s2 = hx * hx + hy * hy
    return math.exp(-s2 / (a2 * z2)) * INV_PI / (a2 * z2 * z2)


@kernel
def slope_terms(x, y, z, alpha):
    """(alpha s, cot t / alpha) of direction w, s = |w_xy| (alpha s = 0: w is the
    normal, where Lambda = 0)."""
    a = clamp_alpha(alpha)
    a_s = a * math.sqrt(x * x + y * y)
    return a_s, (abs(z) / a_s if a_s > 0.0 else math.inf)


@kernel
def z_lambda(x, y, z, alpha):
    """|z| Lambda(w), Smith's exact Lambda for Beckmann (finite at z = 0)."""
    a_s, c = slope_terms(x, y, z, alpha)
    if not a_s > 0.0:
        return 0.0
    # |z| ((erf(c) - 1) / 2 + exp(-c^2) / (2 c sqrt(pi))), with |z| / c = alpha s
    return 0.5 * (a_s * math.exp(-c * c) * INV_SQRT_PI - abs(z) * math.erfc(c))


@kernel
def z_lambda_cycles(x, y, z, alpha):
    """|z| Lambda(w) of the rational approximation Cycles evaluates (module docstring)."""
    a_s, c = slope_terms(x, y, z, alpha)
    if not (a_s > 0.0 and c < 1.6):
        return 0.0
    # |z| (1 - 1.259 c + 0.396 c^2) / (c (3.535 + 2.181 c)), with |z| / c = alpha s
    return a_s * ((0.396 * c - 1.259) * c + 1.0) / (2.181 * c + 3.535)


@kernel
def G1_over_cos(x, y, z, alpha):
    """G1(w) / |w_z| = 1 / (|w_z| (1 + Lambda)), exact: the sampler's masking."""
    return 1.0 / max(abs(z) + z_lambda(x, y, z, alpha), 1e-300)


@kernel
def G2_over_cos2(ox, oy, oz, ix, iy, iz, alpha):
    """G2(wo, wi) / (|wo_z| |wi_z|), height-correlated, with Cycles' Lambda."""
    zo = abs(oz)
    zi = abs(iz)
    den = (zo * zi + zi * z_lambda_cycles(ox, oy, oz, alpha)
           + zo * z_lambda_cycles(ix, iy, iz, alpha))
    if not den > 0.0:
        return 0.0
    return 1.0 / den


@kernel
def sample_slope_x(cot_t, tan_t, u):
    """The stretched visible slope along wo's azimuth: x < cot_t with density
    proportional to (cot_t - x) exp(-x^2), inverted from u in [0, 1)."""
    k = tan_t * INV_SQRT_PI
    erf_c = math.erf(cot_t)
    total = 1.0 + erf_c + k * math.exp(-cot_t * cot_t)
    target = u * total
    # first guess from exp(-erfinv(b)^2) ~ 1 - b^2: k b^2 - b + (target - 1 - k) = 0
    if k > 0.0:
        b = (1.0 - math.sqrt(max(1.0 + 4.0 * k * (1.0 + k - target), 0.0))) / (2.0 * k)
    else:
        b = target - 1.0
    lo = -1.0
    hi = erf_c
    b = min(max(b, lo), hi)
    x = erfinv(b)
    tol = 1e-13 * total                                  # on the CDF, relative
    for _ in range(40):
        g = 1.0 + b + k * math.exp(-x * x) - target     # increasing in b
        if abs(g) <= tol:
            break
        if g > 0.0:
            hi = b
        else:
            lo = b
        slope = 1.0 - x * tan_t                          # dg/db >= 0
        nb = b - g / slope if slope > 0.0 else lo - 1.0
        if not (nb > lo and nb < hi):
            nb = 0.5 * (lo + hi)                         # Newton left the bracket
        if abs(nb - b) <= 1e-15 * max(abs(b), 1e-3):
            b = nb
            x = erfinv(b)
            break
        b = nb
        x = erfinv(b)
    return min(x, cot_t)


@kernel
def sample_visible_normal(ox, oy, oz, alpha, u0, u1):
    """A microfacet normal h ~ D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo_z, wo_z >= 0."""
    a = clamp_alpha(alpha)
    # stretch wo to the configuration with alpha = 1
    vx = a * ox
    vy = a * oy
    vz = max(oz, 0.0)
    n = math.sqrt(vx * vx + vy * vy + vz * vz)
    if not n > 0.0:
        vx, vy, vz, n = 0.0, 0.0, 1.0, 1.0
    vx, vy, vz = vx / n, vy / n, vz / n
    s = math.sqrt(vx * vx + vy * vy)
    if s <= 1e-7 * vz:
        # normal incidence: both slopes Gaussian (variance 1/2), by Box-Muller's radius
        r = math.sqrt(-math.log(1.0 - u0))
        phi = TWO_PI * u1
        sx = r * math.cos(phi)
        sy = r * math.sin(phi)
    else:
        cphi = vx / s
        sphi = vy / s
        x = sample_slope_x(vz / s, min(s / max(vz, 1e-300), 1e150), u0)
        y = erfinv(2.0 * u1 - 1.0)
        # rotate to wo's azimuth
        sx = cphi * x - sphi * y
        sy = sphi * x + cphi * y
    # unstretch; the slope (sx, sy) is the normal (-sx, -sy, 1), normalised
    hx = -a * sx
    hy = -a * sy
    m = math.sqrt(hx * hx + hy * hy + 1.0)
    return hx / m, hy / m, 1.0 / m


@kernel
def reflection_eval(ox, oy, oz, ix, iy, iz, hx, hy, hz, alpha):
    """D G2 / (4 wo_z wi_z) of the upper-hemisphere reflection about the unit half vector
    h (zero unless wo_z, wi_z > 0). Multiply by a Fresnel term for the BRDF."""
    if not (oz > 0.0 and iz > 0.0):
        return 0.0
    return 0.25 * D(hx, hy, hz, alpha) * G2_over_cos2(ox, oy, oz, ix, iy, iz, alpha)


@kernel
def reflection_pdf(ox, oy, oz, hx, hy, hz, alpha):
    """pdf over wi (1/sr) of VNDF-sampled reflection with half vector h: G1(wo) D / (4
    wo_z)."""
    return 0.25 * G1_over_cos(ox, oy, oz, alpha) * D(hx, hy, hz, alpha)
