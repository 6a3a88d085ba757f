"""The GGX (Trowbridge-Reitz) microfacet distribution, Smith masking, and sampling of
visible normals; plus the GGX reflection lobe built from them.

Sources:
  * D: Trowbridge & Reitz 1975; Walter et al. 2007, "Microfacet Models for Refraction
    through Rough Surfaces", eq. 33:  D(h) = 1 / (pi a^2 cos^4 t (1 + tan^2 t / a^2)^2),
    written here as 1 / (pi a^2 (h_z^2 + (h_x^2 + h_y^2) / a^2)^2), which has no tangent
    and stays finite for every unit h. Units: 1/sr (normalised so that
    integral D(h) cos(theta_h) d(omega_h) = 1).
  * Smith G1 (Walter et al. 2007 eq. 34; Heitz 2014, "Understanding the Masking-Shadowing
    Function in Microfacet-Based BRDFs", JCGT 3(2)): G1 = 2 |z| / (|z| + sqrt(z^2 + a^2 s^2))
    with s^2 = x^2 + y^2, the same as 2 / (1 + sqrt(1 + a^2 tan^2 theta)) but defined at
    z = 0 (G1 = 0) and at the normal (G1 = 1).
  * Height-correlated G2 = 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014), here
    2 |zo| |zi| / (|zi| r_o + |zo| r_i) with r = sqrt(z^2 + a^2 s^2).
  * Visible-normal sampling: Heitz 2018, "Sampling the GGX Distribution of Visible
    Normals" (JCGT 7(4)), listing 1; pdf of the sampled normal
    D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo_z.

Directions are unit (n, 3) float64 arrays in the local frame (normal = +Z), pointing away
from the surface. `alpha` is the isotropic GGX roughness per point (Blender/Cycles:
alpha = roughness^2), dimensionless. It is clamped to [ALPHA_MIN, 1] = [1e-4, 1]:
roughness 0 would make D a Dirac delta; at alpha = 1e-4 the lobe is ~0.01 degrees wide
(a mirror to the eye) while every quantity stays an ordinary finite function (peak
D = 1/(pi alpha^2) ~ 3e7 /sr, reflection pdf ~ 8e6 /sr), so the reflection lobes need no
separate delta code path and MIS weights stay meaningful; alpha > 1 is not a Blender
roughness. Every function is finite for wo at the normal, at grazing angles down to
wo_z = 0, and for alpha at either clamp.
"""
from __future__ import annotations

import numpy as np

ALPHA_MIN = 1e-4
INV_PI = 1.0 / np.pi


def clamp_alpha(alpha) -> np.ndarray:
    """GGX alpha clamped to [ALPHA_MIN, 1] (see the module docstring)."""
    return np.clip(np.asarray(alpha, dtype=np.float64), ALPHA_MIN, 1.0)


def _r(w, a2):
    """sqrt(z^2 + a^2 (x^2 + y^2)): |z| (1 + 2 Lambda(w)) of Smith's GGX Lambda."""
    s2 = w[:, 0] * w[:, 0] + w[:, 1] * w[:, 1]
    return np.sqrt(w[:, 2] * w[:, 2] + a2 * s2)


def D(h: np.ndarray, alpha) -> np.ndarray:
    """GGX normal distribution (1/sr) of unit half vectors h (n, 3); zero for h_z <= 0."""
    a = clamp_alpha(alpha)
    a2 = a * a
    s2 = h[:, 0] * h[:, 0] + h[:, 1] * h[:, 1]
    m = s2 / a2 + h[:, 2] * h[:, 2]
    m = np.where(m > 0, m, 1.0)
    return np.where(h[:, 2] > 0, INV_PI / (a2 * m * m), 0.0)


def G1(w: np.ndarray, alpha) -> np.ndarray:
    """Smith masking of direction w for GGX (without the microfacet side test)."""
    a = clamp_alpha(alpha)
    az = np.abs(w[:, 2])
    den = az + _r(w, a * a)
    return np.where(den > 0, 2.0 * az / np.where(den > 0, den, 1.0), 0.0)


def G1_over_cos(w: np.ndarray, alpha) -> np.ndarray:
    """G1(w) / |w_z| = 2 / (|w_z| + r(w)), finite at w_z = 0 (equal to 2 / alpha there)."""
    a = clamp_alpha(alpha)
    den = np.abs(w[:, 2]) + _r(w, a * a)
    return 2.0 / np.maximum(den, 1e-300)


def G2(wo: np.ndarray, wi: np.ndarray, alpha) -> np.ndarray:
    """Height-correlated Smith masking-shadowing (Heitz 2014)."""
    a = clamp_alpha(alpha)
    a2 = a * a
    zo, zi = np.abs(wo[:, 2]), np.abs(wi[:, 2])
    den = zi * _r(wo, a2) + zo * _r(wi, a2)
    return np.where(den > 0, 2.0 * zo * zi / np.where(den > 0, den, 1.0), 0.0)


def G2_over_G1(wo: np.ndarray, wi: np.ndarray, alpha) -> np.ndarray:
    """G2(wo, wi) / G1(wo): the weight of a VNDF-sampled reflection or refraction."""
    a = clamp_alpha(alpha)
    a2 = a * a
    zo, zi = np.abs(wo[:, 2]), np.abs(wi[:, 2])
    ro, ri = _r(wo, a2), _r(wi, a2)
    den = zi * ro + zo * ri
    return np.where(den > 0, zi * (zo + ro) / np.where(den > 0, den, 1.0), 0.0)


def _normalize(v):
    n = np.sqrt((v * v).sum(-1, keepdims=True))
    return v / np.maximum(n, 1e-300)


def sample_visible_normal(wo: np.ndarray, alpha, u: np.ndarray) -> np.ndarray:
    """A microfacet normal h ~ D_wo(h) for wo in the upper hemisphere (Heitz 2018).

    wo: (n, 3) with wo_z >= 0 (callers flip directions from below); u: (n, 2) in [0,1).
    """
    a = clamp_alpha(alpha)
    # stretch wo to the configuration with alpha = 1 (hemisphere)
    vh = _normalize(np.stack([a * wo[:, 0], a * wo[:, 1], np.maximum(wo[:, 2], 0.0)], -1))
    lensq = vh[:, 0] * vh[:, 0] + vh[:, 1] * vh[:, 1]
    inv_len = np.where(lensq > 0, 1.0 / np.sqrt(np.where(lensq > 0, lensq, 1.0)), 0.0)
    t1 = np.where((lensq > 0)[:, None],
                  np.stack([-vh[:, 1] * inv_len, vh[:, 0] * inv_len, np.zeros_like(lensq)], -1),
                  np.array([1.0, 0.0, 0.0]))
    t2 = np.cross(vh, t1)
    # uniform point on the projected disk, warped onto the visible half
    r = np.sqrt(u[:, 0])
    phi = 2.0 * np.pi * u[:, 1]
    p1 = r * np.cos(phi)
    p2 = r * np.sin(phi)
    s = 0.5 * (1.0 + vh[:, 2])
    p2 = (1.0 - s) * np.sqrt(np.maximum(0.0, 1.0 - p1 * p1)) + s * p2
    pz = np.sqrt(np.maximum(0.0, 1.0 - p1 * p1 - p2 * p2))
    nh = p1[:, None] * t1 + p2[:, None] * t2 + pz[:, None] * vh
    # unstretch
    return _normalize(np.stack([a * nh[:, 0], a * nh[:, 1], np.maximum(nh[:, 2], 0.0)], -1))


def visible_normal_pdf(wo: np.ndarray, h: np.ndarray, alpha) -> np.ndarray:
    """pdf (1/sr, over h) of `sample_visible_normal`: G1(wo) max(0, wo.h) D(h) / wo_z."""
    cos_oh = (wo * h).sum(1)
    ok = wo[:, 2] >= 0
    return np.where(ok, G1_over_cos(wo, alpha) * np.maximum(cos_oh, 0.0) * D(h, alpha), 0.0)


# --- the GGX reflection lobe (Fresnel left to the caller) -------------------------------

def reflect(wo: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Mirror wo about the unit normal h."""
    return 2.0 * (wo * h).sum(1, keepdims=True) * h - wo


def half_vector(wo: np.ndarray, wi: np.ndarray):
    """Normalised wo + wi and whether it is defined (wi != -wo)."""
    h = wo + wi
    n = np.sqrt((h * h).sum(1))
    ok = n > 1e-12
    return h / np.where(ok, n, 1.0)[:, None], ok


def reflection_eval(wo: np.ndarray, wi: np.ndarray, alpha):
    """D G2 / (4 |wo_z| |wi_z|) of the upper-hemisphere GGX reflection (1/sr), and h.

    Written as D / (2 (|wi_z| r_o + |wo_z| r_i)) so it stays finite at grazing angles.
    Multiply by a Fresnel term F(wo . h) for the BRDF. Zero unless wo_z, wi_z > 0.
    """
    a = clamp_alpha(alpha)
    a2 = a * a
    h, ok = half_vector(wo, wi)
    ok &= (wo[:, 2] > 0) & (wi[:, 2] > 0)
    den = wi[:, 2] * _r(wo, a2) + wo[:, 2] * _r(wi, a2)
    ok &= den > 0
    val = D(h, a) / (2.0 * np.where(ok, den, 1.0))
    return np.where(ok, val, 0.0), h


def reflection_pdf(wo: np.ndarray, wi: np.ndarray, alpha) -> np.ndarray:
    """pdf over wi (1/sr) of VNDF-sampled reflection: D_wo(h) / (4 wo.h) = G1(wo) D / (4 wo_z)."""
    h, ok = half_vector(wo, wi)
    ok &= (wo[:, 2] > 0) & (wi[:, 2] > 0)
    return np.where(ok, 0.25 * G1_over_cos(wo, alpha) * D(h, alpha), 0.0)


def reflection_sample(wo: np.ndarray, alpha, u: np.ndarray):
    """Sample the GGX reflection from wo (wo_z > 0): returns (wi, h, valid)."""
    h = sample_visible_normal(wo, alpha, u)
    wi = reflect(wo, h)
    valid = (wo[:, 2] > 0) & (wi[:, 2] > 0) & (h[:, 2] > 0) & ((wo * h).sum(1) > 0)
    return wi, h, valid
