"""Cycles' changes to a hit's BSDF that depend on the path so far (its
surface_shader_prepare_closures, and bssrdf_setup's), applied to the material row before
setup: Filter Glossy, the caustics switches, and Christensen-Burley after a diffuse
bounce."""
from __future__ import annotations

import math

from .bsdf.params import P_FILTER_ALPHA, P_SSS_METHOD, P_SSS_RADIUS, SSS_BURLEY
from .jit import kernel
from .path_weights import DIFFUSE_BIT, _INF


@kernel
def prepare_closures(cfg, row, min_pdf, ray_bit, diffuse_bounces):
    """Filter Glossy (cfg.filter_glossy, Cycles' `blur_glossy`; 0 = off): after bounces
    that were unlikely (the smallest BSDF pdf along the path, min_pdf, below
    blur_glossy), every microfacet lobe is widened to at least GGX alpha =
    0.5 sqrt(1 - min_pdf / blur_glossy). A bias that trades sharp caustics and fireflies
    for blur. As in Cycles, whose closure blur follows the closures' setup, only the
    lobes widen: the energy compensation and the layering keep the material's alpha
    (row[P_FILTER_ALPHA]).

    Caustics (cfg.caustics_reflective, cfg.caustics_refractive): with one off, a hit of a
    ray that left a diffuse bounce (ray_bit has DIFFUSE: a diffuse lobe's, or a
    Translucent BSDF's, which is a diffuse and a transmission ray in Cycles) has no glossy
    reflection (resp. refraction) lobes.

    Christensen-Burley subsurface scattering on a path that has made a diffuse bounce
    (diffuse_bounces > 0, Cycles' PATH_RAY_DIFFUSE_ANCESTOR) is a diffuse lobe: its
    radii set to 0 here, principled.setup gives its share to the diffuse lobe. (Cycles:
    its disk probes in directions that mostly meet nothing, for light hardly seen.)

    Returns (keep glossy lobes, keep transmission lobes)."""
    blur = cfg.filter_glossy
    if blur > 0.0 and min_pdf < _INF:
        blur_pdf = min_pdf / blur
        if blur_pdf < 1.0:
            alpha = 0.5 * math.sqrt(1.0 - blur_pdf)
            row[P_FILTER_ALPHA] = alpha     # the lobes only (principled.setup)
    if diffuse_bounces > 0 and row[P_SSS_METHOD] == SSS_BURLEY:
        row[P_SSS_RADIUS] = row[P_SSS_RADIUS + 1] = row[P_SSS_RADIUS + 2] = 0.0
    after_diffuse = (ray_bit & DIFFUSE_BIT) != 0
    return ((cfg.caustics_reflective or not after_diffuse),
            (cfg.caustics_refractive or not after_diffuse))
