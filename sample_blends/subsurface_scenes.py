"""Sample scenes of subsurface scattering, made the way artists make them, with Blender's
defaults: the scenes tests/test_subsurface_vs_cycles.py compares.

subsurface
    Three translucent things on a checker floor in front of a wall: a smooth subdivided
    Suzanne of Principled skin (Subsurface Weight 1, the default Radius, Scale 0.1,
    Random Walk) with pores (a Noise Texture of scale 30 through a Bump of 4 mm into its
    Normal), a wax candle (Principled, Subsurface Weight 1, Scale 0.05, Random Walk
    (Skin)) lit from just above its top by a warm point lamp for a flame, and a marble
    sphere (a Subsurface Scattering node, Scale 0.2, Roughness 0.3, mixed with a Glossy
    BSDF through a Fresnel-less Mix at 0.1). A key area lamp in front, a rim area lamp
    behind (the backlight shows the translucency), a dim sky.
"""
from __future__ import annotations

import math

import bmesh
import bpy

from artist_scenes import (_bmesh_object, _bumped, _link, _new_scene, _smooth, _suzanne,
                           _world, empty_material)
from build_samples import _area_light, _checker, camera, principled, quad


def _subsurface(mat, weight, scale, method="RANDOM_WALK", radius=None):
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Subsurface Weight"].default_value = weight
    bsdf.inputs["Subsurface Scale"].default_value = scale
    if radius is not None:
        bsdf.inputs["Subsurface Radius"].default_value = radius
    bsdf.subsurface_method = method
    return mat


def _marble():
    """A Subsurface Scattering node mixed with a little Glossy BSDF."""
    mat, nt = empty_material("Marble")
    sss = nt.nodes.new("ShaderNodeSubsurfaceScattering")
    sss.inputs["Color"].default_value = (0.85, 0.85, 0.9, 1.0)
    sss.inputs["Scale"].default_value = 0.2
    sss.inputs["Roughness"].default_value = 0.3
    glossy = nt.nodes.new("ShaderNodeBsdfGlossy")
    glossy.inputs["Roughness"].default_value = 0.15
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.1
    _link(nt, sss, "BSSRDF", mix, 1)
    _link(nt, glossy, "BSDF", mix, 2)
    _link(nt, mix, "Shader", nt.nodes["Material Output"], "Surface")
    mat.diffuse_color = (0.85, 0.85, 0.9, 1.0)
    return mat


def _candle(material, x, y, radius=0.14, height=0.5):
    def build(bm):
        bmesh.ops.create_cone(bm, cap_ends=True, segments=32, radius1=radius,
                              radius2=radius, depth=height)
    obj = _bmesh_object("Candle", build, material)
    _smooth(obj)
    obj.location = (x, y, height / 2.0)
    return obj


def _sphere(material, x, y, radius=0.28):
    obj = _bmesh_object("Sphere", lambda bm: bmesh.ops.create_uvsphere(
        bm, u_segments=48, v_segments=24, radius=radius), material)
    _smooth(obj)
    obj.location = (x, y, radius)
    return obj


def subsurface():
    scene = _new_scene()
    _world(scene, (0.4, 0.55, 0.8), 0.05)
    _checker("Floor", -3.0, 3.0, -2.0, 4.0, 0.0, [(0.55, 0.55, 0.55), (0.2, 0.2, 0.2)], 12)
    quad("Wall", [(-3.0, 1.2, 0.0), (3.0, 1.2, 0.0), (3.0, 1.2, 3.0), (-3.0, 1.2, 3.0)],
         principled("Wall", (0.5, 0.45, 0.4)))
    skin = _subsurface(_bumped("Skin", (0.85, 0.55, 0.45), 0.4, "ShaderNodeTexNoise", 30.0,
                               0.004), 1.0, 0.1)
    suzanne = _suzanne(skin, 0.45)
    suzanne.scale = (0.4, 0.4, 0.4)
    wax = _subsurface(principled("Wax", (0.9, 0.8, 0.6), roughness=0.3), 1.0, 0.05,
                      method="RANDOM_WALK_SKIN")
    _candle(wax, -0.8, 0.1)
    _sphere(_marble(), 0.8, 0.1)
    flame = bpy.data.objects.new("Flame", bpy.data.lights.new("Flame", "POINT"))
    flame.data.energy = 4.0
    flame.data.shadow_soft_size = 0.02
    flame.data.color = (1.0, 0.6, 0.3)
    flame.location = (-0.8, 0.1, 0.56)
    scene.collection.objects.link(flame)
    _area_light(scene, (-1.5, -2.5, 2.2), (0.0, 0.0, 0.4), 1.5, 12.0, name="Key")
    _area_light(scene, (0.5, 1.0, 1.6), (0.0, 0.0, 0.4), 0.8, 25.0, name="Rim")
    camera(scene, (0.0, -3.0, 1.0), (math.radians(80.0), 0.0, 0.0), lens=50.0)
    return scene


SCENES = {"subsurface": subsurface}
