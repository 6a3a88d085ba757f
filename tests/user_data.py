"""A snapshot of the user's data that a render must not change: the .blend on disk, the
scene's frame and its render, DRT and Cycles settings, and every object (name,
transforms, visibility, mesh vertices and faces, materials and their node trees)."""
from __future__ import annotations

import hashlib
import os

import numpy as np


def _value(v):
    try:
        return tuple(_value(x) for x in v) if not isinstance(v, str) else v
    except TypeError:
        return v


def rna_values(struct) -> dict:
    """Every plain (non-pointer, non-collection) property of an RNA struct."""
    values = {}
    for prop in struct.bl_rna.properties:
        if prop.identifier == "rna_type" or prop.type in ("POINTER", "COLLECTION"):
            continue
        try:
            values[prop.identifier] = _value(getattr(struct, prop.identifier))
        except (AttributeError, RuntimeError):
            continue
    return values


def _mesh_hash(mesh) -> str:
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    loops = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    return hashlib.sha256(co.tobytes() + loops.tobytes()).hexdigest()


def _tree(tree) -> tuple:
    if tree is None:
        return ()
    nodes = tuple(sorted((n.name, n.bl_idname, n.mute) for n in tree.nodes))
    links = tuple(sorted((l.from_node.name, l.from_socket.identifier, l.to_node.name,
                          l.to_socket.identifier) for l in tree.links))
    return nodes, links


def file_state(path) -> tuple:
    """(sha256, size, mtime in ns) of a file."""
    with open(path, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    st = os.stat(path)
    return digest, st.st_size, st.st_mtime_ns


def snapshot(bpy, blend_path=None) -> dict:
    scene = bpy.context.scene
    state = {"frame": (scene.frame_current, scene.frame_subframe),
             "camera": scene.camera.name if scene.camera else None,
             "render": rna_values(scene.render),
             "image_settings": rna_values(scene.render.image_settings),
             "drt": rna_values(scene.drt), "cycles": rna_values(scene.cycles),
             "view_layers": {v.name: rna_values(v) for v in scene.view_layers}}
    if blend_path is not None:
        state["file"] = file_state(blend_path)
    objects = {}
    for o in bpy.data.objects:
        objects[o.name] = {
            "type": o.type, "data": o.data.name if o.data else None,
            "matrix_world": _value(o.matrix_world), "location": tuple(o.location),
            "rotation": tuple(o.rotation_euler), "scale": tuple(o.scale),
            "hide_render": o.hide_render,
            "materials": tuple(s.material.name if s.material else None
                               for s in o.material_slots),
            "mesh": _mesh_hash(o.data) if o.type == "MESH" else None}
    state["objects"] = objects
    state["materials"] = {m.name: _tree(m.node_tree) for m in bpy.data.materials}
    state["worlds"] = {w.name: _tree(w.node_tree) for w in bpy.data.worlds}
    # Blender's own Render Result image (made by any engine's render) is not the user's
    state["datablocks"] = {kind: sorted(i.name for i in getattr(bpy.data, kind)
                                        if getattr(i, "type", "") != "RENDER_RESULT")
                           for kind in ("objects", "meshes", "materials", "images",
                                        "node_groups", "lights", "cameras", "scenes")}
    return state


def differences(before: dict, after: dict) -> list:
    """The keys whose values differ (nested one level), as 'section.key' strings."""
    out = []
    for section in before.keys() | after.keys():
        a, b = before.get(section), after.get(section)
        if isinstance(a, dict) and isinstance(b, dict):
            out += [f"{section}.{k}" for k in a.keys() | b.keys() if a.get(k) != b.get(k)]
        elif a != b:
            out.append(section)
    return sorted(out)
