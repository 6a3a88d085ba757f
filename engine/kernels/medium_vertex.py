"""A path vertex inside a volume, compiled: where `path_vertex.shade` found that a ray
scattered in its medium (engine.kernels.volume.segment), this stage does what the
surface stage does at a surface, with the Henyey-Greenstein phase function in place of
the BSDF: next-event estimation (one light sample, one shadow ray through the media,
MIS against phase sampling) and, within Cycles' volume bounce limit, a new direction
sampled from the phase function. As in Cycles a volume scattering counts as a bounce,
is seen by lamps as a diffuse ray, and past `volume_bounces` scatterings a path still
gathers the direct light of its last one but goes no further."""
from __future__ import annotations

from ..sampling import dimensions as D
from ..sampling.dispatch import sample_1d, sample_2d
from . import lights as lt
from . import ray_queues
from .jit import kernel
from .path_weights import (DIFFUSE_BIT, ROULETTE_START, SHADOW_BIT, _add, nee_weight,
                           roulette)
from .volume import hg_phase, hg_sample

C_VOLUME_BOUNCES = 14      # cfg entry: Cycles' max volume bounces


@kernel
def scatter(depth, cfg, pkey, index, p, time, px, py, pz, dx, dy, dz, br, bg, bb, g, bounce,
            vbounce, beta, cont, prev_pdf, prev_pos, ray_bits, L, lights, vol, stacks,
            sh_path, sh_org, sh_dir, sh_far, sh_contrib, sh_bounce, sh_stack, ns,
            nx_path, nx_org, nx_dir, nn):
    """Path p (throughput b, after the segment's weight, shutter time `time`) scattered at
    point x moving along d, by a Henyey-Greenstein phase function of anisotropy g. Writes
    at most one shadow ray (returned count ns) and one next ray (nn)."""
    kind, spp = int(cfg[0]), int(cfg[1])
    mode = int(cfg[8])
    clamp = cfg[6] if bounce[p] == 0 else cfg[7]
    base = D.FIRST_BOUNCE + depth * D.PER_BOUNCE
    # whether the phase function samples a next ray; if not, light sampling alone finds
    # the light (its MIS weight is then 1, as a BSDF's at the last bounce)
    goes_on = bounce[p] < int(cfg[2]) and vbounce[p] < int(cfg[C_VOLUME_BOUNCES])
    if lt.n_entries(lights) > 0:
        u_pick = sample_1d(kind, pkey[p], spp, index[p], base + D.LIGHT_PICK)
        u1, u2 = sample_2d(kind, pkey[p], spp, index[p], base + D.LIGHT_POINT)
        k, wx, wy, wz, dist, lr, lg, lb, lpdf, delta, margin = lt.sample(
            lights, px, py, pz, u_pick, u1, u2, time)
        seen = lt.entry_visibility(lights, k)
        if lpdf > 0.0 and max(lr, lg, lb) > 0.0 and (seen & DIFFUSE_BIT) != 0:
            ph = hg_phase(g, dx * wx + dy * wy + dz * wz)
            w = nee_weight(mode, lpdf, ph if goes_on else 0.0, delta) / lpdf * ph
            cr, cg, cb = br * lr * w, bg * lg * w, bb * lb * w
            if not seen & SHADOW_BIT:
                _add(L, p, cr, cg, cb, clamp)
            else:
                sdx, sdy, sdz, far = ray_queues.towards(px, py, pz, px, py, pz, wx, wy, wz,
                                                         dist, margin, cfg[9])
                ns = ray_queues.push(ns, p, bounce[p], px, py, pz, sdx, sdy, sdz, far, cr,
                                      cg, cb, sh_path, sh_org, sh_dir, sh_far, sh_contrib,
                                      sh_bounce, stacks, sh_stack)
    if not goes_on:
        return ns, nn
    u1, u2 = sample_2d(kind, pkey[p], spp, index[p], base + D.BSDF_DIR)
    wx, wy, wz, pdf = hg_sample(g, dx, dy, dz, u1, u2)
    if bounce[p] + 1 >= ROULETTE_START:
        u_rr = sample_1d(kind, pkey[p], spp, index[p], base + D.ROULETTE)
        cont[p] = roulette(u_rr, br, bg, bb)     # applied where the next ray arrives
    if not (max(br, bg, bb) > 0.0 and pdf > 0.0):
        return ns, nn
    beta[p, 0], beta[p, 1], beta[p, 2] = br, bg, bb     # phase / pdf = 1
    bounce[p] += 1
    vbounce[p] += 1
    ray_bits[p] = DIFFUSE_BIT
    prev_pos[p, 0], prev_pos[p, 1], prev_pos[p, 2] = px, py, pz
    prev_pdf[p] = pdf
    return ns, ray_queues.push_next(nn, p, px, py, pz, wx, wy, wz, nx_path, nx_org, nx_dir)
