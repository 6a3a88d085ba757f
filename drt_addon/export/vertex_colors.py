"""Color attributes (vertex colours) for Color Attribute and Attribute nodes: one
attribute per mesh, per triangle corner, scene-linear RGBA as Cycles reads it, exported
only for objects whose materials read one."""
from __future__ import annotations

from typing import Optional

import numpy as np

READERS = {"ShaderNodeVertexColor": "layer_name", "ShaderNodeAttribute": "attribute_name"}


def color_request(materials) -> Optional[str]:
    """The color attribute an object's materials (layer_overrides.slot_materials) read:
    None (none), '' (the mesh's render colour attribute) or a name."""
    from .nodes.links import _all_nodes, uses_nodes
    names = []
    for mat in materials:
        if mat is None or not uses_nodes(mat):
            continue
        for n in _all_nodes(mat.node_tree):
            prop = READERS.get(n.bl_idname)
            if prop is None:
                continue
            if n.bl_idname == "ShaderNodeAttribute" and n.attribute_type != "GEOMETRY":
                continue
            names.append(getattr(n, prop) or "")
    if not names:
        return None
    named = sorted(n for n in names if n)
    return named[0] if named else ""


def mesh_colors(mesh, name: str = "") -> Optional[np.ndarray]:
    """(T, 3, 4) float32 linear RGBA per loop-triangle corner of color attribute `name`
    ('' or a missing name: the render colour attribute); None when the mesh has none."""
    attrs = mesh.color_attributes
    if len(attrs) == 0:
        return None
    attr = attrs.get(name) if name else None
    if attr is None:
        k = attrs.render_color_index
        attr = attrs[k] if 0 <= k < len(attrs) else attrs[0]
    values = np.empty(len(attr.data) * 4, np.float32)
    attr.data.foreach_get("color", values)
    values = values.reshape(-1, 4)
    nt = len(mesh.loop_triangles)
    if attr.domain == "POINT":
        index = np.empty(nt * 3, np.int32)
        mesh.loop_triangles.foreach_get("vertices", index)
    elif attr.domain == "CORNER":
        index = np.empty(nt * 3, np.int32)
        mesh.loop_triangles.foreach_get("loops", index)
    else:
        return None
    return np.ascontiguousarray(values[index].reshape(nt, 3, 4))
