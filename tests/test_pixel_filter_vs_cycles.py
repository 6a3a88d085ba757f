"""Film > Pixel Filter against Cycles: the file's filter type and width are DRT's too.

The scene (built here with bpy): a plane with a fine emissive checker (Checker Texture,
scale 40, white and black, strength 1; the checks about 1.2 pixels wide), turned 20
degrees about the view axis and tilted, so edges cross pixels at every phase; a black
world, no lamp: each pixel is the checker seen through the pixel filter, with no light
transport noise. 48 x 48 pixels, 256 samples per pixel in both engines.

The check: the mean over pixels of |DRT - Cycles| within MAD_TOLERANCE of the image mean,
per filter. The control renders DRT with Blender's default filter (Blackman-Harris 1.5,
what DRT rendered whatever the file said, with its own Filter setting, until it read
the file's) against Cycles with the file's filter: it must fail the same check.

Measured (MAD over the image mean): DRT against Cycles, then each engine against itself
at another seed (the noise floor), then the control:
  Gaussian 1.5          1.58 %   DRT 1.50 %, Cycles 1.60 %    control  4.91 %
  Gaussian 3.0          2.24 %   DRT 2.16 %, Cycles 2.24 %    control 27.1 %
  Box 1.0               1.02 %   DRT 0.96 %, Cycles 1.06 %    control 12.2 %
  Blackman-Harris 3.0   2.40 %   DRT 2.29 %, Cycles 2.32 %    control 32.8 %
DRT and Cycles differ by what either differs from itself: the filters are the same. Image
means within 0.07 %.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import render_current, use_engine

SIZE = 48
SAMPLES = 256
MAD_TOLERANCE = 0.03
CASES = [("GAUSSIAN", 1.5), ("GAUSSIAN", 3.0), ("BOX", 1.0), ("BLACKMAN_HARRIS", 3.0)]

_renders = {}


def _build(bpy):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("Black")
    if bpy.app.version < (5, 0, 0):
        scene.world.use_nodes = True
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    bpy.ops.mesh.primitive_plane_add(size=4.0, rotation=(math.radians(15), 0.0,
                                                         math.radians(20)))
    plane = bpy.context.active_object
    mat = bpy.data.materials.new("Checker")
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.remove(nodes["Principled BSDF"])
    checker = nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 40.0
    checker.inputs["Color1"].default_value = (1.0, 1.0, 1.0, 1.0)
    checker.inputs["Color2"].default_value = (0.0, 0.0, 0.0, 1.0)
    emission = nodes.new("ShaderNodeEmission")
    links.new(checker.outputs["Color"], emission.inputs["Color"])
    links.new(emission.outputs["Emission"], nodes["Material Output"].inputs["Surface"])
    plane.data.materials.append(mat)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, 0.0, 3.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene


def _render(bpy, engine, kind, width):
    key = (engine, kind, width)
    if key not in _renders:
        scene = _build(bpy)
        use_engine(scene, engine, SAMPLES)
        scene.cycles.pixel_filter_type, scene.cycles.filter_width = kind, width
        _renders[key] = render_current(bpy, scene)
    return _renders[key]


def mad(image, reference):
    return float(np.abs(image - reference).mean() / reference.mean())


@pytest.mark.parametrize("kind,width", CASES)
def test_the_files_pixel_filter_matches_cycles_and_the_default_does_not(bpy_drt, kind,
                                                                        width):
    cycles = _render(bpy_drt, "CYCLES", kind, width)
    drt = _render(bpy_drt, "DRT", kind, width)
    default = _render(bpy_drt, "DRT", "BLACKMAN_HARRIS", 1.5)
    assert drt.shape == cycles.shape == (SIZE, SIZE, 3) and np.isfinite(drt).all()
    assert 0.2 < cycles.mean() < 0.8 and cycles.std() > 0.05      # the checker is seen
    got, control = mad(drt, cycles), mad(default, cycles)
    print(f"{kind} {width}: MAD {got:.2%} of the mean; DRT at Blackman-Harris 1.5: "
          f"{control:.2%}")
    assert got <= MAD_TOLERANCE
    assert control > MAD_TOLERANCE
