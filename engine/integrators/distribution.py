"""Cook, Porter and Carpenter's distribution ray tracing (1984).

Rays are distributed over the pixel (anti-aliasing), the lens (depth of field), the time
(motion blur), the light's area (soft shadows) and the glossy and transmission lobes
(blurry reflection and translucency), but light that reaches a surface by diffuse
interreflection is not followed: a diffuse surface gets direct light only. That is the
path tracer's loop with the diffuse bounce budget set to zero (Cycles' Light Paths with
Diffuse bounces 0 renders the same estimator), which is exactly the estimator of the
1984 paper with importance sampling, stratification (Cook's ray-id chaining, see
engine.sampling) and multiple importance sampling of lights and lobes. It runs on the
path tracer's kernels, so it renders every material, volume and motion the path tracer
does.
"""
from __future__ import annotations

from .compiled_path import CompiledPathIntegrator


class DistributionIntegrator(CompiledPathIntegrator):
    def __init__(self, ctx):
        super().__init__(ctx)
        self.cfg = self.cfg._replace(diffuse_bounces=0)   # no diffuse interreflection
