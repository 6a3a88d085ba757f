"""Each integrator is unbiased: a render at modest samples agrees with a high-sample
reference of the same integrator made with a different sampler, per pixel, by a z-test.

z = (mean_test - mean_ref) / sqrt(var_test + var_ref), with each variance the film's
per-pixel estimate of the variance of its mean. For an unbiased estimator z is about
standard normal (narrower for stratified samplers, whose variance the i.i.d. formula
overestimates). Two criteria, both stated here:
- per pixel: at least 95% of pixel channels have |z| < 3;
- pooled over the image: Z = sum(diff) / sqrt(sum(var)) has |Z| < 3.
A control shows that a 5% bias fails them.
"""
import numpy as np
import pytest

from engine import RenderSettings, render
from engine_scenes import cornell_box

PASS_RATE = 0.95
POOLED_Z = 3.0
TEST_SPP = 512


def z_scores(test, ref):
    a, b = test.mean(), ref.mean()
    var = test.variance_of_mean() + ref.variance_of_mean()
    diff = a - b
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(var > 0, diff / np.sqrt(var), np.where(np.abs(diff) < 1e-9, 0.0, np.inf))
    return z


def judge(test, ref):
    """(fraction of pixel channels with |z| < 3, pooled Z)."""
    z = z_scores(test, ref)
    diff = test.mean() - ref.mean()
    var = test.variance_of_mean() + ref.variance_of_mean()
    finite = np.isfinite(var)
    pooled = diff[finite].sum() / np.sqrt(var[finite].sum())
    return float((np.abs(z) < 3).mean()), float(pooled)


def passes(rate, pooled):
    return rate >= PASS_RATE and abs(pooled) < POOLED_Z


def low_variance_cornell():
    """The Cornell box under a large, dim ceiling light: full global illumination with
    low enough variance that a 5% bias stands out (pooled Z shifts by about 10)."""
    scene = cornell_box(12, 12, light_size=1.6)
    scene.lights[0].strength = tuple(np.asarray(scene.lights[0].strength) * 0.1)
    return scene


@pytest.fixture(scope="module")
def path_reference():
    scene = low_variance_cornell()
    ref, _ = render(scene, RenderSettings(samples=2048, sampler="sobol", seed=77,
                                          clamp_indirect=0.0))
    return scene, ref


@pytest.mark.parametrize("sampler", ["jittered", "random"])
def test_path_tracer_is_unbiased(path_reference, sampler):
    scene, ref = path_reference
    test, _ = render(scene, RenderSettings(samples=TEST_SPP, sampler=sampler, seed=3,
                                           clamp_indirect=0.0))
    rate, pooled = judge(test, ref)
    print(f"path/{sampler}: {rate:.1%} of pixel channels within 3 sigma, pooled Z {pooled:+.2f}")
    assert passes(rate, pooled)


def test_the_z_test_detects_a_five_percent_bias(path_reference):
    scene, ref = path_reference
    test, _ = render(scene, RenderSettings(samples=TEST_SPP, seed=3, clamp_indirect=0.0))
    test.sum *= 1.05
    test.sum_sq *= 1.05 ** 2
    rate, pooled = judge(test, ref)
    print(f"5% bias: {rate:.1%} within 3 sigma, pooled Z {pooled:+.2f}")
    assert not passes(rate, pooled)


@pytest.mark.parametrize("integrator", ["distribution", "whitted"])
def test_other_integrators_are_unbiased(integrator):
    scene = low_variance_cornell()
    ref, _ = render(scene, RenderSettings(samples=1024, sampler="sobol", seed=77,
                                          integrator=integrator, clamp_indirect=0.0))
    test, _ = render(scene, RenderSettings(samples=TEST_SPP // 2, sampler="jittered", seed=3,
                                           integrator=integrator, clamp_indirect=0.0))
    rate, pooled = judge(test, ref)
    print(f"{integrator}: {rate:.1%} of pixel channels within 3 sigma, pooled Z {pooled:+.2f}")
    assert passes(rate, pooled)
