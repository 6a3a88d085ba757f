"""The microfacet distribution of the Principled reflection lobes (specular and metal):
GGX, or the lecture's normalised Blinn-Phong where a material asks for it, per point.

`alpha` (n,) is the GGX roughness, `exponent` (n,) the Blinn-Phong exponent matching it,
`blinn` (n,) bool which points use Blinn-Phong (None: none of them, the common case,
which takes GGX's vectorised code directly). Fresnel is left to the caller.
"""
from __future__ import annotations

import numpy as np

from . import blinn_phong
from . import microfacet as mf


def eval_base(o, i, alpha, exponent, blinn=None):
    """(D G / (4 cos cos) (n,), half vector h (n, 3))."""
    if blinn is None:
        return mf.reflection_eval(o, i, alpha)
    h, _ = mf.half_vector(o, i)
    base = np.zeros(len(o))
    gg, bb = np.nonzero(~blinn)[0], np.nonzero(blinn)[0]
    if len(gg):
        base[gg] = mf.reflection_eval(o[gg], i[gg], alpha[gg])[0]
    if len(bb):
        base[bb] = blinn_phong.eval_f(o[bb], i[bb], exponent[bb])
    return base, h


def pdf(o, i, alpha, exponent, blinn=None):
    """pdf over wi (1/sr) of `sample`."""
    if blinn is None:
        return mf.reflection_pdf(o, i, alpha)
    p = np.zeros(len(o))
    gg, bb = np.nonzero(~blinn)[0], np.nonzero(blinn)[0]
    if len(gg):
        p[gg] = mf.reflection_pdf(o[gg], i[gg], alpha[gg])
    if len(bb):
        p[bb] = blinn_phong.pdf(o[bb], i[bb], exponent[bb])
    return p


def sample(o, u, alpha, exponent, blinn=None):
    """(wi (n, 3), valid (n,)) sampled from wo with u (n, 2)."""
    if blinn is None:
        w, _, v = mf.reflection_sample(o, alpha, u)
        return w, v
    w, v = np.zeros((len(o), 3)), np.zeros(len(o), bool)
    gg, bb = np.nonzero(~blinn)[0], np.nonzero(blinn)[0]
    if len(gg):
        w[gg], _, v[gg] = mf.reflection_sample(o[gg], alpha[gg], u[gg])
    if len(bb):
        w[bb], v[bb] = blinn_phong.sample(o[bb], u[bb], exponent[bb])
    return w, v
