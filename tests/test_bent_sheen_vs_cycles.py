"""The Principled sheen where the shading normal is bent, against Cycles at its defaults.

Cycles keeps its sheen closure on the node's own normal (the Normal Map's, or a smooth
mesh's; svm/closure.h), as its diffuse closure, where its microfacet lobes take the valid
reflection normal; a sheen is a diffuse-kind closure, so lights see it with the bump
shadowing against the surface's own shading normal (closure/bsdf.h). DRT read the sheen
towards lights at the normal's own direction wherever the frame was bent (every hit of a
Normal Map), and set it up and sampled it about the bent frame: a dark fabric with a
far-leaning normal map rendered 37 % too dark (its sheen at a fifth of Cycles'), with a
moderate one 1.1 %. Now the sheen is set up, evaluated and sampled about the raw normal
(principled.setup_about)."""
from __future__ import annotations

import math

import pytest

import node_probe
from node_probe import drt_against_cycles, new_material, new_scene

SUN_ANGLE = math.radians(0.526)       # a new sun lamp's angular diameter in Blender


def _fabric(bpy, normal_colour):
    """A dark Principled fabric with a full white sheen (roughness 0.5), its Normal
    from a Normal Map of a constant colour (None: no map)."""
    mat, nt = new_material(bpy, "Fabric")
    p = nt.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (0.05, 0.02, 0.1, 1.0)
    p.inputs["Sheen Weight"].default_value = 1.0
    p.inputs["Sheen Roughness"].default_value = 0.5
    p.inputs["Sheen Tint"].default_value = (1.0, 1.0, 1.0, 1.0)
    if normal_colour is not None:
        colour = nt.nodes.new("ShaderNodeRGB")
        colour.outputs[0].default_value = normal_colour + (1.0,)
        nmap = nt.nodes.new("ShaderNodeNormalMap")
        nt.links.new(colour.outputs[0], nmap.inputs["Color"])
        nt.links.new(nmap.outputs["Normal"], p.inputs["Normal"])
    return mat


def _cloth_scene(bpy, normal_colour):
    """A tilted square of the fabric under a sun and a dim world, seen from above."""
    scene = node_probe.tilted_square(bpy, lambda: _fabric(bpy, normal_colour), 0.3)
    node_probe.sun_and_camera(bpy, scene, 3.0, SUN_ANGLE,
                              (math.radians(40.0), math.radians(20.0), 0.0),
                              (0.0, -1.0, 3.0), (math.radians(20.0), 0.0, 0.0))
    return scene


def _cushion_scene(bpy):
    """A smooth low-poly sphere (16 x 8) of the fabric without a map, lit from the side
    and behind, whose silhouettes bend the frame to the valid reflection normal."""
    scene = new_scene(bpy, 64)
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.3
    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8, radius=1.0)
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(_fabric(bpy, None))
    node_probe.sun_and_camera(bpy, scene, 3.0, SUN_ANGLE,
                              (math.radians(100.0), 0.0, math.radians(150.0)),
                              (0.0, -3.2, 0.0), (math.radians(90.0), 0.0, 0.0))
    return scene


# (scene, samples): the cushion's rim light needs more samples for its blocks
CASES = {
    "far_leaning_map": (lambda bpy: _cloth_scene(bpy, (1.0, 0.2, 0.7)), 128),
    "moderate_map": (lambda bpy: _cloth_scene(bpy, (0.75, 0.4, 0.8)), 128),
    "smooth_silhouettes": (_cushion_scene, 1024),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_sheen_on_a_bent_normal_matches_cycles(bpy_drt, case):
    """DRT against Cycles at equal samples (128, the cushion 1024): mean within 1 %,
    largest 8 x 8 block within 5 %. Measured: far-leaning map 0.00 % and 0.16 %,
    moderate map 0.00 % and 0.14 %, smooth silhouettes 0.06 % and 1.48 %. Before (the
    sheen read at the normal towards lights, set up on the bent frame): 37.3 % and
    83.9 %, 1.06 % and 3.15 %, 11.5 % and 230 %."""
    build, samples = CASES[case]
    mean, block = drt_against_cycles(bpy_drt, build(bpy_drt), samples)
    print(f"{case}: mean {mean:.2%}, largest block {block:.2%}")
    assert mean < 0.01 and block < 0.05, (mean, block)
