"""Blender's Perlin noise and its fractals (Cycles' svm/noise.h, fractal_noise.h,
noisetex.h), in 1 to 4 dimensions.

Perlin noise: the lattice cell of the point (floor, as int), a gradient per corner
chosen by the lookup3 hash of the corner's integer coordinates (hash.hash_uint*), the
quintic fade 6t^5 - 15t^4 + 10t^3, multilinear interpolation; scaled per dimension to
about [-1, 1] (snoise) and repeated every 100000 on each axis, as Cycles does.

A point is (dim, x, y, z, w): its first `dim` coordinates are used (a 1D point is x).
Fractals (FRACTAL_TYPES, the Noise Texture's types) sum octaves at coordinates scaled
by Lacunarity, amplitude scaled by Roughness; Detail counts the octaves after the first,
its fraction blending in one more. `noise_texture` is the node: optional distortion of
the point by noise at random offsets, the fractal's value, and its colour (two more
fractals at other offsets).
"""
from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import kernel
from .hash import M32, hash_float2_to_float, hash_float_to_float, hash_uint, hash_uint2, \
    hash_uint3, hash_uint4

FRACTAL_TYPES = ("MULTIFRACTAL", "FBM", "HYBRID_MULTIFRACTAL", "RIDGED_MULTIFRACTAL",
                 "HETERO_TERRAIN")
MULTIFRACTAL, FBM, HYBRID_MULTIFRACTAL, RIDGED_MULTIFRACTAL, HETERO_TERRAIN = range(5)
NOISE_SCALE = (0.0, 0.25, 0.6616, 0.9820, 0.8344)     # per dimension (OSL's constants)


@kernel(allocates=False)
def fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


@kernel(allocates=False)
def lerp(a, b, t):
    return (1.0 - t) * a + t * b


@kernel(allocates=False)
def grad1(h, x):
    h = h & 15
    g = 1.0 + (h & 7)
    return -g * x if h & 8 else g * x


@kernel(allocates=False)
def grad2(h, x, y):
    h = h & 7
    u = x if h < 4 else y
    v = 2.0 * (y if h < 4 else x)
    return (-u if h & 1 else u) + (-v if h & 2 else v)


@kernel(allocates=False)
def grad3(h, x, y, z):
    h = h & 15
    u = x if h < 8 else y
    v = y if h < 4 else (x if h == 12 or h == 14 else z)
    return (-u if h & 1 else u) + (-v if h & 2 else v)


@kernel(allocates=False)
def grad4(h, x, y, z, w):
    h = h & 31
    u = x if h < 24 else y
    v = y if h < 16 else z
    s = z if h < 8 else w
    return (-u if h & 1 else u) + (-v if h & 2 else v) + (-s if h & 4 else s)


@kernel(allocates=False)
def perlin(dim, x, y, z, w):
    """Unscaled Perlin noise of the point's first `dim` coordinates."""
    fx, fy, fz, fw = math.floor(x), math.floor(y), math.floor(z), math.floor(w)
    X, Y, Z, W = int(fx) & M32, int(fy) & M32, int(fz) & M32, int(fw) & M32
    X1, Y1, Z1, W1 = (X + 1) & M32, (Y + 1) & M32, (Z + 1) & M32, (W + 1) & M32
    x, y, z, w = x - fx, y - fy, z - fz, w - fw
    u = fade(x)
    if dim == 1:
        return lerp(grad1(hash_uint(X), x), grad1(hash_uint(X1), x - 1.0), u)
    v = fade(y)
    if dim == 2:
        return lerp(lerp(grad2(hash_uint2(X, Y), x, y), grad2(hash_uint2(X1, Y), x - 1.0, y), u),
                    lerp(grad2(hash_uint2(X, Y1), x, y - 1.0),
                         grad2(hash_uint2(X1, Y1), x - 1.0, y - 1.0), u), v)
    t = fade(z)
    if dim == 3:
        r = 0.0
        for k in range(2):
            Zk, zk = (Z, z) if k == 0 else (Z1, z - 1.0)
            a = lerp(grad3(hash_uint3(X, Y, Zk), x, y, zk),
                     grad3(hash_uint3(X1, Y, Zk), x - 1.0, y, zk), u)
            b = lerp(grad3(hash_uint3(X, Y1, Zk), x, y - 1.0, zk),
                     grad3(hash_uint3(X1, Y1, Zk), x - 1.0, y - 1.0, zk), u)
            r += lerp(a, b, v) * (1.0 - t if k == 0 else t)
        return r
    s = fade(w)
    r = 0.0
    for m in range(2):
        Wm, wm = (W, w) if m == 0 else (W1, w - 1.0)
        for k in range(2):
            Zk, zk = (Z, z) if k == 0 else (Z1, z - 1.0)
            a = lerp(grad4(hash_uint4(X, Y, Zk, Wm), x, y, zk, wm),
                     grad4(hash_uint4(X1, Y, Zk, Wm), x - 1.0, y, zk, wm), u)
            b = lerp(grad4(hash_uint4(X, Y1, Zk, Wm), x, y - 1.0, zk, wm),
                     grad4(hash_uint4(X1, Y1, Zk, Wm), x - 1.0, y - 1.0, zk, wm), u)
            r += lerp(a, b, v) * (1.0 - t if k == 0 else t) * (1.0 - s if m == 0 else s)
    return r


@kernel(allocates=False)
def snoise(dim, x, y, z, w):
    """Signed noise, about [-1, 1]."""
    r = perlin(dim, np.fmod(x, 100000.0), np.fmod(y, 100000.0), np.fmod(z, 100000.0),
               np.fmod(w, 100000.0))
    return NOISE_SCALE[dim] * r


@kernel(allocates=False)
def fbm(dim, x, y, z, w, detail, roughness, lacunarity, normalize):
    fscale = 1.0
    amp = 1.0
    maxamp = 0.0
    total = 0.0
    for _ in range(int(detail) + 1):
        total += snoise(dim, fscale * x, fscale * y, fscale * z, fscale * w) * amp
        maxamp += amp
        amp *= roughness
        fscale *= lacunarity
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        total2 = total + snoise(dim, fscale * x, fscale * y, fscale * z, fscale * w) * amp
        if normalize:
            return lerp(0.5 * total / maxamp + 0.5, 0.5 * total2 / (maxamp + amp) + 0.5, rmd)
        return lerp(total, total2, rmd)
    return 0.5 * total / maxamp + 0.5 if normalize else total


@kernel(allocates=False)
def multi_fractal(dim, x, y, z, w, detail, roughness, lacunarity):
    value = 1.0
    pwr = 1.0
    for _ in range(int(detail) + 1):
        value *= pwr * snoise(dim, x, y, z, w) + 1.0
        pwr *= roughness
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        value *= rmd * pwr * snoise(dim, x, y, z, w) + 1.0
    return value


@kernel(allocates=False)
def hetero_terrain(dim, x, y, z, w, detail, roughness, lacunarity, offset):
    pwr = roughness
    value = offset + snoise(dim, x, y, z, w)
    x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
    for _ in range(1, int(detail) + 1):
        value += (snoise(dim, x, y, z, w) + offset) * pwr * value
        pwr *= roughness
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        value += rmd * ((snoise(dim, x, y, z, w) + offset) * pwr * value)
    return value


@kernel(allocates=False)
def hybrid_multi_fractal(dim, x, y, z, w, detail, roughness, lacunarity, offset, gain):
    pwr = 1.0
    value = 0.0
    weight = 1.0
    for _ in range(int(detail) + 1):
        if weight <= 0.001:
            break
        weight = min(weight, 1.0)
        signal = (snoise(dim, x, y, z, w) + offset) * pwr
        pwr *= roughness
        value += weight * signal
        weight *= gain * signal
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
    rmd = detail - math.floor(detail)
    if rmd != 0.0 and weight > 0.001:
        weight = min(weight, 1.0)
        value += rmd * weight * ((snoise(dim, x, y, z, w) + offset) * pwr)
    return value


@kernel(allocates=False)
def ridged_multi_fractal(dim, x, y, z, w, detail, roughness, lacunarity, offset, gain):
    pwr = roughness
    signal = offset - abs(snoise(dim, x, y, z, w))
    signal *= signal
    value = signal
    for _ in range(1, int(detail) + 1):
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
        weight = min(max(signal * gain, 0.0), 1.0)
        signal = offset - abs(snoise(dim, x, y, z, w))
        signal *= signal
        signal *= weight
        value += signal * pwr
        pwr *= roughness
    return value


@kernel(allocates=False)
def fractal(kind, dim, x, y, z, w, detail, roughness, lacunarity, offset, gain, normalize):
    """The Noise Texture's fractal of type `kind` (FRACTAL_TYPES index)."""
    if kind == MULTIFRACTAL:
        return multi_fractal(dim, x, y, z, w, detail, roughness, lacunarity)
    if kind == HYBRID_MULTIFRACTAL:
        return hybrid_multi_fractal(dim, x, y, z, w, detail, roughness, lacunarity, offset,
                                    gain)
    if kind == RIDGED_MULTIFRACTAL:
        return ridged_multi_fractal(dim, x, y, z, w, detail, roughness, lacunarity, offset,
                                    gain)
    if kind == HETERO_TERRAIN:
        return hetero_terrain(dim, x, y, z, w, detail, roughness, lacunarity, offset)
    return fbm(dim, x, y, z, w, detail, roughness, lacunarity, normalize)


@kernel(allocates=False)
def random_offset(dim, seed, k):
    """Component k of Cycles' random_float{dim}_offset(seed): in [100, 200]."""
    if dim == 1:
        return 100.0 + hash_float_to_float(seed) * 100.0
    return 100.0 + hash_float2_to_float(seed, float(k)) * 100.0


@kernel(allocates=False)
def offset_point(dim, seed, x, y, z, w):
    return (x + random_offset(dim, seed, 0), y + random_offset(dim, seed, 1) if dim > 1 else y,
            z + random_offset(dim, seed, 2) if dim > 2 else z,
            w + random_offset(dim, seed, 3) if dim > 3 else w)


@kernel(allocates=False)
def distorted(dim, k, x, y, z, w):
    """The noise that distorts coordinate k of the point (at random offset k)."""
    ox, oy, oz, ow = offset_point(dim, float(k), x, y, z, w)
    return snoise(dim, ox, oy, oz, ow)


@kernel(allocates=False)
def noise_texture(dim, x, y, z, w, detail, roughness, lacunarity, offset, gain, distortion,
                  kind, normalize, color):
    """The Noise Texture node on an already scaled point: (Fac, r, g, b); the colour is
    computed only when `color` (else (Fac, 0, 0, 0))."""
    detail = min(max(detail, 0.0), 15.0)
    roughness = max(roughness, 0.0)
    if distortion != 0.0:
        dx = distorted(dim, 0, x, y, z, w) * distortion
        dy = distorted(dim, 1, x, y, z, w) * distortion if dim > 1 else 0.0
        dz = distorted(dim, 2, x, y, z, w) * distortion if dim > 2 else 0.0
        dw = distorted(dim, 3, x, y, z, w) * distortion if dim > 3 else 0.0
        x, y, z, w = x + dx, y + dy, z + dz, w + dw
    value = fractal(kind, dim, x, y, z, w, detail, roughness, lacunarity, offset, gain,
                    normalize)
    if not color:
        return value, 0.0, 0.0, 0.0
    ox, oy, oz, ow = offset_point(dim, float(dim), x, y, z, w)
    g = fractal(kind, dim, ox, oy, oz, ow, detail, roughness, lacunarity, offset, gain,
                normalize)
    ox, oy, oz, ow = offset_point(dim, float(dim + 1), x, y, z, w)
    b = fractal(kind, dim, ox, oy, oz, ow, detail, roughness, lacunarity, offset, gain,
                normalize)
    return value, value, g, b
