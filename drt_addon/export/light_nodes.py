"""A lamp's shader node tree (Light > Nodes), as Cycles reads it: the Emission shader at
the active Light Output multiplies the lamp's own strength (colour x power) by its Color
and its Strength (1 and white in the tree Blender makes, so that tree changes nothing).

Read: Color and Strength as set on the Emission node, or from constant nodes (Value,
RGB, Blackbody of a constant temperature, Math with constant operands, a Light Falloff
node's Quadratic output, which is its Strength: Cycles' physical falloff), through
reroutes. Nothing reaching the Light Output is no light, as in Cycles. What varies over
the lamp or with the ray (textures, Light Falloff's Linear and Constant outputs,
ray-dependent inputs) is not read: the exporter then uses the lamp's own strength and
says so.
"""
from __future__ import annotations

import math

from .blackbody import blackbody_rgb
from .nodes.links import _link

MATH = {"ADD": lambda a, b: a + b, "SUBTRACT": lambda a, b: a - b,
        "MULTIPLY": lambda a, b: a * b,
        "DIVIDE": lambda a, b: a / b if b != 0.0 else 0.0,      # Cycles' safe division
        "POWER": lambda a, b: a ** b if a > 0.0 or float(b).is_integer() else 0.0,
        "MAXIMUM": max, "MINIMUM": min}


class Unread(Exception):
    """A node whose value DRT cannot take as a constant."""


def _source(socket):
    """The output socket feeding `socket` (through reroutes), or None when unlinked."""
    found = _link(socket)
    return None if found is None else found[1]


def _float(socket) -> float:
    out = _source(socket)
    if out is None:
        return float(socket.default_value)
    node = out.node
    if node.type == "VALUE":
        return float(out.default_value)
    if node.type == "MATH" and node.operation in MATH:
        a, b = (_float(s) for s in node.inputs[:2])
        v = MATH[node.operation](a, b)
        return min(max(v, 0.0), 1.0) if node.use_clamp else v
    if node.type == "LIGHT_FALLOFF" and out.name == "Quadratic" \
            and _float(node.inputs["Smooth"]) == 0.0:
        return _float(node.inputs["Strength"])
    raise Unread(node.name)


def _color(socket) -> tuple:
    out = _source(socket)
    if out is None:
        return tuple(float(c) for c in socket.default_value[:3])
    if out.node.type == "RGB":
        return tuple(float(c) for c in out.default_value[:3])
    if out.node.type == "BLACKBODY":
        return blackbody_rgb(_float(out.node.inputs["Temperature"]))
    raise Unread(out.node.name)


def _output(tree):
    outs = [n for n in tree.nodes if n.type == "OUTPUT_LIGHT"]
    active = [n for n in outs if getattr(n, "is_active_output", False)]
    return (active or outs or [None])[0]


def emission_factor(light) -> tuple[tuple | None, str | None]:
    """(RGB factor on the lamp's strength, None) when its nodes read as a constant
    Emission; (None, why) when they cannot be read (the lamp keeps its own strength);
    ((1, 1, 1), None) for a lamp without nodes."""
    tree = getattr(light, "node_tree", None)
    if not getattr(light, "use_nodes", False) or tree is None:
        return (1.0, 1.0, 1.0), None
    out = _output(tree)
    src = _source(out.inputs["Surface"]) if out is not None else None
    if src is None:
        return (0.0, 0.0, 0.0), None          # no shader: Cycles emits nothing
    if src.node.type != "EMISSION":
        return None, f"its nodes end in {src.node.name!r}, which DRT does not read"
    try:
        strength = _float(src.node.inputs["Strength"])
        color = _color(src.node.inputs["Color"])
    except Unread as e:
        return None, f"its node {e.args[0]!r} varies, which DRT does not read"
    if not all(math.isfinite(c) for c in color) or not math.isfinite(strength):
        return None, "its nodes give a non-finite strength"
    return tuple(c * strength for c in color), None
