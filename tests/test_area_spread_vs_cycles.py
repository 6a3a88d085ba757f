"""Area lamps with a Spread, against Cycles at Blender's defaults: a grey floor and a
block under four area lamps whose Spread narrows their light (a 1 m square at 30
degrees, a 2 x 0.5 m rectangle at 10 degrees, tilted, a 1 m disk at 60 degrees and a
1.2 x 0.4 m ellipse at 15 degrees), in a dim grey world, 64 x 64 pixels.

Until 2026-12-03 DRT emitted over the whole hemisphere whatever the Spread (and said
so in its report); a public file, Water.blend (an area lamp of Spread 2 degrees), was 3x
to 20x too bright. The control renders the lamps so (Spread 180 degrees) and fails the
same checks."""
from __future__ import annotations

import math

import node_probe
from node_probe import image_errors, new_material, new_scene

DRT_SAMPLES = CYCLES_SAMPLES = 2048
LAMPS = (  # name, shape, size, size_y, spread (degrees), location, rotation (degrees)
    ("Square", "SQUARE", 1.0, 1.0, 30.0, (-1.2, 0.8, 2.5), (0.0, 0.0, 0.0)),
    ("Strip", "RECTANGLE", 2.0, 0.5, 10.0, (1.0, 1.0, 2.0), (20.0, -15.0, 0.0)),
    ("Disk", "DISK", 1.0, 1.0, 60.0, (1.3, -1.2, 3.0), (0.0, 10.0, 0.0)),
    ("Slot", "ELLIPSE", 1.2, 0.4, 15.0, (-1.0, -1.0, 1.8), (0.0, 0.0, 30.0)),
)


def _scene(bpy, spread=True):
    scene = new_scene(bpy, 64)
    nt = scene.world.node_tree
    nt.nodes["Background"].inputs["Color"].default_value = (0.02, 0.02, 0.02, 1.0)
    bpy.ops.mesh.primitive_plane_add(size=8.0)
    floor = bpy.context.object
    grey, tree = new_material(bpy, "Grey")
    tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    floor.data.materials.append(grey)
    bpy.ops.mesh.primitive_cube_add(size=0.8, location=(0.2, 0.1, 0.4))
    block = bpy.context.object
    red, tree = new_material(bpy, "Red")
    tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.7, 0.2, 0.1, 1.0)
    block.data.materials.append(red)
    for name, shape, size, size_y, degrees, location, rotation in LAMPS:
        light = bpy.data.lights.new(name, "AREA")
        light.shape, light.size, light.size_y = shape, size, size_y
        light.energy = 200.0
        light.spread = math.radians(degrees) if spread else math.pi
        lamp = bpy.data.objects.new(name, light)
        lamp.location = location
        lamp.rotation_euler = tuple(math.radians(a) for a in rotation)
        scene.collection.objects.link(lamp)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location, cam.rotation_euler = (0.0, -6.0, 5.0), (math.radians(50.0), 0.0, 0.0)
    cam.data.lens = 30.0
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene


def test_area_lamps_with_a_spread_match_cycles(bpy_drt):
    """DRT against Cycles, 2048 samples each: mean within 1 %, largest 8 x 8 block within
    12 % of the image mean; the lamps without their Spread miss both by far. The block
    bound is loose because the pools of light under the narrow lamps are nine to
    thirteen times the image mean and sharp-edged: at 1024 samples two seeds of Cycles
    differ by 9.1 % there, of DRT by 11.5 % (measured 2026-12-03)."""
    scene = _scene(bpy_drt)
    cycles = node_probe.render(bpy_drt, scene, "CYCLES", CYCLES_SAMPLES)
    mean, block = image_errors(node_probe.render(bpy_drt, scene, "DRT", DRT_SAMPLES), cycles)
    wide = node_probe.render(bpy_drt, _scene(bpy_drt, spread=False), "DRT", 256)
    c_mean, c_block = image_errors(wide, cycles, "control: the Spread left out")
    print(f"mean {mean:.2%}, largest block {block:.2%}; "
          f"control {c_mean:.2%}, {c_block:.2%}")
    assert mean < 0.01 and block < 0.12, (mean, block)
    assert c_mean > 0.05 and c_block > 0.2, (c_mean, c_block)
