"""Russian roulette as Cycles plays it (engine/kernels/path_weights.py): a path goes on
with probability q = min(sqrt(max throughput), 1), decided when its next ray leaves and
applied at the vertex that ray finds, after the emission found there. The furnace tests
(tests/test_furnace.py) check the whole estimator against closed forms, emission at every
vertex included; these check the rule itself."""
import math

import numpy as np
import pytest

from engine.kernels.path_weights import continues, roulette


@pytest.mark.parametrize("b, q", [((0.25, 0.1, 0.0), 0.5), ((0.04, 0.01, 0.0), 0.2),
                                  ((0.0, 0.81, 0.3), 0.9)])
def test_survival_probability_is_the_square_root_of_the_largest_channel(b, q):
    assert roulette(q * (1 - 1e-9), *b) == pytest.approx(q, rel=1e-12)
    assert roulette(q, *b) == 0.0                 # u >= q: the path ends
    assert roulette(0.0, *b) == pytest.approx(q, rel=1e-12)


@pytest.mark.parametrize("b", [(1.0, 0.2, 0.2), (3.0, 0.0, 0.0), (0.2, 5.0, 0.1)])
def test_a_throughput_of_one_or_more_always_goes_on(b):
    assert all(roulette(u, *b) == 1.0 for u in np.linspace(0.0, 1.0 - 1e-12, 101))


def test_black_and_nan_throughputs_end_the_path():
    assert roulette(0.0, 0.0, 0.0, 0.0) == 0.0
    assert roulette(0.0, -1.0, -2.0, 0.0) == 0.0
    assert roulette(0.5, math.nan, math.nan, math.nan) == 0.0


@pytest.mark.parametrize("b", [(0.3, 0.2, 0.1), (0.01, 0.0, 0.0), (0.7, 0.7, 0.7)])
def test_the_weight_of_the_survivors_is_unbiased(b):
    """Over stratified u, the survivors' weight 1/q averages exactly 1: E[1{u<q} / q] = 1."""
    n = 100_000
    u = (np.arange(n) + 0.5) / n
    verdicts = np.array([roulette(x, *b) for x in u])
    weights = np.where(verdicts > 0, 1.0 / np.where(verdicts > 0, verdicts, 1.0), 0.0)
    q = min(math.sqrt(max(b)), 1.0)
    assert weights.mean() == pytest.approx(1.0, abs=2.0 / (q * n))
    assert (verdicts > 0).mean() == pytest.approx(q, abs=2.0 / n)


def test_the_verdict_is_taken_once_at_the_next_vertex():
    cont = np.array([1.0, 0.25, 0.0])
    assert [continues(cont, p) for p in range(3)] == [1.0, 0.25, 0.0]
    assert cont.tolist() == [1.0, 1.0, 1.0]       # reset: the next bounce draws again
