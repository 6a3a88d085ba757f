"""Jittered, stratified sampling with Cook's ray-id chaining.

For N samples per pixel, sample index s first passes through a per-(pixel, dimension)
permutation: that is Cook's chaining of ray ids, under which the sample that took
sub-pixel stratum k takes an unrelated stratum in the lens, time, light and reflection
dimensions, so every dimension is stratified and the dimensions are decorrelated.

1D: x = (perm(s) + jitter) / N, exactly one sample per stratum of width 1/N.
2D: correlated multi-jittering (Kensler 2013, "Correlated Multi-Jittered Sampling"):
with m = floor(sqrt(N)) columns and n = ceil(N/m) rows, each sample lies in its own
column and row sub-stratum, and the y projection is stratified into N strata; it works for
any N, not only squares.

Sample indices past N start a fresh, independently permuted generation of N, so
progressive and adaptive rendering can ask for more samples without breaking anything.

`pkey` is the path's `hashing.pixel_key(seed, pixel)`; the key of one (pixel, dimension,
generation) continues that chain.
"""
from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import kernel
from .hashing import H0, chain, permute, unit_float
from .sampler import ONE_MINUS_EPSILON, Sampler


@kernel
def _key(pkey, spp, index, dim):
    n = np.uint64(spp)
    index = np.uint64(index)
    return chain(chain(pkey, dim), index // n), index % n


@kernel
def stratified_1d(pkey, spp, index, dim):
    key, s = _key(pkey, spp, index, dim)
    stratum = permute(s, spp, key)
    jitter = unit_float(chain(chain(chain(H0, key), s), 11))
    return min((np.float64(stratum) + jitter) / spp, ONE_MINUS_EPSILON)


@kernel
def stratified_2d(pkey, spp, index, dim):
    key, s = _key(pkey, spp, index, dim)
    m = max(1, int(math.floor(math.sqrt(spp))))
    n = (spp + m - 1) // m
    s = permute(s, spp, key)                               # Cook's ray-id chaining
    um = np.uint64(m)
    col = permute(s % um, m, chain(chain(H0, key), 1))
    row = permute(s // um, n, chain(chain(H0, key), 2))
    jx = unit_float(chain(chain(chain(H0, key), s), 3))
    jy = unit_float(chain(chain(chain(H0, key), s), 4))
    x = (np.float64(col) + (np.float64(row) + jx) / n) / m
    y = (np.float64(s) + jy) / spp
    return min(x, ONE_MINUS_EPSILON), min(y, ONE_MINUS_EPSILON)


class StratifiedSampler(Sampler):
    name = "jittered"
    kind = 0
