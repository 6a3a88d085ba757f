"""What the path kernels read of a render's settings, by name (Cycles' Light Paths,
Clamping, Caustics and Filter Glossy, the sampler, the MIS mode), as one record."""
from __future__ import annotations

from typing import NamedTuple

from .path_weights import MIS


class PathConfig(NamedTuple):
    sampler: int                # engine.sampling's kind
    spp: int                    # its pattern's samples per pixel
    max_bounces: int            # Light Paths > Max Bounces > Total
    diffuse_bounces: int        # ... Diffuse
    glossy_bounces: int         # ... Glossy
    transmission_bounces: int   # ... Transmission
    volume_bounces: int         # ... Volume
    clamp_direct: float         # Clamping > Direct Light (0: off)
    clamp_indirect: float       # Clamping > Indirect Light (0: off)
    mis_mode: int               # path_weights' MIS (the power heuristic), LIGHT_ONLY or
    #                             BSDF_ONLY
    film_transparent: bool      # Film > Transparent: escaped camera rays leave alpha
    filter_glossy: float        # Light Paths > Filter Glossy (0: off)
    caustics_reflective: bool   # Light Paths > Caustics > Reflective
    caustics_refractive: bool   # ... Refractive


def path_config(sampler, settings, film_transparent: bool,
                mis_mode: int = MIS) -> PathConfig:
    """The record of a render (engine.settings.RenderSettings), every field of one type."""
    s = settings
    return PathConfig(int(sampler.kind), int(sampler.pattern), int(s.max_bounces),
                      int(s.diffuse_bounces), int(s.glossy_bounces),
                      int(s.transmission_bounces), int(s.volume_bounces),
                      float(s.clamp_direct), float(s.clamp_indirect), int(mis_mode),
                      bool(film_transparent), float(s.filter_glossy),
                      bool(s.caustics_reflective), bool(s.caustics_refractive))
