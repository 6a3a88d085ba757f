"""Texture nodes. Opcodes 100-119 (120-199: procedural_nodes). Vectors are registers of the texture coordinates (the
compiler feeds the node's default, UV for Image and Generated for the procedural ones,
when its Vector is unlinked).

  TEX_IMAGE_COLOR out, vector | image     the image's colour at (x, y)
  TEX_IMAGE_ALPHA out, vector | image     its alpha
  TEX_CHECKER_COLOR out, vector, color1, color2, scale
  TEX_CHECKER_FAC out, vector, scale
  TEX_GRADIENT out, vector, type          Fac of the Gradient Texture (GRADIENT_* types)
  TEX_GRID out, vector, triple, stochastic | grid
                                          a voxel grid at the object-space point vector
                                          (engine.volume_grid): triple 0 writes one
                                          register, its channels' average; 1 three (a
                                          scalar grid repeated); stochastic 1: Cycles'
                                          one-tap interpolation (kernels.voxel_grid)

Image lookups are engine.kernels.textures.texture_rgba (the node's interpolation,
extension and colour space, baked into the packed texture); field 7 holds the image.
Grid lookups are engine.kernels.voxel_grid.grid_sample; field 7 holds the grid, whose
values and rows are the fields VOXELS and GRIDS of T (engine.nodes.pack).
"""
from __future__ import annotations

import math

from ..kernels.jit import kernel
from ..kernels.textures import texture_rgba
from ..kernels.voxel_grid import grid_channels, grid_sample

TEX_IMAGE_COLOR = 100
TEX_IMAGE_ALPHA = 101
TEX_CHECKER_COLOR = 102
TEX_CHECKER_FAC = 103
TEX_GRADIENT = 104
TEX_GRID = 105
IMAGE_OPS = (TEX_IMAGE_COLOR, TEX_IMAGE_ALPHA)
GRID_OPS = (TEX_GRID,)
VOXELS, GRIDS = 12, 13     # the grids' fields of the shading tuple T (engine.nodes.pack)

GRADIENT_TYPES = ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL",
                  "QUADRATIC_SPHERE", "RADIAL")


@kernel(allocates=False)
def checker(x, y, z, scale):
    """1 on the first colour's squares, 0 on the second's (Cycles' svm_checker)."""
    x = (x * scale + 0.000001) * 0.999999
    y = (y * scale + 0.000001) * 0.999999
    z = (z * scale + 0.000001) * 0.999999
    xi = abs(int(math.floor(x)))
    yi = abs(int(math.floor(y)))
    zi = abs(int(math.floor(z)))
    return 1.0 if (xi % 2 == yi % 2) == (zi % 2 == 1) else 0.0


@kernel(allocates=False)
def gradient(x, y, z, kind):
    if kind == 0:                      # LINEAR
        r = x
    elif kind == 1:                    # QUADRATIC
        r = max(x, 0.0)
        r = r * r
    elif kind == 2:                    # EASING
        r = min(max(x, 0.0), 1.0)
        t = r * r
        r = 3.0 * t - 2.0 * t * r
    elif kind == 3:                    # DIAGONAL
        r = (x + y) * 0.5
    elif kind == 4:                    # SPHERICAL
        r = max(0.999999 - math.sqrt(x * x + y * y + z * z), 0.0)
    elif kind == 5:                    # QUADRATIC_SPHERE
        r = max(0.999999 - math.sqrt(x * x + y * y + z * z), 0.0)
        r = r * r
    else:                              # RADIAL
        r = math.atan2(y, x) / (2.0 * math.pi) + 0.5
    return min(max(r, 0.0), 1.0)


@kernel(allocates=False)
def execute(ins, regs, T):
    code, out = ins[0], ins[1]
    v = ins[2]
    if code == TEX_IMAGE_COLOR or code == TEX_IMAGE_ALPHA:
        r, g, b, a = texture_rgba(T, ins[7], regs[v], regs[v + 1])
        if code == TEX_IMAGE_COLOR:
            regs[out], regs[out + 1], regs[out + 2] = r, g, b
        else:
            regs[out] = a
    elif code == TEX_CHECKER_COLOR:
        f = checker(regs[v], regs[v + 1], regs[v + 2], regs[ins[5]])
        c1, c2 = ins[3], ins[4]
        for k in range(3):
            regs[out + k] = regs[c1 + k] if f > 0.5 else regs[c2 + k]
    elif code == TEX_CHECKER_FAC:
        regs[out] = checker(regs[v], regs[v + 1], regs[v + 2], regs[ins[3]])
    elif code == TEX_GRADIENT:
        regs[out] = gradient(regs[v], regs[v + 1], regs[v + 2], ins[3])
    elif code == TEX_GRID:
        g, st = ins[7], ins[4] != 0
        nc = grid_channels(T[GRIDS], g)
        x, y, z = regs[v], regs[v + 1], regs[v + 2]
        if nc == 3:
            r = grid_sample(T[VOXELS], T[GRIDS], g, x, y, z, 0, st)
            gg = grid_sample(T[VOXELS], T[GRIDS], g, x, y, z, 1, st)
            b = grid_sample(T[VOXELS], T[GRIDS], g, x, y, z, 2, st)
        else:
            r = grid_sample(T[VOXELS], T[GRIDS], g, x, y, z, 0, st)
            gg, b = r, r
        if ins[3] == 0:
            regs[out] = (r + gg + b) / 3.0
        else:
            regs[out], regs[out + 1], regs[out + 2] = r, gg, b
