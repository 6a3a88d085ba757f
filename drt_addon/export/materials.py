"""Blender materials to DRT's Principled parameters.

Reads the node tree's active surface output: a Principled BSDF's own values, with Cycles'
4.x socket names. What DRT cannot model yet (linked sockets, other shader nodes) falls
back to a sensible approximation and is reported once per material.
"""
from __future__ import annotations

import bpy

from ..engine_link import engine
from .errors import Reporter


def uses_nodes(datablock) -> bool:
    """Blender 5 always uses the node tree (use_nodes is deprecated); 4.x has the toggle."""
    if datablock.node_tree is None:
        return False
    return bpy.app.version >= (5, 0, 0) or datablock.use_nodes


def _output_node(tree):
    outputs = [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]
    for n in outputs:
        if getattr(n, "is_active_output", False) and n.target in ("ALL", "CYCLES"):
            return n
    for n in outputs:
        if n.target in ("ALL", "CYCLES"):
            return n
    return outputs[0] if outputs else None


def _linked_node(socket):
    if not socket.is_linked:
        return None
    link = socket.links[0]
    node = link.from_node
    # Walk through reroutes.
    while node.bl_idname == "NodeReroute" and node.inputs[0].is_linked:
        node = node.inputs[0].links[0].from_node
    return node


def _value(node, name, default, reporter, mat_name):
    sock = node.inputs.get(name)
    if sock is None:
        return default
    if sock.is_linked:
        reporter.warn(f"DRT: material {mat_name!r}: the input '{name}' of "
                      f"{node.name!r} is connected to other nodes, which DRT does not "
                      f"evaluate yet; using its unconnected value",
                      key=(mat_name, name))
    v = sock.default_value
    try:
        return tuple(v)
    except TypeError:
        return float(v)


def export_material(mat, reporter: Reporter) -> "engine.Material":
    if mat is None:
        return engine.Material("none")
    name = mat.name
    fallback = engine.Material(name, tuple(mat.diffuse_color[:3]), metallic=float(mat.metallic),
                               roughness=float(mat.roughness), specular_ior_level=0.5)
    if not uses_nodes(mat):
        return fallback
    out = _output_node(mat.node_tree)
    if out is None:
        reporter.warn(f"DRT: material {name!r} has no Material Output node; using its "
                      f"viewport colour", key=(name, "output"))
        return fallback
    node = _linked_node(out.inputs["Surface"])
    if node is None:
        return engine.Material(name, (0.0, 0.0, 0.0), specular_ior_level=0.0)
    if node.bl_idname == "ShaderNodeBsdfPrincipled":
        def v(n, d):
            return _value(node, n, d, reporter, name)
        base = v("Base Color", (0.8, 0.8, 0.8, 1.0))
        emission = v("Emission Color", (0.0, 0.0, 0.0, 1.0))
        strength = v("Emission Strength", 0.0)
        return engine.Material(
            name, tuple(base[:3]), metallic=v("Metallic", 0.0), roughness=v("Roughness", 0.5),
            ior=v("IOR", 1.5), transmission=v("Transmission Weight", 0.0),
            specular_ior_level=v("Specular IOR Level", 0.5),
            emission=tuple(c * strength for c in emission[:3]), alpha=v("Alpha", 1.0))
    if node.bl_idname == "ShaderNodeEmission":
        color = _value(node, "Color", (1, 1, 1, 1), reporter, name)
        strength = _value(node, "Strength", 1.0, reporter, name)
        return engine.Material(name, (0.0, 0.0, 0.0), specular_ior_level=0.0,
                               emission=tuple(c * strength for c in color[:3]))
    if node.bl_idname == "ShaderNodeBsdfDiffuse":
        color = _value(node, "Color", (0.8, 0.8, 0.8, 1), reporter, name)
        return engine.Material(name, tuple(color[:3]), specular_ior_level=0.0)
    reporter.warn(f"DRT: material {name!r} uses the {node.bl_label!r} node, which DRT does "
                  f"not support yet; rendering it as a diffuse surface of its viewport colour",
                  key=(name, "node"))
    return fallback
