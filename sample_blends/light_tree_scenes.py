"""A scene of many lights, made the way artists make one, with Blender's defaults (Light
Tree on, as Cycles has it since Blender 3.5): the comparison of issue 27's "many lights"
(tests/test_light_tree_vs_cycles.py). Built by build_samples.py.

night_street
    A street at night between two rows of buildings, seen from a pedestrian's height:
    48 street lamps on both sidewalks (point lamps of 0.1 m radius, every third a spot
    aimed down, 40 to 120 W, warm white), 12 small coloured shop-sign lamps near the
    ground (2 to 6 W), 36 lit windows (an Emission shader, strength 2 to 6, on quads in
    the facades: 72 emissive triangles) and a dim blue night sky. The asphalt is a
    rough Principled surface, the facades plaster. Most lamps are far from most of what
    the camera sees: picking lamps by power, a renderer spends its samples on lamps
    that light other parts of the street.
"""
from __future__ import annotations

import math
import random

import bpy

from artist_scenes import _new_scene, _world, empty_material
from build_samples import camera, cuboid, principled, quad


def _emission(name, color, strength):
    mat, nt = empty_material(name)
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (*color, 1.0)
    em.inputs["Strength"].default_value = strength
    nt.links.new(em.outputs["Emission"], nt.nodes["Material Output"].inputs["Surface"])
    return mat


def _lamp(scene, name, kind, location, power, color, radius, rotation=(0.0, 0.0, 0.0),
          spot_size=None):
    light = bpy.data.lights.new(name, kind)
    light.energy = power
    light.color = color
    light.shadow_soft_size = radius
    if spot_size is not None:
        light.spot_size = spot_size
        light.spot_blend = 0.3
    obj = bpy.data.objects.new(name, light)
    obj.location = location
    obj.rotation_euler = rotation
    scene.collection.objects.link(obj)
    return obj


def night_street():
    rng = random.Random(27)
    scene = _new_scene()
    _world(scene, (0.05, 0.08, 0.2), 0.3)
    asphalt = principled("Asphalt", (0.08, 0.08, 0.09), roughness=0.6)
    pavement = principled("Pavement", (0.3, 0.3, 0.28), roughness=0.8)
    plaster = [principled(f"Plaster {i}", c, roughness=0.7)
               for i, c in enumerate([(0.6, 0.5, 0.4), (0.45, 0.5, 0.55), (0.65, 0.6, 0.55)])]
    quad("Street", [(-4, -2, 0), (4, -2, 0), (4, 60, 0), (-4, 60, 0)], asphalt)
    for side in (-1, 1):
        x0, x1 = sorted((side * 4.0, side * 7.0))
        quad(f"Sidewalk {side}", [(x0, -2, 0.12), (x1, -2, 0.12), (x1, 60, 0.12),
                                  (x0, 60, 0.12)], pavement)
    windows = [_emission(f"Window {i}", c, s) for i, (c, s) in enumerate(
        [((1.0, 0.8, 0.5), 3.0), ((0.9, 0.9, 1.0), 2.0), ((1.0, 0.6, 0.3), 6.0)])]
    n_window = 0
    for side in (-1, 1):
        face = side * 7.0                                # the facade's plane
        for b in range(6):
            y0 = b * 10.0
            height = 8.0 + 4.0 * rng.random()
            x0, x1 = sorted((face, face + side * 6.0))
            cuboid(f"Building {side} {b}", (x0, y0 + 0.3, 0.0), (x1, y0 + 9.7, height),
                   plaster[(b + (side > 0)) % 3])
            for w in range(3):
                y, z = y0 + 2.0 + 3.0 * w, 3.0 + 3.0 * ((w + b) % 2)
                xw = face - side * 0.01                  # just in front of the facade
                quad(f"Window {n_window}", [(xw, y, z), (xw, y + 1.2, z),
                                            (xw, y + 1.2, z + 1.5), (xw, y, z + 1.5)][::side],
                     windows[n_window % 3])
                n_window += 1
    n_lamp = 0
    for side in (-1, 1):
        for i in range(24):
            y = -1.0 + 2.5 * i
            power = 40.0 + 80.0 * rng.random()
            loc = (side * 4.5, y, 4.0)
            if i % 3 == 0:
                _lamp(scene, f"Street Lamp {n_lamp}", "SPOT", loc, power, (1.0, 0.85, 0.6),
                      0.1, spot_size=math.radians(110.0))     # aimed down (-Z)
            else:
                _lamp(scene, f"Street Lamp {n_lamp}", "POINT", loc, power, (1.0, 0.85, 0.6),
                      0.1)
            n_lamp += 1
    for i in range(12):
        side = -1 if i % 2 else 1
        color = [(1.0, 0.2, 0.3), (0.2, 0.5, 1.0), (0.3, 1.0, 0.4)][i % 3]
        _lamp(scene, f"Sign {i}", "POINT", (side * 6.8, 3.0 + 4.5 * i, 2.6),
              2.0 + 4.0 * rng.random(), color, 0.05)
    camera(scene, (1.2, -6.0, 1.7), (math.radians(86.0), 0.0, math.radians(-4.0)),
           lens=28.0)
    return scene


SCENES = {"night_street": night_street}
