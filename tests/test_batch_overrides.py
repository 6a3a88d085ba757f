"""Command-line overrides (drt_addon/overrides.py): set in memory on DRT's settings and,
for Cycles reference renders, on Cycles'; the seed, which both engines read from the
file's Cycles settings, on Cycles' whatever the engine; an override the running engine
has no setting for is reported, not dropped silently; the .blend on disk is never
written."""
from types import SimpleNamespace

import pytest

from drt_addon.overrides import Overrides, apply_overrides


def fake_scene(adaptive: bool):
    """A scene shaped like bpy's: render settings, DRT's and Cycles' property groups
    (DRT with or without adaptive sampling and a time limit)."""
    drt = SimpleNamespace(samples=64)
    if adaptive:
        drt.__dict__.update(use_adaptive_sampling=False, adaptive_threshold=0.01,
                            adaptive_min_samples=0, time_limit=0.0)
    cycles = SimpleNamespace(samples=4096, seed=0, use_adaptive_sampling=False,
                             adaptive_threshold=0.01, adaptive_min_samples=0, time_limit=0.0)
    return SimpleNamespace(render=SimpleNamespace(engine="CYCLES", resolution_percentage=100),
                           drt=drt, cycles=cycles)


def test_every_override_lands_on_drt():
    scene = fake_scene(adaptive=True)
    missing = apply_overrides(scene, Overrides(samples=16, seed=3, percentage=25,
                                               noise_threshold=0.05, min_samples=8,
                                               time_limit=30.0))
    assert missing == []
    assert scene.render.engine == "DRT" and scene.render.resolution_percentage == 25
    d = scene.drt
    assert (d.samples, d.adaptive_min_samples, d.time_limit) == (16, 8, 30.0)
    assert d.use_adaptive_sampling is True and d.adaptive_threshold == 0.05
    assert scene.cycles.seed == 3                # the file's seed, which DRT reads
    assert scene.cycles.samples == 4096 and scene.cycles.use_adaptive_sampling is False


def test_cycles_overrides_set_cycles_too():
    scene = fake_scene(adaptive=False)
    missing = apply_overrides(scene, Overrides(engine="CYCLES", samples=8, seed=2,
                                               noise_threshold=0.1, time_limit=5.0))
    assert missing == []                         # Cycles has every setting
    c = scene.cycles
    assert (c.samples, c.seed, c.use_adaptive_sampling, c.adaptive_threshold,
            c.time_limit) == (8, 2, True, 0.1, 5.0)
    assert scene.drt.samples == 8


def test_a_drt_without_adaptive_sampling_says_what_was_not_applied():
    scene = fake_scene(adaptive=False)
    missing = apply_overrides(scene, Overrides(samples=2, noise_threshold=0.05,
                                               min_samples=4, time_limit=1.0))
    assert scene.drt.samples == 2
    assert len(missing) == 3
    assert any("--noise-threshold" in m for m in missing)
    assert any("--min-samples" in m for m in missing)
    assert any("--time-limit" in m for m in missing)
    assert not hasattr(scene.drt, "use_adaptive_sampling")


@pytest.mark.parametrize("bad, word", [
    (Overrides(samples=0), "--samples"), (Overrides(seed=-1), "--seed"),
    (Overrides(percentage=0), "--percentage"), (Overrides(noise_threshold=0.0), "--noise"),
    (Overrides(min_samples=-1), "--min-samples"), (Overrides(time_limit=-2.0), "--time"),
])
def test_out_of_range_values_are_refused(bad, word):
    assert len(bad.problems()) == 1 and word in bad.problems()[0]
    assert Overrides(samples=1, seed=0, noise_threshold=1e-4, time_limit=0).problems() == []


def test_overrides_on_a_real_scene(bpy_drt):
    """On Blender's own scene: Cycles' adaptive settings are real properties, and DRT's
    are set exactly when this DRT has them."""
    bpy = bpy_drt
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    missing = apply_overrides(scene, Overrides(engine="CYCLES", samples=5, seed=9,
                                               noise_threshold=0.2, min_samples=3,
                                               time_limit=7.0, percentage=40))
    c = scene.cycles
    assert (c.samples, c.seed, c.use_adaptive_sampling, c.adaptive_min_samples) == \
        (5, 9, True, 3)
    assert c.adaptive_threshold == pytest.approx(0.2) and c.time_limit == pytest.approx(7.0)
    assert scene.render.resolution_percentage == 40 and scene.render.engine == "CYCLES"
    assert missing == []
    missing = apply_overrides(scene, Overrides(noise_threshold=0.3, time_limit=2.0))
    has = hasattr(scene.drt, "adaptive_threshold")
    assert (len(missing) == 0) == has
    if has:
        assert scene.drt.use_adaptive_sampling and scene.drt.adaptive_threshold == \
            pytest.approx(0.3)
