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

from ..kernels.jit import kernel
from .hashing import H0, chain
from .sampler import ONE_MINUS_EPSILON, Sampler

_MASK32 = np.uint64(0xFFFFFFFF)


def _direction_numbers_dim1() -> np.ndarray:
    v = np.zeros(32, dtype=np.uint64)
    v[0] = 1 << 31
    for k in range(1, 32):
        v[k] = int(v[k - 1]) ^ (int(v[k - 1]) >> 1)
    return v


_V1 = _direction_numbers_dim1()


@kernel
def reverse_bits32(x):
    """The 32 low bits of x in reverse order (a uint64 holding a 32-bit word)."""
    x = np.uint64(x) & _MASK32
    x = ((x >> np.uint64(1)) & np.uint64(0x55555555)) | ((x & np.uint64(0x55555555)) << np.uint64(1))
    x = ((x >> np.uint64(2)) & np.uint64(0x33333333)) | ((x & np.uint64(0x33333333)) << np.uint64(2))
    x = ((x >> np.uint64(4)) & np.uint64(0x0F0F0F0F)) | ((x & np.uint64(0x0F0F0F0F)) << np.uint64(4))
    x = ((x >> np.uint64(8)) & np.uint64(0x00FF00FF)) | ((x & np.uint64(0x00FF00FF)) << np.uint64(8))
    return ((x >> np.uint64(16)) | (x << np.uint64(16))) & _MASK32


def _byte_tables(v: np.ndarray) -> np.ndarray:
    """(4, 256): entry [k, b] is the XOR of the direction numbers v[8k + j] over the set
    bits j of byte b, so a 32-bit index needs four look-ups instead of a loop over bits."""
    t = np.zeros((4, 256), dtype=np.uint64)
    for k in range(4):
        for byte in range(256):
            acc = 0
            for j in range(8):
                if byte >> j & 1:
                    acc ^= int(v[8 * k + j])
            t[k, byte] = acc
    return t


_V1_BYTES = _byte_tables(_V1)


@kernel
def sobol_dim1_word(index):
    """Unscrambled Sobol dimension 1 of a 32-bit index, as 32-bit fixed point."""
    index = np.uint64(index) & _MASK32
    m = np.uint64(0xFF)
    return (_V1_BYTES[0, index & m] ^ _V1_BYTES[1, (index >> np.uint64(8)) & m]
            ^ _V1_BYTES[2, (index >> np.uint64(16)) & m] ^ _V1_BYTES[3, index >> np.uint64(24)])


@kernel
def _laine_karras(x, seed):
    """Burley's improved Laine-Karras hash on 32-bit words: on bit-reversed values it is a
    nested uniform (Owen) scramble, each bit flipped by a hash of the bits above it."""
    x = (np.uint64(x) + np.uint64(seed)) & _MASK32
    x ^= (x * np.uint64(0x6C50B47C)) & _MASK32
    x ^= (x * np.uint64(0xB82F1E52)) & _MASK32
    x ^= (x * np.uint64(0xC7AFE638)) & _MASK32
    x ^= (x * np.uint64(0x8D22F6E6)) & _MASK32
    return x


@kernel
def owen_scramble(x, seed):
    return reverse_bits32(_laine_karras(reverse_bits32(x), seed))


@kernel
def _to_float(x32):
    return min(np.float64(x32) * (1.0 / 4294967296.0), ONE_MINUS_EPSILON)


@kernel
def _seeds(pkey, dim):
    h = chain(pkey, dim)
    return (chain(chain(H0, h), 0) & _MASK32, chain(chain(H0, h), 1) & _MASK32,
            chain(chain(H0, h), 2) & _MASK32)


@kernel
def sobol_1d(pkey, index, dim):
    s_index, s_x, _ = _seeds(pkey, dim)
    i = owen_scramble(np.uint64(index) & _MASK32, s_index)
    return _to_float(owen_scramble(reverse_bits32(i), s_x))


@kernel
def sobol_2d(pkey, index, dim):
    s_index, s_x, s_y = _seeds(pkey, dim)
    i = owen_scramble(np.uint64(index) & _MASK32, s_index)
    return (_to_float(owen_scramble(reverse_bits32(i), s_x)),
            _to_float(owen_scramble(sobol_dim1_word(i), s_y)))


@kernel
def _words(f, index):
    out = np.empty(index.shape[0], np.uint64)
    for r in range(index.shape[0]):
        out[r] = f(index[r])
    return out


def sobol_dim0(index: np.ndarray) -> np.ndarray:
    """Unscrambled Sobol dimension 0 as 32-bit fixed point (bit reversal of the index)."""
    index = np.asarray(index, dtype=np.uint64)
    return _words(reverse_bits32, index.ravel()).reshape(index.shape)


def sobol_dim1(index: np.ndarray) -> np.ndarray:
    """Unscrambled Sobol dimension 1 as 32-bit fixed point."""
    index = np.asarray(index, dtype=np.uint64)
    return _words(sobol_dim1_word, index.ravel()).reshape(index.shape)


class SobolSampler(Sampler):
    name = "sobol"
    kind = 1
