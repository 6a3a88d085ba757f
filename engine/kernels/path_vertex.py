"""One vertex of Kajiya's path tracer for every live path of a wavefront: the compiled
form of the loop body of `engine.integrators.path.PathIntegrator.radiance` (read its
docstring for the estimator; the steps and names here are the same).

`shade` runs after the closest-hit query of the bounce. For each live path it adds the
emission the incoming ray found (lamps hit analytically, the world and sun discs for
escaped rays, emissive triangles), weighted by multiple importance sampling against
next-event estimation; it prepares one shadow ray of next-event estimation with its
unoccluded contribution; and it samples the BSDF for the next ray, with Russian roulette.
The caller traces the shadow rays (`Accelerator.occluded`), adds the contributions of
the visible ones, and traces the next rays: the Embree queries stay between the stages.
"""
from __future__ import annotations

import math

import numpy as np

from .. import visibility
from ..bsdf.lobes import TRANSMISSION
from ..sampling import dimensions as D
from ..sampling.dispatch import sample_1d, sample_2d
from . import lights as lt
from .bsdf import principled as bsdf
from .frame import dot, to_local, to_world
from .jit import kernel
from .bsdf.params import P_BASE, P_FILTER_ALPHA, P_METALLIC, P_ROUGHNESS
from .surface import hit_uv, offset_origin, rebuild_at_time
from .textures import apply_to_row, emission_at
from ..nodes.context import N_HIT, path_fields
from ..nodes.differentials import cone_at, cone_moves
from ..nodes.interpreter import has_program
from ..nodes.pack import NREGS
from ..nodes.shading import (apply_rows, bent_diffuse, pick_closure, program_emission,
                             program_hit, program_normal)

MIS, LIGHT_ONLY, BSDF_ONLY = 0, 1, 2
# Numba freezes these into its cache; the cache's fingerprint covers every engine file
DIFFUSE_BIT, GLOSSY_BIT, TRANSMISSION_BIT, SHADOW_BIT = (
    visibility.DIFFUSE, visibility.GLOSSY, visibility.TRANSMISSION, visibility.SHADOW)
ROULETTE_START = 3
_INF = np.inf


@kernel
def power_heuristic(a, b):
    if math.isinf(a):
        return 1.0
    if math.isinf(b):
        return 0.0
    a2, b2 = a * a, b * b
    return a2 / (a2 + b2) if a2 + b2 > 0.0 else 0.0


@kernel
def hit_weight(mode, prev_pdf, light_pdf):
    """Weight of emission found by a BSDF-sampled ray (pdf prev_pdf; inf after a camera
    ray or a specular bounce) that light sampling reaches with light_pdf."""
    if mode == MIS:
        return power_heuristic(prev_pdf, light_pdf)
    if mode == LIGHT_ONLY:
        return 1.0 if (math.isinf(prev_pdf) or not light_pdf > 0.0) else 0.0
    return 1.0


@kernel
def nee_weight(mode, light_pdf, bsdf_pdf, delta):
    """Weight of a light sample that the BSDF would have sampled with bsdf_pdf."""
    if mode == MIS:
        return 1.0 if delta else power_heuristic(light_pdf, bsdf_pdf)
    if mode == LIGHT_ONLY:
        return 1.0
    return 1.0 if (delta or not bsdf_pdf > 0.0) else 0.0


@kernel
def clamp_scale(r, g, b, limit):
    """Cycles' clamp: the factor that scales (r, g, b) so no channel exceeds limit."""
    m = max(r, g, b)
    if limit > 0.0 and m > limit:
        return limit / max(m, 1e-300)
    return 1.0


@kernel
def _add(L, p, r, g, b, limit):
    s = clamp_scale(r, g, b, limit)
    L[p, 0] += r * s
    L[p, 1] += g * s
    L[p, 2] += b * s


@kernel
def uncovered(br, bg, bb):
    """Alpha of a camera sample whose ray got through with throughput b (see
    engine.integrators.coverage)."""
    return 1.0 - min(max((br + bg + bb) / 3.0, 0.0), 1.0)


@kernel
def prepare_closures(cfg, row, min_pdf, ray_bit):
    """Cycles' two changes to a hit's BSDF that depend on the path so far (its
    surface_shader_prepare_closures), applied to the material row before setup:

    Filter Glossy (cfg[11], Cycles' `blur_glossy`; 0 = off): after bounces that were
    unlikely (the smallest BSDF pdf along the path, min_pdf, below blur_glossy), every
    microfacet lobe is widened to at least GGX alpha = 0.5 sqrt(1 - min_pdf /
    blur_glossy). A bias that trades sharp caustics and fireflies for blur. As in Cycles,
    whose closure blur follows the closures' setup, only the lobes widen: the energy
    compensation and the layering keep the material's alpha (row[P_FILTER_ALPHA]).

    Caustics (cfg[12] reflective, cfg[13] refractive; 1 = on): with one off, a hit of a
    ray that left a diffuse bounce has no glossy reflection (resp. refraction) lobes.

    Returns (keep glossy lobes, keep transmission lobes)."""
    blur = cfg[11]
    if blur > 0.0 and min_pdf < _INF:
        blur_pdf = min_pdf / blur
        if blur_pdf < 1.0:
            alpha = 0.5 * math.sqrt(1.0 - blur_pdf)
            row[P_FILTER_ALPHA] = alpha     # the lobes only (principled.setup)
    after_diffuse = ray_bit == DIFFUSE_BIT
    return (cfg[12] != 0.0 or not after_diffuse), (cfg[13] != 0.0 or not after_diffuse)


@kernel
def shade(depth, cfg, pkey, index, beta, counts, L, alpha, prev_pdf, prev_pos, ray_bits,
          min_pdf, path_time, live, ro, rd, rt, hit_t, hit_prim, hit_u, hit_v, stopped,
          geometry, params, emission, textures, tables, lights, world,
          sh_path, sh_org, sh_dir, sh_far, sh_contrib, nx_path, nx_org, nx_dir, path_info):
    """One bounce for the live paths `live` whose rays (ro, rd, rt) hit (hit_*).

    cfg: float64 [sampler kind, spp, max_bounces, diffuse, glossy, transmission limits,
    clamp_direct, clamp_indirect, mis mode, scene radius, film transparent, filter glossy,
    reflective caustics, refractive caustics] (see `prepare_closures`).
    geometry: (v0, v1, v2, normal, tri_scale, material, corner_normals, holdout,
    corner_uvs, moving objects, triangle objects, object table, corner tangents) of every
    triangle (corner normals, holdout, UVs, objects and tangents may be empty; see
    `surface.rebuild_at_time` and engine.nodes.shading). textures: the packed textures
    and shader programs (engine.nodes.pack.pack_shading); a material with a program
    runs it at each hit, and its outputs replace the parameters they drive. path_time: each path's shutter time (its
    moving triangles are placed at that time). alpha: each path's film coverage, or
    empty when the film is opaque. stopped: rays that ended at the transparent bounce
    limit. ray_bits: the kind of each path's current ray (engine.visibility: CAMERA,
    then the bit of the lobe it left by), which decides the lamps it sees; next-event
    estimation evaluates only the lobes the light is seen by and skips the shadow ray
    of a light that casts no shadow. min_pdf: the smallest BSDF pdf along each path so
    far (Filter Glossy, `prepare_closures`). Writes the shadow rays to sh_* (their
    contributions before the clamp, which `add_transmitted` applies) and the continuing paths' next
    rays to nx_*; returns (shadow count, next count). beta, counts, L, alpha, prev_pdf,
    prev_pos are per-path state, updated in place. path_info: (transparent bounces per
    path, ray cone per path (n, 2): footprint at the ray's origin and spread, see
    engine.nodes.differentials), what shader programs read of the path; the cone moves
    on to the next ray's origin."""
    tri_material, holdout, corner_uvs = geometry[5], geometry[7], geometry[8]
    any_textures = textures[1].shape[0] > 0
    film_transparent = cfg[10] > 0.0 and alpha.shape[0] > 0
    kind, spp = int(cfg[0]), int(cfg[1])
    max_bounces = int(cfg[2])
    clamp_direct, clamp_indirect, mode = cfg[6], cfg[7], int(cfg[8])
    scene_radius = cfg[9]
    # Emission found by this bounce's rays is lit by bounce depth - 1 (Cycles' count): a
    # lamp hit from the first surface is direct light, as its next-event estimate is;
    # what the camera sees directly is never clamped.
    clamp_hit = 0.0 if depth == 0 else (clamp_direct if depth == 1 else clamp_indirect)
    n_lights = lt.n_entries(lights)
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
        # 1a. area and sphere lamps in front of the geometry; the ray goes on behind them
        if n_lights > 0:
            t_l, k_l, lr, lg, lb = lt.hit_lamps(lights, ox, oy, oz, dx, dy, dz, t_geom,
                                                ray_bits[p])
            if k_l >= 0:
                lpdf = lt.lamp_pdf(lights, k_l, prev_pos[p, 0], prev_pos[p, 1],
                                   prev_pos[p, 2], dx, dy, dz, t_l)
                w = hit_weight(mode, prev_pdf[p], lpdf)
                _add(L, p, br * lr * w, bg * lg * w, bb * lb * w, clamp_hit)
        # 1b. escaped rays: the world and sun discs (or, for camera rays on a transparent
        # film, no colour and the coverage left)
        if not hit:
            if depth == 0 and film_transparent:
                alpha[p] = uncovered(br, bg, bb)
                continue
            er, eg, eb, epdf = lt.world_escaped(lights, world, ray_bits[p], dx, dy, dz)
            w = hit_weight(mode, prev_pdf[p], epdf)
            er, eg, eb = er * w, eg * w, eb * w
            for s in range(lt.n_suns(lights)):
                sr, sg, sb, spdf = lt.sun_escaped(lights, s, dx, dy, dz)
                w = hit_weight(mode, prev_pdf[p], spdf)
                er += sr * w
                eg += sg * w
                eb += sb * w
            _add(L, p, br * er, bg * eg, bb * eb, clamp_hit)
            continue
        if stopped[j]:
            continue                      # past the transparent bounce limit
        prim = hit_prim[j]
        if depth == 0 and holdout.shape[0] > 0 and holdout[prim]:
            if alpha.shape[0] > 0:        # Cycles' holdout: a hole, for camera rays only
                alpha[p] = uncovered(br, bg, bb)
            continue
        px, py, pz, gx, gy, gz, nx, ny, nz, front, scale = rebuild_at_time(
            geometry, prim, hit_u[j], hit_v[j], dx, dy, dz, path_time[p])
        m = tri_material[prim]
        uu, vv = hit_uv(corner_uvs, prim, hit_u[j], hit_v[j])
        programmed = has_program(textures, m)
        bent = False
        rx, ry, rz = nx, ny, nz
        # the lobe choice's number; a Mix Shader picks its shader with it first
        u_lobe = sample_1d(kind, pkey[p], spp, index[p], base + D.BSDF_LOBE)
        ms = m                                   # the material shaded
        n0x, n0y, n0z = nx, ny, nz               # the surface's own shading normal
        if programmed:
            path_fields(hit_row, counts, path_info[0], p, cone_at(path_info[1], p, t_geom))
            program_hit(textures, geometry, m, prim, hit_u[j], hit_v[j], uu, vv, px, py, pz,
                        gx, gy, gz, nx, ny, nz, dx, dy, dz, front, ray_bits[p], depth, t_geom,
                        hit_row, regs)
            ms, u_lobe = pick_closure(textures, m, regs, u_lobe)
            sx, sy, sz, rx, ry, rz = program_normal(textures, ms, regs, nx, ny, nz, gx, gy,
                                                    gz, -dx, -dy, -dz)
            bent = sx != nx or sy != ny or sz != nz or rx != nx or ry != ny or rz != nz
            nx, ny, nz = sx, sy, sz
        # 1c. emissive surfaces (two-sided), weighted against sampling that triangle
        er, eg, eb = emission_at(textures, emission, m, uu, vv)
        if programmed:
            er, eg, eb = program_emission(textures, m, regs, er, eg, eb)
        if er != 0.0 or eg != 0.0 or eb != 0.0:
            lpdf = lt.mesh_pdf(lights, prim, prev_pos[p, 0], prev_pos[p, 1], prev_pos[p, 2],
                               px, py, pz)
            w = hit_weight(mode, prev_pdf[p], lpdf)
            _add(L, p, br * er * w, bg * eg * w, bb * eb * w, clamp_hit)
        wox, woy, woz = to_local(-dx, -dy, -dz, nx, ny, nz)
        row[:] = params[ms]
        if any_textures:
            apply_to_row(textures, ms, uu, vv, row, P_BASE, P_METALLIC, P_ROUGHNESS)
        if programmed:
            apply_rows(textures, ms, regs, row, P_BASE, P_METALLIC, P_ROUGHNESS)
        keep_g, keep_t = prepare_closures(cfg, row, min_pdf[p], ray_bits[p])
        bsdf.setup(row, front, wox, woy, woz, tables, state)
        room = depth < max_bounces
        ad = room and counts[p, 0] < cfg[3]
        ag = room and counts[p, 1] < cfg[4] and keep_g
        at = room and counts[p, 2] < cfg[5] and keep_t
        # 2. next-event estimation: one light entry, one point, one shadow ray
        if n_lights > 0:
            u_pick = sample_1d(kind, pkey[p], spp, index[p], base + D.LIGHT_PICK)
            u1, u2 = sample_2d(kind, pkey[p], spp, index[p], base + D.LIGHT_POINT)
            k, wx, wy, wz, dist, lr, lg, lb, lpdf, delta, margin = lt.sample(
                lights, px, py, pz, u_pick, u1, u2)
            lx, ly, lz = to_local(wx, wy, wz, nx, ny, nz)
            seen = lt.entry_visibility(lights, k)
            see_d = (seen & DIFFUSE_BIT) != 0
            see_g = (seen & GLOSSY_BIT) != 0 and keep_g
            see_t = (seen & TRANSMISSION_BIT) != 0 and keep_t
            cosine = abs(lz)
            if bent:
                # a Normal Map's normal: specular lobes on its valid-reflection frame,
                # the diffuse lobe on the raw normal with bump shadowing (Cycles)
                fr, fg, fb = bsdf.eval_seen(state, wox, woy, woz, lx, ly, lz, False, see_g,
                                            see_t)
                fr, fg, fb = fr * cosine, fg * cosine, fb * cosine
                if see_d:
                    dr, dg, db = bent_diffuse(state, wox, woy, woz, n0x, n0y, n0z, rx, ry,
                                              rz, wx, wy, wz)
                    fr, fg, fb = fr + dr, fg + dg, fb + db
                cosine = 1.0
            else:
                fr, fg, fb = bsdf.eval_seen(state, wox, woy, woz, lx, ly, lz, see_d, see_g,
                                            see_t)
            front_side = dot(wx, wy, wz, gx, gy, gz) > 0.0
            if (lpdf > 0.0 and max(lr, lg, lb) > 0.0 and max(fr, fg, fb) > 0.0
                    and (front_side or bsdf.transmits(state))):
                sox, soy, soz = offset_origin(px, py, pz, gx, gy, gz, scale, wx, wy, wz)
                sdx, sdy, sdz = wx, wy, wz
                if math.isfinite(dist):
                    # to the sampled point, stopping short of it by the origin's margin
                    tx = px + wx * dist - sox
                    ty = py + wy * dist - soy
                    tz = pz + wz * dist - soz
                    seg = math.sqrt(tx * tx + ty * ty + tz * tz)
                    if seg > 0.0:
                        sdx, sdy, sdz = tx / seg, ty / seg, tz / seg
                    far = min(seg * (1.0 - 2e-5), seg - margin)
                else:
                    far = scene_radius * 4.0
                bpdf = bsdf.pdf_seen(state, wox, woy, woz, lx, ly, lz, ad, ag, at,
                                     see_d, see_g, see_t)
                w = nee_weight(mode, lpdf, bpdf, delta) / lpdf * cosine
                if not seen & SHADOW_BIT:        # a light casting no shadow: no shadow ray
                    _add(L, p, br * fr * lr * w, bg * fg * lg * w, bb * fb * lb * w,
                         clamp_direct if depth == 0 else clamp_indirect)
                else:
                    sh_path[ns_out] = p
                    sh_org[ns_out, 0], sh_org[ns_out, 1], sh_org[ns_out, 2] = sox, soy, soz
                    sh_dir[ns_out, 0], sh_dir[ns_out, 1], sh_dir[ns_out, 2] = sdx, sdy, sdz
                    sh_far[ns_out] = max(far, 0.0)
                    sh_contrib[ns_out, 0] = br * fr * lr * w
                    sh_contrib[ns_out, 1] = bg * fg * lg * w
                    sh_contrib[ns_out, 2] = bb * fb * lb * w
                    ns_out += 1
        # 3. continue by BSDF sampling
        if not (ad or ag or at):
            continue
        u1, u2 = sample_2d(kind, pkey[p], spp, index[p], base + D.BSDF_DIR)
        ix, iy, iz, wr, wg, wb, spdf, skind, sdelta, valid = bsdf.sample(
            state, wox, woy, woz, u_lobe, u1, u2, ad, ag, at)
        if not valid:
            continue
        wx, wy, wz = to_world(ix, iy, iz, nx, ny, nz)
        if bent and ad and not sdelta and spdf > 0.0:
            # the diffuse lobe's share of the weight, moved from the sampling frame's
            # cosine to the raw normal's (with bump shadowing)
            fd_r, fd_g, fd_b = bsdf.eval_seen(state, wox, woy, woz, 0.0, 0.0, 1.0, True,
                                              False, False)
            dr, dg, db = bent_diffuse(state, wox, woy, woz, n0x, n0y, n0z, rx, ry, rz, wx, wy,
                                      wz)
            c = abs(iz)
            wr = max(wr + (dr - fd_r * c) / spdf, 0.0)
            wg = max(wg + (dg - fd_g * c) / spdf, 0.0)
            wb = max(wb + (db - fd_b * c) / spdf, 0.0)
        side = dot(wx, wy, wz, gx, gy, gz)
        if (side >= 0.0) if skind == TRANSMISSION else (side <= 0.0):
            continue       # reflection leaves on the geometric normal's side, refraction through
        br, bg, bb = br * wr, bg * wg, bb * wb
        if depth + 1 >= ROULETTE_START:
            u_rr = sample_1d(kind, pkey[p], spp, index[p], base + D.ROULETTE)
            q = min(max(max(br, bg, bb), 0.0), 0.95)
            if not u_rr < q:
                continue
            q = max(q, 1e-300)
            br, bg, bb = br / q, bg / q, bb / q
        if not max(br, bg, bb) > 0.0:
            continue
        beta[p, 0], beta[p, 1], beta[p, 2] = br, bg, bb
        counts[p, skind] += 1
        ray_bits[p] = DIFFUSE_BIT << skind     # diffuse, glossy, transmission: 2, 4, 8
        if not sdelta:
            min_pdf[p] = min(min_pdf[p], spdf)
        nox, noy, noz = offset_origin(px, py, pz, gx, gy, gz, scale, wx, wy, wz)
        nx_path[nn_out] = p
        cone_moves(path_info[1], p, t_geom)
        nx_org[nn_out, 0], nx_org[nn_out, 1], nx_org[nn_out, 2] = nox, noy, noz
        nx_dir[nn_out, 0], nx_dir[nn_out, 1], nx_dir[nn_out, 2] = wx, wy, wz
        prev_pos[p, 0], prev_pos[p, 1], prev_pos[p, 2] = px, py, pz
        prev_pdf[p] = _INF if sdelta else spdf
        nn_out += 1
    return ns_out, nn_out


@kernel
def add_unoccluded(L, sh_path, sh_contrib, blocked, limit):
    """Add the contributions of the shadow rays that reached their light, clamped."""
    for i in range(sh_path.shape[0]):
        if not blocked[i]:
            _add(L, sh_path[i], sh_contrib[i, 0], sh_contrib[i, 1], sh_contrib[i, 2], limit)


@kernel
def add_transmitted(L, sh_path, sh_contrib, trans, limit):
    """Add the contributions of shadow rays times their transmittance, clamped."""
    for i in range(sh_path.shape[0]):
        if trans[i, 0] > 0.0 or trans[i, 1] > 0.0 or trans[i, 2] > 0.0:
            _add(L, sh_path[i], sh_contrib[i, 0] * trans[i, 0], sh_contrib[i, 1] * trans[i, 1],
                 sh_contrib[i, 2] * trans[i, 2], limit)
