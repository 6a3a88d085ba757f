"""Whitted's ray tracer (1980): the lecture's baseline, with mirror-only interreflection,
hard shadows and one ray per path, on the path tracer's wavefront loop with its own
vertex kernel (`engine.kernels.whitted_vertex`, whose docstring states the estimator).
Lamps are sampled at one fixed point each, so a bounce may queue one shadow ray per
lamp."""
from __future__ import annotations

from ..kernels.whitted_vertex import lamp_rays, shade_whitted
from .compiled_path import CompiledPathIntegrator


class WhittedIntegrator(CompiledPathIntegrator):
    splits_light = False      # no light passes (its vertex kernel adds to Combined alone)

    def __init__(self, ctx):
        super().__init__(ctx)
        self._lamp_rays = lamp_rays(self.lights)
        # subsurface scattering is its diffuse lobe here: no walk, so no scene for rays
        # cast in the kernel (and no second compile of it for that argument); its lamps
        # alone are sampled, so no emitter is evaluated at a light sample either
        self.features = self.features[:3] + (None, None)

    @property
    def shadow_rays_per_path(self) -> int:
        return max(self._lamp_rays, 1)

    @property
    def vertex(self):
        return shade_whitted
