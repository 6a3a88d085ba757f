"""Cycles' multiple-scattering factors of the Principled base lobes at wo, into the
per-hit state (principled.setup calls `compensate`; multiscatter.py has the maths)."""
from __future__ import annotations

from ..jit import kernel
from . import multiscatter as ms
from .state import (S_GLASS_SMOOTH, S_METAL_B, S_METAL_CONST, S_METAL_F0, S_METAL_F82,
                    S_MS_E, S_MS_GLASS, S_MS_METAL, S_MS_SPEC, S_REFRACT_ONLY, S_TINT)


@kernel(allocates=False)
def compensate(multiscatter, woz, cos_o, alpha, alpha_glass, eta_spec, eta_glass, w_spec, m,
               w_glass, tables, state):
    """The multiple-scattering factors at wo: 1 unless
    `multiscatter`; alpha: the reflection lobes' (an anisotropic one's sqrt(alpha_x
    alpha_y), as Cycles' estimate), alpha_glass the glass lobe's (always isotropic); the
    lobe weights, metal F0 and Fresnel kind and the tint must be in
    the state already."""
    state[S_MS_SPEC] = 1.0
    state[S_MS_E] = 1.0
    for c in range(3):
        state[S_MS_METAL + c] = 1.0
        state[S_MS_GLASS + c] = 1.0
    if not multiscatter:
        return
    if w_spec > 0.0 or m > 0.0:
        E = ms.ggx_albedo(cos_o, alpha, tables)
        E_avg = ms.ggx_albedo_avg(alpha, tables)
        state[S_MS_E] = E
        if w_spec > 0.0:
            state[S_MS_SPEC] = ms.compensation(E, E_avg,
                                               ms.dielectric_fresnel_avg(eta_spec, tables))
        if m > 0.0:
            for c in range(3):
                f0 = state[S_METAL_F0 + c]
                # a Glossy BSDF's reflectance is its colour at every angle (Cycles' Fss)
                if state[S_METAL_CONST] != 0.0:
                    f_avg = f0
                elif state[S_METAL_F82] != 0.0:     # Cycles' fresnel_f82_Fss
                    f_avg = ms.schlick_fresnel_avg(f0) - state[S_METAL_B + c] / 126.0
                else:
                    f_avg = ms.schlick_fresnel_avg(f0)
                state[S_MS_METAL + c] = ms.compensation(E, E_avg, f_avg)
    if w_glass > 0.0 and state[S_GLASS_SMOOTH] == 0.0 and state[S_REFRACT_ONLY] == 0.0:
        eta_rel = 1.0 / eta_glass if woz < 0.0 else eta_glass
        c_o = min(abs(woz), 1.0)
        E = ms.glass_albedo(c_o, alpha_glass, eta_rel, tables)
        E_avg = ms.glass_albedo_avg(alpha_glass, eta_rel, tables)
        for c in range(3):
            state[S_MS_GLASS + c] = ms.compensation(E, E_avg, state[S_TINT + c])
