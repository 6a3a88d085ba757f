"""Error metrics (engine/image_error.py) against hand-computed values, FLIP's basic
properties, and the sample ladders of engine/convergence.py on a small engine scene."""
import math

import numpy as np
import pytest

from engine import RenderSettings, render
from engine import convergence
from engine import image_error as ie
from engine_scenes import cornell_box


def test_rmse_and_relmse_by_hand():
    ref = np.array([[[0.0, 0.0, 0.0], [1.0, 2.0, 0.5]]])
    test = np.array([[[0.3, 0.0, 0.0], [1.0, 1.0, 0.5]]])
    # squared errors: 0.09, 0, 0, 0, 1, 0 over 6 values
    assert ie.rmse(test, ref) == pytest.approx(math.sqrt(1.09 / 6), rel=1e-12)
    # relative: 0.09 / (0 + 0.01) = 9 and 1 / (4 + 0.01), the rest 0
    assert ie.relmse(test, ref) == pytest.approx((9.0 + 1.0 / 4.01) / 6, rel=1e-12)
    assert ie.relmse(test, ref, eps=1.0) == pytest.approx((0.09 + 1.0 / 5.0) / 6, rel=1e-12)
    # relMSE divides by the reference, not the test image
    assert ie.relmse(ref, test) == pytest.approx((0.09 / 0.1 + 1.0 / 1.01) / 6, rel=1e-12)


def test_alpha_is_dropped_and_grey_is_three_channels():
    rgb = np.full((2, 2, 3), 0.25)
    rgba = np.concatenate([rgb, np.zeros((2, 2, 1))], axis=2)
    assert ie.rmse(rgba, rgb) == 0.0
    assert ie.rmse(np.full((2, 2), 0.25), rgb) == 0.0


@pytest.mark.parametrize("test, message", [
    (np.zeros((3, 2, 3)), "differ in size"),
    (np.array([[[np.nan, 0, 0], [0, 0, 0]], [[0, 0, 0], [0, 0, np.inf]]]), "2 NaN"),
    (np.zeros((2, 2, 5)), "image, got shape"),
])
def test_bad_images_are_refused_with_a_reason(test, message):
    with pytest.raises(ValueError, match=message):
        ie.rmse(test, np.zeros((2, 2, 3)))


def test_flip_is_zero_for_equal_images_and_grows_with_noise():
    rng = np.random.default_rng(4)
    img = rng.uniform(0.05, 0.8, (48, 64, 3))
    assert ie.flip(img, img) == 0.0
    errors = [ie.flip(np.clip(img + rng.normal(0.0, s, img.shape), 0, None), img)
              for s in (0.01, 0.04, 0.16)]
    assert 0.0 < errors[0] < errors[1] < errors[2] <= 1.0
    error_map, mean = ie.flip_map(img + 0.1, img)
    assert error_map.shape == (48, 64)
    assert mean == pytest.approx(float(error_map.mean()), rel=1e-4)


def test_flip_sees_the_clipped_display_image():
    img = np.full((16, 16, 3), 0.4)
    img[4:8, 4:8] = 5.0                       # a lamp seen directly, over white
    brighter = img.copy()
    brighter[4:8, 4:8] = 50.0
    assert ie.flip(brighter, img) == 0.0      # both clip to white
    assert ie.rmse(brighter, img) > 0.0       # RMSE still counts it


def test_fit_slope_and_the_reference_noise_floor():
    x = np.array([1, 2, 4, 8, 16])
    assert ie.fit_slope(x, 3.0 / x) == pytest.approx(-1.0, abs=1e-12)
    assert ie.fit_slope(x, 3.0 / np.sqrt(x)) == pytest.approx(-0.5, abs=1e-12)
    flattened = 3.0 / x + 0.1                 # a noisy reference adds 0.1 to every point
    assert ie.fit_slope(x, flattened) > -0.9
    assert ie.fit_slope(x, flattened, floor=0.1) == pytest.approx(-1.0, abs=1e-12)
    # points within twice the floor are left out: here all but the first two
    assert ie.fit_slope(x, flattened, floor=0.7) == pytest.approx(
        math.log((1.6 - 0.7) / (3.1 - 0.7)) / math.log(2), abs=1e-12)
    assert ie.fit_slope(x, flattened, floor=2.0) is None
    var = np.full((2, 2, 3), 0.04)
    ref = np.full((2, 2, 3), 1.0)
    floor = ie.noise_floor(var, ref)
    assert floor["mse"] == pytest.approx(0.04)
    assert floor["rmse"] == pytest.approx(0.2)
    assert floor["relmse"] == pytest.approx(0.04 / 1.01)
    # RMSE through its square: sqrt(true MSE + floor)
    rmse = np.sqrt(0.5 / x + floor["mse"])
    assert ie.metric_slope("rmse", x, rmse, floor) == pytest.approx(-0.5, abs=1e-12)
    assert ie.metric_slope("flip", x, 0.3 / x ** 0.4, floor) == pytest.approx(-0.4, abs=1e-12)


def test_sample_ladder_and_settings_that_take_every_sample():
    assert convergence.sample_ladder(16) == [1, 2, 4, 8, 16]
    assert convergence.sample_ladder(20) == [1, 2, 4, 8, 16, 20]
    assert convergence.sample_ladder(1) == [1]
    s = convergence.every_sample(RenderSettings(samples=4), samples=9, sampler="sobol")
    assert (s.samples, s.sampler) == (9, "sobol")


def test_progressive_rungs_are_the_renders_of_that_many_samples():
    """A random or Sobol ladder's rung k is exactly a render of k samples; a jittered
    rung is a render of its own (its strata depend on the count)."""
    scene = cornell_box(12, 10)
    for sampler in ("random", "jittered"):
        settings = RenderSettings(samples=1, seed=3, sampler=sampler)
        rungs = list(convergence.ladder(scene, settings, [1, 2, 4]))
        assert [r.samples for r in rungs] == [1, 2, 4]
        assert rungs[2].seconds > 0
        direct, _ = render(scene, RenderSettings(samples=4, seed=3, sampler=sampler))
        np.testing.assert_allclose(rungs[2].image, direct.mean(), rtol=1e-12, atol=1e-12)
        assert not np.allclose(rungs[0].image, rungs[2].image)


def test_the_reference_is_independent_of_the_ladder():
    scene = cornell_box(12, 10)
    settings = RenderSettings(samples=1, seed=3, sampler="random")
    ref = convergence.reference(scene, settings, 8)
    ladder8 = list(convergence.ladder(scene, settings, [8]))[0]
    assert ref.samples == 8 and ref.variance_of_mean.shape == (10, 12, 3)
    # another seed: not the ladder's samples (which would make the error look too small)
    assert not np.allclose(ref.image, ladder8.image)
