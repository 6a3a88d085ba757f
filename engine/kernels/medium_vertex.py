"""A path vertex inside a volume, compiled: where `path_vertex.shade` found that a ray
scattered in its medium (engine.kernels.volume.segment), this stage does what the
surface stage does at a surface, with the Henyey-Greenstein phase function in place of
the BSDF: next-event estimation (one light sample, one shadow ray through the media,
MIS against phase sampling) and, within Cycles' volume bounce limit, a new direction
sampled from the phase function. As in Cycles a volume scattering counts as a bounce,
is seen by lamps as a diffuse ray, and the scattering that uses up the volume (or the
total) bounce budget ends the path where its ray arrives (path_weights.ends_path).

The direct light of a segment is estimated twice, and the two combined by multiple
importance sampling over the distance (Cycles' "Multiple Importance" volume sampling):
at the distance-sampled scattering (`scatter`, when the path scatters), and at a
distance sampled equiangularly towards the picked light's position (`equiangular_pick`
and `equiangular_shade`, for every segment through a scattering medium, whether the
path scatters or not: one more shadow ray). The scattering picks its light for its point
(the light tree, lights/tree.py); the equiangular strategy picks one for the whole
segment (the tree's segment form, lights/tree_segment.py, as Cycles does), before it
knows its point. The weights are the power heuristic of the two strategies' densities
of the pair (light, distance); a sun or the world, which has no position, is the
distance strategy's alone. A homogeneous segment has both in closed form
(`equiangular_light`). A heterogeneous one is tracked (medium_density.tracked_segment):
its equiangular point's transmittance by ratio tracking, and the two strategies'
densities are those of null-scattering paths (medium_density.equiangular_point), as
in Cycles."""
from __future__ import annotations

import math

from ..sampling import dimensions as D
from ..sampling.dispatch import sample_1d, sample_2d
from . import equiangular as eq
from . import lights as lt
from . import ray_queues
from .jit import kernel
from .lights.lit_segment import lit_range
from .shaded_emitter import radiance as emitter_radiance
from . import light_tally as tl
from .light_tally import VOLUME_SHARES
from .path_weights import (DIFFUSE_BIT, ROULETTE_START, SHADOW_BIT, keep_receiver,
                           SPENT, VOLUME, ends_path, nee_weight, power_heuristic,
                           roulette)
from .volume import EQUIANGULAR, distance_pdf, hg_phase, hg_sample, medium, volume_dim



@kernel(allocates=False)
def scatter(depth, cfg, paths, p, px, py, pz, dx, dy, dz, br, bg, bb, g, tally, lights, vol,
            shadows, ns, nexts, nn, segment, emitters):
    """Path p of `paths` (path_state.PathState; throughput b, after the segment's weight)
    scattered at
    point x moving along d, by a Henyey-Greenstein phase function of anisotropy g. Writes
    at most one shadow ray (returned count ns) and one next ray (nn). `segment` = (ox,
    oy, oz, t_max, t, pdf, method): the homogeneous segment the distance t was sampled
    on, that sample's density and the medium's sampling method, for the weight against
    equiangular sampling (pdf 0: none, the distance sample's alone)."""
    pkey, index, time, bounce, vbounce = paths.key, paths.index, paths.time[p], \
        paths.bounce, paths.vbounce
    kind, spp = cfg.sampler, cfg.spp
    mode = cfg.mis_mode
    clamp = cfg.clamp_direct if bounce[p] == 0 else cfg.clamp_indirect
    base = D.FIRST_BOUNCE + depth * D.PER_BOUNCE
    recv = lt.receiver(px, py, pz, 0.0, 0.0, 0.0, lt.OMNI)    # a point with no normal
    if lt.n_entries(lights) > 0:
        u_pick = sample_1d(kind, pkey[p], spp, index[p], base + D.LIGHT_PICK)
        u1, u2 = sample_2d(kind, pkey[p], spp, index[p], base + D.LIGHT_POINT)
        k, wx, wy, wz, dist, lr, lg, lb, lpdf, delta, lprim, margin = lt.sample(
            lights, recv, u_pick, u1, u2, time)
        if lpdf > 0.0:     # an emission that varies over its triangle: there
            lr, lg, lb = emitter_radiance(emitters, lights, lprim, paths.counts,
                                          (paths.used, paths.cone), p, bounce[p], px, py, pz,
                                          wx, wy, wz, dist, time, lr, lg, lb)
        seen = lt.entry_visibility(lights, k)
        if lpdf > 0.0 and max(lr, lg, lb) > 0.0 and (seen & DIFFUSE_BIT) != 0:
            ph = hg_phase(g, dx * wx + dy * wy + dz * wz)
            w = nee_weight(mode, lpdf, ph, delta) / lpdf * ph
            w *= distance_weight(lights, k, recv, time, dx, dy, dz, segment)
            cr, cg, cb = br * lr * w, bg * lg * w, bb * lb * w
            if not w > 0.0:
                pass                         # the equiangular sample's alone
            elif not seen & SHADOW_BIT:
                tl.lit(tally, p, bounce[p], cr, cg, cb, clamp, VOLUME_SHARES,
                       tl.entry_group(tally, k))
            else:
                sdx, sdy, sdz, far = ray_queues.towards(px, py, pz, px, py, pz, wx, wy, wz,
                                                         dist, margin)
                ns = ray_queues.push(shadows, ns, p, bounce[p], px, py, pz, sdx, sdy, sdz,
                                     far, cr, cg, cb, paths.stacks, -1, -1, lprim)
                tl.queued(tally, ns - 1, p, bounce[p], VOLUME_SHARES, tl.entry_group(tally, k))
    # the path is here within its bounce budget: the phase function samples the next
    # ray, and the path ends at the vertex it finds if this scattering uses a budget up
    u1, u2 = sample_2d(kind, pkey[p], spp, index[p], base + D.BSDF_DIR)
    wx, wy, wz, pdf = hg_sample(g, dx, dy, dz, u1, u2)
    if bounce[p] + 1 >= ROULETTE_START:
        u_rr = sample_1d(kind, pkey[p], spp, index[p], base + D.ROULETTE)
        paths.cont[p] = roulette(u_rr, br, bg, bb)     # applied where the next ray arrives
    if ends_path(cfg, bounce[p] + 1, vbounce[p] + 1, VOLUME):
        paths.cont[p] = SPENT
    if not (max(br, bg, bb) > 0.0 and pdf > 0.0):
        return ns, nn
    paths.beta[p, 0], paths.beta[p, 1], paths.beta[p, 2] = br, bg, bb     # phase / pdf = 1
    if bounce[p] == 0:
        tl.left_first(tally, p, VOLUME_SHARES)
    bounce[p] += 1
    vbounce[p] += 1
    paths.ray_bits[p] = DIFFUSE_BIT
    keep_receiver(paths.prev_pos, p, recv)
    paths.prev_pdf[p] = pdf
    return ns, ray_queues.push_next(nexts, nn, p, px, py, pz, wx, wy, wz)


@kernel(allocates=False)
def distance_weight(lights, k, recv, time, dx, dy, dz, segment):
    """The weight of the distance-sampled scattering's light sample (entry k, picked
    for the scattering point recv) against equiangular sampling towards entry k on the
    same segment: 1 for a light without a position or one the equiangular strategy
    never picks, 0 where the medium samples the others equiangularly only. The
    densities compared are of the pair (light, distance): the equiangular strategy
    picks its light for the segment (`equiangular_light`)."""
    ox, oy, oz, t_max, t, pd, method = segment
    if not pd > 0.0:
        return 1.0
    has, cx, cy, cz = lt.entry_center(lights, k, time)
    if not has:
        return 1.0
    by_segment = lt.select_pdf(lights, k, lt.segment_receiver(ox, oy, oz, dx, dy, dz,
                                                              t_max), time)
    if not by_segment > 0.0:
        return 1.0
    t_lo, t_hi = lit_range(lights, k, ox, oy, oz, dx, dy, dz, 0.0, t_max, time)
    pe = eq.pdf(ox, oy, oz, dx, dy, dz, cx, cy, cz, t_lo, t_hi, t)
    if not pe > 0.0:
        return 1.0                     # where the equiangular strategy never samples
    if int(method) == EQUIANGULAR:
        return 0.0
    return power_heuristic(pd * lt.select_pdf(lights, k, recv, time), pe * by_segment)


@kernel(allocates=False)
def equiangular_pick(depth, cfg, paths, p, ox, oy, oz, dx, dy, dz, t_max, lights):
    """The equiangular strategy's sample on path p's segment o + t d, t in [0, t_max]:
    a light picked for the whole segment (before any point on it is known) and a
    distance sampled towards its position, on the part of the segment it can light
    (lights/lit_segment.py). Returns (entry k, its pick probability, t,
    the distance's density); k = -1: none (no light, or one without a position)."""
    pkey, index, time = paths.key, paths.index, paths.time[p]
    kind, spp = cfg.sampler, cfg.spp
    if lt.n_entries(lights) == 0:
        return -1, 0.0, -1.0, 0.0
    u_pick = sample_1d(kind, pkey[p], spp, index[p], volume_dim(depth, 2))
    k, by_segment = lt.pick_entry(lights, lt.segment_receiver(ox, oy, oz, dx, dy, dz,
                                                              t_max), u_pick, time)
    if k < 0:
        return -1, 0.0, -1.0, 0.0
    has, cx, cy, cz = lt.entry_center(lights, k, time)
    if not has:
        return -1, 0.0, -1.0, 0.0
    t_lo, t_hi = lit_range(lights, k, ox, oy, oz, dx, dy, dz, 0.0, t_max, time)
    t, pe = eq.sample(ox, oy, oz, dx, dy, dz, cx, cy, cz, t_lo, t_hi,
                      sample_1d(kind, pkey[p], spp, index[p], volume_dim(depth, 3)))
    if not pe > 0.0:
        return -1, 0.0, -1.0, 0.0
    return k, by_segment, t, pe


@kernel(allocates=False)
def equiangular_light(depth, cfg, paths, p, ox, oy, oz, dx, dy, dz, t_max, br, bg, bb,
                      channels, method, tally, lights, vol, shadows, ns, emitters):
    """The equiangular half of a homogeneous segment's direct light: path p (throughput
    b before the segment, roulette applied) travels o + t d, t in [0, t_max], through its
    medium, whose distance sampling picked the channels with weights `channels` (RGB),
    with Volume Sampling Method `method` (EQUIANGULAR or MULTIPLE_IMPORTANCE): the
    transmittance and the distance density in closed form. Returns the shadow count."""
    k, by_segment, t, pe = equiangular_pick(depth, cfg, paths, p, ox, oy, oz, dx, dy, dz,
                                            t_max, lights)
    if k < 0:
        return ns
    sar, sag, sab, ssr, ssg, ssb, g, _, _, _ = medium(vol, paths.stacks, p)
    str_, stg, stb = sar + ssr, sag + ssg, sab + ssb
    wr, wg, wb = channels
    return equiangular_shade(
        depth, cfg, paths, p, ox + dx * t, oy + dy * t, oz + dz * t, dx, dy, dz, k,
        by_segment, pe, distance_pdf(str_, stg, stb, wr, wg, wb, t),
        br * ssr * math.exp(-str_ * t), bg * ssg * math.exp(-stg * t),
        bb * ssb * math.exp(-stb * t), g, method, tally, lights, shadows, ns, emitters)


@kernel(allocates=False)
def equiangular_shade(depth, cfg, paths, p, px, py, pz, dx, dy, dz, k, by_segment, pe, pd,
                      sr, sg, sb, g, method, tally, lights, shadows, ns, emitters):
    """The light sample of the equiangular strategy at its point x (`equiangular_pick`'s
    entry k, picked with probability by_segment, at a distance of density pe; pd: the
    distance strategy's density there) of path p moving along d, where the path's
    throughput times the transmittance to x times the scattering coefficient is s (RGB)
    and the phase function's anisotropy g. Samples a point on the light from x and
    queues the shadow ray (returned count ns). Its weight against phase sampling takes
    the light's pick probability for x, as a scattering there would pick it."""
    pkey, index, time, bounce = paths.key, paths.index, paths.time[p], paths.bounce
    kind, spp = cfg.sampler, cfg.spp
    mode = cfg.mis_mode
    if not max(sr, sg, sb) > 0.0:
        return ns
    u1, u2 = sample_2d(kind, pkey[p], spp, index[p], volume_dim(depth, 4))
    wx, wy, wz, dist, lr, lg, lb, ppoint, delta, lprim, margin = lt.sample_entry(
        lights, k, px, py, pz, u1, u2, time)
    if ppoint > 0.0:
        lr, lg, lb = emitter_radiance(emitters, lights, lprim, paths.counts,
                                      (paths.used, paths.cone), p, bounce[p], px, py, pz, wx,
                                      wy, wz, dist, time, lr, lg, lb)
    seen = lt.entry_visibility(lights, k)
    if not (ppoint > 0.0 and max(lr, lg, lb) > 0.0 and (seen & DIFFUSE_BIT) != 0):
        return ns
    select = lt.select_pdf(lights, k, lt.receiver(px, py, pz, 0.0, 0.0, 0.0, lt.OMNI), time)
    if not select > 0.0:
        return ns                      # the light cannot reach this point (tree.py)
    ph = hg_phase(g, dx * wx + dy * wy + dz * wz)
    w_t = 1.0 if method == EQUIANGULAR else power_heuristic(pe * by_segment, pd * select)
    w = (nee_weight(mode, ppoint * select, ph, delta)
         / (ppoint * by_segment) * ph * w_t / pe)
    cr, cg, cb = sr * lr * w, sg * lg * w, sb * lb * w
    if not seen & SHADOW_BIT:
        clamp = cfg.clamp_direct if bounce[p] == 0 else cfg.clamp_indirect
        tl.lit(tally, p, bounce[p], cr, cg, cb, clamp, VOLUME_SHARES, tl.entry_group(tally, k))
        return ns
    sdx, sdy, sdz, far = ray_queues.towards(px, py, pz, px, py, pz, wx, wy, wz, dist,
                                             margin)
    ns = ray_queues.push(shadows, ns, p, bounce[p], px, py, pz, sdx, sdy, sdz, far, cr, cg,
                         cb, paths.stacks, -1, -1, lprim)
    tl.queued(tally, ns - 1, p, bounce[p], VOLUME_SHARES, tl.entry_group(tally, k))
    return ns
