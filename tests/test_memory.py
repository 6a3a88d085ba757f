"""Memory is bounded by the film and the work-unit size, never by samples x pixels; absurd
settings (1e6 samples at 1920 x 1080) are accepted, rendered pass by pass and cancel."""
import tracemalloc

from engine import RenderSettings
from engine_scenes import cornell_box
from memory_probe import CASES, bound, cancel_after, measure, traced_peak


def _peak_bytes(samples, chunk_paths=4096):
    settings = RenderSettings(samples=samples, chunk_paths=chunk_paths, threads=1)
    return traced_peak(cornell_box(48, 48), settings)[0]


def test_peak_memory_does_not_grow_with_samples():
    few, many = _peak_bytes(16), _peak_bytes(256)
    print(f"peak traced memory: {few / 1e6:.1f} MB at 16 spp, {many / 1e6:.1f} MB at 256 spp")
    # 16x the samples: the work grows 16-fold, the memory must not (allow 25% slack)
    assert many < 1.25 * few


def test_peak_memory_follows_the_chunk_size():
    small, large = _peak_bytes(8, chunk_paths=1024), _peak_bytes(8, chunk_paths=16384)
    assert large > 2 * small      # the chunk, not the image, is what memory scales with


def test_a_large_frame_with_a_small_chunk_stays_within_film_plus_chunk():
    _, w, h, samples, chunk, units = CASES[0]
    peak, stats = measure(w, h, samples, chunk, units)
    print(f"{w}x{h}, chunk {chunk}: peak traced {peak / 1e6:.1f} MB, bound "
          f"{bound(w, h, chunk) / 1e6:.1f} MB (film {96 * w * h / 1e6:.1f} MB)")
    assert stats.paths == w * h
    assert peak < bound(w, h, chunk)


def test_absurd_settings_render_progressively_and_cancel(bpy_drt):
    """1e6 samples at 1920 x 1080 (2e12 paths): accepted by DRT's Samples property, and
    rendered pass by pass; cancelled after two work units, memory held the film and a
    work unit, never samples x pixels."""
    bpy_drt.ops.wm.read_factory_settings(use_empty=True)
    bpy_drt.context.scene.drt.samples = 1_000_000           # within the property's range
    settings = bpy_drt.context.scene.drt.to_engine_settings()
    assert settings.samples == 1_000_000
    settings.threads, settings.chunk_paths = 1, 1 << 15
    settings.validate()
    w, h = 1920, 1080
    peak, stats = traced_peak(cornell_box(w, h), settings, cancelled=cancel_after(2))
    print(f"1e6 spp at {w}x{h}, cancelled after {stats.units_done} units: peak traced "
          f"{peak / 1e6:.1f} MB, bound {bound(w, h, settings.chunk_paths) / 1e6:.1f} MB")
    assert stats.cancelled and stats.units_done <= 3
    assert stats.paths <= 3 * settings.chunk_paths
    assert peak < bound(w, h, settings.chunk_paths)


def test_absurd_settings_in_blender_cancel_after_the_first_units(bpy_drt, monkeypatch):
    """The same through Blender's render (F12): the RenderEngine adds Blender's result
    buffers (the image as RGBA float32 and its float64 mean: 48 bytes per pixel)."""
    from hostile_cases import _scene
    from drt_addon.render_engine import DRTRenderEngine, last_render
    scene = _scene(bpy_drt)
    scene.render.resolution_x, scene.render.resolution_y = 1920, 1080
    scene.drt.samples = 1_000_000
    scene.drt.threads = 1
    polls = []

    def cancel_in_tracing(self):
        polls.append(last_render["phase"])
        return polls.count("tracing") > 2

    monkeypatch.setattr(DRTRenderEngine, "_cancel_requested", cancel_in_tracing)
    tracemalloc.start()
    try:
        bpy_drt.ops.render.render()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    stats = last_render["stats"]
    n = 1920 * 1080
    limit = bound(1920, 1080, 1 << 15) + 48 * n + 6e6
    print(f"F12, 1e6 spp at 1920x1080, cancelled after {stats.units_done} units: peak traced "
          f"{peak / 1e6:.1f} MB, bound {limit / 1e6:.1f} MB")
    assert last_render["cancelled_in"] == "tracing" and stats.samples_done == 0
    assert stats.paths <= 3 * (1 << 15)
    assert last_render["pixels"].shape == (1080, 1920, 3)
    assert peak < limit
