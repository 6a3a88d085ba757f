"""Adaptive sampling (engine.adaptive_sampling) and the time limit: Cycles' rules, an
honest per-pixel error estimate, and fewer samples for the same error on a scene whose
noise is uneven."""
import numpy as np
import pytest

from engine import RenderSettings, render
from engine.adaptive_sampling import AdaptiveSampling, noise_variance, spread
from engine.film import Film
from engine.scene import Camera, World
from engine_scenes import cornell_box, look_at


def uneven_scene(size=32):
    """The Cornell box seen from further back in a grey world: the world around it is
    noise-free, the box's indirect light is noisy."""
    scene = cornell_box(size, size)
    scene.world = World((0.4, 0.4, 0.4))
    scene.camera = Camera(look_at((0, -6.5, 1.0), (0, 0, 1.0)), lens=22.0)
    return scene


def relative_error(film_a, film_b):
    """Relative MSE of each of two independent renders of the same scene, measured
    between them: E[(A - B)^2] / 2 is the mean squared error of one render against the
    exact image (both are unbiased), without a reference's own noise."""
    a, b = film_a.mean(), film_b.mean()
    r = 0.5 * (a + b)
    return float(((a - b) ** 2 / 2 / (r * r + 1e-2)).mean())


def test_cycles_automatic_values():
    auto = AdaptiveSampling.from_settings(RenderSettings(adaptive_sampling=True))
    assert auto.threshold == 0.01 and auto.min_samples == 64 and auto.step == 16
    coarse = AdaptiveSampling.from_settings(
        RenderSettings(adaptive_sampling=True, adaptive_threshold=0.1))
    assert coarse.min_samples == 32          # Cycles: threshold 0.1 -> 32
    fine = AdaptiveSampling.from_settings(
        RenderSettings(samples=500, adaptive_sampling=True, adaptive_threshold=0.0))
    assert fine.threshold == pytest.approx(1 / 500) and fine.min_samples == 104
    floor = AdaptiveSampling.from_settings(
        RenderSettings(samples=5000, adaptive_sampling=True, adaptive_threshold=0.0))
    assert floor.threshold == 0.001 and floor.min_samples == 128
    manual = AdaptiveSampling.from_settings(
        RenderSettings(adaptive_sampling=True, adaptive_min_samples=2))
    assert manual.min_samples == 4           # never fewer than 4
    assert AdaptiveSampling.from_settings(RenderSettings()) is None


@pytest.mark.parametrize("least, first", [(64, 80), (52, 64), (4, 16), (16, 32), (79, 96)])
def test_the_first_check_is_cycles(least, first):
    """Cycles' scheduler filters first after 0-based sample (min + 1) | (step - 1)."""
    a = AdaptiveSampling(threshold=0.01, min_samples=least)
    assert a.first_check() == first
    passes = list(a.passes(1024, lambda n: [(0, n)]))
    assert passes[0] == (0, first) and passes[1] == (first, first + 16)
    assert all(b - a == 16 for a, b in passes[1:-1]) and passes[-1][1] == 1024


def test_pixel_error_is_cycles_formula():
    film = Film(3, 1)
    # pixel 0: samples 0.2, 0.6 (index 1 in class B, 2 in class A: the half film) in red;
    # 0.1, 0.1 in green and blue
    film.add(np.zeros(2, int), np.array([[0.2, 0.1, 0.1], [0.6, 0.1, 0.1]]),
             index=np.array([1, 2]))
    # pixel 1: bright (intensity over 1): samples 3 and 5 in every channel
    film.add(np.ones(2, int), np.array([[3.0] * 3, [5.0] * 3]), index=np.array([1, 2]))
    # pixel 2: one sample only (no halves): not converged
    film.add(np.full(1, 2), np.array([[1.0, 1.0, 1.0]]), index=np.array([0]))
    err = AdaptiveSampling(threshold=0.01, min_samples=4).pixel_error(film)
    i0 = 0.4 + 0.1 + 0.1
    assert err[0] == pytest.approx(abs(0.4 - 0.6) / (1e-4 + np.sqrt(i0)))
    assert err[1] == pytest.approx(3 * abs(4.0 - 5.0) / (1e-4 + 12.0))
    assert np.isinf(err[2])


def test_a_check_of_the_sampled_pixels_equals_one_of_every_pixel():
    """Checking only the pixels a pass sampled (the others keep their state, as in
    Cycles) gives the active set that checking every pixel gives, pass after pass."""
    rng = np.random.default_rng(5)
    h, w = 12, 16
    film = Film(w, h)
    noise = np.where(rng.random(h * w) < 0.3, 0.8, 0.02)        # some pixels noisy
    a = AdaptiveSampling(threshold=0.01, min_samples=16)
    unconverged = np.ones(h * w, bool)
    active, start = np.arange(h * w), 0
    for k in (16, 16, 16, 16):
        pix = np.repeat(active, k)
        index = np.tile(np.arange(start, start + k), len(active))
        film.add(pix, 0.5 + noise[pix, None] * rng.standard_normal((len(pix), 3)), index=index)
        start += k
        np.testing.assert_array_equal(a.pixel_error(film, active), a.pixel_error(film)[active])
        active = a.check(film, active, unconverged)
        np.testing.assert_array_equal(active, np.flatnonzero(a.active(film)))
    assert 0 < len(active) < h * w


def test_unconverged_pixels_keep_their_neighbours_alive():
    mask = np.zeros((5, 6), bool)
    mask[2, 3] = True
    out = spread(mask)
    assert out.sum() == 9 and out[1:4, 2:5].all()
    edge = np.zeros((3, 3), bool)
    edge[0, 0] = True
    assert spread(edge).sum() == 4


def test_the_error_estimate_agrees_with_the_measured_error():
    """Per pixel, (I - A)^2 from the half film estimates the variance of the pixel mean.
    Averaged over the image (pixels that see the lamp excluded: few samples of a
    heavy-tailed distribution) it is within 1.4x of the measured error for independent
    samples, and conservative (over, by at most 3x) for stratified ones, whose whole set
    is better stratified than either half."""
    scene = cornell_box(32, 32)
    for sampler, low, high in (("random", 1 / 1.4, 1.4), ("jittered", 1.0, 3.0)):
        films = [render(scene, RenderSettings(samples=16, seed=s, sampler=sampler))[0]
                 for s in (1, 2)]
        a, b = films[0].mean(), films[1].mean()
        keep = (a.sum(-1) < 3) & (b.sum(-1) < 3)
        measured = ((a - b) ** 2 / 2)[keep].mean()
        estimated = 0.5 * (noise_variance(films[0]) + noise_variance(films[1]))[keep].mean()
        assert low < estimated / measured < high, (sampler, estimated, measured)


def test_adaptive_sampling_reaches_the_error_of_uniform_with_fewer_samples():
    """Same total samples: the adaptive render's error is several times lower (measured:
    0.00015 against 0.0011 at threshold 0.02, so uniform sampling needs about 7x the
    samples for that error); the noise-free world stops at the minimum, the box goes on."""
    scene = uneven_scene()
    settings = dict(samples=1024, adaptive_sampling=True, adaptive_threshold=0.02)
    runs = [render(scene, RenderSettings(seed=s, **settings)) for s in (1, 2)]
    per_pixel = sum(st.pixel_samples for _, st in runs) / 2 / (32 * 32)
    assert per_pixel < 200
    film = runs[0][0]
    # min samples for 0.02: ceil(16 / 0.02^0.3) = 52; Cycles' first check after
    # (52 + 1) | 15 + 1 = 64 samples
    assert film.count.min() == 64
    assert film.count.max() > 500
    assert runs[0][1].active_pixels < 32 * 32
    uniform = [render(scene, RenderSettings(seed=s, samples=int(round(per_pixel))))[0]
               for s in (1, 2)]
    adaptive_error = relative_error(runs[0][0], runs[1][0])
    uniform_error = relative_error(*uniform)
    assert adaptive_error < uniform_error / 3, (adaptive_error, uniform_error)


def test_uniform_sampling_is_the_default():
    film, stats = render(uneven_scene(16), RenderSettings(samples=8, seed=3))
    assert (film.count == 8).all() and stats.active_pixels == -1


def test_time_limit_stops_after_the_first_pass():
    scene = cornell_box(24, 24)
    film, stats = render(scene, RenderSettings(samples=4096, seed=1, time_limit=1e-6))
    assert stats.time_limited and not stats.cancelled
    assert film.count.min() >= 1                # the first pass always completes
    assert stats.pixel_samples < 24 * 24 * 16
    assert np.isfinite(film.mean()).all()
    assert "time limit reached" in stats.status(4096, 24 * 24)


@pytest.mark.parametrize("bad", [dict(adaptive_threshold=-0.1), dict(adaptive_threshold=2.0),
                                 dict(adaptive_min_samples=-1), dict(time_limit=-1.0),
                                 dict(time_limit=float("nan"))])
def test_bad_adaptive_settings_are_refused(bad):
    with pytest.raises(ValueError):
        RenderSettings(**bad).validate()
