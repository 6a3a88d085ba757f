"""Evaluating Blender's Principled BSDF (principled.py's lobes, one hit at a time): f of
the lobes a light of given kinds sees, from the state principled.setup filled. The base's
diffuse (Lambert, or Oren-Nayar: oren_nayar.py) under its specular layer, the specular,
metal and glass microfacet lobes (`base_glossy`), scaled by the layers above them, and
the layers' own lobes beside (layers.py: sheen, coat, translucency, hair)."""
from __future__ import annotations

from ..jit import kernel
from . import dielectric, fresnel, layers, oren_nayar, specular_tint
from . import microfacet as mf
from .reflection_lobes import metal_fresnel, reflection_eval
from .state import (S_DIFFUSE, S_ALPHA, S_BECKMANN, S_ETA_GLASS, S_ETA_SPEC, S_GLASS_SMOOTH,
                    S_GLASS_RTINT, S_GLASS_TINTED, S_LAYERED, S_MS_GLASS, S_MS_METAL,
                    S_MS_SPEC,
                    S_ON, S_REFRACT_ONLY, S_SPEC_TINTED, S_TINT, S_W_GLASS, S_W_METAL,
                    S_W_SPEC, S_WALTER)
from ..warp import INV_PI


@kernel(allocates=False)
def eval_seen(state, wox, woy, woz, wix, wiy, wiz, see_d, see_g, see_t):
    """f(wo, wi) in 1/sr of the lobes of the kinds a light is seen by (see_d: diffuse,
    see_g: glossy reflection, see_t: transmission; engine.visibility), delta parts
    excluded."""
    fr = 0.0
    fg = 0.0
    fb = 0.0
    # Lambert under the specular layer; as Cycles' diffuse closure it asks only that the
    # light be above the shading normal, not the view (which a smooth mesh's silhouette
    # can put under it)
    if see_d and wiz > 0.0:
        if state[S_ON + 1] > 0.0:          # with roughness: Oren-Nayar
            fr, fg, fb = oren_nayar.value(state, wox, woy, woz, wix, wiy, wiz)
        else:
            fr = state[S_DIFFUSE] * INV_PI
            fg = state[S_DIFFUSE + 1] * INV_PI
            fb = state[S_DIFFUSE + 2] * INV_PI
    gr, gg, gb = base_glossy(state, wox, woy, woz, wix, wiy, wiz, see_g, see_t)
    if state[S_LAYERED] == 0.0:
        return fr + gr, fg + gg, fb + gb
    s = layers.S_BASE_SCALE
    lr, lg, lb = layers.eval_seen(state, wox, woy, woz, wix, wiy, wiz, see_d, see_g, see_t)
    return (fr + gr * state[s] + lr, fg + gg * state[s + 1] + lg,
            fb + gb * state[s + 2] + lb)


@kernel(allocates=False)
def base_diffuse(state, wox, woy, woz):
    """f (1/sr) of the diffuse lobe alone (Lambert, or Oren-Nayar at the normal), the
    direction-independent value a bent frame's diffuse lobe takes (nodes.shading)."""
    if state[S_ON + 1] > 0.0:
        return oren_nayar.value(state, wox, woy, woz, 0.0, 0.0, 1.0)
    return (state[S_DIFFUSE] * INV_PI, state[S_DIFFUSE + 1] * INV_PI,
            state[S_DIFFUSE + 2] * INV_PI)


@kernel(allocates=False)
def sheen_seen(state, woz, wix, wiy, wiz):
    """f (1/sr) of the sheen alone towards local wi, about its own normal
    (layers.sheen_seen): nothing without the layers."""
    if state[S_LAYERED] == 0.0:
        return 0.0, 0.0, 0.0
    return layers.sheen_seen(state, woz, wix, wiy, wiz)


@kernel(allocates=False)
def translucent_seen(state, wiz):
    """f (1/sr) of the translucent lobe alone (a Translucent BSDF's, layers.py) towards
    local wi: nothing above the surface, or without that lobe."""
    if state[S_LAYERED] == 0.0 or not state[layers.S_EST_TRANS] > 0.0 or not wiz < 0.0:
        return 0.0, 0.0, 0.0
    t = INV_PI
    return (state[layers.S_TRANS] * t, state[layers.S_TRANS + 1] * t,
            state[layers.S_TRANS + 2] * t)


@kernel(allocates=False)
def base_glossy(state, wox, woy, woz, wix, wiy, wiz, see_g, see_t):
    """f (1/sr) of the specular, metal and glass lobes a light of these kinds sees."""
    fr = 0.0
    fg = 0.0
    fb = 0.0
    w_spec = state[S_W_SPEC]
    w_metal = state[S_W_METAL]
    if see_g and (w_spec > 0.0 or w_metal > 0.0):
        base, hx, hy, hz = reflection_eval(state, wox, woy, woz, wix, wiy, wiz)
        cos_oh = min(max(mf.dot(wox, woy, woz, hx, hy, hz), 0.0), 1.0)
        if w_spec > 0.0 and state[S_SPEC_TINTED] != 0.0:
            bw = base * w_spec
            fr += specular_tint.reflectance(state, 0, cos_oh, state[S_ETA_SPEC]) * bw
            fg += specular_tint.reflectance(state, 1, cos_oh, state[S_ETA_SPEC]) * bw
            fb += specular_tint.reflectance(state, 2, cos_oh, state[S_ETA_SPEC]) * bw
        elif w_spec > 0.0:
            F = fresnel.dielectric(cos_oh, state[S_ETA_SPEC])
            v = F * (base * w_spec) * state[S_MS_SPEC]
            fr += v
            fg += v
            fb += v
        if w_metal > 0.0:
            bw = base * w_metal
            fr += metal_fresnel(state, 0, cos_oh) * bw * state[S_MS_METAL]
            fg += metal_fresnel(state, 1, cos_oh) * bw * state[S_MS_METAL + 1]
            fb += metal_fresnel(state, 2, cos_oh) * bw * state[S_MS_METAL + 2]
    w_glass = state[S_W_GLASS]
    if w_glass > 0.0 and state[S_GLASS_SMOOTH] == 0.0 and (see_g if wiz > 0.0 else see_t):
        f_r, f_t, F = dielectric.rough_eval_lobes(wox, woy, woz, wix, wiy, wiz,
                                               state[S_ETA_GLASS], state[S_ALPHA],
                                               state[S_REFRACT_ONLY] != 0.0,
                                               state[S_WALTER] != 0.0,
                                               state[S_BECKMANN] != 0.0)
        k0 = k1 = k2 = 1.0
        if state[S_GLASS_TINTED] != 0.0:        # Specular Tint, Thin Film: F_c for F
            refl = f_r > 0.0
            eta = state[S_ETA_GLASS]
            cos_i, eta_rel = dielectric.pair_cosine(wox, woy, woz, wix, wiy, wiz, eta)
            k0 = specular_tint.glass_factor(state, 0, F, eta, refl, cos_i, eta_rel)
            k1 = specular_tint.glass_factor(state, 1, F, eta, refl, cos_i, eta_rel)
            k2 = specular_tint.glass_factor(state, 2, F, eta, refl, cos_i, eta_rel)
        r, t = S_GLASS_RTINT, S_TINT
        fr += (f_r * state[r] + f_t * state[t]) * k0 * w_glass * state[S_MS_GLASS]
        fg += (f_r * state[r + 1] + f_t * state[t + 1]) * k1 * w_glass * state[S_MS_GLASS + 1]
        fb += (f_r * state[r + 2] + f_t * state[t + 2]) * k2 * w_glass * state[S_MS_GLASS + 2]
    return fr, fg, fb


@kernel(allocates=False)
def eval_f(state, wox, woy, woz, wix, wiy, wiz):
    """The whole BSDF f(wo, wi) in 1/sr, every lobe (delta parts excluded)."""
    return eval_seen(state, wox, woy, woz, wix, wiy, wiz, True, True, True)
