"""Chi-square goodness-of-fit test of a direction sampler against its own pdf.

In the style of Mitsuba 3's `mitsuba.chi2.ChiSquareTest` (after Jakob's
Mitsuba 0.5 test suite): draw N directions, histogram them in cells of the sphere
parameterised by (cos theta, phi), compute each cell's expected count N * integral of
the pdf over the cell, pool the cells whose expected count is below 5, and compare with
Pearson's statistic X^2 = sum (O - E)^2 / E, whose p-value under the null hypothesis
("the samples follow the pdf") comes from the chi-square distribution with
(bins - 1) degrees of freedom (scipy.stats.chi2).

Details:
  * Samples that the sampler rejects (valid = False) form one extra bin with expected
    count N (1 - integral of the pdf over the sphere), so a pdf that does not integrate
    to the probability of producing a sample fails too.
  * A sample in a cell whose expected count is 0 fails the test outright.
  * Cells: rows in cos theta, each row split in phi. By default (`adaptive=True`) the
    edges are quantiles of an independent pilot run of the sampler (cos theta = 0 is
    always an edge), so that peaked lobes (Blinn-Phong n = 1000, GGX alpha = 0.05) get
    many small cells where their mass is and each cell's integral stays accurate; the
    partition never depends on the samples being tested, so the statistic keeps its
    null distribution. `adaptive=False` gives Mitsuba's uniform grid.
  * Cell integrals: tensor-product Gauss-Legendre rule with `ires` x `ires` nodes in
    (cos theta, phi) (d(omega) = d(cos theta) d(phi)), refined adaptively by quartering
    cells until the estimate agrees with the sum over the quarters (Mitsuba uses a
    fixed Simpson sub-grid; the adaptive rule keeps peaked pdfs accurate).
  * Significance: the caller states how many tests the run makes; each test uses the
    Sidak-corrected level 1 - (1 - 0.01)^(1/n_tests), so the whole run has a 1 % chance
    of a false failure.

Units: pdfs are densities in 1/sr with respect to solid angle on the unit sphere.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

SIGNIFICANCE = 0.01


def sidak(alpha: float, n_tests: int) -> float:
    """Per-test level giving family-wise level `alpha` over n independent tests."""
    return 1.0 - (1.0 - alpha) ** (1.0 / max(int(n_tests), 1))


def directions(cos_theta, phi, phi0=0.0):
    """Unit vectors at (cos theta, phi + phi0)."""
    st = np.sqrt(np.maximum(0.0, 1.0 - cos_theta * cos_theta))
    return np.stack([st * np.cos(phi + phi0), st * np.sin(phi + phi0), cos_theta], -1)


def spherical(w, phi0=0.0):
    """(cos theta, phi - phi0 wrapped to [-pi, pi))."""
    phi = np.arctan2(w[:, 1], w[:, 0]) - phi0
    return np.clip(w[:, 2], -1.0, 1.0), (phi + np.pi) % (2.0 * np.pi) - np.pi


@dataclass
class Chi2Result:
    statistic: float
    dof: int
    p_value: float
    threshold: float
    n_cells: int
    n_bins: int
    pdf_integral: float
    valid_fraction: float
    message: str = ""

    @property
    def passed(self) -> bool:
        return not self.message and self.p_value >= self.threshold

    def __str__(self):
        s = (f"chi2={self.statistic:.1f} dof={self.dof} p={self.p_value:.4g} "
             f"(threshold {self.threshold:.3g}) integral={self.pdf_integral:.5f} "
             f"valid={self.valid_fraction:.5f}")
        return s + (f" FAIL: {self.message}" if self.message else "")


class SphereBinning:
    """Cells [c_i, c_i+1] x [phi_ij, phi_ij+1] of the sphere, phi measured from phi0."""

    def __init__(self, cos_edges, phi_edges_per_row, phi0=0.0):
        self.phi0 = float(phi0)
        self.cos_edges = np.asarray(cos_edges, dtype=np.float64)
        self.phi_edges = [np.asarray(p, dtype=np.float64) for p in phi_edges_per_row]
        self.offsets = np.concatenate([[0], np.cumsum([len(p) - 1 for p in self.phi_edges])])
        self.n_cells = int(self.offsets[-1])

    @classmethod
    def uniform(cls, rows, cols):
        return cls(np.linspace(-1.0, 1.0, rows + 1),
                   [np.linspace(-np.pi, np.pi, cols + 1)] * rows)

    @classmethod
    def from_pilot(cls, pilot_dirs, rows, cols):
        """Edges at the quantiles of pilot samples (cos theta = -1, 0, 1 always edges).

        The phi seam goes through the emptiest of 64 azimuth sectors of the pilot, so a
        lobe is never cut in two by it (a cell spanning the seam would hold mass at both
        of its far ends, which no quadrature over the cell sees)."""
        _, p_abs = spherical(pilot_dirs)
        hist = np.bincount(((p_abs + np.pi) / (2 * np.pi) * 64).astype(np.int64) % 64,
                           minlength=64)
        phi0 = -np.pi + (np.argmin(hist) + 0.5) * (2 * np.pi / 64) + np.pi
        c, p = spherical(pilot_dirs, phi0)
        if len(c) >= rows * 10:
            q = np.quantile(c, np.linspace(0.0, 1.0, rows + 1)[1:-1])
        else:
            q = np.linspace(-1.0, 1.0, rows + 1)[1:-1]
        edges = np.unique(np.concatenate([[-1.0, 0.0, 1.0], q]))
        # drop slivers thinner than 1e-12 in cos theta (zero-width rows)
        keep = np.concatenate([[True], np.diff(edges) > 1e-12])
        edges = edges[keep]
        edges[-1] = 1.0
        row = np.clip(np.searchsorted(edges, c, side="right") - 1, 0, len(edges) - 2)
        phi_edges = []
        for i in range(len(edges) - 1):
            pr = p[row == i]
            if len(pr) >= cols * 10:
                inner = np.quantile(pr, np.linspace(0.0, 1.0, cols + 1)[1:-1])
                e = np.unique(np.concatenate([[-np.pi, np.pi], inner]))
            else:
                e = np.linspace(-np.pi, np.pi, max(cols // 4, 1) + 1)
            phi_edges.append(e)
        return cls(edges, phi_edges, phi0)

    def cell_of(self, w):
        c, p = spherical(w, self.phi0)
        row = np.clip(np.searchsorted(self.cos_edges, c, side="right") - 1,
                      0, len(self.cos_edges) - 2)
        cell = np.empty(len(w), dtype=np.int64)
        for i, e in enumerate(self.phi_edges):
            sel = row == i
            if sel.any():
                col = np.clip(np.searchsorted(e, p[sel], side="right") - 1, 0, len(e) - 2)
                cell[sel] = self.offsets[i] + col
        return cell

    def cells(self):
        """(c0, c1, p0, p1): the bounds of every cell, in cell order."""
        c0, c1, p0, p1 = [], [], [], []
        for i, e in enumerate(self.phi_edges):
            k = len(e) - 1
            c0.append(np.full(k, self.cos_edges[i]))
            c1.append(np.full(k, self.cos_edges[i + 1]))
            p0.append(e[:-1])
            p1.append(e[1:])
        return tuple(np.concatenate(v) for v in (c0, c1, p0, p1))

    def integrate(self, pdf, ires=6, rel_tol=1e-4, abs_tol=1e-8, max_depth=16,
                  max_dc=0.05, max_dphi=np.pi / 32):
        """Integral of pdf (a function of (m, 3) directions) over every cell.

        Cells are first cut into pieces at most max_dc x max_dphi; then each piece's
        Gauss-Legendre estimate is compared with the sum over its four quarters, and
        pieces that disagree by more than the tolerance are split again (vectorised over
        all unconverged pieces, at most `max_depth` times)."""
        c0, c1, p0, p1 = self.cells()
        kc = np.maximum(np.ceil((c1 - c0) / max_dc).astype(np.int64), 1)
        kp = np.maximum(np.ceil((p1 - p0) / max_dphi).astype(np.int64), 1)
        owner = np.repeat(np.arange(len(c0)), kc * kp)
        # piece (a, b) of cell k: a-th of kc[k] in cos, b-th of kp[k] in phi
        j = np.arange(len(owner)) - np.repeat(np.cumsum(kc * kp) - kc * kp, kc * kp)
        a, b = j // kp[owner], j % kp[owner]
        dc, dp = (c1 - c0) / kc, (p1 - p0) / kp
        c0, c1 = c0[owner] + a * dc[owner], c0[owner] + (a + 1) * dc[owner]
        p0, p1 = p0[owner] + b * dp[owner], p0[owner] + (b + 1) * dp[owner]
        out = np.zeros(self.n_cells)
        whole = _gauss(pdf, c0, c1, p0, p1, ires, self.phi0)
        for depth in range(max_depth + 1):
            cm, pm = 0.5 * (c0 + c1), 0.5 * (p0 + p1)
            q = [(c0, cm, p0, pm), (c0, cm, pm, p1), (cm, c1, p0, pm), (cm, c1, pm, p1)]
            parts = [_gauss(pdf, *bq, ires, self.phi0) for bq in q]
            split = sum(parts)
            done = np.abs(split - whole) <= abs_tol + rel_tol * np.abs(split)
            if depth == max_depth:
                done[:] = True
            np.add.at(out, owner[done], split[done])
            if done.all():
                break
            nd = ~done
            owner = np.tile(owner[nd], 4)
            c0, c1, p0, p1 = (np.concatenate([bq[k][nd] for bq in q]) for k in range(4))
            whole = np.concatenate([pt[nd] for pt in parts])
        return out


def _gauss(pdf, c0, c1, p0, p1, ires, phi0=0.0):
    """Tensor Gauss-Legendre estimate of the pdf's integral over cells (vectorised)."""
    if len(c0) == 0:
        return np.zeros(0)
    x, wq = np.polynomial.legendre.leggauss(ires)
    hc, hp = 0.5 * (c1 - c0), 0.5 * (p1 - p0)
    mc, mp = 0.5 * (c1 + c0), 0.5 * (p1 + p0)
    cc = mc[:, None, None] + hc[:, None, None] * x[None, :, None]
    pp = mp[:, None, None] + hp[:, None, None] * x[None, None, :]
    cc, pp = np.broadcast_arrays(cc, pp)
    vals = np.asarray(pdf(directions(cc.reshape(-1), pp.reshape(-1), phi0)), dtype=np.float64)
    if not np.all(np.isfinite(vals)):
        raise ValueError("pdf returned a non-finite value")
    vals = vals.reshape(len(c0), ires, ires)
    return (vals * (wq[:, None] * wq[None, :])).sum((1, 2)) * hc * hp


def chi2_test(sample, pdf, n_samples=200_000, *, seed=0, n_tests=1, rows=20, cols=20,
              adaptive=True, ires=6, significance=SIGNIFICANCE) -> Chi2Result:
    """Test `sample` against `pdf`.

    sample(u) -> (wi, valid): u is (n, 3) uniform in [0, 1) (dimension 0 for discrete
        choices, 1-2 for the direction); wi (n, 3) unit directions.
    pdf(wi) -> (m,) density in 1/sr of the directions `sample` returns.
    """
    rng = np.random.default_rng(seed)
    if adaptive:
        wp, vp = sample(rng.random((max(n_samples // 4, 1000), 3)))
        binning = SphereBinning.from_pilot(np.asarray(wp)[np.asarray(vp, bool)], rows, cols)
    else:
        binning = SphereBinning.uniform(rows, cols)
    wi, valid = sample(rng.random((n_samples, 3)))
    wi = np.asarray(wi, dtype=np.float64)
    valid = np.asarray(valid, bool)
    threshold = sidak(significance, n_tests)
    if not np.all(np.isfinite(wi[valid])):
        return Chi2Result(np.inf, 0, 0.0, threshold, 0, 0, np.nan, valid.mean(),
                          "non-finite sampled direction")
    observed = np.bincount(binning.cell_of(wi[valid]), minlength=binning.n_cells)
    integral = binning.integrate(pdf, ires)
    total = float(integral.sum())
    expected = n_samples * integral
    # the rejected samples: one more bin
    observed = np.append(observed, n_samples - valid.sum()).astype(np.float64)
    expected = np.append(expected, max(n_samples * (1.0 - total), 0.0))
    res = dict(threshold=threshold, n_cells=binning.n_cells, pdf_integral=total,
               valid_fraction=float(valid.mean()))
    zero = (expected <= 0.0) & (observed > 0)
    zero[-1] = False            # rejected samples: pooled like any small bin
    if zero.any():
        return Chi2Result(np.inf, 0, 0.0, n_bins=0,
                          message=f"{int(observed[zero].sum())} samples in cells of zero "
                                  f"expected count", **res)
    # pool cells with expected < 5 (Mitsuba: all into one); a pool still below 5 joins
    # the smallest regular bin
    low = expected < 5.0
    o_bins, e_bins = list(observed[~low]), list(expected[~low])
    o_pool, e_pool = observed[low].sum(), expected[low].sum()
    if e_pool >= 5.0 or not e_bins:
        o_bins.append(o_pool)
        e_bins.append(e_pool)
    elif e_pool > 0 or o_pool > 0:
        k = int(np.argmin(e_bins))
        o_bins[k] += o_pool
        e_bins[k] += e_pool
    o_bins, e_bins = np.asarray(o_bins), np.asarray(e_bins)
    if len(e_bins) < 2:
        return Chi2Result(0.0, 0, 1.0, n_bins=len(e_bins),
                          message="fewer than 2 bins: nothing to test", **res)
    stat = float(((o_bins - e_bins) ** 2 / e_bins).sum())
    dof = len(e_bins) - 1
    p = float(stats.chi2.sf(stat, dof))
    return Chi2Result(stat, dof, p, n_bins=len(e_bins), **res)

