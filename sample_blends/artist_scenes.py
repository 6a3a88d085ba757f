"""Sample scenes made the way artists make them, with Blender's defaults everywhere
(Cycles' light paths, Multiscatter GGX, Filter Glossy 1, caustics on): the scenes the
comparisons against Cycles end with (tests/test_artist_scenes_vs_cycles.py).

fog_room
    A room (floor, walls, ceiling) with a window in its left wall, filled with fog (a
    volume-only cube of Principled Volume, density 0.08), lit by a warm area lamp
    outside the window and a dim blue sky; a table-like block and a sphere inside; the
    camera inside the fog. The light through the window draws a shaft in the fog.
"""
from __future__ import annotations

import math

import bpy

from build_samples import camera, cuboid, mesh_object, principled, quad, reset, uv_sphere

SIZE = (64, 48)


def _world(scene, color, strength):
    world = bpy.data.worlds.new("Sky")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*color, 1.0)
    bg.inputs["Strength"].default_value = strength
    scene.world = world


def _volume_only(name, density, color=(0.8, 0.8, 0.8)):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
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
    scene = reset()
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.cycles.samples = 256
    if hasattr(scene, "drt"):
        scene.drt.samples = 256
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


SCENES = {"fog_room": fog_room}
