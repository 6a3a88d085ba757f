"""The hair lobes beside the Principled layers (layers.py): the Hair BSDF node's
Reflection and Transmission about the fibre's tangent (hair.py), and the Principled Hair
BSDF's Chiang closure (hair_chiang.py) with Cycles' bump test on triangles; their setup
from the row's per-hit columns (engine.kernels.hair_tangent writes them), value,
density and samples, in the layers' state slots (layer_slots.py)."""
from __future__ import annotations

from ..jit import kernel
from . import hair, hair_chiang
from .layer_slots import (S_HAIR_T, S_HAIR_R, S_HAIR_TT, S_HAIR_R_LOBE, S_HAIR_TT_LOBE,
                          S_CHIANG_W, S_CHIANG_SIGMA, S_CHIANG_LOBE, S_CHIANG_ALPHA,
                          S_CHIANG_ETA, S_CHIANG_H, S_CHIANG_T, S_CHIANG_ALBEDO,
                          S_EST_CHIANG, S_CHIANG_MESH, S_CHIANG_AS_SAMPLED)
from .params import (P_CHIANG, P_CHIANG_COLOR, P_CHIANG_IOR, P_CHIANG_MELANIN,
                     P_CHIANG_MODE, P_CHIANG_NG, P_CHIANG_OFFSET, P_CHIANG_RANDOM,
                     P_CHIANG_ROUGH, P_CHIANG_T, P_FILTER_ALPHA, P_HAIR_CURVE)


@kernel(allocates=False)
def chiang_setup(row, wox, woy, woz, state):
    """The Principled Hair closure's slots, as Cycles' svm closure and setup make them:
    Random Roughness scales both roughnesses by 1 + 2 (random - 1/2) amount."""
    w_max = 0.0
    for c in range(3):
        state[S_CHIANG_W + c] = max(row[P_CHIANG + c], 0.0)
        state[S_CHIANG_ALBEDO + c] = 0.0
        w_max = max(w_max, state[S_CHIANG_W + c])
    state[S_EST_CHIANG] = w_max
    state[S_CHIANG_AS_SAMPLED] = 0.0
    if not w_max > 0.0:
        return
    state[S_CHIANG_MESH] = 0.0 if row[P_HAIR_CURVE] != 0.0 else 1.0
    random = row[P_CHIANG_RANDOM + 2]
    k = 1.0 + 2.0 * (random - 0.5) * row[P_CHIANG_RANDOM + 1]
    rough = row[P_CHIANG_ROUGH] * k
    radial = row[P_CHIANG_ROUGH + 1] * k
    cr, cg, cb = row[P_CHIANG_COLOR], row[P_CHIANG_COLOR + 1], row[P_CHIANG_COLOR + 2]
    sr, sg, sb = hair_chiang.absorption(int(row[P_CHIANG_MODE]), cr, cg, cb,
                                        row[P_CHIANG_MELANIN], row[P_CHIANG_MELANIN + 1],
                                        cr, cg, cb, row[P_CHIANG_RANDOM], random, radial)
    state[S_CHIANG_SIGMA] = sr
    state[S_CHIANG_SIGMA + 1] = sg
    state[S_CHIANG_SIGMA + 2] = sb
    v, s, m0 = hair_chiang.remap(rough, radial, row[P_CHIANG_ROUGH + 2], row[P_FILTER_ALPHA])
    state[S_CHIANG_LOBE] = v
    state[S_CHIANG_LOBE + 1] = s
    state[S_CHIANG_LOBE + 2] = m0
    state[S_CHIANG_ALPHA] = row[P_CHIANG_OFFSET]
    eta = max(row[P_CHIANG_IOR], 1e-3)
    state[S_CHIANG_ETA] = eta
    # a hit on the back of a triangle: Cycles turns Ng to the view and negates dPdu
    tx, ty, tz = row[P_CHIANG_T], row[P_CHIANG_T + 1], row[P_CHIANG_T + 2]
    gx, gy, gz = row[P_CHIANG_NG], row[P_CHIANG_NG + 1], row[P_CHIANG_NG + 2]
    if gx * wox + gy * woy + gz * woz < 0.0:
        gx, gy, gz, tx, ty, tz = -gx, -gy, -gz, -tx, -ty, -tz
    h = hair_chiang.offset_h(gx, gy, gz, tx, ty, tz, wox, woy, woz)
    state[S_CHIANG_H] = h
    state[S_CHIANG_T], state[S_CHIANG_T + 1], state[S_CHIANG_T + 2] = tx, ty, tz
    ar, ag, ab = hair_chiang.albedo(tx, ty, tz, h, sr, sg, sb, v, eta, wox, woy, woz)
    state[S_CHIANG_ALBEDO] = ar
    state[S_CHIANG_ALBEDO + 1] = ag
    state[S_CHIANG_ALBEDO + 2] = ab


@kernel(allocates=False)
def _bump_shadowed(state, wox, woy, woz, wix, wiy, wiz):
    """Cycles' bump_shadowing_term for the closure evaluated on a triangle: its normal
    (Y = X x wo, hair_chiang's frame) is not the surface's, so light is refused where
    N.wi, N.Y and Y.wi do not agree in sign (N, the shading normal, is local z). Not on
    strands, and not for the closure's own sampled direction (Cycles' bsdf_sample)."""
    if state[S_CHIANG_MESH] == 0.0 or state[S_CHIANG_AS_SAMPLED] != 0.0:
        return False
    tx, ty, tz = state[S_CHIANG_T], state[S_CHIANG_T + 1], state[S_CHIANG_T + 2]
    yx = ty * woz - tz * woy
    yy = tz * wox - tx * woz
    yz = tx * woy - ty * wox
    return wiz * yz * (yx * wix + yy * wiy + yz * wiz) < 0.0


@kernel(allocates=False)
def chiang_eval(state, wox, woy, woz, wix, wiy, wiz):
    """The Principled Hair closure's (F_r, F_g, F_b, pdf) (hair_chiang.evaluate), its
    weight included in F: f |cos|, as Cycles' bsdf_eval (zero where `_bump_shadowed`)."""
    if _bump_shadowed(state, wox, woy, woz, wix, wiy, wiz):
        return 0.0, 0.0, 0.0, 0.0
    T, L = S_CHIANG_T, S_CHIANG_LOBE
    Fr, Fg, Fb, p = hair_chiang.evaluate(
        state[T], state[T + 1], state[T + 2], state[S_CHIANG_H], state[S_CHIANG_SIGMA],
        state[S_CHIANG_SIGMA + 1], state[S_CHIANG_SIGMA + 2], state[L], state[L + 1],
        state[L + 2], state[S_CHIANG_ALPHA], state[S_CHIANG_ETA], wox, woy, woz, wix, wiy,
        wiz)
    W = S_CHIANG_W
    return Fr * state[W], Fg * state[W + 1], Fb * state[W + 2], p


@kernel(allocates=False)
def chiang_sample(state, wox, woy, woz, u_p, u1, u2):
    """A direction from the Principled Hair closure: (wi, F (weight included), pdf, p),
    p 0 for its reflection, 1..3 through the fibre. Until `chiang_sampled_done`,
    chiang_eval gives this direction its value without Cycles' bump test, as Cycles'
    sample does."""
    state[S_CHIANG_AS_SAMPLED] = 1.0
    T, L = S_CHIANG_T, S_CHIANG_LOBE
    x, y, z, Fr, Fg, Fb, p, lobe = hair_chiang.sample(
        state[T], state[T + 1], state[T + 2], state[S_CHIANG_H], state[S_CHIANG_SIGMA],
        state[S_CHIANG_SIGMA + 1], state[S_CHIANG_SIGMA + 2], state[L], state[L + 1],
        state[L + 2], state[S_CHIANG_ALPHA], state[S_CHIANG_ETA], wox, woy, woz, u_p, u1,
        u2)
    W = S_CHIANG_W
    return x, y, z, Fr * state[W], Fg * state[W + 1], Fb * state[W + 2], p, lobe


@kernel(allocates=False)
def chiang_sampled_done(state):
    state[S_CHIANG_AS_SAMPLED] = 0.0


@kernel(allocates=False)
def hair_pdf(state, wox, woy, woz, wix, wiy, wiz, transmission):
    """The hair R (or TT) lobe's evaluation pdf, f cos per unit colour (hair.pdf)."""
    k = S_HAIR_TT_LOBE if transmission else S_HAIR_R_LOBE
    return hair.pdf(state[S_HAIR_T], state[S_HAIR_T + 1], state[S_HAIR_T + 2], state[k],
                    state[k + 1], state[k + 2], transmission, wox, woy, woz, wix, wiy, wiz)


@kernel(allocates=False)
def hair_sample(state, wox, woy, woz, transmission, u1, u2):
    """A direction from the hair R (or TT) lobe, on either side: (wi, its pdf, colour)."""
    k = S_HAIR_TT_LOBE if transmission else S_HAIR_R_LOBE
    x, y, z, p = hair.sample(state[S_HAIR_T], state[S_HAIR_T + 1], state[S_HAIR_T + 2],
                             state[k], state[k + 1], state[k + 2], transmission, wox, woy,
                             woz, u1, u2)
    c = S_HAIR_TT if transmission else S_HAIR_R
    return x, y, z, p, state[c], state[c + 1], state[c + 2]
