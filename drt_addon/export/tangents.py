"""Tangent space for Normal Map, Vector Displacement and UV-map Tangent nodes: MikkTSpace tangents and
bitangent signs per triangle corner, as Cycles computes them (mikktspace.py), exported
only for objects whose materials read tangent space."""
from __future__ import annotations

from typing import Optional

import numpy as np

from . import mikktspace


def wants_tangents(materials) -> bool:
    """Whether an object's materials (layer_overrides.slot_materials) read tangent space:
    a Normal Map or a Vector Displacement node in Tangent space, or a Tangent node
    of a UV map (an anisotropic BSDF's direction)."""
    from .nodes.links import _all_nodes, uses_nodes
    readers = ("ShaderNodeNormalMap", "ShaderNodeVectorDisplacement")
    for mat in materials:
        if mat is None or not uses_nodes(mat):
            continue
        if any((n.bl_idname in readers and n.space == "TANGENT")
               or (n.bl_idname == "ShaderNodeTangent" and n.direction_type == "UV_MAP")
               for n in _all_nodes(mat.node_tree)):
            return True
    return False


def uv_layer(mesh, name: str = ""):
    """The UV map `name`, or for '' (or a name the mesh lacks) the one Cycles uses by
    default: the active render map, else the active one; None without UV maps."""
    layers = mesh.uv_layers
    if len(layers) == 0:
        return None
    layer = layers.get(name) if name else None
    if layer is None:
        layer = next((l for l in layers if l.active_render), None) or layers.active or layers[0]
    return layer


def mesh_tangents(mesh, positions: np.ndarray, triangles: np.ndarray,
                  corner_normals: Optional[np.ndarray], uv_name: str = "") -> np.ndarray:
    """(T, 3, 4) float32: tangent xyz and bitangent sign per loop-triangle corner, in
    object space, as Cycles computes them: MikkTSpace on the render triangles (n-gons
    included), from UV map `uv_name` ('' or a missing name: the active render map), or on
    a mesh without UV maps from map_to_sphere of the positions. `corner_normals` are
    mesh_arrays' split normals (None when every face is flat); flat faces use their
    triangle's own normal, as Cycles does."""
    from .mesh import mesh_uvs, smooth_triangles
    flat = mikktspace.face_normals(positions.astype(np.float32)[triangles])
    normals = np.repeat(flat[:, None], 3, axis=1)
    if corner_normals is not None:
        smooth = smooth_triangles(mesh)
        normals[smooth] = corner_normals[smooth]
    layer = uv_layer(mesh, uv_name)
    uvs = mesh_uvs(mesh, layer.name) if layer is not None else None
    return mikktspace.tangents(positions, triangles, normals, uvs)
