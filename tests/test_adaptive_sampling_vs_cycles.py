"""Adaptive sampling stops pixels where Cycles stops them: the first convergence check
after (Min Samples + 1) | 15 + 1 samples (Cycles' render scheduler), then one every 16
samples, and the same pixels stopping at the first check. Cycles' samples per pixel come
from its Debug Sample Count pass (cycles_sample_count); DRT's are its film's counts.

The scene is tests/test_adaptive_sampling.py's uneven one as a .blend (uneven_noise_blend).
"""
from __future__ import annotations

import numpy as np
import pytest

from cycles_sample_count import counts_from_shares, cycles_sample_counts
from uneven_noise_blend import open_uneven

SIZE, SAMPLES, THRESHOLD = 32, 512, 0.01      # Cycles' default Noise Threshold


def _uneven(bpy):
    scene = open_uneven(bpy)
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    return scene


def _cycles_counts(bpy, scene):
    c = scene.cycles
    scene.render.engine = "CYCLES"
    c.device, c.samples, c.seed, c.use_denoising = "CPU", SAMPLES, 1, False
    c.use_adaptive_sampling, c.adaptive_threshold, c.adaptive_min_samples = True, THRESHOLD, 0
    return cycles_sample_counts(bpy, scene)


def _drt_counts(bpy, scene):
    from drt_addon.export import export_scene
    from engine import render
    d = scene.drt
    d.samples, d.seed, d.use_adaptive_sampling = SAMPLES, 1, True
    d.adaptive_threshold, d.adaptive_min_samples = THRESHOLD, 0
    film, _ = render(export_scene(bpy.context.evaluated_depsgraph_get(), size=(SIZE, SIZE)),
                     d.to_engine_settings())
    return film.count.reshape(SIZE, SIZE)


def test_pixels_stop_on_cycles_checks(bpy_drt):
    """At Cycles' default Noise Threshold (0.01, Min Samples 64). Measured: both
    engines' fewest samples 80, every count on the lattice 80 + 16 k; the share of pixels
    stopping at the first check (the world around the box), DRT 0.903 and Cycles 0.902;
    mean samples 108.5 and 107.1. Before DRT followed Cycles' scheduler its first check
    came at 64 samples, and its passes grew when few pixels were left (at threshold
    0.02 all 65 pixels left went on to 320)."""
    scene = _uneven(bpy_drt)
    cycles = _cycles_counts(bpy_drt, scene)
    drt = _drt_counts(bpy_drt, _uneven(bpy_drt))
    first = 80                                  # Min Samples 64: (64 + 1) | 15 + 1
    for counts in (cycles, drt):
        assert counts.min() == first, counts.min()
        on = (counts == SAMPLES) | ((counts - first) % 16 == 0)
        assert on.all(), np.unique(counts[~on])
        assert counts.max() > 2 * first           # the box goes on
    share = {name: float((c == first).mean()) for name, c in (("DRT", drt), ("Cycles", cycles))}
    print(f"share stopping at {first}: {share}; mean samples DRT {drt.mean():.1f}, "
          f"Cycles {cycles.mean():.1f}")
    assert abs(share["DRT"] - share["Cycles"]) < 0.08, share
    assert abs(drt.mean() / cycles.mean() - 1.0) < 0.08, (drt.mean(), cycles.mean())


def test_counts_follow_from_the_shares_of_the_samples_taken():
    """The helper's own check, without Blender: counts 64..288 on the schedule of a render
    that ended at 288 of 512 come back from their shares; a set that fits two ends (all
    counts even multiples of the step) is refused, not guessed."""
    counts = np.array([64, 64, 80, 96, 144, 288])
    share = (counts / 288).astype(np.float32)
    assert np.array_equal(counts_from_shares(share, 64, 512), counts)
    ended = np.array([64, 112, 512])
    assert np.array_equal(counts_from_shares((ended / 512).astype(np.float32), 64, 512),
                          ended)
    with pytest.raises(ValueError):
        counts_from_shares(np.array([0.5, 1.0], np.float32), 64, 512)   # 128/256 or 256/512
