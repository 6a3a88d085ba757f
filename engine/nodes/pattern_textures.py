"""Blender's pattern textures (Cycles' svm/white_noise.h): White Noise, on its node's
already read inputs.

White Noise hashes the bits of its input (hash.py), so it matches Cycles only where
both engines compute the same float32 input (quantised coordinates).
"""
from __future__ import annotations

from ..kernels.jit import kernel
from .hash import hash_float1_to_float3, hash_float2_to_float, hash_float2_to_float3, \
    hash_float3_to_float, hash_float3_to_float3, hash_float4_to_float, hash_float4_to_float3, \
    hash_float_to_float


@kernel
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
