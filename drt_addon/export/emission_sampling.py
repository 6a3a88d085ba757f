"""Material > Settings > Emission Sampling, as Cycles decides it (scene/shader.cpp,
Shader::estimate_emission): which sides of a material's emissive triangles next-event
estimation samples ('NONE', 'FRONT', 'BACK' or 'FRONT_BACK'; engine.Material
.emission_sampling). A side left out is still seen by the rays that hit it, with
multiple importance sampling weight 1.

'Auto', Blender's default, samples both sides of a material whose estimated emission
exceeds 0.5 in some channel and none of a dimmer one (its light is found by BSDF rays
alone). The estimate follows the node tree from the Material Output's Surface, as
Cycles' output_estimate_emission does: an Emission, Background or Principled BSDF gives
its colour (1 where linked) times its strength (where linked: what the link gives, a
Light Falloff's own Strength or 1); an Add Shader the sum of its two; a Mix Shader the
mix at its Fac (the sum where the Fac is linked); any other shader the sum of its shader
inputs. A colour linked straight into Surface (Cycles converts it to an Emission) counts
a tenth. A node group or a node DRT does not know counts 1 (sampled), as Cycles counts
a node whose emission it cannot estimate."""
from __future__ import annotations

from .nodes.links import _link, _output_node, uses_nodes

METHODS = ("NONE", "AUTO", "FRONT", "BACK", "FRONT_BACK")
AUTO_THRESHOLD = 0.5          # Cycles: reduce_max(|estimate x scale|) > 0.5
AUTO_CONVERSION_SCALE = 0.1   # ... for an Emission made from a colour linked to Surface

_EMITTERS = {"ShaderNodeEmission": ("Color", "Strength"),
             "ShaderNodeBackground": ("Color", "Strength"),
             "ShaderNodeBsdfPrincipled": ("Emission Color", "Emission Strength")}


def _value(socket):
    v = getattr(socket, "default_value", 0.0)
    try:
        return [float(x) for x in tuple(v)[:3]]
    except TypeError:
        return [float(v)] * 3


def _times(a, b):
    return [x * y for x, y in zip(a, b)]


def _plus(a, b):
    return [x + y for x, y in zip(a, b)]


def _strength_link(found, depth):
    """What a linked Strength gives the estimate: a Light Falloff's own Strength (or
    what feeds it), anything else 1."""
    node = found[0]
    if node.bl_idname == "ShaderNodeLightFalloff" and depth < 32:
        sock = node.inputs["Strength"]
        inner = _link(sock)
        return _value(sock) if inner is None else _strength_link(inner, depth + 1)
    return [1.0, 1.0, 1.0]


def _estimate(found, depth=0, memo=None):
    """The emission estimate (r, g, b) of the closure output `found` = (node, socket),
    each output estimated once (`memo`: a chain of Mix Shaders feeding both inputs of
    the next would otherwise take 2^length steps)."""
    node, out = found
    if depth > 64:
        return [1.0, 1.0, 1.0]
    memo = {} if memo is None else memo
    key = (node.as_pointer(), out.identifier)
    if key not in memo:
        memo[key] = _estimate_node(node, out, depth, memo)
    return memo[key]


def _estimate_node(node, out, depth, memo):
    kind = node.bl_idname
    if kind in _EMITTERS:
        color_name, strength_name = _EMITTERS[kind]
        color, strength = node.inputs[color_name], node.inputs[strength_name]
        est = [1.0, 1.0, 1.0] if _link(color) is not None else _value(color)
        linked = _link(strength)
        return _times(est, _value(strength) if linked is None
                      else _strength_link(linked, depth + 1))
    if kind == "ShaderNodeAddShader":
        return _plus(*(_closure_input(node.inputs[k], depth, memo) for k in (0, 1)))
    if kind == "ShaderNodeMixShader":
        a, b = (_closure_input(node.inputs[k], depth, memo) for k in (1, 2))
        if _link(node.inputs[0]) is not None:
            return _plus(a, b)
        fac = _value(node.inputs[0])[0]
        return _plus([(1.0 - fac) * x for x in a], [fac * x for x in b])
    if out.type != "SHADER" or kind == "ShaderNodeGroup" or not kind.startswith(
            "ShaderNode"):
        return [1.0, 1.0, 1.0]
    total = [0.0, 0.0, 0.0]
    for sock in node.inputs:
        if sock.type == "SHADER":
            total = _plus(total, _closure_input(sock, depth, memo))
    return total


def _closure_input(socket, depth, memo):
    found = _link(socket)
    return [0.0, 0.0, 0.0] if found is None else _estimate(found, depth + 1, memo)


def surface_estimate(mat):
    """Cycles' emission estimate of the material's surface (r, g, b), and the scale Auto
    applies to it."""
    out = _output_node(mat.node_tree)
    found = None if out is None else _link(out.inputs["Surface"])
    if found is None:
        return [0.0, 0.0, 0.0], 1.0
    scale = AUTO_CONVERSION_SCALE if found[1].type != "SHADER" else 1.0
    return _estimate(found), scale


def emission_sampling(mat) -> str:
    """The sides of `mat`'s emissive triangles that next-event estimation samples."""
    method = getattr(getattr(mat, "cycles", None), "emission_sampling", "AUTO")
    if method not in METHODS:
        method = "AUTO"
    if method != "AUTO":
        return method
    if mat is None or not uses_nodes(mat):
        return "FRONT_BACK"
    try:
        estimate, scale = surface_estimate(mat)
    except Exception:            # a tree the estimate cannot walk: sampled, as before
        return "FRONT_BACK"
    return ("FRONT_BACK" if max(abs(x * scale) for x in estimate) > AUTO_THRESHOLD
            else "NONE")
