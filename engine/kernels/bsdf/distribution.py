"""Either microfacet distribution per closure: GGX (microfacet.py), or Beckmann
(beckmann.py) where `beckmann` is set. Each function has GGX's name with `_of` and the
flag as its last argument; the callers (dielectric.py, reflection_lobes.py) pass the
state's Beckmann flag."""
from __future__ import annotations

from ..jit import kernel
from . import beckmann as bk
from .microfacet import (D, G1_over_cos, dot, half_vector, reflect, reflection_eval,
                         reflection_pdf, reflection_sample, sample_visible_normal)

@kernel
def D_of(hx, hy, hz, alpha, beckmann):
    if beckmann:
        return bk.D(hx, hy, hz, alpha)
    return D(hx, hy, hz, alpha)


@kernel
def G1_over_cos_of(x, y, z, alpha, beckmann):
    if beckmann:
        return bk.G1_over_cos(x, y, z, alpha)
    return G1_over_cos(x, y, z, alpha)


@kernel
def reflection_eval_of(ox, oy, oz, ix, iy, iz, alpha, beckmann):
    """`reflection_eval` of either distribution."""
    if not beckmann:
        return reflection_eval(ox, oy, oz, ix, iy, iz, alpha)
    hx, hy, hz, ok = half_vector(ox, oy, oz, ix, iy, iz)
    if not ok:
        return 0.0, hx, hy, hz
    return bk.reflection_eval(ox, oy, oz, ix, iy, iz, hx, hy, hz, alpha), hx, hy, hz


@kernel
def reflection_pdf_of(ox, oy, oz, ix, iy, iz, alpha, beckmann):
    """`reflection_pdf` of either distribution."""
    if not beckmann:
        return reflection_pdf(ox, oy, oz, ix, iy, iz, alpha)
    hx, hy, hz, ok = half_vector(ox, oy, oz, ix, iy, iz)
    if not (ok and oz > 0.0 and iz > 0.0):
        return 0.0
    return bk.reflection_pdf(ox, oy, oz, hx, hy, hz, alpha)


@kernel
def sample_visible_normal_of(ox, oy, oz, alpha, u0, u1, beckmann):
    if beckmann:
        return bk.sample_visible_normal(ox, oy, oz, alpha, u0, u1)
    return sample_visible_normal(ox, oy, oz, alpha, u0, u1)


@kernel
def reflection_sample_of(ox, oy, oz, alpha, u0, u1, beckmann):
    """`reflection_sample` of either distribution."""
    if not beckmann:
        return reflection_sample(ox, oy, oz, alpha, u0, u1)
    hx, hy, hz = bk.sample_visible_normal(ox, oy, oz, alpha, u0, u1)
    ix, iy, iz = reflect(ox, oy, oz, hx, hy, hz)
    valid = (oz > 0.0 and iz > 0.0 and hz > 0.0
             and dot(ox, oy, oz, hx, hy, hz) > 0.0)
    return ix, iy, iz, valid
