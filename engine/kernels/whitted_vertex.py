"""One vertex of Whitted's ray tracer (1980) for every live path of a wavefront: the
lecture's baseline, on the same BSDFs, lights, shader programs and motion as the path
tracer (`path_vertex.shade`, whose arguments this kernel takes, so that one wavefront
loop runs both: `engine.integrators.compiled_path`).

At each hit:
- the emission the ray found, unweighted (lamps hit in front of the surface, the world
  and sun discs for escaped rays, emissive surfaces);
- direct light from every lamp through ONE shadow ray to a fixed point of it (the
  sample at (1/2, 1/2): an area lamp's centre, the direction of a sphere lamp's or a
  sun's centre), so shadows are hard. The world and emissive surfaces light nothing
  directly; they are seen along the rays. The light is weighted by the lobes that are
  not followed (diffuse, sheen, translucency, and subsurface scattering as the diffuse
  lobe it is a part of: `bsdf.eval_seen` with diffuse rays only);
- one continuing ray, a perfect mirror reflection or a perfect refraction: the
  material's specular, metal, coat and glass lobes with their roughness set to zero
  (GGX at alpha = 1e-4 for reflection, the exact smooth interface for glass), chosen by
  their weights, so a rough metal is a mirror here, as in Whitted's model. Where a hit
  both reflects and refracts, one of the two rays of Whitted's tree is followed, with
  probability proportional to its weight and the weight divided by that probability: the
  same expectation as the tree, one ray per path.

Only the pixel (and the shutter time, the lens) is sampled; the lobe choice above takes
one number per bounce. Every path ends at the file's Max Bounces (no Russian roulette).
"""
from __future__ import annotations

import numpy as np

from .bsdf.principled import TRANSMISSION
from ..sampling import dimensions as D
from ..sampling.dispatch import sample_1d
from . import lights as lt
from . import ray_queues
from .bsdf import principled as bsdf
from . import hair_tangent
from .bsdf import anisotropic
from .bsdf.state import S_ANY_SIDE
from .bsdf.params import (P_ANISO_KIND, P_COAT_ROUGHNESS, P_FILTER_ALPHA, P_HAIR, P_HOLDOUT,
                          P_ROUGHNESS, P_SETS_NORMAL, P_SSS_WEIGHT, P_TRANSLUCENT)
from .frame import dot, to_local, to_world
from .jit import kernel
from .lights.light_set import sample_lamp_at
from .lights.pack import C_TYPE, EMIT_DIM, LAMPS, T_ENV, T_ENV_MAP
from .path_state import TracedScene
from .path_weights import DIFFUSE_BIT, SHADOW_BIT, _add, holdout_share, uncovered
from .surface import hit_uv, surface_at
from .surface_hit import coat_frame, material_row, run_program, surface_emission
from .tuple_ref import by_ref
from ..nodes.context import N_HIT
from ..nodes.differentials import cone_moves
from ..nodes.interpreter import has_program
from ..nodes.pack import NREGS
from ..nodes.shading import bent_diffuse_lobes, surface_normal

CENTRE = 0.5           # the fixed point of every lamp: its sample at (1/2, 1/2)


@kernel(allocates=False)
def lamp_rays(lights):
    """Shadow rays per shading point: one per lamp that is not the world."""
    count = 0
    lamps = lights[LAMPS]
    for k in range(lights[LAMPS].shape[0]):
        kind = lamps[k, C_TYPE]
        if kind != T_ENV and kind != T_ENV_MAP:
            count += 1
    return count


@kernel(allocates=False)
def mirror_row(row):
    """The material row of the lobes Whitted follows: roughness zero (the coat's too),
    no translucency or subsurface scattering (diffuse lobes), no Filter Glossy."""
    row[P_ROUGHNESS] = 0.0
    row[P_COAT_ROUGHNESS] = 0.0
    row[P_FILTER_ALPHA] = 0.0
    row[P_SSS_WEIGHT] = 0.0
    for c in range(3):
        row[P_TRANSLUCENT + c] = 0.0


@kernel
def shade_whitted(depth, cfg, paths, tally, live, ro, rd, rt, hits, stopped, scene, shadows,
                  nexts, programs, volumes, het, sss, shaded):
    """`whitted_by_ref` with the records by reference, as `path_vertex.shade` passes them
    (tuple_ref.py). The arguments are `whitted_by_ref`'s."""
    s = scene
    refs = by_ref(TracedScene(by_ref(s.geometry), s.params, s.emission, by_ref(s.textures),
                              by_ref(s.tables), by_ref(s.lights), s.world, s.vol,
                              s.het_count))
    return whitted_by_ref(depth, cfg, by_ref(paths), by_ref(tally), live, ro, rd, rt, hits,
                          stopped, refs, by_ref(shadows), by_ref(nexts), by_ref(programs),
                          volumes, het, sss, shaded)


@kernel
def whitted_by_ref(depth, cfg, paths, tally, live, ro, rd, rt, hits, stopped, scene,
                   shadows, nexts, programs, volumes, het, sss, shaded):
    """Whitted's bounce for the live paths `live` whose rays (ro, rd, rt) hit `hits`.
    The arguments are `path_vertex.shade`'s (read its docstring); this kernel reads no
    roulette verdict, MIS state or volume (the paths' min_pdf, cont, prev_pdf, prev_pos;
    volumes, het and sss are unused: subsurface scattering is its diffuse lobe here), and
    queues up to `lamp_rays(lights)` shadow rays per path, so the shadow queue must hold
    that many times the live paths. Returns (shadow count, next count)."""
    pkey, index, beta, counts = paths.key, paths.index, paths.beta, paths.counts
    bounce, stacks, ray_bits, path_time = paths.bounce, paths.stacks, paths.ray_bits, \
        paths.time
    alpha, path_info = paths.alpha, (paths.used, paths.cone)
    geometry, params, emission, textures = scene.geometry, scene.params, scene.emission, \
        scene.textures
    tables, lights, world = scene.tables, scene.lights, scene.world
    hit_t, hit_prim, hit_inst, hit_u, hit_v = hits.t, hits.prim, hits.inst, hits.u, hits.v
    tri_material, holdout, corner_uvs = geometry[3], geometry[5], geometry[6]
    film_transparent = cfg.film_transparent and alpha.shape[0] > 0
    kind, spp = cfg.sampler, cfg.spp
    max_bounces = cfg.max_bounces
    clamp_direct, clamp_indirect = cfg.clamp_direct, cfg.clamp_indirect
    lamps = lights[LAMPS]
    state = np.empty(bsdf.NSTATE)
    row = np.empty(params.shape[1])
    hit_row = np.zeros(N_HIT)
    regs = np.zeros(max(textures[NREGS][0], 1))
    ns_out, nn_out = 0, 0
    base = D.FIRST_BOUNCE + depth * D.PER_BOUNCE
    for j in range(live.shape[0]):
        p = live[j]
        ox, oy, oz = ro[j, 0], ro[j, 1], ro[j, 2]
        dx, dy, dz = rd[j, 0], rd[j, 1], rd[j, 2]
        br, bg, bb = beta[p, 0], beta[p, 1], beta[p, 2]
        hit = hit_prim[j] >= 0
        t_geom = hit_t[j] if hit else rt[j]
        b = bounce[p]
        clamp_hit = clamp_direct if b <= 1 else clamp_indirect     # as path_vertex.shade
        # 1. emission found: every lamp in front of the geometry (rays pass through lamps)
        for k in range(lamps.shape[0]):
            t_l, lr, lg, lb = lt.lamp_hit(lights, k, ox, oy, oz, dx, dy, dz, ray_bits[p],
                                          path_time[p])
            if t_l < t_geom:
                _add(tally.L, p, br * lr, bg * lg, bb * lb, clamp_hit)
        if not hit:
            if b == 0 and film_transparent:
                alpha[p] = uncovered(br, bg, bb)
                continue
            # (no light sampling to weigh against: the receiver's pdfs go unused)
            recv = lt.receiver(ox, oy, oz, 0.0, 0.0, 0.0, lt.OMNI)
            er, eg, eb, _ = lt.world_escaped(lights, world, ray_bits[p], dx, dy, dz, recv,
                                             path_time[p])
            for s in range(lt.n_suns(lights)):
                sr, sg, sb, _ = lt.sun_escaped(lights, s, dx, dy, dz, recv, path_time[p])
                er, eg, eb = er + sr, eg + sg, eb + sb
            _add(tally.L, p, br * er, bg * eg, bb * eb, clamp_hit)
            continue
        if stopped[j]:
            continue                      # past the transparent bounce limit
        prim = hit_prim[j]
        if b == 0 and holdout.shape[0] > 0 and holdout[prim]:
            if alpha.shape[0] > 0:        # Cycles' holdout: a hole, for camera rays only
                alpha[p] = uncovered(br, bg, bb)
            continue
        px, py, pz, gx, gy, gz, nx, ny, nz, front, _ = surface_at(
            geometry, prim, hit_inst[j], hit_u[j], hit_v[j], ox, oy, oz, hit_t[j], dx, dy,
            dz, path_time[p])
        m = tri_material[prim]
        uu, vv = hit_uv(corner_uvs, prim, hit_u[j], hit_v[j])
        programmed = programs is not None and has_program(programs, m)
        bent, correct = False, True
        rx, ry, rz = nx, ny, nz
        u_lobe = sample_1d(kind, pkey[p], spp, index[p], base + D.BSDF_LOBE)
        ms = m
        n0x, n0y, n0z = nx, ny, nz
        if programs is not None and programmed:
            ms, u_lobe, nx, ny, nz, rx, ry, rz, bent, correct = run_program(
                programs, params, geometry, counts, path_info, p, m, prim, hit_inst[j],
                hit_u[j], hit_v[j], uu, vv, px, py, pz, gx, gy, gz, nx, ny, nz, dx, dy, dz, front,
                ray_bits[p], b, t_geom, hit_row, regs, u_lobe)
            if params[ms, P_SETS_NORMAL] != 0.0:      # a Set Normal: the surface's own
                n0x, n0y, n0z = surface_normal(programs, ms, regs, rx, ry, rz)
        holed, u_lobe = holdout_share(params[ms, P_HOLDOUT], u_lobe, b, alpha, p, br, bg, bb)
        if holed:
            continue                      # a Holdout's share: a hole, or no light
        er, eg, eb = surface_emission(programs, textures, emission, params,
                                      lights[EMIT_DIM], m, uu, vv, regs, programmed,
                                      dx * n0x + dy * n0y + dz * n0z, True)
        _add(tally.L, p, br * er, bg * eg, bb * eb, clamp_hit)
        wox, woy, woz = to_local(-dx, -dy, -dz, nx, ny, nz)
        material_row(params, textures, programs, ms, uu, vv, regs, programmed, row)
        if row[P_HAIR] != 0.0:           # a hair closure: the fibre's direction at the hit
            hair_tangent.write(geometry, prim, hit_inst[j], hit_u[j], hit_v[j], path_time[p],
                               nx, ny, nz, row)
        if row[P_ANISO_KIND] != 0.0:     # an anisotropic lobe's tangent, to the frame
            anisotropic.localize_tangent(row, nx, ny, nz)
        if programs is not None and programmed:    # a coat keeps its own normal
            coat_frame(programs, ms, regs, row, bent, n0x, n0y, n0z, gx, gy, gz, -dx, -dy, -dz, nx,
                       ny, nz)
        row[P_SSS_WEIGHT] = 0.0          # Whitted's model: subsurface light is diffuse
        # 2. direct light: one shadow ray to each lamp's fixed point, on the lobes that
        # are not followed (diffuse, sheen, translucency); on a bent frame the sheen about
        # the raw normal, as Cycles' (principled.setup_about)
        dnx, dny, dnz = to_local(rx, ry, rz, nx, ny, nz) if bent else (0.0, 0.0, 1.0)
        bsdf.setup_about(row, front, wox, woy, woz, tables, state, dnx, dny, dnz)
        clamp = clamp_direct if b == 0 else clamp_indirect
        for k in range(lamps.shape[0]):
            if lamps[k, C_TYPE] == T_ENV or lamps[k, C_TYPE] == T_ENV_MAP:
                continue
            seen = lt.entry_visibility(lights, k)
            if not seen & DIFFUSE_BIT:
                continue
            wx, wy, wz, dist, lr, lg, lb, lpdf, delta = sample_lamp_at(
                lights, k, px, py, pz, CENTRE, CENTRE, path_time[p])
            if not (lpdf > 0.0 and max(lr, lg, lb) > 0.0):
                continue
            if bent:
                fr, fg, fb = bent_diffuse_lobes(state, wox, woy, woz, n0x, n0y, n0z, nx, ny,
                                                nz, rx, ry, rz, wx, wy, wz, correct)
            else:
                lx, ly, lz = to_local(wx, wy, wz, nx, ny, nz)
                fr, fg, fb = bsdf.eval_seen(state, wox, woy, woz, lx, ly, lz, True, False,
                                            False)
                c = abs(lz)
                fr, fg, fb = fr * c, fg * c, fb * c
            if not max(fr, fg, fb) > 0.0:
                continue
            w = 1.0 / lpdf
            cr, cg, cb = br * fr * lr * w, bg * fg * lg * w, bb * fb * lb * w
            if not seen & SHADOW_BIT:            # a lamp casting no shadow
                _add(tally.L, p, cr, cg, cb, clamp)
                continue
            sdx, sdy, sdz, far = ray_queues.towards(px, py, pz, px, py, pz, wx, wy, wz,
                                                     dist, 0.0)
            ns_out = ray_queues.push(shadows, ns_out, p, b, px, py, pz, sdx, sdy, sdz, far,
                                     cr, cg, cb, stacks, prim, hit_inst[j])
        # 3. one ray of Whitted's tree: mirror reflection or refraction
        if b >= max_bounces:
            continue
        mirror_row(row)
        bsdf.setup(row, front, wox, woy, woz, tables, state)
        ad = False
        ag = counts[p, 1] < cfg.glossy_bounces
        at = counts[p, 2] < cfg.transmission_bounces
        if not (ag or at):
            continue
        ix, iy, iz, wr, wg, wb, spdf, skind, sdelta, valid = bsdf.sample(
            state, wox, woy, woz, u_lobe, 0.5, 0.5, ad, ag, at)
        if not valid:
            continue
        wx, wy, wz = to_world(ix, iy, iz, nx, ny, nz)
        side = dot(wx, wy, wz, gx, gy, gz)
        if state[S_ANY_SIDE] == 0.0 and ((side >= 0.0) if skind == TRANSMISSION
                                          else (side <= 0.0)):
            continue       # reflection leaves on the geometric normal's side, refraction
            #                through (a hair lobe's direction on either, as in Cycles)
        br, bg, bb = br * wr, bg * wg, bb * wb
        if not max(br, bg, bb) > 0.0 or not (br < np.inf and bg < np.inf and bb < np.inf):
            continue
        beta[p, 0], beta[p, 1], beta[p, 2] = br, bg, bb
        counts[p, skind] += 1
        bounce[p] = b + 1
        ray_bits[p] = DIFFUSE_BIT << skind
        cone_moves(path_info[1], p, t_geom)
        nn_out = ray_queues.push_next(nexts, nn_out, p, px, py, pz, wx, wy, wz, prim,
                                      hit_inst[j])
    return ns_out, nn_out
