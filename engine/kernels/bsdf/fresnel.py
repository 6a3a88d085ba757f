"""Fresnel reflectance: exact unpolarised dielectric, and Schlick's approximation.

Dielectric: the Fresnel equations for an unpolarised wave at a smooth interface between
two non-absorbing media (Born & Wolf, *Principles of Optics*, sec. 1.5; written as in
Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces", eq. 22),
as the mean of the s- and p-polarised power reflectances. Dimensionless, in [0, 1].

Conventions: `eta` is the relative index n_t / n_i of the medium on the far side of the
interface over the medium the light arrives in, for `cos_i > 0`. A negative `cos_i` means
the wave arrives from the other side: the ratio is inverted and |cos_i| used, so both
sides of one interface are described by one `eta` (for a material with IOR `ior` seen
from outside: `eta = ior`; from inside, pass a negative cosine or `eta = 1 / ior`).
eta < 1 is allowed and gives total internal reflection (F = 1) past the critical angle.

Conductors: Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering",
F = F0 + (1 - F0) (1 - cos)^5 with a per-channel F0 (Blender's metallic base colour).

One cosine at a time, float64.
"""
from __future__ import annotations

import math

from ..jit import kernel


@kernel
def dielectric_full(cos_i, eta):
    """(F, cos_t, eta_rel) of the exact unpolarised dielectric Fresnel equations:
    reflectance in [0, 1], |cos| of the refracted direction (0 under total internal
    reflection) and the relative IOR used (1/eta when cos_i < 0)."""
    eta_rel = 1.0 / eta if cos_i < 0.0 else eta
    ci = min(abs(cos_i), 1.0)
    sin2_t = (1.0 - ci * ci) / (eta_rel * eta_rel)
    if sin2_t >= 1.0:
        return 1.0, 0.0, eta_rel
    ct = math.sqrt(max(0.0, 1.0 - sin2_t))
    den_s = ci + eta_rel * ct
    den_p = eta_rel * ci + ct
    if not (den_s > 0.0 and den_p > 0.0):
        return 1.0, ct, eta_rel
    rs = (ci - eta_rel * ct) / den_s
    rp = (eta_rel * ci - ct) / den_p
    F = 0.5 * (rs * rs + rp * rp)
    return min(max(F, 0.0), 1.0), ct, eta_rel


@kernel
def dielectric(cos_i, eta):
    """Exact unpolarised dielectric reflectance (see `dielectric_full`)."""
    return dielectric_full(cos_i, eta)[0]


@kernel
def schlick(f0, cos_theta):
    """Schlick's approximation for one channel, cos clamped to [0, 1]."""
    c = min(max(cos_theta, 0.0), 1.0)
    m = 1.0 - c
    m2 = m * m
    m5 = m2 * m2 * m
    return f0 + (1.0 - f0) * m5


@kernel
def f0_from_ior(ior):
    """Normal-incidence reflectance ((ior - 1) / (ior + 1))^2."""
    r = (ior - 1.0) / (ior + 1.0)
    return r * r


@kernel
def ior_from_f0(f0):
    """The IOR >= 1 with normal-incidence reflectance f0 (f0 clamped to [0, 0.9999])."""
    s = math.sqrt(min(max(f0, 0.0), 0.9999))
    return (1.0 + s) / (1.0 - s)


@kernel
def f82_tint_b(f0, tint):
    """F82-tint's b of one channel: Schlick's value at mu = 1/7 times (1 - tint), over
    mu (1 - mu)^6 there (Cycles' fresnel_f82tint_B)."""
    f = 6.0 / 7.0
    f5 = f * f * f * f * f
    schlick_82 = f0 + (1.0 - f0) * f5
    return schlick_82 * (7.0 / (f5 * f)) * (1.0 - tint)


@kernel
def f82_tint(f0, b, cos_theta):
    """F82-tint Fresnel of one channel: Schlick's minus b mu (1 - mu)^6, in [0, 1]."""
    s = min(max(1.0 - cos_theta, 0.0), 1.0)
    s5 = s * s * s * s * s
    return min(max(f0 + (1.0 - f0) * s5 - b * cos_theta * s5 * s, 0.0), 1.0)
