"""A surface vertex's light split by lobe kind, for Cycles' light passes
(engine.kernels.light_tally): the shares of next-event estimation's light at the first
vertex (`light_shares`), of the direction the path leaves it by (`bounce_shares`), and
what the first surface's lobes of each kind weigh (`lobe_colours`, the Color passes).

A share is the lobe kind's part of the BSDF's value f(wo, wi), per channel: its diffuse
lobes (Lambert, sheen, translucency), its glossy reflection (specular, metal, coat, a
glass's reflection) and its transmission (a glass's refraction), evaluated by
principled.eval_seen restricted to that kind. Where a Normal Map bends the normal, the
diffuse part is path_vertex's bent_diffuse, as the light itself is."""
from __future__ import annotations

from .bsdf import fresnel, layers
from .bsdf import principled as bsdf
from .bsdf.principled import GLOSSY
from .bsdf.reflection_lobes import metal_fresnel
from .bsdf.state import (S_DIFFUSE, S_E_SPEC, S_ETA_GLASS, S_LAYERED, S_MS_METAL,
                         S_REFRACT_ONLY, S_SSS, S_TINT, S_W_GLASS, S_W_METAL, S_W_SPEC)
from .jit import kernel
from .light_tally import DIFFUSE_CLASS, GLOSSY_CLASS, TRANSMISSION_CLASS, one_class, \
    surface_shares
from ..nodes.shading import bent_diffuse

NO_SHARES = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@kernel(allocates=False)
def _shares(state, wox, woy, woz, wix, wiy, wiz, see_g, see_t, fr, fg, fb, dr, dg, db,
            fallback):
    """Shares of f whose diffuse part is d: the rest divided between glossy reflection
    and transmission as their own values at wi divide it."""
    gr, gg, gb = bsdf.eval_seen(state, wox, woy, woz, wix, wiy, wiz, False, see_g, False)
    er, eg, eb = bsdf.eval_seen(state, wox, woy, woz, wix, wiy, wiz, False, see_g, see_t)
    kr = gr / er if er > 0.0 else (1.0 if fallback == GLOSSY_CLASS else 0.0)
    kg = gg / eg if eg > 0.0 else (1.0 if fallback == GLOSSY_CLASS else 0.0)
    kb = gb / eb if eb > 0.0 else (1.0 if fallback == GLOSSY_CLASS else 0.0)
    return surface_shares(dr, dg, db, (fr - dr) * kr, (fg - dg) * kg, (fb - db) * kb,
                          fr, fg, fb, fallback)


@kernel(allocates=False)
def light_shares(state, wox, woy, woz, lx, ly, lz, see_d, see_g, see_t, bent, fr, fg, fb,
                 s0x, s0y, s0z, rx, ry, rz, wx, wy, wz, correct):
    """Shares of next-event estimation's value f (path_vertex.shade's, towards the light
    at local l, world w; with a bent normal it includes the cosine)."""
    dr = dg = db = 0.0
    if see_d:
        if bent:
            dr, dg, db = bent_diffuse(state, wox, woy, woz, s0x, s0y, s0z, rx, ry, rz, wx,
                                      wy, wz, correct)
        else:
            dr, dg, db = bsdf.eval_seen(state, wox, woy, woz, lx, ly, lz, True, False, False)
    return _shares(state, wox, woy, woz, lx, ly, lz, see_g, see_t, fr, fg, fb, dr, dg, db,
                   DIFFUSE_CLASS)


@kernel(allocates=False)
def bounce_shares(state, wox, woy, woz, ix, iy, iz, kind, delta, bent, s0x, s0y, s0z, rx,
                  ry, rz, wx, wy, wz, correct):
    """Shares of the BSDF's value in the sampled direction (local i, world w) of lobe
    kind `kind` (a delta lobe: that kind alone)."""
    cls = DIFFUSE_CLASS if kind == 0 else (GLOSSY_CLASS if kind == GLOSSY
                                           else TRANSMISSION_CLASS)
    if delta:
        return one_class(cls)
    fr, fg, fb = bsdf.eval_seen(state, wox, woy, woz, ix, iy, iz, False, True, True)
    if bent:
        c = abs(iz)
        dr, dg, db = bent_diffuse(state, wox, woy, woz, s0x, s0y, s0z, rx, ry, rz, wx, wy,
                                  wz, correct)
        fr, fg, fb = fr * c + dr, fg * c + dg, fb * c + db
    else:
        dr, dg, db = bsdf.eval_seen(state, wox, woy, woz, ix, iy, iz, True, False, False)
        fr, fg, fb = fr + dr, fg + dg, fb + db
    return _shares(state, wox, woy, woz, ix, iy, iz, True, True, fr, fg, fb, dr, dg, db, cls)


@kernel(allocates=False)
def lobe_colours(state, woz):
    """What the lobes of each kind weigh at this hit for the view's cosine woz (RGB
    tuples: diffuse, glossy, transmission), the Color passes' values. Cycles writes each
    closure's weight times its albedo estimate at the view: the diffuse colour under the
    specular layer (and sheen, translucency and subsurface), the specular layer's albedo,
    the metal's Fresnel at the view, a glass's Fresnel reflectance and its tinted
    transmittance 1 - F; a coat's albedo on top, every base lobe dimmed by the layers."""
    d0, g0, t0 = _channel_colours(state, woz, 0)
    d1, g1, t1 = _channel_colours(state, woz, 1)
    d2, g2, t2 = _channel_colours(state, woz, 2)
    return (d0, d1, d2), (g0, g1, g2), (t0, t1, t2)


@kernel(allocates=False)
def _channel_colours(state, woz, c):
    """lobe_colours in channel c: (diffuse, glossy, transmission)."""
    cos_o = min(max(woz, 0.0), 1.0)
    layered = state[S_LAYERED] != 0.0
    m = state[S_W_METAL]
    w_glass = state[S_W_GLASS]
    F = fresnel.dielectric(cos_o, state[S_ETA_GLASS]) if w_glass > 0.0 else 0.0
    refl = 0.0 if state[S_REFRACT_ONLY] != 0.0 else w_glass * F
    scale = state[layers.S_BASE_SCALE + c] if layered else 1.0
    d = state[S_DIFFUSE + c] + state[S_SSS + c]
    coat = 0.0
    if layered:
        d += state[layers.S_SHEEN_W + c] + state[layers.S_TRANS + c]
        coat = state[layers.S_EST_COAT]
    metal = m * metal_fresnel(state, c, cos_o) * state[S_MS_METAL + c] if m > 0.0 else 0.0
    g = scale * (state[S_W_SPEC] * state[S_E_SPEC] + metal + refl) + coat
    t = scale * w_glass * (1.0 - F) * state[S_TINT + c]
    return d, g, t
