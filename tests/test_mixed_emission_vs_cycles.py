"""A Mix Shader whose Fac varies over the surface, mixing a BSDF with an Emission: Cycles
weighs the emission at each hit by that hit's Fac (svm_node_mix_closure), so a texture
or a Layer Weight on the Fac draws the light. DRT shades each hit by one side picked
with the Fac's probability, and its emission is the mix at the hit's own Fac
(export/nodes/shader_mix.per_hit_emission); before that it was the mix at the Fac's
average over the surface, which is what a public neon sign (mpett/blends neon.blend:
Mix(Fac = a constant Color Ramp of a Gradient Texture; Principled, Emission + Glossy))
showed: its letters at half their brightness (0.50 of Cycles' light over them). The
other two tests: such emission is light-sampled as Cycles samples it, evaluated where a
sample lands (engine.kernels.shaded_emitter), and a value linked straight into a shader
socket emits (Cycles' automatic conversion to an Emission).

The scene, as an artist builds a neon sign: a striped panel (Mix Fac = a Color Ramp,
white - black - white, of a Gradient Texture of Generated coordinates: Emission on
average on 70 % of it, a dark Principled between) and a smooth tube whose emission
follows Layer Weight > Facing (brighter towards its silhouette), over a grey floor they light, in a dim world. The
panel's Emission Strength grows with its height (an Emission's Strength was read as its
average before, with a warning).

Measured (256 samples each; mean, largest 8 x 8 block): 0.10 %, 1.07 %; the panel's
Strength at its average 0.88 %, 389 %; and its Fac at its average too 1.06 %, 536 %;
before the fix 2.14 %, 536 %. With the fix but the panel and tube found by BSDF rays
alone (before engine.kernels.shaded_emitter light-sampled them) 0.00 %, 1.91 %, the
tube's block 2.2 % dark even at 1024 samples: see the second test."""
from __future__ import annotations

import math

import node_probe
from figures import AGAINST_CYCLES, record
from node_probe import image_errors, new_material, new_scene

SAMPLES = 256
TUBE_SAMPLES = 1024      # the tube alone: a 1 % difference, read over its pixels
PANEL_STRENGTH = 6.0     # the panel's average Emission Strength
STRIPE_SHARE = 0.7       # the panel's average Fac (the Color Ramp's white and its ramps)


def _panel_material(bpy):
    mat, nt = new_material(bpy, "stripes")
    nodes, links = nt.nodes, nt.links
    coords = nodes.new("ShaderNodeTexCoord")
    gradient = nodes.new("ShaderNodeTexGradient")
    ramp = nodes.new("ShaderNodeValToRGB")
    e = ramp.color_ramp.elements
    e[0].position, e[0].color = 0.0, (1.0, 1.0, 1.0, 1.0)
    e[1].position, e[1].color = 0.3, (0.0, 0.0, 0.0, 1.0)
    e.new(0.6).color = (1.0, 1.0, 1.0, 1.0)
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (1.0, 0.35, 0.08, 1.0)
    # its Strength grows with height: Generated Y (up the panel) x 12, 6 on average
    height = nodes.new("ShaderNodeSeparateXYZ")
    strength = nodes.new("ShaderNodeMath")
    strength.operation = "MULTIPLY"
    strength.inputs[1].default_value = 2.0 * PANEL_STRENGTH
    links.new(coords.outputs["Generated"], height.inputs["Vector"])
    links.new(height.outputs["Y"], strength.inputs[0])
    links.new(strength.outputs["Value"], emission.inputs["Strength"])
    mix = nodes.new("ShaderNodeMixShader")
    links.new(coords.outputs["Generated"], gradient.inputs["Vector"])
    links.new(gradient.outputs["Fac"], ramp.inputs["Fac"])
    links.new(ramp.outputs["Color"], mix.inputs["Fac"])
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.05, 0.05, 0.05, 1.0)
    links.new(bsdf.outputs["BSDF"], mix.inputs[1])
    links.new(emission.outputs["Emission"], mix.inputs[2])
    links.new(mix.outputs["Shader"], nodes["Material Output"].inputs["Surface"])
    return mat


def _tube_material(bpy):
    mat, nt = new_material(bpy, "tube")
    nodes, links = nt.nodes, nt.links
    facing = nodes.new("ShaderNodeLayerWeight")
    facing.inputs["Blend"].default_value = 0.3
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (0.1, 0.3, 1.0, 1.0)
    emission.inputs["Strength"].default_value = 10.0
    mix = nodes.new("ShaderNodeMixShader")
    links.new(facing.outputs["Facing"], mix.inputs["Fac"])
    links.new(nodes["Principled BSDF"].outputs["BSDF"], mix.inputs[1])
    links.new(emission.outputs["Emission"], mix.inputs[2])
    links.new(mix.outputs["Shader"], nodes["Material Output"].inputs["Surface"])
    return mat


def _neon_scene(bpy):
    scene = new_scene(bpy, 64)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.05
    bpy.ops.mesh.primitive_plane_add(size=8.0)
    floor = bpy.context.object
    floor.data.materials.append(new_material(bpy, "floor")[0])
    bpy.ops.mesh.primitive_plane_add(size=1.6, location=(-0.6, 0.5, 1.0),
                                     rotation=(math.radians(90.0), 0.0, 0.0))
    bpy.context.object.data.materials.append(_panel_material(bpy))
    bpy.ops.mesh.primitive_cylinder_add(radius=0.12, depth=1.6, location=(1.0, 0.0, 0.9))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(_tube_material(bpy))
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location, cam.rotation_euler = (0.0, -5.0, 2.2), (math.radians(72.0), 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene


def test_per_hit_mix_emission_matches_cycles(bpy_drt):
    """Measured (256 samples each; mean, largest 8 x 8 block): see the print. Two
    controls render what DRT rendered before, and must fail: the panel's Fac at its
    average (the emission of a per-hit Mix), and its Strength at its average (an
    Emission's Strength was read as its average, with a warning)."""
    bpy = bpy_drt
    scene = _neon_scene(bpy)
    cycles = node_probe.render(bpy, scene, "CYCLES", SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", SAMPLES)
    mean, block = image_errors(drt, cycles)
    nt = bpy.data.materials["stripes"].node_tree
    emission = nt.nodes["Emission"]
    nt.links.remove(emission.inputs["Strength"].links[0])
    emission.inputs["Strength"].default_value = PANEL_STRENGTH
    flat = image_errors(node_probe.render(bpy, scene, "DRT", SAMPLES), cycles,
                        "control: the panel's Strength at its average")
    mix = nt.nodes["Mix Shader"]
    nt.links.remove(mix.inputs["Fac"].links[0])
    mix.inputs["Fac"].default_value = STRIPE_SHARE
    control = image_errors(node_probe.render(bpy, scene, "DRT", SAMPLES), cycles,
                           "control: and its Fac at its average")
    print(f"mean {mean:.2%}, largest block {block:.2%}; Strength at its average: "
          f"{flat[0]:.2%}, {flat[1]:.2%}; and Fac: {control[0]:.2%}, {control[1]:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)
    assert flat[1] > 0.1 and control[1] > 0.1, (flat, control)


def test_varying_emission_is_light_sampled_as_cycles_samples_it(bpy_drt):
    """The tube alone in a black world: its grey Principled side is lit by nothing but
    the tube itself, through its smooth normals, from faces whose planes it lies behind:
    light that only next-event estimation finds (BSDF rays below a face's geometric
    normal are refused, in both engines). Cycles light-samples the tube, evaluating its
    Layer Weight at each sampled point, and so must DRT (engine.kernels.shaded_emitter);
    the control is DRT with the tube's Emission Sampling at None (what DRT did before
    for an emission that varies per hit: BSDF rays alone), which falls short.
    Measured (1024 samples each, the tube's 154 bright pixels): DRT / Cycles 0.9999;
    control 0.9893."""
    bpy = bpy_drt
    scene = _neon_scene(bpy)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    for name in ("Plane", "Plane.001"):
        bpy.data.objects[name].hide_render = True
    cycles = node_probe.render(bpy, scene, "CYCLES", TUBE_SAMPLES)[..., :3]
    drt = node_probe.render(bpy, scene, "DRT", TUBE_SAMPLES)[..., :3]
    bpy.data.materials["tube"].cycles.emission_sampling = "NONE"
    control = node_probe.render(bpy, scene, "DRT", TUBE_SAMPLES)[..., :3]
    tube = cycles[..., 2] > 0.3
    ratio = float(drt[tube].mean() / cycles[tube].mean())
    unsampled = float(control[tube].mean() / cycles[tube].mean())
    print(f"{tube.sum()} tube pixels: DRT / Cycles {ratio:.4f}; not light-sampled "
          f"{unsampled:.4f}")
    record(AGAINST_CYCLES, tube_ratio=ratio)
    record("control: not light-sampled", tube_ratio=unsampled)
    assert tube.sum() > 80
    assert abs(ratio - 1.0) < 0.004, ratio
    assert unsampled < 0.995, unsampled


def test_a_value_linked_into_a_shader_socket_emits_as_in_cycles(bpy_drt):
    """A colour or a float linked straight into a shader socket, which Blender allows:
    Cycles turns it into an Emission of strength 1, the float into its Strength
    (ShaderGraph::connect). The panel's Surface is its Color Ramp's colour; the tube's
    Mix Shader takes its Layer Weight's Facing as its second shader. Control: the panel's
    colour on a Diffuse BSDF instead (DRT rendered such a link as a diffuse surface of
    the material's viewport colour before). Measured (256 samples each): mean 0.04 %,
    largest block 1.37 %; control 95 %, 728 %; before the change 98 %, 731 %."""
    bpy = bpy_drt
    scene = _neon_scene(bpy)
    panel = bpy.data.materials["stripes"].node_tree
    out = panel.nodes["Material Output"].inputs["Surface"]
    ramp = next(n for n in panel.nodes if n.bl_idname == "ShaderNodeValToRGB")
    panel.links.new(ramp.outputs["Color"], out)
    tube = bpy.data.materials["tube"].node_tree
    tube.links.new(tube.nodes["Layer Weight"].outputs["Facing"],
                   tube.nodes["Mix Shader"].inputs[2])
    cycles = node_probe.render(bpy, scene, "CYCLES", SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", SAMPLES)
    mean, block = image_errors(drt, cycles)
    diffuse = panel.nodes.new("ShaderNodeBsdfDiffuse")
    panel.links.new(ramp.outputs["Color"], diffuse.inputs["Color"])
    panel.links.new(diffuse.outputs["BSDF"], out)
    control = image_errors(node_probe.render(bpy, scene, "DRT", SAMPLES), cycles,
                           "control: the colour on a Diffuse BSDF")
    print(f"mean {mean:.2%}, largest block {block:.2%}; control {control[0]:.2%}, "
          f"{control[1]:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)
    assert control[1] > 0.1, control
