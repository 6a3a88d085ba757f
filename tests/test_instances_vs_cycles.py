"""Instanced geometry as artists make it, against Cycles at its defaults.

A Geometry Nodes scatter: Instance on Points puts a smooth sphere on each vertex of a
6 x 6 grid, with a random rotation and scale per point; the sphere's material reads
Object Info > Random as its base colour. Two collection instances of a glass sphere, one
of them mirrored (scale x -1), refract the scene behind them. A sun and a grey world
light it. The export keeps the sphere once with 36 places and the glass once with 2
(export.instances); DRT's image and its 8 x 8 blocks agree with Cycles'. The control:
the same scene with Object Info's Random unlinked (one colour for every place) does not.
"""
from __future__ import annotations

import node_probe
from node_probe import image_errors, new_material, new_scene

SAMPLES = 128


def _hidden_sphere(bpy, scene, collection, radius, segments, rings):
    """A smooth UV sphere alone in a new collection that the view layer excludes (what
    instancers instance; it does not render itself)."""
    coll = bpy.data.collections.new(collection)
    scene.collection.children.link(coll)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, segments=segments, ring_count=rings)
    bpy.ops.object.shade_smooth()
    sphere = bpy.context.object
    for c in sphere.users_collection:
        c.objects.unlink(sphere)
    coll.objects.link(sphere)
    bpy.context.view_layer.layer_collection.children[collection].exclude = True
    return sphere


def _scatter_scene(bpy):
    scene = new_scene(bpy, 64)
    scene.render.resolution_x = 96
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.3
    bpy.ops.mesh.primitive_plane_add(size=14.0)
    ground_mat, gnt = new_material(bpy, "Ground")
    gnt.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.4, 0.4, 0.4, 1.0)
    bpy.context.object.data.materials.append(ground_mat)

    # the instanced sphere, kept out of the render itself
    ball = _hidden_sphere(bpy, scene, "Source", 0.5, 24, 12)
    mat, nt = new_material(bpy, "Random")
    info = nt.nodes.new("ShaderNodeObjectInfo")
    bsdf = nt.nodes["Principled BSDF"]
    nt.links.new(info.outputs["Random"], bsdf.inputs["Base Color"])
    bsdf.inputs["Roughness"].default_value = 0.4
    ball.data.materials.append(mat)

    # Geometry Nodes: a sphere on each grid vertex, turned and scaled at random
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=5, y_subdivisions=5, size=8.0)
    grid = bpy.context.object
    group = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    n = group.nodes
    gin, gout = n.new("NodeGroupInput"), n.new("NodeGroupOutput")
    place = n.new("GeometryNodeInstanceOnPoints")
    obj = n.new("GeometryNodeObjectInfo")
    obj.inputs["Object"].default_value = ball
    turn = n.new("FunctionNodeRandomValue")
    turn.data_type = "FLOAT_VECTOR"
    turn.inputs["Max"].default_value = (3.0, 3.0, 3.0)
    size = n.new("FunctionNodeRandomValue")
    size.data_type = "FLOAT"
    size.inputs[2].default_value, size.inputs[3].default_value = 0.5, 1.2   # Min, Max
    group.links.new(gin.outputs[0], place.inputs["Points"])
    group.links.new(obj.outputs["Geometry"], place.inputs["Instance"])
    group.links.new(turn.outputs["Value"], place.inputs["Rotation"])
    group.links.new(size.outputs[1], place.inputs["Scale"])
    group.links.new(place.outputs["Instances"], gout.inputs[0])
    grid.modifiers.new("Scatter", "NODES").node_group = group

    # a glass sphere instanced twice, the second mirrored
    glass = _hidden_sphere(bpy, scene, "GlassSource", 0.8, 32, 16)
    glass_src = glass.users_collection[0]
    gmat, gt = new_material(bpy, "Glass")
    gb = gt.nodes["Principled BSDF"]
    gb.inputs["Transmission Weight"].default_value = 1.0
    gb.inputs["Roughness"].default_value = 0.2
    glass.data.materials.append(gmat)
    for name, loc, sx in (("GlassA", (-1.5, -3.0, 1.0), 1.0), ("GlassB", (1.5, -3.0, 1.0), -1.0)):
        e = bpy.data.objects.new(name, None)
        e.instance_type = "COLLECTION"
        e.instance_collection = glass_src
        e.location, e.scale = loc, (sx, 1.0, 1.0)
        scene.collection.objects.link(e)

    node_probe.sun_and_camera(bpy, scene, 3.0, 0.1, (0.6, 0.2, 0.8), (0.0, -10.0, 6.0),
                              (1.0, 0.0, 0.0))
    return scene, nt, bsdf


def test_scattered_instances_match_cycles(bpy_drt):
    bpy = bpy_drt
    scene, nt, bsdf = _scatter_scene(bpy)
    from drt_addon.export import export_scene
    stats = {}
    exported = export_scene(bpy.context.evaluated_depsgraph_get(), stats=stats)
    places = sorted(len(m.instances) for m in exported.meshes if m.instances is not None)
    assert places == [2, 36] and stats["instances"] == 38, (places, stats)
    cycles = node_probe.render(bpy, scene, "CYCLES", SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", SAMPLES)
    mean, block = image_errors(drt, cycles)
    print(f"scattered instances: mean {mean:.2%}, largest block {block:.2%}")
    for link in list(bsdf.inputs["Base Color"].links):       # the control
        nt.links.remove(link)
    one_mean, one_block = image_errors(node_probe.render(bpy, scene, "DRT", SAMPLES), cycles,
                                       "control: one colour for all places")
    print(f"one colour for all places: mean {one_mean:.2%}, largest block {one_block:.2%}")
    assert mean < 0.015 and block < 0.04, (mean, block)
    assert one_block > 0.10, (one_mean, one_block)
