"""Colour nodes to program operations (engine.nodes.color_nodes): Mix (Color, and its
Float and Vector kinds), MixRGB, Color Ramp, Invert, Gamma, Bright/Contrast,
Hue/Saturation/Value, RGB Curves."""
from __future__ import annotations

import importlib

import numpy as np

from ...engine_link import engine
from .errors import Unsupported

CO = importlib.import_module(engine.__name__ + ".nodes.color_nodes")
CV = importlib.import_module(engine.__name__ + ".nodes.converter_nodes")


def _saturate(c, value):
    return c.emit(CV.CV_CLAMP, "float", [value, c.const(0.0), c.const(1.0), 0])


def _by_identifier(node, identifier):
    return next(s for s in node.inputs if s.identifier == identifier)


def _mix(c, node, out):
    kind = node.data_type
    fac_sock = _by_identifier(node, "Factor_Vector" if (
        kind == "VECTOR" and node.factor_mode == "NON_UNIFORM") else "Factor_Float")
    if kind == "RGBA":
        fac = c.socket(fac_sock, "float")
        if node.clamp_factor:
            fac = _saturate(c, fac)
        if node.blend_type not in CO.BLEND_MODES:
            raise Unsupported(f"blend mode {node.blend_type}")
        a = c.socket(_by_identifier(node, "A_Color"), "color")
        b = c.socket(_by_identifier(node, "B_Color"), "color")
        return c.emit(CO.COL_MIX, "color", [fac, a, b, CO.BLEND_MODES.index(node.blend_type),
                                            int(node.clamp_result)])
    if kind == "FLOAT":
        fac = c.socket(fac_sock, "float")
        if node.clamp_factor:
            fac = _saturate(c, fac)
        return c.emit(CV.CV_MIX_FLOAT, "float", [fac, c.socket(_by_identifier(node, "A_Float"),
                                                               "float"),
                                                 c.socket(_by_identifier(node, "B_Float"),
                                                          "float")])
    if kind == "VECTOR":
        per_axis = node.factor_mode == "NON_UNIFORM"
        fac = c.socket(fac_sock, "vector" if per_axis else "float")
        if node.clamp_factor:
            if per_axis:
                parts = [_saturate(c, c.emit(CV.CV_SEPARATE, "float", [fac, k]))
                         for k in range(3)]
                fac = c.emit(CV.CV_COMBINE, "vector", parts)
            else:
                fac = _saturate(c, fac)
        return c.emit(CV.CV_MIX_VECTOR, "vector",
                      [fac, c.socket(_by_identifier(node, "A_Vector"), "vector"),
                       c.socket(_by_identifier(node, "B_Vector"), "vector"), int(per_axis)])
    raise Unsupported(f"Mix of {kind} data")


def _mix_rgb(c, node, out):
    fac = _saturate(c, c.input(node, "Fac", "float"))
    if node.blend_type not in CO.BLEND_MODES:
        raise Unsupported(f"blend mode {node.blend_type}")
    return c.emit(CO.COL_MIX, "color", [fac, c.input(node, 1, "color"),
                                        c.input(node, 2, "color"),
                                        CO.BLEND_MODES.index(node.blend_type),
                                        int(node.use_clamp)])


def _ramp(c, node, out):
    ramp = node.color_ramp
    if ramp.color_mode != "RGB" and ramp.interpolation not in ("CONSTANT", "LINEAR"):
        c.ctx.issue(f"{node.name!r} interpolates in {ramp.color_mode}; DRT uses the table "
                    f"Blender evaluates")
    n = CO.RAMP_TABLE_SIZE
    table = np.array([tuple(ramp.evaluate(i / (n - 1))) for i in range(n)], np.float64)
    offset = c.b.data(table)
    fac = c.input(node, "Fac", "float")
    interpolate = int(ramp.interpolation != "CONSTANT")
    if out.identifier == "Alpha":
        return c.emit(CO.COL_RAMP_ALPHA, "float", [fac, 0, 0, interpolate, offset])
    return c.emit(CO.COL_RAMP_COLOR, "color", [fac, 0, 0, interpolate, offset])


def _invert(c, node, out):
    return c.emit(CO.COL_INVERT, "color", [c.input(node, "Fac", "float"),
                                           c.input(node, "Color", "color")])


def _gamma(c, node, out):
    return c.emit(CO.COL_GAMMA, "color", [c.input(node, "Color", "color"),
                                          c.input(node, "Gamma", "float")])


def _bright_contrast(c, node, out):
    return c.emit(CO.COL_BRIGHT_CONTRAST, "color", [c.input(node, "Color", "color"),
                                                    c.input(node, "Bright", "float"),
                                                    c.input(node, "Contrast", "float")])


def _hsv(c, node, out):
    return c.emit(CO.COL_HSV, "color", [c.input(node, "Hue", "float"),
                                        c.input(node, "Saturation", "float"),
                                        c.input(node, "Value", "float"),
                                        c.input(node, "Fac", "float"),
                                        c.input(node, "Color", "color")])


def _curves(c, node, out):
    """RGB Curves: Cycles' table of the channel curves applied after the combined one,
    over the x range of all four curves."""
    mapping = node.mapping
    mapping.update()
    xs = [p.location[0] for curve in mapping.curves for p in curve.points]
    lo, hi = (min(xs), max(xs)) if xs else (0.0, 1.0)
    lo, hi = min(lo, 0.0), max(hi, 1.0)
    n = CO.RAMP_TABLE_SIZE
    combined = mapping.curves[3]
    table = np.zeros((n, 4))
    for i in range(n):
        t = lo + i / (n - 1) * (hi - lo)
        ti = mapping.evaluate(combined, t)
        table[i, :3] = [mapping.evaluate(mapping.curves[k], ti) for k in range(3)]
    offset = c.b.data(np.concatenate([[lo, hi], table.ravel()]))
    return c.emit(CO.COL_CURVES, "color", [c.input(node, "Fac", "float"),
                                           c.input(node, "Color", "color"), 0, 0, offset])


TRANSLATORS = {
    "ShaderNodeRGBCurve": _curves,
    "ShaderNodeMix": _mix,
    "ShaderNodeMixRGB": _mix_rgb,
    "ShaderNodeValToRGB": _ramp,
    "ShaderNodeInvert": _invert,
    "ShaderNodeGamma": _gamma,
    "ShaderNodeBrightContrast": _bright_contrast,
    "ShaderNodeHueSaturation": _hsv,
}
