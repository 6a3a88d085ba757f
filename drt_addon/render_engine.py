"""The RenderEngine Blender selects as 'DRT' (F12, `blender -b file.blend -E DRT -f 1`, and
the 3D view's Rendered mode: view_update and view_draw, drt_addon.viewport).

The render passes it writes besides Combined are listed in drt_addon.render_passes.

Border render (Render Region): only the border's pixels are traced; the result covers
just that rectangle, which Blender places in the frame (or crops to, with Crop to Render
Region).
"""
from __future__ import annotations

import os
import sys
import time
import traceback

import bpy
import numpy as np
from bpy.props import BoolProperty, PointerProperty

from . import denoise, light_passes, shadow_catcher
from .blender_compat import AO_PASS, set_pass_pixels
from .render_passes import (PASSES, FirstHit, cryptomatte_passes, enabled_passes,
                            shader_aov_passes, vector_pass)
from .render_result import rgba_bottom_up, write_cryptomatte, write_passes

# The tracer (engine: kernels compiled by Numba, Embree through its C API) and the export
# are imported by the first DRT render, not when Blender registers the add-on: a Blender
# that renders with Cycles, or opens no file, pays nothing for DRT (principle 3;
# tests/test_addon.py).

# What the last render did, for the batch renderer and tests (Blender's operator says
# FINISHED even when an engine reported an error). "scene" is the exported description,
# "passes" the extra passes written (top-down float arrays by pass name).
last_render = {"ok": None, "error": None, "warnings": [], "stats": None, "pixels": None,
               "scene": None, "export_stats": None, "passes": {}, "region": None,
               "cancelled_in": None, "phase": None}
# Callables told (samples done, samples asked) after every progressive pass (the batch
# renderer's progress bar).
progress_listeners: list = []
# Callables told (kernels compiled, kernels reachable) while a first render compiles.
compile_listeners: list = []


def compile_line(done: int, total: int) -> str:
    """What a render says while Numba compiles its kernels (once per machine and DRT
    version: they are cached on disk)."""
    return f"compiling kernels, one time: {done} of {total}"


class RenderCancelled(Exception):
    """The user cancelled the render before tracing began (the message: the phase)."""


class DRTViewLayerSettings(bpy.types.PropertyGroup):
    use_pass_denoising_data: BoolProperty(
        name="Denoising Data", default=False,
        description="Write Denoising Normal and Denoising Albedo passes, the inputs of the "
                    "compositor's Denoise node")
    use_pass_noise: BoolProperty(
        name="Noise Estimate", default=False,
        description="Write the 'DRT Noise' pass: per pixel, the standard error of the mean "
                    "radiance (how far the pixel may be from the converged value)")


def _clock(seconds: float) -> str:
    """Blender's time format in its render log: MM:SS.hh."""
    m, sec = divmod(max(seconds, 0.0), 60.0)
    return f"{int(m):02d}:{sec:05.2f}"


def _threads_label(threads: int) -> str:
    """The engine's thread count as the background log shows it (0: the engine's default)."""
    if not threads:
        return "all cores"
    return f"{threads} thread" + ("s" if threads > 1 else "")


PREVIEW_SAMPLES = 16


def preview_settings(settings):
    """Material previews trade noise for speed: at most PREVIEW_SAMPLES samples and
    Cycles' preview-like light paths; everything else as the scene says."""
    from dataclasses import replace
    return replace(settings, samples=min(settings.samples, PREVIEW_SAMPLES),
                   max_bounces=min(settings.max_bounces, 4))


class DRTRenderEngine(bpy.types.RenderEngine):
    bl_idname = "DRT"
    bl_label = "DRT"
    bl_use_preview = True                 # material previews render with DRT
    bl_use_postprocess = True
    bl_use_shading_nodes_custom = False   # keep Cycles' shader nodes editable
    bl_use_eevee_viewport = True          # Material Preview uses EEVEE; Rendered, DRT

    @classmethod
    def register(cls):
        bpy.utils.register_class(DRTViewLayerSettings)
        bpy.types.ViewLayer.drt = PointerProperty(type=DRTViewLayerSettings)

    @classmethod
    def unregister(cls):
        del bpy.types.ViewLayer.drt
        bpy.utils.unregister_class(DRTViewLayerSettings)

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)  # required since Blender 4.4
        self.viewport = None               # drt_addon.viewport.ViewportSession

    def __del__(self):
        # Blender invalidates the engine before deleting it: its own attribute lookup
        # would raise, the instance's dictionary still holds the session
        try:
            viewport = object.__getattribute__(self, "viewport")
        except (AttributeError, ReferenceError):
            return
        if viewport is not None:
            viewport.free()

    # -- the Rendered viewport (drt_addon.viewport) --
    def view_update(self, context, depsgraph):
        from .export import ExportError, Reporter
        try:
            if self.viewport is None:
                from .viewport import ViewportSession
                self.viewport = ViewportSession(self._tag_redraw)
            self.viewport.sync(depsgraph, context, Reporter(self.report))
        except (ExportError, ValueError) as e:
            self.update_stats("", f"DRT: {e}")
            self.report({"ERROR"}, str(e))
        except Exception as e:      # never into Blender's event loop: said, and printed
            traceback.print_exc()
            self.update_stats("", f"DRT viewport: {type(e).__name__}: {e}")
            self.report({"ERROR"}, f"DRT viewport: {type(e).__name__}: {e}")

    def view_draw(self, context, depsgraph):
        if self.viewport is None:
            return
        try:
            self.viewport.draw(context, depsgraph, self)
            self.update_stats("", self.viewport.status())
        except Exception as e:
            if self.viewport.error is None:        # said once, not at every redraw
                traceback.print_exc()
                self.viewport.error = f"DRT viewport: {type(e).__name__}: {e}"
                self.report({"ERROR"}, self.viewport.error)
            self.update_stats("", self.viewport.error)

    def _tag_redraw(self):
        try:
            self.tag_redraw()
        except ReferenceError:             # the engine was freed while a pass finished
            pass

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for name in enabled_passes(renderlayer):
            channels, chan_id, kind, _ = PASSES[name]
            self.register_pass(scene, renderlayer, name, channels, chan_id, kind)
        if denoise.wanted(scene, renderlayer):
            self.register_pass(scene, renderlayer, denoise.NOISY_PASS, 4, "RGBA", "COLOR")
        for names in cryptomatte_passes(renderlayer).values():
            for name in names:
                self.register_pass(scene, renderlayer, name, 4, "RGBA", "COLOR")
        for name, channels, chan_id, kind in shader_aov_passes(renderlayer):
            self.register_pass(scene, renderlayer, name, channels, chan_id, kind)
        for name in light_passes.enabled(renderlayer) + light_passes.group_passes(renderlayer):
            self.register_pass(scene, renderlayer, name, 3, "RGB", "COLOR")

    def render(self, depsgraph):
        from .export import ExportError
        last_render.update(ok=False, error=None, warnings=[], stats=None, pixels=None,
                           scene=None, export_stats=None, passes={}, region=None, progress=[],
                           cancelled_in=None, phase=None, compile_said=None, metadata={})
        try:
            self._render(depsgraph)
        except RenderCancelled as e:
            last_render.update(ok=False, error="cancelled", cancelled_in=str(e))
            self.update_stats("", "DRT: cancelled")
        except ExportError as e:
            self._fail(str(e))
        except Exception as e:  # never let an exception escape into Blender
            # the traceback is for bug reports: on Blender's console, not in the batch
            # renderer's stderr (one line there; DRT_TRACEBACK=1 shows it)
            last_render["traceback"] = traceback.format_exc()
            if not bpy.app.background or os.environ.get("DRT_TRACEBACK"):
                traceback.print_exc()
            self._fail(f"DRT: render failed: {type(e).__name__}: {e}")

    def _cancel_requested(self) -> bool:
        """Esc in Blender (polled before each object of the export, before and after the
        acceleration structure, between work units of the tracing and before the extra
        passes, so a cancel lands within one of those steps)."""
        return self.test_break()

    def _polled(self, phase: str) -> bool:
        """Whether the user cancelled, asked during `phase` (kept in last_render["phase"]:
        'export', 'acceleration structure', 'tracing' or 'passes')."""
        last_render["phase"] = phase
        return self._cancel_requested()

    def _check_cancel(self, phase: str) -> None:
        """Stop the render here (raises RenderCancelled) if the user cancelled it."""
        if self._polled(phase):
            raise RenderCancelled(phase)

    def bake(self, depsgraph, obj, pass_type, pass_filter, width, height):
        """Blender's bake operator, with DRT as the render engine (drt_addon.bake)."""
        from .bake import BakeError, bake
        from .export import ExportError, Reporter
        try:
            bake(self, depsgraph, obj, pass_type, pass_filter, width, height,
                 Reporter(self.report))
        except (BakeError, ExportError) as e:
            self.report({"ERROR"}, str(e))
            raise

    def _fail(self, message):
        last_render.update(ok=False, error=message)
        self.report({"ERROR"}, message)
        self.update_stats("", message)

    def _render(self, depsgraph):
        t0 = time.perf_counter()
        from .engine_link import engine           # the first render of a process loads them
        from .export import BLACK_IMAGE, ExportError, Reporter, export_scene, render_region
        from .export.layer_overrides import render_world
        last_render["import_seconds"] = time.perf_counter() - t0
        scene = depsgraph.scene
        view_layer = depsgraph.view_layer
        region = render_region(scene)
        # Material previews: quick, and silent (their scene is Blender's, not the user's).
        reporter = Reporter(None if self.is_preview else self.report)
        self.update_stats("", "DRT: exporting scene")
        last_render["first_sample_seconds"] = None
        export_stats = {}
        description = export_scene(depsgraph, reporter, region=region, stats=export_stats,
                                   render_engine=self,
                                   check_cancel=lambda: self._check_cancel("export"))
        settings = scene.drt.to_engine_settings()
        if self.is_preview:
            settings = preview_settings(settings)
            description.light_groups = ()
        else:
            # the path tracer splits its light only when a light pass or Environment is
            # asked for
            settings.light_passes = light_passes.splits(view_layer)
        try:
            settings.validate()
        except ValueError as e:
            raise ExportError(f"DRT: invalid render settings: {e}") from e
        export_seconds = time.perf_counter() - t0 - last_render["import_seconds"]
        last_render.update(scene=description, export_stats=export_stats, region=region)
        self._check_cancel("export")
        self.update_stats("", "DRT: building acceleration structure")
        t_build = time.perf_counter()
        ctx = engine.RenderContext(description, settings)
        last_render["build_seconds"] = time.perf_counter() - t_build
        try:
            self._check_cancel("acceleration structure")
        except RenderCancelled:
            ctx.close()
            raise
        result = self.begin_result(0, 0, region.width, region.height, layer=view_layer.name)
        layer = result.layers[0]
        combined = layer.passes["Combined"]
        image = alpha = None
        try:
            def progress(film, stats, fraction):
                if last_render.get("first_sample_seconds") is None:
                    # depsgraph to first sample: export, BVH build, first pass
                    last_render["first_sample_seconds"] = time.perf_counter() - t0
                set_pass_pixels(combined, rgba_bottom_up(*shadow_catcher.combined(
                    ctx, film, view_layer)))
                self.update_result(result)
                self.update_progress(fraction)
                last_render["progress"].append((stats.samples_done, fraction))
                for listener in progress_listeners:
                    listener(stats.samples_done, settings.samples)
                rate = stats.paths_per_second()
                # the estimate leaves out a first render's one-time kernel compile
                left = stats.sampling_seconds() * (1 - fraction) / max(fraction, 1e-9)
                n_pixels = description.width * description.height
                line = (f"DRT | {stats.status(settings.samples, n_pixels)} | "
                        f"{rate / 1e3:.0f}k paths/s | {left:.0f} s left")
                self.update_stats("", line)
                if bpy.app.background:
                    # the line render-farm managers parse (Deadline: `Sample ([0-9]+)/([0-9]+)`)
                    print(f"Fra:{scene.frame_current} | Time:{_clock(time.perf_counter() - t0)}"
                          f" | {line} | {_threads_label(settings.threads)}", flush=True)

            def compiling(done, total):
                line = compile_line(done, total)
                self.update_stats("", f"DRT | {line}")
                for listener in compile_listeners:
                    try:
                        listener(done, total)
                    except Exception as e:      # a progress display never fails a render
                        print(f"DRT: compile progress listener failed: {e!r}",
                              file=sys.stderr)
                if bpy.app.background and last_render.get("compile_said") != done:
                    last_render["compile_said"] = done
                    print(f"Fra:{scene.frame_current} | Time:{_clock(time.perf_counter() - t0)}"
                          f" | DRT | {line}", flush=True)

            film, stats = engine.render(description, settings, context=ctx, progress=progress,
                                        cancelled=lambda: self._polled("tracing"),
                                        compiling=compiling)
            image, alpha = shadow_catcher.combined(ctx, film, view_layer)
            first_hit = FirstHit(ctx, render_world(scene, view_layer), description,
                                 ambient_occlusion=AO_PASS in enabled_passes(view_layer),
                                 aovs=shader_aov_passes(view_layer))
            if not stats.cancelled and denoise.wanted(scene, view_layer):
                self.update_stats("", "DRT: denoising")
                clean = denoise.denoised(scene, image, first_hit, reporter)
                if clean is not None:
                    noisy, image = image, clean.astype(np.float64)
                    if layer.passes.get(denoise.NOISY_PASS) is not None:
                        set_pass_pixels(layer.passes[denoise.NOISY_PASS],
                                        rgba_bottom_up(noisy, alpha))
                    last_render["passes"][denoise.NOISY_PASS] = noisy
            set_pass_pixels(combined, rgba_bottom_up(image, alpha))
            extra = (enabled_passes(view_layer) or cryptomatte_passes(view_layer)
                     or shader_aov_passes(view_layer) or light_passes.enabled(view_layer)
                     or light_passes.group_passes(view_layer))
            if not stats.cancelled and extra and self._polled("passes"):
                stats.cancelled = True             # cancelled before the extra passes
                last_render["cancelled_in"] = "passes"
            elif stats.cancelled:
                last_render["cancelled_in"] = "tracing"
            if not stats.cancelled:
                write_passes(self, layer, ctx, film, view_layer, description, first_hit,
                             lambda: vector_pass(self, depsgraph, settings, region),
                             last_render)
                write_cryptomatte(self, result, layer, ctx, view_layer, last_render)
        finally:
            ctx.close()
            self.end_result(result)
        held_out = description.film_transparent or description.has_holdouts()
        if not stats.cancelled and not np.any(image) and not held_out:
            reporter.warn("DRT: the image is black: no light from the scene reaches the "
                          "camera (check where the camera looks, its clipping range, and "
                          "the lights)", key=BLACK_IMAGE)
        if stats.nonfinite_samples:
            reporter.warn(f"DRT: {stats.nonfinite_samples} samples were NaN or infinite and "
                          "were dropped")
        last_render.update(ok=not stats.cancelled, error="cancelled" if stats.cancelled else None,
                           warnings=reporter.warnings, stats=stats, pixels=image,
                           alpha=alpha, export_seconds=export_seconds)
