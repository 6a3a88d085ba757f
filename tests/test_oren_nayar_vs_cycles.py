"""Diffuse roughness against Cycles at its defaults: a Diffuse BSDF with Roughness 1 (a
clay-orange sphere), a Principled BSDF with Diffuse Roughness 0.8 (a blue sphere, its
specular layer and Roughness at Blender's defaults) and a floor of a Diffuse BSDF at
Roughness 0.5, lit by a sun from over the camera's shoulder (where rough diffuse
surfaces look flat: their rims stay bright) and a dim world, 96 x 64. DRT 128 samples
against Cycles 256; means within 1 %, every 8 x 8 block within 3 % of the image mean.
The control, the same scene with every roughness 0 in DRT alone (Lambert, what DRT
rendered before), fails. The lobe itself: tests/test_oren_nayar.py."""
from __future__ import annotations

import node_probe
from node_probe import image_errors, new_material, new_scene

DRT_SAMPLES = 128
CYCLES_SAMPLES = 256


def _diffuse_material(bpy, obj, name, color, roughness):
    """A material of one Diffuse BSDF, given to `obj`."""
    mat, nt = new_material(bpy, name)
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = color
    diffuse.inputs["Roughness"].default_value = roughness
    nt.links.new(diffuse.outputs["BSDF"], nt.nodes["Material Output"].inputs["Surface"])
    obj.data.materials.append(mat)


def _scene(bpy):
    scene = new_scene(bpy, 96)
    scene.render.resolution_y = 64
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.15
    bpy.ops.mesh.primitive_plane_add(size=12.0)
    _diffuse_material(bpy, bpy.context.object, "Floor", (0.5, 0.5, 0.45, 1.0), 0.5)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=(-1.2, 0.0, 1.0))
    bpy.ops.object.shade_smooth()
    _diffuse_material(bpy, bpy.context.object, "Clay", (0.8, 0.35, 0.15, 1.0), 1.0)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=(1.2, 0.0, 1.0))
    bpy.ops.object.shade_smooth()
    blue = bpy.context.object
    mat, nt = new_material(bpy, "Blue")
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.15, 0.3, 0.8, 1.0)
    bsdf.inputs["Diffuse Roughness"].default_value = 0.8
    blue.data.materials.append(mat)
    node_probe.sun_and_camera(bpy, scene, 3.0, 0.05, (0.9, 0.0, -0.35),
                              (0.0, -6.5, 2.6), (1.25, 0.0, 0.0))
    return scene


def _set_roughness(bpy, value):
    for m in bpy.data.materials:
        for n in m.node_tree.nodes:
            if n.bl_idname == "ShaderNodeBsdfDiffuse":
                n.inputs["Roughness"].default_value = value
            elif n.bl_idname == "ShaderNodeBsdfPrincipled":
                n.inputs["Diffuse Roughness"].default_value = value


def test_rough_diffuse_surfaces_match_cycles(bpy_drt):
    bpy = bpy_drt
    scene = _scene(bpy)
    cycles = node_probe.render(bpy, scene, "CYCLES", CYCLES_SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", DRT_SAMPLES)
    mean, block = image_errors(drt, cycles)
    _set_roughness(bpy, 0.0)
    control = image_errors(node_probe.render(bpy, scene, "DRT", DRT_SAMPLES), cycles,
                           "control: Lambert (roughness 0)")
    print(f"diffuse roughness: mean {mean:.2%}, largest block {block:.2%}; Lambert: mean "
          f"{control[0]:.2%}, largest block {control[1]:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)
    assert control[1] > 0.06, control


def test_diffuse_roughness_is_exported_without_a_warning(bpy_drt):
    """The Diffuse BSDF's Roughness and the Principled BSDF's Diffuse Roughness reach the
    materials (0 stays Lambert), and no warning says they are left out."""
    bpy = bpy_drt
    from drt_addon.export import Reporter, export_scene
    _scene(bpy)
    reporter = Reporter()
    exported = export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    rough = {m.name: m.diffuse_roughness for m in exported.materials}
    assert rough["Clay"] == 1.0 and rough["Floor"] == 0.5
    assert abs(rough["Blue"] - 0.8) < 1e-6
    assert not any("rough" in w.lower() for w in reporter.warnings), reporter.warnings
