"""Independent uniform random samples: the baseline the other samplers must beat."""
from __future__ import annotations

import numpy as np

from .hashing import hash_keys, to_unit_float
from .sampler import Sampler


class IndependentSampler(Sampler):
    name = "random"

    def get_1d(self, dim, pixel, index):
        return to_unit_float(hash_keys(self.seed, pixel, index, dim, 0))

    def get_2d(self, dim, pixel, index):
        h = hash_keys(self.seed, pixel, index, dim)
        return np.stack([to_unit_float(hash_keys(h, 1)), to_unit_float(hash_keys(h, 2))], axis=-1)
