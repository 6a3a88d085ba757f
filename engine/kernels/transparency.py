"""Stochastic transparency (Cycles' transparent closure, Principled Alpha), compiled.

Cycles' Principled Alpha a (and a Transparent BSDF mixed in with weight 1 - a) is a
transparent closure: a ray hitting such a surface passes through it with probability
1 - a (a sampler number per path vertex and layer), tinted by the material's transparent
colour, and the hit it reports is the next surface beyond; otherwise the surface is
opaque. The expectation is Cycles' a x shading + (1 - a) x what lies behind. Every
pass-through counts one transparent bounce of the path (Cycles' transparent bounce; not
a bounce of Max Bounces); a ray that would pass through more than Transparent bounces
surfaces ends there (Cycles terminates such a path). Shadow rays carry the product of
(1 - alpha) x the transparent colour of the surfaces they cross (Cycles' transparent
shadows), over at most that many surfaces (more block). The caller loops: closest-hit
query, one of these kernels (`alpha_pass`, `shadow_pass`), the next query for the rays
that go on.

`materials` is the tuple (material of each triangle, maybe_transparent per material,
alpha per material, transparent colour per material (M, 3), textures T, visibility of
each triangle (engine.visibility masks; empty when every ray sees every triangle));
`geometry` the tuple `path_vertex.shade` takes. Hits on moving objects are placed at the
time of the ray's path (`path_time` per path, `ray_time` per shadow ray).

The same passes skip the surfaces a ray does not see (Ray Visibility): a camera or bounce
ray goes on through a triangle lacking its kind's bit, a shadow ray through one lacking
SHADOW, untinted and without counting a transparent bounce.

A ray going on beyond a surface starts on it and names it, so that the next query passes
it (engine.embree.self_hits); a shadow ray keeps naming the emissive triangle it goes to. The rays that go on are written to `out`: (row, origin
(n, 3), remaining distance, what it names (n, 4))."""
from __future__ import annotations

import numpy as np

from .. import visibility
from ..sampling.dispatch import sample_1d
from .jit import kernel
from .surface import hit_uv, surface_at
from .textures import alpha_at
from .medium_density import attenuate_tracked, has_heterogeneous, heterogeneous_in
from .volume import V_BOUNDARY, attenuate, stack_cross
from ..sampling.hashing import chain
from ..nodes.context import N_HIT
from ..nodes.interpreter import has_program
from ..nodes.pack import MIX, NREGS
from ..nodes.shading import coverage, mix_factor, program_alpha, program_hit

TRANSPARENT_DIM = 1 << 24      # the pass-through numbers' own dimensions (see path.py)
SHADOW_BIT = visibility.SHADOW


@kernel(allocates=False)
def alpha_dim(depth, layer):
    return TRANSPARENT_DIM + depth * 1024 + min(layer, 1023)


@kernel
def _hit_alpha(geometry, materials, prim, inst, u, v, ox, oy, oz, t, dx, dy, dz, time, ray,
               depth, length):
    """What the hit of the ray o + t d lets through (a material program's, run for a ray
    of kind `ray`, the path's bounce depth and the hit's distance `length` from the path's
    last vertex): (its alpha, its material, its surface point, the colour it transmits,
    (1 - alpha) x its transparent colour). A Mix Shader whose Fac varies per hit lets
    through both shaders' share: alpha (1 - Fac) alpha0 + Fac alpha1 and colour
    (1 - Fac) (1 - alpha0) colour0 + Fac (1 - alpha1) colour1, Cycles' sum of the two
    closures (a Light Path's Is Shadow Ray or Is Diffuse Ray picking a Transparent BSDF,
    as architectural glass is made); the shading then picks between the opaque parts
    (engine.nodes.shading.pick_closure)."""
    tri_material, corner_uvs = geometry[3], geometry[6]
    _, _, alpha_table, tcolor, T, _ = materials
    px, py, pz, gx, gy, gz, nx, ny, nz, front, _ = surface_at(
        geometry, prim, inst, u, v, ox, oy, oz, t, dx, dy, dz, time)
    uu, vv = hit_uv(corner_uvs, prim, u, v)
    m = tri_material[prim]
    a = alpha_at(T, alpha_table, m, uu, vv)
    if has_program(T, m):
        hit = np.zeros(N_HIT)
        regs = np.zeros(max(T[NREGS][0], 1))
        program_hit(T, geometry, m, prim, inst, u, v, uu, vv, px, py, pz, gx, gy, gz, nx, ny, nz,
                    dx, dy, dz, front, ray, depth, length, hit, regs)
        a = program_alpha(T, m, regs, a)
        c0, c1 = T[MIX][m, 0], T[MIX][m, 1]
        if c0 >= 0:
            f = mix_factor(T, m, regs)
            a0, a1 = coverage(T, c0, regs, uu, vv), coverage(T, c1, regs, uu, vv)
            w0, w1 = (1.0 - f) * (1.0 - a0), f * (1.0 - a1)
            return ((1.0 - f) * a0 + f * a1, m, px, py, pz,
                    w0 * tcolor[c0, 0] + w1 * tcolor[c1, 0],
                    w0 * tcolor[c0, 1] + w1 * tcolor[c1, 1],
                    w0 * tcolor[c0, 2] + w1 * tcolor[c1, 2])
    return (a, m, px, py, pz, (1.0 - a) * tcolor[m, 0], (1.0 - a) * tcolor[m, 1],
            (1.0 - a) * tcolor[m, 2])


@kernel(allocates=False)
def _emit(out, n_out, r, prim, inst, px, py, pz, far, light):
    """Entry n_out of `out`: ray r goes on from the surface point p of primitive prim of
    place inst, naming it and `light` (the emissive triangle and place a shadow ray goes
    to), for a remaining distance `far`."""
    out_rows, out_org, out_far, out_skip = out
    out_rows[n_out] = r
    out_org[n_out, 0], out_org[n_out, 1], out_org[n_out, 2] = px, py, pz
    out_far[n_out] = max(far, 0.0)
    out_skip[n_out, 0], out_skip[n_out, 1] = prim, inst
    out_skip[n_out, 2], out_skip[n_out, 3] = light


@kernel(allocates=False)
def _pass_through(geometry, prim, inst, u, v, ox, oy, oz, t, d, r, time, far, out, n_out,
                  light):
    """Ray r (origin o, direction d[r]) goes on, unchanged, beyond the surface it hit at
    t; returns whether it hit the surface's front."""
    dx, dy, dz = d[r, 0], d[r, 1], d[r, 2]
    px, py, pz, _, _, _, _, _, _, front, _ = surface_at(
        geometry, prim, inst, u, v, ox, oy, oz, t, dx, dy, dz, time)
    _emit(out, n_out, r, prim, inst, px, py, pz, far, light)
    return front


@kernel
def alpha_pass(depth, layer, limit, kind, spp, pkey, index, live, used, ray_bits, path_time,
               rows, ro, rd, tmax, cur, travelled, factor, stopped,
               geometry, materials, out_rows, out_org, out_far, out_skip):
    """One transparent layer for the camera or bounce rays `rows` (indices into the
    wavefront `live`) whose current closest hits are cur_*: each ray whose hit surface
    lets it through (a sampler number >= alpha) goes on beyond it, tinted, counting one
    transparent bounce of its path (`used`, per path); past `limit` such bounces the
    path stops. A ray whose kind (ray_bits, per path) does not see the hit triangle goes
    on beyond it as it is. ro: the origins the hits cur_* are measured from (row i's at
    ro[i]). Writes the rays that go on (row, origin, remaining distance, what they name);
    returns their count."""
    tri_material, maybe_transparent, _, _, _, tri_vis = materials
    cur_t, cur_prim, cur_inst, cur_u, cur_v = cur.t, cur.prim, cur.inst, cur.u, cur.v
    out = (out_rows, out_org, out_far, out_skip)
    n_out = 0
    for i in range(rows.shape[0]):
        r = rows[i]
        prim = cur_prim[i]
        if prim < 0:
            continue
        if tri_vis.shape[0] > 0 and not tri_vis[prim] & ray_bits[live[r]]:
            travelled[r] += cur_t[i]
            _pass_through(geometry, prim, cur_inst[i], cur_u[i], cur_v[i], ro[i, 0],
                          ro[i, 1], ro[i, 2], cur_t[i], rd, r, path_time[live[r]],
                          tmax[r] - travelled[r], out, n_out, (-1, -1))
            n_out += 1
            continue
        if not maybe_transparent[tri_material[prim]]:
            continue
        dx, dy, dz = rd[r, 0], rd[r, 1], rd[r, 2]
        p = live[r]
        a, m, px, py, pz, tr, tg, tb = _hit_alpha(
            geometry, materials, prim, cur_inst[i], cur_u[i], cur_v[i], ro[i, 0], ro[i, 1],
            ro[i, 2], cur_t[i], dx, dy, dz, path_time[p],
            ray_bits[p], depth, travelled[r] + cur_t[i])
        if not sample_1d(kind, pkey[p], spp, index[p], alpha_dim(depth, layer)) >= a:
            continue
        if used[p] >= limit:
            stopped[r] = True
            continue
        # passed with probability 1 - alpha: the colour it lets through over that
        factor[r, 0] *= tr / (1.0 - a)
        factor[r, 1] *= tg / (1.0 - a)
        factor[r, 2] *= tb / (1.0 - a)
        used[p] += 1
        travelled[r] += cur_t[i]
        _emit(out, n_out, r, prim, cur_inst[i], px, py, pz, tmax[r] - travelled[r], (-1, -1))
        n_out += 1
    return n_out


@kernel
def shadow_pass(layer, limit, rows, so, sd, ray_time, remaining, cur, trans, geometry,
                materials, vol, stacks, tracking, skip, out_rows, out_org, out_far,
                out_skip):
    """One layer of transparent shadows for the shadow rays `rows`: an opaque surface (or
    one past `limit` transparent layers) blocks; a transparent one multiplies the
    transmittance by (1 - alpha) x its transparent colour and the ray goes on; through a
    surface whose object casts no shadow it goes on unchanged. With volumes (vol, the
    rays' stacks; engine.kernels.volume) the medium between layers attenuates the ray,
    and a volume's boundary is crossed (the stack updated) without counting a layer.
    so: the rows' origins (row i's at so[i]). tracking: (each shadow ray's random key,
    the heterogeneous program-run counter; engine.kernels.medium_density), used by the
    rays whose media include a heterogeneous one (ratio tracking). skip: what the rows
    name (row i's at skip[i]: the layer it left, the emissive triangle it goes to)."""
    tri_material, maybe_transparent, _, _, T, tri_vis = materials
    keys, het_count = tracking
    cur_t, cur_prim, cur_inst, cur_u, cur_v = cur.t, cur.prim, cur.inst, cur.u, cur.v
    out = (out_rows, out_org, out_far, out_skip)
    het_scene = stacks.shape[0] > 0 and has_heterogeneous(vol)
    hit = np.zeros(N_HIT if het_scene else 0)
    regs = np.zeros(max(T[NREGS][0], 1) if het_scene else 0)
    n_out = 0
    for i in range(rows.shape[0]):
        r = rows[i]
        prim = cur_prim[i]
        reached = prim < 0 or not cur_t[i] < remaining[i]
        if het_scene and heterogeneous_in(vol, stacks, r):
            attenuate_tracked(vol, stacks, r, trans, T, geometry[9], geometry[12],
                              so[i, 0], so[i, 1], so[i, 2], sd[r, 0], sd[r, 1], sd[r, 2],
                              remaining[i] if reached else cur_t[i],
                              chain(keys[r], layer), hit, regs, het_count)
        elif stacks.shape[0] > 0:
            attenuate(vol, stacks, r, trans, remaining[i] if reached else cur_t[i])
        if reached:
            continue
        light = (skip[i, 2], skip[i, 3])
        if vol.shape[0] > 0 and vol[tri_material[prim], V_BOUNDARY] != 0.0:
            front = _pass_through(geometry, prim, cur_inst[i], cur_u[i], cur_v[i], so[i, 0],
                                  so[i, 1], so[i, 2], cur_t[i], sd, r, ray_time[r],
                                  remaining[i] - cur_t[i], out, n_out, light)
            n_out += 1
            if stacks.shape[0] > 0:
                stack_cross(stacks, r, tri_material[prim], front)
            continue
        if tri_vis.shape[0] > 0 and not tri_vis[prim] & SHADOW_BIT:
            _pass_through(geometry, prim, cur_inst[i], cur_u[i], cur_v[i], so[i, 0], so[i, 1],
                          so[i, 2], cur_t[i], sd, r, ray_time[r],
                          remaining[i] - cur_t[i], out, n_out, light)
            n_out += 1
            continue
        if not maybe_transparent[tri_material[prim]] or layer >= limit:
            trans[r, 0] = trans[r, 1] = trans[r, 2] = 0.0
            continue
        dx, dy, dz = sd[r, 0], sd[r, 1], sd[r, 2]
        _, _, px, py, pz, tr, tg, tb = _hit_alpha(
            geometry, materials, prim, cur_inst[i], cur_u[i], cur_v[i], so[i, 0], so[i, 1],
            so[i, 2], cur_t[i], dx, dy, dz, ray_time[r],
            SHADOW_BIT, 0, cur_t[i])
        trans[r, 0] *= tr
        trans[r, 1] *= tg
        trans[r, 2] *= tb
        if not max(trans[r, 0], trans[r, 1], trans[r, 2]) > 0.0:
            continue
        _emit(out, n_out, r, prim, cur_inst[i], px, py, pz, remaining[i] - cur_t[i], light)
        n_out += 1
    return n_out


@kernel(allocates=False)
def merge_layer(rows, travelled, found, hits):
    """The hits `found` beyond a transparent layer replace the rows' `hits` (t from the
    start; both engine.accel.HitArrays)."""
    for i in range(rows.shape[0]):
        r = rows[i]
        if found.prim[i] >= 0:
            hits.t[r] = travelled[r] + found.t[i]
        else:
            hits.t[r] = 1e300 * 1e300
        hits.prim[r], hits.inst[r] = found.prim[i], found.inst[i]
        hits.u[r], hits.v[r] = found.u[i], found.v[i]
