"""Normalised Blinn-Phong microfacet reflection (the Cook-Torrance era lobe).

Distribution of normals (Blinn 1977, normalised as in Cook & Torrance 1982 / Cook 1984
practice, and Walter et al. 2007 eq. 30):
    D(h) = (n + 2) / (2 pi) cos^n(theta_h)          [1/sr, integral D cos(theta_h) = 1]
BRDF, with the Cook-Torrance V-cavity shadowing-masking (Cook & Torrance 1982, eq. 4)
    G = min(1, 2 (n.h)(n.wo) / (wo.h), 2 (n.h)(n.wi) / (wo.h))
    f(wo, wi) = D(h) G / (4 cos(theta_o) cos(theta_i))            [1/sr]
with no Fresnel factor (multiply by a specular colour or F if wanted). The V-cavity
surface is a real microgeometry, so the lobe conserves energy (directional albedo <= 1)
and is reciprocal (h, G and the denominator are symmetric in wo, wi).

Sampling: the half vector with pdf(h) = (n + 1) / (2 pi) cos^n(theta_h), i.e.
cos(theta_h) = u^(1/(n+1)), then reflection; pdf(wi) = pdf(h) / (4 |wo.h|) (Jacobian of
the reflection map, Walter et al. 2007 eq. 14).

Large exponents (tested up to 1e6): cos^n is evaluated as exp(n/2 log1p(-sin^2)), sampled
cosines come from expm1 so that 1 - cos(theta_h) keeps its precision, and D stays finite
((n + 2) / (2 pi) ~ 1.6e5 at the peak for n = 1e6).

Directions: three floats, unit, in the local frame (normal = +Z), away from the
surface; reflection only (zero unless both are above the surface). `exponent` >= 0.
"""
from __future__ import annotations

import math

from ..jit import kernel
from .microfacet import dot, half_vector

INV_2PI = 0.5 / math.pi
TWO_PI = 2.0 * math.pi


@kernel
def cos_pow(hx, hy, exponent):
    """cos(theta_h)^n for a unit h with h_z > 0, via log1p of sin^2."""
    s2 = min(max(hx * hx + hy * hy, 0.0), 1.0 - 1e-16)
    return math.exp(exponent * 0.5 * math.log1p(-s2))


@kernel
def D(hx, hy, hz, exponent):
    """(n + 2)/(2 pi) cos^n(theta_h); zero for h_z <= 0."""
    if not hz > 0.0:
        return 0.0
    return (exponent + 2.0) * INV_2PI * cos_pow(hx, hy, exponent)


@kernel
def G(ox, oy, oz, ix, iy, iz, hx, hy, hz):
    """Cook-Torrance V-cavity shadowing-masking."""
    c = dot(ox, oy, oz, hx, hy, hz)
    if not c > 0.0:
        return 0.0
    g = min(1.0, min(2.0 * hz * oz / c, 2.0 * hz * iz / c))
    return max(g, 0.0)


@kernel
def eval_f(ox, oy, oz, ix, iy, iz, exponent):
    """BRDF value in 1/sr (no Fresnel factor)."""
    hx, hy, hz, ok = half_vector(ox, oy, oz, ix, iy, iz)
    if not (ok and oz > 0.0 and iz > 0.0):
        return 0.0
    den = 4.0 * oz * iz
    return D(hx, hy, hz, exponent) * G(ox, oy, oz, ix, iy, iz, hx, hy, hz) / den


@kernel
def pdf(ox, oy, oz, ix, iy, iz, exponent):
    """pdf over wi (1/sr) of `sample`."""
    hx, hy, hz, ok = half_vector(ox, oy, oz, ix, iy, iz)
    if not (ok and oz > 0.0 and iz > 0.0):
        return 0.0
    c = dot(ox, oy, oz, hx, hy, hz)
    if not c > 0.0:
        return 0.0
    pdf_h = (exponent + 1.0) * INV_2PI * cos_pow(hx, hy, exponent)
    return pdf_h / (4.0 * c)


@kernel
def sample(ox, oy, oz, u0, u1, exponent):
    """Sample wi from wo: (wi_x, wi_y, wi_z, valid)."""
    log_u = math.log(u0) if u0 > 0.0 else -math.inf   # u = 0: cos = 0, rejected
    k = 2.0 * log_u / (exponent + 1.0)                # log(cos^2)
    cos2 = math.exp(k)
    sin2 = min(max(-math.expm1(k), 0.0), 1.0)
    cos_h = math.sqrt(cos2)
    sin_h = math.sqrt(sin2)
    phi = TWO_PI * u1
    hx = sin_h * math.cos(phi)
    hy = sin_h * math.sin(phi)
    hz = cos_h
    c = dot(ox, oy, oz, hx, hy, hz)
    c2 = 2.0 * c
    ix = c2 * hx - ox
    iy = c2 * hy - oy
    iz = c2 * hz - oz
    valid = oz > 0.0 and iz > 0.0 and c > 0.0 and cos_h > 0.0
    return ix, iy, iz, valid
