"""The Hair BSDF node against Cycles, on strands and on meshes, at Blender's defaults.

The scene: a sphere with 300 particle hairs whose material mixes the node's Reflection
(brown, Offset 2 degrees, RoughnessU 0.2) and Transmission (orange, RoughnessV 0.7)
components half and half; a smooth cylinder with the node's Reflection alone at its
defaults (RoughnessU 0.1, V 1.0, as the public file Untid.blend has it: on a mesh
Cycles shades it about each triangle's second edge and drops the Offset); and a sphere
mixing the Hair BSDF's Reflection with a Diffuse BSDF, on the grey floor under a point
lamp and a dim world. Means within 2 % per channel and 8 x 8 blocks within 5 % of the
image mean (the other comparisons' tolerances). The control, the three Hair BSDFs
replaced by Diffuse BSDFs of their colours (DRT's fallback before it rendered the node),
must fail that.
"""
from __future__ import annotations

import math

import numpy as np

from conftest import as_diffuse, grey_room, render_current, use_engine
from test_multiscatter_vs_cycles import assert_matches, compare


def _hair_node(nt, component, color, offset=0.0, ru=0.1, rv=1.0):
    node = nt.nodes.new("ShaderNodeBsdfHair")
    node.component = component
    node.inputs["Color"].default_value = (*color, 1.0)
    node.inputs["Offset"].default_value = offset
    node.inputs["RoughnessU"].default_value = ru
    node.inputs["RoughnessV"].default_value = rv
    return node


def _material(bpy, name, *closures):
    """A material whose output is the closures mixed half and half (one: itself)."""
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    out = nt.nodes["Material Output"]
    nodes = [make(nt) for make in closures]
    if len(nodes) == 1:
        nt.links.new(nodes[0].outputs[0], out.inputs["Surface"])
    else:
        mix = nt.nodes.new("ShaderNodeMixShader")
        mix.inputs["Fac"].default_value = 0.5
        nt.links.new(nodes[0].outputs[0], mix.inputs[1])
        nt.links.new(nodes[1].outputs[0], mix.inputs[2])
        nt.links.new(mix.outputs[0], out.inputs["Surface"])
    return mat


def _diffuse(color):
    def make(nt):
        node = nt.nodes.new("ShaderNodeBsdfDiffuse")
        node.inputs["Color"].default_value = (*color, 1.0)
        return node
    return make


def _hair(component, color, **kw):
    return lambda nt: _hair_node(nt, component, color, **kw)


def _scene(bpy):
    scene = grey_room(bpy, (64, 48), 0.5, world=0.05)
    # particle hair: Reflection and Transmission, half and half
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.35, location=(-0.75, 0.0, 0.45),
                                         segments=32, ring_count=16)
    bpy.ops.object.shade_smooth()
    ball = bpy.context.object
    skin = bpy.data.materials.new("skin")
    skin.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (
        0.3, 0.2, 0.15, 1.0)
    ball.data.materials.append(skin)
    ball.data.materials.append(_material(
        bpy, "fur", _hair("Reflection", (0.45, 0.3, 0.15), offset=math.radians(2.0),
                          ru=0.2),
        _hair("Transmission", (0.9, 0.5, 0.2), rv=0.7)))
    mod = ball.modifiers.new("Fur", "PARTICLE_SYSTEM")
    st = mod.particle_system.settings
    st.type, st.count, st.hair_length = "HAIR", 300, 0.35
    st.material = 2
    # a mesh with the node's Reflection at its defaults (Untid.blend's)
    bpy.ops.mesh.primitive_cylinder_add(radius=0.3, depth=0.9, location=(0.05, 0.2, 0.45))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(
        _material(bpy, "blue hair", _hair("Reflection", (0.05, 0.18, 1.0))))
    # a mesh mixing it with a Diffuse BSDF
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.3, location=(0.8, -0.1, 0.3),
                                         segments=32, ring_count=16)
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(
        _material(bpy, "sheeny", _hair("Reflection", (0.9, 0.9, 0.9), ru=0.3),
                  _diffuse((0.6, 0.1, 0.1))))
    bpy.ops.object.light_add(type="POINT", location=(1.0, -1.5, 2.5))
    bpy.context.object.data.energy = 300.0
    bpy.context.object.data.shadow_soft_size = 0.3
    bpy.ops.object.camera_add(location=(0.0, -4.0, 1.2), rotation=(math.radians(82), 0, 0))
    scene.camera = bpy.context.object
    return scene


def _as_diffuse(bpy):
    """Every Hair BSDF replaced by a Diffuse BSDF of its colour, in place."""
    as_diffuse(bpy, "ShaderNodeBsdfHair",
               lambda mat, node: tuple(node.inputs["Color"].default_value))


def test_hair_bsdf_on_strands_and_meshes_matches_cycles(bpy_drt):
    bpy = bpy_drt
    scene = _scene(bpy)
    # 1024 and 512 samples: at 256 DRT's worst block alone is 1.1 % to 4.0 % off a
    # 4096-sample Cycles image over six seeds, too close to the 5 % asked of the pair
    use_engine(scene, "CYCLES", 1024)
    cycles = render_current(bpy, scene)
    use_engine(scene, "DRT", 512)
    drt = render_current(bpy, scene)
    from drt_addon import render_engine
    assert not any("Hair BSDF" in w for w in render_engine.last_render["warnings"]), \
        render_engine.last_render["warnings"]
    assert_matches(drt, cycles, 0.02, 0.05)
    _as_diffuse(bpy)
    use_engine(scene, "DRT", 64)
    control = render_current(bpy, scene)
    rel, block = compare(control, cycles)
    print(f"control, Diffuse BSDFs: mean {np.round(100 * rel, 2)} %, "
          f"worst block {100 * block:.2f} %")
    assert block > 0.05, block


def test_hair_bsdf_export(bpy_drt):
    """The node's components as the tracer gets them: colours (a Mix Shader's weight
    included), roughness, Offset; a linked Tangent reported."""
    bpy = bpy_drt
    scene = _scene(bpy)
    use_engine(scene, "DRT", 4)
    from drt_addon.export import Reporter, export_scene
    reporter = Reporter()
    s = export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    mats = {m.name: m for m in s.materials}
    fur, blue, sheeny = mats["fur"], mats["blue hair"], mats["sheeny"]
    np.testing.assert_allclose(fur.hair_reflection, (0.225, 0.15, 0.075))
    np.testing.assert_allclose(fur.hair_transmission, (0.45, 0.25, 0.1))
    np.testing.assert_allclose(fur.hair_reflection_roughness, (0.2, 1.0), rtol=1e-6)
    np.testing.assert_allclose(fur.hair_transmission_roughness, (0.1, 0.7), rtol=1e-6)
    assert math.isclose(fur.hair_reflection_offset, math.radians(2.0), rel_tol=1e-6)
    assert max(fur.base_color) == 0.0 and fur.specular_ior_level == 0.0
    np.testing.assert_allclose(blue.hair_reflection, (0.05, 0.18, 1.0), rtol=1e-6)
    assert blue.hair_transmission == (0.0, 0.0, 0.0)
    np.testing.assert_allclose(sheeny.hair_reflection, (0.45, 0.45, 0.45), rtol=1e-6)
    np.testing.assert_allclose(sheeny.base_color, (0.3, 0.05, 0.05), rtol=1e-6)  # x 0.5
    assert not reporter.warnings, reporter.warnings
    nt = bpy.data.materials["blue hair"].node_tree
    tangent = nt.nodes.new("ShaderNodeTangent")
    nt.links.new(tangent.outputs[0], nt.nodes["Hair BSDF"].inputs["Tangent"])
    reporter = Reporter()
    export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    assert any("Tangent" in w and "Hair BSDF" in w for w in reporter.warnings), \
        reporter.warnings
