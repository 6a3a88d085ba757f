"""Blender's pattern textures (Cycles' svm/white_noise.h, wave.h, magic.h, brick.h):
White Noise, Wave, Magic and Brick, each on its node's already read inputs.

White Noise hashes the bits of its input (hash.py), so it matches Cycles only where
both engines compute the same float32 input (quantised coordinates); the others are
continuous functions of the point, or piecewise constant with edges.
"""
from __future__ import annotations

import math

import numpy as np

from ..kernels.jit import kernel
from .hash import M32, hash_float1_to_float3, hash_float2_to_float, hash_float2_to_float3, \
    hash_float3_to_float, hash_float3_to_float3, hash_float4_to_float, hash_float4_to_float3, \
    hash_float_to_float
from .noise import fbm

WAVE_TYPES = ("BANDS", "RINGS")
BANDS_DIRECTIONS = ("X", "Y", "Z", "DIAGONAL")
RINGS_DIRECTIONS = ("X", "Y", "Z", "SPHERICAL")
WAVE_PROFILES = ("SIN", "SAW", "TRI")
WAVE_MAX_DETAIL = 64.0       # octaves past float32's precision long before this


# ---------------------------------------------------------------- white noise
@kernel(allocates=False)
def white_noise(dim, x, y, z, w, color):
    """White Noise's Color (color) or (Value, 0, 0); a 1D point is w, 2D (x, y), 3D
    (x, y, z), 4D all four."""
    if dim == 1:
        return hash_float1_to_float3(w) if color else (hash_float_to_float(w), 0.0, 0.0)
    if dim == 2:
        return hash_float2_to_float3(x, y) if color else (hash_float2_to_float(x, y), 0.0,
                                                          0.0)
    if dim == 3:
        return hash_float3_to_float3(x, y, z) if color else (hash_float3_to_float(x, y, z),
                                                             0.0, 0.0)
    return hash_float4_to_float3(x, y, z, w) if color else (
        hash_float4_to_float(x, y, z, w), 0.0, 0.0)


# ---------------------------------------------------------------- wave
@kernel(allocates=False)
def wave(kind, bands_direction, rings_direction, profile, x, y, z, distortion, detail,
         detail_scale, detail_roughness, phase):
    """The Wave Texture's Fac at a point already multiplied by its Scale."""
    x = (x + 0.000001) * 0.999999            # as Cycles, against unit-coordinate precision
    y = (y + 0.000001) * 0.999999
    z = (z + 0.000001) * 0.999999
    if kind == 0:                            # BANDS
        if bands_direction == 0:
            n = x * 20.0
        elif bands_direction == 1:
            n = y * 20.0
        elif bands_direction == 2:
            n = z * 20.0
        else:
            n = (x + y + z) * 10.0
    else:                                    # RINGS
        rx = 0.0 if rings_direction == 0 else x
        ry = 0.0 if rings_direction == 1 else y
        rz = 0.0 if rings_direction == 2 else z
        n = math.sqrt(rx * rx + ry * ry + rz * rz) * 20.0
    n += phase
    if distortion != 0.0:                    # Detail is not clamped (Cycles' neither), but
        detail = min(detail, WAVE_MAX_DETAIL)  # capped: a huge linked value must not hang
        n += distortion * (fbm(3, x * detail_scale, y * detail_scale, z * detail_scale, 0.0,
                               detail, detail_roughness, 2.0, True) * 2.0 - 1.0)
    if profile == 0:                         # SIN
        return 0.5 + 0.5 * math.sin(n - 0.5 * math.pi)
    n /= 2.0 * math.pi
    if profile == 1:                         # SAW
        return n - math.floor(n)
    return abs(n - math.floor(n + 0.5)) * 2.0


# ---------------------------------------------------------------- magic
@kernel(allocates=False)
def magic(x, y, z, scale, depth, distortion):
    """The Magic Texture's colour (Fac is its average)."""
    two_pi = 2.0 * math.pi
    px, py, pz = np.fmod(x, two_pi), np.fmod(y, two_pi), np.fmod(z, two_pi)
    a = math.sin((px + py + pz) * 5.0 * scale)
    b = math.cos((-px + py - pz) * 5.0 * scale)
    c = -math.cos((-px - py + pz) * 5.0 * scale)
    if depth > 0:
        a *= distortion
        b *= distortion
        c *= distortion
        b = -math.cos(a - b + c) * distortion
        if depth > 1:
            a = math.cos(a - b - c) * distortion
        if depth > 2:
            c = math.sin(-a - b - c) * distortion
        if depth > 3:
            a = -math.cos(-a + b - c) * distortion
        if depth > 4:
            b = -math.sin(-a + b + c) * distortion
        if depth > 5:
            b = -math.cos(-a + b + c) * distortion
        if depth > 6:
            a = math.cos(a + b + c) * distortion
        if depth > 7:
            c = math.sin(a + b - c) * distortion
        if depth > 8:
            a = -math.cos(-a - b + c) * distortion
        if depth > 9:
            b = -math.sin(a - b + c) * distortion
    if distortion != 0.0:
        d = distortion * 2.0
        a, b, c = a / d, b / d, c / d
    return 0.5 - a, 0.5 - b, 0.5 - c


# ---------------------------------------------------------------- brick
@kernel(allocates=False)
def brick_noise(n):
    """Cycles' integer noise of a brick's number: [0, 1)."""
    n = (n + 1013) & 0x7FFFFFFF
    n = (n >> 13) ^ n
    t = (((n * n) & M32) * 60493 + 19990303) & M32
    nn = (n * t + 1376312589) & 0x7FFFFFFF
    return 0.5 * (nn / 1073741824.0)


@kernel(allocates=False)
def brick(x, y, mortar_size, mortar_smooth, bias, brick_width, row_height, offset_amount,
          offset_frequency, squash_amount, squash_frequency):
    """(tint, mortar) of the Brick Texture at a point already multiplied by its Scale."""
    row = int(math.floor(y / row_height))
    offset = 0.0
    if offset_frequency != 0 and squash_frequency != 0:
        if row % squash_frequency == 0:
            brick_width *= squash_amount
        if row % offset_frequency == 0:
            offset = brick_width * offset_amount
    num = int(math.floor((x + offset) / brick_width))
    bx = (x + offset) - brick_width * num
    by = y - row_height * row
    tint = min(max(brick_noise(((row << 16) + (num & 0xFFFF)) & M32) + bias, 0.0), 1.0)
    min_dist = min(min(bx, by), min(brick_width - bx, row_height - by))
    if min_dist >= mortar_size:
        mortar = 0.0
    elif mortar_smooth == 0.0:
        mortar = 1.0
    else:
        t = (1.0 - min_dist / mortar_size) / mortar_smooth
        mortar = 0.0 if t <= 0.0 else 1.0 if t >= 1.0 else t * t * (3.0 - 2.0 * t)
    return tint, mortar
