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

from node_probe import image_errors, new_material, render
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
