"""Hair against Cycles: a mesh's particle hair and a hair Curves object (export.hair),
drawn as Cycles' default 3D curves, at Blender's defaults otherwise.

The scene: a sphere with 400 particle hairs 0.45 m long (Render Steps 3: 9 keys each;
Hair Shape at Blender's defaults: root 1, tip 0, Radius Scale 0.01, Close Tip: 1 cm
thick at the root) in a second material slot, coloured from root to tip by Curves Info >
Intercept, and a Curves object of six curling strands with a radius attribute, each its
own red by Curves Info > Random, on the grey floor under a point lamp and a dim world. Means
within 2 % per channel and 8 x 8 blocks within 5 % of the image mean (the tolerances of
the other comparisons). The control, View Layer > Filter > Curves off in DRT (no hair, as
before hair was drawn), must fail that. Measured numbers are in the test's output and
docs/hair.md.
"""
from __future__ import annotations

import math

import numpy as np

from conftest import grey_room, render_current, use_engine
from test_multiscatter_vs_cycles import assert_matches, compare


def _principled(bpy, name, color, roughness):
    mat = bpy.data.materials.new(name)
    p = mat.node_tree.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (*color, 1.0)
    p.inputs["Roughness"].default_value = roughness
    return mat


def _scene(bpy, hair=True):
    scene = grey_room(bpy, (64, 48), 0.5, world=0.05)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(-0.45, 0.0, 0.6),
                                         segments=32, ring_count=16)
    bpy.ops.object.shade_smooth()
    ball = bpy.context.object
    ball.data.materials.append(_principled(bpy, "skin", (0.8, 0.7, 0.6), 0.5))
    fur = _principled(bpy, "fur", (0.6, 0.25, 0.05), 0.4)
    ball.data.materials.append(fur)
    # the fur darkens from root to tip: Curves Info > Intercept through a Color Ramp
    nt = fur.node_tree
    info, ramp = nt.nodes.new("ShaderNodeHairInfo"), nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.9, 0.6, 0.3, 1.0)
    ramp.color_ramp.elements[1].color = (0.15, 0.05, 0.02, 1.0)
    nt.links.new(info.outputs["Intercept"], ramp.inputs["Fac"])
    nt.links.new(ramp.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    mod = ball.modifiers.new("Fur", "PARTICLE_SYSTEM")
    st = mod.particle_system.settings
    st.type, st.count, st.hair_length = "HAIR", 400, 0.45
    st.material = 2
    # Curves: six strands curling up from the floor, 0.03 m thick at the root
    curves = bpy.data.hair_curves.new("Curls")
    curves.add_curves([7] * 6)
    pos, radius = [], []
    for c in range(6):
        for k in range(7):
            a = 0.9 * k + c
            pos += [0.7 + 0.12 * math.cos(a) + 0.15 * (c - 2.5), -0.3 + 0.12 * math.sin(a),
                    0.15 * k]
            radius.append(0.015 * (1.0 - k / 7.0))
    curves.attributes["position"].data.foreach_set("vector", pos)
    curves.attributes.new("radius", "FLOAT", "POINT").data.foreach_set("value", radius)
    curls = bpy.data.objects.new("Curls", curves)
    curl = _principled(bpy, "curls", (0.1, 0.3, 0.7), 0.3)
    curls.data.materials.append(curl)
    # each curl its own red: Curves Info > Random
    nt = curl.node_tree
    info, rgb = nt.nodes.new("ShaderNodeHairInfo"), nt.nodes.new("ShaderNodeCombineColor")
    rgb.inputs["Green"].default_value, rgb.inputs["Blue"].default_value = 0.3, 0.7
    nt.links.new(info.outputs["Random"], rgb.inputs["Red"])
    nt.links.new(rgb.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    scene.collection.objects.link(curls)
    bpy.ops.object.light_add(type="POINT", location=(1.0, -1.5, 2.5))
    bpy.context.object.data.energy = 300.0
    bpy.context.object.data.shadow_soft_size = 0.3
    bpy.ops.object.camera_add(location=(0.0, -4.0, 1.2), rotation=(math.radians(82), 0, 0))
    scene.camera = bpy.context.object
    bpy.context.view_layer.use_strand = hair
    return scene


def _render(bpy, scene, engine, samples, hair=True):
    """The same scene with each engine (Blender distributes a new particle system's
    hair differently each time a scene is built, so both render one build)."""
    bpy.context.view_layer.use_strand = hair
    use_engine(scene, engine, samples)
    return render_current(bpy, scene)


def test_particle_hair_and_curves_match_cycles(bpy_drt):
    scene = _scene(bpy_drt)
    cycles = _render(bpy_drt, scene, "CYCLES", 512)
    drt = _render(bpy_drt, scene, "DRT", 256)
    assert_matches(drt, cycles, 0.02, 0.05)
    # F12 reads Render Steps: 2^3 + 1 keys a strand
    from drt_addon import render_engine
    fur = next(c for c in render_engine.last_render["scene"].curves
               if c.name.startswith("Sphere"))
    assert fur.curve_count == 400 and np.all(np.diff(fur.curve_keys) == 9)
    # the controls: no hair; the fur's colour not by Intercept (the ramp's middle)
    bald = _render(bpy_drt, scene, "DRT", 64, hair=False)
    rel, block = compare(bald, cycles)
    print(f"control, no hair: mean {np.round(100 * rel, 2)} %, "
          f"worst block {100 * block:.2f} %")
    assert block > 0.05, block
    nt = bpy_drt.data.materials["fur"].node_tree
    nt.links.remove(nt.nodes["Color Ramp"].inputs["Fac"].links[0])
    nt.nodes["Color Ramp"].inputs["Fac"].default_value = 0.5
    flat = _render(bpy_drt, scene, "DRT", 64)
    rel, block = compare(flat, cycles)
    print(f"control, no Intercept: mean {np.round(100 * rel, 2)} %, "
          f"worst block {100 * block:.2f} %")
    assert block > 0.05, block


def test_hair_export_reads_cycles_settings(bpy_drt):
    """What the exporter hands the tracer: 400 strands of 2^steps + 1 keys (the viewport's
    Steps, 2, in the viewport's depsgraph; F12 reads Render Steps), radius 0.005 at the
    root and 0 at the tip, tapering linearly along the length, in the fur material; six
    curls with their own radii."""
    bpy = bpy_drt
    scene = _scene(bpy)
    use_engine(scene, "DRT", 4)
    from drt_addon.export import Reporter, export_scene
    reporter = Reporter()
    s = export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    fur = next(c for c in s.curves if c.name.startswith("Sphere"))
    curls = next(c for c in s.curves if c.name == "Curls")
    n = 2 ** 2 + 1
    assert fur.curve_count == 400 and np.all(np.diff(fur.curve_keys) == n)
    radii = fur.radii.reshape(400, n)
    np.testing.assert_allclose(radii[:, 0], 0.005, rtol=1e-6)
    assert np.all(radii[:, -1] == 0.0)
    keys = fur.keys.reshape(400, n, 3)
    run = np.concatenate([np.zeros((400, 1)), np.cumsum(
        np.linalg.norm(np.diff(keys, axis=1), axis=2), axis=1)], axis=1)
    np.testing.assert_allclose(radii[:, 1:-1], 0.005 * (1 - run[:, 1:-1] / run[:, -1:]),
                               rtol=1e-5)
    assert s.materials[fur.curve_materials[0]].name == "fur"
    # the roots are on the sphere's faces (a 32 x 16 UV sphere: within its sagitta of the
    # true sphere), the strands 0.45 m long
    np.testing.assert_allclose(np.linalg.norm(keys[:, 0] - (-0.45, 0, 0.6), axis=1), 0.495,
                               atol=0.006)
    np.testing.assert_allclose(run[:, -1], 0.45, rtol=0.02)
    assert curls.curve_count == 6 and curls.radii[0] == np.float32(0.015)
    assert s.materials[curls.curve_materials[0]].name == "curls"
    assert not any("not rendered yet" in w for w in reporter.warnings), reporter.warnings
    # View Layer > Filter > Curves off: no hair
    bpy.context.view_layer.use_strand = False
    assert export_scene(bpy.context.evaluated_depsgraph_get(), Reporter()).curves == []
