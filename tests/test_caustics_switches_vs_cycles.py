"""Light Paths > Caustics, against Cycles: what the switches take away after a diffuse
bounce, and what they leave.

Cycles (kernel/svm/closure.h) drops a hit's glossy microfacet closures when Reflective
Caustics is off, and its refraction closures when Refractive Caustics is off, on rays
that left a diffuse surface; a Translucent BSDF is a diffuse closure and stays (as do
sheen and the hair closures). The scene: test_shadow_ray_glass_vs_cycles' room, its
window a white Translucent BSDF, seen from inside towards the back wall, lit only by a
uniform white world (which Cycles never samples as a light: only rays leaving through
the window find it). Every path that lights the room passes the window after a diffuse
bounce. 64 x 64, DRT 256 samples against Cycles 512."""
from __future__ import annotations

from node_probe import drt_against_cycles, image_errors, new_material, render
from test_shadow_ray_glass_vs_cycles import _room

DRT_SAMPLES = 256
CYCLES_SAMPLES = 512


def _translucent_window_room(bpy):
    scene = _room(bpy)
    bpy.data.objects.remove(bpy.data.objects["Sun"])
    mat, nt = new_material(bpy, "Paper")
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    node = nt.nodes.new("ShaderNodeBsdfTranslucent")
    nt.links.new(node.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    window = bpy.data.objects["Plane"]
    window.data.materials.clear()
    window.data.materials.append(mat)
    scene.camera.location = (0.0, 1.8, 0.0)
    scene.camera.rotation_euler = (1.5708, 0.0, 3.14159)
    scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    scene.cycles.caustics_refractive = False
    return scene


def test_translucency_stays_with_refractive_caustics_off(bpy_drt):
    """Measured: mean 0.13 %, largest block 1.9 %. Before (DRT dropped the Translucent
    BSDF with the refraction lobes): mean 92 %, the room nearly black."""
    bpy = bpy_drt
    scene = _translucent_window_room(bpy)
    cycles = render(bpy, scene, "CYCLES", CYCLES_SAMPLES)
    drt = render(bpy, scene, "DRT", DRT_SAMPLES)
    mean, block = image_errors(drt, cycles)
    print(f"translucent window, refractive caustics off: mean {mean:.2%}, "
          f"largest block {block:.2%}")
    assert mean < 0.01 and block < 0.04, (mean, block)


def _floor_behind_translucent_sheet(bpy):
    """A white Translucent BSDF sheet (2 m) seen from above by an orthographic camera, a
    floor 1 m below it under a sun; the floor's Diffuse BSDF colour is Light Path's
    (Is Diffuse Ray, Is Transmission Ray, 0.5), so what the camera sees of the floor
    through the sheet shows the kind of ray the translucent bounce sends."""
    from node_probe import new_scene, sun_and_top_camera
    scene = new_scene(bpy, 48)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    sheet = bpy.context.object
    mat, nt = new_material(bpy, "Sheet")
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    node = nt.nodes.new("ShaderNodeBsdfTranslucent")
    nt.links.new(node.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    sheet.data.materials.append(mat)
    bpy.ops.mesh.primitive_plane_add(size=40.0, location=(0.0, 0.0, -1.0))
    floor = bpy.context.object
    mat, nt = new_material(bpy, "Floor")
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    path = nt.nodes.new("ShaderNodeLightPath")
    colour = nt.nodes.new("ShaderNodeCombineColor")
    colour.inputs["Blue"].default_value = 0.5
    nt.links.new(path.outputs["Is Diffuse Ray"], colour.inputs["Red"])
    nt.links.new(path.outputs["Is Transmission Ray"], colour.inputs["Green"])
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    nt.links.new(colour.outputs[0], diffuse.inputs["Color"])
    nt.links.new(diffuse.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    floor.data.materials.append(mat)
    sun_and_top_camera(bpy, scene, (0.5, 0.0, 0.3), 0.05, 2.2, 3.0)
    return scene


def test_a_translucent_bounce_sends_a_diffuse_and_transmission_ray(bpy_drt):
    """Cycles labels a Translucent BSDF's bounce diffuse transmission: the ray it sends
    is a diffuse ray and a transmission ray at once (Light Path's Is Diffuse Ray and Is
    Transmission Ray are both 1 where it lands, a Caustics switch treats it as having
    left a diffuse surface, and objects and lamps visible to either kind see it).
    Measured: mean 0.10 %, largest block 0.96 %. Before (a transmission ray only): the
    floor seen through the sheet had no red, mean 38 %, largest block 53 %."""
    scene = _floor_behind_translucent_sheet(bpy_drt)
    mean, block = drt_against_cycles(bpy_drt, scene, DRT_SAMPLES, CYCLES_SAMPLES)
    print(f"floor through a translucent sheet: mean {mean:.2%}, largest block {block:.2%}")
    assert mean < 0.01 and block < 0.04, (mean, block)
