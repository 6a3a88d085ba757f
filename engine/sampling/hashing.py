"""Counter-based hashing: every random number is a pure function of its keys.

A sample value depends only on (seed, pixel, sample index, dimension), never on the order
in which samples are drawn, so any range of sample indices of any pixel renders on its
own and two halves of a render merge into exactly the same image as one whole render.

All arithmetic is on uint64 / uint32 NumPy arrays, where overflow wraps modulo 2**64
(or 2**32) as the mixing functions require.
"""
from __future__ import annotations

import numpy as np

_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_S30, _S27, _S31 = np.uint64(30), np.uint64(27), np.uint64(31)


def mix64(x: np.ndarray) -> np.ndarray:
    """SplitMix64's finaliser: a bijection on 64-bit words with full avalanche."""
    x = np.asarray(x, dtype=np.uint64)
    with np.errstate(over="ignore"):
        x = (x ^ (x >> _S30)) * _M1
        x = (x ^ (x >> _S27)) * _M2
    return x ^ (x >> _S31)


def hash_keys(*keys) -> np.ndarray:
    """Hash any number of integer keys (scalars or broadcastable arrays) to uint64."""
    h = np.uint64(0x243F6A8885A308D3)
    with np.errstate(over="ignore"):
        for k in keys:
            k = np.asarray(k).astype(np.uint64)
            h = mix64(h ^ (k + _GOLDEN))
    return np.asarray(h, dtype=np.uint64)


def to_unit_float(h: np.ndarray) -> np.ndarray:
    """The top 53 bits of a uint64 hash as a float64 in [0, 1)."""
    return (np.asarray(h, dtype=np.uint64) >> np.uint64(11)).astype(np.float64) * (1.0 / 9007199254740992.0)


def permute_index(i: np.ndarray, n, key: np.ndarray) -> np.ndarray:
    """A keyed pseudo-random permutation of range(n), evaluated element-wise.

    Each key selects one permutation; element i maps to perm_key(i). A four-round
    Feistel network on the smallest even number of bits 2h with 2**(2h) >= n (each round
    is a bijection whatever its round function, here SplitMix64 of the half and the key),
    with cycle walking back into [0, n): expected fewer than four steps per element.
    `n` may be a scalar or an array broadcastable with i.
    """
    i, n, key = np.broadcast_arrays(np.asarray(i, dtype=np.uint64),
                                    np.asarray(n, dtype=np.uint64),
                                    np.asarray(key, dtype=np.uint64))
    shape = i.shape
    n = n.ravel()
    bits = np.ceil(np.log2(np.maximum(n, 2).astype(np.float64))).astype(np.uint64)
    h = (bits + np.uint64(1)) >> np.uint64(1)           # half width, >= 1
    hmask = (np.uint64(1) << h) - np.uint64(1)
    round_keys = [mix64(key.ravel() ^ np.uint64(r * 0x9E3779B97F4A7C15 % 2**64)) for r in range(4)]
    x = i.ravel().copy()
    active = np.arange(x.size)
    for _ in range(256):                    # a walk this long has probability < 4**-256
        y, hh, hm = x[active], h[active], hmask[active]
        left, right = y >> hh, y & hm
        for rk in round_keys:
            left, right = right, left ^ (mix64(right ^ rk[active]) & hm)
        y = (left << hh) | right
        x[active] = y
        active = active[y >= n[active]]
        if active.size == 0:
            break
    return x.reshape(shape)
