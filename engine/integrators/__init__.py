"""Integrators: each a short loop over the camera, sampler, lights and BSDF interfaces.

- whitted: mirror-only interreflection, one shadow ray per light (the lecture's baseline)
- distribution: Cook 1984, distributed glossy and transmission, direct light on diffuse
- path: Kajiya's path tracing with next-event estimation and MIS; compiled
  (`compiled_path`) wherever the scene allows, else the NumPy reference (`path`)
"""


def make_integrator(name, ctx):
    from .distribution import DistributionIntegrator
    from .path import PathIntegrator
    from .whitted import WhittedIntegrator
    table = {"path": PathIntegrator, "distribution": DistributionIntegrator,
             "whitted": WhittedIntegrator}
    if name == "path":
        from .compiled_path import CompiledPathIntegrator, unsupported
        if unsupported(ctx) is None:
            return CompiledPathIntegrator(ctx)
    try:
        return table[name](ctx)
    except KeyError:
        raise ValueError(f"unknown integrator {name!r}; choose one of {sorted(table)}") from None
