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

All functions are vectorised; float64 throughout.
"""
from __future__ import annotations

import numpy as np


def dielectric_full(cos_i, eta):
    """Exact dielectric Fresnel reflectance and the transmitted cosine.

    cos_i: (n,) cosine between the incident direction (pointing away from the surface)
    and the normal, signed as described in the module docstring. eta: (n,) or scalar,
    relative IOR (inside over outside), > 0.

    Returns (F, cos_t, eta_rel): reflectance in [0, 1]; |cos| of the refracted direction
    (0 under total internal reflection); and the relative IOR actually used,
    n_transmitted / n_incident (eta or 1/eta depending on the side).
    """
    cos_i = np.asarray(cos_i, dtype=np.float64)
    eta = np.broadcast_to(np.asarray(eta, dtype=np.float64), cos_i.shape)
    inside = cos_i < 0.0
    eta_rel = np.where(inside, 1.0 / eta, eta)
    ci = np.minimum(np.abs(cos_i), 1.0)
    sin2_t = (1.0 - ci * ci) / (eta_rel * eta_rel)
    tir = sin2_t >= 1.0
    ct = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    # With ci = ct = 0 only under TIR (handled below), the denominators are positive.
    den_s = ci + eta_rel * ct
    den_p = eta_rel * ci + ct
    ok = ~tir & (den_s > 0) & (den_p > 0)
    rs = (ci - eta_rel * ct) / np.where(ok, den_s, 1.0)
    rp = (eta_rel * ci - ct) / np.where(ok, den_p, 1.0)
    F = np.where(ok, 0.5 * (rs * rs + rp * rp), 1.0)
    return np.clip(F, 0.0, 1.0), np.where(tir, 0.0, ct), eta_rel


def dielectric(cos_i, eta):
    """Exact unpolarised dielectric reflectance (see `dielectric_full`)."""
    return dielectric_full(cos_i, eta)[0]


def schlick(f0, cos_theta):
    """Schlick's approximation, per channel: f0 (n, 3) or (n,), cos_theta (n,) -> like f0.

    The cosine is clamped to [0, 1]; (1 - cos)^5 is written as a product of squares.
    """
    f0 = np.asarray(f0, dtype=np.float64)
    c = np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)
    m = 1.0 - c
    m2 = m * m
    m5 = m2 * m2 * m
    if f0.ndim == c.ndim + 1:
        m5 = m5[..., None]
    return f0 + (1.0 - f0) * m5


def f0_from_ior(ior):
    """Normal-incidence reflectance ((ior - 1) / (ior + 1))^2 of a dielectric."""
    ior = np.asarray(ior, dtype=np.float64)
    r = (ior - 1.0) / (ior + 1.0)
    return r * r


def ior_from_f0(f0):
    """The IOR >= 1 whose normal-incidence reflectance is f0 (inverse of f0_from_ior).

    f0 is clamped to [0, 0.9999] so that the result stays finite (IOR <= ~4e4)."""
    s = np.sqrt(np.clip(np.asarray(f0, dtype=np.float64), 0.0, 0.9999))
    return (1.0 + s) / (1.0 - s)
