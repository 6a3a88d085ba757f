"""Sample scenes made the way artists make them, with Blender's defaults everywhere
(Cycles' light paths, Multiscatter GGX, Filter Glossy 1, caustics on): the scenes the
comparisons against Cycles end with (tests/test_artist_scenes_vs_cycles.py).

fog_room
    A room (floor, walls, ceiling) with a window in its left wall, filled with fog (a
    volume-only cube of Principled Volume, density 0.08), lit by a warm area lamp
    outside the window and a dim blue sky; a table-like block and a sphere inside; the
    camera inside the fog. The light through the window draws a shaft in the fog.

product_shot
    An HDRI-lit still life: a smooth-shaded Suzanne (Subdivision level 2) of red
    plastic with a hammered finish (Voronoi Texture -> Bump -> Normal) on a bevelled
    metal pedestal with a brushed look (Noise Texture -> Bump), in front of a curved
    backdrop whose colour is a Noise Texture through a Color Ramp. Lit by an
    Environment Texture world (the procedural sky of hdri_world, packed OpenEXR, turned
    by a Mapping node so its sun is behind the product) and a soft area key lamp.
"""
from __future__ import annotations

import math

import bmesh
import bpy

from build_samples import (_packed_sky, camera, cuboid, mesh_object, principled, quad, reset,
                           uv_sphere)

SIZE = (64, 48)


def _new_scene(size=SIZE):
    """An empty scene of `size` pixels, 256 samples in both engines, Blender's defaults
    otherwise."""
    scene = reset()
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.cycles.samples = 256
    if hasattr(scene, "drt"):
        scene.drt.samples = 256
    return scene


def _world(scene, color, strength):
    world = bpy.data.worlds.new("Sky")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*color, 1.0)
    bg.inputs["Strength"].default_value = strength
    scene.world = world


def empty_material(name):
    """(a node material of only its Material Output, its node tree)."""
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    return mat, nt


def _volume_only(name, density, color=(0.8, 0.8, 0.8)):
    mat, nt = empty_material(name)
    vol = nt.nodes.new("ShaderNodeVolumePrincipled")
    vol.inputs["Density"].default_value = density
    vol.inputs["Color"].default_value = (*color, 1.0)
    nt.links.new(vol.outputs["Volume"], nt.nodes["Material Output"].inputs["Volume"])
    return mat


def _wall_with_window(name, x, material, window=((-0.6, 0.6), (1.0, 2.2))):
    """The wall x = const (y in -2..2, z in 0..3) with a rectangular hole, facing +x."""
    (y0, y1), (z0, z1) = window
    ys, zs = (-2.0, y0, y1, 2.0), (0.0, z0, z1, 3.0)
    verts = [(x, y, z) for z in zs for y in ys]
    faces = []
    for j in range(3):
        for i in range(3):
            if i == 1 and j == 1:
                continue                       # the window
            a = j * 4 + i
            faces.append((a, a + 4, a + 5, a + 1))
    return mesh_object(name, verts, faces, material)


def fog_room():
    scene = _new_scene()
    _world(scene, (0.35, 0.5, 0.9), 0.3)
    plaster = principled("Plaster", (0.75, 0.72, 0.68))
    wood = principled("Wood", (0.45, 0.25, 0.12), roughness=0.4)
    ceramic = principled("Ceramic", (0.2, 0.35, 0.6), roughness=0.2)
    quad("Floor", [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], wood)
    quad("Ceiling", [(-2, -2, 3), (-2, 2, 3), (2, 2, 3), (2, -2, 3)], plaster)
    quad("Back", [(-2, 2, 0), (2, 2, 0), (2, 2, 3), (-2, 2, 3)], plaster)
    quad("Right", [(2, -2, 0), (2, 2, 0), (2, 2, 3), (2, -2, 3)], plaster)
    quad("Front", [(-2, -2, 0), (-2, -2, 3), (2, -2, 3), (2, -2, 0)], plaster)
    _wall_with_window("Left", -2.0, plaster)
    cuboid("Table", (0.2, 0.3, 0.0), (1.2, 1.3, 0.75), wood, rotation_z=math.radians(20))
    uv_sphere("Vase", (0.7, 0.8, 1.0), 0.25, ceramic)
    fog = _volume_only("Fog", 0.08)
    cuboid("Fog", (-1.98, -1.98, 0.01), (1.98, 1.98, 2.98), fog)
    lamp = bpy.data.objects.new("Window Lamp", bpy.data.lights.new("Window Lamp", "AREA"))
    lamp.data.size = 1.2
    lamp.data.energy = 1500.0
    lamp.data.color = (1.0, 0.85, 0.65)
    lamp.location = (-3.2, 0.3, 2.6)
    lamp.rotation_euler = (0.0, math.radians(-60.0), 0.0)     # aimed down into the room
    scene.collection.objects.link(lamp)
    camera(scene, (1.6, -1.7, 1.5), (math.radians(85.0), 0.0, math.radians(40.0)), lens=24.0)
    return scene


def _link(nt, out_node, out, in_node, inp):
    nt.links.new(out_node.outputs[out], in_node.inputs[inp])


def _bumped(name, color, roughness, texture, scale, distance, metallic=0.0):
    """A Principled material whose Normal is a Bump (Strength 1) of `texture`'s first
    output, raised `distance` metres at height 1 (Blender's default, 1 mm, is too faint
    to see at this scale)."""
    mat = principled(name, color, roughness=roughness, metallic=metallic)
    nt = mat.node_tree
    tex = nt.nodes.new(texture)
    tex.inputs["Scale"].default_value = scale
    bump = nt.nodes.new("ShaderNodeBump")
    bump.inputs["Distance"].default_value = distance
    _link(nt, tex, 0, bump, "Height")
    _link(nt, bump, "Normal", nt.nodes["Principled BSDF"], "Normal")
    return mat


def _noise_backdrop_material():
    """A Noise Texture through a two-stop Color Ramp into Base Color."""
    mat = principled("Backdrop", (0.6, 0.6, 0.6))
    nt = mat.node_tree
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 3.0
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    stops = ramp.color_ramp.elements
    stops[0].position, stops[0].color = 0.35, (0.25, 0.32, 0.4, 1.0)
    stops[1].position, stops[1].color = 0.65, (0.75, 0.7, 0.62, 1.0)
    _link(nt, noise, "Fac", ramp, "Fac")
    _link(nt, ramp, "Color", nt.nodes["Principled BSDF"], "Base Color")
    return mat


def _smooth(obj):
    obj.data.shade_smooth()
    return obj


def _sweep(name, material, width=8.0, depth=6.0, height=5.0, radius=1.5, steps=8):
    """A photo-studio backdrop: a floor curving up into a wall (at y = depth / 2)."""
    y0, y1 = -depth / 2.0, depth / 2.0 - radius
    profile = [(y0, 0.0)]
    for i in range(steps + 1):
        a = 0.5 * math.pi * i / steps
        profile.append((y1 + radius * math.sin(a), radius - radius * math.cos(a)))
    profile.append((y1 + radius, height))
    verts = [(x, y, z) for (y, z) in profile for x in (-width / 2.0, width / 2.0)]
    faces = [(2 * i, 2 * i + 1, 2 * i + 3, 2 * i + 2) for i in range(len(profile) - 1)]
    return _smooth(mesh_object(name, verts, faces, material))


def _bmesh_object(name, build, material):
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    build(bm)
    bm.to_mesh(mesh)
    bm.free()
    obj = bpy.data.objects.new(name, mesh)
    obj.data.materials.append(material)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _pedestal(material, radius=0.7, height=0.25):
    """A metal disc, its edges bevelled (3 segments), smooth with sharp edges by angle."""
    obj = _bmesh_object("Pedestal", lambda bm: bmesh.ops.create_cone(
        bm, cap_ends=True, segments=48, radius1=radius, radius2=radius, depth=height),
        material)
    obj.data.shade_smooth()
    obj.data.set_sharp_from_angle(angle=math.radians(30.0))
    bevel = obj.modifiers.new("Bevel", "BEVEL")
    bevel.width, bevel.segments = 0.03, 3
    obj.location = (0.0, 0.0, height / 2.0)
    return obj


def _suzanne(material, z):
    obj = _bmesh_object("Suzanne", lambda bm: bmesh.ops.create_monkey(bm, calc_uvs=True),
                        material)
    _smooth(obj)
    sub = obj.modifiers.new("Subdivision", "SUBSURF")
    sub.levels = sub.render_levels = 2
    obj.scale = (0.55, 0.55, 0.55)
    obj.location = (0.0, 0.0, z)
    obj.rotation_euler = (math.radians(-10.0), 0.0, math.radians(-25.0))
    return obj


def _hdri(scene, strength, turn_degrees):
    world = bpy.data.worlds.new("HDRI")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    nt = world.node_tree
    bg = nt.nodes["Background"]
    bg.inputs["Strength"].default_value = strength
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = _packed_sky("product_shot_sky")
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(turn_degrees))
    coords = nt.nodes.new("ShaderNodeTexCoord")
    _link(nt, coords, "Generated", mapping, "Vector")
    _link(nt, mapping, "Vector", env, "Vector")
    _link(nt, env, "Color", bg, "Color")
    scene.world = world


def product_shot():
    scene = _new_scene()
    _hdri(scene, 0.25, 160.0)
    _sweep("Backdrop", _noise_backdrop_material())
    metal = _bumped("Brushed Metal", (0.9, 0.88, 0.85), 0.25, "ShaderNodeTexNoise", 15.0,
                    0.01, metallic=1.0)
    _pedestal(metal)
    plastic = _bumped("Hammered Plastic", (0.7, 0.06, 0.04), 0.35, "ShaderNodeTexVoronoi",
                      5.0, 0.05)
    _suzanne(plastic, 0.25 + 0.55 * 0.8)
    key = bpy.data.objects.new("Key", bpy.data.lights.new("Key", "AREA"))
    key.data.size = 2.0
    key.data.energy = 400.0
    key.location = (-2.5, -2.5, 3.0)
    key.rotation_euler = (math.radians(45.0), 0.0, math.radians(-45.0))    # at the product
    scene.collection.objects.link(key)
    camera(scene, (0.0, -3.3, 1.3), (math.radians(78.0), 0.0, 0.0), lens=50.0)
    return scene


SCENES = {"fog_room": fog_room, "product_shot": product_shot}
