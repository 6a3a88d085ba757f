"""The world's background as uniform radiance (colour x strength)."""
from __future__ import annotations

from ..engine_link import engine
from .errors import Reporter
from .materials import uses_nodes


def export_world(world, reporter: Reporter) -> "engine.World":
    if world is None:
        return engine.World((0.0, 0.0, 0.0))
    if not uses_nodes(world):
        return engine.World(tuple(world.color[:3]))
    tree = world.node_tree
    out = next((n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputWorld"
                and getattr(n, "is_active_output", True)), None)
    if out is None or not out.inputs["Surface"].is_linked:
        return engine.World((0.0, 0.0, 0.0))
    node = out.inputs["Surface"].links[0].from_node
    if node.bl_idname != "ShaderNodeBackground":
        reporter.warn(f"DRT: world {world.name!r} uses {node.bl_label!r}, not supported yet; "
                      "using a black background", key=("world", "node"))
        return engine.World((0.0, 0.0, 0.0))
    color, strength = node.inputs["Color"], node.inputs["Strength"]
    if color.is_linked or strength.is_linked:
        reporter.warn(f"DRT: world {world.name!r}: textured backgrounds are not supported yet; "
                      "using the unconnected colour", key=("world", "linked"))
    s = float(strength.default_value)
    return engine.World(tuple(c * s for c in color.default_value[:3]))
