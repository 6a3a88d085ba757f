"""Blender's hashes for procedural textures (Cycles' util/hash.h): Bob Jenkins' lookup3
hash of one to four 32-bit words (hash_uint .. hash_uint4), the float hashes built on
it, which hash the bits of float32 values (Cycles computes in float32, so a float64
input is first rounded to float32, then its bit pattern is hashed), and the PCG hashes
of 2 to 4 signed integers (Jarzynski and Olano 2020) that Voronoi uses for its cells.

Every 32-bit operation is done on int64 and wrapped to 32 bits, as C's uint32 (masked)
or int32 (two's complement, arithmetic shifts) arithmetic wraps.

  hash_uint*(k...)              a uint32 (as int) from one to four uint32 words
  hash_float*_to_float(x...)    a float in [0, 1] from one to four floats
  hash_float{1,2,3,4}_to_float3 three such floats (White Noise's colours, Voronoi 1D's)
  hash_int{2,3,4}_to_float{2,3,4}  floats in [0, 1] from integer coordinates (PCG)
"""
from __future__ import annotations

import numpy as np

from ..kernels.jit import kernel

M32 = 0xFFFFFFFF
SEED = 0xDEADBEEF
INV_2_32 = 1.0 / 4294967296.0     # float(0xFFFFFFFF) rounds to 2^32 in float32


@kernel(allocates=False)
def rot(x, k):
    return ((x << k) | (x >> (32 - k))) & M32


@kernel(allocates=False)
def mix(a, b, c):
    """lookup3's mix(a, b, c)."""
    a = ((a - c) & M32) ^ rot(c, 4)
    c = (c + b) & M32
    b = ((b - a) & M32) ^ rot(a, 6)
    a = (a + c) & M32
    c = ((c - b) & M32) ^ rot(b, 8)
    b = (b + a) & M32
    a = ((a - c) & M32) ^ rot(c, 16)
    c = (c + b) & M32
    b = ((b - a) & M32) ^ rot(a, 19)
    a = (a + c) & M32
    c = ((c - b) & M32) ^ rot(b, 4)
    b = (b + a) & M32
    return a, b, c


@kernel(allocates=False)
def final(a, b, c):
    """lookup3's final(a, b, c): the mixed c."""
    c = ((c ^ b) - rot(b, 14)) & M32
    a = ((a ^ c) - rot(c, 11)) & M32
    b = ((b ^ a) - rot(a, 25)) & M32
    c = ((c ^ b) - rot(b, 16)) & M32
    a = ((a ^ c) - rot(c, 4)) & M32
    b = ((b ^ a) - rot(a, 14)) & M32
    c = ((c ^ b) - rot(b, 24)) & M32
    return c


@kernel(allocates=False)
def hash_uint(kx):
    a = (SEED + (1 << 2) + 13) & M32
    return final((a + kx) & M32, a, a)


@kernel(allocates=False)
def hash_uint2(kx, ky):
    a = (SEED + (2 << 2) + 13) & M32
    return final((a + kx) & M32, (a + ky) & M32, a)


@kernel(allocates=False)
def hash_uint3(kx, ky, kz):
    a = (SEED + (3 << 2) + 13) & M32
    return final((a + kx) & M32, (a + ky) & M32, (a + kz) & M32)


@kernel(allocates=False)
def hash_uint4(kx, ky, kz, kw):
    s = (SEED + (4 << 2) + 13) & M32
    a, b, c = mix((s + kx) & M32, (s + ky) & M32, (s + kz) & M32)
    return final((a + kw) & M32, b, c)


@kernel(allocates=False)
def float_bits(x):
    """The bit pattern of x rounded to float32, as a non-negative int."""
    return np.int64(np.float32(x).view(np.uint32))


@kernel(allocates=False)
def uint_to_float(n):
    """[0, 2^32) -> [0, 1] as Cycles' uint_to_float_incl: float32(n) / 2^32."""
    return float(np.float32(n)) * INV_2_32


@kernel(allocates=False)
def hash_float_to_float(x):
    return uint_to_float(hash_uint(float_bits(x)))


@kernel(allocates=False)
def hash_float2_to_float(x, y):
    return uint_to_float(hash_uint2(float_bits(x), float_bits(y)))


@kernel(allocates=False)
def hash_float3_to_float(x, y, z):
    return uint_to_float(hash_uint3(float_bits(x), float_bits(y), float_bits(z)))


@kernel(allocates=False)
def hash_float4_to_float(x, y, z, w):
    return uint_to_float(hash_uint4(float_bits(x), float_bits(y), float_bits(z),
                                    float_bits(w)))


@kernel(allocates=False)
def hash_float1_to_float3(x):
    return (hash_float_to_float(x), hash_float2_to_float(x, 1.0),
            hash_float2_to_float(x, 2.0))


@kernel(allocates=False)
def hash_float2_to_float3(x, y):
    return (hash_float2_to_float(x, y), hash_float3_to_float(x, y, 1.0),
            hash_float3_to_float(x, y, 2.0))


@kernel(allocates=False)
def hash_float3_to_float3(x, y, z):
    return (hash_float3_to_float(x, y, z), hash_float4_to_float(x, y, z, 1.0),
            hash_float4_to_float(x, y, z, 2.0))


@kernel(allocates=False)
def hash_float4_to_float3(x, y, z, w):
    return (hash_float4_to_float(x, y, z, w), hash_float4_to_float(z, x, w, y),
            hash_float4_to_float(w, z, y, x))


# ---------------------------------------------------------------- PCG (signed int32)
PCG_A = 1664525
PCG_C = 1013904223
INV_2_31 = 1.0 / 2147483648.0     # float(0x7FFFFFFF) rounds to 2^31 in float32


@kernel(allocates=False)
def i32(x):
    """x wrapped to a signed 32-bit integer."""
    return ((x + 0x80000000) & M32) - 0x80000000


@kernel(allocates=False)
def pcg_to_float(h):
    return float(np.float32(h & 0x7FFFFFFF)) * INV_2_31


@kernel(allocates=False)
def hash_int2_to_float2(x, y):
    x = i32(x * PCG_A + PCG_C)
    y = i32(y * PCG_A + PCG_C)
    x = i32(x + y * PCG_A)
    y = i32(y + x * PCG_A)
    x, y = x ^ (x >> 16), y ^ (y >> 16)
    x = i32(x + y * PCG_A)
    y = i32(y + x * PCG_A)
    return pcg_to_float(x), pcg_to_float(y)


@kernel(allocates=False)
def hash_int3_to_float3(x, y, z):
    x = i32(x * PCG_A + PCG_C)
    y = i32(y * PCG_A + PCG_C)
    z = i32(z * PCG_A + PCG_C)
    for rnd in range(2):
        if rnd == 1:
            x, y, z = x ^ (x >> 16), y ^ (y >> 16), z ^ (z >> 16)
        x = i32(x + y * z)
        y = i32(y + z * x)
        z = i32(z + x * y)
    return pcg_to_float(x), pcg_to_float(y), pcg_to_float(z)


@kernel(allocates=False)
def hash_int4_to_float4(x, y, z, w):
    x = i32(x * PCG_A + PCG_C)
    y = i32(y * PCG_A + PCG_C)
    z = i32(z * PCG_A + PCG_C)
    w = i32(w * PCG_A + PCG_C)
    for rnd in range(2):
        if rnd == 1:
            x, y, z, w = x ^ (x >> 16), y ^ (y >> 16), z ^ (z >> 16), w ^ (w >> 16)
        x = i32(x + y * w)
        y = i32(y + z * x)
        z = i32(z + x * y)
        w = i32(w + y * z)
    return pcg_to_float(x), pcg_to_float(y), pcg_to_float(z), pcg_to_float(w)
