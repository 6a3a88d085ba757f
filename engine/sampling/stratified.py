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
progressive rendering can ask for more samples without breaking anything.

Adaptive sampling stops a pixel at one of Cycles' checks: the first after `first` samples
(80 for Min Samples 64), then every `step` (engine.adaptive_sampling). A pixel stopped at
80 of 1024 would hold a random subset of 1024 strata, little better than random samples;
so under adaptive sampling the generations grow with the pixel instead: the first holds
the `first` samples, and each later one as many as all before it (80, 80, 160, 320, ...).
A pixel that stops holds whole stratified generations and part of one more, at most half
of its samples; one that runs on is stratified in ever larger sets. (`pattern(first,
doubling)` packs this into the one integer the kernels pass around as `spp`.)

`pkey` is the path's `hashing.pixel_key(seed, pixel)`; the key of one (pixel, dimension,
generation) continues that chain by one link. From that key, each permutation (the
sample's, and in 2D the column's and the row's) takes its own variant (the key XORed with
a constant; `permute` mixes it), and the jitter is one more link, with the sample: a 2D
sample costs 4 mixes plus 4 per Feistel walk step, about 17 in all.
"""
from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import kernel
from .hashing import chain, permute, unit_float
from .sampler import ONE_MINUS_EPSILON, Sampler


_LOW32 = (1 << 32) - 1
_S32 = np.uint64(32)
_COLUMN, _ROW = np.uint64(0x6A09E667F3BCC908), np.uint64(0xBB67AE8584CAA73B)
_JITTER = np.uint64(0x3C6EF372FE94F82B)


def pattern(first: int, doubling: bool = False) -> int:
    """Generations of `first` samples, or (doubling) of `first` and then each as large as
    all before it."""
    if not 1 <= first <= _LOW32:
        raise ValueError(f"bad stratification pattern ({first}, {doubling})")
    return first | (int(doubling) << 32)


@kernel
def _key(pkey, spp, index, dim):
    """(key of the generation of sample `index` in dimension `dim`, the sample's place in
    its generation, the generation's size), for the pattern `spp`."""
    packed = np.uint64(spp)
    first = packed & np.uint64(_LOW32)
    index = np.uint64(index)
    if (packed >> np.uint64(32)) == 0 or index < first:
        gen, s, n = index // first, index % first, first
    else:
        q = index // first                  # in [2^(g-1), 2^g) for generation g
        gen = np.uint64(0)
        while (np.uint64(1) << gen) <= q:
            gen += np.uint64(1)
        n = first << (gen - np.uint64(1))
        s = index - n
    return chain(pkey, np.uint64(dim) | (gen << _S32)), s, int(n)


@kernel
def stratified_1d(pkey, spp, index, dim):
    key, s, n = _key(pkey, spp, index, dim)
    stratum = permute(s, n, key)
    jitter = unit_float(chain(key ^ _JITTER, s))
    return min((np.float64(stratum) + jitter) / n, ONE_MINUS_EPSILON)


@kernel
def stratified_2d(pkey, spp, index, dim):
    key, s, spp = _key(pkey, spp, index, dim)
    m = max(1, int(math.floor(math.sqrt(spp))))
    n = (spp + m - 1) // m
    s = permute(s, spp, key)                               # Cook's ray-id chaining
    um = np.uint64(m)
    col = permute(s % um, m, key ^ _COLUMN)
    row = permute(s // um, n, key ^ _ROW)
    j = chain(key ^ _JITTER, s)                            # 32 bits of jitter each
    jx = np.float64(j >> _S32) * (1.0 / 4294967296.0)
    jy = np.float64(j & np.uint64(_LOW32)) * (1.0 / 4294967296.0)
    x = (np.float64(col) + (np.float64(row) + jx) / n) / m
    y = (np.float64(s) + jy) / spp
    return min(x, ONE_MINUS_EPSILON), min(y, ONE_MINUS_EPSILON)


class StratifiedSampler(Sampler):
    name = "jittered"
    kind = 0

    def follow_stops(self, first: int, step: int):
        """Stratify the first `first` samples on their own, then in doubling generations."""
        self.pattern = pattern(max(1, min(first, self.samples_per_pixel)), doubling=True)
