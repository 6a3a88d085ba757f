"""The path tracer on compiled kernels: the wavefront loop in Python, the per-path work in
`engine.kernels.path_vertex`, the ray queries in Embree.

Per bounce: one closest-hit query for the live paths, one `shade` kernel (emission found,
a shadow ray and a continuation ray per path), one occlusion query for the shadow rays,
one kernel adding what got through. Python touches each bounce a handful of times
whatever the number of paths, and every stage releases the GIL, so work units on
threads run in parallel.

It computes the same estimator as `engine.integrators.path.PathIntegrator`, which
remains the reference implementation and serves the scenes this one does not handle yet
(`unsupported` names the reason): motion blur, stochastic transparency and image
textures.
"""
from __future__ import annotations

import numpy as np

from ..kernels import lights as klights
from ..kernels.bsdf import principled as kbsdf
from ..kernels.path_vertex import BSDF_ONLY, LIGHT_ONLY, MIS, add_unoccluded, shade
from ..sampling.dispatch import pixel_keys
from .path import MIS_MODES

_MODE_IDS = {"mis": MIS, "light": LIGHT_ONLY, "bsdf": BSDF_ONLY}


def unsupported(ctx) -> str | None:
    """Why the compiled path tracer cannot render this context yet (None: it can)."""
    if ctx.has_motion:
        return "motion blur"
    if ctx.materials.any_transparent:
        return "stochastic transparency"
    if ctx.materials.any_textures:
        return "image textures"
    try:
        klights.pack_lights(ctx.lights)
    except NotImplementedError as e:
        return str(e)
    return None


class CompiledPathIntegrator:
    def __init__(self, ctx):
        self.ctx = ctx
        s = ctx.settings
        surf = ctx.surfaces
        self.max_bounces = s.max_bounces
        self._mode = "mis"
        self.cfg = np.array([ctx.sampler.kind, ctx.sampler.samples_per_pixel, s.max_bounces,
                             s.diffuse_bounces, s.glossy_bounces, s.transmission_bounces,
                             s.clamp_direct, s.clamp_indirect, MIS, ctx.scene_radius,
                             float(ctx.scene.film_transparent)],
                            dtype=np.float64)
        self.geometry = (surf.v0, surf.v1, surf.v2, surf.normal, surf.tri_scale,
                         surf.material,
                         surf.corner_normals if surf.corner_normals is not None
                         else np.zeros((0, 3, 3), np.float32),
                         surf.holdout if surf.holdout is not None else np.zeros(0, bool))
        self.params = kbsdf.pack_materials(ctx.materials)
        self.emission = np.ascontiguousarray(ctx.materials.emission, dtype=np.float64)
        self.tables = kbsdf.kernel_tables()
        self.lights = klights.pack_lights(ctx.lights)
        self.world = np.ascontiguousarray(ctx.world_radiance, dtype=np.float64)

    @property
    def mis_mode(self) -> str:
        return self._mode

    @mis_mode.setter
    def mis_mode(self, mode: str):
        self._mode = mode
        if mode in _MODE_IDS:
            self.cfg[8] = _MODE_IDS[mode]

    def radiance(self, pixel, index, origins, dirs, tmax, time=None, alpha_out=None):
        if self._mode not in _MODE_IDS:
            raise ValueError(f"mis_mode must be one of {MIS_MODES}, got {self._mode!r}")
        ctx = self.ctx
        n = len(pixel)
        pkey = pixel_keys(np.uint64(ctx.sampler.seed), np.asarray(pixel, np.int64))
        index = np.ascontiguousarray(index, dtype=np.int64)
        L = np.zeros((n, 3))
        coverage = alpha_out if alpha_out is not None else np.zeros(0)
        beta = np.ones((n, 3))
        counts = np.zeros((n, 3), dtype=np.int64)
        prev_pdf = np.full(n, np.inf)           # camera rays count as specular: weight 1
        prev_pos = np.ascontiguousarray(origins, dtype=np.float64).copy()
        live = np.arange(n, dtype=np.int64)
        o = np.ascontiguousarray(origins, dtype=np.float64)
        d = np.ascontiguousarray(dirs, dtype=np.float64)
        tm = np.ascontiguousarray(np.broadcast_to(tmax, (n,)), dtype=np.float64)
        sh_path = np.empty(n, np.int64)
        sh_org, sh_dir = np.empty((n, 3)), np.empty((n, 3))
        sh_far, sh_contrib = np.empty(n), np.empty((n, 3))
        nx_path = np.empty(n, np.int64)
        nx_org, nx_dir = np.empty((n, 3)), np.empty((n, 3))
        for depth in range(self.max_bounces + 1):
            if live.size == 0:
                break
            hits = ctx.accel.intersect(o, d, tm)
            ns, nn = shade(depth, self.cfg, pkey, index, beta, counts, L, coverage,
                           prev_pdf, prev_pos, live, o, d, tm, hits.t, hits.prim, hits.u, hits.v,
                           self.geometry, self.params, self.emission, self.tables,
                           self.lights, self.world,
                           sh_path, sh_org, sh_dir, sh_far, sh_contrib,
                           nx_path, nx_org, nx_dir)
            if ns:
                blocked = ctx.accel.occluded(sh_org[:ns], sh_dir[:ns], sh_far[:ns])
                add_unoccluded(L, sh_path[:ns], sh_contrib[:ns], blocked)
            live = nx_path[:nn].copy()
            o, d = nx_org[:nn].copy(), nx_dir[:nn].copy()
            tm = np.full(nn, np.inf)
        return L
