"""The sampler interface: random access to a pixel's sample values.

A sampler answers get_1d(dim, pixel, index) and get_2d(dim, pixel, index) for arrays of
pixel ids and sample indices. Values are pure functions of (seed, pixel, index, dim), so
any range of sample indices renders on its own and merges exactly (see
`engine.sampling.hashing`). Values are float64 in [0, 1).

Inside the compiled kernels the same values come from `dispatch.sample_1d/2d(kind, pkey,
spp, index, dim)`, with the path's pixel key computed once (`hashing.pixel_key`).
"""
from __future__ import annotations

import numpy as np

ONE_MINUS_EPSILON = 1.0 - 2.0 ** -53


class Sampler:
    name = "abstract"
    kind = -1          # the sampler's id in the compiled dispatch

    def __init__(self, seed: int, samples_per_pixel: int):
        if samples_per_pixel < 1:
            raise ValueError("samples_per_pixel must be at least 1")
        self.seed = int(seed) & 0xFFFFFFFFFFFFFFFF
        self.samples_per_pixel = int(samples_per_pixel)
        # what the compiled dispatch receives as `spp`: how a pixel's sample indices group
        # into generations (only the jittered sampler has any; see stratified.pattern)
        self.pattern = self.samples_per_pixel

    def follow_stops(self, first: int, step: int):
        """Adaptive sampling stops pixels after `first` + k * `step` samples; samplers
        whose point sets are not progressive regroup them to match (default: nothing to
        do, every prefix is well distributed)."""

    def _arrays(self, pixel, index):
        pixel, index = np.broadcast_arrays(np.asarray(pixel, dtype=np.int64),
                                           np.asarray(index, dtype=np.int64))
        return pixel.shape, np.array(pixel.ravel()), np.array(index.ravel())

    def get_1d(self, dim: int, pixel: np.ndarray, index: np.ndarray) -> np.ndarray:
        from .dispatch import batch_1d
        shape, p, i = self._arrays(pixel, index)
        return batch_1d(self.kind, np.uint64(self.seed), self.pattern, dim, p,
                        i).reshape(shape)

    def get_2d(self, dim: int, pixel: np.ndarray, index: np.ndarray) -> np.ndarray:
        from .dispatch import batch_2d
        shape, p, i = self._arrays(pixel, index)
        return batch_2d(self.kind, np.uint64(self.seed), self.pattern, dim, p,
                        i).reshape(shape + (2,))
