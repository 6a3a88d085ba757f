"""The guided CDF search (engine/kernels/cdf_search.py) that the camera's pixel filter
and the environment map's importance sampling use: the same interval as NumPy's
searchsorted over the whole table, for CDFs with flat runs (zero weights), one cell
holding almost all the mass (a sun in an HDRI), u on the guide's cell boundaries, on the
CDF's own knots, just below them, 0 and next to 1."""
from __future__ import annotations

import numpy as np
import pytest

from engine.kernels.cdf_search import guide_cells, guide_table, last_at_most
from engine.piecewise_2d import cdf_1d


def _weights(kind, n, rng):
    if kind == "smooth":
        return 1.0 + np.sin(np.linspace(0, 6, n)) ** 2
    if kind == "sparse":                       # most cells zero: flat CDF runs
        return np.where(rng.random(n) < 0.1, rng.random(n), 0.0)
    if kind == "sun":                          # one cell with nearly all the mass
        w = np.full(n, 1e-6)
        w[n // 3] = 1e6
        return w
    return np.zeros(n)                         # all zero: the uniform fallback


@pytest.mark.parametrize("kind", ["smooth", "sparse", "sun", "zero"])
@pytest.mark.parametrize("n", [1, 7, 64, 2048])
def test_guided_search_finds_searchsorteds_interval(kind, n):
    rng = np.random.default_rng(n)
    cdf = cdf_1d(_weights(kind, n, rng))
    cells = guide_cells(n)
    guide = guide_table(cdf, cells)
    assert guide.shape == (cells + 1,) and guide.dtype == np.int32
    assert cells & (cells - 1) == 0 and 1 <= cells <= 1024
    u = np.concatenate([np.arange(cells) / cells, cdf, np.nextafter(cdf, 0),
                        [0.0, np.nextafter(1.0, 0), 1.0], rng.random(5000)])
    u = u[(u >= 0) & (u <= 1)]
    got = np.array([last_at_most(cdf, float(x), guide) for x in u])
    np.testing.assert_array_equal(got, np.searchsorted(cdf, u, side="right") - 1)


def test_row_guides_of_a_2d_table():
    """guide_table on (rows, n + 1) CDFs gives each row its own guide."""
    rng = np.random.default_rng(9)
    cdf = cdf_1d(np.where(rng.random((5, 300)) < 0.3, rng.random((5, 300)), 0.0))
    guides = guide_table(cdf, guide_cells(300))
    assert guides.shape == (5, guide_cells(300) + 1)
    for r in range(5):
        np.testing.assert_array_equal(guides[r], guide_table(cdf[r], guide_cells(300)))
        u = rng.random(500)
        got = [last_at_most(cdf[r], float(x), guides[r]) for x in u]
        np.testing.assert_array_equal(got, np.searchsorted(cdf[r], u, side="right") - 1)


def test_an_empty_cdf_has_a_guide_of_zeros():
    """An empty light set's CDF: the guide exists (the kernels' types never vary) and
    points nowhere; the light pick returns -1 before using it."""
    assert guide_table(np.zeros(0), 4).tolist() == [0] * 5
    assert guide_table(np.zeros((0, 3)), 2).shape == (0, 3)
