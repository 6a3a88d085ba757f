"""Scale and position invariance, judged by a per-pixel z-test (tests/extreme_checks.py).

The Cornell box (1 m light, direct and indirect light) at 24 x 24 pixels, 64 samples of
the 'random' sampler: the reference at seed 1, every variant at seed 2, so the two differ
by independent noise only. Criteria, from the unscaled scene against itself (measured:
97.7% of pixels |z| < 3, mean z -0.02): at least 95% of pixels |z| < 3 and |mean z| <
0.15. The same test on a 10% brighter light gives mean z +0.47, so it does see a
difference of that size."""
import copy

import numpy as np
import pytest

from engine import RenderSettings, render
from engine_scenes import cornell_box, scaled, translated
from extreme_checks import sane, z_test

SIZE, SAMPLES = 24, 64
PASS_RATE, MEAN_Z = 0.95, 0.15


def _render(scene, seed):
    film, stats = render(scene, RenderSettings(samples=SAMPLES, seed=seed, sampler="random"))
    assert not sane(film, stats), sane(film, stats)
    return film


@pytest.fixture(scope="module")
def reference():
    scene = cornell_box(SIZE, SIZE, light_size=1.0)
    return scene, _render(scene, seed=1)


def _check(film, ref, what):
    z = z_test(film, ref)
    print(f"{what}: {z}")
    assert z.pass_rate >= PASS_RATE, f"{what}: {z}"
    assert abs(z.mean_z) < MEAN_Z, f"{what}: {z}"


@pytest.mark.parametrize("s", [1e-3, 1.0, 1e2, 1e4])
def test_scaled_scene_renders_the_same_image(reference, s):
    """Geometry, camera, light sizes times s, light power times s^2 (same radiance)."""
    scene, ref = reference
    _check(_render(scaled(scene, s), seed=2), ref, f"scale {s:g}")


@pytest.mark.parametrize("d", [1e4, 1e5, 1e6])
def test_scene_far_from_the_origin_renders_the_same_image(reference, d):
    """The whole scene (camera and lights too) moved by (d, -d, d)."""
    scene, ref = reference
    _check(_render(translated(scene, (d, -d, d)), seed=2), ref, f"moved by {d:g}")


def test_the_z_test_sees_a_10_percent_brighter_light(reference):
    scene, ref = reference
    brighter = copy.deepcopy(scene)
    brighter.lights[0].strength = tuple(np.asarray(brighter.lights[0].strength) * 1.1)
    z = z_test(_render(brighter, seed=2), ref)
    print(f"10% brighter light: {z}")
    assert z.mean_z > MEAN_Z
