"""A surface vertex's light split by lobe kind, for Cycles' light passes
(engine.kernels.light_tally): the shares of next-event estimation's light at the first
vertex (`light_shares`), of the direction the path leaves it by (`bounce_shares`), and
what the first surface's lobes of each kind weigh (`lobe_colours`, the Color passes).

A share is the lobe kind's part of the BSDF's value f(wo, wi), per channel: its diffuse
lobes (Lambert, sheen, translucency), its glossy reflection (specular, metal, coat, a
glass's reflection, hair R) and its transmission (a glass's refraction, hair TT),
evaluated by
principled.eval_seen restricted to that kind. Where a Normal Map bends the normal, the
diffuse part is path_vertex's bent_diffuse and bent_translucent, as the light's is."""
from __future__ import annotations

import math

from .bsdf import fresnel, layers, thin_film
from .bsdf import principled as bsdf
from .bsdf.principled import GLOSSY
from .bsdf import microfacet as mf
from .bsdf.state import (S_ALPHA, S_DIFFUSE, S_E_SPEC, S_ETA_GLASS, S_FILM_IOR, S_GLASS_F0,
                         S_GLASS_IOR, S_GLASS_TINTED, S_LAYERED, S_METAL_B, S_METAL_CONST,
                         S_METAL_F0, S_METAL_F82, S_MS_E, S_MS_METAL, S_REFRACT_ONLY, S_SSS,
                         S_THIN_FILM, S_TINT, S_W_GLASS, S_W_METAL, S_W_SPEC)
from .jit import kernel
from .light_tally import DIFFUSE_CLASS, GLOSSY_CLASS, TRANSMISSION_CLASS, one_class, \
    surface_shares
from ..nodes.shading import bent_diffuse, bent_diffuse_lobes

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
                 s0x, s0y, s0z, nx, ny, nz, rx, ry, rz, wx, wy, wz, correct):
    """Shares of next-event estimation's value f (path_vertex.shade's, towards the light
    at local l, world w; with a bent normal it includes the cosine; s the surface's own
    normal, n the frame's, r the raw bent one)."""
    dr = dg = db = 0.0
    if see_d:
        if bent:
            dr, dg, db = bent_diffuse_lobes(state, wox, woy, woz, s0x, s0y, s0z, nx, ny, nz,
                                            rx, ry, rz, wx, wy, wz, correct)
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
                                  wz, ix, iy, iz, correct)
        tr, tg, tb = bsdf.translucent_seen(state, iz)     # as sampled: no bump shadowing
        dr, dg, db = dr + tr * c, dg + tg * c, db + tb * c
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
    the metal's albedo (Schlick's Fresnel over its lobe, E and the multiscatter factor),
    a glass's Fresnel reflectance and its tinted transmittance 1 - F; a coat's albedo on
    top, every base lobe dimmed by the layers."""
    s = schlick_share(woz, state[S_ALPHA]) if state[S_W_METAL] > 0.0 else 0.0
    d0, g0, t0 = _channel_colours(state, woz, s, 0)
    d1, g1, t1 = _channel_colours(state, woz, s, 1)
    d2, g2, t2 = _channel_colours(state, woz, s, 2)
    return (d0, d1, d2), (g0, g1, g2), (t0, t1, t2)


@kernel(allocates=False)
def schlick_share(woz, alpha):
    """s = the mean of (1 - wo.h)^5 over GGX's visible normals at the view (Heitz 2018),
    so that mix(F0, 1, s) is Schlick's Fresnel averaged over the lobe, as Cycles'
    albedo estimate of a metal takes it; a 4 x 4 stratified quadrature (only when the
    Color passes are asked for)."""
    cos_o = min(max(woz, 0.0), 1.0)
    sin_o = math.sqrt(max(1.0 - cos_o * cos_o, 0.0))
    total = 0.0
    for i in range(4):
        for j in range(4):
            hx, hy, hz = mf.sample_visible_normal(sin_o, 0.0, cos_o, alpha, (i + 0.5) / 4.0,
                                                  (j + 0.5) / 4.0)
            k = 1.0 - min(max(sin_o * hx + cos_o * hz, 0.0), 1.0)
            total += k * k * k * k * k
    return total / 16.0


@kernel(allocates=False)
def _channel_colours(state, woz, s, c):
    """lobe_colours in channel c: (diffuse, glossy, transmission); s: schlick_share."""
    cos_o = min(max(woz, 0.0), 1.0)
    layered = state[S_LAYERED] != 0.0
    m = state[S_W_METAL]
    w_glass = state[S_W_GLASS]
    film = state[S_THIN_FILM]
    F = fresnel.dielectric(cos_o, state[S_ETA_GLASS]) if w_glass > 0.0 else 0.0
    if film > 0.0 and w_glass > 0.0 and state[S_GLASS_TINTED] != 0.0:
        # a Thin Film: its reflectance at wo (Cycles' estimate for a film, no table)
        F = thin_film.glass(c, cos_o, film, state[S_FILM_IOR], state[S_GLASS_IOR],
                            state[S_ETA_GLASS], state[S_GLASS_F0 + c])
    refl = 0.0 if state[S_REFRACT_ONLY] != 0.0 else w_glass * F
    scale = state[layers.S_BASE_SCALE + c] if layered else 1.0
    d = state[S_DIFFUSE + c] + state[S_SSS + c]
    coat = 0.0
    hair_r = hair_tt = 0.0
    if layered:
        d += state[layers.S_SHEEN_W + c] + state[layers.S_TRANS + c]
        coat = state[layers.S_EST_COAT]
        # a Hair BSDF's colour (Cycles' albedo of its closures is their weight)
        hair_r, hair_tt = state[layers.S_HAIR_R + c], state[layers.S_HAIR_TT + c]
        # a Principled Hair's: its weight times Cycles' albedo estimate, glossy
        hair_r += state[layers.S_CHIANG_W + c] * state[layers.S_CHIANG_ALBEDO + c]
    metal = 0.0
    if m > 0.0 and film > 0.0 and state[S_METAL_CONST] == 0.0:
        b = state[S_METAL_B + c] if state[S_METAL_F82] != 0.0 else 0.0
        metal = m * thin_film.metal(c, cos_o, film, state[S_FILM_IOR], state[S_METAL_F0 + c],
                                    b) * state[S_MS_E] * state[S_MS_METAL + c]
    elif m > 0.0:
        # the lobe's albedo: Fresnel over the lobe (a Glossy BSDF's is its colour) times
        # the single-scattering albedo E and the multiscatter factor (Cycles' estimate)
        f0 = state[S_METAL_F0 + c]
        f = f0 if state[S_METAL_CONST] != 0.0 else f0 + (1.0 - f0) * s
        metal = m * f * state[S_MS_E] * state[S_MS_METAL + c]
    g = scale * (state[S_W_SPEC] * state[S_E_SPEC] + metal + refl) + coat + hair_r
    t = scale * w_glass * (1.0 - F) * state[S_TINT + c] + hair_tt
    return d, g, t
