"""One entry point per dimension count for all samplers, for the compiled kernels:
`kind` is the sampler's `Sampler.kind` (0 jittered, 1 Sobol, 2 random)."""
from __future__ import annotations

import numpy as np

from ..kernels.jit import kernel
from .hashing import pixel_key
from .independent import random_1d, random_2d
from .sobol import sobol_1d, sobol_2d
from .stratified import stratified_1d, stratified_2d


@kernel
def sample_1d(kind, pkey, spp, index, dim):
    if kind == 0:
        return stratified_1d(pkey, spp, index, dim)
    if kind == 1:
        return sobol_1d(pkey, index, dim)
    return random_1d(pkey, index, dim)


@kernel
def sample_2d(kind, pkey, spp, index, dim):
    if kind == 0:
        return stratified_2d(pkey, spp, index, dim)
    if kind == 1:
        return sobol_2d(pkey, index, dim)
    return random_2d(pkey, index, dim)


@kernel
def batch_1d(kind, seed, spp, dim, pixel, index):
    out = np.empty(pixel.shape[0])
    for r in range(pixel.shape[0]):
        out[r] = sample_1d(kind, pixel_key(seed, pixel[r]), spp, index[r], dim)
    return out


@kernel
def batch_2d(kind, seed, spp, dim, pixel, index):
    out = np.empty((pixel.shape[0], 2))
    for r in range(pixel.shape[0]):
        x, y = sample_2d(kind, pixel_key(seed, pixel[r]), spp, index[r], dim)
        out[r, 0] = x
        out[r, 1] = y
    return out


@kernel
def pixel_keys(seed, pixel):
    """`hashing.pixel_key` of every path of a work unit, computed once per unit."""
    out = np.empty(pixel.shape[0], np.uint64)
    for r in range(pixel.shape[0]):
        out[r] = pixel_key(seed, pixel[r])
    return out
