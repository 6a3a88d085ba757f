"""Cycles' Translucent BSDF (kernel/closure/bsdf_diffuse.h, its translucent closure):
Lambertian transmission, f = colour / pi for wi on the other side of the surface than
wo, sampled by the cosine-weighted hemisphere below. Local shading frame, wo_z > 0 but
for a smooth mesh's silhouette, where, as Cycles, only wi's side counts.
"""
from __future__ import annotations

from ..jit import kernel
from ..warp import INV_PI, cosine_hemisphere


@kernel
def eval_unit(woz, wiz):
    """f / colour (1/sr): 1/pi where wi is below the surface."""
    return INV_PI if wiz < 0.0 else 0.0


@kernel
def pdf(woz, wiz):
    return -wiz * INV_PI if wiz < 0.0 else 0.0


@kernel
def sample(u1, u2):
    """A cosine-weighted direction below the surface."""
    x, y, z = cosine_hemisphere(u1, u2)
    return x, y, -z
