"""Whitted's ray tracer (1980): the lecture's baseline, with mirror-only interreflection.

At each hit: emission; direct light from every light, each through ONE shadow ray to a
fixed point of the light (its centre for area and sphere lights, the sun's central
direction), so shadows are hard; then the ray continues as a perfect mirror reflection or
a perfect refraction, glossy reflection being replaced by the mirror direction. Diffuse
interreflection is not followed. Only the pixel is sampled (anti-aliasing).

The reflectance of the mirror and the transmittance of the refraction come from the
Principled parameters: metals reflect F_schlick(base colour); dielectrics reflect the
exact Fresnel term of their IOR (scaled by Specular IOR Level, 0.5 = as is) and transmit
the rest where Transmission is set. Where a hit both reflects and refracts, one of the two
rays of Whitted's tree is followed, chosen with probability proportional to its weight
(and the weight divided by that probability), which has the same expectation as the tree
and keeps the wavefront one ray per path.
"""
from __future__ import annotations

import numpy as np

from ..bsdf import fresnel
from ..lights import luminance
from ..sampling import dimensions as D
from ..surface import offset_origin
from .coverage import background_is_transparent, end_at_holdouts, uncovered
from ..warp import INV_PI
from .path import intersect_alpha, shadow_transmittance

CENTRE = 0.5


def _reflect(d, n):
    return d - 2.0 * (d * n).sum(1, keepdims=True) * n


def _refract(d, n, eta_rel):
    """Refract unit d through the surface with normal n facing the incoming side,
    eta_rel = n_transmitted / n_incident. Returns direction and a validity mask."""
    cos_i = -(d * n).sum(1)
    sin2_t = (1.0 - cos_i ** 2) / eta_rel ** 2
    ok = sin2_t < 1.0
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    t = d / eta_rel[:, None] + ((cos_i / eta_rel) - cos_t)[:, None] * n
    t /= np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-300)
    return t, ok


class WhittedIntegrator:
    def __init__(self, ctx):
        self.ctx = ctx
        self.max_depth = ctx.settings.max_bounces

    def _direct(self, si, diffuse_albedo, time):
        """Sum over all lights of one deterministic shadow ray each (hard shadows)."""
        ctx = self.ctx
        n = len(si.position)
        out = np.zeros((n, 3))
        centre = np.full((n, 2), CENTRE)
        for model in ctx.lights.models:
            if getattr(model, "is_environment", False):
                continue        # Whitted sees the world only along mirror rays
            ls = model.sample(si.position, centre, time)
            cos = (ls.wi * si.shading_normal).sum(1)
            ok = (ls.pdf > 0) & (cos > 0) & ((ls.wi * si.geometric_normal).sum(1) > 0) \
                & (ls.radiance.max(1) > 0)
            if not ok.any():
                continue
            sel = np.nonzero(ok)[0]
            org = offset_origin(si.position[sel], si.geometric_normal[sel], si.scale[sel],
                                ls.wi[sel])
            far = np.where(np.isfinite(ls.dist[sel]), ls.dist[sel] * (1.0 - 2e-5),
                           ctx.scene_radius * 4.0)
            trans = shadow_transmittance(ctx, org, ls.wi[sel], np.maximum(far, 0.0),
                                         None if time is None else time[sel])
            vis = trans.max(1) > 0
            sv = sel[vis]
            out[sv] += (diffuse_albedo[sv] * INV_PI * cos[sv, None] * ls.radiance[sv]
                        * trans[vis] / ls.pdf[sv, None])
        return out

    def radiance(self, pixel, index, origins, dirs, tmax, time=None, alpha_out=None):
        ctx = self.ctx
        mats = ctx.materials
        n = len(pixel)
        L = np.zeros((n, 3))
        beta = np.ones((n, 3))
        path = np.arange(n)
        o, d, tm = origins, dirs, tmax
        transparent = np.zeros(n, dtype=np.int64)     # transparent bounces per path
        for depth in range(self.max_depth + 1):
            if path.size == 0:
                break
            b = beta[path]
            tp = None if time is None else time[path]
            hits, tfac, t_used, stopped = intersect_alpha(
                ctx, o, d, tm, tp, pixel[path], index[path], depth, transparent[path])
            if tfac is not None:
                transparent[path] = t_used
                b = b * tfac
            t_geom = np.where(hits.hit, hits.t, tm)
            alive = np.ones(path.size, dtype=bool)
            if len(ctx.lights):
                t_l, k_l, le = ctx.lights.hit_surfaces(o, d, t_geom, tp)
                on_light = k_l >= 0
                if depth == 0:
                    on_light &= ctx.light_visible_camera[np.maximum(k_l, 0)]
                L[path[on_light]] += b[on_light] * le[on_light]   # and the ray goes on
            escaped = alive & ~hits.hit
            if background_is_transparent(ctx, alpha_out, depth):
                alpha_out[path[escaped]] = uncovered(b[escaped])
            else:
                L[path[escaped]] += b[escaped] * ctx.world.escaped(d[escaped])
            alive &= ~escaped
            if stopped is not None:
                alive &= ~stopped               # past the transparent bounce limit
            alive = end_at_holdouts(ctx, hits, alive, b, path, alpha_out, depth)
            live = np.nonzero(alive)[0]
            if live.size == 0:
                break
            si = ctx.surfaces.build(hits, live, d, tp)
            rows = path[live]
            bl = b[live]
            m = si.material
            L[rows] += bl * mats.emission_at(m, si.uv)
            base = mats.base_color_at(m, si.uv)
            metal = np.clip(mats.metallic_at(m, si.uv), 0, 1)[:, None]
            metal_f0 = mats.metal_color_at(m, base)
            trans = np.clip(mats.transmission[m], 0, 1)[:, None] * (1 - metal)
            dl = d[live]
            cos_o = np.clip(-(dl * si.shading_normal).sum(1), 0.0, 1.0)
            # Seen from the side the ray came from, entering if it hit the front face.
            eta = np.where(si.front_facing, mats.ior[m], 1.0 / np.maximum(mats.ior[m], 1e-6))
            f_d = fresnel.dielectric(cos_o, eta)[:, None]
            spec = np.clip(2.0 * mats.specular_ior_level[m], 0.0, None)[:, None]
            k_r = (metal * fresnel.schlick(metal_f0, cos_o)
                   + (1 - metal) * np.minimum(f_d * spec, 1.0))
            k_t = trans * (1.0 - f_d)
            k_d = base * (1 - metal) * (1 - trans) * (1.0 - np.minimum(f_d * spec, 1.0))
            if len(ctx.lights):
                L[rows] += bl * self._direct(si, k_d, None if tp is None else tp[live])
            if depth == self.max_depth:
                break
            # Follow the mirror or the refracted ray (one branch of Whitted's tree).
            wr, wt = luminance(bl * k_r), luminance(bl * k_t)
            total = wr + wt
            u = ctx.sampler.get_1d(D.bounce_dim(depth, D.BSDF_LOBE), pixel[rows], index[rows])
            take_t = u * total < wt
            p_branch = np.where(take_t, wt, wr) / np.where(total > 0, total, 1.0)
            new_d = _reflect(dl, si.shading_normal)
            eta_rel = np.where(si.front_facing, mats.ior[m], 1.0 / np.maximum(mats.ior[m], 1e-6))
            t_dir, t_ok = _refract(dl, si.shading_normal, eta_rel)
            new_d = np.where(take_t[:, None], t_dir, new_d)
            weight = np.where(take_t[:, None], k_t, k_r) / np.maximum(p_branch, 1e-300)[:, None]
            side = (new_d * si.geometric_normal).sum(1)
            cont = (total > 0) & np.where(take_t, t_ok & (side < 0), side > 0)
            keep = np.nonzero(cont)[0]
            if keep.size == 0:
                break
            path = rows[keep]
            beta[path] = bl[keep] * weight[keep]
            d = new_d[keep]
            o = offset_origin(si.position[keep], si.geometric_normal[keep], si.scale[keep], d)
            tm = np.full(keep.size, np.inf)
        return L
