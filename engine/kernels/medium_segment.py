"""The medium along a ray, before whatever the ray reaches: the first stage of a path
vertex (`path_vertex.shade`) for a ray that travels inside a volume. The segment adds the
medium's emission, weighs the throughput by its transmittance and may scatter the path
(then `medium_vertex.scatter` shades that point); through a medium sampled
equiangularly it also queues that strategy's light sample (`medium_vertex.
equiangular_light`). A heterogeneous medium is tracked by null scattering
(`medium_density.tracked_segment`)."""
from __future__ import annotations

from ..sampling.dispatch import sample_1d
from . import lights as lt
from . import light_tally as tl
from .jit import kernel
from .medium_density import (equiangular_point, heterogeneous_in, path_key, scatters_in,
                             tracked_segment)
from .medium_vertex import equiangular_light, equiangular_pick, equiangular_shade
from .path_weights import _INF
from .volume import (DISTANCE, distance_pdf, medium, sample_method, segment, volume_dim)

# what a ray outside any medium carries to the lamps it finds (found_light.lamps_in_front):
# (homogeneous segment's extinction and scattering weights, heterogeneous factor)
NO_SEGMENT = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
# (ox, oy, oz, t_max, t, pdf, method) of a scattering's segment: none
NO_SEGMENT_MIS = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@kernel
def along_ray(depth, cfg, paths, p, tally, lights, vol, het, textures, geometry, shadows,
              ns_out, ox, oy, oz, dx, dy, dz, t_geom, br, bg, bb, clamp_hit, vhit, regs,
              het_count, emitters):
    """Path p's ray (o, d) through its media up to t_geom, with throughput b; `het`:
    the scene has heterogeneous media. Returns (vmode, scattered, t_end, throughput
    after the segment, the segment for the lamps found (NO_SEGMENT's layout), the phase
    anisotropy where it scattered, the scattering's segment for MIS (NO_SEGMENT_MIS's
    layout), shadow count)."""
    pkey, index, cont, stacks = paths.key, paths.index, paths.cont, paths.stacks
    b, bits, time = paths.bounce[p], paths.ray_bits[p], paths.time[p]
    kind, spp = cfg.sampler, cfg.spp
    n_lights = lt.n_entries(lights)
    b0r, b0g, b0b = br, bg, bb
    str_ = stg = stb = wcr = wcg = wcb = 0.0
    mfr = mfg = mfb = 1.0                    # a heterogeneous segment's factor at a lamp
    g_phase = 0.0
    segment_mis = NO_SEGMENT_MIS
    if het and heterogeneous_in(vol, stacks, p):
        # null-scattering tracking (engine.kernels.medium_density); the factor is also
        # taken at the nearest lamp in front of the geometry
        t_lamp = _INF
        if n_lights > 0:
            t_lamp = lt.hit_lamps(lights, ox, oy, oz, dx, dy, dz, t_geom, bits, time)[0]
        vmode = 3
        method = sample_method(vol, stacks, p)
        k_eq, by_segment, t_eq, pe = -1, 0.0, -1.0, 0.0
        if (method != DISTANCE and n_lights > 0 and cont[p] > 0.0
                and scatters_in(vol, stacks, p, textures)):
            k_eq, by_segment, t_eq, pe = equiangular_pick(depth, cfg, paths, p, ox, oy, oz,
                                                          dx, dy, dz, t_geom, lights)
        scattered, t_end, fr, fg, fb, mfr, mfg, mfb, er, eg, eb, g_phase, pd, eq = \
            tracked_segment(vol, stacks, p, textures, geometry[9], geometry[12], ox, oy,
                            oz, dx, dy, dz, t_geom, t_lamp, t_eq, br, bg, bb, bits, b,
                            path_key(pkey[p], index[p], depth), vhit, regs, het_count)
        if scattered and method != DISTANCE:
            segment_mis = (ox, oy, oz, t_geom, t_end, pd, float(method))
        if k_eq >= 0:
            # the segment's direct light at an equiangular distance, its transmittance
            # from the same tracking (the roulette verdict on this ray applies)
            br0, bg0, bb0 = b0r / cont[p], b0g / cont[p], b0b / cont[p]
            trr, trg, trb, ssr, ssg, ssb, g_eq, pd_eq = equiangular_point(
                vol, stacks, p, textures, geometry[9], geometry[12], ox, oy, oz, dx, dy, dz,
                t_eq, br0, bg0, bb0, eq, bits, b, vhit, regs, het_count)
            ns_out = equiangular_shade(
                depth, cfg, paths, p, ox + dx * t_eq, oy + dy * t_eq, oz + dz * t_eq, dx,
                dy, dz, k_eq, by_segment, pe, pd_eq, br0 * trr * ssr, bg0 * trg * ssg,
                bb0 * trb * ssb, g_eq, method, tally, lights, shadows, ns_out, emitters)
        br, bg, bb = br * fr, bg * fg, bb * fb
    else:
        vmode, scattered, t_end, br, bg, bb, str_, stg, stb, wcr, wcg, wcb, er, eg, eb = \
            segment(vol, stacks, p, br, bg, bb, t_geom,
                    sample_1d(kind, pkey[p], spp, index[p], volume_dim(depth, 0)),
                    sample_1d(kind, pkey[p], spp, index[p], volume_dim(depth, 1)))
        method = sample_method(vol, stacks, p)
        if scattered:
            g_phase = medium(vol, stacks, p)[6]
            if method != DISTANCE:
                segment_mis = (ox, oy, oz, t_geom, t_end,
                               distance_pdf(str_, stg, stb, wcr, wcg, wcb, t_end),
                               float(method))
        if vmode == 2 and method != DISTANCE and n_lights > 0 and cont[p] > 0.0:
            # the segment's direct light at an equiangular distance (the roulette verdict
            # on this ray applies, as at a scattering)
            ns_out = equiangular_light(
                depth, cfg, paths, p, ox, oy, oz, dx, dy, dz, t_geom, b0r / cont[p],
                b0g / cont[p], b0b / cont[p], (wcr, wcg, wcb), method, tally, lights, vol,
                shadows, ns_out, emitters)
    tl.found(tally, p, b, er, eg, eb, clamp_hit, False, -1)    # a medium's: no group
    return (vmode, scattered, t_end, br, bg, bb,
            (str_, stg, stb, wcr, wcg, wcb, mfr, mfg, mfb), g_phase, segment_mis, ns_out)
