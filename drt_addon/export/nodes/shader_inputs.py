"""The inputs of shader nodes (export.nodes.shader and the modules it hands them to): an
unlinked socket's own value, or the node graph linked to it compiled into the
material's program."""
from __future__ import annotations

from ...blender_compat import node_input
from ..material_params import NodeParam
from .links import _link


def _default(sock, color):
    v = sock.default_value
    if color:
        return tuple(float(x) for x in tuple(v)[:3])
    try:
        return float(v)
    except TypeError:
        return float(tuple(v)[0])


def _input(node, name, ctx, color, default, texturable=True):
    """The value of input `name` of `node`: its own value when unlinked; else the node
    graph linked to it, compiled into the material's program (engine.nodes): a constant
    when the graph does not depend on the hit (folded now), otherwise a NodeParam that
    the program evaluates at every hit (texturable inputs), or its average (reported)."""
    sock = node_input(node, name)
    if sock is None:
        return default
    if _link(sock) is None:
        return _default(sock, color)
    value = ctx.nodes.socket(sock, "color" if color else "float")
    folded = ctx.nodes.fold(value)
    if folded is not None:
        return folded
    param = NodeParam(value, ctx.nodes)
    if not texturable:
        ctx.issue(f"the input '{name}' of {node.name!r} varies per hit, which DRT does not "
                  f"render there; using its average")
        return param.mean()
    return param


def _constant(node, name, ctx, default, color=False):
    return _input(node, name, ctx, color, default, texturable=False)
