"""Procedural texture nodes to program operations (engine.nodes.procedural_nodes):
White Noise, Noise, Voronoi, Wave, Magic, Brick.

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
PAT = importlib.import_module(engine.__name__ + ".nodes.pattern_textures")
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


def _wave(c, node, out):
    mode = (_index(PAT.WAVE_TYPES, node.wave_type, "wave type")
            + 2 * _index(PAT.BANDS_DIRECTIONS, node.bands_direction, "bands direction")
            + 8 * _index(PAT.RINGS_DIRECTIONS, node.rings_direction, "rings direction")
            + 32 * _index(PAT.WAVE_PROFILES, node.wave_profile, "wave profile"))
    fac = c.emit(P.TEX_WAVE, "float",
                 [_texture_coordinates(c, node), _float(c, node, "Scale"),
                  _pack(c, node, ("Distortion", "Detail", "Detail Scale")),
                  _pack(c, node, ("Detail Roughness", "Phase Offset", None)), mode])
    return fac if out.identifier == "Fac" else c.convert(fac, "color")


def _magic(c, node, out):
    color = c.emit(P.TEX_MAGIC, "color",
                   [_texture_coordinates(c, node), _float(c, node, "Scale"),
                    _float(c, node, "Distortion"), int(node.turbulence_depth)])
    if out.identifier == "Fac":                    # Cycles: the colour's average
        return c.emit(CV.CV_AVERAGE, "float", [color])
    return color


def _brick(c, node, out):
    props = c.const((float(node.offset), float(node.squash), 0.0), "vector")
    frequencies = int(node.offset_frequency) + 1024 * int(node.squash_frequency)
    bricks = c.emit(P.TEX_BRICK, "vector",
                    [_texture_coordinates(c, node),
                     _pack(c, node, ("Scale", "Mortar Size", "Mortar Smooth")),
                     _pack(c, node, ("Bias", "Brick Width", "Row Height")), props,
                     frequencies])
    if out.identifier == "Fac":
        return c.emit(CV.CV_SEPARATE, "float", [bricks, 1])
    return c.emit(P.TEX_BRICK_COLOR, "color",
                  [bricks, c.input(node, "Color1", "color"), c.input(node, "Color2", "color"),
                   c.input(node, "Mortar", "color")])


TRANSLATORS = {
    "ShaderNodeTexWhiteNoise": _white_noise,
    "ShaderNodeTexNoise": _noise,
    "ShaderNodeTexVoronoi": _voronoi,
    "ShaderNodeTexWave": _wave,
    "ShaderNodeTexMagic": _magic,
    "ShaderNodeTexBrick": _brick,
}
