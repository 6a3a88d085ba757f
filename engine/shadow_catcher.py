"""Cycles' shadow catcher (Object > Visibility > Shadow Catcher): an object that records
what the rest of the scene does to it, its shadows and the light other objects bounce
onto it, as a pass of its own for compositing over a photographed background plate,
and is itself a hole in the Combined pass.

What Cycles does (read in its intersect_closest.h, film/light_passes.h and
film/read.h, and measured against its renders), and how DRT does the same:
- A camera ray (or its continuation through transparent layers) whose first hit is a
  catcher (not also a holdout) splits the path there. The path goes on as usual and adds
  to Combined (C). A copy goes on in a world of catcher objects alone, lit by the lamps
  whose object is a shadow catcher (every lamp, by Blender's default), the catchers'
  own emission and the world: the catcher as it would look with nothing else there
  (K). What the paths that never split gathered is the matte (M): the other objects
  and the background.
- DRT traces the copies as a second run of the same integrator on the samples that split,
  with their random numbers (the two runs agree wherever nothing else matters, so the
  ratio below is quiet where nothing shadows), on a context whose other surfaces are
  seen by camera rays only and end them (`CatcherRun`).
- The film keeps, besides Combined, CHANNELS more per sample: M, K, (the matte's
  transparency, the split count, 0) and the world behind a catcher (an opaque film).
- `shadow_pass`: (C - M) / K per channel where a pixel had splits (1 where K = 0, and
  where none), laid over white by Combined's alpha: 1 where nothing shadows the
  catcher, less in shadow, more where other objects add light.
- `combined`: with the Shadow Catcher pass on, the matte, transparent where the
  catcher is; with it off, Cycles' approximation: the matte over the shadow (alpha 1 -
  mean(S) where the catcher is) and, on an opaque film, over the world behind it.
"""
from __future__ import annotations

import copy
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from . import visibility

CHANNELS = 4
MATTE, CATCHER, COUNTS, BEHIND = range(CHANNELS)


def catcher_triangles(accel) -> np.ndarray | None:
    """A flag per global triangle of `accel` (engine.accel.Accelerator): its object is a
    shadow catcher and not a holdout; None when no object is one."""
    ordered = accel.ordered_meshes
    flags = [bool(getattr(m, "shadow_catcher", False)) and not getattr(m, "holdout", False)
             for m in ordered]
    if not any(flags):
        return None
    return np.concatenate([np.full(len(m.triangles), f) for m, f in zip(ordered, flags)])


class CatcherRun:
    """The second run of a render's integrator that traces the shadow catcher's copies of
    the paths that split (see the module's docstring)."""

    def __init__(self, ctx, catcher: np.ndarray, like: "CatcherRun | None" = None):
        """The run of `ctx` for the triangles flagged in `catcher`; `like`: the run of a
        context on the same geometry and materials (RenderContext.view and relit), whose
        catcher-path surfaces and emissive triangles are reused, not made again."""
        from .integrators import make_integrator
        from .mesh_lights import EmissiveTriangles
        self.catcher = np.asarray(catcher, bool)
        self.opaque = not ctx.scene.film_transparent
        run = copy.copy(ctx)
        lamps = [lamp for lamp in ctx.scene.lights if getattr(lamp, "shadow_catcher", True)]
        # a transparent film: a copy's camera ray that escapes adds nothing
        run.scene = replace(ctx.scene, lights=lamps, film_transparent=True, light_groups=())
        run.settings = replace(ctx.settings, light_passes=False)
        if like is None:
            self.surfaces = ctx.surfaces.seen_by_catcher_paths(self.catcher)
            self.mesh_lights = EmissiveTriangles.from_scene(
                ctx.scene, ctx.accel, ctx.materials.emission, only=self.catcher)
        else:
            self.surfaces, self.mesh_lights = like.surfaces, like.mesh_lights
        run.surfaces = self.surfaces
        run._light(run.scene, self.mesh_lights, ctx.world)
        run.catcher = None
        self.integrator = make_integrator(ctx.settings.integrator, run)
        # the main run's lights and world: what an escaped camera ray sees
        self.main = ctx.integrator

    def samples(self, pixel, index, rays, time, radiance, alpha, first) -> np.ndarray:
        """The film's catcher channels (n, CHANNELS, 3) of a batch of camera samples:
        `rays` (engine.camera.CameraRays) and `time` (None: nothing moves) as the main run
        traced them, its `radiance` (n, 3) and coverage `alpha` (n,) or None, `first` the
        global triangle each camera ray found (-1: none)."""
        from .kernels.lights.batch import world_escaped_batch
        n = len(pixel)
        first = np.asarray(first, np.int64)
        found = (first >= 0) & (first < len(self.catcher))
        split = np.zeros(n)
        split[found] = self.catcher[first[found]]
        out = np.zeros((n, CHANNELS, 3))
        out[:, MATTE] = radiance * (1.0 - split)[:, None]
        out[:, COUNTS, 0] = (0.0 if alpha is None else 1.0 - alpha) + split
        out[:, COUNTS, 1] = split
        rows = np.flatnonzero(split)
        if rows.size:
            d = np.ascontiguousarray(rays.directions[rows])
            out[rows, CATCHER] = self.integrator.radiance(
                pixel[rows], index[rows], np.ascontiguousarray(rays.origins[rows]), d,
                np.ascontiguousarray(np.broadcast_to(rays.tmax, (n,))[rows]),
                time=None if time is None else time[rows], alpha_out=np.ones(rows.size))
        if self.opaque:
            # the world behind a catcher, and where a camera ray escaped (Cycles'
            # background pass, which its approximate matte is laid over)
            behind = np.flatnonzero((split > 0) | (first < 0))
            if behind.size:
                out[behind, BEHIND] = world_escaped_batch(
                    self.main.lights, self.main.world, rays.directions[behind],
                    visibility.CAMERA)[0]
        return out


def scale(extra: np.ndarray, factor: float) -> None:
    """Film > Exposure on the catcher channels (n, CHANNELS, 3) of a batch, in place:
    the light, not the counts."""
    for c in (MATTE, CATCHER, BEHIND):
        extra[:, c] *= factor


class CatcherParts(NamedTuple):
    """A film's catcher channels as (height, width, ...) means, row 0 at the top."""
    matte: np.ndarray           # M (h, w, 3)
    catcher: np.ndarray         # K (h, w, 3)
    transparency: np.ndarray    # the matte's (h, w)
    splits: np.ndarray          # the share of samples that split (h, w)
    behind: np.ndarray          # the world behind the catcher (h, w, 3)


def parts(film) -> CatcherParts:
    """The catcher channels of `film`: its last CHANNELS extra channels."""
    c = np.maximum(film.count, 1)[:, None, None]
    mean = (film.extra_sum[:, -CHANNELS:] / c).reshape(film.height, film.width, CHANNELS, 3)
    return CatcherParts(mean[..., MATTE, :], mean[..., CATCHER, :],
                        mean[..., COUNTS, 0], mean[..., COUNTS, 1], mean[..., BEHIND, :])


def shadow_pass(combined: np.ndarray, alpha: np.ndarray, p: CatcherParts) -> np.ndarray:
    """Cycles' Shadow Catcher pass (h, w, 3) from the Combined pass's colour and alpha
    (its film, before the catcher's changes) and the catcher parts."""
    k = p.catcher
    safe = np.where(k != 0.0, k, 1.0)
    ratio = np.where(k != 0.0, (combined - p.matte) / safe, 1.0)
    a = np.asarray(alpha, np.float64)[..., None]
    s = (1.0 - a) + a * ratio
    return np.where((p.splits > 0.0)[..., None], s, 1.0)


def combined(combined: np.ndarray, alpha: np.ndarray, p: CatcherParts, pass_on: bool,
             opaque: bool) -> tuple[np.ndarray, np.ndarray]:
    """Cycles' Combined pass (colour (h, w, 3), alpha (h, w)) of a scene with shadow
    catchers: the matte, whose alpha leaves the catcher transparent, with the Shadow
    Catcher pass on; else the matte over the shadow, and on an opaque film over the
    world behind it."""
    matte_alpha = np.clip(1.0 - p.transparency, 0.0, 1.0)
    if pass_on:
        return p.matte, matte_alpha
    s = shadow_pass(combined, alpha, p)
    shadow = 1.0 - np.clip(s.mean(axis=-1), 0.0, 1.0)
    a = (1.0 - matte_alpha) * shadow + matte_alpha
    if not opaque:
        return p.matte, a
    return p.matte + p.behind * (1.0 - a)[..., None], np.ones_like(a)
