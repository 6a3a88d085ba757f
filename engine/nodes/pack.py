"""Every material's shader program as the arrays the kernels read, appended to the
texture tuple T of engine.kernels.textures (one Numba argument; always the same array
types, so one compilation serves every scene):

  T[OPS]    int32 (n_ops, WIDTH): the instructions of every program, concatenated;
            image operations name global texture ids (T[TEXTURES] rows), table
            operations global offsets into T[DATA]
  T[INIT]   float64: every program's initial registers, concatenated
  T[DATA]   float64: every program's tables, concatenated
  T[PROG]   int64 (n_mat, 5): first instruction, instruction count, first initial
            register, register count (0 instructions: no program), 1 when the
            program reads the hit's differentials (a Bump), else 0
  T[OUTS]   int64 (n_mat, N_OUT): the register of each program output, -1 where the
            program does not drive that parameter
  T[NREGS]  int64 (1,): the largest register count (the size of a register file)
  T[MIX]    int64 (n_mat, 2): the two materials a material's Mix Shader picks between
            per hit (MaterialTable.mix_children; -1: none)
  T[VOXELS] float32: the values of every voxel grid the programs read, concatenated
  T[GRIDS]  float64 (n_grids, volume_grid.N_GRID): each grid's offset, size and map
            (engine.volume_grid.pack_grids); grid operations name rows of it
  T[MAJORANTS] float64: each material's majorant grid (engine.kernels.majorant_grid),
            zeros until the integrator bounds its heterogeneous volume; (0, ...) when
            no program computes a volume
"""
from __future__ import annotations

import numpy as np

from ..kernels.majorant_grid import empty_table
from ..kernels.textures import pack_textures
from ..volume_grid import pack_grids
from .bump import BUMP_ENTER, BUMP_NORMAL
from .color_nodes import DATA_OPS
from .program import N_OUT, OUTPUTS, WIDTH
from .texture_nodes import GRID_OPS, GRIDS, IMAGE_OPS, VOXELS

OPS = 5
INIT = 6
DATA = 7
PROG = 8
OUTS = 9
NREGS = 10
MIX = 11
MAJORANTS = 14
assert (VOXELS, GRIDS) == (MIX + 1, MIX + 2)


def pack_programs(table) -> tuple:
    """The program fields (OPS .. NREGS) of a MaterialTable with `programs` and
    `texture_index` (id(Texture) -> global texture id)."""
    programs = list(getattr(table, "programs", None) or [])
    n_mat = len(table.metallic)
    prog = np.zeros((n_mat, 5), np.int64)
    outs = np.full((n_mat, N_OUT), -1, np.int64)
    ops, init, data = [], [], []
    n_ops = n_init = n_data = 0
    grids, grid_index = [], {}
    for m, p in enumerate(programs):
        if p is None or len(p.ops) == 0:
            continue
        o = np.array(p.ops, np.int32, copy=True).reshape(-1, WIDTH)
        for k in range(len(o)):
            if o[k, 0] in IMAGE_OPS:
                o[k, 7] = table.texture_index[id(p.images[o[k, 7]])]
            if o[k, 0] in DATA_OPS:
                o[k, 6] += n_data
            if o[k, 0] in GRID_OPS:
                grid = p.grids[o[k, 7]]
                if id(grid) not in grid_index:
                    grid_index[id(grid)] = len(grids)
                    grids.append(grid)
                o[k, 7] = grid_index[id(grid)]
        bumps = bool(np.isin(o[:, 0], (BUMP_ENTER, BUMP_NORMAL)).any())
        prog[m] = (n_ops, len(o), n_init, p.n_regs, bumps)
        for j, name in enumerate(OUTPUTS):
            if name in p.outputs:
                outs[m, j] = p.outputs[name].reg
        ops.append(o)
        init.append(p.init)
        data.append(p.data)
        n_ops += len(o)
        n_init += p.n_regs
        n_data += len(p.data)
    voxels, grid_rows = pack_grids(grids)
    volumes = [j for j, name in enumerate(OUTPUTS) if name.startswith("volume_")]
    maj = empty_table(n_mat if (outs[:, volumes] >= 0).any() else 0)
    return (np.concatenate(ops) if ops else np.zeros((0, WIDTH), np.int32),
            np.concatenate(init) if init else np.zeros(0),
            np.concatenate(data) if data else np.zeros(0),
            prog, outs, np.array([int(prog[:, 3].max()) if n_mat else 0], np.int64),
            np.ascontiguousarray(getattr(table, "mix_children",
                                         np.full((n_mat, 2), -1, np.int64)), np.int64),
            voxels, grid_rows, maj)


def pack_shading(table) -> tuple:
    """T: the textures (engine.kernels.textures.pack_textures) and the programs."""
    return pack_textures(table) + pack_programs(table)
