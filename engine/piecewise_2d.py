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

f must be finite and >= 0 (callers pass magnitudes). The sampling and the pdf are
computed by `engine.kernels.lights.environment_map` from these CDFs.
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
