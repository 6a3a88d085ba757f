"""A path vertex that scatters below its surface: where `path_vertex.shade` sampled the
Principled BSDF's subsurface lobe (bsdf/subsurface_lobe.py), this stage enters the
surface, walks inside it (engine/kernels/subsurface.py) and shades the point where the
walk leaves as Cycles does (integrator/subsurface.h):

1. entry: the view direction refracted through a GGX microfacet normal about the
   shading normal (made a valid reflector for the view, as path_vertex.shade makes it
   for the specular lobes: Cycles' bssrdf N) (alpha: the
   material's roughness^2 for the Principled BSDF, the node's Roughness for the
   Subsurface Scattering node; IOR clamped to [1.01, 3.8]) with no Fresnel weight (only
   the direction matters); Random Walk (Skin) enters half its paths by a cosine
   direction about -N and the rest with alpha 1. A direction that does not go into the
   surface ends the path;
2. the walk, in the object it entered;
3. exit: a Lambertian surface of weight 1 at the exit point (the throughput carries the
   colour) with the exit's shading normal (bent by the material's program where it
   bends it: a bump or normal map), no emission: next-event
   estimation (one light, one shadow ray, MIS against the diffuse bounce) and, while a
   diffuse bounce is left, a cosine-distributed next ray. The walk is no bounce (Cycles
   does not count it); the exit's bounce is a diffuse one.

Christensen-Burley has neither entry nor walk: its exit comes from Cycles' disk sampling
(engine/kernels/subsurface_disk.py), with the disk drawn from the vertex's own BSDF
sample numbers, and is shaded as in step 3.

The entry direction uses the vertex's own BSDF sample numbers; the walk and the exit use
the walk's hashed stream, independent of them.
"""
from __future__ import annotations

import math

from . import lights as lt
from . import ray_queues
from .bsdf import microfacet as mf
from .bsdf.params import (P_BASE, P_ROUGHNESS, P_SETS_NORMAL, P_SSS_ALPHA,
                          P_SSS_ANISOTROPY, P_SSS_IOR, P_SSS_METHOD, P_SSS_RADIUS,
                          SSS_BURLEY, SSS_SKIN)
from .frame import dot, to_local, to_world
from .jit import kernel
from .shaded_emitter import radiance as emitter_radiance
from . import light_tally as tl
from .light_tally import DIFFUSE_SHARES
from ..sampling.hashing import stream_uniform
from .path_weights import (DIFFUSE_BIT, ROULETTE_START, SHADOW_BIT, keep_receiver,
                           SPENT, ends_path, nee_weight, roulette)
from .subsurface import MAX_BOUNCES, object_of, walk, walk_radius
from .subsurface_disk import find_exit
from ..embree.rays import new_ray_record
from .surface import hit_uv, rebuild_at_time
from .surface_hit import run_program
from .terminator import shadow_origin
from .warp import INV_PI, cosine_hemisphere
from ..nodes.interpreter import has_program
from ..nodes.shading import bump_shadowing, surface_normal

EXIT_STEP = MAX_BOUNCES + 1     # the walk stream's step whose numbers the exit uses


@kernel(allocates=False)
def entry_direction(row, dx, dy, dz, nx, ny, nz, u1, u2):
    """The direction into the surface for a ray along d hitting shading normal n (facing
    the ray), or ok False."""
    wix, wiy, wiz = -dx, -dy, -dz
    skin = row[P_SSS_METHOD] == SSS_SKIN
    if skin:
        if u1 < 0.5:
            lx, ly, lz = cosine_hemisphere(2.0 * u1, u2)
            ox, oy, oz = to_world(lx, ly, lz, nx, ny, nz)
            return -ox, -oy, -oz, True
        u1 = 2.0 * (u1 - 0.5)
        alpha = 1.0
    elif row[P_SSS_ALPHA] >= 0.0:
        alpha = min(row[P_SSS_ALPHA], 1.0)
    else:
        r = min(max(row[P_ROUGHNESS], 0.0), 1.0)
        alpha = r * r
    ior = min(max(row[P_SSS_IOR], 1.01), 3.8)
    ix, iy, iz = to_local(wix, wiy, wiz, nx, ny, nz)
    if not iz > 0.0:
        return 0.0, 0.0, 0.0, False
    hx, hy, hz = mf.sample_visible_normal(ix, iy, iz, alpha, u1, u2)
    hx, hy, hz = to_world(hx, hy, hz, nx, ny, nz)
    eta = 1.0 / ior
    cos_hi = dot(hx, hy, hz, wix, wiy, wiz)
    arg = 1.0 - eta * eta * (1.0 - cos_hi * cos_hi)
    k = eta * cos_hi - max(math.sqrt(max(arg, 0.0)), 1e-7)
    return -eta * wix + k * hx, -eta * wiy + k * hy, -eta * wiz + k * hz, True


@kernel(allocates=False)
def walk_params(row):
    """(albedo, walk radius) per channel, and the anisotropy, of material row `row`."""
    skin = row[P_SSS_METHOD] == SSS_SKIN
    ior = min(max(row[P_SSS_IOR], 1.01), 3.8)
    a0 = min(max(row[P_BASE], 0.0), 1.0)
    a1 = min(max(row[P_BASE + 1], 0.0), 1.0)
    a2 = min(max(row[P_BASE + 2], 0.0), 1.0)
    r0 = walk_radius(max(row[P_SSS_RADIUS], 0.0), a0, ior, skin)
    r1 = walk_radius(max(row[P_SSS_RADIUS + 1], 0.0), a1, ior, skin)
    r2 = walk_radius(max(row[P_SSS_RADIUS + 2], 0.0), a2, ior, skin)
    return (a0, a1, a2), (r0, r1, r2), row[P_SSS_ANISOTROPY]


@kernel(allocates=False)
def scatter_below(cfg, key, p, paths, rays, geometry, row, prim, inst, front, px, py, pz,
                  gx, gy, gz, nx, ny, nz, dx, dy, dz, u1, u2, br, bg, bb, tally,
                  lights, shadows, ns, nexts, nn, programs, params, hit_row, regs,
                  emitters):
    """Path p (throughput b, the lobe's weight included) enters the surface it hit at p
    (triangle prim of instance inst, from outside where front; geometric normal g and
    shading normal n facing the ray along d), walks from p, its first ray naming prim
    (as Cycles' walk starts), or for Christensen-Burley finds its exit by the disk
    (subsurface_disk.find_exit), and leaves: queues at most one shadow ray (count ns) and
    one next ray (count nn), as path_vertex.shade does. key: the walk's stream
    (subsurface.walk_key); rays: the scene for rays cast here (subsurface.local_hit).
    programs (None in a scene without shader
    programs), params, hit_row, regs: what the exit's material program reads and writes
    (path_vertex.shade's), run there for the normal it bends. paths: the paths' state
    (path_state.PathState), updated for path p."""
    time, bounce, counts, beta = paths.time[p], paths.bounce, paths.counts, paths.beta
    cont, prev_pdf, prev_pos, ray_bits = paths.cont, paths.prev_pdf, paths.prev_pos, \
        paths.ray_bits
    min_pdf, stacks, path_info = paths.min_pdf, paths.stacks, (paths.used, paths.cone)
    mesh = object_of(rays[1], prim)
    if row[P_SSS_METHOD] == SSS_BURLEY:
        left, prim2, inst2, u, v, wdx, wdy, wdz, tr, tg, tb = find_exit(
            rays, new_ray_record(rays[0]), geometry, key, time, mesh, inst, front, px, py,
            pz, gx, gy, gz, (max(row[P_SSS_RADIUS], 0.0), max(row[P_SSS_RADIUS + 1], 0.0),
                             max(row[P_SSS_RADIUS + 2], 0.0)), u1, u2)
        tr, tg, tb = br * tr, bg * tg, bb * tb
    else:
        ex_dx, ex_dy, ex_dz, ok = entry_direction(row, dx, dy, dz, nx, ny, nz, u1, u2)
        if not ok or dot(ex_dx, ex_dy, ex_dz, gx, gy, gz) >= 0.0:
            return ns, nn
        albedo, radius, g = walk_params(row)
        left, prim2, inst2, u, v, wdx, wdy, wdz, tr, tg, tb = walk(
            rays, new_ray_record(rays[0]), key, time, mesh, inst, prim, px, py, pz, ex_dx,
            ex_dy, ex_dz, nx, ny, nz, albedo, radius, g, (br, bg, bb), True)
    if not left or not max(tr, tg, tb) > 0.0:
        return ns, nn
    # the exit, seen from outside along the walk's last direction reversed
    qx, qy, qz, hx, hy, hz, mx, my, mz, front2, _ = rebuild_at_time(
        geometry, prim2, inst2, u, v, -wdx, -wdy, -wdz, time)
    b = bounce[p]
    n0x, n0y, n0z = mx, my, mz          # the surface's own normal (shadow rays leave by it)
    soften, bent = True, False
    if programs is not None:
        # a bump or normal map bends the exit's normal too: Cycles runs the shader there
        # for it (SD_HAS_BSSRDF_BUMP), its lobes on that normal made a valid reflector
        m2 = geometry[3][prim2]
        if has_program(programs, m2):
            uu, vv = hit_uv(geometry[6], prim2, u, v)
            _, _, bx, by, bz, rx, ry, rz, bent, soften = run_program(
                programs, params, geometry, counts, path_info, p, m2, prim2, inst2, u, v,
                uu, vv, qx, qy, qz, hx, hy, hz, mx, my, mz, -wdx, -wdy, -wdz, front2,
                ray_bits[p], b, 0.0, hit_row, regs, 0.5)
            if bent:
                mx, my, mz = bx, by, bz
                if params[m2, P_SETS_NORMAL] != 0.0:     # a Set Normal: the surface's own
                    n0x, n0y, n0z = surface_normal(programs, m2, regs, rx, ry, rz)
    mode = cfg.mis_mode
    # next-event estimation on the exit's Lambertian surface (lights picked for it as
    # Cycles' tree picks them: one-sided, on the surface's own normal, sd->N)
    recv = lt.receiver(qx, qy, qz, n0x, n0y, n0z, lt.ONE_SIDED)
    if lt.n_entries(lights) > 0:
        k, lx, ly, lz, dist, lr, lg, lb, lpdf, delta, lprim, margin = lt.sample(
            lights, recv, stream_uniform(key, EXIT_STEP, 0),
            stream_uniform(key, EXIT_STEP, 1), stream_uniform(key, EXIT_STEP, 2), time)
        if lpdf > 0.0:     # an emission that varies over its triangle: there
            lr, lg, lb = emitter_radiance(emitters, lights, lprim, counts, path_info, p, b,
                                          qx, qy, qz, lx, ly, lz, dist, time, lr, lg, lb)
        seen = lt.entry_visibility(lights, k)
        # (Cycles' bump shadowing where the normal is bent: path_vertex's bent_diffuse)
        cosine = dot(lx, ly, lz, mx, my, mz) * bump_shadowing(n0x, n0y, n0z, mx, my, mz,
                                                             lx, ly, lz, soften)
        if (lpdf > 0.0 and max(lr, lg, lb) > 0.0 and cosine > 0.0
                and (seen & DIFFUSE_BIT) != 0):
            bpdf = cosine * INV_PI
            wt = nee_weight(mode, lpdf, bpdf, delta) / lpdf * cosine * INV_PI
            cr, cg, cb = tr * lr * wt, tg * lg * wt, tb * lb * wt
            if not seen & SHADOW_BIT:
                clamp = cfg.clamp_direct if b == 0 else cfg.clamp_indirect
                tl.lit(tally, p, b, cr, cg, cb, clamp, DIFFUSE_SHARES, tl.entry_group(tally, k))
            else:
                sox, soy, soz, own = shadow_origin(
                    geometry[0], geometry[1], geometry[4], geometry[13], geometry[9], prim2,
                    inst2, u, v, qx, qy, qz, hx, hy, hz, n0x, n0y, n0z, lx, ly, lz)
                sdx, sdy, sdz, far = ray_queues.towards(sox, soy, soz, qx, qy, qz, lx, ly,
                                                         lz, dist, margin)
                ns = ray_queues.push(shadows, ns, p, b, sox, soy, soz, sdx, sdy, sdz, far, cr,
                                     cg, cb, stacks, own, inst2, lprim)
                tl.queued(tally, ns - 1, p, b, DIFFUSE_SHARES, tl.entry_group(tally, k))
    # the diffuse bounce from the exit (f cos / pdf = 1); the path is here within its
    # bounce budget, and ends at the vertex this ray finds if it uses it up
    ix, iy, iz = cosine_hemisphere(stream_uniform(key, EXIT_STEP, 3),
                                   stream_uniform(key, EXIT_STEP, 4))
    ox, oy, oz = to_world(ix, iy, iz, mx, my, mz)
    if dot(ox, oy, oz, hx, hy, hz) <= 0.0 or not iz > 0.0:
        return ns, nn
    shadowing = bump_shadowing(n0x, n0y, n0z, mx, my, mz, ox, oy, oz, soften)
    tr, tg, tb = tr * shadowing, tg * shadowing, tb * shadowing
    if not max(tr, tg, tb) > 0.0:
        return ns, nn
    if b + 1 >= ROULETTE_START:
        cont[p] = roulette(stream_uniform(key, EXIT_STEP, 5), tr, tg, tb)
    if ends_path(cfg, b + 1, counts[p, 0] + 1, 0):
        cont[p] = SPENT
    if not (tr < math.inf and tg < math.inf and tb < math.inf):
        return ns, nn
    pdf = iz * INV_PI
    beta[p, 0], beta[p, 1], beta[p, 2] = tr, tg, tb
    counts[p, 0] += 1
    bounce[p] = b + 1
    ray_bits[p] = DIFFUSE_BIT
    min_pdf[p] = min(min_pdf[p], pdf)
    keep_receiver(prev_pos, p, recv)
    prev_pdf[p] = pdf
    return ns, ray_queues.push_next(nexts, nn, p, qx, qy, qz, ox, oy, oz, prim2, inst2)
