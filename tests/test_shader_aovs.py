"""Shader AOVs (engine.shader_aovs, drt_addon/export/nodes/aov_output.py): the view
layer's AOV passes hold what the materials' AOV Output nodes receive at the first
surface each camera ray meets, as in Cycles.

The scene (tests/test_passes.py's plane, seen at an angle) has a Checker Texture wired
to an AOV Output node "tint" (a Color AOV) and the checker's Fac to a node "fac" (a
Value AOV); a cube with a material without AOV nodes stands on the plane, where both
passes are 0 as in Cycles (and the Color AOV's alpha, the share of samples that wrote
it). Both engines at 16 samples; every 8 x 8 block of each pass (RGBA for the Color
AOV) within 0.02 of Cycles' (measured: 0.0086 and 0.0107); the passes must show the
checker (a uniform pass is off by 0.45 and 0.55)."""
import numpy as np
import pytest

from conftest import read_render_rgba, render_current
from test_passes import H, W, build_scene, composite


def _scene(bpy, engine):
    scene = build_scene(bpy)
    mat = bpy.data.materials["Base"]
    nt = mat.node_tree
    tex = nt.nodes.new("ShaderNodeTexChecker")
    tex.inputs["Scale"].default_value = 10.0
    tex.inputs["Color1"].default_value = (0.9, 0.6, 0.1, 1.0)
    tex.inputs["Color2"].default_value = (0.1, 0.3, 0.7, 1.0)
    tint = nt.nodes.new("ShaderNodeOutputAOV")
    tint.aov_name = "tint"
    nt.links.new(tex.outputs["Color"], tint.inputs["Color"])
    fac = nt.nodes.new("ShaderNodeOutputAOV")
    fac.aov_name = "fac"
    nt.links.new(tex.outputs["Fac"], fac.inputs["Value"])
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.2, 0.8, 0.5))
    vl = scene.view_layers[0]
    for name, kind in (("tint", "COLOR"), ("fac", "VALUE")):
        aov = vl.aovs.add()
        aov.name, aov.type = name, kind
    scene.render.engine = engine
    scene.cycles.samples = scene.drt.samples = 16
    return scene


def _blocks(img, size=8):
    h, w = img.shape[:2]
    return img.reshape(h // size, size, w // size, size, -1).mean(axis=(1, 3))


@pytest.mark.parametrize("name", ["tint", "fac"])
def test_aov_pass_matches_cycles(bpy_drt, name):
    bpy = bpy_drt
    out = {}
    for engine in ("CYCLES", "DRT"):
        scene = _scene(bpy, engine)
        composite(bpy, scene, name)
        render_current(bpy, scene)
        out[engine] = read_render_rgba(bpy, scene).reshape(H, W, 4)
    cycles, drt = out["CYCLES"], out["DRT"]
    channels = 4 if name == "tint" else 3
    c, d = cycles[..., :channels], drt[..., :channels]
    assert _blocks(c[..., :3]).std(axis=(0, 1)).max() > 0.05       # the checker shows
    assert (c[..., :3] < 1e-6).all(axis=2).sum() > 20               # the cube: 0
    diff = np.abs(_blocks(d - c)).max()
    uniform = np.abs(_blocks(np.broadcast_to(c.mean(axis=(0, 1)), c.shape) - c)).max()
    print(f"AOV {name}: worst block {diff:.4f} (a uniform pass: {uniform:.4f}); "
          f"alpha Cycles {cycles[..., 3].min():.3f}..{cycles[..., 3].max():.3f}, "
          f"DRT {drt[..., 3].min():.3f}..{drt[..., 3].max():.3f}")
    assert diff < 0.02 and uniform > 0.05


def test_a_material_without_aov_nodes_exports_none(bpy_drt):
    from drt_addon.export.errors import Reporter
    from drt_addon.export.materials import export_material
    bpy = bpy_drt
    _scene(bpy, "DRT")
    plain = export_material(bpy.data.materials.new("Plain"), Reporter())
    assert plain.aovs is None
    base = export_material(bpy.data.materials["Base"], Reporter())
    assert set(base.aovs.outputs) == {"tint", "fac"}
