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
"""
from __future__ import annotations

import numpy as np

from .hashing import hash_keys, permute_index, to_unit_float
from .sampler import ONE_MINUS_EPSILON, Sampler


class StratifiedSampler(Sampler):
    name = "jittered"

    def _split(self, dim, pixel, index):
        index = np.asarray(index, dtype=np.uint64)
        n = np.uint64(self.samples_per_pixel)
        generation = index // n
        local = index % n
        key = hash_keys(self.seed, pixel, dim, generation)
        return key, local

    def get_1d(self, dim, pixel, index):
        key, s = self._split(dim, pixel, index)
        n = self.samples_per_pixel
        stratum = permute_index(s, n, key)
        jitter = to_unit_float(hash_keys(key, s, 11))
        return np.minimum((stratum + jitter) / n, ONE_MINUS_EPSILON)

    def get_2d(self, dim, pixel, index):
        key, s = self._split(dim, pixel, index)
        big_n = self.samples_per_pixel
        m = max(1, int(np.floor(np.sqrt(big_n))))
        n = (big_n + m - 1) // m
        s = permute_index(s, big_n, key)                    # Cook's ray-id chaining
        col = permute_index(s % np.uint64(m), m, hash_keys(key, 1))
        row = permute_index(s // np.uint64(m), n, hash_keys(key, 2))
        jx = to_unit_float(hash_keys(key, s, 3))
        jy = to_unit_float(hash_keys(key, s, 4))
        x = (col + (row + jx) / n) / m
        y = (s + jy) / big_n
        return np.minimum(np.stack([x, y], axis=-1), ONE_MINUS_EPSILON)
