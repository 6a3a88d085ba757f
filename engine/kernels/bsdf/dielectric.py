"""Dielectric interfaces (glass, water): smooth (Fresnel-weighted delta reflection and
refraction) and rough (GGX or Beckmann microfacet reflection + transmission, the
`beckmann` flag of the rough functions), one direction at a time.

Sources: Fresnel from `fresnel.dielectric_full` (exact, unpolarised). Rough transmission
is Walter, Marschner, Li & Torrance 2007, "Microfacet Models for Refraction through
Rough Surfaces" (EGSR), eqs. 16, 17, 20-21 (generalised half vector, transmission BTDF and
its Jacobian), with GGX D and height-correlated Smith G2 from `microfacet` (Heitz 2014)
and visible-normal sampling (Heitz 2018): a normal h ~ D_wo, then reflection with
probability F(wo.h) or refraction with 1 - F(wo.h). Sampled reflection weighs
F G2/G1 / P(reflect), refraction (1 - F) G2/G1 / P(refract).

Sides: `eta` is the material IOR relative to the outside (interior over exterior, as
Blender's IOR). wo_z > 0: wo is outside, light refracts into a medium of relative index
eta; wo_z < 0: wo is inside and the relative index is 1/eta. Internally both directions
are mirrored through the tangent plane so that wo_z > 0 ("canonical"), and the results
mirrored back. Total internal reflection (eta_rel < 1 past the critical angle) reflects
everything.

No radiance scaling, as Cycles: refraction carries no factor 1/eta_rel^2 (Veach 1997,
sec. 5.2, and pbrt's TransportMode::Radiance carry it; Cycles' bsdf_microfacet_eval has
ior^2 in its refraction value and its delta refraction weighs 1 - F). So the BTDF is the
adjoint form: f(wo, wi) / n(wi)^2 = f(wi, wo) / n(wo)^2, and the directional albedo is at
most 1 from either side. For closed objects seen from outside the two conventions give
the same image (a path entering glass and leaving it gains and loses eta^2); they differ
where a path ends inside a denser medium: emission on or inside glass and lamps inside
glass are seen eta^2 brighter than under radiance scaling, as Cycles renders them
(tests/test_glass_emission.py; on a public file, floating_iceberg_water.blend, the
blue channel's mean against Cycles went from -2.25 % to +0.06 %).

Pairs the sampler never produces (a choice, to match Cycles): Cycles evaluates the
refraction lobe at every pair of directions on opposite sides from the generalised half
vector h ~ wo + eta_rel wi alone, with |wo.h|, |wi.h| and F(|wo.h|), without checking that
h is a microfacet normal that refracts one into the other (wo.h > 0 > wi.h; Walter's
condition; Cycles' own TODO in bsdf_microfacet_eval). Visible-normal sampling never
produces those pairs, so only next-event estimation sees them, with their MIS weight:
a rough glass lit through by a lamp gains light (the rough glass sphere of
docs/comparisons.md: +0.7% of its image at roughness 0.67). `rough_eval` and `rough_pdf`
follow Cycles unless `walter` is set; with it they are Walter's BTDF and the sampler's
own density (what the chi-square tests check), which agree with Cycles' on every pair
the sampler produces. `rough_sample` returns the direction only; the Principled mixture
computes the weight as f |cos| / pdf (lobe_batch.py does the same for the lobe alone).

Units: f in 1/sr, pdf in 1/sr, sample weights dimensionless. Directions are three
floats, unit, local frame (normal = +Z), pointing away from the surface; wi_z < 0 for
refraction when wo_z > 0.
"""
from __future__ import annotations

import math

from ..jit import kernel
from . import beckmann as bk
from . import fresnel
from . import distribution as dist
from . import microfacet as mf
from .thin_film import glass_choice

# Below this GGX alpha a rough interface is treated as smooth; |eta - 1| below
# INDEX_MATCHED is no interface at all.
SMOOTH_ALPHA = 10.0 ** -3.5
INDEX_MATCHED = 1e-6


@kernel
def is_smooth(alpha, eta):
    """Whether (alpha, eta) is handled by the smooth (delta) model."""
    return alpha <= SMOOTH_ALPHA or abs(eta - 1.0) < INDEX_MATCHED


@kernel
def canonical(oz, eta):
    """(sign, eta_rel): wo_z * sign >= 0 and the relative index seen from that side."""
    if oz < 0.0:
        return -1.0, 1.0 / eta
    return 1.0, eta


@kernel(allocates=False)
def pair_cosine(ox, oy, oz, ix, iy, iz, eta):
    """(cos of wo to the half vector of the pair (wo, wi), eta_rel): the arguments of
    the pair's Fresnel reflectance; the half vector wo + wi of a reflection, -(eta_rel
    wi + wo) of a refraction, on wo's side."""
    sign, eta_rel = canonical(oz, eta)
    oz, iz = oz * sign, iz * sign
    if iz > 0.0:
        hx, hy, hz = ox + ix, oy + iy, oz + iz
    else:
        hx, hy, hz = -(eta_rel * ix + ox), -(eta_rel * iy + oy), -(eta_rel * iz + oz)
    n = math.sqrt(hx * hx + hy * hy + hz * hz)
    if not n > 0.0:
        return 1.0, eta_rel
    return min(abs(ox * hx + oy * hy + oz * hz) / n, 1.0), eta_rel


@kernel
def choice_probs(F, allow_reflect, allow_refract):
    """Probabilities of choosing reflection and refraction."""
    if allow_reflect and allow_refract:
        return F, 1.0 - F
    return (1.0 if allow_reflect else 0.0), (1.0 if allow_refract else 0.0)


# --- smooth interface ------------------------------------------------------------------

@kernel
def smooth_sample(ox, oy, oz, eta, u, allow_reflect, allow_refract, film):
    """Delta reflection or refraction chosen by Fresnel (or forced by the allow flags):
    (wi_x, wi_y, wi_z, weight, refracted, valid, F); its pdf is a delta, F is the
    Fresnel reflectance the weight holds (F or 1 - F): under a film (thin_film.
    glass_choice; NO_FILM for none) the film's, averaged over the channels."""
    sign, eta_rel = canonical(oz, eta)
    cz = oz * sign
    F, cos_t, eta_t = fresnel.dielectric_full(cz, eta_rel)
    if F < 1.0:
        F = glass_choice(film, cz, eta_rel, F)
    pr, pt = choice_probs(F, allow_reflect, allow_refract)
    refr = u >= pr
    if refr:
        ix, iy, iz = -ox / eta_t, -oy / eta_t, -cos_t
        p = pt
        ok = p > 0.0 and cz > 0.0 and F < 1.0
        w = 1.0 - F
    else:
        ix, iy, iz = -ox, -oy, cz
        p = pr
        ok = p > 0.0 and cz > 0.0
        w = F
    w = w / p if ok else 0.0
    return ix, iy, iz * sign, w, refr, ok, F


@kernel
def smooth_refract(ox, oy, oz, eta):
    """The delta refraction alone (Refraction BSDF): (wi_x, wi_y, wi_z, weight, valid),
    weight 1 (no Fresnel factor, no radiance scaling), invalid under total internal
    reflection."""
    sign, eta_rel = canonical(oz, eta)
    cz = oz * sign
    F, cos_t, eta_t = fresnel.dielectric_full(cz, eta_rel)
    ok = cz > 0.0 and F < 1.0
    return -ox / eta_t, -oy / eta_t, -cos_t * sign, 1.0 if ok else 0.0, ok


# --- rough interface -------------------------------------------------------------------

@kernel
def refraction_half(ox, oy, oz, ix, iy, iz, eta_rel):
    """Generalised half vector h ~ wo + eta wi (Walter eq. 16), facing +Z, with wo.h,
    wi.h and its validity (canonical directions)."""
    hx = ox + eta_rel * ix
    hy = oy + eta_rel * iy
    hz = oz + eta_rel * iz
    n = math.sqrt(hx * hx + hy * hy + hz * hz)
    ok = n > 1e-12
    if not ok:
        n = 1.0
    hx, hy, hz = hx / n, hy / n, hz / n
    if hz < 0.0:
        hx, hy, hz = -hx, -hy, -hz
    cos_oh = mf.dot(ox, oy, oz, hx, hy, hz)
    cos_ih = mf.dot(ix, iy, iz, hx, hy, hz)
    ok = ok and cos_oh > 0.0 and cos_ih < 0.0 and hz > 0.0
    return hx, hy, hz, cos_oh, cos_ih, ok


@kernel
def cycles_pair(ox, oy, oz, ix, iy, iz, eta_rel, walter):
    """A refraction pair (canonical directions) as Cycles evaluates it: (h, s = +-|wo +
    eta wi|, |wo.h|, -|wi.h|, usable), usable for any generalised half vector facing +Z,
    also where it is not a microfacet normal that refracts one into the other (Walter's
    condition, required only with `walter`)."""
    hx, hy, hz, cos_oh, cos_ih, ok = refraction_half(ox, oy, oz, ix, iy, iz, eta_rel)
    usable = oz > 0.0 and hz > 0.0 and (ok or not walter)
    s = cos_oh + eta_rel * cos_ih
    return hx, hy, hz, s, abs(cos_oh), -abs(cos_ih), usable


@kernel
def rough_eval(ox, oy, oz, ix, iy, iz, eta, alpha):
    """(f_reflect, f_refract) in 1/sr; one of them is zero for each pair."""
    f_r, f_t, _ = rough_eval_lobes(ox, oy, oz, ix, iy, iz, eta, alpha, False, False, False)
    return f_r, f_t


@kernel
def rough_eval_lobes(ox, oy, oz, ix, iy, iz, eta, alpha, refract_only, walter, beckmann):
    """`rough_eval`, or with `refract_only` Cycles' Refraction BSDF: no reflection and
    the refraction without its Fresnel factor 1 - F (zero under total internal
    reflection). `walter`: refraction on Walter's pairs only. Returns (f_reflect, f_refract, F): F is the Fresnel reflectance
    at the pair's half vector, which the value holds as F or 1 - F (for a Specular
    Tint, specular_tint.py)."""
    a = mf.clamp_alpha(alpha)
    sign, eta_rel = canonical(oz, eta)
    oz = oz * sign
    iz = iz * sign
    if iz > 0.0:
        base_r, hx, hy, hz = dist.reflection_eval_of(ox, oy, oz, ix, iy, iz, a, beckmann)
        if base_r == 0.0 or refract_only:
            return 0.0, 0.0, 0.0
        F_r = fresnel.dielectric(max(mf.dot(ox, oy, oz, hx, hy, hz), 0.0), eta_rel)
        return F_r * base_r, 0.0, F_r
    hx, hy, hz, s, cos_oh, cos_ih, usable = cycles_pair(ox, oy, oz, ix, iy, iz, eta_rel,
                                                        walter)
    if not (usable and iz < 0.0):
        return 0.0, 0.0, 0.0
    F_t = fresnel.dielectric(cos_oh, eta_rel)
    if refract_only:
        F_t = 1.0 if F_t >= 1.0 else 0.0
    den = s * s / (eta_rel * eta_rel)          # Cycles' ior^2: no radiance scaling
    if beckmann:
        g2c = bk.G2_over_cos2(ox, oy, oz, ix, iy, iz, a)
        if not (g2c > 0.0 and den > 0.0):
            return 0.0, 0.0, F_t
        return 0.0, bk.D(hx, hy, hz, a) * (1.0 - F_t) * (-cos_ih) * cos_oh * g2c / den, F_t
    a2 = a * a
    zo, zi = oz, -iz
    g_den = zi * mf.r_len(ox, oy, oz, a2) + zo * mf.r_len(ix, iy, iz, a2)
    if not (g_den > 0.0 and den > 0.0):
        return 0.0, 0.0, F_t
    val = (2.0 * mf.D(hx, hy, hz, a) * (1.0 - F_t) * (-cos_ih) * cos_oh
           / (g_den * den))
    return 0.0, val, F_t


@kernel
def rough_pdf(ox, oy, oz, ix, iy, iz, eta, alpha, allow_reflect, allow_refract, walter,
              beckmann, film):
    """pdf over wi (1/sr) of `rough_sample` with the same allow flags and film, also on
    Cycles' pairs unless `walter` (see rough_eval_lobes)."""
    a = mf.clamp_alpha(alpha)
    sign, eta_rel = canonical(oz, eta)
    oz = oz * sign
    iz = iz * sign
    g1c = dist.G1_over_cos_of(ox, oy, oz, a, beckmann)
    if iz > 0.0:
        # reflection: P(reflect | h) D_wo(h) / (4 wo.h)
        hx, hy, hz, ok = mf.half_vector(ox, oy, oz, ix, iy, iz)
        if not (ok and oz > 0.0):
            return 0.0
        cos_oh = max(mf.dot(ox, oy, oz, hx, hy, hz), 0.0)
        F_r = fresnel.dielectric(cos_oh, eta_rel)
        if F_r < 1.0:
            F_r = glass_choice(film, cos_oh, eta_rel, F_r)
        pr, _ = choice_probs(F_r, allow_reflect, allow_refract)
        return pr * 0.25 * g1c * dist.D_of(hx, hy, hz, a, beckmann)
    # refraction: P(refract | h) D_wo(h) |dh/dwi|
    hx, hy, hz, s, cos_oh, cos_ih, usable = cycles_pair(ox, oy, oz, ix, iy, iz, eta_rel,
                                                        walter)
    if not usable:
        return 0.0
    F_t = fresnel.dielectric(cos_oh, eta_rel)
    if F_t < 1.0:
        F_t = glass_choice(film, cos_oh, eta_rel, F_t)
    _, pt = choice_probs(F_t, allow_reflect, allow_refract)
    den = s * s
    if not den > 0.0:
        return 0.0
    jac = eta_rel * eta_rel * (-cos_ih) / den
    return pt * g1c * cos_oh * dist.D_of(hx, hy, hz, a, beckmann) * jac


@kernel
def rough_sample(ox, oy, oz, eta, alpha, u_choice, u0, u1, allow_reflect, allow_refract,
                 beckmann, film):
    """Sample the rough interface: u_choice picks reflection or refraction (by the
    Fresnel reflectance at the visible normal, a film's if `film` is not NO_FILM:
    thin_film.glass_choice), (u0, u1) the visible normal. Returns (wi_x, wi_y, wi_z,
    refracted, valid); the weight and pdf of the choice are left to the caller (the
    Principled mixture recomputes both)."""
    a = mf.clamp_alpha(alpha)
    sign, eta_rel = canonical(oz, eta)
    oz = oz * sign
    hx, hy, hz = dist.sample_visible_normal_of(ox, oy, oz, a, u0, u1, beckmann)
    cos_oh = mf.dot(ox, oy, oz, hx, hy, hz)
    F, cos_t, eta_t = fresnel.dielectric_full(max(cos_oh, 0.0), eta_rel)
    Fc = glass_choice(film, max(cos_oh, 0.0), eta_rel, F) if F < 1.0 else F
    pr, pt = choice_probs(Fc, allow_reflect, allow_refract)
    refr = u_choice >= pr
    if refr:
        k = cos_oh / eta_t - cos_t
        ix = -ox / eta_t + k * hx
        iy = -oy / eta_t + k * hy
        iz = -oz / eta_t + k * hz
        p = pt
    else:
        ix, iy, iz = mf.reflect(ox, oy, oz, hx, hy, hz)
        p = pr
    # renormalise against rounding (the refraction formula is unit only up to ulps)
    ix, iy, iz = mf.normalize(ix, iy, iz)
    ok = p > 0.0 and oz > 0.0 and cos_oh > 0.0 and hz > 0.0
    if refr:
        ok = ok and F < 1.0 and iz < 0.0
    else:
        ok = ok and iz > 0.0
    # the pdf of the choice made must be positive
    g1c = dist.G1_over_cos_of(ox, oy, oz, a, beckmann)
    d = dist.D_of(hx, hy, hz, a, beckmann)
    if refr:
        cos_ih = mf.dot(ix, iy, iz, hx, hy, hz)
        s = cos_oh + eta_t * cos_ih
        den = s * s
        ok = ok and den > 0.0
        pdf = p * (g1c * cos_oh * d * eta_t * eta_t * abs(cos_ih) / (den if den > 0.0 else 1.0))
    else:
        pdf = p * (0.25 * g1c * d)
    ok = ok and pdf > 0.0
    return ix, iy, iz * sign, refr, ok
