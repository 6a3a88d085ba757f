"""The Principled Hair BSDF node's closure (Chiang model) as the exporter hands it to
the tracer: its inputs as Blender names them, rendered by
engine/kernels/bsdf/hair_chiang.py beside a material's other lobes."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

PARAMETRIZATIONS = ("ABSORPTION", "MELANIN", "COLOR")   # hair_chiang's mode numbers


@dataclass(frozen=True)
class PrincipledHair:
    """Blender's defaults. `weight` is the closure's weight colour (a Mix or Add Shader's
    share); `color`, `absorption` and `melanin`, `melanin_redness`, `tint` are read by
    the `parametrization` they belong to. `strand_random`: the Random socket is
    unlinked, so a strand reads its own Random (the Hair Info node's), as Cycles does;
    elsewhere (a mesh) the socket's value `random`."""
    weight: tuple = (1.0, 1.0, 1.0)
    parametrization: str = "COLOR"
    color: tuple = (0.017513, 0.005763, 0.002059)
    melanin: float = 0.8
    melanin_redness: float = 1.0
    tint: tuple = (1.0, 1.0, 1.0)
    absorption: tuple = (0.245531, 0.52, 1.365)
    roughness: float = 0.3
    radial_roughness: float = 0.3
    coat: float = 0.0
    ior: float = 1.55
    offset: float = math.radians(2.0)
    random_color: float = 0.0
    random_roughness: float = 0.0
    random: float = 0.0
    strand_random: bool = True

    def __post_init__(self):
        if self.parametrization not in PARAMETRIZATIONS:
            raise ValueError(f"Principled Hair parametrization must be one of "
                             f"{PARAMETRIZATIONS}, not {self.parametrization!r}")

    def scaled(self, f) -> "PrincipledHair":
        return replace(self, weight=tuple(float(w) * f for w in self.weight))

    def mode_colour(self) -> tuple:
        """The colour the parametrization reads: Color, Absorption Coefficient or Tint."""
        return {"COLOR": self.color, "ABSORPTION": self.absorption,
                "MELANIN": self.tint}[self.parametrization]
