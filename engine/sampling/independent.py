"""Independent uniform random samples: the baseline the other samplers must beat."""
from __future__ import annotations

from ..kernels.jit import kernel
from .hashing import H0, chain, unit_float
from .sampler import Sampler


@kernel
def random_1d(pkey, index, dim):
    return unit_float(chain(chain(chain(pkey, index), dim), 0))


@kernel
def random_2d(pkey, index, dim):
    h = chain(chain(pkey, index), dim)
    return unit_float(chain(chain(H0, h), 1)), unit_float(chain(chain(H0, h), 2))


class IndependentSampler(Sampler):
    name = "random"
    kind = 2
