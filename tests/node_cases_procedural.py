"""The procedural textures' node graphs tests/test_nodes_vs_cycles.py compares with
Cycles (White Noise), one family per kind, on tiles of TILE pixels so that a pattern's
features span several pixels.

Patterns read Generated coordinates (the tile's [0, 1] square) unless a case says
otherwise. White Noise hashes the bits of its input, so its input is quantised (Snap)
to cells of a few pixels: both engines then hash the same float32 values, and only the
pixels across cell edges mix neighbouring cells (antialiasing, the same in both).
"""
from __future__ import annotations

from node_cases import axis, gen, ident

TILE = 32


def _set(node, **inputs):
    for name, value in inputs.items():
        ident(node.inputs, name).default_value = value


def _snapped(nt, p, step=0.25):
    """Generated coordinates snapped to a grid of `step` (z to 0)."""
    snap = p.node(nt, "ShaderNodeVectorMath", operation="SNAP")
    nt.links.new(gen(nt, p), snap.inputs[0])
    snap.inputs[1].default_value = (step, step, 1.0)
    return snap.outputs[0]


# ---------------------------------------------------------------- white noise
def _white_noise(dims, output):
    def build(nt, p):
        n = p.node(nt, "ShaderNodeTexWhiteNoise", noise_dimensions=dims)
        if dims == "1D":
            w = p.node(nt, "ShaderNodeMath", operation="SNAP")
            nt.links.new(axis(nt, p, gen(nt, p), 0), w.inputs[0])
            w.inputs[1].default_value = 0.125
            nt.links.new(w.outputs[0], n.inputs["W"])
        else:
            nt.links.new(_snapped(nt, p), n.inputs["Vector"])
            _set(n, W=0.37)
        return n.outputs[output]
    return build


PATTERNS = [
    ("white_noise_2d", _white_noise("2D", "Value")),
    ("white_noise_3d", _white_noise("3D", "Value")),
    ("white_noise_3d_color", _white_noise("3D", "Color")),
    ("white_noise_4d_color", _white_noise("4D", "Color")),
    ("white_noise_1d", _white_noise("1D", "Color")),
]

FAMILIES = {"procedural_patterns": (PATTERNS, "plane")}
TILES = {name: TILE for name in FAMILIES}
