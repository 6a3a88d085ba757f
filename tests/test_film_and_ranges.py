"""Any range of sample indices renders on its own, and films merge exactly."""
import numpy as np

from engine import RenderSettings, render
from engine.film import Film
from engine_scenes import cornell_box


def _cycles_class_a(s: int) -> bool:
    """Cycles' sample_is_class_A (kernel/sample/pattern.h), in plain Python."""
    return bin(s & 0xAAAAAAAA).count("1") % 2 == 1


def test_the_half_film_holds_cycles_class_a():
    """Sample s goes to the half film exactly when Cycles puts it in class A: two of
    every four consecutive indices, and half of any aligned power-of-two run of 4 or
    more."""
    film = Film(1, 1)
    n = 4096
    values = np.random.default_rng(3).random((n, 3))
    film.add(np.zeros(n, int), values, index=np.arange(n))
    chosen = np.array([_cycles_class_a(s) for s in range(n)])
    assert film.count_half[0] == chosen.sum() == n // 2
    np.testing.assert_allclose(film.sum_half[0], values[chosen].sum(axis=0), rtol=1e-12)
    assert all(chosen[k:k + 4].sum() == 2 for k in range(0, n, 4))


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
    # the half film (adaptive sampling's error estimate) merges too
    assert np.array_equal(merged.count_half, whole.count_half)
    assert np.array_equal(whole.count_half, np.full(24 * 24, 4))
    np.testing.assert_allclose(merged.sum_half, whole.sum_half, rtol=1e-12, atol=1e-12)
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
    assert copy.count_half.sum() == sum(_cycles_class_a(s) for s in range(50))
