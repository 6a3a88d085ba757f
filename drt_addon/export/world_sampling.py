"""Whether Cycles samples the world as a light: only when its surface varies over
directions (Cycles' `Shader::has_surface_spatial_varying`, set when a node that reads
the shading point or direction is compiled into the background shader). A world of one
colour is found by the rays that escape and never sampled, so a Light Path trick that
tells shadow rays from the others (architectural glass over a window) lets it in only
through the rays that pass. The rule also needs World > Settings > Sampling Method
other than None (`world.cycles.sampling_method`).

Cycles' own list of such nodes (scene/shader_nodes.h, has_spatial_varying) and the
textures whose unlinked Vector it feeds with texture coordinates (shader_nodes.cpp,
LINK_TEXTURE_* and LINK_POSITION). Constant folding, which can drop a node before it is
compiled, is not modelled: a world is taken as varying whenever such a node feeds it."""
from __future__ import annotations

from .nodes.links import _link, uses_nodes

VARYING = frozenset({
    "ShaderNodeTexCoord", "ShaderNodeNewGeometry", "ShaderNodeUVMap",
    "ShaderNodeLightFalloff", "ShaderNodeHairInfo", "ShaderNodePointInfo",
    "ShaderNodeVolumeInfo", "ShaderNodeVertexColor", "ShaderNodeAttribute",
    "ShaderNodeCameraData", "ShaderNodeFresnel", "ShaderNodeLayerWeight",
    "ShaderNodeWireframe", "ShaderNodeBump", "ShaderNodeScript", "ShaderNodeNormalMap",
    "ShaderNodeTangent", "ShaderNodeBevel", "ShaderNodeAmbientOcclusion",
    "ShaderNodeRaycast"})
COORDINATE_TEXTURES = frozenset({
    "ShaderNodeTexImage", "ShaderNodeTexEnvironment", "ShaderNodeTexSky",
    "ShaderNodeTexGradient", "ShaderNodeTexNoise", "ShaderNodeTexGabor",
    "ShaderNodeTexVoronoi", "ShaderNodeTexIES", "ShaderNodeTexWave",
    "ShaderNodeTexMagic", "ShaderNodeTexChecker", "ShaderNodeTexBrick"})


def world_varies(world, output) -> bool:
    """Whether the world's surface (the World Output node `output`; None: none) varies
    over directions, as Cycles decides it."""
    if world is None or not uses_nodes(world) or output is None:
        return False
    return _feeds_varying(output.inputs["Surface"], set())


def _feeds_varying(socket, seen) -> bool:
    found = _link(socket)
    if found is None:
        return False
    node, _ = found
    key = node.as_pointer()
    if key in seen:
        return False
    seen.add(key)
    kind = node.bl_idname
    if kind in VARYING:
        return True
    if kind in COORDINATE_TEXTURES:
        vector = node.inputs.get("Vector")
        if vector is None or _link(vector) is None:
            return True
    if kind == "ShaderNodeGroup" and node.node_tree is not None:
        outputs = [n for n in node.node_tree.nodes if n.bl_idname == "NodeGroupOutput"]
        if any(_feeds_varying(s, seen) for n in outputs for s in n.inputs):
            return True
    return any(_feeds_varying(s, seen) for s in node.inputs)
