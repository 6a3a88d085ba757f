"""Integrators: one wavefront loop (`compiled_path`) of compiled kernels between Embree
queries, with the vertex kernel and bounce limits of each.

- path: Kajiya's path tracing with next-event estimation and MIS (kernels.path_vertex)
- distribution: Cook 1984, distributed glossy and transmission, direct light on diffuse
  (the path tracer with no diffuse bounce)
- whitted: mirror-only interreflection, one shadow ray per lamp (the lecture's baseline,
  kernels.whitted_vertex)
"""


def make_integrator(name, ctx):
    from .compiled_path import CompiledPathIntegrator
    from .distribution import DistributionIntegrator
    from .whitted import WhittedIntegrator
    table = {"path": CompiledPathIntegrator, "distribution": DistributionIntegrator,
             "whitted": WhittedIntegrator}
    if name not in table:
        raise ValueError(f"unknown integrator {name!r}; choose one of {sorted(table)}")
    if name == "whitted" and ctx.scene.has_volumes():
        raise ValueError("the scene has volumes, which Whitted's ray tracer does not "
                         "render (choose 'path' or 'distribution')")
    return table[name](ctx)
