"""The path tracer on compiled kernels: the wavefront loop in Python, the per-path work in
`engine.kernels.path_vertex`, the ray queries in Embree.

Per bounce: one closest-hit query for the live paths (repeated through transparent
layers where materials have alpha), one `shade` kernel (emission found, a shadow ray and
a continuation ray per path), one occlusion query for the shadow rays (closest-hit
queries through transparent layers where needed), one kernel adding what got through.
Python touches each bounce a handful of times whatever the number of paths, and every
stage releases the GIL, so work units on threads run in parallel.

The estimator is in `engine.kernels.path_vertex`'s docstring. Motion blur: each path
keeps the shutter time of its camera ray for all its rays, the accelerator places moving
objects at that time, hits on them are rebuilt there (`kernels.surface.rebuild_at_time`),
and a lamp that moves during the shutter is its slice at that time
(`kernels.lights.light_set.slice_row`).
"""
from __future__ import annotations

import numpy as np

from .. import light_passes, visibility
from ..accel import HitArrays
from ..surface import or_empty
from ..kernels import lights as klights
from ..kernels.lights.pack import EMISSION_SHADED, TRI_VISIBILITY
from ..kernels.bsdf import principled as kbsdf
from ..kernels.bsdf.layered_emission import dimming_rows
from ..kernels.bsdf.params import P_EMISSION_DIM
from ..bsdf.material_table import flatten_mixes
from ..kernels.camera_rays import pack_camera
from ..kernels.jit import Kernel
from ..kernels.path_config import path_config
from ..kernels.path_state import TracedScene, new_paths
from ..kernels.ray_queues import next_queue, shadow_queue
from ..kernels.path_vertex import shade
from ..kernels.light_tally import add_transmitted, add_unoccluded, new_tally
from ..kernels.path_weights import BSDF_ONLY, LIGHT_ONLY, MIS
from ..kernels.transparency import alpha_pass, merge_layer, shadow_pass
from ..kernels.majorant_bounds import bound_majorants
from ..kernels.medium_density import shadow_keys
from ..kernels.volume import STACK, V_HET, pack_volumes
from ..nodes.pack import PROG
from ..nodes.differentials import camera_cones
from ..sampling.dispatch import pixel_keys
from .volume_stack import camera_stack

_MODE_IDS = {"mis": MIS, "light": LIGHT_ONLY, "bsdf": BSDF_ONLY}
MIS_MODES = tuple(_MODE_IDS)
VOLUME_BOUNDS_MAX = 256     # volume boundaries one path may cross (Cycles: 1024)


class CompiledPathIntegrator:
    """Kajiya's path tracer; subclasses change the vertex kernel (`vertex`, one of
    path_vertex.shade's signature) or the bounce limits, and keep this wavefront loop."""

    splits_light = True       # its vertex kernel writes light passes and light groups

    def __init__(self, ctx):
        self.ctx = ctx
        s = ctx.settings
        surf, mats = ctx.surfaces, ctx.materials
        self.max_bounces = s.max_bounces
        # the render camera, for Camera and Window coordinates and the rays' footprints
        camera = getattr(ctx, "camera", None)
        self.camera = pack_camera(camera, ctx.filter)[0] if camera is not None \
            else np.zeros(0)
        self.transparent_limit = s.transparent_bounces
        self._mode = "mis"
        self.cfg = path_config(ctx.sampler, s, ctx.scene.film_transparent)
        self.geometry = surf.geometry(self.camera)
        self.params = kbsdf.pack_materials(mats)
        self.emission = np.ascontiguousarray(mats.emission, dtype=np.float64)
        self.textures = mats.shading()
        vis = or_empty(surf.visibility, 0, np.uint8)
        self.materials = (surf.material, np.ascontiguousarray(mats.maybe_transparent),
                          np.ascontiguousarray(mats.alpha, dtype=np.float64),
                          np.ascontiguousarray(mats.transparent_color, dtype=np.float64),
                          self.textures, vis)
        # Ray Visibility: closest hits pass through surfaces some ray kind does not see,
        # shadow rays through objects casting no shadow (engine.visibility)
        ray_kinds = visibility.CAMERA | visibility.DIFFUSE | visibility.GLOSSY \
            | visibility.TRANSMISSION
        self.skips_hits = bool(((vis & ray_kinds) != ray_kinds).any())
        self.skips_shadows = bool(((vis & visibility.SHADOW) == 0).any())
        self.any_transparent = mats.any_transparent
        self.tables = kbsdf.kernel_tables()
        dim_rows = dimming_rows(self.params, self.tables)
        dimming = ((self.params[surf.material, P_EMISSION_DIM], dim_rows)
                   if len(dim_rows) else None)
        self.lights = klights.pack_lights(ctx.lights, surf.visibility, ctx.has_motion,
                                          tree=s.light_tree, dimming=dimming)
        self.world = np.ascontiguousarray(ctx.world_radiance, dtype=np.float64)
        # homogeneous volumes (engine.kernels.volume): the table, and the media the
        # camera is inside, where every path starts
        self.vol = pack_volumes(flatten_mixes(ctx.scene.materials)[0],
                                ctx.scene.world.volume)
        self.has_volumes = self.vol.shape[0] > 0
        # heterogeneous volumes (engine.kernels.medium_density): their objects and
        # majorants; `het_runs` counts their program runs (0 in any other scene)
        self.heterogeneous = self.has_volumes and bool(self.vol[:, V_HET].any())
        if self.heterogeneous:
            # majorant grids hold a still scene's media where they are; with motion
            # blur each medium keeps one majorant everywhere
            bound_majorants(self.vol, self.textures, surf.material,
                            self.geometry[8], self.geometry[9],
                            (surf.positions, surf.corners), self.camera,
                            grids=not ctx.has_motion)
        self.het_runs = np.zeros(1, np.int64)
        # what shade is compiled with (None: without that code; see its docstring)
        programmed = bool((self.textures[PROG][:, 1] > 0).any())
        # a material that scatters below its surface walks there with rays the kernel
        # casts itself (engine.kernels.subsurface)
        rays = ctx.accel.kernel_rays() if mats.any_subsurface else None
        self.subsurface = rays is not None
        # emissive triangles whose emission varies over them: their light samples run
        # their material (engine.kernels.shaded_emitter)
        shaded = bool((self.lights[TRI_VISIBILITY] & EMISSION_SHADED).any())
        self.features = (self.textures if programmed else None,
                         self.vol if self.has_volumes else None,
                         self.vol if self.heterogeneous else None, rays,
                         self.emission if shaded else None)
        self.start_stack = (camera_stack(ctx, self.vol, surf.material) if self.has_volumes
                            else np.full(STACK, -1, np.int32))
        # the scene as the vertex kernels read it
        self.scene = TracedScene(self.geometry, self.params, self.emission, self.textures,
                                 self.tables, self.lights, self.world, self.vol,
                                 self.het_runs)
        # Cycles' light passes and light groups, when the render asks for them
        passes, groups = light_passes.wanted(ctx)
        self.light_passes = passes and self.splits_light
        self.light_groups = groups if self.splits_light else ()
        self.group_tables = (light_passes.group_tables(ctx, groups) if self.light_groups
                             else None)

    def entry_kernels(self) -> list:
        """The compiled kernels this integrator calls from Python (engine.render's
        compile progress finds their callees)."""
        mine = [v for v in globals().values() if isinstance(v, Kernel) and v is not shade]
        return mine + [self.vertex]

    @property
    def vertex(self):
        """The kernel that shades one bounce of every live path (a property, not a
        class attribute: wrapping a kernel at import would make its dispatcher)."""
        return shade

    @property
    def shadow_rays_per_path(self) -> int:
        """The most shadow rays the vertex kernel queues per path and bounce: one, one
        more for the equiangular light sample of a segment in a medium, and one more for
        the exit of a subsurface walk."""
        return 1 + int(self.has_volumes) + int(self.subsurface)

    @property
    def mis_mode(self) -> str:
        return self._mode

    @mis_mode.setter
    def mis_mode(self, mode: str):
        self._mode = mode
        if mode in _MODE_IDS:
            self.cfg = self.cfg._replace(mis_mode=_MODE_IDS[mode])

    # -- transparency: repeated queries through surfaces with alpha < 1 ----------------
    def _through_transparent(self, depth, paths, live, used, ray_bits, path_time, time, o,
                             d, tm, hits):
        """Closest hits seen through transparent layers and surfaces the rays do not see
        (engine.kernels.transparency); time: the rays' shutter times (None when nothing
        moves). A ray going on beyond a layer starts on it, naming it (Accelerator.
        intersect's skip). Returns (the hits (HitArrays), throughput factor (m, 3),
        stopped (m,))."""
        m = len(live)
        found = HitArrays(hits.t.copy(), hits.prim.copy(), hits.inst.copy(), hits.u.copy(),
                          hits.v.copy())
        factor, stopped = np.ones((m, 3)), np.zeros(m, bool)
        travelled = np.zeros(m)
        rows = np.arange(m, dtype=np.int64)
        cur = hits.arrays()
        out_rows, out_org, out_far = np.empty(m, np.int64), np.empty((m, 3)), np.empty(m)
        out_skip = np.empty((m, 4), np.int64)
        cfg = self.cfg
        layer = 0
        seg_org = np.ascontiguousarray(o, np.float64)    # where the hits cur are measured from
        while rows.size:
            k = alpha_pass(depth, layer, self.transparent_limit, cfg.sampler, cfg.spp,
                           paths[0], paths[1], live, used, ray_bits, path_time, rows, seg_org,
                           d, tm, cur, travelled, factor, stopped,
                           self.geometry, self.materials, out_rows, out_org, out_far,
                           out_skip)
            if k == 0:
                break
            rows = out_rows[:k].copy()
            seg_org = out_org[:k].copy()
            cur = self.ctx.accel.intersect(seg_org, d[rows], out_far[:k],
                                           None if time is None else time[rows],
                                           out_skip[:k, :2]).arrays()
            merge_layer(rows, travelled, cur, found)
            layer += 1
        return found, factor, stopped

    def shadow_transmittance(self, org, dirs, far, time, stacks, keys, skip=None):
        """Transmittance (n, 3) of shadow rays through transparent layers and volumes
        (stacks: each ray's volume stack, updated as it crosses boundaries; (0, STACK)
        without volumes); time: their shutter times (None when nothing moves); keys:
        their random streams in heterogeneous media (empty without); skip (n, 2) or (n, 4):
        what each ray must not hit (Accelerator.occluded's), None: nothing."""
        n = len(org)
        trans = np.ones((n, 3))
        rows = np.arange(n, dtype=np.int64)
        o, remaining = org, far
        cur_skip = np.full((n, 4), -1, np.int64)
        if skip is not None:
            cur_skip[:, :skip.shape[1]] = skip
        out_rows, out_org, out_far = np.empty(n, np.int64), np.empty((n, 3)), np.empty(n)
        out_skip = np.empty((n, 4), np.int64)
        ray_time = np.zeros(n) if time is None else np.ascontiguousarray(time, np.float64)
        layer = 0
        while rows.size:
            h = self.ctx.accel.intersect(o, dirs[rows], remaining,
                                         None if time is None else time[rows],
                                         cur_skip)
            k = shadow_pass(layer, self.transparent_limit, rows, o, dirs, ray_time,
                            remaining, h.arrays(), trans, self.geometry,
                            self.materials, self.vol, stacks, (keys, self.het_runs),
                            cur_skip, out_rows, out_org, out_far, out_skip)
            rows = out_rows[:k].copy()
            o, remaining = out_org[:k].copy(), out_far[:k].copy()
            cur_skip = out_skip[:k].copy()
            layer += 1
        return trans

    def radiance(self, pixel, index, origins, dirs, tmax, time=None, alpha_out=None,
                 split=False, first_out=None, first_hits=None, stop=None):
        """Radiance (n, 3) of the camera rays (origins, dirs, tmax) of samples `index` of
        pixels `pixel`; with `split`, the whole LightTally (engine.kernels.light_tally),
        with the light passes and groups this integrator was asked for. first_out: (n,)
        int64 to fill with the global triangle each camera ray found (through
        transparent layers and surfaces it does not see; -1: none), which decides where
        Cycles' shadow catcher splits a path (engine.shadow_catcher). first_hits: the
        camera rays' hits (engine.accel.Hits) to take instead of intersecting them (a
        bake's rays, which hit their texel's point: engine.bake). stop: a
        threading.Event that, once set, ends every path at its next bounce (a cancel)."""
        if self._mode not in _MODE_IDS:
            raise ValueError(f"mis_mode must be one of {MIS_MODES}, got {self._mode!r}")
        ctx, s = self.ctx, self.ctx.settings
        n = len(pixel)
        pkey = pixel_keys(np.uint64(ctx.sampler.seed), np.asarray(pixel, np.int64))
        index = np.ascontiguousarray(index, dtype=np.int64)
        coverage = alpha_out if alpha_out is not None else np.zeros(0)
        cone = camera_cones(self.camera, np.ascontiguousarray(dirs, dtype=np.float64))
        k = n if self.has_volumes else 0
        stacks = np.ascontiguousarray(np.tile(self.start_stack, (k, 1)), np.int32)
        # each path's shutter time, kept for all its rays (zeros when nothing moves)
        moving = time is not None
        path_time = np.ascontiguousarray(time, np.float64) if moving else np.zeros(n)
        paths = new_paths(pkey, index, path_time, coverage, stacks, cone)
        # each path's last vertex, as its light sample's receiver (point, normal, mode:
        # kernels/lights/tree.py); the camera's, with no normal
        paths.prev_pos[:, :3] = origins
        live = np.arange(n, dtype=np.int64)
        ns_max = n * self.shadow_rays_per_path       # the shadow rays one bounce may queue
        tally = new_tally(n, ns_max, split and self.light_passes,
                          len(self.light_groups) if split else 0, self.group_tables)
        # the shadow rays a bounce queues (a copy of the volume stack each), the next rays
        shadows = shadow_queue(ns_max, k > 0, STACK)
        nexts = next_queue(n)
        no_keys = np.zeros(0, np.uint64)
        o = np.ascontiguousarray(origins, dtype=np.float64)
        d = np.ascontiguousarray(dirs, dtype=np.float64)
        # a writable copy: a read-only view (np.broadcast_to) would be another type to
        # Numba, and load a second copy of the shading kernel (15 MB, 0.1 s per process)
        tm = np.array(np.broadcast_to(tmax, (n,)), dtype=np.float64)
        no_stop = np.zeros(n, bool)
        skip = None                  # what the rays leave (camera rays: nothing)
        # the camera rays' step, one per bounce (Max Bounces + 1 of them: the last one's
        # ray gathers what it finds; path_weights.ends_path), and one per crossing of a
        # volume's boundary
        steps = self.max_bounces + 2 + (VOLUME_BOUNDS_MAX if self.has_volumes else 0)
        for depth in range(steps):
            if live.size == 0 or (stop is not None and stop.is_set()):
                break
            ray_time = path_time[live] if moving else None
            hits = (first_hits if depth == 0 and first_hits is not None
                    else ctx.accel.intersect(o, d, tm, ray_time, skip))
            found, stopped = hits.arrays(), no_stop
            if self.any_transparent or self.skips_hits:
                found, factor, stopped = self._through_transparent(
                    depth, (pkey, index), live, paths.used, paths.ray_bits, path_time,
                    ray_time, o, d, tm, hits)
                paths.beta[live] *= factor
            if depth == 0 and first_out is not None:
                first_out[:] = found.prim
            ns, nn = self.vertex(depth, self.cfg, paths, tally, live, o, d, tm, found, stopped,
                                 self.scene, shadows, nexts, *self.features)
            if ns:
                sh = shadows
                sh_time = path_time[sh.path[:ns]] if moving else None
                clamps = (sh.bounce[:ns], s.clamp_direct, s.clamp_indirect)
                if self.any_transparent or self.skips_shadows or self.has_volumes:
                    keys = (shadow_keys(pkey, index, sh.path[:ns], depth)
                            if self.heterogeneous else no_keys)
                    trans = self.shadow_transmittance(sh.org[:ns], sh.dir[:ns], sh.far[:ns],
                                                      sh_time,
                                                      sh.stack[:ns] if k else sh.stack, keys,
                                                      sh.skip[:ns])
                    add_transmitted(tally, sh.path[:ns], sh.contrib[:ns], trans, *clamps)
                else:
                    blocked = ctx.accel.occluded(sh.org[:ns], sh.dir[:ns], sh.far[:ns],
                                                 sh_time, sh.skip[:ns])
                    add_unoccluded(tally, sh.path[:ns], sh.contrib[:ns], blocked, *clamps)
            live = nexts.path[:nn].copy()
            o, d = nexts.org[:nn].copy(), nexts.dir[:nn].copy()
            # a view: only the next query reads it, before shade writes the queue again
            skip = nexts.skip[:nn]
            tm = np.full(nn, np.inf)
        return tally if split else tally.L
