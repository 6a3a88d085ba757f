"""Principled's Coat as Cycles builds it (kernel/svm/closure.h, the Principled BSDF's
"second layer"): a single-scattering GGX reflection with the exact dielectric Fresnel of
the coat IOR, alpha = coat roughness^2, over everything below it, which it

  * dims by its albedo: the lower layers' weight is multiplied by 1 - weight E(wo),
    E(wo) = F0 + (1 - F0) s(wo) being Cycles' estimate of a dielectric GGX layer's
    reflectance (bsdf_microfacet_estimate_albedo; multiscatter.layer_reflectance), and
  * tints: by mix(1, tint^d, weight) per channel, d = 1 / cos theta_t the path length
    through a coat of unit thickness at the refracted view angle (Beer's law with the
    tint normalised to normal incidence; light leaving the coat is not tinted again).

Scalar kernels on the local frame (wo_z > 0); the lobe's eval, pdf and sampling are
GGX reflection's (microfacet.py) times the Fresnel term, so only the Fresnel and the
layering terms live here.
"""
from __future__ import annotations

import math

from ..jit import kernel
from . import fresnel
from . import microfacet as mf
from . import multiscatter as ms


@kernel
def layer_albedo(cos_o, alpha, ior, tables):
    """The coat's reflectance at wo as the layers below see it (0 without an interface)."""
    if not ior > 1.0:
        return 0.0
    return ms.layer_reflectance(cos_o, alpha, ior, tables)


@kernel
def path_length(cos_o, ior):
    """1 / cos theta_t: the path through a unit-thick coat of IOR `ior` >= 1 along the
    view direction refracted into it (no total internal reflection from outside)."""
    s2 = (1.0 - cos_o * cos_o) / (ior * ior)
    return 1.0 / math.sqrt(max(1.0 - s2, 1e-12))


@kernel
def tint_factor(tint, weight, depth):
    """mix(1, tint^depth, weight) for one channel."""
    return 1.0 + weight * (max(tint, 0.0) ** depth - 1.0)


@kernel
def eval_unit(ox, oy, oz, ix, iy, iz, alpha, ior):
    """f (1/sr) of the coat lobe at weight 1: F(wo.h) D G2 / (4 cos_o cos_i)."""
    base, hx, hy, hz = mf.reflection_eval(ox, oy, oz, ix, iy, iz, alpha)
    if base == 0.0:
        return 0.0
    cos_oh = min(max(mf.dot(ox, oy, oz, hx, hy, hz), 0.0), 1.0)
    return fresnel.dielectric(cos_oh, ior) * base
