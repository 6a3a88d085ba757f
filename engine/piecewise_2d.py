"""Piecewise-constant distributions on [0, 1] and [0, 1]^2, sampled by inverting their
CDFs (pbrt-v4's PiecewiseConstant1D / PiecewiseConstant2D; Cycles' background map).

A 2D function f (H rows, W columns; row r covers v in [r/H, (r+1)/H), column c covers
u in [c/W, (c+1)/W)) is sampled as
  row r from the marginal CDF  M[i] = sum_{r<i} sum_c f[r, c] / sum f  (H + 1 values),
  column c from row r's conditional CDF  C[r, j] = sum_{c<j} f[r, c] / sum_c f[r, c],
and inside the chosen cell linearly, so the map from u in [0,1)^2 to (u, v) is continuous
and monotonic in each coordinate (stratification survives). The density of that
procedure in (u, v) is
  pdf(u, v) = H (M[r+1] - M[r]) x W (C[r, c+1] - C[r, c]),
computed here from the CDFs themselves, so the pdf is the exact density of the sampler
(no separate table that could disagree with it by rounding). Cells of f = 0 have pdf 0
and are never sampled. A row (or the whole function) that is zero everywhere gets a
uniform CDF, so no division by zero; its rows have marginal probability 0 anyway.

f must be finite and >= 0 (callers pass magnitudes). The compiled twin is
`engine.kernels.lights.environment_map` (same arrays, same operations).
"""
from __future__ import annotations

import numpy as np


def cdf_1d(f) -> np.ndarray:
    """(n + 1,) CDF of the non-negative weights f (n,) along the last axis: 0 first, 1
    last exactly; uniform where the weights sum to zero. Works on (..., n) arrays."""
    f = np.asarray(f, dtype=np.float64)
    n = f.shape[-1]
    run = np.cumsum(f, axis=-1)
    total = run[..., -1:]
    uniform = np.broadcast_to(np.arange(1, n + 1) / n, f.shape)
    ok = total > 0
    cdf = np.where(ok, run / np.where(ok, total, 1.0), uniform)
    cdf[..., -1] = 1.0
    zero = np.zeros(f.shape[:-1] + (1,))
    return np.concatenate([zero, cdf], axis=-1)


def upper_bound(cdf, rows, u):
    """For each i, the number of entries of cdf[rows[i]] that are <= u[i] (searchsorted
    side='right' in each row), by a vectorised binary search (the kernels' loop)."""
    lo = np.zeros(len(u), dtype=np.int64)
    hi = np.full(len(u), cdf.shape[-1], dtype=np.int64)
    while True:
        todo = lo < hi
        if not todo.any():
            return lo
        mid = (lo + hi) >> 1
        below = cdf[rows, np.minimum(mid, cdf.shape[-1] - 1)] <= u
        lo = np.where(todo & below, mid + 1, lo)
        hi = np.where(todo & ~below, mid, hi)


def invert_cdf(cdf, rows, u):
    """(cell index, offset in [0, 1] within the cell) of uniforms u in the CDFs
    cdf[rows] ((m, n + 1) array): the last cell whose start is <= u (cells of zero width
    are skipped), the offset linear in u."""
    n = cdf.shape[-1] - 1
    i = np.clip(upper_bound(cdf, rows, u) - 1, 0, n - 1)
    lo, hi = cdf[rows, i], cdf[rows, i + 1]
    width = hi - lo
    off = np.where(width > 0, (u - lo) / np.where(width > 0, width, 1.0), 0.0)
    return i, np.clip(off, 0.0, 1.0)


class PiecewiseConstant2D:
    """Sample (u, v) in [0, 1)^2 with density proportional to f (see the module doc)."""

    def __init__(self, f):
        f = np.asarray(f, dtype=np.float64)
        if f.ndim != 2 or f.shape[0] < 1 or f.shape[1] < 1:
            raise ValueError(f"need a (rows, columns) function, got shape {f.shape}")
        if not (np.isfinite(f).all() and (f >= 0).all()):
            raise ValueError("the function must be finite and non-negative")
        self.height, self.width = f.shape
        self.conditional = np.ascontiguousarray(cdf_1d(f))          # (H, W + 1)
        self.marginal = np.ascontiguousarray(cdf_1d(f.sum(axis=1)))  # (H + 1,)
        self.integral = float(f.mean())                             # of f over [0,1]^2

    def sample(self, u):
        """u (n, 2) -> (uv (n, 2), pdf (n,) in (u, v) measure). u[:, 0] picks the row
        (v), u[:, 1] the column (u)."""
        u = np.asarray(u, dtype=np.float64)
        r, dv = invert_cdf(self.marginal[None, :], np.zeros(len(u), np.int64), u[:, 0])
        c, du = invert_cdf(self.conditional, r, u[:, 1])
        uv = np.stack([(c + du) / self.width, (r + dv) / self.height], axis=1)
        return uv, self.cell_pdf(r, c)

    def cell_pdf(self, r, c):
        """Density in (u, v) of the cells (row r, column c)."""
        m = self.marginal[r + 1] - self.marginal[r]
        k = self.conditional[r, c + 1] - self.conditional[r, c]
        return (self.height * m) * (self.width * k)

    def cell_of(self, uv):
        """(row, column) of the cells holding (u, v) (u wraps, v is clamped)."""
        uv = np.asarray(uv, dtype=np.float64)
        c = np.floor(np.mod(uv[:, 0], 1.0) * self.width).astype(np.int64)
        r = np.floor(uv[:, 1] * self.height).astype(np.int64)
        return np.clip(r, 0, self.height - 1), np.clip(c, 0, self.width - 1)

    def pdf(self, uv):
        """Density in (u, v) with which `sample` produces uv."""
        r, c = self.cell_of(uv)
        return self.cell_pdf(r, c)
