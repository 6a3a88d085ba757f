"""Blender's own evaluation of a texture node at given points, through geometry nodes.

Blender evaluates its procedural textures (White Noise, Noise, Voronoi, Wave, Magic,
Brick) as geometry-node fields with the same functions Cycles' kernels use, in float32.
`evaluate` builds a mesh with one vertex per point, a geometry-nodes modifier that
stores the texture node's output at each vertex (Vector = the vertex position, every
other linked input read from a per-vertex attribute), and reads the result back: an
exact reference for the engine's kernels at arbitrary inputs, with no rendering.
"""
from __future__ import annotations

import numpy as np

DATA_TYPES = {"VALUE": ("FLOAT", "value", 1), "RGBA": ("FLOAT_COLOR", "color", 4),
              "VECTOR": ("FLOAT_VECTOR", "vector", 3)}


def evaluate(bpy, node_type, points, output, settings=None, inputs=None):
    """The `output` socket (name or identifier) of a `node_type` node at each of
    `points` (n, 3): (n,) or (n, 3). settings: the node's properties; inputs: {socket
    name: a float (the socket's value) or an (n,) NumPy array (per point); colours and vectors as tuples}."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    n = len(points)
    mesh = bpy.data.meshes.new("fields")
    mesh.from_pydata([tuple(p) for p in points], [], [])
    per_point = {}
    for k, (name, value) in enumerate((inputs or {}).items()):
        if isinstance(value, np.ndarray):
            attr = mesh.attributes.new(f"in{k}", "FLOAT", "POINT")
            attr.data.foreach_set("value", np.asarray(value, np.float32).ravel())
            per_point[name] = f"in{k}"
    obj = bpy.data.objects.new("fields", mesh)
    bpy.context.scene.collection.objects.link(obj)
    tree = bpy.data.node_groups.new("fields", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    gin = tree.nodes.new("NodeGroupInput")
    gout = tree.nodes.new("NodeGroupOutput")
    node = tree.nodes.new(node_type)
    for k, v in (settings or {}).items():
        setattr(node, k, v)
    if node.inputs.get("Vector") is not None:          # 1D nodes have none
        tree.links.new(tree.nodes.new("GeometryNodeInputPosition").outputs[0],
                       node.inputs["Vector"])
    for name, value in (inputs or {}).items():
        sock = node.inputs.get(name)
        if sock is None:                                  # not used by these settings
            continue
        if name in per_point:
            read = tree.nodes.new("GeometryNodeInputNamedAttribute")
            read.data_type = "FLOAT"
            read.inputs["Name"].default_value = per_point[name]
            tree.links.new(read.outputs["Attribute"], sock)
        elif hasattr(sock.default_value, "__len__"):
            sock.default_value = value
        else:
            sock.default_value = float(value)
    out = next(s for s in node.outputs if output in (s.name, s.identifier))
    data_type, field, width = DATA_TYPES[out.type]
    store = tree.nodes.new("GeometryNodeStoreNamedAttribute")
    store.data_type = data_type
    store.domain = "POINT"
    store.inputs["Name"].default_value = "result"
    tree.links.new(gin.outputs[0], store.inputs["Geometry"])
    tree.links.new(out, store.inputs["Value"])
    tree.links.new(store.outputs[0], gout.inputs[0])
    mod = obj.modifiers.new("fields", "NODES")
    mod.node_group = tree
    try:
        depsgraph = bpy.context.evaluated_depsgraph_get()
        depsgraph.update()
        evaluated = obj.evaluated_get(depsgraph)
        attr = evaluated.data.attributes["result"]
        values = np.zeros(n * width, np.float32)
        attr.data.foreach_get(field, values)
    finally:
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)
        bpy.data.node_groups.remove(tree)
    values = values.reshape(n, width).astype(np.float64)
    return values[:, 0] if width == 1 else values[:, :3]
