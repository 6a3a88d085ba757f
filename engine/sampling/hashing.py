"""Counter-based hashing: every random number is a pure function of its keys.

A sample value depends only on (seed, pixel, sample index, dimension), never on the order
in which samples are drawn, so any range of sample indices of any pixel renders on its
own and two halves of a render merge into exactly the same image as one whole render.

The functions are compiled scalar kernels on uint64 words (overflow wraps modulo 2**64,
as the mixing functions require); `hash_keys` and `permute_index` also take NumPy arrays
for callers outside the kernels.

A hash of several keys is a chain: h = mix64(h ^ (key + GOLDEN)) per key, starting from
H0. So the prefix over (seed, pixel) is computed once per path (`pixel_key`) and every
dimension's key continues the chain from there: the same value as hashing all the keys
at once.
"""
from __future__ import annotations

import numpy as np

from ..kernels.jit import kernel

H0 = np.uint64(0x243F6A8885A308D3)
GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31 = np.uint64(30), np.uint64(27), np.uint64(31)
_S11 = np.uint64(11)
_ONE = np.uint64(1)


@kernel
def mix64(x):
    """SplitMix64's finaliser: a bijection on 64-bit words with full avalanche."""
    x = np.uint64(x)
    x = (x ^ (x >> _S30)) * _M1
    x = (x ^ (x >> _S27)) * _M2
    return x ^ (x >> _S31)


@kernel
def chain(h, key):
    """One link of the key chain: h, then key."""
    return mix64(np.uint64(h) ^ (np.uint64(key) + GOLDEN))


@kernel
def pixel_key(seed, pixel):
    """The chain over (seed, pixel): computed once per path, continued per dimension."""
    return chain(chain(H0, seed), pixel)


@kernel
def unit_float(h):
    """The top 53 bits of a uint64 hash as a float64 in [0, 1)."""
    return np.float64(np.uint64(h) >> _S11) * (1.0 / 9007199254740992.0)


# Each Feistel round's key is the permutation's key, mixed once, XORed with its own
# constant (the round function mixes the result again)
_R0, _R1 = np.uint64(0x9E3779B97F4A7C15), np.uint64(0x3C6EF372FE94F82A)
_R2, _R3 = np.uint64(0xDAA66D2C7DDF743F), np.uint64(0x78DDE6E5FD29F054)


@kernel
def permute(i, n, key):
    """A keyed pseudo-random permutation of range(n), evaluated at i.

    Each key selects one permutation. A four-round Feistel network on exactly the b bits
    that hold n - 1 (unbalanced when b is odd: halves of floor(b/2) and ceil(b/2) bits
    that swap places every round, so four rounds restore them; each round is a bijection
    whatever its round function, here SplitMix64 of the half and the round's key), with
    cycle walking back into [0, n): fewer than two steps per value on average, whatever
    n is. The round keys are one mix of the key, each XORed with its own constant: one
    mix64 per permutation, four per step of the walk. For n = 2 a key bit decides the
    swap."""
    n = np.uint64(n)
    x = np.uint64(i)
    if n <= _ONE:
        return np.uint64(0)
    h = mix64(key)
    bits = np.uint64(1)
    while (_ONE << bits) < n:
        bits += _ONE
    if bits == _ONE:
        return x ^ (h & _ONE)
    a = bits >> _ONE              # width of the left half; the right half has bits - a
    b = bits - a
    r0, r1, r2, r3 = h ^ _R0, h ^ _R1, h ^ _R2, h ^ _R3
    ma, mb = (_ONE << a) - _ONE, (_ONE << b) - _ONE
    for _ in range(1024):         # a walk this long has probability < 2**-1024
        left, right = x >> b, x & mb                      # widths (a, b)
        left, right = right, left ^ (mix64(right ^ r0) & ma)   # (b, a)
        left, right = right, left ^ (mix64(right ^ r1) & mb)   # (a, b)
        left, right = right, left ^ (mix64(right ^ r2) & ma)   # (b, a)
        left, right = right, left ^ (mix64(right ^ r3) & mb)   # (a, b)
        x = (left << b) | right
        if x < n:
            break
    return x


@kernel
def _hash_rows(keys):
    out = np.empty(keys.shape[0], np.uint64)
    for r in range(keys.shape[0]):
        h = H0
        for c in range(keys.shape[1]):
            h = chain(h, keys[r, c])
        out[r] = h
    return out


@kernel
def _permute_rows(i, n, key):
    out = np.empty(i.shape[0], np.uint64)
    for r in range(i.shape[0]):
        out[r] = permute(i[r], n[r], key[r])
    return out


def hash_keys(*keys) -> np.ndarray:
    """Hash any number of integer keys (scalars or broadcastable arrays) to uint64."""
    arrays = np.broadcast_arrays(*[np.asarray(k).astype(np.uint64) for k in keys])
    shape = arrays[0].shape
    stacked = np.stack([a.ravel() for a in arrays], axis=1)
    return _hash_rows(np.ascontiguousarray(stacked)).reshape(shape)


def to_unit_float(h: np.ndarray) -> np.ndarray:
    """The top 53 bits of a uint64 hash as a float64 in [0, 1)."""
    return (np.asarray(h, dtype=np.uint64) >> np.uint64(11)).astype(np.float64) \
        * (1.0 / 9007199254740992.0)


def permute_index(i, n, key) -> np.ndarray:
    """`permute` element-wise over broadcastable arrays i, n, key."""
    i, n, key = np.broadcast_arrays(np.asarray(i, dtype=np.uint64),
                                    np.asarray(n, dtype=np.uint64),
                                    np.asarray(key, dtype=np.uint64))
    shape = i.shape
    out = _permute_rows(np.array(i.ravel()), np.array(n.ravel()), np.array(key.ravel()))
    return out.reshape(shape)


@kernel
def stream_key(pkey, index, salt, depth):
    """A hashed random stream of sample `index` of pixel key pkey at wavefront step
    `depth`, apart from every other stream by `salt` (a volume's tracking, a subsurface
    walk): numbers without count, for loops of unbounded length."""
    return chain(chain(chain(pkey, index), salt), depth)


@kernel
def stream_uniform(key, step, j):
    """Number j of step `step` of stream `key` (stream_key), in [0, 1)."""
    return unit_float(chain(chain(key, step), j))
