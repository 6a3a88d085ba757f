"""Material Output > Displacement, as Cycles renders it.

Bump Only (Material > Settings > Displacement, Blender's default): the surface is not
moved; its shading normal is bent as if it were, as Cycles builds it (its shader graph's
bump from displacement):
the displacement vector's height along the normal, dot(displacement, N), at the hit and
at the hit moved by a Filter Width (0.1) of its pixel steps in x and y, feeds a Bump of
Distance 1 and Strength 1 whose normal replaces the surface's own (Cycles' Set Normal:
engine.Material.sets_normal).

The Displacement node gives (Height - Midlevel) x Scale along its Normal (the shading
normal when unlinked), in Object space (its default) taken into the object's space,
normalised there and brought back, so that a scaled object scales it (engine.nodes.bump
DISP_OBJECT_VECTOR); any other vector is used as it is.

Displacement Only and Displacement and Bump move the surface (`true_displacement`: an
engine.displacement.Displacement, its own program, run on the mesh's vertices at export);
Displacement and Bump also bends the normal as Bump Only does, evaluated, as in Cycles, at
the undisplaced surface (its position and object coordinates, and its pixel steps for
the bent normal: NodeCompiler.undisplaced) and worked out in the object's space
(BUMP_NORMAL_OBJECT).
"""
from __future__ import annotations

import importlib

from ...engine_link import engine
from .compiler import NodeCompiler
from .input import normal_input
from .links import _linked_node
from .vector import BU, FILTER_WIDTH, VE, _math

C = importlib.import_module(engine.__name__ + ".nodes.context")
D = importlib.import_module(engine.__name__ + ".displacement")


def displacement_method(mat) -> str:
    """Material > Settings > Displacement: 'BUMP', 'DISPLACEMENT' or 'BOTH' (Blender 4.1+
    keeps it on the material, older versions in its Cycles settings)."""
    return (getattr(mat, "displacement_method", None)
            or getattr(getattr(mat, "cycles", None), "displacement_method", None) or "BUMP")


def moves_surface(materials) -> bool:
    """Whether any of an object's materials (layer_overrides.slot_materials) moves its
    surface: a linked Displacement socket and a method other than Bump Only (its meshes
    then need vertex normals)."""
    from .links import _link, _output_node, uses_nodes
    for mat in materials:
        if mat is None or not uses_nodes(mat) or displacement_method(mat) == "BUMP":
            continue
        out = _output_node(mat.node_tree)
        disp = out.inputs.get("Displacement") if out is not None else None
        if disp is not None and _link(disp) is not None:
            return True
    return False


def true_displacement(mat, socket, ctx):
    """The engine.displacement.Displacement of a material whose displacement moves the
    surface (Displacement Only, Displacement and Bump); None for Bump Only. Compiled into
    a program of its own, so that surface hits never run it."""
    method = displacement_method(mat)
    if method == "BUMP":
        return None
    c = NodeCompiler(ctx)
    src = _linked_node(socket)
    height = None
    if src is not None and src.bl_idname == "ShaderNodeDisplacement":
        h = _math(c, "SUBTRACT", c.input(src, "Height", "float"),
                  c.input(src, "Midlevel", "float"))
        height = _math(c, "MULTIPLY", h, c.input(src, "Scale", "float"))
        direction, kind, space = normal_input(c, src), "NORMAL", src.space
    elif src is not None and src.bl_idname == "ShaderNodeVectorDisplacement":
        mid = c.convert(c.input(src, "Midlevel", "float"), "vector")
        v = c.emit(VE.VEC_MATH, "vector", [c.input(src, "Vector", "vector"), mid, mid,
                                           c.const(1.0), VE.VECTOR_OPS.index("SUBTRACT")])
        direction = c.emit(VE.VEC_MATH, "vector", [v, v, v, c.input(src, "Scale", "float"),
                                                   VE.VECTOR_OPS.index("SCALE")])
        kind, space = "VECTOR", src.space
    else:                 # any other vector: a world-space offset, as Cycles adds it to P
        direction, kind, space = c.socket(socket, "vector"), "VECTOR", "WORLD"
    return D.Displacement(c.build(), direction, height, kind, space,
                          keep_normals=method == "BOTH")


def _height(c, socket):
    """dot(displacement, N) of what is linked to the Displacement socket (Cycles' bump
    from displacement). A Displacement node in Object space (its default) gives
    M normalize(M^T N) x height, which a scaled object lengthens or shortens."""
    src = _linked_node(socket)
    if src is not None and src.bl_idname == "ShaderNodeDisplacement":
        h = _math(c, "SUBTRACT", c.input(src, "Height", "float"),
                  c.input(src, "Midlevel", "float"))
        scaled = _math(c, "MULTIPLY", h, c.input(src, "Scale", "float"))
        along = normal_input(c, src)
        if src.space == "OBJECT":
            d = c.emit(BU.DISP_OBJECT_VECTOR, "vector", [along, scaled], varying=True)
        elif not src.inputs["Normal"].is_linked:
            return scaled         # along the shading normal: dot with N is the height
        else:
            d = c.emit(VE.VEC_MATH, "vector", [along, along, along, scaled,
                                               VE.VECTOR_OPS.index("SCALE")])
    else:
        d = c.socket(socket, "vector")
    n = c.normal()
    one = c.const(1.0)
    return c.emit(VE.VEC_MATH_VALUE, "float", [d, n, n, one, VE.VECTOR_OPS.index("DOT_PRODUCT")])


def displacement_normal(mat, socket, ctx):
    """The bent shading normal (a program Value) of the material's linked Displacement
    socket, or None when it does not vary (nothing to bend) or the method does not bump
    (Displacement Only: Cycles bends nothing; the moved surface has its own normals)."""
    method = displacement_method(mat)
    if method == "DISPLACEMENT":
        return None
    c = ctx.nodes
    # whether the height varies, asked of a scratch compiler: the material's program then
    # holds the height only where the bump uses it (inside the undisplaced region for
    # Displacement and Bump)
    if not _height(NodeCompiler(ctx), socket).varying:
        return None

    def bent(steps=lambda: None):
        h = _height(c, socket)
        width = c.const(FILTER_WIDTH)
        hx, hy = (c.at_offset(axis, width, lambda: _height(c, socket)) for axis in (0, 1))
        steps()
        # Displacement and Bump: Cycles works the bump out in the object's space
        op = BU.BUMP_NORMAL_OBJECT if method == "BOTH" else BU.BUMP_NORMAL
        return c.emit(op, "vector", [c.normal(), c.const(1.0), c.const(1.0),
                                                width, _math(c, "SUBTRACT", hx, h),
                                                _math(c, "SUBTRACT", hy, h)], varying=True)
    # Displacement and Bump: on the moved surface, bumped as if it had not moved
    return c.undisplaced(bent) if method == "BOTH" else bent()
