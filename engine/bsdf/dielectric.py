"""Dielectric interfaces (glass, water): smooth (Fresnel-weighted delta reflection and
refraction) and rough (GGX microfacet reflection + transmission).

Sources: Fresnel from `fresnel.dielectric_full` (exact, unpolarised). Rough transmission
is Walter, Marschner, Li & Torrance 2007, "Microfacet Models for Refraction through
Rough Surfaces" (EGSR), eqs. 16, 17, 20-21 (generalised half vector, transmission BTDF and
its Jacobian), with GGX D and height-correlated Smith G2 from `microfacet` (Heitz 2014)
and visible-normal sampling (Heitz 2018): a normal h ~ D_wo, then reflection with
probability F(wo.h) or refraction with 1 - F(wo.h). Sampled reflection weighs
F G2/G1 / P(reflect), refraction (1 - F) G2/G1 / eta^2 / P(refract).

Sides: `eta` is the material IOR relative to the outside (interior over exterior, as
Blender's IOR). wo_z > 0: wo is outside, light refracts into a medium of relative index
eta; wo_z < 0: wo is inside and the relative index is 1/eta. Internally both directions
are mirrored through the tangent plane so that wo_z > 0 ("canonical"), and the results
mirrored back. Total internal reflection (eta_rel < 1 past the critical angle) reflects
everything.

Radiance scaling (a choice, documented): the BSDF transports *radiance*, so refraction
carries the factor 1/eta_rel^2 with eta_rel = n(wi side) / n(wo side) (Veach 1997,
sec. 5.2; pbrt's TransportMode::Radiance). A camera path entering glass is weighted by
(1 - F)/eta^2, leaving it by (1 - F) eta^2, so the factors cancel for closed objects seen
from outside (Cycles, which leaves them out, renders the same image then); they matter
only when a light or the camera is inside a medium. Consequences: the BSDF obeys the
generalised reciprocity f(wo, wi) / n(wo)^2 = f(wi, wo) / n(wi)^2, and its directional
albedo from the optically denser side may exceed 1 (radiance is concentrated by
refraction); the flux-conserving quantity is the albedo with the 1/eta_rel^2 removed,
which is <= 1.

Pairs the sampler never produces (a choice, to match Cycles): Cycles evaluates the
refraction lobe at every pair of directions on opposite sides from the generalised half
vector h ~ wo + eta_rel wi alone, with |wo.h|, |wi.h| and F(|wo.h|), without checking that
h is a microfacet normal that refracts one into the other (wo.h > 0 > wi.h; Walter's
condition; Cycles' own TODO in bsdf_microfacet_eval). Visible-normal sampling never
produces those pairs, so only next-event estimation sees them, with their MIS weight:
a rough glass lit through by a lamp gains light (the rough glass sphere of
docs/comparisons.md: +0.7% of its image at roughness 0.67). `rough_eval` and `rough_pdf`
follow Cycles by default (`as_cycles=True`, or one flag per row); with False they are Walter's
BTDF and the sampler's own density (what the chi-square tests check), which agree with
the default on every pair the sampler produces.

Units: f in 1/sr, pdf in 1/sr (inf for the delta choices of the smooth interface),
sample weights dimensionless. Directions are unit (n, 3) float64, local frame
(normal = +Z), pointing away from the surface; wi_z < 0 for refraction when wo_z > 0.
"""
from __future__ import annotations

import numpy as np

from . import fresnel, microfacet as mf

# Below this GGX alpha a rough interface is treated as smooth (alpha_x alpha_y <= 1e-7,
# about Cycles' threshold for a sharp glass: roughness <= 0.018).
SMOOTH_ALPHA = 10.0 ** -3.5
# |eta - 1| below this: no interface (straight-through refraction, F = 0), always smooth.
INDEX_MATCHED = 1e-6


def is_smooth(alpha, eta) -> np.ndarray:
    """Whether (alpha, eta) is handled by the smooth (delta) model."""
    return (np.asarray(alpha) <= SMOOTH_ALPHA) | (np.abs(np.asarray(eta) - 1.0) < INDEX_MATCHED)


def _canonical(wo, eta):
    flip = wo[:, 2] < 0
    sign = np.where(flip, -1.0, 1.0)
    wo_c = wo * np.stack([np.ones_like(sign), np.ones_like(sign), sign], -1)
    eta = np.broadcast_to(np.asarray(eta, dtype=np.float64), flip.shape)
    return wo_c, np.where(flip, 1.0 / eta, eta), sign


def _zflip(w, sign):
    return w * np.stack([np.ones_like(sign), np.ones_like(sign), sign], -1)


def _choice_probs(F, allow_reflect, allow_refract):
    ar = np.broadcast_to(np.asarray(allow_reflect, dtype=bool), F.shape)
    at = np.broadcast_to(np.asarray(allow_refract, dtype=bool), F.shape)
    both = ar & at
    pr = np.where(both, F, np.where(ar, 1.0, 0.0))
    pt = np.where(both, 1.0 - F, np.where(at, 1.0, 0.0))
    return pr, pt


# --- smooth interface ------------------------------------------------------------------

def smooth_sample(wo, eta, u, allow_reflect=True, allow_refract=True):
    """Delta reflection or refraction chosen by Fresnel (or forced by the allow flags).

    u: (n,) in [0, 1). Returns (wi, weight (n,), refracted (n,) bool, valid (n,) bool);
    the pdf of the choice is a delta (report pdf = inf, delta = True).
    """
    wo_c, eta_rel, sign = _canonical(wo, eta)
    F, cos_t, eta_t = fresnel.dielectric_full(wo_c[:, 2], eta_rel)
    pr, pt = _choice_probs(F, allow_reflect, allow_refract)
    refr = u >= pr
    wi_r = np.stack([-wo_c[:, 0], -wo_c[:, 1], wo_c[:, 2]], -1)
    wi_t = np.stack([-wo_c[:, 0] / eta_t, -wo_c[:, 1] / eta_t, -cos_t], -1)
    wi_c = np.where(refr[:, None], wi_t, wi_r)
    p = np.where(refr, pt, pr)
    ok = (p > 0) & (wo_c[:, 2] > 0) & np.where(refr, F < 1.0, True)
    w = np.where(refr, (1.0 - F) / (eta_t * eta_t), F) / np.where(ok, p, 1.0)
    return _zflip(wi_c, sign), np.where(ok, w, 0.0), refr, ok


# --- rough interface -------------------------------------------------------------------

def _refraction_half(wo_c, wi_c, eta_rel, as_cycles=False):
    """Generalised half vector h ~ wo + eta wi (Walter eq. 16), facing +Z, |wo.h|,
    -|wi.h|, |wo + eta wi|^2 and validity: Walter's (wo.h > 0 > wi.h), or where
    `as_cycles` (a bool, or one per row) any h, as Cycles evaluates it."""
    h = wo_c + eta_rel[:, None] * wi_c
    n = np.sqrt((h * h).sum(1))
    ok = n > 1e-12
    h = h / np.where(ok, n, 1.0)[:, None]
    h = np.where((h[:, 2] < 0)[:, None], -h, h)
    cos_oh = (wo_c * h).sum(1)
    cos_ih = (wi_c * h).sum(1)
    den = (cos_oh + eta_rel * cos_ih) ** 2
    ok &= np.asarray(as_cycles, bool) | ((cos_oh > 0) & (cos_ih < 0))
    ok &= h[:, 2] > 0
    return h, np.abs(cos_oh), -np.abs(cos_ih), den, ok


def rough_eval(wo, wi, eta, alpha, as_cycles=True):
    """(f_reflect, f_refract), each (n,) in 1/sr; one of them is zero for each pair
    (`as_cycles`: see the module's note on pairs the sampler never produces).

    f_reflect = F D G2 / (4 |wo_z wi_z|); f_refract (Walter eq. 21 times 1/eta_rel^2):
    (1 - F) D G2 |wi.h| |wo.h| / (|wo_z wi_z| (wo.h + eta_rel wi.h)^2).
    """
    a = mf.clamp_alpha(alpha)
    wo_c, eta_rel, sign = _canonical(wo, eta)
    wi_c = _zflip(wi, sign)
    upper = wi_c[:, 2] > 0
    # reflection
    base_r, h_r = mf.reflection_eval(wo_c, wi_c, a)
    F_r = fresnel.dielectric(np.maximum((wo_c * h_r).sum(1), 0.0), eta_rel)
    f_r = np.where(upper, F_r * base_r, 0.0)
    # refraction
    h, cos_oh, cos_ih, den, ok = _refraction_half(wo_c, wi_c, eta_rel, as_cycles)
    ok &= (wo_c[:, 2] > 0) & (wi_c[:, 2] < 0)
    F_t = fresnel.dielectric(np.where(ok, cos_oh, 1.0), eta_rel)
    a2 = a * a
    zo, zi = wo_c[:, 2], -wi_c[:, 2]
    g_den = zi * mf._r(wo_c, a2) + zo * mf._r(wi_c, a2)     # G2 / (zo zi) = 2 / g_den
    ok &= (g_den > 0) & (den > 0)
    val = (2.0 * mf.D(h, a) * (1.0 - F_t) * (-cos_ih) * cos_oh
           / np.where(ok, g_den * den, 1.0))
    f_t = np.where(ok, val, 0.0)
    return f_r, f_t


def rough_pdf(wo, wi, eta, alpha, allow_reflect=True, allow_refract=True, as_cycles=True):
    """pdf over wi (1/sr) of `rough_sample` with the same allow flags; with `as_cycles`
    also on the pairs it never produces, as Cycles' MIS weights see them (module note).""" 
    a = mf.clamp_alpha(alpha)
    wo_c, eta_rel, sign = _canonical(wo, eta)
    wi_c = _zflip(wi, sign)
    upper = wi_c[:, 2] > 0
    g1c = mf.G1_over_cos(wo_c, a)
    # reflection: P(reflect | h) D_wo(h) / (4 wo.h)
    h_r, ok_r = mf.half_vector(wo_c, wi_c)
    ok_r &= upper & (wo_c[:, 2] > 0)
    F_r = fresnel.dielectric(np.maximum((wo_c * h_r).sum(1), 0.0), eta_rel)
    pr, _ = _choice_probs(F_r, allow_reflect, allow_refract)
    pdf_r = np.where(ok_r, pr * 0.25 * g1c * mf.D(h_r, a), 0.0)
    # refraction: P(refract | h) D_wo(h) |dh/dwi|, dh/dwi = eta^2 |wi.h| / (wo.h + eta wi.h)^2
    h, cos_oh, cos_ih, den, ok = _refraction_half(wo_c, wi_c, eta_rel, as_cycles)
    ok &= (wo_c[:, 2] > 0) & ~upper
    F_t = fresnel.dielectric(np.where(ok, cos_oh, 1.0), eta_rel)
    _, pt = _choice_probs(F_t, allow_reflect, allow_refract)
    ok &= den > 0
    jac = eta_rel * eta_rel * (-cos_ih) / np.where(ok, den, 1.0)
    pdf_t = np.where(ok, pt * g1c * cos_oh * mf.D(h, a) * jac, 0.0)
    return np.where(upper, pdf_r, pdf_t)


def rough_sample(wo, eta, alpha, u_choice, u, allow_reflect=True, allow_refract=True):
    """Sample the rough interface. u_choice: (n,) picks reflection/refraction, u: (n, 2)
    the visible normal. Returns (wi, weight (n,), refracted, valid, pdf)."""
    a = mf.clamp_alpha(alpha)
    wo_c, eta_rel, sign = _canonical(wo, eta)
    h = mf.sample_visible_normal(wo_c, a, u)
    cos_oh = (wo_c * h).sum(1)
    F, cos_t, eta_t = fresnel.dielectric_full(np.maximum(cos_oh, 0.0), eta_rel)
    pr, pt = _choice_probs(F, allow_reflect, allow_refract)
    refr = u_choice >= pr
    wi_r = mf.reflect(wo_c, h)
    wi_t = -wo_c / eta_t[:, None] + (cos_oh / eta_t - cos_t)[:, None] * h
    wi_c = np.where(refr[:, None], wi_t, wi_r)
    # renormalise against rounding (the refraction formula is unit only up to ulps)
    wi_c = wi_c / np.maximum(np.sqrt((wi_c * wi_c).sum(1)), 1e-300)[:, None]
    p = np.where(refr, pt, pr)
    ok = ((p > 0) & (wo_c[:, 2] > 0) & (cos_oh > 0) & (h[:, 2] > 0)
          & np.where(refr, (F < 1.0) & (wi_c[:, 2] < 0), wi_c[:, 2] > 0))
    g = mf.G2_over_G1(wo_c, wi_c, a)
    w = np.where(refr, (1.0 - F) * g / (eta_t * eta_t), F * g) / np.where(ok, p, 1.0)
    # pdf of the choice made
    g1c = mf.G1_over_cos(wo_c, a)
    d = mf.D(h, a)
    cos_ih = (wi_c * h).sum(1)
    den = (cos_oh + eta_t * cos_ih) ** 2
    ok &= np.where(refr, den > 0, True)
    pdf_r = 0.25 * g1c * d
    pdf_t = g1c * cos_oh * d * eta_t * eta_t * np.abs(cos_ih) / np.where(den > 0, den, 1.0)
    pdf = p * np.where(refr, pdf_t, pdf_r)
    ok &= pdf > 0
    return (_zflip(wi_c, sign), np.where(ok, w, 0.0), refr, ok, np.where(ok, pdf, 0.0))
