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
        why = unsupported(ctx)
        if why is None:
            return CompiledPathIntegrator(ctx)
        if ctx.scene.has_volumes():
            raise ValueError(f"the scene has volumes, which the path integrator renders "
                             f"only where it runs compiled; here it cannot: {why}")
    elif ctx.scene.has_volumes():
        raise ValueError(f"the scene has volumes, which only the 'path' integrator renders "
                         f"(not {name!r})")
    try:
        return table[name](ctx)
    except KeyError:
        raise ValueError(f"unknown integrator {name!r}; choose one of {sorted(table)}") from None
