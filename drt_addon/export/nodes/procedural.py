"""Procedural texture nodes to program operations (engine.nodes.procedural_nodes): White
Noise, Noise, Voronoi.

An unlinked Vector reads Generated coordinates, as in Cycles, except White Noise's, which
is the socket's own value. A node whose legacy texture mapping (the node's Mapping panel
in the sidebar) is not the identity is reported: DRT ignores it.
"""
from __future__ import annotations

import importlib

from ...engine_link import engine
from .errors import Unsupported
from .texture import C, coordinates

P = importlib.import_module(engine.__name__ + ".nodes.procedural_nodes")
N = importlib.import_module(engine.__name__ + ".nodes.noise")
VOR = importlib.import_module(engine.__name__ + ".nodes.voronoi")
CV = importlib.import_module(engine.__name__ + ".nodes.converter_nodes")

DIMENSIONS = {"1D": 1, "2D": 2, "3D": 3, "4D": 4}


def _index(options, value, what):
    if value not in options:
        raise Unsupported(f"{what} {value}")
    return options.index(value)


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


def _pack(c, node, names):
    """Three float inputs (None: 0) in one register triple (CV_COMBINE)."""
    values = [_float(c, node, n) if n else c.const(0.0) for n in names]
    return c.emit(CV.CV_COMBINE, "vector", values)


def _texture_coordinates(c, node):
    m = getattr(node, "texture_mapping", None)
    if m is not None and (any(abs(v) > 1e-9 for v in tuple(m.translation) + tuple(m.rotation))
                          or any(abs(v - 1.0) > 1e-9 for v in m.scale)
                          or (m.mapping_x, m.mapping_y, m.mapping_z) != ("X", "Y", "Z")
                          or m.use_min or m.use_max):
        c.ctx.issue(f"{node.name!r} has a texture mapping (sidebar > Mapping); DRT ignores "
                    f"it, connect a Mapping node instead")
    return coordinates(c, node, C.H_GENERATED)


def _white_noise(c, node, out):
    dims = _dims(node, "noise_dimensions")
    op = P.TEX_WHITE_NOISE_COLOR if out.identifier == "Color" else P.TEX_WHITE_NOISE_VALUE
    return c.emit(op, "color" if out.identifier == "Color" else "float",
                  [c.input(node, "Vector", "vector"), _float(c, node, "W"), dims])


def _noise(c, node, out):
    mode = (_dims(node, "noise_dimensions")
            + 8 * _index(N.FRACTAL_TYPES, node.noise_type, "noise type")
            + 64 * int(bool(getattr(node, "normalize", True))))
    operands = [_texture_coordinates(c, node), _pack(c, node, ("W", "Scale", "Detail")),
                _pack(c, node, ("Roughness", "Lacunarity", "Distortion")),
                _pack(c, node, ("Offset", "Gain", None)), mode]
    if out.identifier == "Color":
        return c.emit(P.TEX_NOISE_COLOR, "color", operands)
    return c.emit(P.TEX_NOISE_FAC, "float", operands)


def _voronoi(c, node, out):
    output = _index(P.VORONOI_OUTPUTS, out.identifier, "the Voronoi output")
    mode = (_dims(node, "voronoi_dimensions")
            + 8 * _index(VOR.FEATURES, node.feature, "Voronoi feature")
            + 64 * _index(VOR.METRICS, node.distance, "Voronoi distance")
            + 512 * int(bool(node.normalize)) + 1024 * output)
    kind = "color" if output == 1 else "vector" if output == 2 else "float"
    return c.emit(P.TEX_VORONOI, kind,
                  [_texture_coordinates(c, node), _pack(c, node, ("W", "Scale", "Detail")),
                   _pack(c, node, ("Roughness", "Lacunarity", "Smoothness")),
                   _pack(c, node, ("Exponent", "Randomness", None)), mode])


TRANSLATORS = {
    "ShaderNodeTexWhiteNoise": _white_noise,
    "ShaderNodeTexNoise": _noise,
    "ShaderNodeTexVoronoi": _voronoi,
}
