"""Coat, sheen, translucency and the Refraction BSDF against Cycles: four small scenes
(64 x 48 pixels) built here with bpy at Blender's defaults (bounces, Filter Glossy,
Principled inputs not named), rendered by Cycles (1024 samples per pixel) and DRT (1024),
each compared with `compare` of tests/test_multiscatter_vs_cycles.py: image means within
1 % per channel and every 8 x 8 block mean within 3 % of the image mean. Each scene has
a control, DRT rendering it without the feature (as it did before), which must fail.

  * coat: a red Principled sphere with Coat Weight 1 on a grey plane, an area lamp and
    a dim world; control: coat weight 0.
  * sheen: a dark blue Principled sphere with Sheen Weight 1 (roughness 0.5) and a grey
    sphere Mix(Diffuse, Sheen BSDF) lit from behind-above (grazing light shows sheen);
    control: sheen weight 0 and the Sheen BSDF replaced by black.
  * translucent: a leaf-green plane, Mix(Diffuse, Translucent), lit by an area lamp from
    behind (the camera sees only transmitted light and the dim world); control: the
    Translucent BSDF replaced by a Diffuse one.
  * refraction: a large Refraction BSDF sphere (IOR 1.45, roughness 0) before a striped
    wall, lit by a white sky (strength 1) alone, Filter Glossy 0 in both engines
    (with 1, DRT is -2.06 % off, its Glass BSDF +0.26 %: Blender's default distribution
    for the Refraction BSDF is Beckmann, which DRT renders as GGX (warned), and Filter
    Glossy widens the smooth sphere into a rough lobe; at roughness 0.3 DRT is -2.18 %
    off with Filter Glossy 0; with the node set to GGX in both engines -0.03 % at
    roughness 0.3 and +0.02 % smooth with Filter Glossy 1); control: a Glass BSDF (what
    DRT rendered it as before). Under an area lamp instead, DRT is -2.1 % off Cycles for
    this sphere and -2.2 % for a Glass BSDF sphere alike (the known lamp-caustics
    difference of docs/comparisons.md, glass_caustics), so the sky isolates the lobe.

Measured (DRT vs Cycles: mean per channel, worst block; control the same):
  coat         -0.04 %, 0.32 %;  control +1.2 / -2.2 / -2.4 %, 25 %
  sheen        +0.05 %, 0.63 %;  control -2.5 / -2.5 / -2.1 %, 18 %
  translucent  -0.00 %, 0.06 %;  control -80 / -88 / -71 %, 165 %
  refraction   +0.02 %, 0.46 %;  control +1.5 / +1.5 / +1.7 %, 13 %
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import render_current
from test_multiscatter_vs_cycles import compare

SAMPLES = 1024
MEAN_TOLERANCE = 0.01
BLOCK_TOLERANCE = 0.03

_renders = {}


def _fresh(bpy):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("World")
    bg = scene.world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bg.inputs["Strength"].default_value = 0.1
    return scene


def _camera(scene, bpy, location, rotation_deg, lens=40.0):
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = location
    cam.rotation_euler = tuple(math.radians(a) for a in rotation_deg)
    cam.data.lens = lens
    scene.collection.objects.link(cam)
    scene.camera = cam


def _area(scene, bpy, location, rotation_deg, size, energy):
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "AREA"))
    lamp.data.size = size
    lamp.data.energy = energy
    lamp.location = location
    lamp.rotation_euler = tuple(math.radians(a) for a in rotation_deg)
    scene.collection.objects.link(lamp)


def _material(bpy, name):
    """A material whose tree holds only its output node."""
    mat = bpy.data.materials.new(name)
    nodes = mat.node_tree.nodes
    for node in list(nodes):
        if node.bl_idname != "ShaderNodeOutputMaterial":
            nodes.remove(node)
    return mat, nodes, mat.node_tree.links, nodes["Material Output"]


def _principled(bpy, name, **inputs):
    mat = bpy.data.materials.new(name)
    p = mat.node_tree.nodes["Principled BSDF"]
    for key, value in inputs.items():
        p.inputs[key].default_value = value
    return mat


def _plane(scene, bpy, size, location=(0.0, 0.0, 0.0), rotation_deg=(0.0, 0.0, 0.0), mat=None):
    bpy.ops.mesh.primitive_plane_add(size=size, location=location,
                                     rotation=tuple(math.radians(a) for a in rotation_deg))
    obj = bpy.context.active_object
    if mat is not None:
        obj.data.materials.append(mat)
    return obj


def _sphere(bpy, location, radius, mat):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=radius,
                                         location=location)
    obj = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(mat)
    return obj


def _mix(bpy, name, first, second, fac=0.5, color=(0.8, 0.8, 0.8, 1.0)):
    """Mix(first, second) of two BSDF node types with colour `color` each."""
    mat, nodes, links, out = _material(bpy, name)
    a, b = nodes.new(first), nodes.new(second)
    for node in (a, b):
        if "Color" in node.inputs:
            node.inputs["Color"].default_value = color
    mix = nodes.new("ShaderNodeMixShader")
    mix.inputs[0].default_value = fac
    links.new(a.outputs[0], mix.inputs[1])
    links.new(b.outputs[0], mix.inputs[2])
    links.new(mix.outputs[0], out.inputs["Surface"])
    return mat


def grey(bpy):
    return _principled(bpy, "Grey", **{"Base Color": (0.5, 0.5, 0.5, 1.0)})


# --- the scenes ----------------------------------------------------------------------------

def coat_scene(bpy, control=False):
    scene = _fresh(bpy)
    _camera(scene, bpy, (0.0, -4.2, 1.6), (72.0, 0.0, 0.0))
    _area(scene, bpy, (1.0, -1.5, 3.5), (20.0, 10.0, 0.0), 2.0, 150.0)
    _plane(scene, bpy, 12.0, mat=grey(bpy))
    red = _principled(bpy, "CoatedRed", **{"Base Color": (0.8, 0.08, 0.05, 1.0),
                                          "Coat Weight": 0.0 if control else 1.0})
    _sphere(bpy, (0.0, 0.0, 0.8), 0.8, red)
    return scene


def sheen_scene(bpy, control=False):
    scene = _fresh(bpy)
    _camera(scene, bpy, (0.0, -4.5, 1.2), (80.0, 0.0, 0.0))
    _area(scene, bpy, (0.0, 2.5, 3.0), (-40.0, 0.0, 0.0), 2.0, 300.0)
    _plane(scene, bpy, 12.0, mat=grey(bpy))
    blue = _principled(bpy, "Velvet", **{"Base Color": (0.05, 0.05, 0.25, 1.0),
                                        "Sheen Weight": 0.0 if control else 1.0})
    _sphere(bpy, (-0.75, 0.0, 0.65), 0.65, blue)
    second = "ShaderNodeBsdfDiffuse" if control else "ShaderNodeBsdfSheen"
    cloth = _mix(bpy, "Cloth", "ShaderNodeBsdfDiffuse", second, 0.5, (0.3, 0.3, 0.3, 1.0))
    if control:       # the sheen replaced by black
        cloth.node_tree.nodes["Diffuse BSDF.001"].inputs["Color"].default_value = (0, 0, 0, 1)
    _sphere(bpy, (0.75, 0.0, 0.65), 0.65, cloth)
    return scene


def translucent_scene(bpy, control=False):
    scene = _fresh(bpy)
    _camera(scene, bpy, (0.0, -3.0, 0.0), (90.0, 0.0, 0.0))
    _area(scene, bpy, (0.0, 1.5, 0.5), (-90.0, 0.0, 0.0), 1.5, 100.0)
    second = "ShaderNodeBsdfDiffuse" if control else "ShaderNodeBsdfTranslucent"
    leaf = _mix(bpy, "Leaf", "ShaderNodeBsdfDiffuse", second, 0.5, (0.2, 0.6, 0.1, 1.0))
    _plane(scene, bpy, 2.0, rotation_deg=(90.0, 0.0, 0.0), mat=leaf)
    return scene


def refraction_scene(bpy, control=False):
    scene = _fresh(bpy)
    # lit by the sky alone: DRT's lamp caustics through glass differ from Cycles' by
    # about -2 % here, for the Glass BSDF as much as for this one (docs/comparisons.md,
    # glass_caustics), which is not what this test is about
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    # Filter Glossy off in both engines (DRT reads it): with Cycles' default 1 DRT is
    # -2.0 % (blocks -5 %) here while its Glass BSDF matches Cycles' (+0.03 %): the
    # refraction-only lobe widened after diffuse bounces still differs (left open)
    scene.cycles.blur_glossy = 0.0
    _camera(scene, bpy, (0.0, -4.0, 1.0), (85.0, 0.0, 0.0))
    _plane(scene, bpy, 12.0, mat=grey(bpy))
    for k in range(6):                     # a striped wall behind the sphere
        colour = (0.8, 0.7, 0.1, 1.0) if k % 2 else (0.1, 0.2, 0.7, 1.0)
        _plane(scene, bpy, 1.0, location=(-2.5 + k, 2.0, 1.0), rotation_deg=(90.0, 0.0, 0.0),
               mat=_principled(bpy, f"Stripe{k}", **{"Base Color": colour}))
    mat, nodes, links, out = _material(bpy, "Refraction")
    node = nodes.new("ShaderNodeBsdfGlass" if control else "ShaderNodeBsdfRefraction")
    node.inputs["IOR"].default_value = 1.45
    node.inputs["Roughness"].default_value = 0.0
    links.new(node.outputs[0], out.inputs["Surface"])
    _sphere(bpy, (0.0, 0.0, 1.0), 0.9, mat)
    return scene


SCENES = {"coat": coat_scene, "sheen": sheen_scene, "translucent": translucent_scene,
          "refraction": refraction_scene}


def render(bpy, name, engine, control=False):
    key = (name, engine, control)
    if key not in _renders:
        scene = SCENES[name](bpy, control)
        scene.render.engine = engine
        c = scene.cycles
        c.samples = scene.drt.samples = SAMPLES
        c.use_denoising = c.use_adaptive_sampling = False
        c.device = "CPU"
        _renders[key] = render_current(bpy, scene)
    return _renders[key]


def within(rel, block):
    return bool((np.abs(rel) <= MEAN_TOLERANCE).all() and block <= BLOCK_TOLERANCE)


@pytest.mark.parametrize("name", list(SCENES))
def test_matches_cycles_and_the_control_does_not(bpy_drt, name):
    cycles = render(bpy_drt, name, "CYCLES")
    drt = render(bpy_drt, name, "DRT")
    control = render(bpy_drt, name, "DRT", control=True)
    assert drt.shape == cycles.shape == (48, 64, 3) and np.isfinite(drt).all()
    assert cycles.mean() > 0.02
    rel, block = compare(drt, cycles)
    c_rel, c_block = compare(control, cycles)
    print(f"{name}: DRT vs Cycles mean {np.round(100 * rel, 2)} %, worst block "
          f"{100 * block:.2f} %; control mean {np.round(100 * c_rel, 2)} %, worst block "
          f"{100 * c_block:.2f} %")
    assert (np.abs(rel) <= MEAN_TOLERANCE).all(), rel
    assert block <= BLOCK_TOLERANCE, block
    assert not within(c_rel, c_block)
