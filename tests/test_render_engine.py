"""The RenderEngine inside Blender: progressive passes with progress, cancel that stops
within one work unit and leaves a valid partial image, and the error path."""
import os

import numpy as np
import pytest

from conftest import SAMPLES_DIR

CORNELL = os.path.join(SAMPLES_DIR, "cornell_box.blend")


def _open(bpy, samples=64, percentage=25):
    bpy.ops.wm.open_mainfile(filepath=CORNELL, load_ui=False)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    scene.render.resolution_percentage = percentage
    scene.drt.samples = samples
    return scene


def test_render_is_progressive_with_monotonic_progress(bpy_drt):
    from drt_addon.render_engine import last_render
    _open(bpy_drt, samples=64)
    bpy_drt.ops.render.render()
    assert last_render["ok"]
    progress = last_render["progress"]
    samples = [s for s, _ in progress]
    fractions = [f for _, f in progress]
    assert len(progress) >= 5                       # several passes, each shown
    assert samples == sorted(samples) and samples[-1] == 64
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    assert samples[0] == 1                          # a first image after one sample


def test_cancel_stops_within_one_work_unit_and_keeps_a_valid_image(bpy_drt):
    from drt_addon.render_engine import DRTRenderEngine, last_render
    scene = _open(bpy_drt, samples=4096, percentage=50)
    scene.drt.threads = 2
    polls = []

    def cancel_after_a_few_polls(self):
        if last_render["phase"] == "tracing":
            polls.append(1)
        return len(polls) > 6

    original = DRTRenderEngine._cancel_requested
    DRTRenderEngine._cancel_requested = cancel_after_a_few_polls
    try:
        bpy_drt.ops.render.render()
    finally:
        DRTRenderEngine._cancel_requested = original
    stats = last_render["stats"]
    assert stats.cancelled and last_render["error"] == "cancelled"
    assert stats.units_running_at_cancel <= 2       # only units already running finish
    img = last_render["pixels"]
    assert img is not None and np.isfinite(img).all() and img.max() > 0
    assert stats.paths < 128 * 128 * 4096 / 10     # it really stopped early
    # Blender stays usable: the next render works.
    _open(bpy_drt, samples=2)
    bpy_drt.ops.render.render()
    assert last_render["ok"]


def test_extreme_but_legal_settings_render(bpy_drt):
    from drt_addon.render_engine import last_render
    scene = _open(bpy_drt, samples=2)
    scene.cycles.filter_width = 0.01
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.max_bounces = 0
    bpy_drt.ops.render.render()
    assert last_render["ok"]
    assert np.isfinite(last_render["pixels"]).all()


def test_no_camera_is_refused_with_a_clear_error(bpy_drt):
    import pytest
    bpy_drt.ops.wm.read_factory_settings(use_empty=True)
    bpy_drt.context.scene.render.engine = "DRT"
    with pytest.raises(RuntimeError, match="camera"):   # Blender refuses before DRT runs
        bpy_drt.ops.render.render()


def test_material_previews_are_rendered_by_drt_quickly(bpy_drt):
    """Blender draws material previews with an engine whose bl_use_preview is set; the
    preview render itself only runs with a UI, so this checks the contract and the
    preview settings (the bpy module renders no previews in background mode)."""
    from drt_addon.render_engine import PREVIEW_SAMPLES, DRTRenderEngine, preview_settings
    from drt_addon.engine_link import engine
    assert DRTRenderEngine.bl_use_preview is True
    s = preview_settings(engine.RenderSettings(samples=4096, max_bounces=12, seed=7))
    assert s.samples == PREVIEW_SAMPLES and s.max_bounces == 4 and s.seed == 7
    assert preview_settings(engine.RenderSettings(samples=4)).samples == 4


def test_noise_threshold_and_time_limit_reach_the_engine(bpy_drt):
    """DRT's Sampling panel settings: with a Noise Threshold the render stops pixels
    early (fewer samples than Max Samples over the frame, progress ends at 1), and the
    stats line says how many pixels converged."""
    from drt_addon.render_engine import last_render
    scene = _open(bpy_drt, samples=512, percentage=12)
    scene.drt.use_adaptive_sampling = True
    scene.drt.adaptive_threshold = 0.1
    settings = scene.drt.to_engine_settings()
    assert settings.adaptive_sampling and settings.adaptive_threshold == pytest.approx(0.1)
    bpy_drt.ops.render.render()
    assert last_render["ok"]
    stats = last_render["stats"]
    n = last_render["pixels"].shape[0] * last_render["pixels"].shape[1]
    assert 32 * n <= stats.pixel_samples < 512 * n * 0.5
    assert stats.active_pixels >= 0 and "converged" in stats.status(512, n)
    assert last_render["progress"][-1][1] == 1.0
    assert not any("Jittered" in w for w in last_render["warnings"])   # it suits Jittered
    scene.drt.use_adaptive_sampling = False
    scene.drt.time_limit = 0.5
    assert scene.drt.to_engine_settings().time_limit == pytest.approx(0.5)


def test_blender_fixed_threads_reach_the_engine_when_drt_threads_is_0(bpy_drt):
    """Blender's Performance > Threads set to Fixed (what `blender -t N` reports, as
    render farms start Blender) gives the engine that many threads when DRT's own
    Threads is 0; DRT's own setting wins when set; Auto leaves the engine's default."""
    scene = _open(bpy_drt, samples=1)
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 3
    scene.drt.threads = 0
    assert scene.drt.to_engine_settings().threads == 3
    scene.drt.threads = 2
    assert scene.drt.to_engine_settings().threads == 2
    scene.render.threads_mode = "AUTO"
    scene.drt.threads = 0
    assert scene.drt.to_engine_settings().threads == 0
