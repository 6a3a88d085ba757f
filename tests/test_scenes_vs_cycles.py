"""Comparison scenes vs Cycles: each scene of sample_blends/build_samples.py's
COMPARISON_SCENES exercises one area of the renderer (metals, a glossy dielectric, glass,
depth of field, instancing, world light, ray visibility, a mirror's caustic, glass
caustics, shader nodes at their own defaults) and is rendered by DRT and by Cycles from the same .blend at Blender's defaults,
as a user would make it: Multiscatter GGX on every Principled BSDF, Cycles' default light
paths (path tracing, full global illumination), Filter Glossy 1, both caustics switches
on, the default clamps (`test_scene_files_hold_blenders_defaults` checks the files).
64 x 64 pixels; Cycles 1024 samples per pixel, DRT 512; one render per engine and scene,
cached for the module.

Thresholds, every scene (`within`, also the controls' check):
- MEAN_TOLERANCE = 2%: relative difference of the image means, per channel;
- MAD_TOLERANCE = 5%: per-pixel mean absolute difference over Cycles' image mean. It
  contains both renders' noise: measured 0.3% (world light) to 2.2% (glass);
- BLOCK_TOLERANCE = 5%: the mean (over channels) of every 8 x 8 pixel block differs from
  Cycles' by at most 5% of that block's Cycles mean plus 10% of the image mean (the
  floor keeps dark blocks from being judged on noise alone). The two whole-image checks
  dilute an error confined to part of the image: rendering the plastic spheres without
  their specular layer moves the image mean by under 2% and the MAD by under 3%, but
  moves blocks by 7%.

Issue 8's limits ("Done when"): image means within ISSUE_MEAN_TOLERANCE = 1% per channel
(ISSUE_MEAN_SCENES) and the 8 x 8-block mean absolute difference, the mean over the blocks
of |difference of the block means|, within ISSUE_BLOCK_TOLERANCE = 3% of the image mean
(`issue_block_mad`, every scene). Where the noise at these sample counts allows, every
single block is held to the same 3% as well (`issue_block`, ISSUE_BLOCK_SCENES). Measured
with 4 DRT seeds against Cycles (and Cycles against itself with another seed):
- block MAD: 0.22% to 0.36% on glass, glass_caustics and ray_visibility, 0.30% to 0.81% on
  mirror_caustic (Cycles against itself: 1.19% there, 0.14% to 0.16% elsewhere);
- means: glass_caustics -0.01% (docs/comparisons.md, 128 x 128, since DRT plays Cycles'
  Russian roulette: before, its larger boosts met Clamp Indirect more often, -0.21% to
  -0.32% over 4 seeds; -1.04% before DRT evaluated rough refraction as Cycles does,
  engine/kernels/bsdf/dielectric.py; blocks at its caustics were 7.3% off), glass
  within 0.09%, ray_visibility within 0.18%; metals, glossy_dielectric, dof, instances
  and world_light within 0.1% (earlier measurement, 16 pairs); node_closures (added
  2026-11-26: Refraction BSDF at its Beckmann default, Glass, Glossy, Specular Tint,
  coat) 0.05%, largest block 0.90%, block MAD 0.19% (one seed). Its control renders the
  nodes as DRT did before that day (Beckmann as GGX, the Glossy as a Schlick metal, no
  tint): largest block 5.75%, issue 8's block 4.45%.
Not held, with the reason measured:
- mirror_caustic's mean: the lamp's small bright reflection in the plate is noise in both
  engines: Cycles against itself with another seed differs by 1.16% in the mean and by
  39% of the image mean in that block (DRT seeds: -0.04% to +0.75%).
- single blocks of ray_visibility (1.1% to 4.5% over 4 seeds), glass_caustics (2.6% to
  4.7%, at the caustics: DRT's noise there, Cycles against itself 1.4%) and
  mirror_caustic (the plate's glint, above): noise at these sample counts.
- glass_caustics with caustics off in both (`test_caustics_switched_off_in_the_file_match_cycles`):
  mean 0.13% (held to 1%).

`test_checks_reject_plausible_errors` renders each scene once more with DRT (128 samples)
with one plausible modelling or export error and checks that the comparison fails; at
128 samples the correct scene still passes every check of `within` (measured: blocks at
most 3.4%, MAD at most 4.6%), so the failures come from the error, not from noise
(glass_caustics' control, refractive caustics off: mean 3.96%, block MAD 3.96%; the
correct scene at 512 samples: 0.21% and 0.28%). Among the controls, the
settings the six older scenes used to force: DRT with single-scatter GGX on the metals
(issue 8's block 38%, this module's 17%) or with Filter Glossy off on the metals (10%)
and on the glass (22%). Filter Glossy off on mirror_caustic is no control: there it
changes the plate's glint, which is noise at 128 samples (largest block 5.3% with one
sampler seed, 3.5% with another, against 3.4% for the correct scene; mean 0.45%).

The six scenes built first (metals to world_light) forced single-scatter GGX and Filter
Glossy 0 until DRT had Multiscatter GGX and Filter Glossy (issue 8); they keep Blender's
defaults now, as the three built since do.
"""
import math
import os

import numpy as np
import pytest

from conftest import SAMPLES_DIR, render_blend

MEAN_TOLERANCE = 0.02
MAD_TOLERANCE = 0.05
BLOCK_TOLERANCE = 0.05
BLOCK = 8
BLOCK_FLOOR = 0.1
CYCLES_SAMPLES = 1024
DRT_SAMPLES = 512
CONTROL_SAMPLES = 128
SIZE = (64, 64)

SCENES = ["metals", "glossy_dielectric", "glass", "dof", "instances", "world_light",
          "ray_visibility", "mirror_caustic", "glass_caustics", "node_closures"]
# Issue 8's limits, where the noise at these sample counts lets a test hold them (the
# module docstring gives the measurements): image means within 1% per channel, and every
# 8 x 8 block mean within 3% of the image mean (`issue_block`).
ISSUE_MEAN_TOLERANCE = 0.01
ISSUE_BLOCK_TOLERANCE = 0.03
ISSUE_MEAN_SCENES = ["metals", "glossy_dielectric", "glass", "dof", "instances",
                     "world_light", "ray_visibility", "glass_caustics", "node_closures"]
ISSUE_BLOCK_SCENES = ["metals", "glossy_dielectric", "glass", "dof", "instances",
                      "world_light", "node_closures"]

_renders = {}


def _path(name):
    return os.path.join(SAMPLES_DIR, f"{name}.blend")


def _render(bpy, name, engine, samples=None, setup=None, tag=""):
    key = (name, engine, tag)
    if key not in _renders:
        samples = samples or (CYCLES_SAMPLES if engine == "CYCLES" else DRT_SAMPLES)
        _renders[key] = render_blend(bpy, _path(name), engine, samples=samples,
                                     percentage=100, setup=setup)
    return _renders[key]


def _blocks(img):
    """The means (over channels) of the BLOCK x BLOCK pixel blocks."""
    h, w, _ = img.shape
    return img.mean(axis=2).reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK).mean(axis=(1, 3))


def compare(drt, cycles):
    """(relative difference of the means per channel (3,), MAD over Cycles' mean, largest
    block difference as defined in the module docstring)."""
    m_drt, m_cyc = drt.mean(axis=(0, 1)), cycles.mean(axis=(0, 1))
    rel = np.abs(m_drt - m_cyc) / m_cyc
    mad = float(np.abs(drt - cycles).mean() / cycles.mean())
    b_drt, b_cyc = _blocks(drt), _blocks(cycles)
    block = float((np.abs(b_drt - b_cyc) / (b_cyc + BLOCK_FLOOR * cycles.mean())).max())
    return rel, mad, block


def issue_block(drt, cycles):
    """Issue 8's block measure: the largest |difference of the block means| over Cycles'
    image mean."""
    return float(np.abs(_blocks(drt) - _blocks(cycles)).max() / cycles.mean())


def issue_block_mad(drt, cycles):
    """Issue 8's 8 x 8-block mean absolute difference: the mean over the blocks of
    |difference of the block means|, over Cycles' image mean."""
    return float(np.abs(_blocks(drt) - _blocks(cycles)).mean() / cycles.mean())


def within(drt, cycles):
    rel, mad, block = compare(drt, cycles)
    return bool((rel <= MEAN_TOLERANCE).all() and mad <= MAD_TOLERANCE
                and block <= BLOCK_TOLERANCE)


def _report(label, drt, cycles):
    rel, mad, block = compare(drt, cycles)
    print(f"{label}: DRT mean {np.round(drt.mean(axis=(0, 1)), 5)}, Cycles mean "
          f"{np.round(cycles.mean(axis=(0, 1)), 5)}, mean difference "
          f"{100 * rel.max():.2f}%, MAD {100 * mad:.2f}%, largest block {100 * block:.2f}%, "
          f"issue 8's block MAD {100 * issue_block_mad(drt, cycles):.2f}% and largest block "
          f"{100 * issue_block(drt, cycles):.2f}%")
    return rel, mad, block


@pytest.mark.parametrize("name", SCENES)
def test_scene_matches_cycles(bpy_drt, name):
    cycles = _render(bpy_drt, name, "CYCLES")
    drt = _render(bpy_drt, name, "DRT")
    assert drt.shape == cycles.shape == (*SIZE[::-1], 3)
    assert np.isfinite(drt).all()
    # Something to compare: lit, with structure (two flat or black images would "match").
    assert cycles.mean() > 0.02 and cycles.std() > 0.2 * cycles.mean()
    rel, mad, block = _report(name, drt, cycles)
    assert (rel <= MEAN_TOLERANCE).all(), (name, rel)
    assert mad <= MAD_TOLERANCE, (name, mad)
    assert block <= BLOCK_TOLERANCE, (name, block)
    assert issue_block_mad(drt, cycles) <= ISSUE_BLOCK_TOLERANCE, name
    if name in ISSUE_MEAN_SCENES:
        assert (rel <= ISSUE_MEAN_TOLERANCE).all(), (name, rel)
    if name in ISSUE_BLOCK_SCENES:
        assert issue_block(drt, cycles) <= ISSUE_BLOCK_TOLERANCE, name


def _bsdf(material):
    import bpy
    return bpy.data.materials[material].node_tree.nodes["Principled BSDF"]


def _roughness_as_alpha(names):
    """Roughness used as GGX alpha (Cycles squares it): set roughness to sqrt(r)."""
    def setup(scene):
        for m in names:
            r = _bsdf(m).inputs["Roughness"]
            r.default_value = math.sqrt(r.default_value)
    return setup


def _full_tint_per_crossing(scene):
    """The glass's base colour applied at each crossing (Cycles: its square root)."""
    c = _bsdf("GlassSmooth").inputs["Base Color"]
    c.default_value = (*(v * v for v in c.default_value[:3]), 1.0)


def _no_specular_layer(scene):
    for r in (0.15, 0.35, 0.7):
        _bsdf(f"Plastic{r}").inputs["Specular IOR Level"].default_value = 0.0


def _half_aperture(scene):
    """Aperture radius halved (e.g. a diameter taken for a radius): f-stop doubled."""
    scene.camera.data.dof.aperture_fstop *= 2.0


def _array_not_evaluated(scene):
    """The Array modifier's copies missing (the unevaluated mesh exported)."""
    scene.objects["Posts"].modifiers["Array"].show_render = False


def _instance_scale_ignored(scene):
    for obj in scene.objects:
        if obj.name.startswith("Inst"):
            obj.scale = (1.0, 1.0, 1.0)


def _ray_visibility_ignored(scene):
    """Every object and lamp seen by every ray (the flags not exported)."""
    for obj in scene.objects:
        for flag in ("camera", "diffuse", "glossy", "transmission", "shadow"):
            setattr(obj, f"visible_{flag}", True)


def _no_filter_glossy(scene):
    scene.cycles.blur_glossy = 0.0


def _single_scatter(names):
    """Single-scattering GGX where the file has Multiscatter GGX (the distribution not
    exported)."""
    def setup(scene):
        for m in names:
            _bsdf(m).distribution = "GGX"
    return setup


def _direct_clamped(scene):
    """Direct light clamped at 10 (the lamp seen in the plate from the first surface
    counted as indirect light was this error)."""
    scene.cycles.sample_clamp_direct = 10.0


def _no_refractive_caustics(scene):
    scene.cycles.caustics_refractive = False


def _world_strength_ignored(scene):
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0


def _closures_as_before(scene):
    """The node closures as DRT rendered them before 2026-11-26: the Refraction BSDF's
    Beckmann as GGX, no Specular Tint, the Glossy BSDF as a Principled metal (Schlick's
    Fresnel)."""
    import bpy
    mats = bpy.data.materials
    mats["Refraction"].node_tree.nodes["Refraction BSDF"].distribution = "GGX"
    for name in ("TintedCopper", "TintedPlastic"):
        _bsdf(name).inputs["Specular Tint"].default_value = (1.0, 1.0, 1.0, 1.0)
    nt = mats["Glossy"].node_tree
    glossy = nt.nodes["Glossy BSDF"]
    metal = nt.nodes.new("ShaderNodeBsdfPrincipled")
    metal.inputs["Base Color"].default_value = glossy.inputs["Color"].default_value
    metal.inputs["Roughness"].default_value = glossy.inputs["Roughness"].default_value
    metal.inputs["Metallic"].default_value = 1.0
    nt.nodes.remove(glossy)
    nt.links.new(metal.outputs[0], nt.nodes["Material Output"].inputs["Surface"])


# scene -> (plausible error, DRT-side scene change that produces it). Measured at 128
# samples (largest block difference; the other checks in brackets):
CONTROLS = {
    "metals-alpha": ("metals", _roughness_as_alpha(["Metal0.1", "Metal0.3", "Metal0.6"])),
    # blocks 16%, MAD 13%, mean 3.2%
    "metals-single-scatter": ("metals", _single_scatter(["Metal0.1", "Metal0.3", "Metal0.6"])),
    # blocks 17%, mean 3.1%
    "metals-no-filter-glossy": ("metals", _no_filter_glossy),       # blocks 10%, mean 2.9%
    "glass-no-filter-glossy": ("glass", _no_filter_glossy),         # blocks 22%, mean 6.3%
    "glass-tint": ("glass", _full_tint_per_crossing),               # blocks 13%, mean 4.4%
    "glossy_dielectric-no-specular": ("glossy_dielectric", _no_specular_layer),  # 7%
    "dof-aperture": ("dof", _half_aperture),                         # blocks 12%, MAD 6.4%
    "instances-array": ("instances", _array_not_evaluated),          # blocks 25%
    "instances-scale": ("instances", _instance_scale_ignored),       # blocks 8.3%
    "world_light-strength": ("world_light", _world_strength_ignored),  # all about 33%
    "ray_visibility-ignored": ("ray_visibility", _ray_visibility_ignored),  # mean 104%
    "mirror_caustic-direct-clamped": ("mirror_caustic", _direct_clamped),      # mean 40%
    "glass_caustics-no-caustics": ("glass_caustics", _no_refractive_caustics),  # mean 4.0%
    "node_closures-as-before": ("node_closures", _closures_as_before),
}


@pytest.mark.parametrize("control", CONTROLS)
def test_checks_reject_plausible_errors(bpy_drt, control):
    name, setup = CONTROLS[control]
    cycles = _render(bpy_drt, name, "CYCLES")
    wrong = _render(bpy_drt, name, "DRT", samples=CONTROL_SAMPLES, setup=setup, tag=control)
    _report(f"{control} (DRT with the error)", wrong, cycles)
    assert not within(wrong, cycles), control


LIGHT_PATH_DEFAULTS = ("max_bounces", "diffuse_bounces", "glossy_bounces",
                       "transmission_bounces", "transparent_max_bounces",
                       "sample_clamp_direct", "sample_clamp_indirect", "blur_glossy",
                       "caustics_reflective", "caustics_refractive")


def test_scene_files_hold_blenders_defaults(bpy_drt):
    """Every comparison scene is as a user makes it: Blender's defaults for the light
    paths, clamps, Filter Glossy and caustics (Cycles' settings, which DRT reads) and Multiscatter
    GGX on every Principled BSDF; plus what each scene is built to show (cheap: no
    rendering)."""
    bpy = bpy_drt
    from drt_addon.export import export_scene
    for name in SCENES:
        bpy.ops.wm.open_mainfile(filepath=_path(name), load_ui=False)
        scene = bpy.context.scene
        assert (scene.render.resolution_x, scene.render.resolution_y) == SIZE, name
        c = scene.cycles                     # DRT renders with these too
        for prop in LIGHT_PATH_DEFAULTS:
            assert getattr(c, prop) == c.bl_rna.properties[prop].default, (name, prop)
        assert c.blur_glossy == 1.0 and c.caustics_reflective and c.caustics_refractive
        assert (c.max_bounces, c.diffuse_bounces, c.glossy_bounces, c.transmission_bounces,
                c.sample_clamp_indirect) == (12, 4, 4, 12, 10.0), name
        nodes = [n for m in bpy.data.materials if m.node_tree
                 for n in m.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled"]
        assert nodes, name
        for node in nodes:
            assert node.distribution == "MULTI_GGX", (name, node.id_data.name)
        lamps = [o for o in scene.objects if o.type == "LIGHT"]
        world = scene.world.node_tree.nodes["Background"]
        world_radiance = world.inputs["Strength"].default_value * max(
            world.inputs["Color"].default_value[:3])
        if name in ("glass", "world_light"):
            assert not lamps and world_radiance > 0.5, name
        if name == "node_closures":
            kinds = {n.bl_idname: n for m in bpy.data.materials if m.node_tree
                     for n in m.node_tree.nodes}
            assert kinds["ShaderNodeBsdfRefraction"].distribution == "BECKMANN"
            assert kinds["ShaderNodeBsdfGlass"].distribution == "MULTI_GGX"
            glossy = kinds.get("ShaderNodeBsdfGlossy") or kinds["ShaderNodeBsdfAnisotropic"]
            assert glossy.distribution == "MULTI_GGX"           # (Blender 4.x: Anisotropic)
        if name == "dof":
            dof = scene.camera.data.dof
            assert dof.use_dof and dof.aperture_blades == 6
            assert (dof.aperture_fstop, dof.focus_distance) == pytest.approx((0.4, 1.2))
        if name == "instances":
            exported = export_scene(bpy.context.evaluated_depsgraph_get())
            instanced = [m for m in exported.meshes if "#" in m.name]
            # the block and the ball, each one mesh with its 36 places (export.instances)
            assert sorted(len(m.instances) for m in instanced) == [36, 36]
            posts = [m for m in exported.meshes if m.name == "Posts"]
            assert len(posts) == 1 and len(posts[0].triangles) == 8 * 12   # 8 array copies


def _caustics_off(scene):
    scene.cycles.caustics_reflective = False
    scene.cycles.caustics_refractive = False


def test_caustics_switched_off_in_the_file_match_cycles(bpy_drt):
    """The file's Caustics switches (Light Paths > Caustics) are honoured as Cycles does:
    a hit of a ray leaving a diffuse bounce has no glossy or refraction lobes."""
    cycles = _render(bpy_drt, "glass_caustics", "CYCLES", setup=_caustics_off, tag="off")
    drt = _render(bpy_drt, "glass_caustics", "DRT", setup=_caustics_off, tag="off")
    rel, mad, block = _report("glass_caustics, caustics off in both", drt, cycles)
    assert (rel <= ISSUE_MEAN_TOLERANCE).all() and mad <= MAD_TOLERANCE
    assert block <= BLOCK_TOLERANCE
    # and it is a different image from the one with caustics on
    assert not within(_render(bpy_drt, "glass_caustics", "CYCLES"), cycles)


def _unclamped_8_bounces(scene):
    """What the public glass-spheres file sets: Indirect Light clamping off, 8 bounces."""
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.max_bounces = 8


def test_the_files_clamp_and_bounces_match_cycles(bpy_drt):
    """The file's Light Paths settings, not defaults of DRT's own: glass_caustics with
    Indirect Light clamping off and 8 bounces matches Cycles rendering the same file, and
    DRT with Blender's default clamp of 10 (what DRT rendered before it read the file's
    clamp) does not."""
    cycles = _render(bpy_drt, "glass_caustics", "CYCLES", setup=_unclamped_8_bounces,
                     tag="unclamped")
    drt = _render(bpy_drt, "glass_caustics", "DRT", setup=_unclamped_8_bounces,
                  tag="unclamped")
    rel, mad, block = _report("glass_caustics, unclamped, 8 bounces", drt, cycles)
    assert (rel <= ISSUE_MEAN_TOLERANCE).all() and mad <= MAD_TOLERANCE
    assert block <= BLOCK_TOLERANCE
    clamped = _render(bpy_drt, "glass_caustics", "DRT", samples=CONTROL_SAMPLES,
                      tag="clamp 10")
    assert not within(clamped, cycles)


def _no_diffuse_bounce(scene):
    scene.cycles.diffuse_bounces = 0


def _distribution(scene):
    scene.drt.integrator = "distribution"


def test_distribution_ray_tracing_matches_cycles_without_diffuse_bounces(bpy_drt):
    """DRT's distribution integrator (Cook 1984: every effect distributed, no diffuse
    interreflection) is Cycles' path tracing with Light Paths > Diffuse bounces 0: on
    glossy_dielectric, whose file keeps Cycles' default 4 diffuse bounces, DRT's
    distribution render matches Cycles' render with 0. Control: the path tracer's render
    of the same file does not."""
    cycles = _render(bpy_drt, "glossy_dielectric", "CYCLES", setup=_no_diffuse_bounce,
                     tag="no diffuse")
    drt = _render(bpy_drt, "glossy_dielectric", "DRT", setup=_distribution,
                  tag="distribution")
    rel, mad, block = _report("glossy_dielectric, distribution vs no diffuse bounce", drt,
                              cycles)
    assert (rel <= ISSUE_MEAN_TOLERANCE).all() and mad <= MAD_TOLERANCE
    assert block <= BLOCK_TOLERANCE
    assert not within(_render(bpy_drt, "glossy_dielectric", "DRT"), cycles)
