"""Owen-scrambled Sobol points, random access per pixel (quasi-Monte Carlo).

Each 2D dimension uses the first two Sobol dimensions (the radix-2 van der Corput
sequence and its companion with direction numbers v_k = v_{k-1} xor (v_{k-1} >> 1)),
with the sample index shuffled and each coordinate Owen-scrambled by a hash keyed on
(seed, pixel, dimension): Burley 2020, "Practical Hash-based Owen Scrambling". Every
prefix of 2**k samples of a pixel is then a (0, k, 2)-net in each 2D dimension, and the
dimensions are decorrelated by their independent index shuffles.

Why not scipy.stats.qmc.Sobol: it generates one sequence front to back with one scramble,
while a renderer needs a different scramble per pixel and random access to any sample
index of any pixel, vectorised over millions of (pixel, index) pairs. The test suite
checks the unscrambled points here against scipy's first two Sobol dimensions.
"""
from __future__ import annotations

import numpy as np

from .hashing import hash_keys
from .sampler import ONE_MINUS_EPSILON, Sampler

_U32 = np.uint32


def _direction_numbers_dim1() -> np.ndarray:
    v = np.zeros(32, dtype=np.uint64)
    v[0] = 1 << 31
    for k in range(1, 32):
        v[k] = int(v[k - 1]) ^ (int(v[k - 1]) >> 1)
    return v.astype(np.uint32)


_V1 = _direction_numbers_dim1()


def reverse_bits32(x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, dtype=np.uint32)
    x = ((x >> _U32(1)) & _U32(0x55555555)) | ((x & _U32(0x55555555)) << _U32(1))
    x = ((x >> _U32(2)) & _U32(0x33333333)) | ((x & _U32(0x33333333)) << _U32(2))
    x = ((x >> _U32(4)) & _U32(0x0F0F0F0F)) | ((x & _U32(0x0F0F0F0F)) << _U32(4))
    x = ((x >> _U32(8)) & _U32(0x00FF00FF)) | ((x & _U32(0x00FF00FF)) << _U32(8))
    return (x >> _U32(16)) | (x << _U32(16))


def sobol_dim0(index: np.ndarray) -> np.ndarray:
    """Unscrambled Sobol dimension 0 as 32-bit fixed point (bit reversal of the index)."""
    return reverse_bits32(index)


def sobol_dim1(index: np.ndarray) -> np.ndarray:
    """Unscrambled Sobol dimension 1 as 32-bit fixed point."""
    index = np.asarray(index, dtype=np.uint32)
    out = np.zeros(index.shape, dtype=np.uint32)
    for k in range(32):
        bit = (index >> _U32(k)) & _U32(1)
        if not bit.any():
            if (index >> _U32(k)).max(initial=0) == 0:
                break
            continue
        out ^= _V1[k] * bit
    return out


def _laine_karras(x: np.ndarray, seed: np.ndarray) -> np.ndarray:
    """Burley's improved Laine-Karras hash: on bit-reversed values it is a nested
    uniform (Owen) scramble, each bit flipped by a hash of the bits above it."""
    with np.errstate(over="ignore"):
        x = x + seed
        x ^= x * _U32(0x6C50B47C)
        x ^= x * _U32(0xB82F1E52)
        x ^= x * _U32(0xC7AFE638)
        x ^= x * _U32(0x8D22F6E6)
    return x


def owen_scramble(x: np.ndarray, seed: np.ndarray) -> np.ndarray:
    return reverse_bits32(_laine_karras(reverse_bits32(x), seed))


def _to_float(x32: np.ndarray) -> np.ndarray:
    # add half a fixed-point step of jitter-free centring is not wanted: Owen scrambling
    # already randomises the low bits; map to [0,1) exactly.
    return np.minimum(x32.astype(np.float64) * (1.0 / 4294967296.0), ONE_MINUS_EPSILON)


class SobolSampler(Sampler):
    name = "sobol"

    def _seeds(self, dim, pixel):
        h = hash_keys(self.seed, pixel, dim)
        s = [(hash_keys(h, k) & np.uint64(0xFFFFFFFF)).astype(np.uint32) for k in range(3)]
        return s

    def get_1d(self, dim, pixel, index):
        s_index, s_x, _ = self._seeds(dim, pixel)
        i = owen_scramble(np.asarray(index, dtype=np.uint64).astype(np.uint32), s_index)
        return _to_float(owen_scramble(sobol_dim0(i), s_x))

    def get_2d(self, dim, pixel, index):
        s_index, s_x, s_y = self._seeds(dim, pixel)
        i = owen_scramble(np.asarray(index, dtype=np.uint64).astype(np.uint32), s_index)
        x = owen_scramble(sobol_dim0(i), s_x)
        y = owen_scramble(sobol_dim1(i), s_y)
        return np.stack([_to_float(x), _to_float(y)], axis=-1)
