"""Any range of sample indices renders on its own, and films merge exactly."""
import numpy as np

from engine import RenderSettings, render
from engine.film import Film
from engine_scenes import cornell_box


def test_split_sample_ranges_merge_into_the_whole_render():
    scene = cornell_box(24, 24)
    settings = RenderSettings(samples=8, seed=11, chunk_paths=1024)
    whole, _ = render(scene, settings)
    first, _ = render(scene, settings, sample_start=0, sample_end=3)
    second, _ = render(scene, settings, sample_start=3, sample_end=8)
    merged = first.merge(second)
    assert np.array_equal(merged.count, whole.count)
    np.testing.assert_allclose(merged.sum, whole.sum, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(merged.sum_sq, whole.sum_sq, rtol=1e-12, atol=1e-12)
    # the half film of odd samples (adaptive sampling's error estimate) merges too
    assert np.array_equal(merged.count_odd, whole.count_odd)
    assert np.array_equal(whole.count_odd, np.full(24 * 24, 4))
    np.testing.assert_allclose(merged.sum_odd, whole.sum_odd, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(merged.variance_of_mean(), whole.variance_of_mean(),
                               rtol=1e-9, atol=1e-12)


def test_chunking_and_threads_do_not_change_the_image():
    scene = cornell_box(20, 20)
    a, _ = render(scene, RenderSettings(samples=4, seed=5, chunk_paths=256, threads=1))
    b, _ = render(scene, RenderSettings(samples=4, seed=5, chunk_paths=1 << 16, threads=2))
    np.testing.assert_allclose(a.sum, b.sum, rtol=1e-12, atol=1e-12)


def test_different_seeds_give_independent_images():
    scene = cornell_box(20, 20)
    a, _ = render(scene, RenderSettings(samples=2, seed=1))
    b, _ = render(scene, RenderSettings(samples=2, seed=2))
    da, db = a.mean(), b.mean()
    assert not np.allclose(da, db)
    # Same expectation: compare means with the directly seen light (radiance ~76) clipped.
    ma, mb = np.clip(da, 0, 1).mean(), np.clip(db, 0, 1).mean()
    assert abs(ma - mb) / ma < 0.1
    # Independent noise: the per-pixel differences are not correlated with each other.
    diff = (np.clip(da, 0, 1) - np.clip(db, 0, 1))[..., 0].ravel()
    r = np.corrcoef(diff[:-1], diff[1:])[0, 1]
    assert abs(r) < 0.3


def test_film_statistics():
    film = Film(2, 1)
    rng = np.random.default_rng(0)
    v = rng.random((1000, 3))
    film.add(np.zeros(1000, int), v, index=np.arange(1000))
    np.testing.assert_allclose(film.mean()[0, 0], v.mean(0))
    np.testing.assert_allclose(film.variance_of_mean()[0, 0], v.var(0, ddof=1) / 1000)
    assert np.isinf(film.variance_of_mean()[0, 1]).all()
    assert (film.mean()[0, 1] == 0).all()


def test_cancel_returns_a_valid_partial_film():
    scene = cornell_box(32, 32)
    calls = []

    def cancelled():
        calls.append(1)
        return len(calls) > 3

    film, stats = render(scene, RenderSettings(samples=64, chunk_paths=512), cancelled=cancelled)
    assert stats.cancelled
    assert 0 < film.count.sum() < 32 * 32 * 64
    assert np.isfinite(film.mean()).all()


def test_film_statistics_rebuild_the_film_in_another_process():
    """What a Dask worker ships: every per-pixel array, the half film included."""
    film = Film(3, 2)
    rng = np.random.default_rng(1)
    film.add(rng.integers(0, 6, 50), rng.random((50, 3)), rng.random(50),
             index=np.arange(50))
    copy = Film.from_statistics(3, 2, {k: v.copy() for k, v in film.statistics().items()})
    for name in Film.STATISTICS:
        assert np.array_equal(getattr(copy, name), getattr(film, name)), name
    assert copy.count_odd.sum() == 25
