"""`ShaderProgram`: a material's node graph as typed operations on registers, and
`ProgramBuilder`, which the exporter's node compiler drives.

A `Value` is a register holding a float ('float', one register) or a triple ('color' or
'vector', three consecutive registers). The builder hands out registers in order;
constants are registers whose initial value is set (`ShaderProgram.init`), everything
else starts at 0 and is written by one instruction. `varying` marks values that depend
on the hit (an input node upstream): the others are constants the exporter may fold
(`ShaderProgram.constant_value`).

The program's outputs (OUTPUTS) are the per-hit values of the Principled parameters that
the material's nodes drive; a parameter the program leaves out keeps the material's
plain value.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# MaterialTable.PARAMS, the shading normal (a Normal Map's), a Mix Shader's factor (the
# probability of its second shader, Material.mix), a heterogeneous volume's
# coefficients at a point (engine.kernels.medium_density), a Principled Hair's colour
# (its parametrization's Color, Tint or Absorption Coefficient) and Melanin, the
# surface's own normal where the Displacement socket's bump sets it while a shader has a
# Normal of its own (engine.nodes.shading.surface_normal), a Translucent BSDF's
# colour (its weight included), an anisotropic BSDF's tangent (world space) and
# Rotation (engine.kernels.bsdf.anisotropic), and the Principled's Coat Normal
OUTPUTS = ("base_color", "metallic", "roughness", "emission", "alpha", "normal", "mix",
           "volume_absorption", "volume_scattering", "volume_emission", "hair_color",
           "hair_melanin", "surface_normal", "translucent_color", "tangent",
           "anisotropic_rotation", "coat_normal")
OUTPUT_WIDTH = {"base_color": 3, "metallic": 1, "roughness": 1, "emission": 3, "alpha": 1,
                "normal": 3, "mix": 1, "volume_absorption": 3, "volume_scattering": 3,
                "volume_emission": 3, "hair_color": 3, "hair_melanin": 1,
                "surface_normal": 3, "translucent_color": 3, "tangent": 3,
                "anisotropic_rotation": 1, "coat_normal": 3}
N_OUT = len(OUTPUTS)
WIDTH = 8            # int32 per instruction: opcode, output register, six operands


@dataclass(frozen=True)
class Value:
    reg: int
    kind: str                   # 'float', 'color' or 'vector'
    varying: bool = False

    @property
    def width(self) -> int:
        return 1 if self.kind == "float" else 3


@dataclass
class ShaderProgram:
    """ops: (n, WIDTH) int32; init: (n_regs,) float64 initial registers; images: the
    engine.textures.Texture objects that image operations name by index (field 7 of
    their instruction, texture_nodes.IMAGE_OPS); data: float64 tables (a Color Ramp's)
    that table operations (color_nodes.DATA_OPS) address by offset (field 6); outputs:
    {OUTPUTS name: Value}; grids: the engine.volume_grid.VoxelGrids that grid
    operations (texture_nodes.GRID_OPS) name by index (field 7)."""
    ops: np.ndarray
    init: np.ndarray
    images: list = field(default_factory=list)
    data: np.ndarray = field(default_factory=lambda: np.zeros(0))
    outputs: dict = field(default_factory=dict)
    grids: list = field(default_factory=list)

    @property
    def n_regs(self) -> int:
        return len(self.init)

    def evaluate(self, value: Value, hits: np.ndarray) -> np.ndarray:
        """`value` at each hit row of hits (n, context.N_HIT): (n,) or (n, 3)."""
        from .interpreter import evaluate_registers
        regs = evaluate_registers(self, hits)
        return regs[:, value.reg] if value.width == 1 else regs[:, value.reg:value.reg + 3]

    def constant_value(self, value: Value):
        """A non-varying value, computed: a float or an RGB/XYZ tuple."""
        from .context import hit_rows
        hit = hit_rows(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]))
        v = self.evaluate(value, hit)[0]
        return float(v) if value.width == 1 else tuple(float(x) for x in v)

    def mean_value(self, value: Value, n: int = 16):
        """A summary of a varying value: its mean over an n x n grid of UVs and generated
        coordinates across the unit square, normal +Z, seen head-on by a camera ray."""
        from .context import hit_rows
        s = (np.arange(n) + 0.5) / n
        u, v = np.meshgrid(s, s)
        uv = np.stack([u.ravel(), v.ravel()], 1)
        pos = np.column_stack([uv * 2.0 - 1.0, np.zeros(len(uv))])
        hits = hit_rows(pos, np.tile([0.0, 0.0, 1.0], (len(uv), 1)), uv=uv)
        m = self.evaluate(value, hits).mean(axis=0)
        return float(m) if value.width == 1 else tuple(float(x) for x in m)


class ProgramBuilder:
    def __init__(self):
        self._ops = []
        self._init = []
        self._consts = {}
        self.images = []
        self._image_index = {}
        self.outputs = {}
        self._data = []
        self.grids = []

    def _alloc(self, width):
        reg = len(self._init)
        self._init.extend([0.0] * width)
        return reg

    def block(self, width: int) -> int:
        """The first of `width` registers an instruction uses as scratch (a saved part of
        the hit row: engine.nodes.bump)."""
        return self._alloc(width)

    def constant(self, x, kind=None) -> Value:
        """A constant register: a float, or a triple (kind 'color' unless given)."""
        if np.ndim(x) == 0:
            key = ("float", float(x))
            vals = [float(x)]
        else:
            vals = [float(c) for c in tuple(x)[:3]]
            vals += [vals[-1]] * (3 - len(vals))
            key = (kind or "color", tuple(vals))
        if key not in self._consts:
            reg = self._alloc(len(vals))
            self._init[reg:reg + len(vals)] = vals
            self._consts[key] = Value(reg, key[0])
        return self._consts[key]

    def image(self, texture) -> int:
        """The index of an engine.textures.Texture in this program's images."""
        if id(texture) not in self._image_index:
            self._image_index[id(texture)] = len(self.images)
            self.images.append(texture)
        return self._image_index[id(texture)]

    def grid(self, grid) -> int:
        """The index of an engine.volume_grid.VoxelGrid in this program's grids."""
        for k, g in enumerate(self.grids):
            if g is grid:
                return k
        self.grids.append(grid)
        return len(self.grids) - 1

    def data(self, values) -> int:
        """Append a float table to the program's data; its offset."""
        offset = len(self._data)
        self._data.extend(float(x) for x in np.asarray(values, np.float64).ravel())
        return offset

    def emit(self, opcode: int, kind: str, operands=(), varying=None, image=None,
             grid=None) -> Value:
        """One instruction writing a new register of `kind`. operands: up to six ints
        (registers of Values or immediate codes; Values are replaced by their register).
        varying: defaults to whether any Value operand varies. image: a Texture to read,
        or grid: a VoxelGrid (its index goes to field 7)."""
        ops = [o.reg if isinstance(o, Value) else int(o) for o in operands]
        if len(ops) > WIDTH - 2 - (image is not None or grid is not None):
            raise ValueError(f"opcode {opcode}: too many operands")
        if varying is None:
            varying = any(o.varying for o in operands if isinstance(o, Value))
        out = Value(self._alloc(1 if kind == "float" else 3), kind, bool(varying))
        row = [opcode, out.reg] + ops + [0] * (WIDTH - 2 - len(ops))
        if image is not None:
            row[7] = self.image(image)
        if grid is not None:
            row[7] = self.grid(grid)
        self._ops.append(row)
        return out

    def output(self, name: str, value: Value):
        if name not in OUTPUTS:
            raise ValueError(f"unknown program output {name!r}")
        want = OUTPUT_WIDTH[name]
        if value.width != want:
            raise ValueError(f"output {name!r} takes {want} registers, got a {value.kind}")
        self.outputs[name] = value

    def build(self) -> ShaderProgram:
        ops = np.array(self._ops, np.int32).reshape(-1, WIDTH)
        return ShaderProgram(ops, np.array(self._init, np.float64), list(self.images),
                             np.array(self._data, np.float64), dict(self.outputs),
                             list(self.grids))
