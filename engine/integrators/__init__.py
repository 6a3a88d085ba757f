"""Integrators: each a short loop over the camera, sampler, lights and BSDF interfaces.

- whitted: mirror-only interreflection, one shadow ray per light (the lecture's baseline)
- distribution: Cook 1984, distributed glossy and transmission, direct light on diffuse
- path: Kajiya's path tracing with next-event estimation and MIS, compiled
  (`compiled_path`; `path` is its NumPy reference, which the tests compare it with)
"""


def make_integrator(name, ctx):
    from .distribution import DistributionIntegrator
    from .whitted import WhittedIntegrator
    if name == "path":
        from .compiled_path import CompiledPathIntegrator
        return CompiledPathIntegrator(ctx)
    table = {"distribution": DistributionIntegrator, "whitted": WhittedIntegrator}
    if ctx.scene.has_volumes():
        raise ValueError(f"the scene has volumes, which only the 'path' integrator renders "
                         f"(not {name!r})")
    try:
        return table[name](ctx)
    except KeyError:
        raise ValueError(f"unknown integrator {name!r}; choose one of "
                         f"{sorted(table) + ['path']}") from None
