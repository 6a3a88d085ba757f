"""The render driver: turns a Scene and RenderSettings into a Film.

Work is split into units of (a block of pixels) x (a range of sample indices), each at
most `settings.chunk_paths` paths, so memory is bounded by the chunk size, never by
samples x pixels. Units run on a thread pool: Embree and most NumPy kernels release the
GIL, so threads use every core. Samples go in passes (progressive rendering): after each
pass the caller's `progress` callback sees the film, and `cancelled` is polled between
units, so a cancel returns within one unit's time and leaves a valid partial film (each
pixel is the mean of the samples it got).

Any sample range [sample_start, sample_end) renders on its own and the films of disjoint
ranges merge exactly (`Film.merge`): every random number is a function of (seed, pixel,
sample index, dimension), see `engine.sampling`.
"""
from __future__ import annotations

import copy
import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from concurrent.futures import TimeoutError as FutureTimeout
from dataclasses import replace

import numpy as np

from .accel import Accelerator
from .adaptive_sampling import AdaptiveSampling
from .bsdf.material_table import MaterialTable
from .camera import CameraModel, CameraRays
from .film import Film
from . import instancing, light_passes, shadow_catcher
from .integrators import make_integrator
from .kernels.camera_rays import generate as generate_camera_rays
from .kernels.camera_rays import pack_camera
from .kernels.compile_watch import CompileWatch, reachable
from .kernels.jit import Kernel
from .lights import LightSet
from .mesh_lights import EmissiveTriangles
from .pixel_filter import PixelFilter
from .sampling import dimensions as D
from .sampling import make_sampler
from .sampling.dispatch import pixel_keys
from .scene import Scene
from .render_stats import RenderStats
from .settings import RenderSettings
from .surface import SurfaceBuilder
from .world_light import world_model


POLL = 0.05      # seconds between looks at cancel and compile progress while units run


class RenderContext:
    """Everything a render needs, built once per scene (the acceleration structure is the
    expensive part)."""

    def __init__(self, scene: Scene, settings: RenderSettings):
        settings.validate()
        self.scene, self.settings = scene, settings
        self.camera = CameraModel(scene.camera, scene.width, scene.height, scene.pixel_aspect)
        self.filter = PixelFilter(settings.filter_type, settings.filter_width)
        self.sampler = make_sampler(settings.sampler, settings.seed, settings.samples)
        adaptive = AdaptiveSampling.from_settings(settings)
        if adaptive is not None:
            self.sampler.follow_stops(adaptive.first_check(), adaptive.step)
        self.has_motion = scene.has_motion()
        self.materials = MaterialTable(scene.materials)
        # instanced meshes stay instanced unless they emit or bound a volume
        meshes = instancing.resolve(
            scene.meshes, _instanceable(scene.materials, self.materials.emission_estimate))
        self.accel = Accelerator(meshes, threads=1, time_enabled=self.has_motion,
                                 curves=scene.curves)
        self.surfaces = SurfaceBuilder(self.accel, [getattr(m, "holdout", False)
                                                    for m in scene.materials])
        self._light(scene, EmissiveTriangles.from_scene(
            scene, self.accel, self.materials.emission_estimate,
            shaded=self.materials.emission_shaded))
        self.integrator = make_integrator(settings.integrator, self)
        self.catcher = self._catcher_run()
        # A camera that does not move gets its rays from one compiled kernel.
        self.camera_kernel = None if self.has_motion else pack_camera(self.camera, self.filter)

    def _catcher_run(self, like=None):
        """The shadow catcher's second run (engine.shadow_catcher; None without a catcher
        object), reusing `like`'s, a run on the same geometry, where given."""
        if like is not None:
            return shadow_catcher.CatcherRun(self, like.catcher, like)
        catcher = shadow_catcher.catcher_triangles(self.accel)
        return None if catcher is None else shadow_catcher.CatcherRun(self, catcher)

    def film_channels(self) -> int:
        """The RGB channels the film keeps per pixel besides Combined: the light passes
        and groups (engine.light_passes), then the shadow catcher's."""
        return light_passes.channels(self) + (shadow_catcher.CHANNELS
                                              if self.catcher is not None else 0)

    def _light(self, scene: Scene, mesh_lights, world=None) -> None:
        """The scene radius, the world model and the light set of `scene` (its lamps, a
        Sky Texture's sun disc, the emissive triangles `mesh_lights`); `world`: the
        world model when it is already built."""
        self.scene_radius = _scene_radius(scene, self.accel)
        # the uniform world's radiance (zeros under an environment map), and the world
        # model (engine.world_light) escaped rays read
        self.world = world_model(scene.world) if world is None else world
        self.world_radiance = np.asarray(getattr(self.world, "radiance", np.zeros(3)),
                                         dtype=np.float64)[:3]
        # a Sky Texture's sun disc is one more lamp (engine.scene.World.sun)
        sun = getattr(scene.world, "sun", None)
        lamps = list(scene.lights) + ([sun] if sun is not None else [])
        self.lights = LightSet(lamps, self.scene_radius, mesh_lights=mesh_lights,
                               world=self.world, world_sun=sun)
        self.light_visible_camera = np.array(
            [getattr(m, "visible_camera", True) for m in self.lights.models] or [True])

    def close(self):
        self.accel.close()

    def relit(self, scene: Scene) -> "RenderContext":
        """This context with `scene`'s lamps and world, for a scene whose geometry and
        materials are this one's (the Rendered viewport after an edit of lamps or the
        world alone): the acceleration structure, the materials and the emissive
        triangles are kept; the lights, the world and the integrator are new."""
        other = copy.copy(self)
        other.scene = scene
        other.camera = CameraModel(scene.camera, scene.width, scene.height, scene.pixel_aspect)
        other.camera_kernel = None if self.has_motion else pack_camera(other.camera,
                                                                       self.filter)
        other._light(scene, self.lights.mesh)
        other.integrator = make_integrator(self.settings.integrator, other)
        other.catcher = None if self.catcher is None else other._catcher_run(self.catcher)
        return other

    def view(self, camera, width: int, height: int) -> "RenderContext":
        """This scene seen through `camera` at `width` x `height` (the Rendered viewport
        navigating, or rendering its first passes at a lower resolution): the
        acceleration structure, materials and lights are this context's, not rebuilt;
        the camera model, the camera kernel and the integrator (which packs the camera)
        are new. The lights are rebuilt only when the camera leaves the scene's bounds
        (lights at infinity are placed by the scene radius). Close only the context the
        scene was built for: views share its acceleration structure."""
        other = copy.copy(self)
        other.scene = replace(self.scene, camera=camera, width=int(width), height=int(height))
        other.camera = CameraModel(camera, other.scene.width, other.scene.height,
                                   other.scene.pixel_aspect)
        other.camera_kernel = None if other.has_motion else pack_camera(other.camera,
                                                                        other.filter)
        if _scene_radius(other.scene, self.accel) > self.scene_radius * (1.0 + 1e-9):
            other._light(other.scene, self.lights.mesh, self.world)
        other.integrator = make_integrator(self.settings.integrator, other)
        other.catcher = None if self.catcher is None else other._catcher_run(self.catcher)
        return other

    def entry_kernels(self) -> list:
        """The compiled kernels this render calls from Python: the camera's, the ray
        queries', and the integrator's (`compile_watch.reachable` finds their callees)."""
        from .embree import rays
        found = [generate_camera_rays, pixel_keys, rays.intersect_batch, rays.occluded_batch]
        found += self.integrator.entry_kernels()
        if self.catcher is not None:
            from .kernels.lights.batch import _world_rows
            found.append(_world_rows)
        if self.accel.moving:
            from . import accel
            found += [v for v in vars(accel).values() if isinstance(v, Kernel)]
        return found


def _holds_volume(m) -> bool:
    return (getattr(m, "volume", None) is not None or not getattr(m, "surface", True)
            or any(_holds_volume(side) for side in (getattr(m, "mix", None) or ())))


def _instanceable(materials, emission):
    """Whether an instanced mesh may stay instanced (engine.instancing): none of its
    materials emits (by the emission table the mesh lights read) or holds a volume."""
    emission = np.asarray(emission, np.float64).reshape(-1, 3)
    blocked = np.zeros(max(len(materials), len(emission)), bool)
    blocked[:len(emission)] = emission.max(axis=1) > 0.0
    blocked[:len(materials)] |= [_holds_volume(m) for m in materials]

    def keep(mesh) -> bool:
        used = np.unique(mesh.material_indices)
        return not blocked[used[used < len(blocked)]].any()
    return keep


def _scene_radius(scene: Scene, accel: Accelerator) -> float:
    pts = [accel.positions] if len(accel.positions) else []
    pts += [np.stack(instancing.world_bounds(p.mesh)) for p in accel.prototypes]
    pts += [c.keys for c in accel.curves]
    for l in scene.lights:
        if hasattr(l, "position"):
            pts.append(np.asarray(l.position, dtype=np.float64)[None])
        elif hasattr(l, "matrix"):
            pts.append(np.asarray(l.matrix, dtype=np.float64)[None, :3, 3])
    pts.append(np.asarray(scene.camera.matrix, dtype=np.float64)[None, :3, 3])
    # bounds of each part, then of the parts (the positions are not copied into one array)
    lo = np.min([p.min(0) for p in pts], axis=0)
    hi = np.max([p.max(0) for p in pts], axis=0)
    return float(max(np.linalg.norm(hi - lo) * 0.5, 1e-6))


def camera_rays(ctx: RenderContext, pixel: np.ndarray, index: np.ndarray):
    """The camera rays of samples `index` of pixels `pixel`: sub-pixel position through the
    pixel filter, a lens point only with an aperture, a shutter time only when something
    moves. Returns (CameraRays, time or None). Every pass (radiance, AOVs) uses this."""
    if ctx.camera_kernel is not None:
        n = len(pixel)
        o, d, tmax = np.empty((n, 3)), np.empty((n, 3)), np.empty(n)
        pixel = np.ascontiguousarray(pixel, dtype=np.int64)
        generate_camera_rays(*ctx.camera_kernel, ctx.sampler.kind,
                             ctx.sampler.pattern,
                             pixel_keys(np.uint64(ctx.sampler.seed), pixel), pixel,
                             np.ascontiguousarray(index, dtype=np.int64), o, d, tmax)
        return CameraRays(o, d, tmax), None
    w = ctx.scene.width
    u_pix = ctx.sampler.get_2d(D.PIXEL, pixel, index)
    offset = ctx.filter.sample(u_pix)
    film_xy = np.stack([pixel % w + 0.5 + offset[:, 0], pixel // w + 0.5 + offset[:, 1]], axis=1)
    lens_u = ctx.sampler.get_2d(D.LENS, pixel, index) if ctx.camera.has_lens else None
    # The time dimension exists only when something moves within an open shutter.
    time = ctx.scene.shutter.sample(ctx.sampler.get_1d(D.TIME, pixel, index)) \
        if ctx.has_motion else None
    return ctx.camera.generate(film_xy, lens_u, time), time


def render_unit(ctx: RenderContext, pixels: np.ndarray, sample_start: int, sample_end: int,
                stop=None):
    """Radiance of samples [sample_start, sample_end) of each pixel in `pixels`.
    Returns (pixel ids, sample indices, radiance (n, 3) float64, alpha (n,) or None when
    the film is opaque, the film's other channels (n, ctx.film_channels(), 3): the light
    passes and groups of engine.light_passes, then the shadow catcher's; None when it
    keeps none). stop: a threading.Event that, once set, ends the unit's paths at their
    next bounce (a cancelled render: its result is then not to be used)."""
    k = sample_end - sample_start
    pixel = np.repeat(pixels.astype(np.int64), k)
    index = np.tile(np.arange(sample_start, sample_end, dtype=np.int64), len(pixels))
    rays, time = camera_rays(ctx, pixel, index)
    n = len(pixel)
    alpha = np.ones(n) if ctx.scene.needs_alpha() else None
    lights = light_passes.channels(ctx)
    first = np.full(n, -1, np.int64) if ctx.catcher is not None else None
    found = ctx.integrator.radiance(pixel, index, rays.origins, rays.directions, rays.tmax,
                                    time=time, alpha_out=alpha, split=bool(lights),
                                    first_out=first, stop=stop)
    radiance = found.L if lights else found
    if not ctx.film_channels():
        return pixel, index, radiance, alpha, None
    parts = [light_passes.per_sample(found, n, lights)] if lights else []
    if ctx.catcher is not None:
        parts.append(ctx.catcher.samples(pixel, index, rays, time, radiance, alpha, first))
    return pixel, index, radiance, alpha, (parts[0] if len(parts) == 1
                                           else np.concatenate(parts, axis=1))


def plan_passes(total: int, first: int = 1, growth: float = 2.0, largest: int = 64):
    """Sample counts per progressive pass: 1, 2, 4, ... up to `largest` per pass."""
    passes, size, done = [], first, 0
    while done < total:
        size = min(size, total - done)
        passes.append((done, done + size))
        done += size
        size = min(int(size * growth) or 1, largest)
    return passes


def render(scene: Scene, settings: RenderSettings, *, sample_start: int = 0,
           sample_end: int | None = None, progress=None, cancelled=None,
           context: RenderContext | None = None, compiling=None):
    """Render samples [sample_start, sample_end) (default: all of settings.samples).

    progress(film, stats, fraction) is called after every pass; cancelled() is polled
    between work units, and every POLL seconds while a unit runs. compiling(done, total)
    is called while Numba compiles kernels (a first render with an empty cache): `done`
    of the `total` kernels the render can reach are compiled; a cancel then returns at
    once and the compile finishes in the background (its kernels are cached). With
    adaptive sampling (engine.adaptive_sampling) later passes take samples only in the
    pixels that have not converged; with a time limit the render stops at the first unit
    boundary after it. Returns (film, stats)."""
    ctx = context or RenderContext(scene, settings)
    sample_end = settings.samples if sample_end is None else sample_end
    if not (0 <= sample_start < sample_end):
        raise ValueError(f"empty or negative sample range [{sample_start}, {sample_end})")
    film = Film(scene.width, scene.height, extra=ctx.film_channels())
    lights = light_passes.channels(ctx)
    stats = RenderStats()
    n_pixels = scene.width * scene.height
    threads = settings.threads or min(os.cpu_count() or 1, 8)
    lock = threading.Lock()
    t0 = time.perf_counter()
    total = sample_end - sample_start
    stop = threading.Event()
    adaptive = AdaptiveSampling.from_settings(settings)
    active = np.arange(n_pixels)
    unconverged = np.ones(n_pixels, dtype=bool)
    passes = adaptive.passes(total, plan_passes) if adaptive else plan_passes(total)

    running = [0]
    abandoned = threading.Event()

    def run(pixels, a, b):
        with lock:
            if stop.is_set():
                return 0
            running[0] += 1
        try:
            pix, index, rad, alpha, extra = render_unit(ctx, pixels, a, b, stop)
        finally:
            with lock:
                running[0] -= 1
        if stop.is_set():
            return 0                           # cut short by a cancel: not a sample
        bad = ~np.isfinite(rad).all(axis=1)
        if extra is not None:
            bad |= ~np.isfinite(extra).all(axis=(1, 2))
        if bad.any():
            rad[bad] = 0.0
            if extra is not None:
                extra[bad] = 0.0
        if settings.film_exposure != 1.0:
            rad *= settings.film_exposure      # Film > Exposure, on the way into the film
            if lights:
                light_passes.scale_light(extra[:, :lights], settings.film_exposure)
            if ctx.catcher is not None:
                shadow_catcher.scale(extra[:, lights:], settings.film_exposure)
        with lock:
            if abandoned.is_set():             # finished after render() returned
                return 0
            film.add(pix, rad, alpha, index=index, extra=extra)
            stats.paths += len(pix)
            stats.nonfinite_samples += int(bad.sum())
            stats.units_done += 1
        return len(pix)

    def should_stop() -> bool:
        if cancelled is not None and cancelled():
            stats.cancelled = True
        elif settings.time_limit > 0 and stats.samples_done > 0 and \
                time.perf_counter() - t0 >= settings.time_limit:
            # after the first pass, so that every pixel has a sample
            stats.time_limited = True
        else:
            return False
        return True

    watch = CompileWatch(reachable(ctx.entry_kernels()))
    stats.kernels_reachable = watch.total
    pool = ThreadPoolExecutor(threads)
    try:
        with watch:
            for a, b in passes:
                a, b = a + sample_start, b + sample_start
                # Pixels per unit: two units per thread, none over chunk_paths paths
                # (memory) nor under 8192 (per-call overhead holds the GIL) unless that
                # leaves a thread idle (the viewport's coarse images)
                k = b - a
                most = max(1, settings.chunk_paths // k)
                least = min(-(-8192 // k), -(-len(active) // threads))
                per_unit = min(most, max(least, -(-len(active) // (2 * threads))))
                futures = [pool.submit(run, active[start:start + per_unit], a, b)
                           for start in range(0, len(active), per_unit)]
                for f in futures:
                    while True:
                        if not stop.is_set() and should_stop():
                            with lock:
                                stop.set()
                                stats.units_running_at_cancel = running[0]
                        if stop.is_set() and watch.compiling:
                            break       # a compile cannot be interrupted: left running
                        try:
                            f.result(timeout=POLL)
                            break
                        except FutureTimeout:
                            if watch.compiling and compiling is not None:
                                compiling(len(watch.done), watch.total)
                stats.compile_seconds = watch.seconds
                stats.kernels_compiled = len(watch.done)
                stats.seconds = time.perf_counter() - t0
                if stats.cancelled:
                    break
                if not stop.is_set():
                    stats.samples_done = b - sample_start
                if adaptive is not None and stats.samples_done >= adaptive.first_check():
                    active = adaptive.check(film, active, unconverged)
                    stats.active_pixels = len(active)
                if progress is not None:
                    fraction = stats.samples_done / total
                    if settings.time_limit > 0:
                        fraction = max(fraction, min(stats.seconds / settings.time_limit, 1.0))
                    progress(film, stats, 1.0 if stop.is_set() or not len(active) else fraction)
                if stop.is_set() or not len(active):
                    break
    finally:
        # after a cancel during a compile, the unit compiling goes on in the background
        if stop.is_set():
            with lock:
                abandoned.set()
        pool.shutdown(wait=not stop.is_set(), cancel_futures=True)
        if context is None:
            ctx.close()
    stats.seconds = time.perf_counter() - t0
    stats.pixel_samples = int(film.count.sum())
    return film, stats
