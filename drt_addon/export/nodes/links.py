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


def usable_link(socket):
    """The link into input `socket` that Cycles follows, or None: an unlinked socket, a
    muted link and an invalid one (Blender marks one link of every cycle of nodes
    invalid, drawn red) count as unlinked, as Cycles' shader sync skips them."""
    if not socket.is_linked:
        return None
    link = socket.links[0]
    if getattr(link, "is_muted", False) or not getattr(link, "is_valid", True):
        return None
    return link


def _link(socket):
    """(from node, from socket) feeding `socket`, through reroutes; None if unlinked
    (or linked only through a muted or invalid link, or a loop of reroutes)."""
    link = usable_link(socket)
    seen = set()
    while link is not None:
        node, out = link.from_node, link.from_socket
        if node.bl_idname != "NodeReroute":
            return node, out
        if node.as_pointer() in seen:
            return None
        seen.add(node.as_pointer())
        link = usable_link(node.inputs[0])
    return None


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


def tree_problems(tree) -> list:
    """What is broken in a node tree (and its groups), as the user sees it in the node
    editor: links Blender marks invalid (a cycle of nodes: red links), which are ignored
    as in Cycles; and reroutes with nothing linked into them, whose sockets keep their
    own values."""
    problems = []
    trees = [tree] + [n.node_tree for n in _all_nodes(tree)
                      if n.bl_idname == "ShaderNodeGroup" and n.node_tree is not None]
    for t in trees:
        bad = [link for link in t.links
               if not getattr(link, "is_valid", True) and not getattr(link, "is_muted", False)]
        if bad:
            names = sorted({f"{link.from_node.name!r} -> {link.to_node.name!r}" for link in bad})
            problems.append(f"its nodes are linked in a loop ({', '.join(names)}); the loop's "
                            f"invalid (red) links are ignored, as in Cycles")
        dangling = sorted(n.name for n in t.nodes if n.bl_idname == "NodeReroute"
                          and not n.inputs[0].is_linked and n.outputs[0].is_linked)
        if dangling:
            problems.append(f"nothing is linked into the reroute {', '.join(map(repr, dangling))}"
                            f"; the sockets it feeds use their own values")
    return problems
