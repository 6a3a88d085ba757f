"""Samplers: deterministic, random-access, stratified per dimension, decorrelated
across dimensions (Cook's ray-id chaining), and different for different seeds."""
import numpy as np
import pytest
from scipy import stats
from scipy.stats import qmc

from engine.sampling import make_sampler
from engine.sampling.hashing import permute_index
from engine.sampling.sobol import sobol_dim0, sobol_dim1

NAMES = ("jittered", "sobol", "random")


@pytest.mark.parametrize("n", [1, 2, 3, 5, 16, 17, 100, 1024, 1000])
def test_permutation_is_a_bijection(n):
    keys = np.arange(20)
    for key in keys:
        p = permute_index(np.arange(n), n, key)
        assert np.array_equal(np.sort(p), np.arange(n))


def test_permutations_differ_between_keys():
    perms = {tuple(permute_index(np.arange(8), 8, k)) for k in range(200)}
    assert len(perms) > 150          # 8! = 40320 possible; near-random keys rarely collide


def test_unscrambled_sobol_matches_scipy():
    ref = qmc.Sobol(2, scramble=False).random(256)
    gray = np.arange(256) ^ (np.arange(256) >> 1)        # scipy emits in Gray-code order
    mine = np.stack([sobol_dim0(gray), sobol_dim1(gray)], axis=1) / 2.0 ** 32
    assert np.array_equal(mine, ref)


@pytest.mark.parametrize("name", NAMES)
def test_deterministic_and_random_access(name):
    s = make_sampler(name, seed=7, samples_per_pixel=64)
    pix = np.repeat(np.arange(10), 64)
    idx = np.tile(np.arange(64), 10)
    a = s.get_2d(5, pix, idx)
    b = make_sampler(name, seed=7, samples_per_pixel=64).get_2d(5, pix, idx)
    assert np.array_equal(a, b)
    # Any subset, in any order, gives the same values: random access.
    order = np.random.default_rng(0).permutation(len(pix))[:100]
    assert np.array_equal(s.get_2d(5, pix[order], idx[order]), a[order])
    assert ((a >= 0) & (a < 1)).all()
    c = make_sampler(name, seed=8, samples_per_pixel=64).get_2d(5, pix, idx)
    assert not np.allclose(a, c)


@pytest.mark.parametrize("name,spp", [("jittered", 16), ("jittered", 64), ("jittered", 37),
                                      ("sobol", 16), ("sobol", 64)])
def test_stratified_in_every_dimension(name, spp):
    """One point per 1D stratum in x and in y for each pixel and dimension (for jittered
    with N samples: N strata in y; for Sobol a (0,m,2)-net: N strata in x and y)."""
    s = make_sampler(name, seed=1, samples_per_pixel=spp)
    for dim in (0, 1, 3, 4, 12, 40):
        for pixel in (0, 17, 123456):
            u = s.get_2d(dim, np.full(spp, pixel), np.arange(spp))
            ys = np.sort(np.floor(u[:, 1] * spp).astype(int))
            assert np.array_equal(ys, np.arange(spp)), (dim, pixel)
            if name == "sobol":
                xs = np.sort(np.floor(u[:, 0] * spp).astype(int))
                assert np.array_equal(xs, np.arange(spp))
            else:
                m = int(np.floor(np.sqrt(spp)))
                cols = np.bincount(np.floor(u[:, 0] * m).astype(int), minlength=m)
                assert cols.max() - cols.min() <= int(np.ceil(spp / m)) - spp // m + 1


def test_random_sampler_is_not_stratified():
    s = make_sampler("random", seed=1, samples_per_pixel=64)
    u = s.get_2d(0, np.zeros(64, int), np.arange(64))
    assert len(np.unique(np.floor(u[:, 1] * 64))) < 64


@pytest.mark.parametrize("name", NAMES)
def test_dimensions_are_decorrelated(name):
    """Cook's ray-id chaining: the sub-pixel stratum of a sample says nothing about its
    stratum in another dimension. Over many pixels, the correlation between the same
    sample's values in two dimensions is zero within noise."""
    spp, npix = 16, 4000
    s = make_sampler(name, seed=2, samples_per_pixel=spp)
    pix = np.repeat(np.arange(npix), spp)
    idx = np.tile(np.arange(spp), npix)
    a = s.get_2d(0, pix, idx)
    for dim in (1, 3, 6):
        b = s.get_2d(dim, pix, idx)
        for i in range(2):
            for j in range(2):
                r, _ = stats.pearsonr(a[:, i], b[:, j])
                # under independence r ~ N(0, 1/N); 4.5 sigma over 12 comparisons
                assert abs(r) < 4.5 / np.sqrt(len(a)), (name, dim, i, j, r)


@pytest.mark.parametrize("name", NAMES)
def test_uniform_marginals(name):
    """Every value is uniformly distributed over [0,1) across pixels (KS test)."""
    spp = 8
    s = make_sampler(name, seed=3, samples_per_pixel=spp)
    pix = np.repeat(np.arange(5000), spp)
    idx = np.tile(np.arange(spp), 5000)
    for dim in (0, 7):
        u = s.get_2d(dim, pix, idx)
        for k in range(2):
            assert stats.kstest(u[:, k], "uniform").pvalue > 1e-3
        assert stats.kstest(s.get_1d(dim, pix, idx), "uniform").pvalue > 1e-3


def test_jittered_beyond_planned_count_stays_stratified_per_generation():
    s = make_sampler("jittered", seed=4, samples_per_pixel=16)
    u = s.get_1d(3, np.zeros(32, int), np.arange(32))
    for gen in range(2):
        strata = np.sort(np.floor(u[gen * 16:(gen + 1) * 16] * 16).astype(int))
        assert np.array_equal(strata, np.arange(16))


def test_jittered_under_adaptive_sampling_stratifies_up_to_each_stopping_point():
    """Adaptive sampling stops pixels after min_samples + k * step samples: the jittered
    sampler's first generation ends at min samples (52), and later ones double (52, 104,
    208, ...), so a pixel holds whole stratified sets and part of one more, in the
    compiled dispatch every kernel uses."""
    s = make_sampler("jittered", seed=9, samples_per_pixel=1024)
    s.follow_stops(52, 16)
    for dim in (0, 5):
        u = s.get_1d(dim, np.full(416, 7), np.arange(416))
        bounds = [(0, 52), (52, 104), (104, 208), (208, 416)]
        for a, b in bounds:
            strata = np.sort(np.floor(u[a:b] * (b - a)).astype(int))
            assert np.array_equal(strata, np.arange(b - a)), (dim, a, b)
        xy = s.get_2d(dim, np.full(52, 3), np.arange(52))
        assert np.array_equal(np.sort(np.floor(xy[:, 1] * 52).astype(int)), np.arange(52))
    plain = make_sampler("jittered", seed=9, samples_per_pixel=1024).get_1d(0, np.zeros(52, int),
                                                                          np.arange(52))
    assert len(np.unique(np.floor(plain * 52))) < 52   # without: a subset of 1024 strata
