"""Render > Denoise in DRT, as Cycles does it (drt_addon/denoise.py, engine/denoiser.py).

The Cornell box (sample_blends/cornell_box.blend, 64 x 64 pixels) at 16 samples per
pixel, denoised by each engine with Cycles' default settings (OpenImageDenoise, albedo and
normal, Accurate prefilter, High quality), against a reference: Cycles at 1024 samples,
not denoised.

- DRT's denoised image agrees with Cycles' denoised one: means within 3% per channel
  (measured -0.9/-1.5/-1.8%; at 16 samples the noisy means themselves are off the
  reference's by up to 1.0% in DRT and 0.3% in Cycles, and denoising moves them by up to
  0.8% more), and pixel by pixel: relMSE 0.0039, against 0.026 for DRT's noisy image
  (the control), which must be at least 4 times larger.
- Measured against the reference: relMSE of DRT 0.0232 noisy, 0.0031 denoised (7.4x
  less); Cycles 0.0298 noisy, 0.0035 denoised (8.6x).
- DRT's denoiser takes DRT's noise away about as well as Cycles' takes Cycles' away: the
  relMSE to the reference falls by at least half of the factor Cycles' falls by.
- The noisy render is kept as the "Noisy Image" pass, which reaches the compositor, and
  equals the same render made with Denoise off.
- The view layer's Denoising switch, the input passes, prefilter and quality reach the
  denoiser; OptiX is denoised with OpenImageDenoise and says so; without the binding the
  render stays noisy and says why.
"""
from __future__ import annotations

import os

import numpy as np
import pytest

from conftest import SAMPLES_DIR, render_current, use_engine
from test_passes import composite

CORNELL = os.path.join(SAMPLES_DIR, "cornell_box.blend")
SAMPLES = 16
REFERENCE_SAMPLES = 1024
PERCENT = 25                    # of the file's 256 x 256

_renders = {}


def _open(bpy, engine, samples, denoise=True):
    bpy.ops.wm.open_mainfile(filepath=CORNELL, load_ui=False)
    scene = bpy.context.scene
    scene.render.resolution_percentage = PERCENT
    use_engine(scene, engine, samples)
    scene.cycles.use_denoising = denoise
    return scene


def _render(bpy, engine, samples, denoise=True):
    key = (engine, samples, denoise)
    if key not in _renders:
        scene = _open(bpy, engine, samples, denoise)
        _renders[key] = render_current(bpy, scene)
        if engine == "DRT":
            from drt_addon import render_engine
            passes = render_engine.last_render["passes"]
            _renders[key + ("noisy",)] = passes.get("Noisy Image")
    return _renders[key]


def _rel_mse(a, ref):
    return float(np.mean((a - ref) ** 2 / (ref ** 2 + 0.01)))


def test_denoised_drt_matches_denoised_cycles(bpy_drt):
    drt = _render(bpy_drt, "DRT", SAMPLES)
    noisy = _renders[("DRT", SAMPLES, True, "noisy")]
    cycles = _render(bpy_drt, "CYCLES", SAMPLES)
    assert noisy is not None and not np.allclose(noisy, drt)
    rel = drt.mean(axis=(0, 1)) / cycles.mean(axis=(0, 1)) - 1
    assert np.abs(rel).max() < 0.03, rel
    agree, control = _rel_mse(drt, cycles), _rel_mse(noisy, cycles)
    assert agree < 0.25 * control, (agree, control)


def test_drt_denoises_its_noise_about_as_well_as_cycles_does(bpy_drt):
    ref = _render(bpy_drt, "CYCLES", REFERENCE_SAMPLES, denoise=False)
    drt = _render(bpy_drt, "DRT", SAMPLES)
    drt_noisy = _renders[("DRT", SAMPLES, True, "noisy")]
    cycles = _render(bpy_drt, "CYCLES", SAMPLES)
    cycles_noisy = _render(bpy_drt, "CYCLES", SAMPLES, denoise=False)
    drt_gain = _rel_mse(drt_noisy, ref) / _rel_mse(drt, ref)
    cycles_gain = _rel_mse(cycles_noisy, ref) / _rel_mse(cycles, ref)
    assert drt_gain > 2 and drt_gain > 0.5 * cycles_gain, (drt_gain, cycles_gain)


def test_noisy_image_pass_is_the_render_without_denoise_and_reaches_the_compositor(bpy_drt):
    bpy = bpy_drt
    from drt_addon import render_engine
    off = _render(bpy, "DRT", SAMPLES, denoise=False)
    assert "Noisy Image" not in render_engine.last_render["passes"]
    scene = _open(bpy, "DRT", SAMPLES)
    composite(bpy, scene, "Noisy Image")
    through_compositor = render_current(bpy, scene)
    np.testing.assert_allclose(through_compositor, off, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(render_engine.last_render["passes"]["Noisy Image"], off,
                               rtol=1e-5, atol=1e-6)


@pytest.fixture
def recorded(bpy_drt, monkeypatch):
    """engine.denoiser.denoise, recording the settings of each call."""
    from drt_addon.engine_link import engine
    import importlib
    denoiser = importlib.import_module(engine.__name__ + ".denoiser")
    calls = []
    original = denoiser.denoise

    def denoise(color, albedo=None, normal=None, settings=denoiser.DenoiseSettings()):
        calls.append((settings, albedo is not None, normal is not None))
        return original(color, albedo, normal, settings)
    monkeypatch.setattr(denoiser, "denoise", denoise)
    return denoiser, calls


def test_the_files_denoise_settings_reach_the_denoiser(bpy_drt, recorded):
    bpy = bpy_drt
    from drt_addon import render_engine
    denoiser, calls = recorded
    scene = _open(bpy, "DRT", 4)
    scene.render.resolution_percentage = 10
    c = scene.cycles
    c.denoising_input_passes, c.denoising_prefilter = "RGB_ALBEDO", "FAST"
    c.denoising_quality = "BALANCED"
    render_current(bpy, scene)
    assert calls == [(denoiser.DenoiseSettings("RGB_ALBEDO", "FAST", "BALANCED"), True, False)]
    c.denoising_input_passes = "RGB"
    render_current(bpy, scene)
    assert calls[-1] == (denoiser.DenoiseSettings("RGB", "FAST", "BALANCED"), False, False)
    scene.view_layers[0].cycles.use_denoising = False       # View Layer > Denoising
    render_current(bpy, scene)
    assert len(calls) == 2 and "Noisy Image" not in render_engine.last_render["passes"]


def test_optix_is_denoised_with_oidn_and_a_missing_binding_keeps_the_render_noisy(
        bpy_drt, recorded, monkeypatch):
    """OptiX (offered only where an NVIDIA GPU is) is denoised with OpenImageDenoise, with
    a warning; checked on drt_addon.denoise itself, since this Blender has no OptiX to
    choose. Without the binding a render stays noisy and says why."""
    bpy = bpy_drt
    from types import SimpleNamespace
    from drt_addon import denoise, render_engine
    from drt_addon.export import Reporter
    denoiser, calls = recorded
    cycles = SimpleNamespace(denoiser="OPTIX", denoising_input_passes="RGB",
                             denoising_prefilter="ACCURATE", denoising_quality="HIGH")
    reporter = Reporter()
    image = np.random.default_rng(1).random((8, 8, 3))
    out = denoise.denoised(SimpleNamespace(cycles=cycles), image, None, reporter)
    assert out.shape == (8, 8, 3) and len(calls) == 1
    assert any("OptiX" in w for w in reporter.warnings)

    scene = _open(bpy, "DRT", 4)
    scene.render.resolution_percentage = 10
    monkeypatch.setattr(denoiser, "available", lambda: "no OpenImageDenoise here (test)")
    image = render_current(bpy, scene)
    warnings = render_engine.last_render["warnings"]
    assert any("not denoised: no OpenImageDenoise here (test)" in w for w in warnings)
    assert "Noisy Image" not in render_engine.last_render["passes"] and len(calls) == 1
    np.testing.assert_allclose(image, render_engine.last_render["pixels"], rtol=1e-5,
                               atol=1e-6)


def test_an_oidn_failure_keeps_the_render_noisy_and_says_so(bpy_drt, monkeypatch):
    bpy = bpy_drt
    import importlib
    from drt_addon import render_engine
    from drt_addon.engine_link import engine
    denoiser = importlib.import_module(engine.__name__ + ".denoiser")

    def fails(*args, **kwargs):
        raise RuntimeError("OpenImageDenoise failed: out of memory (test)")
    monkeypatch.setattr(denoiser, "denoise", fails)
    scene = _open(bpy, "DRT", 4)
    scene.render.resolution_percentage = 10
    image = render_current(bpy, scene)
    last = render_engine.last_render
    assert last["ok"], last["error"]
    assert any("not denoised: OpenImageDenoise failed: out of memory (test)" in w
               for w in last["warnings"]), last["warnings"]
    assert "Noisy Image" not in last["passes"]
    np.testing.assert_allclose(image, last["pixels"], rtol=1e-5, atol=1e-6)
