"""Builds DRT's sample scenes with bpy, deterministically.

    python sample_blends/build_samples.py [--out-dir sample_blends] [NAME ...]

Each scene is a function below; its .blend is written next to this script. Scenes use
Principled BSDFs (with Specular IOR Level 0 where a scene is meant to be purely diffuse)
and keep Blender's defaults elsewhere, so they render the same in Cycles and DRT.
"""
from __future__ import annotations

import argparse
import math
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.frame_set(1)
    return scene


def principled(name, color, roughness=0.5, specular=0.5, metallic=0.0, emission=None,
               strength=0.0):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Specular IOR Level"].default_value = specular
    bsdf.inputs["Metallic"].default_value = metallic
    if emission is not None:
        bsdf.inputs["Emission Color"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    mat.diffuse_color = (*color, 1.0)
    return mat


def mesh_object(name, verts, faces, material):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.validate()
    obj = bpy.data.objects.new(name, mesh)
    obj.data.materials.append(material)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def quad(name, corners, material):
    return mesh_object(name, corners, [(0, 1, 2, 3)], material)


def cuboid(name, lo, hi, material, rotation_z=0.0):
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    verts = [(x - cx, y - cy, z) for (x, y, z) in
             [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
              (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    obj = mesh_object(name, verts, faces, material)
    obj.location = (cx, cy, 0.0)
    obj.rotation_euler = (0.0, 0.0, rotation_z)
    return obj


def camera(scene, location, rotation, lens=35.0):
    data = bpy.data.cameras.new("Camera")
    data.lens = lens
    obj = bpy.data.objects.new("Camera", data)
    obj.location = location
    obj.rotation_euler = rotation
    scene.collection.objects.link(obj)
    scene.camera = obj
    return obj


def render_defaults(scene, size=(256, 256), samples=64):
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.device = "CPU"
    if hasattr(scene, "drt"):
        scene.drt.samples = samples
    world = bpy.data.worlds.new("World")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world


def cornell_box():
    """The Cornell box: a 2 m room, two blocks, one square area light under the ceiling."""
    scene = reset()
    white = principled("White", (0.73, 0.73, 0.73), specular=0.0)
    red = principled("Red", (0.65, 0.05, 0.05), specular=0.0)
    green = principled("Green", (0.12, 0.45, 0.15), specular=0.0)
    quad("Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], white)
    quad("Ceiling", [(-1, -1, 2), (-1, 1, 2), (1, 1, 2), (1, -1, 2)], white)
    quad("Back", [(-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)], white)
    quad("Left", [(-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)], red)
    quad("Right", [(1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)], green)
    cuboid("TallBlock", (-0.6, -0.1, 0.0), (-0.05, 0.45, 1.2), white, math.radians(17))
    cuboid("ShortBlock", (0.1, -0.6, 0.0), (0.65, -0.05, 0.6), white, math.radians(-17))
    light = bpy.data.lights.new("Light", "AREA")
    light.shape = "SQUARE"
    light.size = 0.5
    light.energy = 60.0
    lobj = bpy.data.objects.new("Light", light)
    lobj.location = (0.0, 0.0, 1.98)
    scene.collection.objects.link(lobj)
    camera(scene, (0.0, -3.9, 1.0), (math.radians(90), 0.0, 0.0), lens=35.0)
    render_defaults(scene)
    return scene


SCENES = {"cornell_box": cornell_box}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("names", nargs="*", help=f"scenes to build (default all: {', '.join(SCENES)})")
    p.add_argument("--out-dir", default=HERE)
    args = p.parse_args(argv)
    names = args.names or list(SCENES)
    for name in names:
        if name not in SCENES:
            p.error(f"unknown scene {name!r}")
        SCENES[name]()
        path = os.path.join(os.path.abspath(args.out_dir), f"{name}.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path, compress=False)
        print(f"built {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
