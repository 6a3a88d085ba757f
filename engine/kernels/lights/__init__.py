"""Light sampling as compiled scalar kernels: a faithful port of `engine.lights`
(LightSet and every light model) and `engine.mesh_lights` (emissive triangles).

    L = pack_lights(light_set)                 # once per scene (NumPy arrays)
    k, wix, wiy, wiz, dist, r, g, b, pdf, delta, margin = sample(L, px, py, pz, u_pick, u1,
                                                                 u2, time)
    t, k, r, g, b = hit_lamps(L, ox, oy, oz, dx, dy, dz, tmax, ray_bit, time)   # nearest
    n_lamps(L);  t, r, g, b = lamp_hit(L, k, ox, oy, oz, dx, dy, dz, ray_bit, time)
    lamp_pdf(L, k, px, py, pz, wix, wiy, wiz, t, time)
    mesh_pdf(L, prim, px, py, pz, qx, qy, qz)
    environment_pdf(L, dx, dy, dz);  environment_radiance(L) -> (r, g, b)
    world_escaped(L, world, ray_bit, dx, dy, dz) -> (r, g, b, pdf)   # escaped rays
    n_suns(L);  sun_escaped(L, j, dx, dy, dz, time) -> (r, g, b, pdf)
    n_entries(L);  entry_visibility(L, k)

Every pdf is in solid angle with the pick probability included, as LightSet's. `time` is
the ray's shutter time in [0, 1]: a lamp that moves during the shutter is its slice at
that time (pack.py, TimeSlicedLight). Array drivers for tests: `batch`.
"""
from .light_set import (environment_pdf, environment_radiance, hit_lamps,
                        is_uniform_world, lamp_hit, lamp_pdf, entry_visibility, mesh_pdf,
                        n_entries, n_lamps, n_suns, sample, sun_escaped, world_escaped)
from .pack import pack_lights

__all__ = ["pack_lights", "n_entries", "n_lamps", "sample", "hit_lamps", "lamp_hit",
           "entry_visibility",
           "lamp_pdf", "mesh_pdf", "environment_pdf", "environment_radiance", "n_suns",
           "sun_escaped", "world_escaped", "is_uniform_world"]
