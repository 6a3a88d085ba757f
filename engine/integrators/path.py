"""Kajiya's path tracer, wavefront style, with next-event estimation and MIS.

A batch of paths advances one bounce at a time. At each surface vertex:
  1. emission seen by the incoming ray: area and sphere lamps (hit analytically), sun
     discs (escaped rays) and emissive triangles (hit by the ray cast), each weighted
     against light sampling by the power heuristic with the pdf light sampling would have
     had for that direction (`LightSet.pdf`, `LightSet.mesh_pdf`); camera rays and
     specular bounces (pdf = inf) see emission with weight 1;
  2. next-event estimation: one light entry (lamp or emissive triangle) picked in
     proportion to its power, one point on it, one shadow ray, weighted against BSDF
     sampling by the power heuristic;
  3. BSDF sampling over the lobes whose bounce budget (Cycles' diffuse, glossy,
     transmission and total limits) is not used up; Cycles' Russian roulette: the ray
     leaves with a verdict (survival probability q = min(sqrt(max throughput), 1), or
     ended), applied at the vertex it finds, after the emission found there (step 1).
Where no lobe may continue, light sampling takes the whole weight (no MIS), so direct
light stays unbiased with zero bounces.

`mis_mode` (a test and debug hook, not a user setting) selects the weights of those two
estimators of direct light: 'mis' (default) the power heuristic; 'light' light sampling
only (BSDF-sampled rays that hit a light light sampling could have produced add nothing);
'bsdf' BSDF sampling only (next-event estimation is kept only for delta lights and for
directions the BSDF cannot sample, e.g. when no bounce is left). All three are unbiased
and must agree in expectation (tests/test_light_transport.py).

Radiance sums are float64: a path's throughput is a product of many factors and the
film sums millions of them.
"""
from __future__ import annotations

import numpy as np

from .. import visibility
from ..bsdf.lobes import TRANSMISSION
from ..bsdf.principled import PrincipledBSDF
from ..sampling import dimensions as D
from ..surface import offset_origin
from .coverage import background_is_transparent, end_at_holdouts, uncovered
from ..warp import to_local, to_world

ROULETTE_START = 3
MIS_MODES = ("mis", "light", "bsdf")


def power_heuristic(a, b):
    a2, b2 = a * a, b * b
    with np.errstate(invalid="ignore", over="ignore"):
        w = np.where(np.isinf(a), 1.0, a2 / np.where(a2 + b2 > 0, a2 + b2, 1.0))
    return np.where(np.isinf(b) & ~np.isinf(a), 0.0, w)


def _clamp(values, limit):
    if limit <= 0:
        return values
    m = values.max(axis=1, keepdims=True)
    return np.where(m > limit, values * (limit / np.maximum(m, 1e-300)), values)


def _shadow_origins(surfaces, si, sel, wi):
    """The shadow rays' origins of the hits sel of si towards wi (engine.kernels.terminator)."""
    cut = surfaces.terminator_cutoff
    if cut is None:
        return offset_origin(si.position[sel], si.geometric_normal[sel], si.scale[sel], wi)
    from ..kernels.terminator import shadow_origins
    return shadow_origins(surfaces.positions, surfaces.corners, surfaces.corner_normals, cut,
                          si.prim[sel], np.ascontiguousarray(si.bary[sel]),
                          np.ascontiguousarray(si.position[sel]),
                          np.ascontiguousarray(si.geometric_normal[sel]),
                          np.ascontiguousarray(si.shading_normal[sel]),
                          np.ascontiguousarray(si.scale[sel], dtype=np.float64),
                          np.ascontiguousarray(wi))


# Sampler dimensions of the pass-through decisions at transparent surfaces: outside the
# per-bounce layout of engine.sampling.dimensions (so no other effect's numbers shift),
# one per (path vertex, transparent layer).
def _rows(mats, surfaces, si, depth, ray=None):
    """The rows shader programs read for hits si, or None when no material has one.
    The NumPy reference knows a ray's kind only as camera (depth 0) or not (reported as
    a diffuse ray), unless given."""
    if not mats.any_programs:
        return None
    if ray is None:
        ray = visibility.CAMERA if depth == 0 else visibility.DIFFUSE
    return surfaces.shader_rows(si, ray, depth)


TRANSPARENT_DIM = 1 << 24


def _alpha_dim(depth: int, layer: int) -> int:
    return TRANSPARENT_DIM + depth * 1024 + min(layer, 1023)


def intersect_alpha(ctx, o, d, tm, tp, px, ix, depth, used):
    """Closest hits, seen through materials with alpha < 1 (stochastic transparency).

    Cycles' Principled Alpha a (and a Transparent BSDF mixed in with weight 1 - a) is a
    transparent closure: here a ray hitting such a surface passes through it with
    probability 1 - a (a sampler number per path vertex and layer), tinted by the
    material's transparent colour, and the hit it reports is the next surface beyond;
    otherwise the surface is opaque. The expectation is Cycles' a x shading + (1 - a) x
    what lies behind. Every pass-through counts one transparent bounce of the path
    (`used`, Cycles' transparent bounce; not a bounce of `max_bounces`); a ray that would
    pass through more than `settings.transparent_bounces` surfaces ends there (Cycles
    terminates such a path).

    Returns (hits with t measured from o, throughput factor (n, 3) or None, updated
    `used`, stopped mask or None)."""
    hits = ctx.accel.intersect(o, d, tm, tp)
    mats = ctx.materials
    if not mats.any_transparent or len(o) == 0:
        return hits, None, used, None
    n = len(o)
    limit = ctx.settings.transparent_bounces
    surfaces = ctx.surfaces
    factor = np.ones((n, 3))
    used = used.copy()
    stopped = np.zeros(n, bool)
    travelled = np.zeros(n)
    t_all, prim_all, u_all, v_all = hits.t.copy(), hits.prim.copy(), hits.u.copy(), hits.v.copy()
    rows = np.arange(n)
    cur = hits
    layer = 0
    while rows.size:
        hit = cur.prim >= 0
        m = np.where(hit, surfaces.material[np.maximum(cur.prim, 0)], 0)
        c = np.nonzero(hit & mats.maybe_transparent[m])[0]
        if c.size == 0:
            break
        si = surfaces.build(cur, c, d[rows], None if tp is None else tp[rows])
        alpha = mats.alpha_at(si.material, si.uv, _rows(mats, surfaces, si, depth))
        u_t = ctx.sampler.get_1d(_alpha_dim(depth, layer), px[rows[c]], ix[rows[c]])
        through = u_t >= alpha
        over = through & (used[rows[c]] >= limit)
        stopped[rows[c[over]]] = True
        go = np.nonzero(through & ~over)[0]
        if go.size == 0:
            break
        g = rows[c[go]]
        factor[g] *= mats.transparent_color[si.material[go]]
        used[g] += 1
        travelled[g] += cur.t[c[go]]
        new_o = offset_origin(si.position[go], si.geometric_normal[go], si.scale[go], d[g])
        remaining = np.maximum(np.asarray(tm)[g] - travelled[g], 0.0)
        cur = ctx.accel.intersect(new_o, d[g], remaining, None if tp is None else tp[g])
        found = cur.prim >= 0
        t_all[g] = np.where(found, travelled[g] + cur.t, np.inf)
        prim_all[g], u_all[g], v_all[g] = cur.prim, cur.u, cur.v
        rows = g
        layer += 1
    return type(hits)(t_all, prim_all, u_all, v_all), factor, used, stopped


def shadow_transmittance(ctx, org, dirs, far, time=None):
    """Fraction (n, 3) of light that reaches org along dirs over [0, far): 0 behind an
    opaque surface; through surfaces with alpha < 1 the product of (1 - alpha) x their
    transparent colour (Cycles' transparent shadows), over at most
    `settings.transparent_bounces` such surfaces (more block)."""
    mats = ctx.materials
    n = len(org)
    if not mats.any_transparent:
        vis = ~ctx.accel.occluded(org, dirs, far, time)
        return np.repeat(vis[:, None].astype(np.float64), 3, axis=1)
    limit = ctx.settings.transparent_bounces
    surfaces = ctx.surfaces
    T = np.ones((n, 3))
    rows = np.arange(n)
    o, remaining = org, np.asarray(far, dtype=np.float64)
    layer = 0
    while rows.size:
        h = ctx.accel.intersect(o, dirs[rows], remaining, None if time is None else time[rows])
        hr = np.nonzero((h.prim >= 0) & (h.t < remaining))[0]
        if hr.size == 0:
            break
        m = surfaces.material[h.prim[hr]]
        opaque = ~mats.maybe_transparent[m]
        T[rows[hr[opaque]]] = 0.0
        tr = hr[~opaque]
        if tr.size == 0:
            break
        if layer >= limit:
            T[rows[tr]] = 0.0
            break
        si = surfaces.build(h, tr, dirs[rows], None if time is None else time[rows])
        alpha = mats.alpha_at(si.material, si.uv,
                              _rows(mats, surfaces, si, 0, visibility.SHADOW))
        T[rows[tr]] *= (1.0 - alpha)[:, None] * mats.transparent_color[si.material]
        still = T[rows[tr]].max(1) > 0
        tr = tr[still]
        g = rows[tr]
        o = offset_origin(si.position[still], si.geometric_normal[still], si.scale[still],
                          dirs[g])
        remaining = np.maximum(remaining[tr] - h.t[tr], 0.0)
        rows = g
        layer += 1
    return T


class PathIntegrator:
    def __init__(self, ctx):
        self.ctx = ctx                       # engine.render.RenderContext
        s = ctx.settings
        self.limits = np.array([s.diffuse_bounces, s.glossy_bounces, s.transmission_bounces])
        self.max_bounces = s.max_bounces
        self.mis_mode = "mis"                # test/debug hook, see the module docstring

    def _hit_weight(self, prev_pdf, light_pdf):
        """Weight of emission found by a BSDF-sampled ray (pdf prev_pdf, inf after a
        camera ray or a specular bounce) that light sampling reaches with light_pdf."""
        mode = self.mis_mode
        if mode == "mis":
            return power_heuristic(prev_pdf, light_pdf)
        if mode == "light":
            return np.where(np.isinf(prev_pdf) | ~(light_pdf > 0), 1.0, 0.0)
        if mode == "bsdf":
            return np.ones(len(prev_pdf))
        raise ValueError(f"mis_mode must be one of {MIS_MODES}, got {mode!r}")

    def _nee_weight(self, light_pdf, bsdf_pdf, delta):
        """Weight of a light sample that the BSDF would have sampled with bsdf_pdf."""
        mode = self.mis_mode
        if mode == "mis":
            return np.where(delta, 1.0, power_heuristic(light_pdf, bsdf_pdf))
        if mode == "light":
            return np.ones(len(light_pdf))
        if mode == "bsdf":
            return np.where(delta | ~(bsdf_pdf > 0), 1.0, 0.0)
        raise ValueError(f"mis_mode must be one of {MIS_MODES}, got {mode!r}")

    def radiance(self, pixel, index, origins, dirs, tmax, time=None, alpha_out=None):
        """Radiance along camera rays; pixel/index give each path's sampler coordinates,
        alpha_out (n,) if given receives each path's film coverage (Film > Transparent),
        time (or None when nothing moves) each path's shutter time, kept for all its
        rays so that moving objects are where they were when the path was taken."""
        ctx = self.ctx
        sampler, lights, mats, s = ctx.sampler, ctx.lights, ctx.materials, ctx.settings
        n = len(pixel)
        L = np.zeros((n, 3))
        # Per-path state, indexed by path id; `path` lists the live ones.
        beta = np.ones((n, 3))
        counts = np.zeros((n, 3), dtype=np.int64)
        transparent = np.zeros(n, dtype=np.int64)     # transparent bounces per path
        path = np.arange(n)
        o, d, tm = origins, dirs, tmax
        prev_pdf = np.full(n, np.inf)        # camera rays count as specular: MIS weight 1
        prev_pos = o
        verdict = np.ones(n)                 # the roulette's, for each path's next vertex

        def add(rows, contrib, depth, direct=False):
            # Cycles' clamps: direct light at the first hit (its next-event estimates,
            # direct=True, and the emission its BSDF rays find at depth 1), indirect
            # beyond it; what the camera sees directly (depth 0) is never clamped.
            limit = s.clamp_direct if direct else (s.clamp_indirect if depth > 0 else 0.0)
            L[rows] += _clamp(contrib, limit)   # rows are unique: one entry per path

        for depth in range(self.max_bounces + 1):
            if path.size == 0:
                break
            px, ix = pixel[path], index[path]
            b = beta[path]
            tp = None if time is None else time[path]
            hits, tfac, t_used, stopped = intersect_alpha(ctx, o, d, tm, tp, px, ix, depth,
                                                          transparent[path])
            if tfac is not None:
                transparent[path] = t_used
                b = b * tfac
            t_geom = np.where(hits.hit, hits.t, tm)
            alive = np.ones(path.size, dtype=bool)

            # 1a. area and sphere lights in front of the geometry
            if len(lights):
                t_l, k_l, le = lights.hit_surfaces(o, d, t_geom, tp)
                on_light = k_l >= 0
                if depth == 0:
                    on_light &= ctx.light_visible_camera[np.maximum(k_l, 0)]
                if on_light.any():
                    sel = np.nonzero(on_light)[0]
                    light_pdf = lights.pdf(k_l[sel], prev_pos[sel], d[sel], t_l[sel],
                                           None if tp is None else tp[sel])
                    w = self._hit_weight(prev_pdf[sel], light_pdf)
                    add(path[sel], b[sel] * le[sel] * w[:, None], depth, direct=depth == 1)
                    # Lamps are not surfaces: as in Cycles the ray goes on to what lies
                    # behind the lamp (hit below, or the background).
            # 1b. escaped rays: world background and sun discs
            escaped = alive & ~hits.hit
            if escaped.any():
                sel = np.nonzero(escaped)[0]
                # the world, weighted against its own next-event estimation
                w_env = self._hit_weight(prev_pdf[sel], lights.environment_pdf(d[sel]))
                # (Ray Visibility: camera rays may not see the world; the NumPy
                # reference models no other ray kind, see engine.visibility)
                seen = float(depth > 0 or bool(ctx.world.seen_by & visibility.CAMERA))
                env = ctx.world.escaped(d[sel]) * (w_env * seen)[:, None]
                t_sel = None if tp is None else tp[sel]
                for k, sun in lights.suns():
                    w = self._hit_weight(prev_pdf[sel], sun.pdf(None, d[sel], None, t_sel)
                                         * lights.select_pdf[k])
                    env += sun.escaped(d[sel], t_sel) * w[:, None]
                if background_is_transparent(ctx, alpha_out, depth):
                    alpha_out[path[sel]] = uncovered(b[sel])
                else:
                    add(path[sel], b[sel] * env, depth, direct=depth == 1)
                alive[sel] = False
            if stopped is not None:
                alive &= ~stopped               # past the transparent bounce limit
            alive = end_at_holdouts(ctx, hits, alive, b, path, alpha_out, depth)
            live = np.nonzero(alive)[0]
            if live.size == 0:
                break

            # The surfaces hit
            si = ctx.surfaces.build(hits, live, d, tp)
            t_live = None if tp is None else tp[live]
            shader_rows = _rows(mats, ctx.surfaces, si, depth)
            ns, ng = si.shading_normal, si.geometric_normal
            if shader_rows is not None:
                ns = mats.shading_normal(si.material, shader_rows, ns, ng)
            wo = to_local(-d[live], ns)
            rows = path[live]
            b_live = b[live]
            px_l, ix_l = px[live], ix[live]
            # 1c. emissive surfaces (two-sided, like Cycles' Emission shader), weighted
            # against next-event estimation of the emissive triangle that was hit
            if mats.any_emission:
                em = mats.emission_at(si.material, si.uv, shader_rows)
                glow = np.nonzero((em != 0).any(axis=1))[0]
                if glow.size:
                    g_live = live[glow]
                    light_pdf = lights.mesh_pdf(hits.prim[g_live], prev_pos[g_live],
                                                si.position[glow])
                    w = self._hit_weight(prev_pdf[g_live], light_pdf)
                    add(rows[glow], b_live[glow] * em[glow] * w[:, None], depth, direct=depth == 1)

            # the roulette's verdict, after the emission found: 0 ends the path, else
            # the throughput is divided by the survival probability
            q = verdict[rows]
            verdict[rows] = 1.0
            ended = q == 0.0
            b_live = b_live / np.where(ended, 1.0, q)[:, None]

            bsdf = PrincipledBSDF.from_materials(mats, si.material, si.front_facing, si.uv,
                                                 hits=shader_rows)
            c_live = counts[rows]
            allowed = (c_live < self.limits[None, :]) & (depth < self.max_bounces)

            # 2. next-event estimation
            if len(lights):
                u_pick = sampler.get_1d(D.bounce_dim(depth, D.LIGHT_PICK), px_l, ix_l)
                u_pt = sampler.get_2d(D.bounce_dim(depth, D.LIGHT_POINT), px_l, ix_l)
                ls, entry, delta = lights.sample(si.position, u_pick, u_pt, t_live)
                wi_local = to_local(ls.wi, ns)
                # towards a uniform world (never sampled by Cycles, whose escaping rays
                # find it) refraction on Walter's pairs only (dielectric.py's note)
                bsdf.as_cycles = ~lights.uniform_world(entry)
                f = bsdf.eval_f(wo, wi_local)
                # As in Cycles the lobes alone decide, on the shading normals; a shadow
                # ray leaves a smooth mesh from its curved surface (kernels.terminator).
                ok = (ls.pdf > 0) & (ls.radiance.max(1) > 0) & (f.max(1) > 0) & ~ended
                if ok.any():
                    sel = np.nonzero(ok)[0]
                    org = _shadow_origins(ctx.surfaces, si, sel, ls.wi[sel])
                    dist = ls.dist[sel]
                    finite = np.isfinite(dist)
                    # the shadow ray runs from the offset origin to the sampled light point
                    # and stops short of it by the same relative margin as the origin (and,
                    # for emissive triangles, which are geometry, before the light itself)
                    to = si.position[sel] + ls.wi[sel] * np.where(finite, dist, 0.0)[:, None] - org
                    seg = np.linalg.norm(to, axis=1)
                    sdir = np.where((finite & (seg > 0))[:, None],
                                    to / np.where(seg > 0, seg, 1.0)[:, None], ls.wi[sel])
                    far = np.where(finite, seg * (1.0 - 2e-5), ctx.scene_radius * 4.0)
                    if ls.margin is not None:
                        far = np.where(finite, np.minimum(far, seg - ls.margin[sel]), far)
                    trans = shadow_transmittance(ctx, org, sdir, np.maximum(far, 0.0),
                                                 None if t_live is None else t_live[sel])
                    vis = trans.max(1) > 0
                    if vis.any():
                        sv = sel[vis]
                        bsdf_pdf = bsdf.pdf(wo, wi_local, allowed)[sv]
                        w = self._nee_weight(ls.pdf[sv], bsdf_pdf, delta[sv])
                        contrib = (b_live[sv] * f[sv] * np.abs(wi_local[sv, 2:3])
                                   * ls.radiance[sv] * trans[vis] * (w / ls.pdf[sv])[:, None])
                        add(rows[sv], contrib, depth, direct=depth == 0)

            bsdf.as_cycles = True
            # 3. continue by BSDF sampling
            u_lobe = sampler.get_1d(D.bounce_dim(depth, D.BSDF_LOBE), px_l, ix_l)
            u_dir = sampler.get_2d(D.bounce_dim(depth, D.BSDF_DIR), px_l, ix_l)
            bs = bsdf.sample(wo, u_lobe, u_dir, allowed)
            wi_world = to_world(bs.wi, ns)
            # reflection leaves on the geometric normal's side, refraction through it
            side = (wi_world * ng).sum(1)
            cont = (bs.valid & allowed.any(1) & ~ended
                    & np.where(bs.kind == TRANSMISSION, side < 0, side > 0))
            new_beta = b_live * bs.weight
            next_verdict = np.ones(len(rows))
            if depth + 1 >= ROULETTE_START:
                u_rr = sampler.get_1d(D.bounce_dim(depth, D.ROULETTE), px_l, ix_l)
                q = np.minimum(np.sqrt(np.maximum(new_beta.max(1), 0.0)), 1.0)
                next_verdict = np.where(u_rr < q, q, 0.0)
            cont &= new_beta.max(1) > 0
            keep = np.nonzero(cont)[0]
            if keep.size == 0:
                break
            path = rows[keep]
            beta[path] = new_beta[keep]
            verdict[path] = next_verdict[keep]
            counts[path, bs.kind[keep]] += 1
            d = wi_world[keep]
            o = offset_origin(si.position[keep], ng[keep], si.scale[keep], d)
            tm = np.full(keep.size, np.inf)
            prev_pos = si.position[keep]
            prev_pdf = np.where(bs.delta[keep], np.inf, bs.pdf[keep])
        return L
