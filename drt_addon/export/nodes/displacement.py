"""Material Output > Displacement, as Cycles renders it in Bump Only mode (Material >
Settings > Displacement, Blender's default): the surface is not moved; its shading normal
is bent as if it were, as Cycles builds it (its shader graph's bump from displacement):
the displacement vector's height along the normal, dot(displacement, N), at the hit and
at the hit moved by a Filter Width (0.1) of its pixel steps in x and y, feeds a Bump of
Distance 1 and Strength 1 whose normal replaces the surface's.

The Displacement node gives (Height - Midlevel) x Scale along its Normal (the shading
normal when unlinked); any other vector is used as it is. Cycles measures the bump in
object space; DRT in world space (the same for objects that are not scaled).
Displacement Only and Displacement and Bump (true displacement, which moves the
surface) are rendered as Bump Only: reported.
"""
from __future__ import annotations

import importlib

from ...engine_link import engine
from .input import hit3, normal_input
from .links import _linked_node
from .vector import BU, FILTER_WIDTH, VE, _math

C = importlib.import_module(engine.__name__ + ".nodes.context")


def _height(c, socket):
    """dot(displacement, N) of what is linked to the Displacement socket."""
    src = _linked_node(socket)
    if src is not None and src.bl_idname == "ShaderNodeDisplacement":
        h = _math(c, "SUBTRACT", c.input(src, "Height", "float"),
                  c.input(src, "Midlevel", "float"))
        scaled = _math(c, "MULTIPLY", h, c.input(src, "Scale", "float"))
        if not src.inputs["Normal"].is_linked:
            return scaled         # along the shading normal: dot with N is the height
        along = normal_input(c, src)
        d = c.emit(VE.VEC_MATH, "vector", [along, along, along, scaled,
                                           VE.VECTOR_OPS.index("SCALE")])
    else:
        d = c.socket(socket, "vector")
    n = hit3(c, C.H_N)
    one = c.const(1.0)
    return c.emit(VE.VEC_MATH_VALUE, "float", [d, n, n, one, VE.VECTOR_OPS.index("DOT_PRODUCT")])


def displacement_normal(mat, socket, ctx):
    """The bent shading normal (a program Value) of the material's linked Displacement
    socket, or None when it does not vary (nothing to bend)."""
    method = getattr(mat, "displacement_method", None) or getattr(
        getattr(mat, "cycles", None), "displacement_method", "BUMP")
    if method != "BUMP":
        ctx.issue(f"its displacement ({method.replace('_', ' ').title()}) is rendered as "
                  "Bump Only: the surface is not moved")
    c = ctx.nodes
    h = _height(c, socket)
    if not h.varying:
        return None
    width = c.const(FILTER_WIDTH)
    hx, hy = (c.at_offset(axis, width, lambda: _height(c, socket)) for axis in (0, 1))
    return c.emit(BU.BUMP_NORMAL, "vector", [hit3(c, C.H_N), c.const(1.0), c.const(1.0),
                                            width, _math(c, "SUBTRACT", hx, h),
                                            _math(c, "SUBTRACT", hy, h)], varying=True)
