"""The reflection shared by the Principled specular and metal lobes, from the per-hit
state: the microfacet lobe (GGX or Beckmann, microfacet.py and beckmann.py, or the
lecture's Blinn-Phong) and the metal lobe's Fresnel factor: Schlick's from F0
(Principled), Cycles' F82-tint where a Specular Tint is set (fresnel.py), under a Thin
Film (thin_film.py), or F0 itself at every angle (a Glossy BSDF). principled.py calls
these; the state's slots: state.py."""
from __future__ import annotations

from ..jit import kernel
from . import anisotropic, blinn_phong, fresnel, thin_film
from . import distribution as dist
from . import microfacet as mf
from .params import P_SPEC_TINT
from .state import (S_ALPHA, S_ANISO, S_BECKMANN, S_BLINN, S_EXPONENT, S_FILM_IOR, S_METAL_B,
                    S_METAL_CONST, S_METAL_F0, S_METAL_F82, S_THIN_FILM)


@kernel(allocates=False)
def metal_fresnel(state, c, cos_oh):
    """The metal lobe's Fresnel factor in channel c: Schlick's from F0 (Principled),
    F82-tint where Specular Tint is not white, or F0 itself at every angle (a Glossy
    BSDF: Cycles gives it no Fresnel term, its colour is the closure's weight)."""
    if state[S_METAL_CONST] != 0.0:
        return state[S_METAL_F0 + c]
    if state[S_THIN_FILM] > 0.0:           # a Thin Film over the F82-tint metal
        b = state[S_METAL_B + c] if state[S_METAL_F82] != 0.0 else 0.0
        return thin_film.metal(c, cos_oh, state[S_THIN_FILM], state[S_FILM_IOR],
                               state[S_METAL_F0 + c], b)
    if state[S_METAL_F82] != 0.0:
        return fresnel.f82_tint(state[S_METAL_F0 + c], state[S_METAL_B + c], cos_oh)
    return fresnel.schlick(state[S_METAL_F0 + c], cos_oh)


@kernel
def f82_setup(row, state):
    """Cycles' F82-tint metal (Kutz et al., "Novel aspects of the Adobe Standard
    Material"): Schlick's Fresnel minus b mu (1 - mu)^6, with b per channel such that at
    mu = 1/7 (about 82 degrees) it is Schlick's value times the tint. Nothing to do for
    a white tint (plain Schlick)."""
    tinted = False
    for c in range(3):
        tinted = tinted or min(row[P_SPEC_TINT + c], 1.0) != 1.0
    if not tinted:
        return
    state[S_METAL_F82] = 1.0
    for c in range(3):                        # Cycles clamps the F82 tint to 1
        state[S_METAL_B + c] = fresnel.f82_tint_b(state[S_METAL_F0 + c],
                                                  min(row[P_SPEC_TINT + c], 1.0))


@kernel(allocates=False)
def reflection_eval(state, ox, oy, oz, ix, iy, iz):
    """D G / (4 cos cos) of the reflection lobes (GGX, Beckmann or Blinn-Phong) and h."""
    if state[S_BLINN] != 0.0:
        hx, hy, hz, _ = mf.half_vector(ox, oy, oz, ix, iy, iz)
        return blinn_phong.eval_f(ox, oy, oz, ix, iy, iz, state[S_EXPONENT]), hx, hy, hz
    if state[S_ANISO] != 0.0:
        return anisotropic.lobe_eval(state, ox, oy, oz, ix, iy, iz, state[S_BECKMANN] != 0.0)
    return dist.reflection_eval_of(ox, oy, oz, ix, iy, iz, state[S_ALPHA],
                                 state[S_BECKMANN] != 0.0)


@kernel(allocates=False)
def reflection_pdf(state, ox, oy, oz, ix, iy, iz):
    if state[S_BLINN] != 0.0:
        return blinn_phong.pdf(ox, oy, oz, ix, iy, iz, state[S_EXPONENT])
    if state[S_ANISO] != 0.0:
        return anisotropic.lobe_pdf(state, ox, oy, oz, ix, iy, iz, state[S_BECKMANN] != 0.0)
    return dist.reflection_pdf_of(ox, oy, oz, ix, iy, iz, state[S_ALPHA],
                                state[S_BECKMANN] != 0.0)


@kernel(allocates=False)
def reflection_sample(state, ox, oy, oz, u1, u2):
    if state[S_BLINN] != 0.0:
        return blinn_phong.sample(ox, oy, oz, u1, u2, state[S_EXPONENT])
    if state[S_ANISO] != 0.0:
        return anisotropic.lobe_sample(state, ox, oy, oz, u1, u2, state[S_BECKMANN] != 0.0)
    return dist.reflection_sample_of(ox, oy, oz, state[S_ALPHA], u1, u2,
                                   state[S_BECKMANN] != 0.0)
