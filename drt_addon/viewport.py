"""The Rendered viewport: DRT tracing the 3D view progressively while the artist works.

One ViewportSession per 3D view in Rendered mode (its RenderEngine's view_update and
view_draw call `sync` and `draw`), as Cycles' viewport session works:

- **Export once, then only what changed.** The first sync exports the scene from the
  viewport's depsgraph (viewport visibility, no motion blur) with an export.memo.ExportMemo;
  later syncs read `depsgraph.updates`, drop the geometry and materials the edit touched,
  and export again reusing the rest (a moved object or a lamp's strength evaluates no
  mesh). The acceleration structure is rebuilt from the exported arrays, except after an
  edit of lamps or the world alone (`RenderContext.relit` keeps it).
- **Navigation re-exports nothing.** The view's camera comes from the 3D view's matrices
  (drt_addon.viewport_camera); a new view gets a new camera on the same
  engine.RenderContext (`RenderContext.view`).
- **Progressive, in a thread.** Each restart traces first at a coarse resolution (one
  sample at 1/2^k of the size, as Cycles' start resolution of 64 pixels, then finer), then
  at full resolution in passes that grow towards PASS_SECONDS each, merging films
  (engine.film.Film.merge), up to Sampling > Viewport samples (`scene.cycles.preview_samples`,
  0: no limit). The thread reads no `bpy`: it publishes images, and tags the engine for
  a redraw (that only sets a flag in Blender, as Cycles' session thread does).
- **Restarts do not wait.** An edit or a move bumps the session's generation; the old
  thread sees it at its next poll and stops, its results are dropped, and its context is
  closed once it has finished.
- **Denoising** as the viewport's Cycles settings ask (Sampling > Viewport > Denoise,
  with its input passes, prefilter, quality and start sample), by OpenImageDenoise on
  every published image from the start sample on (drt_addon.denoise).
- **Drawing** (`draw`, in view_draw): the newest image is uploaded as a float texture and
  drawn with Blender's display space shader, so the view transform and look apply as in
  Cycles' viewport; a coarse image is stretched over the view.
"""
from __future__ import annotations

import threading
import time
from dataclasses import replace
from importlib import import_module

import numpy as np

from . import shadow_catcher
from .engine_link import engine
from .export.memo import ExportMemo
from .viewport_camera import ViewportView, view_of

START_RESOLUTION = 64    # pixels on the longer side of the first, coarsest image (Cycles')
PASS_SECONDS = 0.5       # a full-resolution pass grows towards this long
UNLIMITED = 1 << 24      # preview_samples 0: Cycles' "no limit"
# Paths per work unit: a restart waits for the units running (they cannot be
# interrupted), so they are small: ~0.1 s at 3 us a path
UNIT_PATHS = 1 << 15

# The newest session's timings and counts, for tests and docs (last_render's twin).
last_viewport = {}


def viewport_settings(scene):
    """engine.RenderSettings of the viewport: the render's own, with Sampling > Viewport's
    samples (Cycles' preview_samples; 1024 without the Cycles add-on), no adaptive
    sampling or time limit, and small work units (UNIT_PATHS)."""
    settings = scene.drt.to_engine_settings()
    samples = int(getattr(getattr(scene, "cycles", None), "preview_samples", 1024))
    return replace(settings, samples=samples if samples > 0 else UNLIMITED,
                   adaptive_sampling=False, time_limit=0.0,
                   chunk_paths=min(settings.chunk_paths, UNIT_PATHS))


def denoise_settings(scene):
    """(engine.denoiser.DenoiseSettings, start sample) of Sampling > Viewport > Denoise,
    or None when the viewport is not denoised."""
    c = getattr(scene, "cycles", None)
    if c is None or not getattr(c, "use_preview_denoising", False):
        return None
    denoiser = import_module(engine.__name__ + ".denoiser")
    if denoiser.available() is not None:
        return None                           # ViewportSession.status says why
    inputs = c.preview_denoising_input_passes
    from .denoise import quality
    s = denoiser.DenoiseSettings(input_passes=inputs, prefilter=c.preview_denoising_prefilter,
                                 quality=quality(c, "preview_denoising_quality"))
    return s, max(1, int(c.preview_denoising_start_sample))


def is_paused(scene) -> bool:
    """Cycles' Pause of the Rendered viewport (`scene.cycles.preview_pause`, the header's
    pause button): the view keeps its last image and traces nothing until resumed."""
    return bool(getattr(getattr(scene, "cycles", None), "preview_pause", False))


def _original(scene):
    """The scene the artist edits: an edit of a render setting reaches the depsgraph's
    evaluated copy only with the next evaluation, and Blender may not evaluate for it."""
    return getattr(scene, "original", None) or scene


class _Run:
    """One restart's work: its generation, context, view, settings and thread."""

    def __init__(self, generation, ctx, view: ViewportView, settings, denoise):
        self.generation, self.ctx, self.view = generation, ctx, view
        self.settings, self.denoise = settings, denoise
        self.thread = None


class ViewportSession:
    def __init__(self, tag_redraw):
        self.memo = ExportMemo()
        self.tag_redraw = tag_redraw
        self.ctx = None              # the context of the newest export
        self.view = None
        self.settings = self.denoise = None
        self.generation = 0
        self.lock = threading.Lock()
        self.published = None        # (generation, rgba (h, w, 4) float32, samples, resolution step)
        self.drawn = None            # (generation, samples, step) of the texture
        self.texture = None
        self.runs = []               # _Run whose thread may still be tracing
        self.retired = []            # contexts to close once no run uses them
        self.reporter = None
        self.error = None
        self.note = ""               # what the status line adds (a denoiser missing)
        self.paused = False          # Cycles' Pause (scene.cycles.preview_pause)

    # -- main thread: Blender's view_update and view_draw ---------------------------------

    def sync(self, depsgraph, context, reporter, settings_changed=False) -> None:
        """Export (the first time) or export what `depsgraph.updates` changed, and restart.
        `settings_changed`: the render settings changed (`draw` saw it; Blender does not
        always tell view_update), so export again whatever the updates say."""
        from .export import export_scene
        t0 = time.perf_counter()
        scene = _original(depsgraph.scene)
        settings, denoise = viewport_settings(scene), denoise_settings(scene)
        first = self.ctx is None
        if first:
            self.paused = is_paused(scene)
        if not first and not settings_changed:
            kinds = self.memo.forget_updated(depsgraph.updates)
            if not kinds or (kinds == {"SCENE"} and settings == self.settings
                             and denoise == self.denoise):
                return                        # a selection, or nothing DRT shows
        self.reporter = reporter
        view = view_of(context, depsgraph)
        stats = {}
        description = export_scene(depsgraph, reporter, stats=stats, memo=self.memo,
                                   view=(view.camera, view.width, view.height))
        settings.validate()
        t_export = time.perf_counter()
        relight = (not first and not settings_changed and self.memo.lights_only
                   and settings == self.settings
                   and (getattr(description.world, "volume", None) is None)
                   == (getattr(self.ctx.scene.world, "volume", None) is None))
        # lamps or the world alone: the acceleration structure and materials are kept
        ctx = self.ctx.relit(description) if relight else engine.RenderContext(description,
                                                                              settings)
        if self.ctx is not None and not relight:   # a relit context shares its structure
            self.retired.append(self.ctx)
        self.ctx, self.settings, self.denoise = ctx, settings, denoise
        self.note = ""
        if denoise is None and getattr(getattr(scene, "cycles", None), "use_preview_denoising",
                                       False):
            why = import_module(engine.__name__ + ".denoiser").available()
            self.note = f" (not denoised: {why})"
        last_viewport.update(syncs=last_viewport.get("syncs", 0) + 1, export_stats=stats,
                             export_seconds=t_export - t0,
                             build_seconds=time.perf_counter() - t_export, first_sync=first,
                             rebuilt=not relight,
                             edit_time=t0, first_image_seconds=None)
        self._restart(view)

    def draw(self, context, depsgraph, render_engine) -> None:
        """Restart if the view moved (nothing is exported), then draw the newest image."""
        self._close_finished()
        if self.ctx is None:
            return
        scene = _original(depsgraph.scene)
        self.follow_pause(scene, context, depsgraph)
        if (viewport_settings(scene), denoise_settings(scene)) != (self.settings, self.denoise):
            self.sync(depsgraph, context, self.reporter, settings_changed=True)
        self.look(view_of(context, depsgraph))
        with self.lock:
            published = self.published
        if self.paused and published is not None:
            published = (self.generation,) + published[1:]   # paused: the last image
        if published is None or published[0] != self.generation:
            return                           # nothing of this view yet: keep the last frame
        self._upload(published)
        self._draw_texture(depsgraph.scene, render_engine)
        if last_viewport.get("drawn_generation") != published[0]:
            last_viewport.update(first_drawn_at=time.perf_counter(), full_drawn_at=None)
        if published[3] == 1 and last_viewport.get("full_drawn_at") is None:
            last_viewport["full_drawn_at"] = time.perf_counter()   # full resolution
        last_viewport.update(drawn_generation=published[0], drawn_samples=published[2],
                             drawn_step=published[3])

    def status(self) -> str:
        """The viewport's stats line: samples done of the viewport's, or what went wrong."""
        if self.error:
            return self.error
        if self.paused:
            return "DRT: paused"
        if self.view is not None and (self.view.region.width < 1 or self.view.region.height < 1):
            return "DRT: the Render Region is empty"
        with self.lock:
            published = self.published
        if published is None or published[0] != self.generation:
            return "DRT: rendering"
        samples, total = published[2], self.settings.samples
        limit = "" if total >= UNLIMITED else f"/{total}"
        denoised = " (denoised)" if last_viewport.get("denoised") else ""
        return (f"Sample {samples}{limit}{denoised}{self.note}" if samples
                else "DRT: rendering")

    def follow_pause(self, scene, context, depsgraph) -> None:
        """Pause (the thread stops, the last image stays) or resume (a restart) as the
        scene's Pause says."""
        paused = is_paused(scene)
        if paused == self.paused:
            return
        self.paused = paused
        if paused:
            self.generation += 1
        else:
            self._restart(view_of(context, depsgraph))

    def look(self, view: ViewportView) -> bool:
        """Trace `view` from now on if it is not the one traced (navigation: nothing is
        exported); returns whether the render restarted."""
        if self.view is not None and view.key == self.view.key:
            return False
        last_viewport.update(edit_time=time.perf_counter(), first_image_seconds=None,
                             looks=last_viewport.get("looks", 0) + 1)
        self._restart(view)
        return True

    def free(self) -> None:
        """Stop tracing and release every context (the engine is being freed)."""
        self.generation += 1
        for run in self.runs:
            if run.thread is not None:
                run.thread.join(timeout=30.0)
        self.runs = []
        for ctx in self.retired + ([self.ctx] if self.ctx is not None else []):
            ctx.close()
        self.retired, self.ctx, self.texture = [], None, None

    # -- the render thread -----------------------------------------------------------------

    def _restart(self, view: ViewportView) -> None:
        self.generation += 1
        self.view = view
        self.error = None                     # a new start: said again if it recurs
        run = _Run(self.generation, self.ctx, view, self.settings, self.denoise)
        if view.region.width < 1 or view.region.height < 1 or self.paused:
            return                            # an empty Render Region, or paused
        run.thread = threading.Thread(target=self._trace, args=(run,), daemon=True,
                                      name=f"DRT viewport {run.generation}")
        self.runs.append(run)
        run.thread.start()

    def _stale(self, run) -> bool:
        return run.generation != self.generation

    def _trace(self, run: _Run) -> None:
        try:
            self._trace_run(run)
        except Exception as e:               # shown in the viewport's stats, never raised
            self.error = f"DRT viewport: {type(e).__name__}: {e}"
            last_viewport["error"] = self.error

    def _trace_run(self, run: _Run) -> None:
        render = import_module(engine.__name__ + ".render")
        film_mod = import_module(engine.__name__ + ".film")
        rect = run.view.region
        camera = run.view.traced_camera()
        w, h = rect.width, rect.height
        # coarse images first: one sample at 1/2^k of the size, finer until 1/2
        step = 1
        while max(w, h) // (step * 2) >= START_RESOLUTION:
            step *= 2
        one = replace(run.settings, samples=1)
        while step > 1:
            ctx = run.ctx.view(camera, -(-w // step), -(-h // step))
            film, _ = render.render(ctx.scene, one, context=ctx,
                                    cancelled=lambda: self._stale(run))
            if self._stale(run):
                return
            self._publish(run, film, 0, step, None)
            step //= 2
        ctx = run.ctx.view(camera, w, h)
        film, done, size = film_mod.Film(w, h, extra=ctx.film_channels()), 0, 1
        guides = None
        while done < run.settings.samples and not self._stale(run):
            size = min(size, run.settings.samples - done)
            t = time.perf_counter()
            part, stats = render.render(ctx.scene, run.settings, sample_start=done,
                                        sample_end=done + size, context=ctx,
                                        cancelled=lambda: self._stale(run))
            if self._stale(run) or stats.cancelled:
                return
            film = film.merge(part)
            done += size
            if run.denoise is not None and done >= run.denoise[1] and guides is None:
                guides = self._guides(ctx, run.denoise[0])
            self._publish(run, film, done, 1, guides)
            seconds = max(time.perf_counter() - t, 1e-3)
            size = int(max(1, min(2 * size, size * PASS_SECONDS / seconds)))

    def _guides(self, ctx, settings):
        """(albedo, normal) for OIDN from engine.aov's first hits, as the final render's."""
        if not settings.uses_albedo:
            return (None, None)
        aov = import_module(engine.__name__ + ".aov")
        first = aov.first_hit_passes(ctx)
        normal = first.camera_normal(ctx.scene.camera.matrix) if settings.uses_normal else None
        return (first.albedo, normal)

    def _publish(self, run, film, samples, step, guides) -> None:
        # shadow catchers as Cycles' viewport shows them: the shadow laid in
        image, alpha = shadow_catcher.combined(run.ctx, film, None)
        if guides is not None:
            denoiser = import_module(engine.__name__ + ".denoiser")
            try:
                image = denoiser.denoise(image, guides[0], guides[1], run.denoise[0])
            except RuntimeError as e:          # OIDN failed: the noisy image, said once
                self.error = f"DRT viewport: not denoised: {e}"
        h, w = image.shape[:2]
        rgba = np.empty((h, w, 4), np.float32)
        rgba[..., :3] = image[::-1]            # bottom-up, as textures are
        rgba[..., 3] = alpha[::-1]
        with self.lock:
            if self._stale(run):
                return
            self.published = (run.generation, rgba, samples, step)
        now = time.perf_counter()
        if last_viewport.get("first_image_seconds") is None:
            last_viewport["first_image_seconds"] = now - last_viewport.get("edit_time", now)
        last_viewport.update(samples=samples, step=step, generation=run.generation,
                             denoised=guides is not None, published_at=now)
        self.tag_redraw()

    def _close_finished(self) -> None:
        self.runs = [r for r in self.runs if r.thread is not None and r.thread.is_alive()]
        busy = {id(r.ctx.accel) for r in self.runs}     # relit contexts share theirs
        keep = []
        for ctx in self.retired:
            if id(ctx.accel) in busy:
                keep.append(ctx)
            else:
                ctx.close()
        self.retired = keep

    # -- drawing ------------------------------------------------------------------------------

    def _upload(self, published) -> None:
        import gpu
        generation, rgba, samples, step = published
        if self.drawn == (generation, samples, step) and self.texture is not None:
            return
        h, w = rgba.shape[:2]
        buffer = gpu.types.Buffer("FLOAT", w * h * 4, rgba.reshape(-1))
        self.texture = gpu.types.GPUTexture((w, h), format="RGBA16F", data=buffer)
        self.drawn = (generation, samples, step)

    def _draw_texture(self, scene, render_engine) -> None:
        import gpu
        from gpu_extras.presets import draw_texture_2d
        rect, size = self.view.region, self.view.pixel_size
        gpu.state.blend_set("ALPHA_PREMULT")
        render_engine.bind_display_space_shader(scene)
        draw_texture_2d(self.texture, (rect.x * size, rect.y * size), rect.width * size,
                        rect.height * size)
        render_engine.unbind_display_space_shader()
        gpu.state.blend_set("NONE")
