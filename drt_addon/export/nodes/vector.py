"""Vector nodes to program operations (engine.nodes.vector_nodes, engine.nodes.bump):
Vector Math, Mapping, Normal, Normal Map (tangent space, from the tangents of the mesh's
UV map) and Bump."""
from __future__ import annotations

import importlib
import math

from ...engine_link import engine
from .errors import Unsupported
from .input import normal_input

VE = importlib.import_module(engine.__name__ + ".nodes.vector_nodes")
BU = importlib.import_module(engine.__name__ + ".nodes.bump")
CV = importlib.import_module(engine.__name__ + ".nodes.converter_nodes")
FILTER_WIDTH = 0.1           # Cycles' bump offset before the Filter Width input (4.x)


def _vector_math(c, node, out):
    op = node.operation
    if op not in VE.VECTOR_OPS:
        raise Unsupported(f"the Vector Math operation {op}")
    a, b, d = (c.input(node, k, "vector") for k in range(3))
    scale = c.input(node, 3, "float") if len(node.inputs) > 3 else c.const(1.0)
    code = VE.VEC_MATH_VALUE if op in VE.VALUE_OPS else VE.VEC_MATH
    kind = "float" if op in VE.VALUE_OPS else "vector"
    value = c.emit(code, kind, [a, b, d, scale, VE.VECTOR_OPS.index(op)])
    if out.identifier == "Value" and kind == "vector":
        return c.const(0.0)
    if out.identifier == "Vector" and kind == "float":
        return c.const((0.0, 0.0, 0.0), "vector")
    return value


def _mapping(c, node, out):
    kind = VE.MAPPING_TYPES.index(node.vector_type)
    location = c.input(node, "Location", "vector") if node.inputs.get("Location") else \
        c.const((0.0, 0.0, 0.0), "vector")
    return c.emit(VE.VEC_MAPPING, "vector", [c.input(node, "Vector", "vector"), location,
                                             c.input(node, "Rotation", "vector"),
                                             c.input(node, "Scale", "vector"), kind])


def _normal(c, node, out):
    """Cycles' Normal node (svm_node_normal): its own direction (the sphere widget, kept
    as its Normal output's value), normalised, and the dot product of that direction with
    the normalised Normal input."""
    d = [float(x) for x in node.outputs["Normal"].default_value]
    length = math.sqrt(sum(x * x for x in d))
    direction = c.const(tuple(x / length for x in d) if length > 0.0 else (0.0, 0.0, 0.0),
                        "vector")
    if out.identifier == "Normal":
        return direction
    n = c.input(node, "Normal", "vector")
    one = c.const(1.0)
    unit = c.emit(VE.VEC_MATH, "vector", [n, n, n, one, VE.VECTOR_OPS.index("NORMALIZE")])
    return c.emit(VE.VEC_MATH_VALUE, "float", [direction, unit, unit, one,
                                               VE.VECTOR_OPS.index("DOT_PRODUCT")])


def _normal_map(c, node, out):
    if node.space != "TANGENT":
        raise Unsupported(f"a Normal Map in {node.space} space is not evaluated")
    return c.emit(VE.VEC_NORMAL_MAP, "vector", [c.input(node, "Color", "color"),
                                                c.input(node, "Strength", "float"),
                                                c.normal()], varying=True)


def _math(c, op, a, b):
    return c.emit(CV.CV_MATH, "float", [a, b, b, CV.MATH_OPS.index(op), 0])


def _bump(c, node, out):
    """Cycles' Bump: the Height at the hit and at the hit moved by Filter Width pixel
    steps in x and y; an unlinked Height leaves the Normal input as it is."""
    normal = normal_input(c, node)
    height = node.inputs["Height"]
    if not height.is_linked:
        return normal
    strength = c.input(node, "Strength", "float")
    distance = c.input(node, "Distance", "float")
    if node.invert:
        distance = _math(c, "MULTIPLY", distance, c.const(-1.0))
    width = c.input(node, "Filter Width", "float") if node.inputs.get("Filter Width") \
        else c.const(FILTER_WIDTH)
    h = c.socket(height, "float")
    if not h.varying:
        return normal
    hx, hy = (c.at_offset(axis, width, lambda: c.socket(height, "float"))
              for axis in (0, 1))
    return c.emit(BU.BUMP_NORMAL, "vector", [normal, strength, distance, width,
                                            _math(c, "SUBTRACT", hx, h),
                                            _math(c, "SUBTRACT", hy, h)], varying=True)


TRANSLATORS = {
    "ShaderNodeBump": _bump,
    "ShaderNodeNormalMap": _normal_map,
    "ShaderNodeNormal": _normal,
    "ShaderNodeVectorMath": _vector_math,
    "ShaderNodeMapping": _mapping,
}
