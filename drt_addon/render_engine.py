"""The RenderEngine Blender selects as 'DRT' (F12, `blender -b file.blend -E DRT -f 1`)."""
from __future__ import annotations

import time
import traceback

import bpy
import numpy as np

from .engine_link import engine
from .export import ExportError, Reporter, export_scene, render_size

# What the last render did, for the batch renderer (Blender's operator says FINISHED even
# when an engine reported an error).
last_render = {"ok": None, "error": None, "warnings": [], "stats": None, "pixels": None}


def _rgba_bottom_up(image: np.ndarray) -> np.ndarray:
    """(h, w, 3) top-down float image to Blender's flat bottom-up RGBA float32."""
    h, w, _ = image.shape
    out = np.empty((h, w, 4), dtype=np.float32)
    out[..., :3] = image[::-1]
    out[..., 3] = 1.0
    return out.reshape(-1)


class DRTRenderEngine(bpy.types.RenderEngine):
    bl_idname = "DRT"
    bl_label = "DRT"
    bl_use_preview = False
    bl_use_postprocess = True
    bl_use_shading_nodes_custom = False   # keep Cycles' shader nodes editable
    bl_use_eevee_viewport = True          # Material Preview and viewport use EEVEE

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)  # required since Blender 4.4

    def render(self, depsgraph):
        last_render.update(ok=False, error=None, warnings=[], stats=None, pixels=None)
        try:
            self._render(depsgraph)
        except ExportError as e:
            self._fail(str(e))
        except Exception as e:  # never let an exception escape into Blender
            traceback.print_exc()
            self._fail(f"DRT: render failed: {type(e).__name__}: {e}")

    def _fail(self, message):
        last_render.update(ok=False, error=message)
        self.report({"ERROR"}, message)
        self.update_stats("", message)

    def _render(self, depsgraph):
        scene = depsgraph.scene
        width, height = render_size(scene)
        reporter = Reporter(self.report)
        self.update_stats("", "DRT: exporting scene")
        t0 = time.perf_counter()
        description = export_scene(depsgraph, reporter, size=(width, height))
        settings = scene.drt.to_engine_settings()
        try:
            settings.validate()
        except ValueError as e:
            raise ExportError(f"DRT: invalid render settings: {e}") from e
        export_seconds = time.perf_counter() - t0
        self.update_stats("", "DRT: building acceleration structure")
        ctx = engine.RenderContext(description, settings)
        result = self.begin_result(0, 0, width, height)
        combined = result.layers[0].passes["Combined"]
        try:
            def progress(film, stats, fraction):
                combined.rect.foreach_set(_rgba_bottom_up(film.mean()))
                self.update_result(result)
                self.update_progress(fraction)
                rate = stats.paths_per_second()
                left = stats.seconds * (1 - fraction) / max(fraction, 1e-9)
                self.update_stats("", f"DRT | Sample {stats.samples_done}/{settings.samples} | "
                                      f"{rate / 1e3:.0f}k paths/s | {left:.0f} s left")

            film, stats = engine.render(description, settings, context=ctx, progress=progress,
                                        cancelled=self.test_break)
            image = film.mean()
            combined.rect.foreach_set(_rgba_bottom_up(image))
        finally:
            ctx.close()
            self.end_result(result)
        if stats.nonfinite_samples:
            reporter.warn(f"DRT: {stats.nonfinite_samples} samples were NaN or infinite and "
                          "were dropped")
        last_render.update(ok=not stats.cancelled, error="cancelled" if stats.cancelled else None,
                           warnings=reporter.warnings, stats=stats, pixels=image,
                           export_seconds=export_seconds)
