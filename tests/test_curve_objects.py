"""Curve, text and surface objects: Blender evaluates them to a mesh that its depsgraph
hands on as an instance of the object, beside the object itself (whose data is the
Curve). As Cycles (object_is_geometry: only mesh data is drawn), DRT draws that mesh
once. Until 2026-11-30 it drew both, two coincident copies: rays leaving one copy met
the other at distance 0, and a public file's neon tube (neon_curve.blend) came out
speckled dark, its emissive twin (neon_tree_experiment.blend) 80 % too bright."""
from __future__ import annotations

import math

import numpy as np

from conftest import grey_room, render_current, use_engine
from test_multiscatter_vs_cycles import assert_matches


def _scene(bpy):
    scene = grey_room(bpy, (64, 48), 0.5, world=0.05)
    bpy.ops.curve.primitive_bezier_curve_add(location=(-0.4, 0.0, 0.6))
    tube = bpy.context.object
    tube.data.bevel_depth, tube.data.bevel_resolution = 0.08, 4
    tube.scale = (1.2, 1.2, 1.2)
    mat = bpy.data.materials.new("tube")
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (
        0.8, 0.5, 0.2, 1.0)
    tube.data.materials.append(mat)
    bpy.ops.object.text_add(location=(0.3, -0.3, 0.05))
    text = bpy.context.object
    text.data.body, text.data.extrude, text.data.size = "DRT", 0.05, 0.5
    glow = bpy.data.materials.new("glow")
    glow.node_tree.nodes["Principled BSDF"].inputs["Emission Color"].default_value = (
        0.2, 1.0, 0.3, 1.0)
    glow.node_tree.nodes["Principled BSDF"].inputs["Emission Strength"].default_value = 3.0
    text.data.materials.append(glow)
    bpy.ops.object.light_add(type="POINT", location=(1.0, -1.5, 2.5))
    bpy.context.object.data.energy = 300.0
    bpy.ops.object.camera_add(location=(0.0, -3.5, 1.6), rotation=(math.radians(68), 0, 0))
    scene.camera = bpy.context.object
    scene["drt_test_objects"] = [tube.name, text.name]
    return scene


def test_each_curve_and_text_object_is_one_mesh(bpy_drt):
    bpy = bpy_drt
    scene = _scene(bpy)
    from drt_addon.export import Reporter, export_scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    s = export_scene(depsgraph, Reporter())
    for name in scene["drt_test_objects"]:
        mine = [m for m in s.meshes if m.name.split("#")[0] == name]
        evaluated = bpy.data.objects[name].evaluated_get(depsgraph).to_mesh()
        evaluated.calc_loop_triangles()
        assert len(mine) == 1, [m.name for m in s.meshes]
        assert len(mine[0].triangles) == len(evaluated.loop_triangles) > 0


def test_curve_and_text_objects_match_cycles(bpy_drt):
    scene = _scene(bpy_drt)
    use_engine(scene, "CYCLES", 512)
    cycles = render_current(bpy_drt, scene)
    use_engine(scene, "DRT", 256)
    drt = render_current(bpy_drt, scene)
    assert_matches(drt, cycles, 0.02, 0.05)
    assert np.isfinite(drt).all()
