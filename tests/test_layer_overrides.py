"""View Layer > Override > Material and World, as Cycles renders them
(drt_addon/export/layer_overrides.py).

- Export: with a material override every object renders with it, in each of its slots
  and also without any slot; the mesh export asks for what the override's nodes read (an
  image texture's UVs), not what the objects' own materials read.
- Against Cycles: the Cornell box as a clay render (a grey Principled override) and the
  world-lit scene under a world override, each at Blender's defaults: image means within
  2 % per channel and 8 x 8 blocks within 5 % of the image mean (the tolerances of the
  other comparisons); the same render without the override is the control, and fails
  them. Measured (DRT 256 samples, Cycles 512, 32 x 32): clay -0.05 % in each channel,
  worst block 2.56 % (control +23.9 / +6.9 / -15.6 %, 230 %); world +0.01 %, 0.13 %
  (control -25 / +133 / +1400 %, 163 %). Before, DRT warned that it ignored both
  overrides and rendered the objects' own materials and the scene's World.
"""
from __future__ import annotations

import os

import numpy as np
import pytest

from conftest import SAMPLES_DIR, render_blend
from test_multiscatter_vs_cycles import assert_matches, compare, within

DRT_SAMPLES, CYCLES_SAMPLES = 256, 512


def _clay(bpy):
    mat = bpy.data.materials.get("clay") or bpy.data.materials.new("clay")
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.6
    return mat


def _textured(bpy):
    """An override that reads the mesh's UVs: an image texture as its base colour."""
    mat = bpy.data.materials.new("checker override")
    nt = mat.node_tree
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = bpy.data.images.new("checks", 4, 4)
    nt.links.new(tex.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    return mat


def test_every_slot_and_slotless_objects_take_the_override(bpy_drt):
    bpy = bpy_drt
    from drt_addon.export import export_scene
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_cube_add()
    cube = bpy.context.object
    for name in ("red", "blue"):
        cube.data.materials.append(bpy.data.materials.new(name))
    cube.data.polygons[0].material_index = 1
    bpy.ops.mesh.primitive_plane_add(size=4.0, location=(0.0, 0.0, -1.0))  # no slot
    bpy.ops.object.camera_add(location=(0.0, -6.0, 2.0), rotation=(1.3, 0.0, 0.0))
    scene.camera = bpy.context.object
    scene.render.resolution_x = scene.render.resolution_y = 16

    def export():
        return export_scene(bpy.context.evaluated_depsgraph_get())

    own = export()
    assert sorted(m.name for m in own.materials) == ["blue", "none", "red"]
    assert all(m.uvs is None for m in own.meshes)        # no material reads UVs
    scene.view_layers[0].material_override = _textured(bpy)
    clay = export()
    names = {m.name for m in clay.materials}
    assert names == {"checker override"}, names
    assert all(len(m.triangles) and (m.material_indices == 0).all() for m in clay.meshes)
    assert all(m.uvs is not None for m in clay.meshes)   # what the override reads


def _clay_setup(scene):
    import bpy
    scene.view_layers[0].material_override = _clay(bpy)


def _orange_world(scene):
    import bpy
    world = bpy.data.worlds.new("orange")
    world.color = (1.0, 0.45, 0.1)
    if world.node_tree is not None:           # a new world has nodes in Blender 5
        world.node_tree.nodes["Background"].inputs["Color"].default_value = (
            1.0, 0.45, 0.1, 1.0)
    scene.view_layers[0].world_override = world


@pytest.mark.parametrize("blend, setup", [("cornell_box", _clay_setup),
                                          ("world_light", _orange_world)],
                         ids=["material", "world"])
def test_the_override_renders_as_in_cycles(bpy_drt, blend, setup):
    path = os.path.join(SAMPLES_DIR, f"{blend}.blend")
    cycles = render_blend(bpy_drt, path, "CYCLES", CYCLES_SAMPLES, percentage=50,
                          setup=setup)
    drt = render_blend(bpy_drt, path, "DRT", DRT_SAMPLES, percentage=50, setup=setup)
    assert_matches(drt, cycles, 0.02, 0.05)
    own = render_blend(bpy_drt, path, "DRT", 64, percentage=50)
    rel, block = compare(own, cycles)
    print(f"control, without the override: mean {np.round(100 * rel, 1)} %, worst block "
          f"{100 * block:.1f} %")
    assert not within(own, cycles)
    assert np.isfinite(own).all()
