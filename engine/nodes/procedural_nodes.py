"""Procedural texture nodes: White Noise, Noise, Voronoi, Wave, Magic, Brick. Opcodes
120-199 (the texture range; 100-119 are texture_nodes'). The kernels are Blender's own
functions: hash.py, noise.py, voronoi.py, pattern_textures.py.

A node with more inputs than an instruction has operands reads them packed three to a
register triple (the compiler's CV_COMBINE); `mode` packs the node's enum settings.

  TEX_WHITE_NOISE_VALUE out, vector, w, dims
  TEX_WHITE_NOISE_COLOR out, vector, w, dims
  TEX_NOISE_FAC out, vector, (w, scale, detail), (roughness, lacunarity, distortion),
                (offset, gain, -), mode          mode = dims + 8 type + 64 normalize
  TEX_NOISE_COLOR ... (the same operands)
  TEX_VORONOI out, vector, (w, scale, detail), (roughness, lacunarity, smoothness),
              (exponent, randomness, -), mode    mode = dims + 8 feature + 64 metric
                                                 + 512 normalize + 1024 output
                                                 (VORONOI_OUTPUTS index)
  TEX_WAVE out, vector, scale, (distortion, detail, detail scale),
           (detail roughness, phase, -), mode    mode = type + 2 bands direction
                                                 + 8 rings direction + 32 profile
  TEX_MAGIC out, vector, scale, distortion, depth     the colour (Fac: its average)
  TEX_BRICK out, vector, (scale, mortar size, mortar smooth),
            (bias, brick width, row height), (offset, squash, -), frequencies
            a vector (tint, mortar, 0); frequencies = offset + 1024 squash frequency
  TEX_BRICK_COLOR out, brick, color1, color2, mortar  the Brick Texture's colour

dims is 1-4; types, features, metrics, directions and profiles index
noise.FRACTAL_TYPES, voronoi.FEATURES / METRICS and pattern_textures' tuples.
"""
from __future__ import annotations

from ..kernels.jit import kernel
from .noise import noise_texture
from .pattern_textures import brick, magic, wave, white_noise
from .voronoi import voronoi_texture

TEX_WHITE_NOISE_VALUE = 120
TEX_WHITE_NOISE_COLOR = 121
TEX_NOISE_FAC = 122
TEX_NOISE_COLOR = 123
TEX_VORONOI = 124
TEX_WAVE = 125
TEX_MAGIC = 126
TEX_BRICK = 127
TEX_BRICK_COLOR = 128

VORONOI_OUTPUTS = ("Distance", "Color", "Position", "W", "Radius")


@kernel(allocates=False)
def texture_point(regs, dims, v, w, scale):
    """The node's point (its first `dims` coordinates used; a 1D point is W) times
    scale."""
    if dims == 1:
        return w * scale, 0.0, 0.0, 0.0
    return regs[v] * scale, regs[v + 1] * scale, regs[v + 2] * scale, w * scale


@kernel(allocates=False)
def execute_noise(ins, regs):
    out, v, a, b, c, mode = ins[1], ins[2], ins[3], ins[4], ins[5], ins[6]
    dims = mode % 8
    x, y, z, w = texture_point(regs, dims, v, regs[a], regs[a + 1])
    fac, r, g, bl = noise_texture(dims, x, y, z, w, regs[a + 2], regs[b], regs[b + 1],
                                  regs[c], regs[c + 1], regs[b + 2], (mode // 8) % 8,
                                  mode // 64 == 1, ins[0] == TEX_NOISE_COLOR)
    if ins[0] == TEX_NOISE_COLOR:
        regs[out], regs[out + 1], regs[out + 2] = r, g, bl
    else:
        regs[out] = fac


@kernel(allocates=False)
def execute_voronoi(ins, regs):
    out, v, a, b, c, mode = ins[1], ins[2], ins[3], ins[4], ins[5], ins[6]
    dims = mode % 8
    scale = regs[a + 1]
    x, y, z, w = texture_point(regs, dims, v, regs[a], scale)
    d, r, g, bl, px, py, pz, pw, radius = voronoi_texture(
        dims, (mode // 8) % 8, (mode // 64) % 8, (mode // 512) % 2 == 1, x, y, z, w, scale,
        regs[a + 2], regs[b], regs[b + 1], regs[b + 2], regs[c], regs[c + 1])
    output = mode // 1024
    if output == 0:
        regs[out] = d
    elif output == 1:
        regs[out], regs[out + 1], regs[out + 2] = r, g, bl
    elif output == 2:
        if dims == 1:                        # a 1D position is its W
            px = 0.0
        regs[out], regs[out + 1], regs[out + 2] = px, py, pz
    elif output == 3:
        regs[out] = px if dims == 1 else pw if dims == 4 else 0.0
    else:
        regs[out] = radius


@kernel(allocates=False)
def execute(ins, regs):
    code, out, v = ins[0], ins[1], ins[2]
    if code == TEX_WHITE_NOISE_VALUE or code == TEX_WHITE_NOISE_COLOR:
        r, g, b = white_noise(ins[4], regs[v], regs[v + 1], regs[v + 2], regs[ins[3]],
                              code == TEX_WHITE_NOISE_COLOR)
        regs[out] = r
        if code == TEX_WHITE_NOISE_COLOR:
            regs[out + 1], regs[out + 2] = g, b
    elif code == TEX_NOISE_FAC or code == TEX_NOISE_COLOR:
        execute_noise(ins, regs)
    elif code == TEX_VORONOI:
        execute_voronoi(ins, regs)
    elif code == TEX_WAVE:
        s, a, b, mode = regs[ins[3]], ins[4], ins[5], ins[6]
        regs[out] = wave(mode % 2, (mode // 2) % 4, (mode // 8) % 4, mode // 32,
                         regs[v] * s, regs[v + 1] * s, regs[v + 2] * s, regs[a], regs[a + 1],
                         regs[a + 2], regs[b], regs[b + 1])
    elif code == TEX_MAGIC:
        r, g, b = magic(regs[v], regs[v + 1], regs[v + 2], regs[ins[3]], ins[5],
                        regs[ins[4]])
        regs[out], regs[out + 1], regs[out + 2] = r, g, b
    elif code == TEX_BRICK:
        a, b, c, freq = ins[3], ins[4], ins[5], ins[6]
        s = regs[a]
        tint, mortar = brick(regs[v] * s, regs[v + 1] * s, regs[a + 1], regs[a + 2],
                             regs[b], regs[b + 1], regs[b + 2], regs[c], freq % 1024,
                             regs[c + 1], freq // 1024)
        regs[out], regs[out + 1], regs[out + 2] = tint, mortar, 0.0
    elif code == TEX_BRICK_COLOR:
        t, c1, c2, m = ins[2], ins[3], ins[4], ins[5]
        tint, f = regs[t], regs[t + 1]
        for k in range(3):
            color = regs[c1 + k]
            if f != 1.0:
                color = (1.0 - tint) * color + tint * regs[c2 + k]
            regs[out + k] = color * (1.0 - f) + regs[m + k] * f
