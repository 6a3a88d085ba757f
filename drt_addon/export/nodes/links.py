"""Walking Blender node trees: whether a datablock uses its nodes, a material's active
output, the node linked into a socket (through reroutes) and every node of a tree with
its groups."""
from __future__ import annotations

import bpy


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


def _link(socket):
    """(from node, from socket) feeding `socket`, through reroutes; None if unlinked
    (or linked only through a muted link)."""
    if not socket.is_linked:
        return None
    link = socket.links[0]
    if getattr(link, "is_muted", False):
        return None
    node, out = link.from_node, link.from_socket
    while node.bl_idname == "NodeReroute":
        if not node.inputs[0].is_linked:
            return None
        link = node.inputs[0].links[0]
        node, out = link.from_node, link.from_socket
    return node, out


def _linked_node(socket):
    found = _link(socket)
    return None if found is None else found[0]


def _all_nodes(tree, seen=None):
    """The nodes of a tree and of the node groups in it (each group once)."""
    seen = set() if seen is None else seen
    for n in tree.nodes:
        yield n
        sub = getattr(n, "node_tree", None) if n.bl_idname == "ShaderNodeGroup" else None
        if sub is not None and sub.name_full not in seen:
            seen.add(sub.name_full)
            yield from _all_nodes(sub, seen)
