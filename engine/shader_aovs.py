"""Shader AOVs: what a material's AOV Output nodes say at the first surface each camera
ray meets, as Cycles writes them into the view layer's AOV passes (View Layer > Shader
AOV; a Color AOV reads the node's Color input, a Value AOV its Value input).

A material's AOV Output nodes are compiled into one shader program of their own
(`ShaderAOVs`), apart from the program the path tracer runs, so a scene without AOV
passes never evaluates them. The pass is the mean over the pixel's first-hit camera
samples (engine.aov), a sample that hits nothing, or hits a material without that
AOV, adding 0, as in Cycles; a Color AOV's alpha is the share of the samples that
wrote it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

COLOR, VALUE = "COLOR", "VALUE"


@dataclass
class ShaderAOVs:
    """One material's AOV Output nodes: `program` (an engine.nodes.program.ShaderProgram)
    and, per AOV name, the program Values of the node's Color and Value inputs."""
    program: object
    outputs: dict = field(default_factory=dict)     # {name: (color Value, value Value)}


@dataclass(frozen=True)
class AovPass:
    """An AOV pass of the view layer: its name and kind (COLOR or VALUE)."""
    name: str
    kind: str = COLOR

    def __post_init__(self):
        if self.kind not in (COLOR, VALUE):
            raise ValueError(f"AOV {self.name!r}: kind must be COLOR or VALUE, "
                             f"got {self.kind!r}")

    @property
    def width(self) -> int:
        """Channels: a Color AOV's RGB and the share of samples that wrote it (Cycles'
        alpha: 0 where a material has no such AOV node), a Value AOV's value."""
        return 4 if self.kind == COLOR else 1


def aov_values(materials, passes, material: np.ndarray, hits: np.ndarray) -> dict:
    """{pass name: (n, AovPass.width) values} at n first hits of materials `material`
    (indices into `materials`, engine.scene.Material), whose hit rows
    (engine.nodes.context) are `hits`; 0 where a material has no AOV Output node of that
    name."""
    from .nodes.interpreter import evaluate_registers
    n = len(material)
    out = {p.name: np.zeros((n, p.width)) for p in passes}
    if n == 0:
        return out
    for k in np.unique(material):
        aovs = getattr(materials[k], "aovs", None) if k < len(materials) else None
        if aovs is None:
            continue
        rows = np.nonzero(material == k)[0]
        wanted = [p for p in passes if p.name in aovs.outputs]
        if not wanted:
            continue
        regs = evaluate_registers(aovs.program, np.ascontiguousarray(hits[rows]))
        for p in wanted:
            color, value = aovs.outputs[p.name]
            if p.kind == COLOR:
                got = regs[:, color.reg:color.reg + color.width]
                out[p.name][rows, :3] = got if got.shape[1] == 3 else \
                    np.repeat(got[:, :1], 3, axis=1)
                out[p.name][rows, 3] = 1.0
            else:
                out[p.name][rows, 0] = regs[:, value.reg]
    return out
