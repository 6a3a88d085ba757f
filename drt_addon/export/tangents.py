"""Tangent space for Normal Map and Vector Displacement nodes: Blender's MikkTSpace
tangents and bitangent signs per triangle corner (`Mesh.calc_tangents`, the tangents
Cycles reads), exported only for objects whose materials read tangent space."""
from __future__ import annotations

from typing import Optional

import numpy as np


def wants_tangents(materials) -> bool:
    """Whether an object's materials (layer_overrides.slot_materials) read tangent space:
    a Normal Map or a Vector Displacement node in Tangent space."""
    from .nodes.links import _all_nodes, uses_nodes
    readers = ("ShaderNodeNormalMap", "ShaderNodeVectorDisplacement")
    for mat in materials:
        if mat is None or not uses_nodes(mat):
            continue
        if any(n.bl_idname in readers and n.space == "TANGENT"
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


def mesh_tangents(mesh, uv_name: str = "") -> Optional[np.ndarray]:
    """(T, 3, 4) float32: tangent xyz and bitangent sign per loop-triangle corner, in
    object space, from UV map `uv_name` ('' or a missing name: the active render map);
    None when the mesh has no UV map or Blender cannot compute them (n-gons)."""
    layer = uv_layer(mesh, uv_name)
    if layer is None:
        return None
    try:
        mesh.calc_tangents(uvmap=layer.name)
    except RuntimeError:
        return None
    nt = len(mesh.loop_triangles)
    loops = np.empty(nt * 3, np.int32)
    mesh.loop_triangles.foreach_get("loops", loops)
    t = np.empty(len(mesh.loops) * 3, np.float32)
    mesh.loops.foreach_get("tangent", t)
    s = np.empty(len(mesh.loops), np.float32)
    mesh.loops.foreach_get("bitangent_sign", s)
    out = np.concatenate([t.reshape(-1, 3)[loops], s[loops, None]], axis=1)
    return np.ascontiguousarray(out.reshape(nt, 3, 4))


def to_world(tangents: Optional[np.ndarray], m3: np.ndarray) -> Optional[np.ndarray]:
    """Tangents of an instance with linear part m3: directions by m3 (normalised), signs
    flipped by a mirroring transform (the bitangent is a cross product)."""
    if tangents is None:
        return None
    t = tangents[..., :3].reshape(-1, 3).astype(np.float64) @ m3.T
    t /= np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-300)
    sign = tangents[..., 3:] * (1.0 if np.linalg.det(m3) >= 0 else -1.0)
    return np.concatenate([t.reshape(-1, 3, 3), sign], axis=2).astype(np.float32)
