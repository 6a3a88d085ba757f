"""The AOV Output node (Cycles' svm/aov.h): what a material's AOV Output nodes receive
on their Color and Value inputs, compiled into a shader program of its own
(engine.shader_aovs.ShaderAOVs), which only the view layer's AOV passes evaluate."""
from __future__ import annotations

import importlib

from ...engine_link import engine
from .compiler import NodeCompiler

shader_aovs = importlib.import_module(engine.__name__ + ".shader_aovs")

AOV_OUTPUT = "ShaderNodeOutputAOV"


def material_aovs(mat, ctx):
    """The ShaderAOVs of material `mat`'s (unmuted, top-level) AOV Output nodes, None
    when it has none. Two nodes of one AOV name: the first is read."""
    nodes = [n for n in mat.node_tree.nodes if n.bl_idname == AOV_OUTPUT and not n.mute
             and n.aov_name]
    if not nodes:
        return None
    c = NodeCompiler(ctx)
    outputs = {}
    for node in nodes:
        if node.aov_name not in outputs:
            outputs[node.aov_name] = (c.input(node, "Color", "color"),
                                      c.input(node, "Value", "float"))
    return shader_aovs.ShaderAOVs(c.build(), outputs)
