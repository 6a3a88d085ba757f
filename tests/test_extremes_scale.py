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


@pytest.mark.parametrize("d", [1e5, 1e7])
def test_no_acne_and_no_leak_far_from_the_origin(d):
    """The acne and leak checks of tests/test_robustness.py, 1e5 and 1e7 from the origin:
    a plane under a sun at 85 degrees is exactly rho / pi E cos(85 deg) in every pixel
    (direct light); a box with walls 1e-3 of its size thick, a point light just above
    its roof, is black inside (full global illumination)."""
    from engine import Camera, Material, PointLight, Scene, SunLight, World
    from engine_scenes import box, look_at, quad
    o = np.array([d, -d, d])
    theta = np.radians(85.0)
    plane = Scene(Camera(look_at(o + (0, -0.5, 2.0), o), lens=50, clip_start=1e-2),
                  24, 24, [quad(o, (1, 0, 0), (0, 1, 0))],
                  [Material("m", (0.8,) * 3, specular_ior_level=0.0)],
                  [SunLight((-np.sin(theta), 0.0, -np.cos(theta)), (3.0,) * 3)],
                  World((0, 0, 0)))
    film, _ = render(plane, RenderSettings(samples=4, diffuse_bounces=0, filter_type="BOX",
                                           filter_width=0.1))
    np.testing.assert_allclose(film.mean()[..., 0], 0.8 / np.pi * 3.0 * np.cos(theta),
                               rtol=1e-6)
    t = 1e-3
    walls = [box(o + lo, o + hi) for lo, hi in (
        ((-1, -1, -1), (1, 1, -1 + t)), ((-1, -1, 1 - t), (1, 1, 1)),
        ((-1, -1, -1), (-1 + t, 1, 1)), ((1 - t, -1, -1), (1, 1, 1)),
        ((-1, -1, -1), (1, -1 + t, 1)), ((-1, 1 - t, -1), (1, 1, 1)))]
    closed = Scene(Camera(look_at(o + (0, -0.8, 0.5), o + (0, 0, -0.9)), lens=18,
                          clip_start=1e-3, clip_end=10),
                   24, 24, walls, [Material("w", (0.9,) * 3, specular_ior_level=0.0)],
                   [PointLight(tuple(o + (0, 0, 1.05)), (1e3,) * 3)], World((0, 0, 0)))
    film, _ = render(closed, RenderSettings(samples=8))
    assert film.count.sum() == 24 * 24 * 8 and film.sum.max() == 0.0
