"""The sampler interface: random access to a pixel's sample values.

A sampler answers get_1d(dim, pixel, index) and get_2d(dim, pixel, index) for arrays of
pixel ids and sample indices. Values are pure functions of (seed, pixel, index, dim), so
any range of sample indices renders on its own and merges exactly (see
`engine.sampling.hashing`). Values are float64 in [0, 1).
"""
from __future__ import annotations

import numpy as np

from .hashing import hash_keys

ONE_MINUS_EPSILON = 1.0 - 2.0 ** -53


class Sampler:
    name = "abstract"

    def __init__(self, seed: int, samples_per_pixel: int):
        if samples_per_pixel < 1:
            raise ValueError("samples_per_pixel must be at least 1")
        self.seed = int(seed) & 0xFFFFFFFFFFFFFFFF
        self.samples_per_pixel = int(samples_per_pixel)

    def pattern_key(self, dim: int, pixel: np.ndarray) -> np.ndarray:
        """One 64-bit key per (seed, pixel, dimension): selects that pixel's permutation
        or scramble in that dimension."""
        return hash_keys(self.seed, pixel, dim)

    def get_1d(self, dim: int, pixel: np.ndarray, index: np.ndarray) -> np.ndarray:
        raise NotImplementedError  # interface; every concrete sampler overrides it

    def get_2d(self, dim: int, pixel: np.ndarray, index: np.ndarray) -> np.ndarray:
        raise NotImplementedError  # interface; every concrete sampler overrides it
