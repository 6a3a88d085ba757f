"""The lobes beyond Principled's base, as Cycles stacks them (kernel/svm/closure.h):

    sheen        (sheen.py)        on top, dimming what is below by its albedo (a Sheen
                                   BSDF node's sheen, P_SHEEN_LAYERED 0, dims nothing);
    coat         (coat.py)         under the sheen, dimming and tinting what is below;
    base         (principled.py)   diffuse, specular, metal, glass: scaled per channel by
                                   `S_BASE_SCALE`, the product of the layers' factors;
    translucent  (translucent.py)  a Translucent BSDF mixed in beside them (no layering);
    hair R, TT   (hair.py)         a Hair BSDF node's Reflection and Transmission, beside
                                   them, about the fibre's tangent that the integrator
                                   writes into the row per hit (P_HAIR_T);
    chiang       (hair_chiang.py)  a Principled Hair BSDF (Chiang), beside them, about
                                   the fibre's dP/du (P_CHIANG_T), with the geometric
                                   normal (P_CHIANG_NG), also written per hit.

A material row uses them only where P_LAYERS is 1; then principled.setup calls `setup`
here, which fills the slots below and returns nothing else, and principled's eval, pdf
and sample add this module's lobes. A row with P_LAYERS = 0 never reads a slot here
(tests/test_layered_bsdf.py checks that with NaN slots).

The sheen lies on its own normal (S_SHEEN_N, in the local frame): the frame's, or where
path_vertex bends the frame to Cycles' valid reflection normal, the raw normal, as
Cycles' sheen keeps the node's normal (svm/closure.h); its LTC is set up for wo's angle to
that normal, and its value, density and samples are taken about it (`sheen_seen`).

The coat lies on its own normal too (S_COAT_N): the frame's, or where the material's
program bends the frame or gives a Coat Normal, that Coat Normal or the surface's own
normal, made a valid reflector for the view (engine.kernels.surface_hit.coat_frame), as
Cycles' coat closure lies on its Coat Normal (sd->N when unlinked); its layering
albedo is taken at wo's angle to it, its value and density about it, and its value is
scaled by wi's cosine to it over the frame's, which the callers multiply by.

Lobe kinds: coat GLOSSY; sheen DIFFUSE (Cycles labels it diffuse reflection); translucent
TRANSMISSION for the bounce that follows it (it leaves through the surface; the ray it
sends is a diffuse ray as well, as Cycles' diffuse-transmission label makes it:
principled.sample's S_DIFFUSE_LABEL) and seen by lights as diffuse, as Cycles classifies
it; it is sampled wherever diffuse lobes are
(principled.sample's allow flags: Refractive Caustics off leaves it, as Cycles' filter
leaves its diffuse closures); hair R
GLOSSY, hair TT TRANSMISSION (Cycles' closure classes, which the lights' visibility and
the passes follow). A sampled hair direction is kept on either side of the surface, as
Cycles keeps it (`hair_sample`; principled.sample weighs it with the density drawn).
The Principled Hair closure is GLOSSY for the lights and the passes (Cycles' class) and
may be sampled where glossy or transmission lobes are allowed; the bounce it makes
counts as GLOSSY for its R lobe and TRANSMISSION for the three through the fibre
(Cycles' labels), against those kinds' bounce limits (path_weights.ends_path).
"""
from __future__ import annotations

from ..frame import to_local, to_world
from ..jit import kernel
from . import coat, hair, sheen, translucent
from .layer_slots import (  # noqa: F401  (re-exported: principled, state, the passes)
    WEIGHT_CUTOFF, MIN_SELECTION, S_FIRST, S_BASE_SCALE, S_COAT_W, S_COAT_ALPHA, S_COAT_IOR,
    S_SHEEN_W, S_SHEEN_A, S_SHEEN_B, S_SHEEN_CX, S_SHEEN_CY, S_TRANS, S_EST_COAT,
    S_EST_SHEEN, S_EST_TRANS, S_HAIR_T, S_HAIR_R, S_HAIR_TT, S_HAIR_R_LOBE, S_HAIR_TT_LOBE,
    S_EST_HAIR_R, S_EST_HAIR_TT, S_CHIANG_W, S_CHIANG_SIGMA, S_CHIANG_LOBE, S_CHIANG_ALPHA,
    S_CHIANG_ETA, S_CHIANG_H, S_CHIANG_T, S_CHIANG_ALBEDO, S_EST_CHIANG, S_CHIANG_MESH,
    S_CHIANG_AS_SAMPLED, S_SHEEN_N, S_COAT_N, NSTATE)
from .hair_layer import (chiang_eval, chiang_sample, chiang_sampled_done,  # noqa: F401
                         chiang_setup, hair_pdf, hair_sample)
from . import microfacet as mf
from .params import (P_COAT_IOR, P_COAT_N, P_COAT_ROUGHNESS, P_COAT_TINT, P_COAT_WEIGHT,
                     P_FILTER_ALPHA, P_HAIR_CURVE, P_HAIR_R, P_HAIR_R_OFFSET,
                     P_HAIR_R_ROUGH, P_HAIR_T, P_HAIR_TT, P_HAIR_TT_OFFSET, P_HAIR_TT_ROUGH,
                     P_SHEEN_LAYERED, P_SHEEN_ROUGHNESS, P_SHEEN_TINT, P_SHEEN_WEIGHT,
                     P_TRANSLUCENT)


@kernel(allocates=False)
def setup(row, wox, woy, woz, tables, state, snx, sny, snz):
    """Fill the slots above for outgoing wo (local, wo_z > 0), the sheen on the unit
    normal sn (local; (0, 0, 1): the frame's)."""
    cos_o = min(max(woz, 0.0), 1.0)
    scale = 1.0                                  # the layers' scalar factor so far
    # sheen, set up for wo as its own normal sees it
    state[S_SHEEN_N], state[S_SHEEN_N + 1], state[S_SHEEN_N + 2] = snx, sny, snz
    sox, soy, soz = wox, woy, woz
    if snz != 1.0:
        sox, soy, soz = to_local(wox, woy, woz, snx, sny, snz)
    sw = max(row[P_SHEEN_WEIGHT], 0.0)
    sheen_max = 0.0
    sheen_mean = 0.0
    state[S_SHEEN_CX], state[S_SHEEN_CY] = sheen.azimuth(sox, soy)
    state[S_SHEEN_A], state[S_SHEEN_B] = 1.0, 0.0
    for c in range(3):
        state[S_SHEEN_W + c] = 0.0
    if sw > WEIGHT_CUTOFF:
        rough = min(max(row[P_SHEEN_ROUGHNESS], 0.0), 1.0)
        a, b, R = sheen.lookup(min(max(soz, 0.0), 1.0), rough, tables)
        state[S_SHEEN_A], state[S_SHEEN_B] = a, b
        for c in range(3):
            w = sw * max(row[P_SHEEN_TINT + c], 0.0) * max(R, 0.0)
            state[S_SHEEN_W + c] = w
            sheen_max = max(sheen_max, w)
            sheen_mean += w / 3.0
        if row[P_SHEEN_LAYERED] != 0.0:
            scale = min(max(1.0 - sheen_max, 0.0), 1.0)
    state[S_EST_SHEEN] = max(sheen_mean, MIN_SELECTION * sw) if sheen_max > 0.0 else 0.0
    # coat, about its own normal where it has one (row[P_COAT_N], per hit)
    cw = max(row[P_COAT_WEIGHT], 0.0)
    ior = max(row[P_COAT_IOR], 1.0)
    cnx, cny, cnz = row[P_COAT_N], row[P_COAT_N + 1], row[P_COAT_N + 2]
    if cnx == 0.0 and cny == 0.0 and cnz == 0.0:
        cnx, cny, cnz = 0.0, 0.0, 1.0
    state[S_COAT_N], state[S_COAT_N + 1], state[S_COAT_N + 2] = cnx, cny, cnz
    if cnz != 1.0:
        cos_o = min(max(wox * cnx + woy * cny + woz * cnz, 0.0), 1.0)
    state[S_COAT_W] = 0.0
    state[S_COAT_IOR] = ior
    state[S_COAT_ALPHA] = 1.0
    state[S_EST_COAT] = 0.0
    for c in range(3):
        state[S_BASE_SCALE + c] = 1.0
    if cw > WEIGHT_CUTOFF:
        rough = min(max(row[P_COAT_ROUGHNESS], 0.0), 1.0)
        alpha = mf.clamp_alpha(rough * rough)
        state[S_COAT_ALPHA] = mf.clamp_alpha(max(alpha, row[P_FILTER_ALPHA]))
        if ior > 1.0:
            state[S_COAT_W] = cw * scale
            E = coat.layer_albedo(cos_o, alpha, ior, tables)
            state[S_EST_COAT] = cw * scale * max(E, MIN_SELECTION)
            scale = scale * min(max(1.0 - cw * E, 0.0), 1.0)
        tinted = (row[P_COAT_TINT] != 1.0 or row[P_COAT_TINT + 1] != 1.0
                  or row[P_COAT_TINT + 2] != 1.0)
        if tinted:
            depth = coat.path_length(cos_o, ior)
            for c in range(3):
                state[S_BASE_SCALE + c] = coat.tint_factor(row[P_COAT_TINT + c], cw, depth)
    for c in range(3):
        state[S_BASE_SCALE + c] = state[S_BASE_SCALE + c] * scale
    # translucent
    t_mean = 0.0
    for c in range(3):
        state[S_TRANS + c] = max(row[P_TRANSLUCENT + c], 0.0)
        t_mean += state[S_TRANS + c] / 3.0
    state[S_EST_TRANS] = t_mean
    # hair: each lobe's f cos integrates to at most 1, so its colour estimates its albedo
    r_max = 0.0
    tt_max = 0.0
    for c in range(3):
        state[S_HAIR_R + c] = max(row[P_HAIR_R + c], 0.0)
        state[S_HAIR_TT + c] = max(row[P_HAIR_TT + c], 0.0)
        r_max = max(r_max, state[S_HAIR_R + c])
        tt_max = max(tt_max, state[S_HAIR_TT + c])
        state[S_HAIR_T + c] = row[P_HAIR_T + c]
    state[S_EST_HAIR_R] = r_max
    state[S_EST_HAIR_TT] = tt_max
    if r_max > 0.0 or tt_max > 0.0:
        on_strand = row[P_HAIR_CURVE] != 0.0        # Cycles: no offset on a mesh
        state[S_HAIR_R_LOBE] = row[P_HAIR_R_OFFSET] if on_strand else 0.0
        state[S_HAIR_R_LOBE + 1] = hair.clamp_roughness(row[P_HAIR_R_ROUGH])
        state[S_HAIR_R_LOBE + 2] = hair.clamp_roughness(row[P_HAIR_R_ROUGH + 1])
        state[S_HAIR_TT_LOBE] = row[P_HAIR_TT_OFFSET] if on_strand else 0.0
        state[S_HAIR_TT_LOBE + 1] = hair.clamp_roughness(row[P_HAIR_TT_ROUGH])
        state[S_HAIR_TT_LOBE + 2] = hair.clamp_roughness(row[P_HAIR_TT_ROUGH + 1])
    chiang_setup(row, wox, woy, woz, state)


@kernel(allocates=False)
def base_scale_mean(state):
    """The layers' dimming of the base, averaged over the channels (for selection)."""
    return (state[S_BASE_SCALE] + state[S_BASE_SCALE + 1] + state[S_BASE_SCALE + 2]) / 3.0


@kernel(allocates=False)
def sheen_seen(state, woz, wix, wiy, wiz):
    """f (1/sr) of the sheen towards local wi, about its own normal (none while wo is
    under the frame's normal, unless the sheen has a normal of its own)."""
    if not state[S_EST_SHEEN] > 0.0 or not (woz > 0.0 or state[S_SHEEN_N + 2] != 1.0):
        return 0.0, 0.0, 0.0
    x, y, z = _about_sheen(state, wix, wiy, wiz)
    s = sheen.shape(x, y, z, state[S_SHEEN_CX], state[S_SHEEN_CY], state[S_SHEEN_A],
                    state[S_SHEEN_B])
    return state[S_SHEEN_W] * s, state[S_SHEEN_W + 1] * s, state[S_SHEEN_W + 2] * s


@kernel(allocates=False)
def _about_sheen(state, x, y, z):
    """Local direction (x, y, z) in the sheen's own frame."""
    if state[S_SHEEN_N + 2] == 1.0:
        return x, y, z
    return to_local(x, y, z, state[S_SHEEN_N], state[S_SHEEN_N + 1], state[S_SHEEN_N + 2])


@kernel(allocates=False)
def _about_coat(state, x, y, z):
    """Local direction (x, y, z) in the coat's own frame."""
    if state[S_COAT_N + 2] == 1.0:
        return x, y, z
    return to_local(x, y, z, state[S_COAT_N], state[S_COAT_N + 1], state[S_COAT_N + 2])


@kernel(allocates=False)
def eval_seen(state, wox, woy, woz, wix, wiy, wiz, see_d, see_g, see_t):
    """f (1/sr) of the sheen, coat, translucent and hair lobes that a light of the given
    kinds sees (principled.eval_seen adds the scaled base)."""
    fr = fg = fb = 0.0
    if see_d:
        fr, fg, fb = sheen_seen(state, woz, wix, wiy, wiz)
    if see_g and state[S_COAT_W] > 0.0:
        ox, oy, oz = _about_coat(state, wox, woy, woz)
        ix, iy, iz = _about_coat(state, wix, wiy, wiz)
        v = state[S_COAT_W] * coat.eval_unit(ox, oy, oz, ix, iy, iz, state[S_COAT_ALPHA],
                                             state[S_COAT_IOR])
        if state[S_COAT_N + 2] != 1.0 and v > 0.0:
            # the callers multiply f by wi's cosine to the frame's normal; the coat's is
            # to its own (Cycles' closure eval includes it)
            v = v * iz / abs(wiz) if wiz != 0.0 else 0.0
        fr += v
        fg += v
        fb += v
    if see_d and state[S_EST_TRANS] > 0.0:
        t = translucent.eval_unit(woz, wiz)
        fr += state[S_TRANS] * t
        fg += state[S_TRANS + 1] * t
        fb += state[S_TRANS + 2] * t
    if see_g and state[S_EST_HAIR_R] > 0.0 and wiz > 0.0:
        v = hair_pdf(state, wox, woy, woz, wix, wiy, wiz, False) / wiz
        fr += state[S_HAIR_R] * v
        fg += state[S_HAIR_R + 1] * v
        fb += state[S_HAIR_R + 2] * v
    if see_t and state[S_EST_HAIR_TT] > 0.0 and wiz < 0.0:
        v = hair_pdf(state, wox, woy, woz, wix, wiy, wiz, True) / -wiz
        fr += state[S_HAIR_TT] * v
        fg += state[S_HAIR_TT + 1] * v
        fb += state[S_HAIR_TT + 2] * v
    if see_g and state[S_EST_CHIANG] > 0.0 and wiz != 0.0:
        cr, cg, cb, _ = chiang_eval(state, wox, woy, woz, wix, wiy, wiz)
        c = abs(wiz)
        fr += cr / c
        fg += cg / c
        fb += cb / c
    return fr, fg, fb


@kernel(allocates=False)
def selection(state, allow_d, allow_g, allow_t):
    """Unnormalised selection weights (coat, sheen, translucent, hair R, hair TT,
    Principled Hair) over the allowed kinds."""
    wc = state[S_EST_COAT] if allow_g else 0.0
    ws = state[S_EST_SHEEN] if allow_d else 0.0
    wt = state[S_EST_TRANS] if allow_d else 0.0    # diffuse to Cycles' Caustics switches
    whr = state[S_EST_HAIR_R] if allow_g else 0.0
    wht = state[S_EST_HAIR_TT] if allow_t else 0.0
    wch = state[S_EST_CHIANG] if (allow_g or allow_t) else 0.0
    return wc, ws, wt, whr, wht, wch


@kernel(allocates=False)
def mixture_pdf(state, wox, woy, woz, wix, wiy, wiz, qc, qs, qt, qhr, qht, qch):
    """sum q_i pdf_i over the coat, sheen, translucent and hair lobes (evaluation's)."""
    p = 0.0
    if qc > 0.0:
        ox, oy, oz = _about_coat(state, wox, woy, woz)
        ix, iy, iz = _about_coat(state, wix, wiy, wiz)
        p += qc * mf.reflection_pdf(ox, oy, oz, ix, iy, iz, state[S_COAT_ALPHA])
    if qs > 0.0:
        x, y, z = _about_sheen(state, wix, wiy, wiz)
        p += qs * sheen.pdf(x, y, z, state[S_SHEEN_CX], state[S_SHEEN_CY],
                            state[S_SHEEN_A], state[S_SHEEN_B])
    if qt > 0.0:
        p += qt * translucent.pdf(woz, wiz)
    if qhr > 0.0:
        p += qhr * hair_pdf(state, wox, woy, woz, wix, wiy, wiz, False)
    if qht > 0.0:
        p += qht * hair_pdf(state, wox, woy, woz, wix, wiy, wiz, True)
    if qch > 0.0:
        p += qch * chiang_eval(state, wox, woy, woz, wix, wiy, wiz)[3]
    return p


@kernel(allocates=False)
def sample(state, wox, woy, woz, lobe, u1, u2):
    """A direction from lobe 0 (coat), 1 (sheen) or 2 (translucent): (wi, valid)."""
    if lobe == 0:
        if state[S_COAT_N + 2] == 1.0:
            return mf.reflection_sample(wox, woy, woz, state[S_COAT_ALPHA], u1, u2)
        ox, oy, oz = _about_coat(state, wox, woy, woz)
        x, y, z, valid = mf.reflection_sample(ox, oy, oz, state[S_COAT_ALPHA], u1, u2)
        wx, wy, wz = to_world(x, y, z, state[S_COAT_N], state[S_COAT_N + 1],
                              state[S_COAT_N + 2])
        return wx, wy, wz, valid
    if lobe == 1:
        x, y, z = sheen.sample(u1, u2, state[S_SHEEN_CX], state[S_SHEEN_CY],
                               state[S_SHEEN_A], state[S_SHEEN_B])
        if state[S_SHEEN_N + 2] == 1.0:
            return x, y, z, z > 0.0 and woz > 0.0
        wx, wy, wz = to_world(x, y, z, state[S_SHEEN_N], state[S_SHEEN_N + 1],
                              state[S_SHEEN_N + 2])
        return wx, wy, wz, z > 0.0
    x, y, z = translucent.sample(u1, u2)
    return x, y, z, z < 0.0
