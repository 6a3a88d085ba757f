"""Shader nodes against Cycles, pixel by pixel (node_probe; the cases: node_cases and
node_cases_procedural): every case of every node family is one tile of an emission-only
render by each engine.

Thresholds per tile (Cycles' tile mean floored at 0.02): the tile means within 1%, the
8 x 8 block means within 3%, and the per-pixel mean absolute difference within 3% (it
holds the antialiasing noise at sharp edges of both renders, 64 samples each, 256 for
the spheres). The
control renders the same scene with DRT's old fallback (every probe's colour unlinked:
the socket's own value) and checks that the comparison fails there for every case, so
each case shows its node is evaluated."""
from __future__ import annotations

import numpy as np
import pytest

import node_cases
import node_cases_bump
import node_cases_procedural
import node_probe

SAMPLES = 64
# Spheres: Fresnel's bright rim against the black background and a dim centre make the
# rim's antialiasing noise large next to the tile mean; 256 samples bring it under 3%.
SPHERE_SAMPLES = 256
MEAN_TOL = 0.01
BLOCK_TOL = 0.03
PIXEL_TOL = 0.03

FAMILIES = {**node_cases.FAMILIES, **node_cases_procedural.FAMILIES,
            **node_cases_bump.FAMILIES}
TILES = node_cases_procedural.TILES          # pixels per tile where not node_probe.TILE

_renders = {}


def _family(bpy, name):
    if name not in _renders:
        cases, shape = FAMILIES[name]
        tile = TILES.get(name, node_probe.TILE)
        scene, columns, rows = node_probe.build_scene(bpy, cases, shape=shape, tile=tile)
        spp = SPHERE_SAMPLES if shape == "sphere" else SAMPLES
        cycles = node_probe.render(bpy, scene, "CYCLES", spp)
        drt = node_probe.render(bpy, scene, "DRT", spp)
        node_probe.unlink_probes(bpy)
        fallback = node_probe.render(bpy, scene, "DRT", 4)
        _renders[name] = (cases, [node_probe.tiles(img, columns, rows, tile)
                                  for img in (drt, cycles, fallback)])
    return _renders[name]


def _errors(bpy, family):
    cases, (drt, cycles, fallback) = _family(bpy, family)
    rows = []
    for k, (name, _) in enumerate(cases):
        rows.append((name, node_probe.tile_errors(drt[k], cycles[k]),
                     node_probe.tile_errors(fallback[k], cycles[k])))
    return rows


def _fails(errors):
    mean, mad, block = errors
    return mean > MEAN_TOL or block > BLOCK_TOL or mad > PIXEL_TOL


@pytest.mark.parametrize("family", sorted(FAMILIES))
def test_nodes_match_cycles(bpy_drt, family):
    rows = _errors(bpy_drt, family)
    bad = [f"{name}: mean {e[0]:.2%}, pixels {e[1]:.2%}, block {e[2]:.2%}"
           for name, e, _ in rows if _fails(e)]
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("family", sorted(FAMILIES))
def test_comparison_fails_without_the_nodes(bpy_drt, family):
    rows = _errors(bpy_drt, family)
    passing = [name for name, _, control in rows if not _fails(control)]
    assert not passing, f"these cases match Cycles even with their nodes left out: {passing}"


@pytest.mark.parametrize("family", sorted(node_cases_bump.FAMILIES))
def test_bump_cases_fail_with_flat_bumps(bpy_drt, family):
    """The bump cases differ from the surface's own normal: with every Bump's Height
    unlinked (the Normal input passed through) DRT fails each bump case's comparison."""
    bpy = bpy_drt
    cases, (_, cycles, _) = _family(bpy, family)
    scene, columns, rows = node_probe.build_scene(bpy, cases, shape=FAMILIES[family][1])
    for mat in bpy.data.materials:
        for node in mat.node_tree.nodes:
            if node.bl_idname == "ShaderNodeBump":
                for link in list(node.inputs["Height"].links):
                    mat.node_tree.links.remove(link)
    flat = node_probe.tiles(node_probe.render(bpy, scene, "DRT", 16), columns, rows)
    passing = [name for k, (name, _) in enumerate(cases) if name.startswith("bump")
               and not _fails(node_probe.tile_errors(flat[k], cycles[k]))]
    assert not passing, f"these bump cases match Cycles with flat bumps: {passing}"


def test_unsupported_node_warns_and_falls_back(bpy_drt):
    """A node DRT does not evaluate is named in one warning for the material, and the
    socket it feeds keeps its own value: the render completes and is not black."""
    bpy = bpy_drt

    def build(nt, p):
        gabor = p.node(nt, "ShaderNodeTexGabor")
        mix = p.node(nt, "ShaderNodeMix", data_type="RGBA")
        nt.links.new(gabor.outputs["Value"], node_cases.ident(mix.inputs, "A_Color"))
        node_cases.ident(mix.inputs, "B_Color").default_value = (0.2, 0.4, 0.6, 1.0)
        node_cases.ident(mix.inputs, "A_Color").default_value = (0.9, 0.1, 0.1, 1.0)
        node_cases.ident(mix.inputs, "Factor_Float").default_value = 0.25
        return node_cases.ident(mix.outputs, "Result_Color")

    scene, _, _ = node_probe.build_scene(bpy, [("unsupported", build)])
    from drt_addon.export import Reporter, export_scene
    reporter = Reporter()
    desc = export_scene(bpy.context.evaluated_depsgraph_get(), reporter, size=(8, 8))
    warnings = [w for w in reporter.warnings if "Gabor Texture" in w]
    assert len(warnings) == 1 and "unsupported" in warnings[0], reporter.warnings
    # Mix of the socket's own colour (A) and B at 0.25, folded to a constant
    assert desc.materials[0].emission == pytest.approx(
        (0.75 * 0.9 + 0.25 * 0.2, 0.75 * 0.1 + 0.25 * 0.4, 0.75 * 0.1 + 0.25 * 0.6))
    img = node_probe.render(bpy, scene, "DRT", 4)
    assert np.isfinite(img).all() and img.mean() > 0.1



def _tilted_plane(bpy, color, sun_tilt):
    """A diffuse plane whose Normal Map tilts its normal, under a sun tilted `sun_tilt`
    (radians about x and y) from overhead, seen from overhead (direct light only)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    mat = bpy.data.materials.new("Tilted")
    mat.use_nodes = True
    nt = mat.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Specular IOR Level"].default_value = 0.0
    bsdf.inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nmap.inputs["Color"].default_value = color
    nt.links.new(nmap.outputs[0], bsdf.inputs["Normal"])
    bpy.context.object.data.materials.append(mat)
    node_probe.sun_and_top_camera(bpy, scene, (sun_tilt, sun_tilt, 0.0), 0.0, 1.0, 5.0)
    scene.render.resolution_x = scene.render.resolution_y = 8
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("World")
    scene.world.color = (0.0, 0.0, 0.0)
    if scene.world.node_tree is not None:
        scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.cycles.max_bounces = 0
    return scene


@pytest.mark.parametrize("color, sun_tilt", [((0.85, 0.5, 0.8, 1.0), 0.0),
                                             ((0.2, 0.6, 0.75, 1.0), 0.0),
                                             ((0.85, 0.5, 0.8, 1.0), 0.5),
                                             ((0.2, 0.6, 0.75, 1.0), -0.4)])
def test_normal_map_diffuse_matches_cycles(bpy_drt, color, sun_tilt):
    """Cycles' Principled lights its diffuse lobe by the Normal Map's own normal (its
    specular lobes by one made a valid reflector for the view), dimmed by Cycles 5.0's
    bump shadowing term where the light is low over the surface itself: a plane tilted
    49 and 55 degrees by its map agrees with Cycles to 0.5% (measured: 0.00%) under a
    sun overhead and under suns tilted off it. Using the valid-reflection normal for the
    diffuse lobe too is 9% and 15% too bright under the overhead sun; Cycles 3 and 4's
    bump shadowing term was 2.8% and 1.9% too bright under the tilted ones."""
    bpy = bpy_drt
    scene = _tilted_plane(bpy, color, sun_tilt)
    cycles = node_probe.render(bpy, scene, "CYCLES", 16).mean()
    drt = node_probe.render(bpy, scene, "DRT", 16).mean()
    print(f"tilted plane {color} sun {sun_tilt}: DRT / Cycles - 1 = {drt / cycles - 1:+.2%}")
    assert drt == pytest.approx(cycles, rel=0.005)


def _mix_scene(bpy, fac_kind):
    """A sphere and the floor under an area lamp, both shaded by a Mix Shader of a red
    diffuse and a blue glossy plastic (Principled) whose Fac varies per hit (a UV
    checker, or Layer Weight's Facing)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=48, ring_count=24)
    bpy.ops.object.shade_smooth()
    sphere = bpy.context.object
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, -1.0))
    floor = bpy.context.object
    mat, nt, out = node_probe.empty_material(bpy, "Mixed")
    mix = nt.nodes.new("ShaderNodeMixShader")
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.8, 0.1, 0.05, 1.0)
    metal = nt.nodes.new("ShaderNodeBsdfPrincipled")
    metal.inputs["Base Color"].default_value = (0.1, 0.3, 0.9, 1.0)
    metal.inputs["Roughness"].default_value = 0.25
    if fac_kind == "checker":
        fac = nt.nodes.new("ShaderNodeTexChecker")
        fac.inputs["Scale"].default_value = 6.0
        nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["UV"], fac.inputs["Vector"])
        nt.links.new(fac.outputs["Fac"], mix.inputs["Fac"])
    else:
        fac = nt.nodes.new("ShaderNodeLayerWeight")
        fac.inputs["Blend"].default_value = 0.4
        nt.links.new(fac.outputs["Facing"], mix.inputs["Fac"])
    nt.links.new(diffuse.outputs[0], mix.inputs[1])
    nt.links.new(metal.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    for obj in (sphere, floor):
        obj.data.materials.append(mat)
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "AREA"))
    lamp.data.energy, lamp.data.size = 400.0, 2.0
    lamp.location, lamp.rotation_euler = (2.0, -2.0, 4.0), (0.5, 0.0, 0.8)
    scene.collection.objects.link(lamp)
    _camera_and_film(bpy, scene, (0.0, -5.5, 1.2), (1.37, 0.0, 0.0))
    return scene, mix


def _camera_and_film(bpy, scene, location, rotation):
    """A camera at location / rotation, a 64 x 64 film and a new (default) world."""
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location, cam.rotation_euler = location, rotation
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.render.resolution_x = scene.render.resolution_y = 64
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("World")


def _image_errors(drt, cycles):
    h, w, _ = cycles.shape
    d = (drt - cycles).mean(axis=2).reshape(h // 8, 8, w // 8, 8).mean(axis=(1, 3))
    return abs(drt.mean() / cycles.mean() - 1.0), float(np.abs(d).mean() / cycles.mean())


@pytest.mark.parametrize("fac_kind", ["checker", "facing"])
def test_mix_shader_with_per_hit_factor_matches_cycles(bpy_drt, fac_kind):
    """A Mix Shader whose Fac varies per hit shades each hit by one of its shaders, picked
    with the Fac's probability: image mean within 1%, mean 8 x 8 block difference
    within 3%. Mixing by the Fac's average (DRT before) fails the block check."""
    bpy = bpy_drt
    scene, mix = _mix_scene(bpy, fac_kind)
    cycles = node_probe.render(bpy, scene, "CYCLES", 1024)
    drt = node_probe.render(bpy, scene, "DRT", 512)
    mean, block = _image_errors(drt, cycles)
    print(f"mix by {fac_kind}: mean {mean:.2%}, blocks {block:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)
    # the old behaviour: the same mix at the Fac's average, everywhere
    from drt_addon.export import Reporter, export_scene
    desc = export_scene(bpy.context.evaluated_depsgraph_get(), Reporter())
    average = desc.materials[0].mix is not None and float(np.clip(
        desc.materials[0].shader.mean_value(desc.materials[0].shader.outputs["mix"]), 0, 1))
    for link in list(mix.inputs["Fac"].links):
        bpy.data.materials["Mixed"].node_tree.links.remove(link)
    mix.inputs["Fac"].default_value = average
    averaged = node_probe.render(bpy, scene, "DRT", 128)
    assert _image_errors(averaged, cycles)[1] > 0.03


@pytest.mark.parametrize("outer", ["mix", "add"])
def test_a_per_hit_mix_inside_a_constant_mix_or_add_matches_cycles(bpy_drt, outer):
    """The per-hit Mix above (a UV checker's Fac) inside a constant Mix Shader (Fac 0.35,
    with a green Diffuse) or an Add Shader (with a dim green Emission): a constant
    combination distributes over the per-hit mix, so each hit picks one side by the
    checker and shades the constant combination of that side, as Cycles' closures sum.
    Image mean within 1 %, mean 8 x 8 block difference within 3 %. Before, the inner mix
    was mixed by its Fac's average: the control, the checker's Fac set to that average,
    fails the block check."""
    bpy = bpy_drt
    scene, mix = _mix_scene(bpy, "checker")
    nt = bpy.data.materials["Mixed"].node_tree
    out = nt.nodes["Material Output"]
    if outer == "mix":
        top = nt.nodes.new("ShaderNodeMixShader")
        top.inputs["Fac"].default_value = 0.35
        other = nt.nodes.new("ShaderNodeBsdfDiffuse")
        other.inputs["Color"].default_value = (0.1, 0.7, 0.1, 1.0)
        nt.links.new(mix.outputs[0], top.inputs[1])
        nt.links.new(other.outputs[0], top.inputs[2])
    else:
        top = nt.nodes.new("ShaderNodeAddShader")
        other = nt.nodes.new("ShaderNodeEmission")
        other.inputs["Color"].default_value = (0.1, 0.7, 0.1, 1.0)
        other.inputs["Strength"].default_value = 0.3
        nt.links.new(other.outputs[0], top.inputs[0])
        nt.links.new(mix.outputs[0], top.inputs[1])
    nt.links.new(top.outputs[0], out.inputs["Surface"])
    from drt_addon.export import Reporter, export_scene
    reporter = Reporter()
    desc = export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    sides = desc.materials[0].mix
    assert sides is not None and not any("average" in w for w in reporter.warnings)
    if outer == "mix":                   # each side holds the green diffuse at 0.35
        assert all(s.base_color[1] > 0.2 for s in sides)
    else:                                # ... or the green emission
        assert all(tuple(s.emission) == pytest.approx((0.03, 0.21, 0.03), rel=1e-5)
                   for s in sides)
    _matches_and_its_average_does_not(bpy, scene, f"per-hit mix inside {outer}", 1024,
                                      512, nt, mix.inputs["Fac"], 0.5)


def _matches_and_its_average_does_not(bpy, scene, label, cycles_spp, drt_spp, nt, socket,
                                      average):
    """DRT within 1 % of Cycles' image mean and 3 % of its 8 x 8 blocks; with `socket`
    unlinked and set to `average` (the per-hit value's average, as DRT rendered it
    before), the blocks are off by more than 3 %."""
    cycles = node_probe.render(bpy, scene, "CYCLES", cycles_spp)
    drt = node_probe.render(bpy, scene, "DRT", drt_spp)
    mean, block = _image_errors(drt, cycles)
    print(f"{label}: mean {mean:.2%}, blocks {block:.2%}")
    assert mean < 0.01 and block < 0.03, (mean, block)
    for link in list(socket.links):
        nt.links.remove(link)
    socket.default_value = average
    averaged = node_probe.render(bpy, scene, "DRT", 128)
    assert _image_errors(averaged, cycles)[1] > 0.03


def test_a_translucent_colour_that_varies_per_hit_matches_cycles(bpy_drt):
    """A Translucent BSDF whose Color is a UV checker (red and blue), on a sheet lit from
    behind by a sun, in a Mix with a white Diffuse (Fac 0.3): the checker shows through
    per hit (program output translucent_color), as in Cycles. Image mean within 1 %,
    mean 8 x 8 block difference within 3 %; the control, the checker's average colour
    (DRT before, with a warning), fails the block check."""
    bpy = bpy_drt
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=3.0, rotation=(1.5708, 0.0, 0.0))
    sheet = bpy.context.object
    mat, nt, out = node_probe.empty_material(bpy, "Sheet")
    translucent = nt.nodes.new("ShaderNodeBsdfTranslucent")
    checker = nt.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 4.0
    checker.inputs["Color1"].default_value = (0.9, 0.1, 0.05, 1.0)
    checker.inputs["Color2"].default_value = (0.05, 0.2, 0.9, 1.0)
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["UV"], checker.inputs["Vector"])
    nt.links.new(checker.outputs["Color"], translucent.inputs["Color"])
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.3
    nt.links.new(translucent.outputs[0], mix.inputs[1])
    nt.links.new(nt.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    sheet.data.materials.append(mat)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (-1.2, 0.0, 0.3)           # from behind the sheet
    scene.collection.objects.link(sun)
    _camera_and_film(bpy, scene, (0.0, -4.0, 0.0), (1.5708, 0.0, 0.0))
    from drt_addon.export import Reporter, export_scene
    reporter = Reporter()
    desc = export_scene(bpy.context.evaluated_depsgraph_get(), reporter)
    assert "translucent_color" in desc.materials[0].shader.outputs
    assert not any("varies per hit" in w for w in reporter.warnings)
    _matches_and_its_average_does_not(bpy, scene, "per-hit translucent colour", 512, 256,
                                      nt, translucent.inputs["Color"],
                                      (0.475, 0.15, 0.475, 1.0))
