"""The interpreter: one material's program run on one hit (`run`), as Cycles' SVM runs a
shader's node stack, a switch per node family; and `evaluate_registers`, its array
driver for NumPy callers and the exporter's constant folding."""
from __future__ import annotations

import numpy as np

from ..kernels.jit import kernel
from . import bump, color_nodes, converter_nodes, input_nodes, procedural_nodes, \
    texture_nodes, vector_nodes
from .pack import DATA, INIT, NREGS, OPS, PROG, pack_shading


@kernel(allocates=False)
def has_program(T, m):
    prog = T[PROG]
    return 0 <= m < prog.shape[0] and prog[m, 1] > 0


@kernel(allocates=False)
def reads_differentials(T, m):
    """Whether material m's program reads the hit's differentials (context.H_DX, H_DY)."""
    return has_program(T, m) and T[PROG][m, 4] != 0


@kernel(allocates=False)
def run(T, m, hit, regs):
    """Run material m's program on the hit row `hit`; its registers end in regs (at
    least T[NREGS][0] long). No-op for a material without a program."""
    if not has_program(T, m):
        return
    prog, ops, init, data = T[PROG], T[OPS], T[INIT], T[DATA]
    start, count, r0, nr = prog[m, 0], prog[m, 1], prog[m, 2], prog[m, 3]
    for k in range(nr):
        regs[k] = init[r0 + k]
    for i in range(start, start + count):
        ins = ops[i]
        code = ins[0]
        if code < 100:
            input_nodes.execute(ins, regs, hit)
        elif code < 120:
            texture_nodes.execute(ins, regs, T)
        elif code < 200:
            procedural_nodes.execute(ins, regs)
        elif code < 300:
            color_nodes.execute(ins, regs, data)
        elif code < 400:
            converter_nodes.execute(ins, regs)
        elif code < 420:
            vector_nodes.execute(ins, regs, hit)
        else:
            bump.execute(ins, regs, hit)


@kernel
def _registers_loop(T, material, hits, width):
    n = hits.shape[0]
    out = np.zeros((n, width))
    regs = np.zeros(max(T[NREGS][0], 1))
    for i in range(n):
        run(T, material[i], hits[i], regs)
        out[i, :] = regs[:width]
    return out


class _OneProgram:
    """A MaterialTable-like holder of one program, for `pack_shading`."""

    def __init__(self, program):
        self.metallic = np.zeros(1)
        self.programs = [program]
        self.textures = list(program.images)
        self.texture_index = {id(t): k for k, t in enumerate(self.textures)}
        self._inputs = {}
        for name in ("base_color", "roughness", "emission", "alpha"):
            setattr(self, name, np.zeros((1, 3) if name in ("base_color", "emission")
                                         else 1))


def evaluate_registers(program, hits) -> np.ndarray:
    """Every register of `program` after running it on each hit row: (n, n_regs)."""
    if len(program.ops) == 0:
        # constants only (an RGB or Value node, a missing image's pink): `run` skips a
        # material without instructions, so its registers are the initial values
        init = np.asarray(program.init, np.float64) if program.n_regs else np.zeros(1)
        return np.tile(init, (len(hits), 1))
    T = pack_shading(_OneProgram(program))
    hits = np.ascontiguousarray(hits, np.float64)
    return _registers_loop(T, np.zeros(len(hits), np.int64), hits, max(program.n_regs, 1))


def evaluate_materials(T, material, hits) -> np.ndarray:
    """Registers (n, T[NREGS]) of each hit's material program (zeros without one)."""
    hits = np.ascontiguousarray(hits, np.float64)
    material = np.ascontiguousarray(material, np.int64)
    return _registers_loop(T, material, hits, max(int(T[NREGS][0]), 1))
