"""Procedural texture nodes: White Noise. Opcodes 120-199 (the texture range; 100-119
are texture_nodes'). The kernels are Blender's own functions: hash.py,
pattern_textures.py.

  TEX_WHITE_NOISE_VALUE out, vector, w, dims
  TEX_WHITE_NOISE_COLOR out, vector, w, dims

dims is 1-4.
"""
from __future__ import annotations

from ..kernels.jit import kernel
from .pattern_textures import white_noise

TEX_WHITE_NOISE_VALUE = 120
TEX_WHITE_NOISE_COLOR = 121


@kernel
def execute(ins, regs):
    code, out, v = ins[0], ins[1], ins[2]
    if code == TEX_WHITE_NOISE_VALUE or code == TEX_WHITE_NOISE_COLOR:
        r, g, b = white_noise(ins[4], regs[v], regs[v + 1], regs[v + 2], regs[ins[3]],
                              code == TEX_WHITE_NOISE_COLOR)
        regs[out] = r
        if code == TEX_WHITE_NOISE_COLOR:
            regs[out + 1], regs[out + 2] = g, b
