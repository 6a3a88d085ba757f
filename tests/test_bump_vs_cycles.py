"""The Bump node and the Light Path depths in lit scenes, against Cycles at its defaults
(the node-by-node emission comparisons are in test_nodes_vs_cycles.py).

Bump: a diffuse and glossy Principled floor whose Normal is a Bump of a Noise texture,
under a sun and a dim world, seen by a perspective camera (the bump's offsets follow each
camera ray's footprint, growing with distance). The image and its 8 x 8 blocks agree
with Cycles; without the bump (its Height unlinked) the blocks do not.

Bent sphere: a smooth sphere whose normal is bent by a Normal Map (a diffuse one,
every normal tilted by about 40 degrees) or by a Bump of a noise (a glossy plastic),
under a low sun. Its light falls off towards the surface's own terminator as Cycles
5.0's bump shadowing term has it (a GGX shadowing of the light's angle to the smooth
normal, with a roughness from the bend), not the bent normal's.

Depths: a mirror tilted 45 degrees shows a diffuse wall, partly through a pane that is
fully transparent (Alpha 0) and partly through a thin pane of glass; the wall's colour is
(Glossy Depth, Transparent Depth, Transmission Depth) / 2, so each region of the image is
a different mix. With the depths unlinked the colour is the sockets' own value and the
comparison fails."""
from __future__ import annotations

import pytest

import node_probe
from node_probe import image_errors, new_material, new_scene

BUMP_SAMPLES = 256
DEPTH_SAMPLES = 64
SPHERE_SAMPLES = 64


def _bump_scene(bpy):
    scene = new_scene(bpy)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.1
    bpy.ops.mesh.primitive_plane_add(size=12.0)
    floor = bpy.context.object
    mat, nt = new_material(bpy, "Bumpy")
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.7, 0.5, 0.3, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.3
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 2.0
    coords = nt.nodes.new("ShaderNodeTexCoord")
    nt.links.new(coords.outputs["Object"], noise.inputs["Vector"])
    bump = nt.nodes.new("ShaderNodeBump")
    bump.inputs["Distance"].default_value = 0.3
    nt.links.new(noise.outputs["Fac"], bump.inputs["Height"])
    nt.links.new(bump.outputs["Normal"], bsdf.inputs["Normal"])
    floor.data.materials.append(mat)
    node_probe.sun_and_camera(bpy, scene, 3.0, 0.05, (0.7, 0.3, 0.5), (0.0, -5.0, 3.5),
                              (0.98, 0.0, 0.0))
    return scene, nt, bump


def test_bump_lit_matches_cycles(bpy_drt):
    """Measured: mean 0.08%, largest block 0.17% of the image mean (0.7% and 1.2% with
    Cycles 3 and 4's bump shadowing term); flat: mean 5%, largest block 14%."""
    bpy = bpy_drt
    scene, nt, bump = _bump_scene(bpy)
    _matches_and_flat_does_not(bpy, scene, nt, bump.inputs["Height"], "bump lit")


def _matches_and_flat_does_not(bpy, scene, nt, socket, what):
    """DRT's render matches Cycles' (mean 1.5%, 8 x 8 blocks 3%), and with `socket`
    unlinked (a flat surface) its blocks differ by more than 10%."""
    cycles = node_probe.render(bpy, scene, "CYCLES", BUMP_SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", BUMP_SAMPLES)
    mean, block = image_errors(drt, cycles)
    print(f"{what}: mean {mean:.2%}, largest block {block:.2%}")
    for link in list(socket.links):
        nt.links.remove(link)
    flat_mean, flat_block = image_errors(node_probe.render(bpy, scene, "DRT", 64), cycles,
                                          "control: the bump unlinked")
    print(f"flat: mean {flat_mean:.2%}, largest block {flat_block:.2%}")
    assert mean < 0.015 and block < 0.03, (mean, block)
    assert flat_block > 0.1, flat_block


def test_displacement_in_bump_mode_matches_cycles(bpy_drt):
    """The same floor with the noise as the Material Output's Displacement (through a
    Displacement node, Scale 0.3) instead of a Bump on the BSDF: Cycles' default Bump
    Only mode bends the normal as a Bump of the displacement's height would. Without the
    displacement the blocks differ."""
    bpy = bpy_drt
    scene, nt, bump = _bump_scene(bpy)
    for link in list(bump.outputs["Normal"].links):
        nt.links.remove(link)
    disp = nt.nodes.new("ShaderNodeDisplacement")
    disp.inputs["Scale"].default_value = 0.3
    nt.links.new(bump.inputs["Height"].links[0].from_socket, disp.inputs["Height"])
    nt.links.new(disp.outputs["Displacement"],
                 nt.nodes["Material Output"].inputs["Displacement"])
    assert bpy.data.materials["Bumpy"].displacement_method == "BUMP"   # Blender's default
    _matches_and_flat_does_not(bpy, scene, nt, disp.outputs["Displacement"],
                               "displacement as bump")


def _bent_sphere(bpy, kind):
    """A smooth sphere under a low sun, its normal bent by a Normal Map ('normal_map': a
    diffuse Principled) or by a Bump of a Noise texture ('bump': a glossy plastic)."""
    scene, _, nt, bsdf = node_probe.smooth_sphere_scene(bpy, 64, 32, "Mapped")
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    if kind == "normal_map":
        bent = nt.nodes.new("ShaderNodeNormalMap")
        bent.inputs["Color"].default_value = (0.75, 0.5, 0.85, 1.0)
    else:
        bsdf.inputs["Specular IOR Level"].default_value = 0.5
        bsdf.inputs["Roughness"].default_value = 0.3
        noise = nt.nodes.new("ShaderNodeTexNoise")
        noise.inputs["Scale"].default_value = 3.0
        bent = nt.nodes.new("ShaderNodeBump")
        bent.inputs["Distance"].default_value = 0.2
        nt.links.new(noise.outputs["Fac"], bent.inputs["Height"])
    nt.links.new(bent.outputs["Normal"], bsdf.inputs["Normal"])
    node_probe.sun_and_top_camera(bpy, scene, (0.0, 1.1, 0.4), 0.01, 2.2, 10.0)
    return scene


@pytest.mark.parametrize("kind", ["normal_map", "bump"])
def test_bent_sphere_lit_matches_cycles(bpy_drt, kind):
    """Measured, of the image mean: normal map mean 0.02%, largest block 0.7%; bump mean
    0.09%, largest block 0.6%. With Cycles 3 and 4's bump shadowing term (Chiang et
    al.'s, which fades the light towards the bent normal's terminator): normal map mean
    7.2%, largest block 52%; bump mean 1.4%, largest block 7.3%. (On a coarser sphere,
    32 x 16 faces, the light by the terminator: test_terminator_vs_cycles.py.)"""
    bpy = bpy_drt
    scene = _bent_sphere(bpy, kind)
    cycles = node_probe.render(bpy, scene, "CYCLES", SPHERE_SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", SPHERE_SAMPLES)
    mean, block = image_errors(drt, cycles)
    print(f"{kind} sphere: mean {mean:.2%}, largest block {block:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)


@pytest.mark.parametrize("kind, corrected_limit", [("normal_map", 0.2), ("bump", 0.02)])
def test_bent_sphere_without_bump_map_correction_matches_cycles(bpy_drt, kind,
                                                                corrected_limit):
    """Material > Settings > Bump Map Correction off: Cycles lights the specular lobes by
    the bent normal as it is (not made a valid reflector for the view) and lets the
    diffuse light end abruptly at the smooth surface's terminator (no GGX fade).
    Measured, of the image mean: normal map mean 0.03%, largest block 0.7%; bump mean
    0.07%, largest block 0.6%. Correcting anyway (DRT before it read the setting):
    normal map mean 6.9%, largest block 43%; bump mean 0.5%, largest block 3.1%."""
    bpy = bpy_drt
    scene = _bent_sphere(bpy, kind)
    mat = bpy.data.materials["Mapped"]
    mat.cycles.use_bump_map_correction = False
    cycles = node_probe.render(bpy, scene, "CYCLES", SPHERE_SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", SPHERE_SAMPLES)
    mean, block = image_errors(drt, cycles)
    mat.cycles.use_bump_map_correction = True
    corrected = image_errors(node_probe.render(bpy, scene, "DRT", SPHERE_SAMPLES), cycles,
                             "control: with bump map correction")
    print(f"{kind} sphere, no correction: mean {mean:.2%}, largest block {block:.2%}; "
          f"corrected: mean {corrected[0]:.2%}, largest block {corrected[1]:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)
    assert corrected[1] > corrected_limit, corrected


def _pane(bpy, location, name):
    bpy.ops.mesh.primitive_plane_add(size=2.0, location=location, rotation=(1.5708, 0, 0))
    obj = bpy.context.object
    mat, nt = new_material(bpy, name)
    obj.data.materials.append(mat)
    return nt, nt.nodes["Principled BSDF"]


def _depth_scene(bpy):
    scene = new_scene(bpy, 32)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    # the mirror, tilted 45 degrees about x: the camera looking down sees along +y
    bpy.ops.mesh.primitive_plane_add(size=2.0, rotation=(-0.7854, 0.0, 0.0))
    mirror, nt = new_material(bpy, "Mirror")
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Metallic"].default_value = 1.0
    bsdf.inputs["Roughness"].default_value = 0.0
    bsdf.inputs["Base Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bpy.context.object.data.materials.append(mirror)
    # the wall the mirror shows, its colour made of the depths
    nt, bsdf = _pane(bpy, (0.0, 4.0, 0.0), "Wall")
    bpy.context.object.scale = (2.0, 2.0, 1.0)
    path = nt.nodes.new("ShaderNodeLightPath")
    combine = nt.nodes.new("ShaderNodeCombineColor")
    for k, name in enumerate(("Glossy Depth", "Transparent Depth", "Transmission Depth")):
        half = nt.nodes.new("ShaderNodeMath")
        half.operation = "MULTIPLY"
        half.inputs[1].default_value = 0.5
        nt.links.new(path.outputs[name], half.inputs[0])
        nt.links.new(half.outputs[0], combine.inputs[k])
    nt.links.new(combine.outputs[0], bsdf.inputs["Base Color"])
    # the left half of the wall behind a transparent pane, the right behind glass
    _, clear = _pane(bpy, (-0.6, 2.0, 0.0), "Clear")
    bpy.context.object.scale = (0.55, 1.0, 1.0)
    clear.inputs["Alpha"].default_value = 0.0
    _, glass = _pane(bpy, (0.6, 2.0, 0.0), "Glass")
    bpy.context.object.scale = (0.55, 1.0, 1.0)
    glass.inputs["Transmission Weight"].default_value = 1.0
    glass.inputs["IOR"].default_value = 1.0
    glass.inputs["Roughness"].default_value = 0.0
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type, cam.data.ortho_scale = "ORTHO", 1.6
    cam.location = (0.0, 0.0, 5.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene, path


def test_light_path_depths_lit_match_cycles(bpy_drt):
    """Measured: mean 0.1%, largest block 1% (depths unlinked: largest block 20%)."""
    bpy = bpy_drt
    scene, path = _depth_scene(bpy)
    cycles = node_probe.render(bpy, scene, "CYCLES", DEPTH_SAMPLES)
    drt = node_probe.render(bpy, scene, "DRT", DEPTH_SAMPLES)
    mean, block = image_errors(drt, cycles)
    print(f"depths: mean {mean:.2%}, largest block {block:.2%}")
    nt = bpy.data.materials["Wall"].node_tree
    for out in path.outputs:
        for link in list(out.links):
            nt.links.remove(link)
    unlinked = image_errors(node_probe.render(bpy, scene, "DRT", 16), cycles,
                            "control: the depths unlinked")[1]
    print(f"depths unlinked: largest block {unlinked:.2%}")
    assert mean < 0.02 and block < 0.05, (mean, block)
    assert unlinked > 0.1, unlinked
