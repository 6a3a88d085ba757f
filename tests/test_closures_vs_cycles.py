"""Coat, sheen, translucency, the Refraction BSDF, Beckmann, the Glossy BSDF, the
Principled Specular Tint, the Glass BSDF's Color and the Metallic BSDF against Cycles:
ten small scenes
(64 x 48 pixels) built here with bpy at Blender's defaults (bounces, Filter Glossy,
Principled inputs not named), rendered by Cycles (512 samples per pixel) and DRT (512),
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
  * refraction: a large smooth Refraction BSDF sphere (IOR 1.45) before a striped wall,
    lit by a white sky (strength 1) alone, at Blender's defaults: Filter Glossy 1 widens
    it after blurry bounces into a rough lobe of the node's default distribution,
    Beckmann (rendered as GGX before: -2.06 %, worst block 7.4 %); control: a Glass BSDF
    (what DRT rendered it as before that).
  * beckmann: rough Refraction (roughness 0.3, its default distribution), Glass (0.3)
    and Glossy (0.4) BSDF spheres with Beckmann in the same room; control: the three
    with GGX, what DRT rendered Beckmann as before (the Refraction sphere alone was
    -2.18 % then).
  * glossy: two dark Glossy BSDF spheres (Multiscatter GGX, roughness 0.2 and 0.5) in
    the same room: Cycles' Glossy reflects its colour at every angle (no Fresnel term);
    control: Principled metals of the same colours, Schlick's Fresnel, what DRT
    rendered a Glossy BSDF as before (brighter towards grazing angles).
  * specular_tint: two Principled metals (Cycles' F82-tint Fresnel) and two
    dielectrics (the specular layer's tinted F0) with a Specular Tint; control: white
    tints (what DRT rendered before).
  * glass_tint: a smooth and a rough Principled glass (IOR 2.2) with strong Specular
    Tints (the reflection's F0 tinted, 1 - F_c let through); control: white tints.
  * glass_color: a smooth and a rough Glass BSDF with a strong Color, which Cycles
    applies to the reflection as well as the refraction; control: Principled glasses
    whose refraction has that tint and whose reflection is white (DRT before).
  * metallic: four Metallic BSDF spheres (Blender 4.3+), F82 Tint and Physical Conductor
    (DRT: the F82-tint fit, tests/test_metallic_node.py), each at its defaults and with
    a metal's colours, over the three distributions; control: grey diffuse spheres
    (what DRT rendered the node as before: a warning and the viewport colour).

Measured (DRT vs Cycles: mean per channel, worst block; control the same), at 512
samples (at 1024 the worst blocks were 0.06 % to 1.62 %, the means the same within
0.05 %; 512 renders the module in a third of the time):
  coat         +0.02 %, 1.19 %;  control +1.2 / -2.2 / -2.4 %, 26 %
  sheen        +0.09 %, 0.82 %;  control -2.4 / -2.4 / -2.1 %, 19 %
  translucent  -0.00 %, 0.08 %;  control -80 / -88 / -71 %, 165 %
  refraction   -0.02 %, 0.65 %;  control +0.24 / +0.24 / +0.47 %, 13 %
  beckmann     -0.07 %, 0.92 %;  control -3.8 / -3.7 / -3.4 %, 9.6 %
  glossy       -0.04 %, 0.31 %;  control +0.89 / +1.1 / +1.2 %, 6.8 %
  specular_tint 0.00 %, 0.59 %;  control +1.27 / +1.66 / +0.33 %, 4.2 %
  glass_tint   -0.31 / -0.18 / -0.28 %, 1.72 %;  control -0.36 / +0.42 / -0.99 %, 7.8 %
  glass_color  -0.04 %, 0.45 %;  control +2.2 / +3.2 / +2.0 %, 9.2 %
  metallic     +0.08 / +0.06 / -0.06 %, 0.50 %;  control +3.9 / +8.1 / +16.9 %, 37 %
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import render_current
from test_multiscatter_vs_cycles import compare

SAMPLES = 512
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


def _striped_room(bpy, sky=1.0):
    """A grey floor and a striped wall behind where the spheres go, lit by a white sky
    alone: DRT's lamp caustics through glass differ a little from Cycles'
    (docs/comparisons.md, glass_caustics), which is not what these scenes are about."""
    scene = _fresh(bpy)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = sky
    _camera(scene, bpy, (0.0, -4.0, 1.0), (85.0, 0.0, 0.0))
    _plane(scene, bpy, 12.0, mat=grey(bpy))
    for k in range(6):
        colour = (0.8, 0.7, 0.1, 1.0) if k % 2 else (0.1, 0.2, 0.7, 1.0)
        _plane(scene, bpy, 1.0, location=(-2.5 + k, 2.0, 1.0), rotation_deg=(90.0, 0.0, 0.0),
               mat=_principled(bpy, f"Stripe{k}", **{"Base Color": colour}))
    return scene


def _bsdf(bpy, name, kind, **inputs):
    mat, nodes, links, out = _material(bpy, name)
    node = nodes.new(kind)
    for key, value in inputs.items():
        if key == "distribution":
            node.distribution = value
        else:
            node.inputs[key].default_value = value
    links.new(node.outputs[0], out.inputs["Surface"])
    return mat, node


def refraction_scene(bpy, control=False):
    """A smooth Refraction BSDF sphere at Blender's defaults: Filter Glossy 1 widens it
    after blurry bounces into a rough lobe of the node's default distribution, Beckmann."""
    scene = _striped_room(bpy)
    mat, node = _bsdf(bpy, "Refraction", "ShaderNodeBsdfGlass" if control
                      else "ShaderNodeBsdfRefraction", IOR=1.45, Roughness=0.0)
    assert control or node.distribution == "BECKMANN"          # Blender's default
    _sphere(bpy, (0.0, 0.0, 1.0), 0.9, mat)
    return scene


def beckmann_scene(bpy, control=False):
    """Rough Refraction (its default distribution), Glass and Glossy BSDF spheres with
    Beckmann; control: the three with GGX (what DRT rendered Beckmann as before)."""
    scene = _striped_room(bpy)
    dist = "GGX" if control else "BECKMANN"
    for k, (kind, inputs) in enumerate((
            ("ShaderNodeBsdfRefraction", dict(IOR=1.45, Roughness=0.3)),
            ("ShaderNodeBsdfGlass", dict(IOR=1.45, Roughness=0.3)),
            ("ShaderNodeBsdfGlossy", dict(Roughness=0.4, Color=(0.9, 0.8, 0.6, 1.0))))):
        mat, node = _bsdf(bpy, f"Beckmann{k}", kind, distribution=dist, **inputs)
        _sphere(bpy, (-1.3 + 1.3 * k, 0.0, 0.75), 0.6, mat)
    return scene


def glossy_scene(bpy, control=False):
    """Two dark Glossy BSDF spheres at Blender's defaults (Multiscatter GGX): Cycles'
    Glossy has no Fresnel term, its colour is its reflectance at every angle; control:
    Principled metals of the same colours (Schlick's Fresnel, which whitens towards
    grazing angles: what DRT rendered a Glossy BSDF as before)."""
    scene = _striped_room(bpy)
    for k, (colour, rough) in enumerate((((0.15, 0.1, 0.05, 1.0), 0.2),
                                          ((0.5, 0.25, 0.08, 1.0), 0.5))):
        if control:
            mat = _principled(bpy, f"Glossy{k}", **{"Base Color": colour, "Metallic": 1.0,
                                                     "Roughness": rough})
        else:
            mat, _ = _bsdf(bpy, f"Glossy{k}", "ShaderNodeBsdfGlossy", Color=colour,
                           Roughness=rough)
        _sphere(bpy, (-0.7 + 1.4 * k, 0.0, 0.75), 0.65, mat)
    return scene


def tint_scene(bpy, control=False):
    """Two Principled metals and two dielectrics with a Specular Tint (metals: Cycles'
    F82-tint Fresnel, Schlick's times the tint at about 82 degrees, so the tint shows
    towards the silhouettes; dielectrics: the specular layer's F0 times the tint, fading
    to white at grazing angles); control: the same with white tints (what DRT rendered
    before)."""
    scene = _striped_room(bpy)
    for k, (colour, metal, tint, rough) in enumerate((
            ((0.95, 0.7, 0.3, 1.0), 1.0, (1.0, 0.3, 0.1, 1.0), 0.25),
            ((0.9, 0.9, 0.9, 1.0), 1.0, (0.2, 0.5, 1.0, 1.0), 0.5),
            ((0.05, 0.05, 0.05, 1.0), 0.0, (1.0, 0.2, 0.1, 1.0), 0.2),
            ((0.3, 0.4, 0.2, 1.0), 0.0, (0.1, 0.6, 2.0, 1.0), 0.4))):
        mat = _principled(bpy, f"Tinted{k}", **{
            "Base Color": colour, "Metallic": metal, "Roughness": rough,
            "Specular IOR Level": 0.5 if k < 3 else 1.0,
            "Specular Tint": (1.0, 1.0, 1.0, 1.0) if control else tint})
        _sphere(bpy, (-1.35 + 0.9 * k, 0.0, 0.42), 0.42, mat)
    return scene


def glass_tint_scene(bpy, control=False):
    """Principled glass spheres (smooth and rough) with a Specular Tint: Cycles tints
    their reflection's F0 and lets the complement through (1 - F_c); control: white
    tints (what DRT rendered before)."""
    scene = _striped_room(bpy)
    for k, (tint, rough) in enumerate((((0.1, 0.5, 4.0, 1.0), 0.0),
                                        ((4.0, 1.0, 0.1, 1.0), 0.3))):
        mat = _principled(bpy, f"TintedGlass{k}", **{
            "Base Color": (1.0, 1.0, 1.0, 1.0), "Transmission Weight": 1.0, "IOR": 2.2,
            "Roughness": rough, "Specular Tint": (1.0, 1.0, 1.0, 1.0) if control else tint})
        _sphere(bpy, (-0.7 + 1.4 * k, 0.0, 0.75), 0.65, mat)
    return scene


def glass_color_scene(bpy, control=False):
    """Glass BSDF spheres (smooth and rough, IOR 1.6) with a strong Color: Cycles tints
    their reflection by it as well as their refraction (its reflection_tint); control:
    Principled glasses of base colour Color^2, whose refraction is tinted by Color and
    reflection is white (what DRT rendered a Glass BSDF as before)."""
    scene = _striped_room(bpy)
    for k, (colour, rough) in enumerate((((0.15, 0.45, 0.95), 0.0),
                                          ((0.95, 0.35, 0.1), 0.3))):
        if control:
            mat = _principled(bpy, f"ColouredGlass{k}", **{
                "Base Color": (*(c * c for c in colour), 1.0), "Transmission Weight": 1.0,
                "IOR": 1.6, "Roughness": rough})
        else:
            mat, _ = _bsdf(bpy, f"ColouredGlass{k}", "ShaderNodeBsdfGlass",
                           Color=(*colour, 1.0), IOR=1.6, Roughness=rough)
        _sphere(bpy, (-0.7 + 1.4 * k, 0.0, 0.75), 0.65, mat)
    return scene


def metallic_scene(bpy, control=False):
    """Four Metallic BSDF spheres (Blender 4.3+): F82 Tint at the node's defaults and
    with a gold colour and a red edge (GGX), Physical Conductor at its defaults (Multiscatter
    GGX) and with gold's IOR and Extinction (Beckmann); control: grey diffuse spheres,
    what DRT rendered the unsupported node as before (the viewport colour)."""
    scene = _striped_room(bpy)
    for k, (fresnel, dist, rough, inputs) in enumerate((
            ("F82", "MULTI_GGX", 0.25, {}),
            ("F82", "GGX", 0.45, {"Base Color": (0.95, 0.75, 0.3, 1.0),
                                  "Edge Tint": (1.0, 0.35, 0.2, 1.0)}),
            ("PHYSICAL_CONDUCTOR", "MULTI_GGX", 0.3, {}),
            ("PHYSICAL_CONDUCTOR", "BECKMANN", 0.35, {"IOR": (0.18, 0.42, 1.37),
                                                      "Extinction": (3.42, 2.35, 1.77)}))):
        if control:
            mat, _ = _bsdf(bpy, f"Metallic{k}", "ShaderNodeBsdfDiffuse")
        else:
            mat, node = _bsdf(bpy, f"Metallic{k}", "ShaderNodeBsdfMetallic", distribution=dist,
                              Roughness=rough)
            node.fresnel_type = fresnel             # before its inputs: it shows them
            for key, value in inputs.items():
                node.inputs[key].default_value = value
        _sphere(bpy, (-1.35 + 0.9 * k, 0.0, 0.42), 0.42, mat)
    return scene


SCENES = {"coat": coat_scene, "sheen": sheen_scene, "translucent": translucent_scene,
          "refraction": refraction_scene, "beckmann": beckmann_scene, "glossy": glossy_scene,
          "specular_tint": tint_scene, "glass_tint": glass_tint_scene,
          "glass_color": glass_color_scene, "metallic": metallic_scene}


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
