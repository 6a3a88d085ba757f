"""Sample scenes of Volume objects (OpenVDB grids), made the way artists make them, with
Blender's defaults: the scenes tests/test_volume_objects_vs_cycles.py compares.

smoke_plume
    A column of smoke rising from a fire on a concrete floor in front of a wall, as a
    Volume object reading smoke_plume.vdb (written here, deterministically: density,
    temperature and flame grids of 48 x 48 x 80 voxels of 4 cm, turbulent from a sum of
    random sine waves). Its material is a Principled Volume with Blender's default
    attributes (density, temperature), Density 10, Blackbody Intensity 1 over a
    Temperature of 1500 K (so 3000 K where the temperature grid is 2), and an Attribute
    node reading the flame grid into Emission Strength. Lit by a sun and a dim sky.
"""
from __future__ import annotations

import math
import os
import sys

import bpy
import numpy as np

from artist_scenes import _new_scene, empty_material
from build_samples import HERE, camera, cuboid, principled, quad

sys.path.insert(0, os.path.dirname(HERE))
from drt_addon.export.volume_objects import openvdb_module  # noqa: E402

SIZE = (48, 64)
VOXEL = 0.04
SHAPE = (48, 48, 80)


def _turbulence(x, y, z, rng, waves=24):
    """A smooth random field in about [-1, 1]: a sum of sine waves of random
    directions, wavelengths (0.4 to 1.6 m) and phases."""
    f = np.zeros_like(x)
    for _ in range(waves):
        d = rng.normal(size=3)
        d *= rng.uniform(4.0, 16.0) / np.linalg.norm(d)
        f += np.sin(d[0] * x + d[1] * y + d[2] * z + rng.uniform(0.0, 2.0 * math.pi))
    return f / math.sqrt(waves / 2.0)


def plume_grids() -> dict:
    """{name: (nx, ny, nz) float32} of the plume: density, temperature, flame."""
    rng = np.random.default_rng(1984)
    i, j, k = np.meshgrid(*(np.arange(n, dtype=np.float64) for n in SHAPE), indexing="ij")
    x = (i - (SHAPE[0] - 1) / 2) * VOXEL
    y = (j - (SHAPE[1] - 1) / 2) * VOXEL
    z = k * VOXEL
    top = SHAPE[2] * VOXEL
    sway = 0.18 * np.sin(1.3 * z + 0.5)
    r = np.hypot(x - sway, y - 0.6 * sway)
    radius = 0.16 + 0.14 * z
    core = np.exp(-2.0 * (r / radius) ** 2)
    fade = np.clip(1.0 - z / top, 0.0, 1.0) ** 1.5
    density = core * fade * np.clip(1.0 + 0.7 * _turbulence(x, y, z, rng), 0.0, None)
    heat = np.exp(-2.0 * (r / (0.7 * radius)) ** 2) * np.exp(-z / 0.6)
    temperature = 2.0 * heat * np.clip(1.0 + 0.3 * _turbulence(x, y, z, rng), 0.0, None)
    flame = np.clip(heat - 0.35, 0.0, None) * np.exp(-z / 0.3) * 3.0
    grids = {"density": density, "temperature": temperature, "flame": flame}
    # below a thousandth a voxel is empty (Blender's default Clipping of a Volume)
    return {n: np.where(g > 1e-3, g, 0.0).astype(np.float32) for n, g in grids.items()}


def write_plume(path: str) -> None:
    vdb = openvdb_module()
    out = []
    for name, values in plume_grids().items():
        grid = vdb.FloatGrid()
        grid.copyFromArray(values, ijk=(0, 0, 0), tolerance=0.0)
        grid.transform = vdb.createLinearTransform(voxelSize=VOXEL)
        grid.transform.postTranslate((-(SHAPE[0] - 1) / 2 * VOXEL,
                                      -(SHAPE[1] - 1) / 2 * VOXEL, 0.0))
        grid.name = name
        out.append(grid)
    vdb.write(path, grids=out)


def _smoke_material():
    mat, nt = empty_material("Smoke")
    vol = nt.nodes.new("ShaderNodeVolumePrincipled")
    vol.inputs["Density"].default_value = 10.0
    vol.inputs["Color"].default_value = (0.55, 0.55, 0.6, 1.0)
    vol.inputs["Blackbody Intensity"].default_value = 1.0
    vol.inputs["Temperature"].default_value = 1500.0
    vol.inputs["Emission Color"].default_value = (1.0, 0.45, 0.1, 1.0)
    flame = nt.nodes.new("ShaderNodeAttribute")
    flame.attribute_name = "flame"
    nt.links.new(flame.outputs["Fac"], vol.inputs["Emission Strength"])
    nt.links.new(vol.outputs["Volume"], nt.nodes["Material Output"].inputs["Volume"])
    return mat


def smoke_plume():
    scene = _new_scene(SIZE)
    world = bpy.data.worlds.new("Dusk")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.3, 0.4, 0.6, 1.0)
    bg.inputs["Strength"].default_value = 0.3
    scene.world = world
    concrete = principled("Concrete", (0.5, 0.48, 0.45), roughness=0.8)
    quad("Floor", [(-4, -3, 0), (4, -3, 0), (4, 4, 0), (-4, 4, 0)], concrete)
    cuboid("Wall", (-4.0, 1.6, 0.0), (4.0, 1.8, 4.0), principled("Brick", (0.45, 0.2, 0.12)))
    path = os.path.join(HERE, "smoke_plume.vdb")
    write_plume(path)
    volume = bpy.data.volumes.new("Plume")
    volume.filepath = path
    smoke = bpy.data.objects.new("Plume", volume)
    smoke.data.materials.append(_smoke_material())
    scene.collection.objects.link(smoke)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.data.angle = math.radians(3.0)
    sun.rotation_euler = (math.radians(50.0), 0.0, math.radians(-40.0))
    scene.collection.objects.link(sun)
    camera(scene, (0.0, -3.4, 1.45), (math.radians(88.0), 0.0, 0.0), lens=30.0)
    return scene


SCENES = {"smoke_plume": smoke_plume}
# files a scene writes beside its .blend, which the .blend names by relative path
SIDE_FILES = {"smoke_plume": ("smoke_plume.vdb",)}
