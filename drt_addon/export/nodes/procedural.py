"""Procedural texture nodes to program operations (engine.nodes.procedural_nodes): White
Noise.

White Noise's unlinked Vector is the socket's own value, as in Cycles.
"""
from __future__ import annotations

import importlib

from ...engine_link import engine
from .errors import Unsupported

P = importlib.import_module(engine.__name__ + ".nodes.procedural_nodes")

DIMENSIONS = {"1D": 1, "2D": 2, "3D": 3, "4D": 4}


def _dims(node, prop):
    value = getattr(node, prop)
    if value not in DIMENSIONS:
        raise Unsupported(f"{value} dimensions")
    return DIMENSIONS[value]


def _float(c, node, name):
    """Input `name` as a float; 0 for a socket this Blender's node lacks."""
    if node.inputs.get(name) is None:
        return c.const(0.0)
    return c.input(node, name, "float")


def _white_noise(c, node, out):
    dims = _dims(node, "noise_dimensions")
    op = P.TEX_WHITE_NOISE_COLOR if out.identifier == "Color" else P.TEX_WHITE_NOISE_VALUE
    return c.emit(op, "color" if out.identifier == "Color" else "float",
                  [c.input(node, "Vector", "vector"), _float(c, node, "W"), dims])


TRANSLATORS = {
    "ShaderNodeTexWhiteNoise": _white_noise,
}
