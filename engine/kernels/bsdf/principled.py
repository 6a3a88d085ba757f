"""Blender's Principled BSDF as a mixture of lobes, one hit at a time.

Composition (Blender's manual, "Principled BSDF", and Cycles' layering; every lobe in the
local shading frame, m = metallic, t = transmission, GGX alpha = roughness^2 clamped to
microfacet.ALPHA_MIN):

  metal         weight  m                   GGX reflection, Schlick Fresnel, F0 = base colour
                                            clamped to [0, 1] (F82-tint with a Specular Tint,
                                            reflection_lobes.py; the Glossy BSDF's constant)
  transmission  weight  (1 - m) t           dielectric interface with the material IOR:
                                            smooth (delta) if alpha <= SMOOTH_ALPHA, else
                                            rough GGX (Walter et al. 2007); reflection is
                                            untinted, refraction tinted by sqrt(base colour)
                                            per crossing (Cycles' choice: a round trip
                                            through a closed object gives the base colour)
  specular      weight  (1 - m)(1 - t)      GGX reflection with exact dielectric Fresnel of
                                            an IOR adjusted by Specular IOR Level:
                                            F0' = F0(ior) * 2 level (0.5 = plain IOR, 0 =
                                            no specular, 1 = twice F0), IOR' = IOR(F0')
  diffuse       weight  (1 - m)(1 - t)      Lambert or Oren-Nayar, under the specular
                        (1 - E_spec(wo))    layer: it gets only the energy the layer does not
                                            reflect, E_spec(wo) being that layer's albedo as
                                            Cycles estimates it (albedo.py, multiscatter.py)

The weights sum to 1 and each part conserves energy, so the whole does. Cycles' E_spec
for GGX is the Fresnel reflectance averaged over the visible normals, which ignores the
energy the single-scattering lobe loses to masking: a rough single-scattering plastic
reflects a little less than 1 in a white furnace, as in Cycles; with Multiscatter GGX
(compensation.py: the metal, specular and rough glass lobes scaled per wo by
1 + F_ms (1 - E(wo)) / E(wo)) the furnace is white again. The lecture's Blinn-Phong
distribution may replace GGX in the reflection lobes (never compensated). Coat, sheen,
translucency and the Refraction BSDF's refraction-only glass (layers.py; rows with
P_LAYERS / P_REFRACT_ONLY), the Beckmann distribution (beckmann.py) and the tinted
specular layer and glass (specular_tint.py) complete Cycles' closures.

Sampling: a lobe is chosen with probability proportional to an estimate of its albedo at
wo, averaged over the colour channels as Cycles weighs a closure's sample (its
sample_weight, the average of its weight times its albedo), at least MIN_SELECTION of
its weight; the diffuse lobe is drawn about its own normal
(the frame's, or a bent frame's raw one: setup_about), as is the sheen; the mixture pdf is
sum_i q_i pdf_i over the allowed lobes (the delta part of a smooth glass has no density:
pdf = inf, delta True).
The allow flags over DIFFUSE / GLOSSY / TRANSMISSION restrict sampling and its pdf to the
lobe kinds a hit keeps (the Caustics switches drop glossy reflection or refraction after a
diffuse bounce, as Cycles filters those closures; bounce limits end paths instead,
path_weights.ends_path; glass reflection counts as GLOSSY, refraction as TRANSMISSION).
The state's slots: state.py. Tests reach these kernels over arrays through batch.py.

Use, per hit:
    setup(row, front_facing, wox, woy, woz, tables, state)   # fills state[:NSTATE]
    eval_f(state, wo..., wi...)      -> (r, g, b)   the whole BSDF, every lobe
                                     (eval_f, eval_seen: principled_eval.py)
    pdf(state, wo..., wi..., allow_d, allow_g, allow_t) -> mixture pdf of `sample`
    sample(state, wo..., u_lobe, u1, u2, allow_d, allow_g, allow_t)
        -> (wix, wiy, wiz, weight_r, weight_g, weight_b, pdf, kind, delta, valid)
    transmits(state) -> whether light from behind the surface can contribute
`row` is a material parameter row (`params`, `pack_materials`), `tables` is
`kernel_tables()`, directions are in the local shading frame with wo_z > 0 (the
integrator flips the normal towards the incoming ray), and `front_facing` says whether
the ray arrived from outside (the glass lobe's relative IOR is 1/ior otherwise).
"""
from __future__ import annotations

import math

from ..jit import kernel
from . import anisotropic, dielectric, fresnel, layers, oren_nayar, specular_tint, subsurface_lobe
from . import thin_film
from . import microfacet as mf
from . import multiscatter as ms
from .albedo import specular_albedo
from .compensation import compensate
from .reflection_lobes import f82_setup, metal_fresnel, reflection_pdf, reflection_sample
from .state import (NSTATE, S_ALPHA, S_ANY_SIDE, S_BECKMANN, S_BLINN, S_DIFFUSE,  # noqa: F401
                    S_DIFFUSE_LABEL, S_DIFFUSE_N,
                    S_EST, S_ETA_GLASS, S_ETA_SPEC, S_EXPONENT, S_GLASS_SMOOTH,
                    S_GLASS_RTINT, S_GLASS_TINTED, S_LAYERED, S_METAL_CONST, S_METAL_F0,
                    S_METAL_F82,
                    S_MS_E, S_MS_GLASS, S_MS_METAL, S_MS_SPEC, S_REFRACT_ONLY,
                    S_SPEC_TINTED, S_EST_SSS, S_E_SPEC, S_SSS, S_TINT, S_W_GLASS, S_W_METAL,
                    S_W_SPEC, S_WALTER, S_THIN_FILM, S_FILM_IOR)
from .params import (GLOSSY_BECKMANN, GLOSSY_BLINN_PHONG, GLOSSY_GGX,  # noqa: F401
                     GLOSSY_MULTI_GGX, NPARAM, P_BASE, P_GLASS_COLOR, P_GLASS_REFLECT,
                     P_GLOSSY_MODEL,
                     P_HAS_GLASS_COLOR, P_FILTER_ALPHA, P_HAS_METAL_COLOR, P_IOR,
                     P_LAYERS, P_METAL_COLOR, P_METAL_CONSTANT, P_METALLIC,
                     P_REFRACT_ONLY, P_ROUGHNESS, P_SPEC_LEVEL, P_THIN_FILM, P_THIN_FILM_IOR,
                     P_TRANSMISSION, pack_materials)
from .tables import kernel_tables  # noqa: F401  (re-exported)
from .principled_eval import (base_diffuse, base_glossy, eval_f,  # noqa: F401  (re-exported)
                              eval_seen, sheen_seen, translucent_seen)
from ..frame import to_world
from ..warp import INV_PI, cosine_hemisphere

DIFFUSE, GLOSSY, TRANSMISSION = 0, 1, 2    # lobe kinds
SUBSURFACE = 3             # the subsurface lobe (subsurface_lobe.py): a walk, not a direction
# Lower bound of a present lobe's selection estimate, relative to its weight, so a lobe
# that reflects little at this wo (black metal at normal incidence) can still be sampled
MIN_SELECTION = 0.02
# Largest float below 1: the rescaled lobe coordinate stays in [0, 1)
ONE_MINUS_EPS = 1.0 - 2.0 ** -53



@kernel(allocates=False)
def setup(row, front_facing, wox, woy, woz, tables, state):
    """Fill state[:NSTATE] with the lobes' parameters at this hit for outgoing wo."""
    setup_about(row, front_facing, wox, woy, woz, tables, state, 0.0, 0.0, 1.0)


@kernel(allocates=False)
def setup_about(row, front_facing, wox, woy, woz, tables, state, dnx, dny, dnz):
    """`setup`, with the diffuse and sheen lobes about the unit normal dn of the local
    frame: a bent frame's raw normal (path_vertex), as Cycles' diffuse and sheen closures
    keep the node's normal where its microfacet lobes take the valid reflection one.
    The diffuse lobe is sampled and its density counted about dn; its value towards a
    direction stays the caller's (nodes.shading.bent_diffuse)."""
    # parameters, clamped to their ranges
    m = min(max(row[P_METALLIC], 0.0), 1.0)
    t = min(max(row[P_TRANSMISSION], 0.0), 1.0)
    rough = min(max(row[P_ROUGHNESS], 0.0), 1.0)
    ior = max(row[P_IOR], 1e-5)
    level = max(row[P_SPEC_LEVEL], 0.0)
    layered = row[P_LAYERS] != 0.0
    state[S_LAYERED] = 1.0 if layered else 0.0
    state[S_REFRACT_ONLY] = row[P_REFRACT_ONLY]
    state[S_WALTER] = 0.0       # Cycles' refraction pairs (path_vertex sets it per light)
    state[S_DIFFUSE_N], state[S_DIFFUSE_N + 1], state[S_DIFFUSE_N + 2] = dnx, dny, dnz
    if layered:
        layers.setup(row, wox, woy, woz, tables, state, dnx, dny, dnz)
    alpha = mf.clamp_alpha(rough * rough)
    # Filter Glossy widens the lobes after setup, as Cycles' closure blur does: the energy
    # compensation and the layering below keep the material's own alpha
    lobe_alpha = mf.clamp_alpha(max(alpha, row[P_FILTER_ALPHA]))
    state[S_ALPHA] = lobe_alpha
    state[S_BLINN] = 1.0 if row[P_GLOSSY_MODEL] == GLOSSY_BLINN_PHONG else 0.0
    state[S_BECKMANN] = 1.0 if row[P_GLOSSY_MODEL] == GLOSSY_BECKMANN else 0.0
    state[S_METAL_CONST] = row[P_METAL_CONSTANT]
    state[S_METAL_F82] = 0.0
    # a Thin Film on the specular layer, the metal and the glass (thin_film.py)
    film = row[P_THIN_FILM] > thin_film.CUTOFF
    state[S_THIN_FILM] = row[P_THIN_FILM] if film else 0.0
    state[S_FILM_IOR] = max(row[P_THIN_FILM_IOR], 1e-5)
    state[S_EXPONENT] = max(2.0 / (lobe_alpha * lobe_alpha) - 2.0, 0.0)
    # the metal and specular lobes' own alpha (anisotropic: the isotropic one the
    # compensation and the layering take); Blinn-Phong stays isotropic
    alpha_r = alpha
    if state[S_BLINN] == 0.0:
        alpha_r = anisotropic.setup(row, rough, row[P_FILTER_ALPHA], state)
    else:
        state[anisotropic.S_ANISO] = 0.0
    base_w = (1.0 - m) * (1.0 - t)
    # specular layer: F0 scaled by 2 * level, IOR recomputed from it
    f0 = fresnel.f0_from_ior(ior) * 2.0 * level
    eta_s = fresnel.ior_from_f0(f0)
    if ior < 1.0:
        eta_s = 1.0 / eta_s
    eta_spec = ior if level == 0.5 else eta_s
    state[S_ETA_SPEC] = eta_spec
    spec_on = f0 > 0.0 and abs(eta_spec - 1.0) > 1e-7
    eta_glass = ior if front_facing else 1.0 / ior
    state[S_ETA_GLASS] = eta_glass
    state[S_GLASS_SMOOTH] = 1.0 if dielectric.is_smooth(lobe_alpha, eta_glass) else 0.0
    has_metal = row[P_HAS_METAL_COLOR] != 0.0
    has_glass = row[P_HAS_GLASS_COLOR] != 0.0
    diffuse_max = 0.0
    for c in range(3):
        base = max(row[P_BASE + c], 0.0)          # Cycles: diffuse is not clamped
        clamped = min(base, 1.0)                  # ... metal F0 and glass tint are
        if has_metal:
            state[S_METAL_F0 + c] = min(max(row[P_METAL_COLOR + c], 0.0), 1.0)
        else:
            state[S_METAL_F0 + c] = clamped
        if has_glass:
            state[S_TINT + c] = min(max(row[P_GLASS_COLOR + c], 0.0), 1.0)
        else:
            state[S_TINT + c] = math.sqrt(clamped)
        state[S_GLASS_RTINT + c] = max(row[P_GLASS_REFLECT + c], 0.0)
        # (less the share that scatters below the surface: subsurface_lobe.py)
        state[S_DIFFUSE + c] = subsurface_lobe.split(row, c, base, clamped, base_w, state)
        diffuse_max = max(diffuse_max, state[S_DIFFUSE + c])
    oren_nayar.setup(row, woz, state)       # the diffuse lobe's roughness (0: Lambert)
    if m > 0.0 and state[S_METAL_CONST] == 0.0:
        f82_setup(row, state)
    w_diff = base_w if diffuse_max > 0.0 else 0.0
    w_spec = base_w if spec_on else 0.0
    w_glass = (1.0 - m) * t
    state[S_W_SPEC] = w_spec
    state[S_W_METAL] = m
    state[S_W_GLASS] = w_glass
    state[S_GLASS_TINTED] = 0.0
    glass_f0 = film or specular_tint.is_tinted(row)      # per channel F_c (specular_tint)
    if w_glass > 0.0 and state[S_REFRACT_ONLY] == 0.0 and glass_f0:
        specular_tint.glass_setup(row, eta_glass, ior, state)

    # albedo-dependent weights at wo
    cos_o = min(max(woz, 0.0), 1.0)
    compensate(row[P_GLOSSY_MODEL] == GLOSSY_MULTI_GGX, woz, cos_o, alpha_r, alpha,
               eta_spec, eta_glass, w_spec, m, w_glass, tables, state)
    e_spec = 0.0
    est_spec = 0.0
    state[S_SPEC_TINTED] = 0.0
    if w_spec > 0.0:
        # the layer's albedo as the diffuse sees it
        e_spec = specular_albedo(cos_o, alpha_r, eta_spec, tables)
        if state[S_BLINN] == 0.0:
            if film or specular_tint.is_tinted(row):
                e_spec = specular_tint.setup(row, row[P_GLOSSY_MODEL] == GLOSSY_MULTI_GGX,
                                             cos_o, alpha_r, eta_spec, e_spec, tables, state)
            else:
                e_est = ms.layer_reflectance(cos_o, alpha_r, eta_spec, tables) * state[S_MS_E]
                e_spec = max(e_est, e_spec) * state[S_MS_SPEC]
        est_spec = w_spec * e_spec
    state[S_E_SPEC] = e_spec
    est_diff = 0.0
    below = 1.0 - min(e_spec, 1.0)
    for c in range(3):
        state[S_DIFFUSE + c] = state[S_DIFFUSE + c] * below
        est_diff += state[S_DIFFUSE + c] / 3.0
    subsurface_lobe.scale(state, below, below, below)
    subsurface_lobe.estimate(state, MIN_SELECTION * base_w * subsurface_lobe.weight(row))
    est_metal = 0.0
    if m > 0.0:
        F = 0.0
        for c in range(3):
            F += metal_fresnel(state, c, cos_o) * state[S_MS_METAL + c] / 3.0
        est_metal = m * F
    est_gr = 0.0
    est_gt = 0.0
    if w_glass > 0.0:
        F = fresnel.dielectric(woz, eta_glass)
        if state[S_REFRACT_ONLY] != 0.0:          # no reflection, refraction unless TIR
            F = 1.0 if F >= 1.0 else 0.0
        tint = (state[S_TINT] + state[S_TINT + 1] + state[S_TINT + 2]) / 3.0
        c_ms = (state[S_MS_GLASS] + state[S_MS_GLASS + 1] + state[S_MS_GLASS + 2]) / 3.0
        est_gr = w_glass * F * c_ms if state[S_REFRACT_ONLY] == 0.0 else 0.0
        est_gt = w_glass * (1.0 - F) * tint * c_ms
    # floors so that every present lobe can be sampled
    state[S_EST] = max(est_diff, MIN_SELECTION * w_diff) if w_diff > 0.0 else 0.0
    state[S_EST + 1] = max(est_spec, MIN_SELECTION * w_spec) if w_spec > 0.0 else 0.0
    state[S_EST + 2] = max(est_metal, MIN_SELECTION * m) if m > 0.0 else 0.0
    half_floor = 0.5 * (MIN_SELECTION * w_glass)
    state[S_EST + 3] = max(est_gr, half_floor) if w_glass > 0.0 else 0.0
    state[S_EST + 4] = max(est_gt, half_floor) if w_glass > 0.0 else 0.0
    if layered:                  # the layers above dim (and tint) every base lobe
        s_mean = layers.base_scale_mean(state)
        for c in range(3):
            state[S_DIFFUSE + c] = state[S_DIFFUSE + c] * state[layers.S_BASE_SCALE + c]
        for k in range(5):
            state[S_EST + k] = state[S_EST + k] * s_mean
        s = layers.S_BASE_SCALE
        subsurface_lobe.scale(state, state[s], state[s + 1], state[s + 2])
        state[S_EST_SSS] = state[S_EST_SSS] * s_mean


@kernel(allocates=False)
def _diffuse_cosine(state, wix, wiy, wiz):
    """cos of wi to the diffuse lobe's normal (wiz unless setup_about moved it)."""
    return (state[S_DIFFUSE_N] * wix + state[S_DIFFUSE_N + 1] * wiy
            + state[S_DIFFUSE_N + 2] * wiz)


@kernel(allocates=False)
def transmits(state):
    """True where light from behind the surface can contribute (glass, translucency, a
    Hair BSDF's transmission, a Principled Hair BSDF)."""
    return state[S_W_GLASS] > 0.0 or (state[S_LAYERED] != 0.0 and (
        state[layers.S_EST_TRANS] > 0.0 or state[layers.S_EST_HAIR_TT] > 0.0
        or state[layers.S_EST_CHIANG] > 0.0))


@kernel(allocates=False)
def selection(state, allow_d, allow_g, allow_t):
    """Lobe probabilities (diffuse, specular, metal, glass; coat, sheen, translucent,
    hair R, hair TT of layers.py; subsurface; Principled Hair) over the allowed kinds.
    The subsurface lobe may be chosen while any kind may continue: it leaves as a
    diffuse surface, lit directly even without a diffuse bounce left (Cycles)."""
    w0 = state[S_EST] if allow_d else 0.0
    w1 = state[S_EST + 1] if allow_g else 0.0
    w2 = state[S_EST + 2] if allow_g else 0.0
    w3 = (state[S_EST + 3] if allow_g else 0.0) + (state[S_EST + 4] if allow_t else 0.0)
    wc = ws = wt = whr = wht = wch = 0.0
    if state[S_LAYERED] != 0.0:
        wc, ws, wt, whr, wht, wch = layers.selection(state, allow_d, allow_g, allow_t)
    wu = state[S_EST_SSS] if (allow_d or allow_g or allow_t) else 0.0
    total = w0 + w1 + w2 + w3 + wc + ws + wt + whr + wht + wu + wch
    if not total > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return (w0 / total, w1 / total, w2 / total, w3 / total, wc / total, ws / total,
            wt / total, whr / total, wht / total, wu / total, wch / total)


@kernel(allocates=False)
def mixture_pdf(state, wox, woy, woz, wix, wiy, wiz, q, allow_g, allow_t):
    """sum_i q_i pdf_i over the lobes, for the selection probabilities q (`selection`;
    the subsurface lobe's has no density here)."""
    q0, q1, q2, q3, qc, qs, qt, qhr, qht, qu, qch = q
    p = 0.0
    cos_d = _diffuse_cosine(state, wix, wiy, wiz)
    if cos_d > 0.0:
        p += q0 * (cos_d * INV_PI)
    q_refl = q1 + q2
    if q_refl > 0.0:
        p += q_refl * reflection_pdf(state, wox, woy, woz, wix, wiy, wiz)
    if q3 > 0.0 and state[S_GLASS_SMOOTH] == 0.0:
        p += q3 * dielectric.rough_pdf(wox, woy, woz, wix, wiy, wiz, state[S_ETA_GLASS],
                                       state[S_ALPHA], allow_g and state[S_REFRACT_ONLY] == 0.0,
                                       allow_t, state[S_WALTER] != 0.0,
                                       state[S_BECKMANN] != 0.0,
                                       specular_tint.glass_film(state))
    if qc > 0.0 or qs > 0.0 or qt > 0.0 or qhr > 0.0 or qht > 0.0 or qch > 0.0:
        p += layers.mixture_pdf(state, wox, woy, woz, wix, wiy, wiz, qc, qs, qt, qhr, qht,
                                qch)
    return p


@kernel(allocates=False)
def pdf(state, wox, woy, woz, wix, wiy, wiz, allow_d, allow_g, allow_t):
    """Mixture pdf (1/sr) of `sample` with the same allow flags."""
    q = selection(state, allow_d, allow_g, allow_t)
    return mixture_pdf(state, wox, woy, woz, wix, wiy, wiz, q, allow_g, allow_t)


@kernel(allocates=False)
def pdf_seen(state, wox, woy, woz, wix, wiy, wiz, allow_d, allow_g, allow_t,
             see_d, see_g, see_t):
    """The part of `pdf` (same allow flags) due to the lobes of the kinds a light is seen
    by: the density with which BSDF sampling reaches that light through wi."""
    q0, q1, q2, q3, qc, qs, qt, qhr, qht, qu, qch = selection(state, allow_d, allow_g,
                                                              allow_t)
    if not see_d:
        q0 = qs = qt = 0.0
    if not see_g:
        q1 = q2 = qc = qhr = qch = 0.0
    if not see_t:
        qht = 0.0
    if not (see_g if wiz > 0.0 else see_t):
        q3 = 0.0
    return mixture_pdf(state, wox, woy, woz, wix, wiy, wiz,
                       (q0, q1, q2, q3, qc, qs, qt, qhr, qht, qu, qch), allow_g, allow_t)


@kernel(allocates=False)
def sample(state, wox, woy, woz, u_lobe, u1, u2, allow_d, allow_g, allow_t):
    """Choose a lobe with u_lobe, a direction with (u1, u2) (the rest of u_lobe, rescaled,
    picks a glass reflection or refraction). Returns
    (wix, wiy, wiz, weight_r, weight_g, weight_b, pdf, kind, delta, valid): weight is
    f |cos| / pdf (zero where invalid), pdf the mixture pdf over the allowed lobes (inf
    for the delta choices of a smooth glass, with delta True). state[S_ANY_SIDE] says
    whether the direction may leave on either side of the surface (a hair lobe's),
    state[S_DIFFUSE_LABEL] whether it is a diffuse ray besides its kind (a translucent
    lobe's transmission)."""
    q = selection(state, allow_d, allow_g, allow_t)
    state[S_ANY_SIDE] = 0.0
    state[S_DIFFUSE_LABEL] = 0.0
    lobe = 0
    lo = 0.0
    total = 0.0
    for k in range(11):
        if k > 0 and u_lobe >= total and q[k] > 0.0:
            lobe, lo = k, total
        total += q[k]
    q_sel = q[lobe]
    u_re = min(max((u_lobe - lo) / (q_sel if q_sel > 0.0 else 1.0), 0.0), ONE_MINUS_EPS)

    wix, wiy, wiz = 0.0, 0.0, 1.0
    kind = DIFFUSE
    ok = total > 0.0 and q_sel > 0.0
    if not ok:
        return wix, wiy, wiz, 0.0, 0.0, 0.0, 0.0, kind, False, False
    if lobe == 9:                       # below the surface: the caller walks it
        return (wix, wiy, wiz, state[S_SSS] / q_sel, state[S_SSS + 1] / q_sel,
                state[S_SSS + 2] / q_sel, math.inf, SUBSURFACE, True, True)
    hair_d = 0.0                        # a hair lobe's sampled pdf less its evaluated one
    hr = hg = hb = 0.0
    if lobe == 0:
        wix, wiy, wiz = cosine_hemisphere(u1, u2)
        if state[S_DIFFUSE_N + 2] != 1.0:       # about a bent frame's raw normal
            wix, wiy, wiz = to_world(wix, wiy, wiz, state[S_DIFFUSE_N],
                                     state[S_DIFFUSE_N + 1], state[S_DIFFUSE_N + 2])
    elif lobe == 1 or lobe == 2:
        wix, wiy, wiz, ok = reflection_sample(state, wox, woy, woz, u1, u2)
        kind = GLOSSY
    elif lobe == 10:                    # Principled Hair: on either side, exact pdf
        wix, wiy, wiz, _, _, _, ps, p_fibre = layers.chiang_sample(state, wox, woy, woz,
                                                                   u_re, u1, u2)
        kind = GLOSSY if p_fibre == 0 else TRANSMISSION
        ok = ps > 0.0 and (allow_g if p_fibre == 0 else allow_t)
        state[S_ANY_SIDE] = 1.0
        if not ok:
            layers.chiang_sampled_done(state)
    elif lobe > 6:                      # hair R, TT: on either side, with their own pdf
        tt = lobe == 8
        wix, wiy, wiz, ps, hr, hg, hb = layers.hair_sample(state, wox, woy, woz, tt, u1, u2)
        ok = ps > 0.0
        kind = TRANSMISSION if tt else GLOSSY
        hair_d = ps - layers.hair_pdf(state, wox, woy, woz, wix, wiy, wiz, tt)
        state[S_ANY_SIDE] = 1.0
    elif lobe > 3:                      # coat, sheen, translucent
        wix, wiy, wiz, ok = layers.sample(state, wox, woy, woz, lobe - 4, u1, u2)
        kind = (GLOSSY, DIFFUSE, TRANSMISSION)[lobe - 4]
        if lobe == 6:
            state[S_DIFFUSE_LABEL] = 1.0
    elif state[S_GLASS_SMOOTH] != 0.0:
        if state[S_REFRACT_ONLY] != 0.0:
            wix, wiy, wiz, ws, ok = dielectric.smooth_refract(wox, woy, woz,
                                                              state[S_ETA_GLASS])
            refr = True
            ok = ok and allow_t
        else:
            wix, wiy, wiz, ws, refr, ok, F = dielectric.smooth_sample(
                wox, woy, woz, state[S_ETA_GLASS], u_re, allow_g, allow_t,
                specular_tint.glass_film(state))
        kind = TRANSMISSION if refr else GLOSSY
        if not ok:
            return wix, wiy, wiz, 0.0, 0.0, 0.0, 0.0, kind, False, False
        w = ws * state[S_W_GLASS] / q_sel
        t = S_TINT if refr else S_GLASS_RTINT
        wr, wg, wb = state[t] * w, state[t + 1] * w, state[t + 2] * w
        if state[S_GLASS_TINTED] != 0.0:        # Specular Tint, Thin Film: F_c for F
            eta = state[S_ETA_GLASS]
            _, eta_rel = dielectric.canonical(woz, eta)
            cos_o = min(abs(woz), 1.0)
            wr *= specular_tint.glass_factor(state, 0, F, eta, not refr, cos_o, eta_rel)
            wg *= specular_tint.glass_factor(state, 1, F, eta, not refr, cos_o, eta_rel)
            wb *= specular_tint.glass_factor(state, 2, F, eta, not refr, cos_o, eta_rel)
        if state[S_LAYERED] != 0.0:
            s = layers.S_BASE_SCALE
            wr, wg, wb = wr * state[s], wg * state[s + 1], wb * state[s + 2]
        return wix, wiy, wiz, wr, wg, wb, math.inf, kind, True, True
    else:
        wix, wiy, wiz, refr, ok = dielectric.rough_sample(
            wox, woy, woz, state[S_ETA_GLASS], state[S_ALPHA], u_re, u1, u2,
            allow_g and state[S_REFRACT_ONLY] == 0.0, allow_t, state[S_BECKMANN] != 0.0,
            specular_tint.glass_film(state))
        kind = TRANSMISSION if refr else GLOSSY
    if not ok:
        return wix, wiy, wiz, 0.0, 0.0, 0.0, 0.0, kind, False, False
    # non-delta choices: one-sample mixture estimator f |cos| / sum_j q_j pdf_j, of the
    # allowed lobes only (a lobe a Caustics switch drops adds nothing)
    fr, fg, fb = eval_seen(state, wox, woy, woz, wix, wiy, wiz, allow_d, allow_g, allow_t)
    p = mixture_pdf(state, wox, woy, woz, wix, wiy, wiz, q, allow_g, allow_t)
    c = abs(wiz)
    if q[10] > 0.0 and not allow_g and c > 0.0:
        # the Principled Hair closure is selectable with its transmission lobes alone:
        # its value counts (eval_seen gates it as the glossy closure it is for lights)
        cr, cg, cb, _ = layers.chiang_eval(state, wox, woy, woz, wix, wiy, wiz)
        fr, fg, fb = fr + cr / c, fg + cg / c, fb + cb / c
    if lobe == 10:
        layers.chiang_sampled_done(state)
    if hair_d != 0.0:
        # as Cycles: the sampled hair lobe counts with the value and density its
        # sampling gave (f cos = pdf, on either side), the other lobes as evaluated
        fr, fg, fb = fr * c + hr * hair_d, fg * c + hg * hair_d, fb * c + hb * hair_d
        p += q_sel * hair_d
        c = 1.0
    if not (p > 0.0 and p < math.inf):
        return wix, wiy, wiz, 0.0, 0.0, 0.0, 0.0, kind, False, False
    s = c / p
    return wix, wiy, wiz, fr * s, fg * s, fb * s, p, kind, False, True
