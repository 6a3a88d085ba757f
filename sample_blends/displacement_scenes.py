"""Sample scenes of true displacement, made the way artists make them, with Blender's
defaults: the scenes tests/test_displacement_vs_cycles.py compares.

displacement
    A cobbled path and a rock at sunset. The path is a 4 x 3 m plane with a Subdivision
    modifier (Simple, 7 levels at render), its material Displacement Only: a Voronoi
    Texture's Distance (scale 5, default Generated coordinates) through a Color Ramp
    into a Displacement node (Scale 0.12) raises rounded cobbles with mortar between
    them, and the same ramp, mixed with a Noise Texture, colours stones and mortar. The
    rock is a smooth UV sphere (Subdivision level 2) with Displacement and Bump: a Noise
    Texture (scale 3, detail 6) into a Displacement node (Scale 0.25) moves its surface,
    and the bump adds the detail finer than its faces. A low warm sun, a cool area fill
    lamp, a dim blue sky.
"""
from __future__ import annotations

import math

import bpy

from artist_scenes import _bmesh_object, _link, _new_scene, _smooth, _world
from build_samples import camera, principled


def _displaced(mat, height_socket, scale, method):
    """Link `height_socket` through a Displacement node (Scale `scale`) into the Material
    Output's Displacement, with Settings > Displacement `method`."""
    nt = mat.node_tree
    disp = nt.nodes.new("ShaderNodeDisplacement")
    disp.inputs["Scale"].default_value = scale
    nt.links.new(height_socket, disp.inputs["Height"])
    _link(nt, disp, "Displacement", nt.nodes["Material Output"], "Displacement")
    mat.displacement_method = method
    return mat


def _cobbles():
    mat = principled("Cobbles", (0.5, 0.5, 0.5), roughness=0.6)
    nt = mat.node_tree
    voronoi = nt.nodes.new("ShaderNodeTexVoronoi")
    voronoi.inputs["Scale"].default_value = 5.0
    ramp = nt.nodes.new("ShaderNodeValToRGB")          # stones high, mortar low
    stops = ramp.color_ramp.elements
    stops[0].position, stops[0].color = 0.0, (1.0, 1.0, 1.0, 1.0)
    stops[1].position, stops[1].color = 0.8, (0.0, 0.0, 0.0, 1.0)
    _link(nt, voronoi, "Distance", ramp, "Fac")
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 12.0
    mix = nt.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"

    def socket(sockets, identifier):
        return next(x for x in sockets if x.identifier == identifier)
    socket(mix.inputs, "A_Color").default_value = (0.16, 0.14, 0.12, 1.0)      # mortar
    tint = nt.nodes.new("ShaderNodeValToRGB")
    tint.color_ramp.elements[0].color = (0.35, 0.3, 0.27, 1.0)
    tint.color_ramp.elements[1].color = (0.6, 0.55, 0.48, 1.0)
    _link(nt, noise, "Fac", tint, "Fac")
    nt.links.new(tint.outputs["Color"], socket(mix.inputs, "B_Color"))
    nt.links.new(ramp.outputs["Color"], socket(mix.inputs, "Factor_Float"))
    nt.links.new(socket(mix.outputs, "Result_Color"),
                 nt.nodes["Principled BSDF"].inputs["Base Color"])
    return _displaced(mat, ramp.outputs["Color"], 0.12, "DISPLACEMENT")


def _rock():
    mat = principled("Rock", (0.42, 0.4, 0.37), roughness=0.5)
    nt = mat.node_tree
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 3.0
    noise.inputs["Detail"].default_value = 6.0
    return _displaced(mat, noise.outputs["Fac"], 0.25, "BOTH")


def _path(material):
    import bmesh

    def build(bm):
        bmesh.ops.create_grid(bm, x_segments=2, y_segments=2, size=0.5)
    obj = _bmesh_object("Path", build, material)
    obj.scale = (4.0, 3.0, 1.0)
    sub = obj.modifiers.new("Subdivision", "SUBSURF")
    sub.subdivision_type = "SIMPLE"
    sub.levels, sub.render_levels = 3, 7
    return obj


def _boulder(material):
    import bmesh
    obj = _bmesh_object("Rock", lambda bm: bmesh.ops.create_uvsphere(
        bm, u_segments=48, v_segments=24, radius=0.45), material)
    _smooth(obj)
    sub = obj.modifiers.new("Subdivision", "SUBSURF")
    sub.levels, sub.render_levels = 1, 2
    obj.location = (0.55, 0.35, 0.3)
    obj.scale = (1.3, 1.0, 0.8)
    return obj


def displacement():
    scene = _new_scene()
    _world(scene, (0.35, 0.45, 0.7), 0.15)
    _path(_cobbles())
    _boulder(_rock())
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy, sun.data.angle = 4.0, math.radians(3.0)
    sun.data.color = (1.0, 0.8, 0.6)
    sun.rotation_euler = (math.radians(72.0), 0.0, math.radians(-60.0))     # low, from the right
    scene.collection.objects.link(sun)
    fill = bpy.data.objects.new("Fill", bpy.data.lights.new("Fill", "AREA"))
    fill.data.size, fill.data.energy = 2.0, 150.0
    fill.data.color = (0.7, 0.8, 1.0)
    fill.location = (-2.5, -2.0, 2.5)
    fill.rotation_euler = (math.radians(45.0), 0.0, math.radians(-50.0))
    scene.collection.objects.link(fill)
    camera(scene, (0.0, -2.6, 1.3), (math.radians(68.0), 0.0, 0.0), lens=35.0)
    return scene


SCENES = {"displacement": displacement}
