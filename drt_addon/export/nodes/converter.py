"""Converter nodes to program operations (engine.nodes.converter_nodes): Math, Map
Range, Clamp, Separate / Combine XYZ and Color (RGB, HSV, HSL; and the legacy RGB and
HSV nodes), RGB to BW, and Blackbody of a temperature that does not vary per hit (a
constant, export/blackbody.py)."""
from __future__ import annotations

import importlib

import numpy as np

from ...engine_link import engine
from ..blackbody import blackbody_rgb, table as blackbody_table
from .errors import Unsupported

CV = importlib.import_module(engine.__name__ + ".nodes.converter_nodes")
COL = importlib.import_module(engine.__name__ + ".nodes.color_nodes")


def _math(c, node, out):
    if node.operation not in CV.MATH_OPS:
        raise Unsupported(f"the Math operation {node.operation}")
    a, b, d = (c.input(node, k, "float") for k in range(3))
    return c.emit(CV.CV_MATH, "float", [a, b, d, CV.MATH_OPS.index(node.operation),
                                        int(node.use_clamp)])


def _map_range(c, node, out):
    if node.data_type != "FLOAT":
        raise Unsupported("Map Range on vectors")
    kind = CV.MAP_RANGE_TYPES.index(node.interpolation_type)
    to = c.emit(CV.CV_COMBINE, "vector", [c.input(node, "To Min", "float"),
                                          c.input(node, "To Max", "float"),
                                          c.input(node, "Steps", "float")
                                          if node.inputs.get("Steps") is not None
                                          else c.const(4.0)])
    return c.emit(CV.CV_MAP_RANGE, "float", [c.input(node, "Value", "float"),
                                             c.input(node, "From Min", "float"),
                                             c.input(node, "From Max", "float"), to,
                                             2 * kind + int(node.clamp)])


def _clamp(c, node, out):
    return c.emit(CV.CV_CLAMP, "float", [c.input(node, "Value", "float"),
                                         c.input(node, "Min", "float"),
                                         c.input(node, "Max", "float"),
                                         int(node.clamp_type == "RANGE")])


def _component(c, value, out):
    k = next(i for i, s in enumerate(out.node.outputs) if s.identifier == out.identifier)
    return c.emit(CV.CV_SEPARATE, "float", [value, k])


def _separate_xyz(c, node, out):
    return _component(c, c.input(node, "Vector", "vector"), out)


def _combine_xyz(c, node, out):
    return c.emit(CV.CV_COMBINE, "vector", [c.input(node, k, "float") for k in range(3)])


TO_MODEL = {"HSV": CV.CV_RGB_TO_HSV, "HSL": CV.CV_RGB_TO_HSL}
FROM_MODEL = {"HSV": CV.CV_HSV_TO_RGB, "HSL": CV.CV_HSL_TO_RGB}


def _separate_color(c, node, out, mode=None):
    mode = mode or getattr(node, "mode", "RGB")
    color = c.input(node, 0, "color")
    if mode != "RGB":
        color = c.emit(TO_MODEL[mode], "color", [color])
    return _component(c, color, out)


def _combine_color(c, node, out, mode=None):
    mode = mode or getattr(node, "mode", "RGB")
    color = c.emit(CV.CV_COMBINE, "color", [c.input(node, k, "float") for k in range(3)])
    if mode != "RGB":
        color = c.emit(FROM_MODEL[mode], "color", [color])
    return color


def _rgb_to_bw(c, node, out):
    return c.input(node, "Color", "float")         # the link converts by luminance


def blackbody_of(c, kelvin):
    """Blender's blackbody colour (luminance 1, export/blackbody.py) of a temperature
    Value: a constant when it folds to one, else looked up per hit in the table (linear
    between its 25 K rows, as blackbody_rgb)."""
    folded = c.fold(kelvin)
    if folded is not None:
        return c.const(blackbody_rgb(folded), "color")
    t, rgb = blackbody_table()
    offset = c.b.data(np.concatenate([[t[0], t[-1], len(t)], rgb.ravel()]))
    return c.emit(COL.COL_TABLE, "color", [kelvin, 0, 0, 0, offset])


def _blackbody(c, node, out):
    return blackbody_of(c, c.input(node, "Temperature", "float"))


TRANSLATORS = {
    "ShaderNodeBlackbody": _blackbody,
    "ShaderNodeMath": _math,
    "ShaderNodeMapRange": _map_range,
    "ShaderNodeClamp": _clamp,
    "ShaderNodeSeparateXYZ": _separate_xyz,
    "ShaderNodeCombineXYZ": _combine_xyz,
    "ShaderNodeSeparateColor": _separate_color,
    "ShaderNodeCombineColor": _combine_color,
    "ShaderNodeSeparateRGB": lambda c, n, o: _separate_color(c, n, o, "RGB"),
    "ShaderNodeCombineRGB": lambda c, n, o: _combine_color(c, n, o, "RGB"),
    "ShaderNodeSeparateHSV": lambda c, n, o: _separate_color(c, n, o, "HSV"),
    "ShaderNodeCombineHSV": lambda c, n, o: _combine_color(c, n, o, "HSV"),
    "ShaderNodeRGBToBW": _rgb_to_bw,
}
