"""What a .blend holds, in the words of issue 27's list of what artists bring (hair, VDB
volumes, displacement, subsurface, many lamps, lit fog, light node trees, a world node
program), so docs/public_files.py can say which public files test which of them.

`kinds(scene)` inspects the open file's scene as it renders: objects visible to
the renderer, their modifiers, materials, lamps and world. Nothing is rendered.
"""
from __future__ import annotations

MANY_LAMPS = 8

# in the order the page lists them
KINDS = ("hair", "VDB volume", "smoke or fluid domain", "volume material", "world volume",
         "lamps in a volume", "displacement", "subsurface", "many lamps", "spot lamp",
         "light node tree", "world node program", "Light Path node")

_WORLD_PLAIN = {"ShaderNodeOutputWorld", "ShaderNodeBackground", "ShaderNodeTexEnvironment",
                "ShaderNodeTexCoord", "ShaderNodeMapping", "NodeFrame", "NodeReroute"}


def _output_links(tree, output_type, socket):
    return any(n.bl_idname == output_type and n.inputs[socket].is_linked
               for n in tree.nodes)


def _nodes(tree, seen=None):
    """Every node of a tree and of the node groups in it."""
    seen = set() if seen is None else seen
    for n in tree.nodes:
        yield n
        group = getattr(n, "node_tree", None)
        if group is not None and group.name not in seen:
            seen.add(group.name)
            yield from _nodes(group, seen)


def _subsurface(node) -> bool:
    if node.bl_idname == "ShaderNodeSubsurfaceScattering":
        return True
    if node.bl_idname != "ShaderNodeBsdfPrincipled":
        return False
    weight = node.inputs.get("Subsurface Weight")
    return weight is not None and (weight.is_linked or weight.default_value > 0.0)


def kinds(scene) -> list:
    """The KINDS the scene holds."""
    objects = [o for o in scene.objects if not o.hide_render]
    found = set()
    materials = {slot.material for o in objects for slot in o.material_slots
                 if slot.material is not None and slot.material.node_tree is not None}
    for o in objects:
        if o.type == "VOLUME":
            found.add("VDB volume")
        if o.type == "CURVES" or any(ps.settings.type == "HAIR"
                                     for ps in getattr(o, "particle_systems", [])):
            found.add("hair")
        if any(md.type == "FLUID" for md in o.modifiers):
            found.add("smoke or fluid domain")
    for m in materials:
        tree = m.node_tree
        if _output_links(tree, "ShaderNodeOutputMaterial", "Volume"):
            found.add("volume material")
        if _output_links(tree, "ShaderNodeOutputMaterial", "Displacement") and \
                getattr(m, "displacement_method", "BUMP") != "BUMP":
            found.add("displacement")
        for n in _nodes(tree):
            if _subsurface(n):
                found.add("subsurface")
            if n.bl_idname == "ShaderNodeLightPath":
                found.add("Light Path node")
    lamps = [o for o in objects if o.type == "LIGHT"]
    if len(lamps) >= MANY_LAMPS:
        found.add("many lamps")
    if any(o.data.type == "SPOT" for o in lamps):
        found.add("spot lamp")
    if any(getattr(o.data, "use_nodes", False) and o.data.node_tree is not None
           and len(o.data.node_tree.nodes) > 2 for o in lamps):
        found.add("light node tree")
    world = scene.world
    if world is not None and world.node_tree is not None:
        if _output_links(world.node_tree, "ShaderNodeOutputWorld", "Volume"):
            found.add("world volume")
        names = {n.bl_idname for n in _nodes(world.node_tree)}
        if names - _WORLD_PLAIN:
            found.add("world node program")
        if "ShaderNodeLightPath" in names:
            found.add("Light Path node")
    if lamps and found & {"volume material", "world volume", "VDB volume"}:
        found.add("lamps in a volume")
    return [k for k in KINDS if k in found]
