"""Principled's Specular Tint on the dielectric specular layer, as Cycles renders it (its
"generalized Schlick" Fresnel with the real dielectric curve, svm/closure.h and
closure/bsdf_microfacet.h): the layer's reflectance in channel c is

    F_c(mu) = f0_c + (1 - f0_c) s(mu),   s = (F(mu) - F0) / (1 - F0) in [0, 1],

with F the dielectric Fresnel of the layer's IOR, F0 = F(1) and f0_c = min(F0 tint_c, 1):
the tint colours the reflection at the normal and fades towards white at grazing
angles. Everything that depends on the layer's Fresnel follows the same remap, which is
linear in F: the multiscatter Fss (Cycles: f0 + (1 - f0) s(Fss)), Cycles' estimate of the
layer's albedo that dims the diffuse below (f0 + (1 - f0) s of its table), and DRT's
floor on it, the single-scattering albedo (a_c E + b_c A with E the GGX albedo for F = 1,
A the untinted layer's, b_c = (1 - f0_c) / (1 - F0), a_c = f0_c - b_c F0). The diffuse
below is dimmed by the largest channel's albedo, as Cycles' closure_layering_weight
does. A white tint never reaches this module (principled.setup), so untinted materials
pay nothing (principle 3). The metal lobe's tint is F82-tint (fresnel.py).

A Thin Film takes this module's per-channel path too (principled.setup): F_c is then the
film's reflectance (thin_film.specular_layer, with the tint's F0 scaling), and the
albedo the layer below sees is F_c at wo (Cycles' estimate for a film: no table, no
floor) times the closure weight's multiscatter darkening, E times the factor.

The glass lobe (Principled's transmission) takes the same F_c (a film's too), from
F0 = F(1) of its IOR: its reflection carries F_c where the untinted lobe carries F, its
refraction 1 - F_c where it carries 1 - F (Cycles: reflectance F_c, transmittance (1 - F_c) times
the refraction tint). `glass_factor` is that ratio per channel at the pair's own F, so
the dielectric kernels stay as they are; the reflect/refract choice keeps F (an
importance choice; the weights carry the tint). Its multiscatter compensation stays
the refraction tint's, as in Cycles.
"""
from __future__ import annotations

from ..jit import kernel
from . import fresnel
from . import multiscatter as ms
from . import thin_film
from .params import P_SPEC_TINT
from .state import (S_FILM_IOR, S_GLASS_F0, S_GLASS_IOR, S_GLASS_TINTED, S_MS_E, S_SPEC_F0,
                    S_SPEC_MS, S_SPEC_TINTED, S_THIN_FILM)


@kernel
def is_tinted(row):
    return (row[P_SPEC_TINT] != 1.0 or row[P_SPEC_TINT + 1] != 1.0
            or row[P_SPEC_TINT + 2] != 1.0)


@kernel
def remap(F, f0_real):
    """s = (F - F0) / (1 - F0), clamped to [0, 1] (Cycles' inverse_lerp, saturated)."""
    den = 1.0 - f0_real
    if not den > 1e-12:
        return 1.0
    return min(max((F - f0_real) / den, 0.0), 1.0)


@kernel(allocates=False)
def setup(row, multiscatter, cos_o, alpha, eta_spec, exact, tables, state):
    """Fill the tinted layer's slots (f0 and multiscatter factor per channel) and return
    its albedo at wo as the diffuse below sees it. `exact`: the untinted layer's
    single-scattering albedo (albedo.specular_albedo)."""
    state[S_SPEC_TINTED] = 1.0
    f0_real = fresnel.f0_from_ior(eta_spec)
    estimate = ms.layer_reflectance(cos_o, alpha, eta_spec, tables)
    s_est = remap(estimate, f0_real)
    e_white = ms.ggx_albedo(cos_o, alpha, tables)          # the layer with F = 1
    E_avg = ms.ggx_albedo_avg(alpha, tables) if multiscatter else 1.0
    s_ss = remap(ms.dielectric_fresnel_avg(eta_spec, tables), f0_real)
    den = max(1.0 - f0_real, 1e-12)
    albedo = 0.0
    for c in range(3):
        f0 = min(max(f0_real * row[P_SPEC_TINT + c], 0.0), 1.0)
        state[S_SPEC_F0 + c] = f0
        factor = 1.0
        if multiscatter:
            factor = ms.compensation(state[S_MS_E], E_avg, f0 + (1.0 - f0) * s_ss)
        state[S_SPEC_MS + c] = factor
        if state[S_THIN_FILM] > 0.0:
            film = thin_film.specular_layer(c, cos_o, state[S_THIN_FILM], state[S_FILM_IOR],
                                            eta_spec, f0)
            # Cycles' closure weight carries the multiscatter darkening E (1 + Fms (1 -
            # E) / E) (S_MS_E times the factor), its estimate the film's reflectance
            albedo = max(albedo, film * state[S_MS_E] * factor)
            continue
        b = (1.0 - f0) / den
        floor = (f0 - b * f0_real) * e_white + b * exact
        cycles = (f0 + (1.0 - f0) * s_est) * state[S_MS_E]
        albedo = max(albedo, max(cycles, floor) * factor)
    return albedo


@kernel(allocates=False)
def reflectance(state, c, cos_oh, eta_spec):
    """F_c of the tinted layer times its multiscatter factor, at cos(wo, h) = cos_oh."""
    f0 = state[S_SPEC_F0 + c]
    if state[S_THIN_FILM] > 0.0:
        return thin_film.specular_layer(c, cos_oh, state[S_THIN_FILM], state[S_FILM_IOR],
                                        eta_spec, f0) * state[S_SPEC_MS + c]
    s = remap(fresnel.dielectric(cos_oh, eta_spec), fresnel.f0_from_ior(eta_spec))
    return (f0 + (1.0 - f0) * s) * state[S_SPEC_MS + c]


@kernel
def glass_setup(row, eta, ior, state):
    """The glass lobe's tinted F0 per channel (Cycles: F0(ior) x tint, saturated); ior
    its own (for a Thin Film on it)."""
    state[S_GLASS_TINTED] = 1.0
    state[S_GLASS_IOR] = ior
    f0_real = fresnel.f0_from_ior(eta)
    for c in range(3):
        state[S_GLASS_F0 + c] = min(max(f0_real * row[P_SPEC_TINT + c], 0.0), 1.0)


@kernel(allocates=False)
def glass_factor(state, c, F, eta, reflected, cos_i, eta_rel):
    """F_c / F for a reflection, (1 - F_c) / (1 - F) for a refraction, at the pair's
    Fresnel reflectance F (dielectric.rough_eval_lobes, smooth_sample), which it has at
    cos_i of wo to the pair's half vector and the relative index eta_rel of that side.
    Under a Thin Film F_c is the film's reflectance there (Cycles: the film's index
    relative to the side the light comes from, 1 outside or the glass's inside), and F is
    the film's average over the channels by which the choice was made
    (thin_film.glass_choice)."""
    f0 = state[S_GLASS_F0 + c]
    if state[S_THIN_FILM] > 0.0:
        Fc = thin_film.glass(c, cos_i, state[S_THIN_FILM], state[S_FILM_IOR],
                             state[S_GLASS_IOR], eta_rel, f0)
    else:
        Fc = f0 + (1.0 - f0) * remap(F, fresnel.f0_from_ior(eta))
    if reflected:
        return Fc / F if F > 0.0 else 0.0
    return (1.0 - Fc) / (1.0 - F) if F < 1.0 else 0.0


@kernel(allocates=False)
def glass_film(state):
    """The glass lobe's film for dielectric.rough_sample, rough_pdf and smooth_sample
    (thin_film.glass_choice): NO_FILM unless a Thin Film lies on it."""
    if state[S_THIN_FILM] > 0.0 and state[S_GLASS_TINTED] != 0.0:
        return (state[S_THIN_FILM], state[S_FILM_IOR], state[S_GLASS_IOR],
                state[S_GLASS_F0], state[S_GLASS_F0 + 1], state[S_GLASS_F0 + 2])
    return thin_film.NO_FILM
