"""One vertex of Kajiya's path tracer, with next-event estimation and MIS, for every live
path of a wavefront (the loop: `engine.integrators.compiled_path`).

The estimator, at each surface vertex:
  1. emission seen by the incoming ray: area and sphere lamps (hit analytically), sun
     discs (escaped rays) and emissive triangles (hit by the ray cast), each weighted
     against light sampling by the power heuristic with the pdf light sampling would have
     had for that direction; camera rays and specular bounces (pdf = inf) see emission
     with weight 1 (lamps and the world: found_light.py);
  2. next-event estimation: one light entry (lamp or emissive triangle) picked in
     proportion to its power, one point on it, one shadow ray, weighted against BSDF
     sampling by the power heuristic;
  3. BSDF sampling over every lobe; Cycles' Russian roulette: the ray leaves with a
     verdict (survival probability q = min(sqrt(max throughput), 1), or ended), applied
     at the vertex it finds, after the emission found there (step 1). A bounce that uses
     up a budget (Cycles' total, diffuse, glossy and transmission limits, each plus one:
     path_weights.ends_path) leaves with the verdict "ended": its ray gathers only what
     it finds, as in Cycles. The integrator's `mis_mode` (a test and debug
hook, not a user setting) selects the weights of the two estimators of direct light:
'mis' (default) the power heuristic; 'light' light sampling only; 'bsdf' BSDF sampling
only (next-event estimation is kept for delta lights and for directions the BSDF cannot
sample). All three are unbiased and agree in expectation
(tests/test_path_estimators.py). Radiance sums are float64.

`shade` runs after the closest-hit query of the bounce; the caller traces the shadow
rays it queues (`Accelerator.occluded`), adds the contributions of the visible ones, and
traces the next rays.
"""
from __future__ import annotations


import numpy as np

from .bsdf.principled import SUBSURFACE, TRANSMISSION
from ..sampling import dimensions as D
from ..sampling.dispatch import sample_1d, sample_2d
from . import lights as lt
from .lights.pack import EMIT_DIM
from .bsdf import principled as bsdf
from .bsdf.joint_sample import sample_joint
from .bsdf.state import S_ANY_SIDE, S_DIFFUSE_LABEL, S_WALTER
from . import hair_tangent
from .bsdf import anisotropic
from . import ray_queues
from .frame import dot, to_local, to_world
from .jit import kernel
from .light_bsdf import lit_bsdf
from .found_light import background, escaped, lamps_in_front
from . import light_tally as tl
from .pass_shares import NO_SHARES, bounce_shares, light_shares, lobe_colours
from .medium_vertex import scatter
from .path_state import TracedScene
from .tuple_ref import by_ref
from .path_weights import (DIFFUSE_BIT, GLOSSY_BIT, ROULETTE_START, SHADOW_BIT, SPENT,
                           TRANSMISSION_BIT, _INF, continues, ends_path, hit_weight,
                           holdout_share,
                           keep_receiver, nee_weight, previous_receiver, roulette, uncovered)
from .medium_density import has_heterogeneous
from .medium_segment import NO_SEGMENT, NO_SEGMENT_MIS, along_ray
from .prepare_closures import prepare_closures
from .volume import V_BOUNDARY, V_HAS, in_medium, stack_cross
from .bsdf.params import P_ANISO_KIND, P_BUMP_CORRECTION, P_HAIR, P_HOLDOUT, P_SETS_NORMAL
from .surface import hit_uv, surface_at
from .terminator import shadow_origin
from .surface_hit import coat_frame, material_row, run_program, surface_emission
from .shaded_emitter import EmitterShading, radiance as emitter_radiance
from .subsurface import walk_key
from .subsurface_vertex import scatter_below
from ..nodes.context import N_HIT
from ..nodes.differentials import cone_moves
from ..nodes.interpreter import has_program
from ..nodes.pack import NREGS
from ..nodes.shading import (bent_diffuse, may_emit, surface_normal,
                             valid_reflection_normal)

@kernel
def shade(depth, cfg, paths, tally, live, ro, rd, rt, hits, stopped, scene, shadows, nexts,
          programs, volumes, het, sss, shaded):
    """`shade_by_ref` with the records by reference (tuple_ref.py): the kernels a vertex
    calls take the light table, the geometry, the path state, ... as one pointer each,
    not as their arrays' hundreds of words. The arguments are `shade_by_ref`'s."""
    s = scene
    refs = by_ref(TracedScene(by_ref(s.geometry), s.params, s.emission, by_ref(s.textures),
                              by_ref(s.tables), by_ref(s.lights), s.world, s.vol,
                              s.het_count))
    return shade_by_ref(depth, cfg, by_ref(paths), by_ref(tally), live, ro, rd, rt, hits,
                        stopped, refs, by_ref(shadows), by_ref(nexts), by_ref(programs),
                        volumes, het, sss, shaded)


@kernel
def shade_by_ref(depth, cfg, paths, tally, live, ro, rd, rt, hits, stopped, scene, shadows,
                 nexts, programs, volumes, het, sss, shaded):
    """One bounce for the live paths `live` whose rays (ro, rd, rt) hit `hits`
    (engine.accel.HitArrays: t, prim, inst, u, v per ray; prim -1 where missed); stopped:
    rays that ended at the transparent bounce limit. Writes the shadow rays to `shadows`
    (ray_queues.ShadowQueue; their contributions before the clamp, which
    light_tally.add_transmitted applies) and the continuing paths' next rays to `nexts`
    (ray_queues.NextQueue); returns (shadow count, next count).

    cfg: the render's engine.kernels.path_config.PathConfig (see `prepare_closures`).
    tally: where the light goes (engine.kernels.light_tally: Combined, and the light
    passes and light groups when the render asks for them).
    paths: every path's state (engine.kernels.path_state.PathState, whose docstring says
    what each field holds), updated in place; scene: engine.kernels.path_state.TracedScene.
    A ray in a medium first travels through it (`medium_segment.along_ray`): it may
    scatter there (`medium_vertex.scatter` shades that point), emission along it is
    added, and what it reaches beyond is weighted by its transmittance. A hit on a
    volume's boundary surface is crossed without a bounce.

    programs, volumes, het, sss, shaded: what the scene uses, each None when it does not
    (Numba then compiles this kernel without that code, and never compiles what only it
    calls: a scene without node programs and volumes compiles in about half the time,
    benchmarks section 10). programs: the
    shading tables when a material has a shader program; volumes: the volume table
    when the scene has media; het: the same when one of them is heterogeneous; sss: the
    scene for rays cast inside a kernel (engine.kernels.subsurface.local_hit) when a
    material scatters below its surface: a sampled subsurface lobe then walks there
    (engine.kernels.subsurface_vertex), queueing one more shadow ray for its exit;
    shaded: the emission table when a light entry's emission varies over its triangle,
    which a light sample then evaluates there (engine.kernels.shaded_emitter)."""
    pkey, index, beta, counts = paths.key, paths.index, paths.beta, paths.counts
    bounce, ray_bits, min_pdf = paths.bounce, paths.ray_bits, paths.min_pdf
    cont, prev_pdf, prev_pos, path_time = paths.cont, paths.prev_pdf, paths.prev_pos, \
        paths.time
    alpha, stacks, path_info = paths.alpha, paths.stacks, (paths.used, paths.cone)
    geometry, params, emission, textures = scene.geometry, scene.params, scene.emission, \
        scene.textures
    tables, lights, world, vol, het_count = scene.tables, scene.lights, scene.world, \
        scene.vol, scene.het_count
    hit_t, hit_prim, hit_inst, hit_u, hit_v = hits.t, hits.prim, hits.inst, hits.u, hits.v
    het_scene = has_heterogeneous(vol)
    vhit = np.zeros(N_HIT)
    tri_material, holdout, corner_uvs = geometry[3], geometry[5], geometry[6]
    film_transparent = cfg.film_transparent and alpha.shape[0] > 0
    kind, spp = cfg.sampler, cfg.spp
    clamp_direct, clamp_indirect, mode = cfg.clamp_direct, cfg.clamp_indirect, cfg.mis_mode
    n_lights = lt.n_entries(lights)
    state = np.empty(bsdf.NSTATE)
    row = np.empty(params.shape[1])
    hit_row = np.zeros(N_HIT)
    regs = np.zeros(max(textures[NREGS][0], 1))
    if shaded is None:
        emitters = None
    else:        # the emitters' programs write buffers of their own
        emitters = EmitterShading(programs, params, geometry, textures, emission,
                                  np.zeros(N_HIT), np.zeros(max(textures[NREGS][0], 1)))
    ns_out, nn_out = 0, 0
    base = D.FIRST_BOUNCE + depth * D.PER_BOUNCE
    # what shadow rays' origins read (terminator), taken out of the tuple once
    positions, corners, corner_normals, objects, cutoff = (
        geometry[0], geometry[1], geometry[4], geometry[9], geometry[13])
    for j in range(live.shape[0]):
        p = live[j]
        ox, oy, oz = ro[j, 0], ro[j, 1], ro[j, 2]
        dx, dy, dz = rd[j, 0], rd[j, 1], rd[j, 2]
        br, bg, bb = beta[p, 0], beta[p, 1], beta[p, 2]
        hit = hit_prim[j] >= 0
        t_geom = hit_t[j] if hit else rt[j]
        b = bounce[p]
        # Emission found by this bounce's rays is clamped by bounce b - 1 (Cycles'
        # film_clamp_light): what the camera sees and what the first surface's ray finds
        # (a lamp hit from there is direct light, as its next-event estimate is) by the
        # Direct clamp, the rest by the Indirect one.
        clamp_hit = clamp_direct if b <= 1 else clamp_indirect
        # 0. the medium along the ray: emission, transmittance, maybe a scattering
        b0r, b0g, b0b = br, bg, bb
        vmode, scattered, t_end = 0, False, t_geom
        seg = NO_SEGMENT
        g_phase = 0.0
        segment_mis = NO_SEGMENT_MIS             # no equiangular counterpart
        if volumes is not None and in_medium(stacks, p):
            # A ray that reaches nothing goes on through its media to infinity, also past
            # the camera's clip end (Cycles ends a missed ray's volume segment at
            # FLT_MAX); lamps are still found only up to the ray's own end.
            vmode, scattered, t_end, br, bg, bb, seg, g_phase, segment_mis, ns_out = \
                along_ray(depth, cfg, paths, p, tally, lights, vol, het is not None and
                          het_scene, textures, geometry, shadows, ns_out, ox, oy, oz, dx,
                          dy, dz, t_geom if hit else _INF, br, bg, bb, clamp_hit, vhit,
                          regs, het_count, emitters)
        # 1a. area and sphere lamps in front of the geometry
        lamps_in_front(tally, lights, paths, p, b, ox, oy, oz, dx, dy, dz,
                       min(t_end, t_geom),
                       (vmode,) + seg,
                       vol.shape[0] > 0, mode, b0r, b0g, b0b, clamp_hit)
        if volumes is not None and scattered:
            q = continues(cont, p)             # the roulette, after the emission found
            if q == 0.0:
                continue
            br, bg, bb = br / q, bg / q, bb / q
            cone_moves(path_info[1], p, t_end)
            ns_out, nn_out = scatter(depth, cfg, paths, p, ox + dx * t_end, oy + dy * t_end,
                                     oz + dz * t_end, dx, dy, dz, br, bg, bb, g_phase, tally,
                                     lights, vol, shadows, ns_out, nexts, nn_out, segment_mis,
                                     emitters)
            continue
        # 1b. escaped rays: the world and sun discs (or, for camera rays on a transparent
        # film, no colour and the coverage left)
        if not hit:
            if b == 0 and film_transparent:
                alpha[p] = uncovered(br, bg, bb)
                background(tally, lights, world, paths, p, dx, dy, dz, br, bg, bb)
                continue
            escaped(tally, lights, world, paths, p, b, dx, dy, dz, mode, br, bg, bb,
                    clamp_hit)
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
        if vol.shape[0] > 0 and vol[m, V_BOUNDARY] != 0.0:
            # a volume's boundary: no surface; the ray goes on inside or outside it
            stack_cross(stacks, p, m, front)
            cone_moves(path_info[1], p, t_geom)
            beta[p, 0], beta[p, 1], beta[p, 2] = br, bg, bb
            nn_out = ray_queues.push_next(nexts, nn_out, p, px, py, pz, dx, dy, dz, prim,
                                          hit_inst[j])
            continue
        if cont[p] <= 0.0 and not may_emit(textures, emission, m):
            continue                      # ended by the roulette, and nothing to find here
        uu, vv = hit_uv(corner_uvs, prim, hit_u[j], hit_v[j])
        programmed = programs is not None and has_program(programs, m)
        bent, correct = False, True
        rx, ry, rz = nx, ny, nz
        # the lobe choice's number; a Mix Shader picks its shader with it first
        u_lobe = sample_1d(kind, pkey[p], spp, index[p], base + D.BSDF_LOBE)
        ms = m                                   # the material shaded
        n0x, n0y, n0z = nx, ny, nz               # the surface's own shading normal
        if programs is not None and programmed:
            ms, u_lobe, nx, ny, nz, rx, ry, rz, bent, correct = run_program(
                programs, params, geometry, counts, path_info, p, m, prim, hit_inst[j],
                hit_u[j], hit_v[j], uu, vv, px, py, pz, gx, gy, gz, nx, ny, nz, dx, dy, dz, front,
                ray_bits[p], b, t_geom, hit_row, regs, u_lobe)
        else:
            correct = params[m, P_BUMP_CORRECTION] != 0.0
        holed, u_lobe = holdout_share(params[ms, P_HOLDOUT], u_lobe, b, alpha, p, br, bg, bb)
        if holed:
            continue                      # a Holdout's share: a hole, or no light
        # Cycles' sd->N, which bent lobes are shadowed against and shadow rays are lifted
        # by: the surface's own normal, or the bent one where the program sets it (the
        # Displacement socket's bump)
        s0x, s0y, s0z = n0x, n0y, n0z
        if programs is not None and params[ms, P_SETS_NORMAL] != 0.0:
            s0x, s0y, s0z = surface_normal(programs, ms, regs, rx, ry, rz)
        if not bent and correct and (nx != gx or ny != gy or nz != gz):
            # a smooth mesh's normal, as Cycles' specular lobes (and the subsurface
            # entry) use it: made a valid reflector for the view (a silhouette's normal
            # may face away from it); the diffuse lobe keeps it as it is
            sx, sy, sz = valid_reflection_normal(gx, gy, gz, -dx, -dy, -dz, nx, ny, nz)
            if sx != nx or sy != ny or sz != nz:
                rx, ry, rz = nx, ny, nz
                nx, ny, nz, bent = sx, sy, sz, True
        # 1c. emissive surfaces (two-sided), weighted against sampling that triangle
        # (dimmed by a coat and sheen as Cycles' closures dim it: not on a spent path)
        er, eg, eb = surface_emission(programs, textures, emission, params,
                                      lights[EMIT_DIM], m, uu, vv, regs, programmed,
                                      dx * s0x + dy * s0y + dz * s0z, cont[p] != SPENT)
        if er != 0.0 or eg != 0.0 or eb != 0.0:
            lpdf = lt.mesh_pdf(lights, prim, previous_receiver(prev_pos, p), px, py, pz,
                               path_time[p])
            w = hit_weight(mode, prev_pdf[p], lpdf)
            tl.found(tally, p, b, br * er * w, bg * eg * w, bb * eb * w, clamp_hit, False,
                     tl.prim_group(tally, prim))
        q = continues(cont, p)            # the roulette, after the emission found
        if q == 0.0:
            continue
        br, bg, bb = br / q, bg / q, bb / q
        wox, woy, woz = to_local(-dx, -dy, -dz, nx, ny, nz)
        material_row(params, textures, programs, ms, uu, vv, regs, programmed, row)
        if row[P_HAIR] != 0.0:           # a hair closure: the fibre's direction at the hit
            hair_tangent.write(geometry, prim, hit_inst[j], hit_u[j], hit_v[j], path_time[p],
                               nx, ny, nz, row)
        if row[P_ANISO_KIND] != 0.0:     # an anisotropic lobe's tangent, to the frame
            anisotropic.localize_tangent(row, nx, ny, nz)
        if programs is not None and programmed:    # a coat keeps its own normal
            coat_frame(programs, ms, regs, row, bent, s0x, s0y, s0z, gx, gy, gz, -dx, -dy,
                       -dz, nx, ny, nz)
        keep_g, keep_t = prepare_closures(cfg, row, min_pdf[p], ray_bits[p], counts[p, 0])
        dnx, dny, dnz = 0.0, 0.0, 1.0
        if bent:     # the diffuse and sheen lobes about the raw normal, as Cycles' are
            dnx, dny, dnz = to_local(rx, ry, rz, nx, ny, nz)
        bsdf.setup_about(row, front, wox, woy, woz, tables, state, dnx, dny, dnz)
        if b == 0 and tl.on(tally):
            d_col, g_col, t_col = lobe_colours(state, woz)
            tl.colours(tally, p, br, bg, bb, d_col, g_col, t_col)
        # the point lights are picked for (lights/tree.py), as Cycles' tree picks them:
        # on the surface's own normal (sd->N, not a lobe's bent one), light from below it
        # counting only where the surface transmits
        recv = lt.receiver(px, py, pz, s0x, s0y, s0z,
                           lt.TWO_SIDED if bsdf.transmits(state) else lt.ONE_SIDED)
        # every lobe may continue: a path reaches a vertex only within its bounce budget
        # (the bounce that used it up ended the path at the vertex it found: ends_path)
        ad, ag, at = True, keep_g, keep_t
        # 2. next-event estimation: one light entry, one point, one shadow ray
        if n_lights > 0:
            # (one light: no number drawn to pick it; the tree may still refuse it)
            u_pick = sample_1d(kind, pkey[p], spp, index[p], base + D.LIGHT_PICK) \
                if n_lights > 1 else 0.0
            u1, u2 = sample_2d(kind, pkey[p], spp, index[p], base + D.LIGHT_POINT)
            k, wx, wy, wz, dist, lr, lg, lb, lpdf, delta, lprim, margin = lt.sample(
                lights, recv, u_pick, u1, u2, path_time[p])
            lx, ly, lz = to_local(wx, wy, wz, nx, ny, nz)
            # a uniform world, which Cycles never samples (its escaping rays find it):
            # refraction towards it on Walter's pairs, as those rays see it
            state[S_WALTER] = 1.0 if lt.is_uniform_world(lights, k) else 0.0
            seen = lt.entry_visibility(lights, k)
            see_d = (seen & DIFFUSE_BIT) != 0
            see_g = (seen & GLOSSY_BIT) != 0 and keep_g
            see_t = (seen & TRANSMISSION_BIT) != 0 and keep_t
            fr, fg, fb, cosine = lit_bsdf(state, bent, wox, woy, woz, lx, ly, lz, see_d,
                                          see_g, see_t, s0x, s0y, s0z, nx, ny, nz, rx, ry,
                                          rz, wx, wy, wz, correct)
            if lpdf > 0.0 and max(fr, fg, fb) > 0.0:
                # an emission that varies over its triangle: what it sends from there (its
                # program runs only for a sample the lobes take)
                lr, lg, lb = emitter_radiance(emitters, lights, lprim, counts, path_info, p,
                                              b, px, py, pz, wx, wy, wz, dist, path_time[p],
                                              lr, lg, lb)
            # as in Cycles, the lobes alone decide (on the shading normals): a light
            # under the triangle's own plane but above its smooth normal lights it, its
            # shadow ray leaving from the curved surface the normals describe
            if lpdf > 0.0 and max(lr, lg, lb) > 0.0 and max(fr, fg, fb) > 0.0:
                sox, soy, soz, own = shadow_origin(
                    positions, corners, corner_normals, cutoff, objects, prim, hit_inst[j],
                    hit_u[j], hit_v[j], px, py, pz, gx, gy, gz, s0x, s0y, s0z, wx, wy, wz)
                sdx, sdy, sdz, far = ray_queues.towards(sox, soy, soz, px, py, pz, wx, wy,
                                                         wz, dist, margin)
                bpdf = bsdf.pdf_seen(state, wox, woy, woz, lx, ly, lz, ad, ag, at,
                                     see_d, see_g, see_t)
                shares = NO_SHARES
                if b == 0 and tl.on(tally):
                    shares = light_shares(state, wox, woy, woz, lx, ly, lz, see_d, see_g,
                                          see_t, bent, fr, fg, fb, s0x, s0y, s0z, nx, ny,
                                          nz, rx, ry, rz, wx, wy, wz, correct)
                w = nee_weight(mode, lpdf, bpdf, delta) / lpdf * cosine
                fr, fg, fb = fr * w, fg * w, fb * w
                group = tl.entry_group(tally, k)
                if not seen & SHADOW_BIT:        # a light casting no shadow: no shadow ray
                    tl.lit(tally, p, b, br * fr * lr, bg * fg * lg, bb * fb * lb,
                           clamp_direct if b == 0 else clamp_indirect, shares, group)
                else:
                    ns_out = ray_queues.push(shadows, ns_out, p, b, sox, soy, soz, sdx, sdy,
                                             sdz, far, br * fr * lr, bg * fg * lg,
                                             bb * fb * lb, stacks, own, hit_inst[j],
                                             lprim)
                    tl.queued(tally, ns_out - 1, p, b, shares, group)
                    if (vol.shape[0] > 0 and vol[m, V_HAS] != 0.0
                            and dot(wx, wy, wz, gx, gy, gz) < 0.0):
                        # towards a light through the surface: the shadow ray enters or
                        # leaves the material's volume there, as the refracted path does
                        stack_cross(shadows.stack, ns_out - 1, m, front)
            state[S_WALTER] = 0.0
        # 3. continue by BSDF sampling
        u1, u2 = sample_2d(kind, pkey[p], spp, index[p], base + D.BSDF_DIR)
        ix, iy, iz, wr, wg, wb, spdf, skind, sdelta, valid = sample_joint(
            state, wox, woy, woz, u_lobe, u1, u2, ad, ag, at)
        if not valid:
            continue
        if skind == SUBSURFACE:
            if sss is not None:
                if b == 0:
                    tl.left_first(tally, p, tl.DIFFUSE_SHARES)
                cone_moves(path_info[1], p, t_geom)
                ns_out, nn_out = scatter_below(
                    cfg, walk_key(pkey[p], index[p], depth), p, paths, sss,
                    geometry, row, prim, hit_inst[j], front, px, py, pz, gx, gy, gz, nx,
                    ny, nz, dx, dy, dz, u1, u2, br * wr, bg * wg, bb * wb, tally, lights,
                    shadows, ns_out, nexts, nn_out, programs, params, hit_row, regs,
                    emitters)
            continue
        wx, wy, wz = to_world(ix, iy, iz, nx, ny, nz)
        if bent and ad and not sdelta and spdf > 0.0:
            # the diffuse and sheen lobes' share of the weight, moved from the sampling
            # frame's cosine (eval_seen's: the diffuse above its plane only) to the raw
            # normal's (with bump shadowing)
            fd_r, fd_g, fd_b = bsdf.base_diffuse(state, wox, woy, woz)
            fs_r, fs_g, fs_b = bsdf.sheen_seen(state, woz, ix, iy, iz)
            dr, dg, db = bent_diffuse(state, wox, woy, woz, s0x, s0y, s0z, rx, ry, rz, wx, wy,
                                      wz, ix, iy, iz, correct)
            c, a = max(iz, 0.0), abs(iz)
            wr = max(wr + (dr - fd_r * c - fs_r * a) / spdf, 0.0)
            wg = max(wg + (dg - fd_g * c - fs_g * a) / spdf, 0.0)
            wb = max(wb + (db - fd_b * c - fs_b * a) / spdf, 0.0)
        side = dot(wx, wy, wz, gx, gy, gz)
        if state[S_ANY_SIDE] == 0.0 and ((side >= 0.0) if skind == TRANSMISSION
                                          else (side <= 0.0)):
            continue       # reflection leaves on the geometric normal's side, refraction
            #                through (a hair lobe's direction on either, as in Cycles)
        if b == 0 and tl.on(tally):
            tl.left_first(tally, p, bounce_shares(state, wox, woy, woz, ix, iy, iz, skind,
                                                  sdelta, bent, s0x, s0y, s0z, rx, ry, rz,
                                                  wx, wy, wz, correct))
        br, bg, bb = br * wr, bg * wg, bb * wb
        if b + 1 >= ROULETTE_START:
            u_rr = sample_1d(kind, pkey[p], spp, index[p], base + D.ROULETTE)
            cont[p] = roulette(u_rr, br, bg, bb)
        if ends_path(cfg, b + 1, counts[p, skind] + 1, skind):
            cont[p] = SPENT
        if not max(br, bg, bb) > 0.0 or not (br < _INF and bg < _INF and bb < _INF):
            continue       # nothing left, or overflowed (or NaN): the path ends here
        beta[p, 0], beta[p, 1], beta[p, 2] = br, bg, bb
        counts[p, skind] += 1
        bounce[p] = b + 1
        if skind == TRANSMISSION and vol.shape[0] > 0 and vol[m, V_HAS] != 0.0:
            stack_cross(stacks, p, m, front)     # into or out of the material's volume
        ray_bits[p] = DIFFUSE_BIT << skind     # diffuse, glossy, transmission: 2, 4, 8
        if state[S_DIFFUSE_LABEL] != 0.0:      # a translucent bounce: diffuse as well
            ray_bits[p] |= DIFFUSE_BIT
        if not sdelta:
            min_pdf[p] = min(min_pdf[p], spdf)
        cone_moves(path_info[1], p, t_geom)
        nn_out = ray_queues.push_next(nexts, nn_out, p, px, py, pz, wx, wy, wz, prim,
                                      hit_inst[j])
        keep_receiver(prev_pos, p, recv)
        prev_pdf[p] = _INF if sdelta else spdf
    return ns_out, nn_out
