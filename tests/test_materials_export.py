"""Materials from Blender's shader nodes, with Cycles' meaning (drt_addon/export/materials.py).

- Each supported node kind exports the engine Material values Cycles' reading of the
  node implies (Principled, Diffuse, Glossy, Glass, Emission, Transparent, Mix, Add,
  Fresnel-driven mixes), and Glossy / Glass land in the right BSDF lobes.
- What DRT approximates is reported once per material, and the scene still renders.
- Image textures: pixels exported once per image, with the node's interpolation and
  extension, sRGB decoded like Cycles, UVs from the right UV map; and a textured scene
  rendered by DRT matches Cycles (direct light only): per-channel means within
  MEAN_TOLERANCE and a per-pixel mean absolute difference within MAD_TOLERANCE of the mean.
"""

import numpy as np
import pytest

from conftest import render_current

MEAN_TOLERANCE = 0.02
MAD_TOLERANCE = 0.05


# --------------------------------------------------------------------------- helpers
def _reset(bpy):
    bpy.ops.wm.read_factory_settings(use_empty=True)


def _material(bpy, name, keep_principled=False):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nt = mat.node_tree
    if not keep_principled:
        nt.nodes.remove(nt.nodes["Principled BSDF"])
    return mat, nt


def _out(nt):
    return nt.nodes["Material Output"].inputs["Surface"]


def _export(mat):
    from drt_addon.export.errors import Reporter
    from drt_addon.export.materials import export_material
    r = Reporter()
    return export_material(mat, r), r.warnings


def _single(bpy, kind, **inputs):
    mat, nt = _material(bpy, kind)
    node = nt.nodes.new(kind)
    for k, v in inputs.items():
        node.inputs[k].default_value = v
    nt.links.new(node.outputs[0], _out(nt))
    return mat, nt, node


def close(a, b, tol=1e-6):
    return np.allclose(np.asarray(a, float), np.asarray(b, float), atol=tol)


def test_constant_nodes_feed_their_value(bpy_drt):
    """An RGB, a Value and a muted Math node straight into the BSDF: a graph of constants
    only (no instruction), folded at export to the nodes' values (it folded to 0, a black
    and smooth surface, before)."""
    _reset(bpy_drt)
    mat, nt = _material(bpy_drt, "Constants", keep_principled=True)
    bsdf = nt.nodes["Principled BSDF"]
    rgb = nt.nodes.new("ShaderNodeRGB")
    rgb.outputs[0].default_value = (0.2, 0.5, 0.8, 1.0)
    value = nt.nodes.new("ShaderNodeValue")
    value.outputs[0].default_value = 0.3
    muted = nt.nodes.new("ShaderNodeMath")
    muted.inputs[0].default_value = 0.7
    muted.mute = True
    nt.links.new(rgb.outputs[0], bsdf.inputs["Base Color"])
    nt.links.new(value.outputs[0], bsdf.inputs["Roughness"])
    nt.links.new(muted.outputs[0], bsdf.inputs["Metallic"])
    m, warnings = _export(mat)
    assert close(m.base_color, (0.2, 0.5, 0.8)) and warnings == []
    assert m.roughness == pytest.approx(0.3) and m.metallic == pytest.approx(0.7)


# --------------------------------------------------------------------------- node kinds
def test_principled_values(bpy_drt):
    bpy = bpy_drt
    _reset(bpy)
    mat, nt = _material(bpy, "P", keep_principled=True)
    p = nt.nodes["Principled BSDF"]
    vals = {"Base Color": (0.2, 0.4, 0.6, 1.0), "Metallic": 0.3, "Roughness": 0.7,
            "IOR": 1.33, "Transmission Weight": 0.4, "Specular IOR Level": 0.25,
            "Emission Color": (1.0, 0.5, 0.25, 1.0), "Emission Strength": 4.0, "Alpha": 1.0}
    for k, v in vals.items():
        p.inputs[k].default_value = v
    m, warnings = _export(mat)
    assert close(m.base_color, (0.2, 0.4, 0.6)) and m.metallic == pytest.approx(0.3)
    assert m.roughness == pytest.approx(0.7) and m.ior == pytest.approx(1.33)
    assert m.transmission == pytest.approx(0.4)
    assert m.specular_ior_level == pytest.approx(0.25)
    assert close(m.emission, (4.0, 2.0, 1.0))               # colour x strength
    assert m.alpha == 1.0 and m.metal_color is None and m.glass_color is None
    assert warnings == []
    # Alpha: coverage; emission stays colour x strength (emitted by the opaque part)
    p.inputs["Alpha"].default_value = 0.25
    m, _ = _export(mat)
    assert m.alpha == pytest.approx(0.25) and close(m.emission, (4.0, 2.0, 1.0))
    assert close(m.transparent_color, (1, 1, 1))
    # coat and sheen are exported; subsurface is not modelled: reported, naming the node
    p.inputs["Coat Weight"].default_value = 0.5
    p.inputs["Coat Tint"].default_value = (0.9, 0.8, 0.7, 1.0)
    p.inputs["Sheen Weight"].default_value = 0.25
    p.inputs["Sheen Roughness"].default_value = 0.3
    m, warnings = _export(mat)
    assert warnings == []
    assert m.coat_weight == pytest.approx(0.5) and m.coat_roughness == pytest.approx(0.03)
    assert m.coat_ior == pytest.approx(1.5) and close(m.coat_tint, (0.9, 0.8, 0.7))
    assert m.sheen_weight == pytest.approx(0.25) and m.sheen_layered
    assert m.sheen_roughness == pytest.approx(0.3)
    # subsurface scattering: Cycles' random walk of Radius x Scale, the node's IOR
    assert m.subsurface_weight == 0.0
    p.inputs["Subsurface Weight"].default_value = 0.5
    p.inputs["Subsurface Radius"].default_value = (1.0, 0.5, 0.25)
    p.inputs["Subsurface Scale"].default_value = 0.2
    p.inputs["Subsurface Anisotropy"].default_value = 0.3
    m, warnings = _export(mat)
    assert warnings == [] and m.subsurface_weight == pytest.approx(0.5)
    assert close(m.subsurface_radius, (0.2, 0.1, 0.05))
    assert m.subsurface_anisotropy == pytest.approx(0.3) and m.subsurface_alpha is None
    assert m.subsurface_ior == pytest.approx(m.ior) and m.subsurface_method == "RANDOM_WALK"
    p.subsurface_method = "RANDOM_WALK_SKIN"
    p.inputs["Subsurface IOR"].default_value = 1.33
    m, warnings = _export(mat)
    assert warnings == [] and m.subsurface_method == "RANDOM_WALK_SKIN"
    assert m.subsurface_ior == pytest.approx(1.33)
    p.subsurface_method = "BURLEY"             # Christensen-Burley: Cycles' disk
    m, warnings = _export(mat)
    assert warnings == [] and m.subsurface_method == "BURLEY"
    assert m.subsurface_weight == pytest.approx(0.5) and close(m.subsurface_radius,
                                                               (0.2, 0.1, 0.05))
    p.subsurface_method = "RANDOM_WALK"
    p.inputs["Subsurface Weight"].default_value = 0.0
    # Specular Tint: the metal's F82 tint, the specular layer's and the glass's F0 tint
    assert close(m.specular_tint, (1, 1, 1))
    p.inputs["Specular Tint"].default_value = (1.0, 0.5, 0.25, 1.0)
    m, warnings = _export(mat)
    assert close(m.specular_tint, (1.0, 0.5, 0.25)) and warnings == []


def test_diffuse_glossy_glass_emission_transparent(bpy_drt):
    bpy = bpy_drt
    _reset(bpy)
    m, w = _export(_single(bpy, "ShaderNodeBsdfDiffuse", Color=(0.5, 0.25, 0.1, 1))[0])
    assert close(m.base_color, (0.5, 0.25, 0.1)) and m.specular_ior_level == 0.0
    assert m.metallic == 0.0 and m.transmission == 0.0 and w == []

    m, w = _export(_single(bpy, "ShaderNodeBsdfGlossy", Color=(0.9, 0.6, 0.2, 1),
                           Roughness=0.3)[0])
    assert m.metallic == 1.0 and close(m.base_color, (0.9, 0.6, 0.2))
    assert m.roughness == pytest.approx(0.3) and w == []

    m, w = _export(_single(bpy, "ShaderNodeBsdfGlass", Color=(0.7, 0.9, 0.8, 1),
                           Roughness=0.1, IOR=1.45)[0])
    assert m.transmission == 1.0 and m.metallic == 0.0
    assert m.ior == pytest.approx(1.45) and m.roughness == pytest.approx(0.1)
    assert close(m.glass_color, (0.7, 0.9, 0.8)) and w == []
    # Cycles tints the reflection by the Color too (its reflection_tint); Principled: white
    assert close(m.glass_reflection_tint, (0.7, 0.9, 0.8))

    m, w = _export(_single(bpy, "ShaderNodeEmission", Color=(1.0, 0.5, 0.0, 1),
                           Strength=3.0)[0])
    assert close(m.emission, (3.0, 1.5, 0.0)) and close(m.base_color, (0, 0, 0))
    assert m.specular_ior_level == 0.0 and m.alpha == 1.0

    m, w = _export(_single(bpy, "ShaderNodeBsdfTransparent", Color=(1.0, 0.5, 0.25, 1))[0])
    assert m.alpha == 0.0 and close(m.transparent_color, (1.0, 0.5, 0.25))


def test_sheen_translucent_refraction(bpy_drt):
    bpy = bpy_drt
    _reset(bpy)
    m, w = _export(_single(bpy, "ShaderNodeBsdfSheen", Color=(0.5, 0.4, 0.3, 1),
                           Roughness=0.2)[0])
    assert m.sheen_weight == 1.0 and not m.sheen_layered and w == []
    assert close(m.sheen_tint, (0.5, 0.4, 0.3)) and m.sheen_roughness == pytest.approx(0.2)
    assert close(m.base_color, (0, 0, 0)) and m.specular_ior_level == 0.0
    m, w = _export(_single(bpy, "ShaderNodeBsdfTranslucent", Color=(0.2, 0.6, 0.1, 1))[0])
    assert close(m.translucent_color, (0.2, 0.6, 0.1)) and w == []
    assert close(m.base_color, (0, 0, 0)) and m.specular_ior_level == 0.0
    # Refraction BSDF: the glass lobe without reflection (its default Beckmann
    # distribution is not reported while the surface is smooth)
    m, w = _export(_single(bpy, "ShaderNodeBsdfRefraction", Color=(0.9, 0.9, 1.0, 1),
                           IOR=1.33)[0])
    assert m.transmission == 1.0 and m.refraction_only and w == []
    assert m.ior == pytest.approx(1.33) and close(m.glass_color, (0.9, 0.9, 1.0))
    # a leaf: Mix(Diffuse, Translucent) is a half-weight diffuse beside half translucency
    mat, _, _ = _mix(bpy, "Leaf", ("ShaderNodeBsdfDiffuse", {"Color": (0.2, 0.6, 0.1, 1)}),
                     ("ShaderNodeBsdfTranslucent", {"Color": (0.4, 0.8, 0.2, 1)}))
    m, w = _export(mat)
    assert close(m.base_color, (0.1, 0.3, 0.05)) and close(m.translucent_color, (0.2, 0.4, 0.1))
    assert w == []
    # Subsurface Scattering node: all of it walks, Color the albedo, Roughness the
    # entry's alpha as it is; no specular layer
    m, w = _export(_single(bpy, "ShaderNodeSubsurfaceScattering", Color=(0.9, 0.5, 0.3, 1),
                           Scale=0.5, Radius=(1.0, 0.4, 0.2), IOR=1.3, Roughness=0.6,
                           Anisotropy=0.2)[0])
    assert w == [] and m.subsurface_weight == 1.0 and close(m.base_color, (0.9, 0.5, 0.3))
    assert close(m.subsurface_radius, (0.5, 0.2, 0.1)) and m.specular_ior_level == 0.0
    assert m.subsurface_ior == pytest.approx(1.3) and m.subsurface_alpha == pytest.approx(0.6)
    assert m.subsurface_anisotropy == pytest.approx(0.2)
    # mixed half and half with a diffuse: half of the mixed base walks
    mat, _, _ = _mix(bpy, "Skin", ("ShaderNodeBsdfDiffuse", {"Color": (0.5, 0.5, 0.5, 1)}),
                     ("ShaderNodeSubsurfaceScattering", {"Color": (0.5, 0.5, 0.5, 1)}))
    m, w = _export(mat)
    assert w == [] and m.subsurface_weight == pytest.approx(0.5)
    assert close(m.base_color, (0.5, 0.5, 0.5))


def _mix(bpy, name, a, b, fac=0.5, add=False):
    mat, nt = _material(bpy, name)
    nodes = []
    for kind, inputs in (a, b):
        n = nt.nodes.new(kind)
        for k, v in inputs.items():
            n.inputs[k].default_value = v
        nodes.append(n)
    mix = nt.nodes.new("ShaderNodeAddShader" if add else "ShaderNodeMixShader")
    off = 0 if add else 1
    if not add:
        mix.inputs[0].default_value = fac
    nt.links.new(nodes[0].outputs[0], mix.inputs[off])
    nt.links.new(nodes[1].outputs[0], mix.inputs[off + 1])
    nt.links.new(mix.outputs[0], _out(nt))
    return mat, nt, mix


DIFFUSE = ("ShaderNodeBsdfDiffuse", {"Color": (0.8, 0.1, 0.1, 1)})
GLOSSY = ("ShaderNodeBsdfGlossy", {"Color": (1.0, 1.0, 1.0, 1), "Roughness": 0.2})
EMISSION = ("ShaderNodeEmission", {"Color": (1.0, 1.0, 0.5, 1), "Strength": 2.0})
TRANSPARENT = ("ShaderNodeBsdfTransparent", {"Color": (1, 1, 1, 1)})
PRINCIPLED = ("ShaderNodeBsdfPrincipled", {"Base Color": (0.2, 0.6, 0.2, 1),
                                           "Roughness": 0.4})


def test_mix_shader_blends_lobes_with_their_own_colours(bpy_drt):
    bpy = bpy_drt
    _reset(bpy)
    m, w = _export(_mix(bpy, "DG", DIFFUSE, GLOSSY, fac=0.25)[0])
    # 75% Lambert of the diffuse colour + 25% GGX mirror of the glossy colour
    assert m.metallic == pytest.approx(0.25)
    assert close(m.base_color, (0.8, 0.1, 0.1)) and close(m.metal_color, (1, 1, 1))
    assert m.roughness == pytest.approx(0.2)             # only the glossy lobe is rough
    assert m.specular_ior_level == 0.0 and w == []
    # two Principled-like sides of one colour: plain parameter blend
    b = ("ShaderNodeBsdfPrincipled", {"Base Color": (0.2, 0.6, 0.2, 1), "Roughness": 0.8,
                                      "Metallic": 1.0})
    m, w = _export(_mix(bpy, "PP", PRINCIPLED, b, fac=0.5)[0])
    assert m.metallic == pytest.approx(0.5) and m.metal_color is None
    assert m.roughness == pytest.approx(0.6) and close(m.base_color, (0.2, 0.6, 0.2))
    # with a Transparent BSDF: alpha = 1 - fac
    m, w = _export(_mix(bpy, "PT", PRINCIPLED, TRANSPARENT, fac=0.3)[0])
    assert m.alpha == pytest.approx(0.7) and close(m.base_color, (0.2, 0.6, 0.2))
    # with an Emission: half the emission, half the BSDF (a darker base colour)
    m, w = _export(_mix(bpy, "DE", DIFFUSE, EMISSION, fac=0.5)[0])
    assert close(m.emission, (1.0, 1.0, 0.5)) and close(m.base_color, (0.4, 0.05, 0.05))


def test_fresnel_and_layer_weight_factors(bpy_drt):
    bpy = bpy_drt
    _reset(bpy)
    mat, nt, mix = _mix(bpy, "Plastic", DIFFUSE, GLOSSY)
    f = nt.nodes.new("ShaderNodeFresnel")
    f.inputs["IOR"].default_value = 1.6
    nt.links.new(f.outputs[0], mix.inputs[0])
    m, w = _export(mat)
    # Principled's own Fresnel-weighted specular layer over the diffuse base
    assert m.metallic == 0.0 and m.specular_ior_level == 0.5
    assert m.ior == pytest.approx(1.6) and m.roughness == pytest.approx(0.2)
    assert close(m.base_color, (0.8, 0.1, 0.1))
    assert len(w) == 1 and "Plastic" in w[0] and "Fresnel" in w[0]
    # Layer Weight Facing between two diffuse colours: mixed per hit (each hit shaded by
    # one side, picked with the Fac's probability); the plain values are the mixture at
    # the Fac's average over the hemisphere seen head-on (1 - |cos| at normal incidence
    # of the summary grid: 0)
    mat, nt, mix = _mix(bpy, "Facing", DIFFUSE, ("ShaderNodeBsdfDiffuse",
                                                 {"Color": (0.0, 0.0, 0.8, 1)}))
    lw = nt.nodes.new("ShaderNodeLayerWeight")
    lw.inputs["Blend"].default_value = 0.5           # Facing = 1 - |cos|
    nt.links.new(lw.outputs["Facing"], mix.inputs[0])
    m, w = _export(mat)
    assert w == []
    assert m.mix is not None and "mix" in m.shader.outputs
    a, b = m.mix
    assert close(a.base_color, (0.8, 0.1, 0.1)) and close(b.base_color, (0.0, 0.0, 0.8))


def test_add_shader(bpy_drt):
    bpy = bpy_drt
    _reset(bpy)
    m, w = _export(_mix(bpy, "Glow", DIFFUSE, EMISSION, add=True)[0])
    assert close(m.emission, (2.0, 2.0, 1.0)) and close(m.base_color, (0.8, 0.1, 0.1))
    assert w == []                                     # exact: emission + BSDF
    m, w = _export(_mix(bpy, "Sum", DIFFUSE, GLOSSY, add=True)[0])
    assert m.metallic == pytest.approx(0.5)             # half the weight each, colours x2
    assert close(m.base_color, (1.6, 0.2, 0.2)) and close(m.metal_color, (2, 2, 2))
    assert len(w) == 1 and "Sum" in w[0] and "adds two BSDFs" in w[0]


def test_glossy_and_glass_export_to_the_right_lobes(bpy_drt):
    from engine.bsdf.material_table import MaterialTable
    from engine.kernels.bsdf import state as S
    from engine.kernels.bsdf.batch import Principled
    bpy = bpy_drt
    _reset(bpy)
    mats = [_export(_single(bpy, "ShaderNodeBsdfGlossy", Color=(0.9, 0.6, 0.2, 1),
                            Roughness=0.3)[0])[0],
            _export(_single(bpy, "ShaderNodeBsdfGlass", Color=(0.7, 0.9, 0.8, 1),
                            Roughness=0.0, IOR=1.45)[0])[0],
            _export(_mix(bpy, "DG", DIFFUSE, GLOSSY, fac=0.25)[0])[0]]
    st = Principled.from_materials(MaterialTable(mats), np.arange(3)).states()

    def weights(k):     # diffuse colour's largest channel, specular, metal, glass
        return [st[k, S.S_DIFFUSE:S.S_DIFFUSE + 3].max(), st[k, S.S_W_SPEC],
                st[k, S.S_W_METAL], st[k, S.S_W_GLASS]]
    assert close(weights(0), [0, 0, 1, 0])                  # metal only
    assert close(st[0, S.S_METAL_F0:S.S_METAL_F0 + 3], (0.9, 0.6, 0.2))  # F0 = the colour
    assert st[0, S.S_ALPHA] == pytest.approx(0.09)         # GGX alpha = roughness^2
    assert close(weights(1), [0, 0, 0, 1])                  # glass only
    assert close(st[1, S.S_TINT:S.S_TINT + 3], (0.7, 0.9, 0.8))  # tint per crossing = colour
    assert st[1, S.S_ETA_GLASS] == pytest.approx(1.45) and st[1, S.S_GLASS_SMOOTH] == 1.0
    assert st[2, S.S_W_METAL] == pytest.approx(0.25)
    assert st[2, S.S_W_SPEC] == 0.0 and st[2, S.S_W_GLASS] == 0.0
    assert close(st[2, S.S_DIFFUSE:S.S_DIFFUSE + 3], np.array([0.8, 0.1, 0.1]) * 0.75)
    assert close(st[2, S.S_METAL_F0:S.S_METAL_F0 + 3], (1, 1, 1))


def test_microfacet_distribution_is_exported(bpy_drt):
    """Each node's distribution reaches Material.glossy_model: Multiscatter GGX (Blender's
    default for Principled, Glossy and Glass), GGX and Beckmann (the Refraction BSDF's
    default) as they are, Ashikhmin-Shirley as GGX (reported); a Mix takes the distribution of its glossiest closure."""
    bpy = bpy_drt
    _reset(bpy)
    for kind in ("ShaderNodeBsdfPrincipled", "ShaderNodeBsdfGlossy", "ShaderNodeBsdfGlass"):
        mat, nt, node = _single(bpy, kind)
        assert node.distribution == "MULTI_GGX"                  # Blender's default
        m, w = _export(mat)
        assert m.glossy_model == "MULTI_GGX" and w == [], kind
        # Cycles' Glossy reflects its colour at every angle; Principled's metal is Schlick's
        assert m.metal_fresnel == ("CONSTANT" if kind == "ShaderNodeBsdfGlossy"
                                   else "SCHLICK"), kind
        node.distribution = "GGX"
        m, w = _export(mat)
        assert m.glossy_model == "GGX" and w == [], kind
        if kind != "ShaderNodeBsdfPrincipled":
            node.distribution = "BECKMANN"
            m, w = _export(mat)
            assert m.glossy_model == "BECKMANN" and w == [], kind
    # the Refraction BSDF's default is Beckmann; Ashikhmin-Shirley is rendered as GGX
    mat, nt, node = _single(bpy, "ShaderNodeBsdfRefraction")
    node.inputs["Roughness"].default_value = 0.3
    assert node.distribution == "BECKMANN"
    m, w = _export(mat)
    assert m.glossy_model == "BECKMANN" and m.refraction_only and w == []
    mat, nt, node = _single(bpy, "ShaderNodeBsdfGlossy")
    node.distribution = "ASHIKHMIN_SHIRLEY"
    m, w = _export(mat)
    assert m.glossy_model == "GGX"
    assert len(w) == 1 and "ASHIKHMIN_SHIRLEY" in w[0] and "GGX" in w[0]
    # Diffuse + single-scatter Glossy: the glossy side decides, no report
    gloss = ("ShaderNodeBsdfGlossy", {"Color": (1, 1, 1, 1), "Roughness": 0.2})
    mat, nt, mix = _mix(bpy, "DG1", DIFFUSE, gloss, fac=0.25)
    nt.nodes["Glossy BSDF"].distribution = "GGX"
    m, w = _export(mat)
    assert m.glossy_model == "GGX" and w == []
    # two glossy closures of different distributions: the glossier one's, reported
    mat, nt, mix = _mix(bpy, "PG", PRINCIPLED, gloss, fac=0.25)
    nt.nodes["Glossy BSDF"].distribution = "GGX"
    m, w = _export(mat)
    assert m.glossy_model == "MULTI_GGX"
    assert len(w) == 1 and "distributions" in w[0]
    # the Fresnel-mixed "plastic": the glossy closure's distribution
    mat, nt, mix = _mix(bpy, "Plastic1", DIFFUSE, gloss)
    nt.nodes["Glossy BSDF"].distribution = "GGX"
    nt.links.new(nt.nodes.new("ShaderNodeFresnel").outputs[0], mix.inputs[0])
    m, _ = _export(mat)
    assert m.specular_ior_level == 0.5 and m.glossy_model == "GGX"


# --------------------------------------------------------------------------- warnings
def _camera_and_sun(bpy, scene, ortho=2.0, size=(48, 48)):
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = ortho
    cam.location = (0.0, 0.0, 5.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.data.angle = 0.0
    scene.collection.objects.link(sun)
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100


def _plane(bpy, name, x=0.0, half=1.0, uv=((0, 0), (1, 0), (1, 1), (0, 1))):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(x - half, -half, 0), (x + half, -half, 0), (x + half, half, 0),
                      (x - half, half, 0)], [], [(0, 1, 2, 3)])
    layer = mesh.uv_layers.new(name="UVMap")
    for li, loop in enumerate(mesh.loops):
        layer.uv[li].vector = uv[loop.vertex_index]
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def test_bump_map_correction_off_is_exported(bpy_drt):
    """Cycles' Bump Map Correction (on by default) shapes how a bent normal is lit; off,
    the material and the sides of its per-hit Mix Shader carry it (no warning). The
    rendering is compared with Cycles in test_bump_vs_cycles.py."""
    bpy = bpy_drt
    mat, nt = _material(bpy, "Mapped", keep_principled=True)
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nt.links.new(nmap.outputs[0], nt.nodes["Principled BSDF"].inputs["Normal"])
    m, warnings = _export(mat)
    assert warnings == [] and m.bump_correction
    mat.cycles.use_bump_map_correction = False
    m, warnings = _export(mat)
    assert warnings == [] and not m.bump_correction
    mix = nt.nodes.new("ShaderNodeMixShader")
    noise = nt.nodes.new("ShaderNodeTexNoise")
    nt.links.new(noise.outputs["Fac"], mix.inputs["Fac"])
    nt.links.new(nt.nodes["Principled BSDF"].outputs[0], mix.inputs[1])
    nt.links.new(nt.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], _out(nt))
    m, warnings = _export(mat)
    assert m.mix is not None and [side.bump_correction for side in m.mix] == [False, False]


def test_unsupported_nodes_warn_once_per_material_and_render(bpy_drt):
    from drt_addon import render_engine
    bpy = bpy_drt
    _reset(bpy)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    scene.drt.samples = 1
    _camera_and_sun(bpy, scene, size=(8, 8))
    mat, nt = _material(bpy, "Weird")
    toon = nt.nodes.new("ShaderNodeBsdfToon")
    hair = nt.nodes.new("ShaderNodeBsdfRayPortal")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(toon.outputs[0], mix.inputs[1])
    nt.links.new(hair.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], _out(nt))
    ok_mat, _ = _material(bpy, "Fine", keep_principled=True)
    for i, m in enumerate([mat, mat, ok_mat]):             # two objects share "Weird"
        _plane(bpy, f"P{i}", x=2.5 * i - 2.5).data.materials.append(m)
    bpy.ops.render.render()
    last = render_engine.last_render
    assert last["ok"], last["error"]
    mine = [w for w in last["warnings"] if "'Weird'" in w]
    assert len(mine) == 1, last["warnings"]
    assert "Toon" in mine[0] and "Ray Portal" in mine[0] and "viewport colour" in mine[0]
    assert not any("'Fine'" in w for w in last["warnings"])
    assert np.isfinite(last["pixels"]).all() and last["pixels"].max() > 0


# --------------------------------------------------------------------------- textures
# A 4 x 4 checker of saturated and mid colours (sRGB-encoded bytes), rows bottom-up.
CHECKER = np.array([
    [(0.9, 0.2, 0.1), (0.1, 0.3, 0.8), (0.9, 0.2, 0.1), (0.5, 0.5, 0.5)],
    [(0.1, 0.8, 0.2), (0.95, 0.9, 0.3), (0.1, 0.8, 0.2), (0.2, 0.2, 0.2)],
    [(0.9, 0.2, 0.1), (0.1, 0.3, 0.8), (0.7, 0.1, 0.6), (0.1, 0.3, 0.8)],
    [(0.3, 0.3, 0.3), (0.95, 0.9, 0.3), (0.1, 0.8, 0.2), (0.95, 0.9, 0.3)]], np.float32)


def _checker_image(bpy, name="Checker"):
    img = bpy.data.images.new(name, 4, 4, alpha=True)
    rgba = np.ones((4, 4, 4), np.float32)
    rgba[:, :, :3] = CHECKER
    img.pixels.foreach_set(rgba.ravel())
    return img


def _image_node(nt, img, interpolation="Linear", extension="REPEAT"):
    node = nt.nodes.new("ShaderNodeTexImage")
    node.image = img
    node.interpolation = interpolation
    node.extension = extension
    return node


def test_a_material_the_exporter_cannot_read_is_reported_and_the_rest_renders(bpy_drt,
                                                                                monkeypatch):
    """Whatever goes wrong while reading one material's nodes (here: a reader that
    raises, standing in for a set-up the exporter does not know), the render does not
    fail: that material is its viewport colour, and one warning names it and the error."""
    from drt_addon.export import materials
    bpy = bpy_drt
    _reset(bpy)
    mat, nt, node = _single(bpy, "ShaderNodeBsdfDiffuse", Color=(0.2, 0.4, 0.6, 1.0))
    mat.diffuse_color = (0.7, 0.1, 0.1, 1.0)

    def broken(*args, **kwargs):
        raise AttributeError("'NodeParam' object has no attribute 'texture'")
    monkeypatch.setattr(materials, "_closure", broken)
    m, warnings = _export(mat)
    assert close(m.base_color, (0.7, 0.1, 0.1))
    assert len(warnings) == 1 and repr(mat.name) in warnings[0]
    assert "could not read its nodes" in warnings[0] and "AttributeError" in warnings[0]
    monkeypatch.undo()
    m, warnings = _export(mat)
    assert close(m.base_color, (0.2, 0.4, 0.6)) and warnings == []


def test_image_texture_export(bpy_drt):
    from engine.textures import srgb_to_linear
    bpy = bpy_drt
    _reset(bpy)
    img = _checker_image(bpy)
    mat, nt = _material(bpy, "Tex", keep_principled=True)
    p = nt.nodes["Principled BSDF"]
    a = _image_node(nt, img, "Closest", "CLIP")
    nt.links.new(a.outputs["Color"], p.inputs["Base Color"])
    b = _image_node(nt, img, "Closest", "CLIP")             # same image and settings
    nt.links.new(b.outputs["Color"], p.inputs["Emission Color"])
    p.inputs["Emission Strength"].default_value = 2.0
    data = bpy.data.images.new("Rough", 2, 2, alpha=True)
    data.colorspace_settings.name = "Non-Color"
    data.pixels.foreach_set(np.full(16, 0.25, np.float32))
    c = _image_node(nt, data, "Linear", "EXTEND")
    nt.links.new(c.outputs["Color"], p.inputs["Roughness"])
    from drt_addon.export.errors import Reporter
    from drt_addon.export.materials import export_material
    reporter = Reporter()
    m = export_material(mat, reporter)
    assert reporter.warnings == []
    # the textured inputs are outputs of the material's program (engine.nodes)
    prog = m.shader
    assert set(prog.outputs) == {"base_color", "emission", "roughness"}
    assert len(prog.images) == 2                    # the two same nodes: one Texture
    t, tr = prog.images
    assert (t.interpolation, t.extension, t.srgb) == ("Closest", "CLIP", True)
    # pixels as Blender stores them (8-bit: quantised to 1/255), rows bottom-up
    assert np.allclose(t.pixels[:, :, :3], CHECKER, atol=0.5 / 255)
    uv = np.array([[0.125 + 0.25 * i, 0.125 + 0.25 * j] for j in range(4) for i in range(4)])
    looked = t.lookup(uv)[:, :3].reshape(4, 4, 3)
    expected = srgb_to_linear(np.floor(CHECKER * 255 + 0.5) / 255)
    assert np.allclose(looked, expected, atol=1e-5)
    from engine.nodes.context import hit_rows
    hits = hit_rows(np.zeros((16, 3)), np.tile([0.0, 0.0, 1.0], (16, 1)), uv=uv)
    base = prog.evaluate(prog.outputs["base_color"], hits).reshape(4, 4, 3)
    assert np.allclose(base, expected, atol=1e-5)
    emission = prog.evaluate(prog.outputs["emission"], hits).reshape(4, 4, 3)
    assert np.allclose(emission, 2.0 * expected, atol=1e-5)      # x Emission Strength
    assert (tr.srgb, tr.interpolation, tr.extension) == (False, "Linear", "EXTEND")
    rough = prog.evaluate(prog.outputs["roughness"], hit_rows(
        np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), uv=np.array([[0.3, 0.7]])))
    assert rough[0] == pytest.approx(0.25, abs=2 / 255)         # colour -> luminance
    # a second material with the same image, other settings: pixels still read once
    mat2, nt2 = _material(bpy, "Tex2", keep_principled=True)
    d = _image_node(nt2, img, "Linear", "REPEAT")
    nt2.links.new(d.outputs["Color"], nt2.nodes["Principled BSDF"].inputs["Base Color"])
    t2 = export_material(mat2, reporter).shader.images[0]
    assert t2 is not t and np.shares_memory(t2.pixels, t.pixels)


def test_uvs_exported_only_for_textured_materials_from_the_right_map(bpy_drt):
    from drt_addon.export import export_scene
    bpy = bpy_drt
    _reset(bpy)
    scene = bpy.context.scene
    _camera_and_sun(bpy, scene, size=(8, 8))
    img = _checker_image(bpy)
    textured, nt = _material(bpy, "Textured", keep_principled=True)
    node = _image_node(nt, img)
    nt.links.new(node.outputs["Color"], nt.nodes["Principled BSDF"].inputs["Base Color"])
    plain, _ = _material(bpy, "Plain", keep_principled=True)
    a = _plane(bpy, "A", x=-1.5, uv=((0, 0), (2, 0), (2, 1), (0, 1)))
    a.data.materials.append(textured)
    b = _plane(bpy, "B", x=1.5)
    b.data.materials.append(plain)
    desc = export_scene(bpy.context.evaluated_depsgraph_get())
    mesh = {m.name: m for m in desc.meshes}
    assert mesh["B"].uvs is None
    uvs = mesh["A"].uvs
    assert uvs.shape == (2, 3, 2)
    # each triangle corner carries its vertex's UV: u = (x + 2.5) (0..2), v = y + 1 / 2...
    pos = mesh["A"].positions[mesh["A"].triangles]
    assert np.allclose(uvs[..., 0], (pos[..., 0] + 2.5), atol=1e-6)
    assert np.allclose(uvs[..., 1], (pos[..., 1] + 1.0) / 2.0, atol=1e-6)
    # a UV Map node names a second map: that one is exported
    second = a.data.uv_layers.new(name="Second")
    for li in range(len(a.data.loops)):
        second.uv[li].vector = (0.25, 0.75)
    uvnode = nt.nodes.new("ShaderNodeUVMap")
    uvnode.uv_map = "Second"
    nt.links.new(uvnode.outputs["UV"], node.inputs["Vector"])
    desc = export_scene(bpy.context.evaluated_depsgraph_get())
    uvs = {m.name: m for m in desc.meshes}["A"].uvs
    assert np.allclose(uvs, [0.25, 0.75])


def _render(bpy, engine, samples):
    scene = bpy.context.scene
    scene.render.engine = engine
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.device = "CPU"
    scene.cycles.diffuse_bounces = 0
    scene.drt.samples = samples
    scene.cycles.diffuse_bounces = 0
    return render_current(bpy, scene)


def build_texture_scene(bpy):
    """Two 2 x 2 m planes side by side under a sun straight above, seen by an orthographic
    camera from above (64 x 32 pixels, 4 m wide): left, a Principled BSDF (no specular)
    whose Base Color is the 4 x 4 sRGB checker, Linear / REPEAT, on UVs running from
    -0.25 to 1.25 (so the image repeats past its edges); right, an Emission shader whose
    Color is the same image, Closest / CLIP, on UVs from -0.1 to 1.1 (clipped to black
    outside). Direct light only."""
    _reset(bpy)
    scene = bpy.context.scene
    _camera_and_sun(bpy, scene, ortho=4.0, size=(64, 32))
    img = _checker_image(bpy)
    lam, nt = _material(bpy, "Lit", keep_principled=True)
    p = nt.nodes["Principled BSDF"]
    p.inputs["Specular IOR Level"].default_value = 0.0
    node = _image_node(nt, img, "Linear", "REPEAT")
    nt.links.new(node.outputs["Color"], p.inputs["Base Color"])
    glow, nt = _material(bpy, "Glow")
    em = nt.nodes.new("ShaderNodeEmission")
    node = _image_node(nt, img, "Closest", "CLIP")
    nt.links.new(node.outputs["Color"], em.inputs["Color"])
    nt.links.new(em.outputs[0], _out(nt))
    lo, hi = -0.25, 1.25
    _plane(bpy, "Left", x=-1.0, uv=((lo, lo), (hi, lo), (hi, hi), (lo, hi))) \
        .data.materials.append(lam)
    lo, hi = -0.1, 1.1
    _plane(bpy, "Right", x=1.0, uv=((lo, lo), (hi, lo), (hi, hi), (lo, hi))) \
        .data.materials.append(glow)
    return scene


def _render_both(bpy, build, samples):
    """(DRT image, Cycles image, DRT's exported scene) of the scene `build` makes."""
    build(bpy)
    cycles = _render(bpy, "CYCLES", samples)
    drt = _render(bpy, "DRT", samples)
    from drt_addon import render_engine
    return drt, cycles, render_engine.last_render["scene"]


@pytest.fixture(scope="module")
def texture_renders(bpy_drt):
    return _render_both(bpy_drt, build_texture_scene, 64)


def compare(drt, cycles):
    m_drt, m_cyc = drt.mean(axis=(0, 1)), cycles.mean(axis=(0, 1))
    rel = np.abs(m_drt - m_cyc) / m_cyc
    mad = float(np.abs(drt - cycles).mean() / cycles.mean())
    return rel, mad


def test_textured_scene_matches_cycles(texture_renders):
    drt, cycles, _ = texture_renders
    assert drt.shape == cycles.shape == (32, 64, 3)
    assert cycles.max() > 0.5 and cycles[:, :32].min() > 0.0    # lit, not a blank render
    rel, mad = compare(drt, cycles)
    print(f"\ntextured scene: DRT mean {drt.mean(axis=(0, 1))}, Cycles mean "
          f"{cycles.mean(axis=(0, 1))}, relative difference {rel}, MAD {mad:.4f} of the mean")
    for half, sl in (("lit", np.s_[:, :32]), ("emission", np.s_[:, 32:])):
        r, m = compare(drt[sl], cycles[sl])
        print(f"  {half} half: relative mean difference {r}, MAD {m:.4f}")
    assert np.all(rel < MEAN_TOLERANCE), rel
    assert mad < MAD_TOLERANCE, mad
    for sl in (np.s_[:, :32], np.s_[:, 32:]):          # each half on its own too
        r, m = compare(drt[sl], cycles[sl])
        assert np.all(r < MEAN_TOLERANCE) and m < MAD_TOLERANCE, (r, m)


def test_texture_comparison_rejects_wrong_texture_readings(texture_renders):
    """The thresholds catch the mistakes a texture exporter can make, checked against the
    same Cycles render by re-rendering DRT's exported scene with each mistake: the image
    upside down (rows top-down), sRGB not decoded, sRGB decoded before interpolation
    (Cycles decodes after), Closest instead of Linear, texels shifted by one column."""
    import copy

    from engine import RenderSettings, render
    from engine.textures import Texture, srgb_to_linear
    drt, cycles, scene = texture_renders

    def rerender(mutate):
        s = copy.deepcopy(scene)
        for m in s.materials:
            if m.shader is not None:
                m.shader.images = [mutate(t) for t in m.shader.images]
        film, _ = render(s, RenderSettings(samples=16, diffuse_bounces=0))
        return film.mean()                  # row 0 at the top, like the EXR read back

    def flipped(t):
        return Texture(t.pixels[::-1], t.interpolation, t.extension, t.srgb, t.name)

    def not_decoded(t):
        return Texture(t.pixels, t.interpolation, t.extension, False, t.name)

    def decoded_before_interpolation(t):
        px = t.pixels.copy()
        px[:, :, :3] = srgb_to_linear(px[:, :, :3]) if t.srgb else px[:, :, :3]
        return Texture(px, t.interpolation, t.extension, False, t.name)

    def closest(t):
        return Texture(t.pixels, "Closest", t.extension, t.srgb, t.name)

    def shifted(t):
        return Texture(np.roll(t.pixels, 1, axis=1), t.interpolation, t.extension, t.srgb,
                       t.name)

    lit = np.s_[:, :32]                     # the Linear-filtered half
    for mistake, region in ((flipped, np.s_[:, :]), (not_decoded, np.s_[:, :]),
                            (decoded_before_interpolation, lit), (closest, lit),
                            (shifted, np.s_[:, :])):
        img = rerender(mistake)
        assert img.shape == cycles.shape
        rel, mad = compare(img[region], cycles[region])
        assert np.any(rel > MEAN_TOLERANCE) or mad > MAD_TOLERANCE, (mistake.__name__, rel, mad)
    # and the correct reading re-rendered the same way passes (so the check is sound)
    img = rerender(lambda t: t)
    for region in (np.s_[:, :], lit):
        rel, mad = compare(img[region], cycles[region])
        assert np.all(rel < MEAN_TOLERANCE) and mad < MAD_TOLERANCE, (rel, mad)


def build_alpha_scene(bpy, alpha_checker=False):
    """Stochastic transparency against Cycles: the textured Lambertian plane (Linear /
    REPEAT checker) under a sun, half covered 0.5 m above by a plane whose Principled Alpha
    is 0.4 (base colour 0.8, no specular) and a quarter by a Mix Shader of a Diffuse BSDF
    and a Transparent BSDF (Fac 0.7, i.e. alpha 0.3). 48 x 48 pixels, direct light only:
    what the camera sees through the covers and the covers' transparent shadows.
    alpha_checker: the veil's Alpha is a Checker Texture's Fac (a cut-out, per hit, as a
    leaf's alpha mask is) scaled to 0.1 / 0.9 by a Map Range."""
    _reset(bpy)
    scene = bpy.context.scene
    _camera_and_sun(bpy, scene, ortho=2.0, size=(48, 48))
    img = _checker_image(bpy)
    lam, nt = _material(bpy, "Lit", keep_principled=True)
    p = nt.nodes["Principled BSDF"]
    p.inputs["Specular IOR Level"].default_value = 0.0
    node = _image_node(nt, img, "Linear", "REPEAT")
    nt.links.new(node.outputs["Color"], p.inputs["Base Color"])
    _plane(bpy, "Floor").data.materials.append(lam)
    veil, nt = _material(bpy, "Veil", keep_principled=True)
    p = nt.nodes["Principled BSDF"]
    p.inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    p.inputs["Specular IOR Level"].default_value = 0.0
    p.inputs["Alpha"].default_value = 0.4
    if alpha_checker:
        checker = nt.nodes.new("ShaderNodeTexChecker")
        checker.inputs["Scale"].default_value = 3.0
        remap = nt.nodes.new("ShaderNodeMapRange")
        remap.inputs["To Min"].default_value = 0.1
        remap.inputs["To Max"].default_value = 0.9
        nt.links.new(checker.outputs["Fac"], remap.inputs["Value"])
        nt.links.new(remap.outputs["Result"], p.inputs["Alpha"])
    cover = _plane(bpy, "Veil", x=0.5, half=0.5)
    cover.scale = (1.0, 2.0, 1.0)
    cover.location.z = 0.5
    cover.data.materials.append(veil)
    mat, nt, mix = _mix(bpy, "Screen", ("ShaderNodeBsdfDiffuse", {"Color": (0.2, 0.4, 0.9, 1)}),
                        TRANSPARENT, fac=0.7)
    screen = _plane(bpy, "Screen", x=-0.5, half=0.5)
    screen.location = (0.0, 0.5, 0.25)
    screen.data.materials.append(mat)
    return scene


@pytest.fixture(scope="module")
def alpha_renders(bpy_drt):
    return _render_both(bpy_drt, build_alpha_scene, 256)


def test_alpha_matches_cycles(alpha_renders):
    drt, cycles, _ = alpha_renders
    rel, mad = compare(drt, cycles)
    print(f"\nalpha scene: DRT mean {drt.mean(axis=(0, 1))}, Cycles mean "
          f"{cycles.mean(axis=(0, 1))}, relative difference {rel}, MAD {mad:.4f}")
    assert np.all(rel < MEAN_TOLERANCE), rel
    assert mad < MAD_TOLERANCE, mad
    # the covered half on its own (the uncovered one would dilute an error)
    r, m = compare(drt[:, 24:], cycles[:, 24:])
    assert np.all(r < MEAN_TOLERANCE) and m < MAD_TOLERANCE, (r, m)


@pytest.fixture(scope="module")
def checker_alpha_renders(bpy_drt):
    return _render_both(bpy_drt, lambda bpy: build_alpha_scene(bpy, alpha_checker=True), 256)


def test_per_hit_alpha_matches_cycles(checker_alpha_renders):
    """A Principled Alpha driven by nodes (a checker cut-out): each hit's own alpha, not
    the average (the export once failed on it: 'NodeParam' has no attribute 'texture')."""
    drt, cycles, scene = checker_alpha_renders
    veil = next(m for m in scene.materials if m.name == "Veil")
    assert "alpha" in veil.shader.outputs
    rel, mad = compare(drt[:, 24:], cycles[:, 24:])
    print(f"\nchecker alpha, covered half: relative difference {rel}, MAD {mad:.4f}")
    assert np.all(rel < MEAN_TOLERANCE) and mad < MAD_TOLERANCE, (rel, mad)
    # the checker shows: the veil's average alpha everywhere fails the same comparison
    import copy

    from engine import RenderSettings, render
    s = copy.deepcopy(scene)
    veil = next(m for m in s.materials if m.name == "Veil")
    del veil.shader.outputs["alpha"]
    img = render(s, RenderSettings(samples=256, diffuse_bounces=0))[0].mean()
    r, m = compare(img[:, 24:], cycles[:, 24:])
    print(f"average alpha instead: relative difference {r}, MAD {m:.4f}")
    assert np.any(r > MEAN_TOLERANCE) or m > MAD_TOLERANCE, (r, m)


def test_alpha_comparison_rejects_ignoring_alpha(alpha_renders):
    """The same comparison fails when DRT's exported scene is rendered opaque."""
    import copy

    from engine import RenderSettings, render
    drt, cycles, scene = alpha_renders
    s = copy.deepcopy(scene)
    for m in s.materials:
        m.alpha = 1.0
    img = render(s, RenderSettings(samples=16, diffuse_bounces=0))[0].mean()
    rel, mad = compare(img[:, 24:], cycles[:, 24:])
    assert np.any(rel > MEAN_TOLERANCE) or mad > MAD_TOLERANCE, (rel, mad)


def test_a_node_tree_without_an_output_is_black_as_in_cycles(bpy_drt):
    """A material whose node tree has no Material Output (the public RoomExercise.blend
    has five such objects) has no closure in Cycles: an opaque black surface, not its
    viewport colour (what DRT rendered before: a green plane here). Both engines, 16
    samples: the plane's pixels are black, the world around it the same."""
    from node_probe import new_material, new_scene, render
    bpy = bpy_drt
    scene = new_scene(bpy, 32)
    bpy.ops.mesh.primitive_plane_add(size=1.0)
    mat, nt = new_material(bpy, "NoOutput")
    nt.nodes.remove(nt.nodes["Material Output"])
    mat.diffuse_color = (0.2, 0.9, 0.2, 1.0)
    bpy.context.object.data.materials.append(mat)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, 0.0, 3.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    cycles, drt = (render(bpy, scene, e, 16) for e in ("CYCLES", "DRT"))
    assert cycles[16, 16, :3].max() == 0.0 and drt[16, 16, :3].max() == 0.0
    np.testing.assert_allclose(drt[0, 0, :3], cycles[0, 0, :3], rtol=1e-3)


def test_anisotropic_bsdfs_export_their_mapping_tangent_and_rotation(bpy_drt):
    """Principled, Metallic and Glossy anisotropy: the node's mapping, its amount, the
    tangent as a per-hit program output (the Geometry node's radial tangent when
    unlinked, as Cycles links it), Rotation plain or per hit; nothing reported. An
    isotropic BSDF has no tangent output: it pays for nothing."""
    bpy = bpy_drt
    m, w = _export(_single(bpy, "ShaderNodeBsdfPrincipled", Metallic=1.0, Anisotropic=0.6,
                           **{"Anisotropic Rotation": 0.1})[0])
    assert w == [] and m.anisotropy_kind == "PRINCIPLED"
    assert m.anisotropy == pytest.approx(0.6) and m.anisotropic_rotation == pytest.approx(0.1)
    assert "tangent" in m.shader.outputs and "anisotropic_rotation" not in m.shader.outputs
    m, w = _export(_single(bpy, "ShaderNodeBsdfGlossy", Anisotropy=-0.4)[0])
    assert w == [] and m.anisotropy_kind == "GLOSSY" and m.anisotropy == pytest.approx(-0.4)
    mat, nt, node = _single(bpy, "ShaderNodeBsdfMetallic", Anisotropy=0.5)
    noise = nt.nodes.new("ShaderNodeTexNoise")
    nt.links.new(noise.outputs["Fac"], node.inputs["Rotation"])
    tangent = nt.nodes.new("ShaderNodeTangent")
    tangent.direction_type = "UV_MAP"
    nt.links.new(tangent.outputs["Tangent"], node.inputs["Tangent"])
    m, w = _export(mat)
    assert w == [] and m.anisotropy_kind == "PRINCIPLED"
    assert {"tangent", "anisotropic_rotation"} <= set(m.shader.outputs)
    from drt_addon.export.tangents import wants_tangents
    assert wants_tangents([mat])             # the UV map's tangents are exported
    for kind, inputs in (("ShaderNodeBsdfPrincipled", {"Metallic": 1.0}),
                         ("ShaderNodeBsdfGlossy", {"Anisotropy": 0.0}),
                         ("ShaderNodeBsdfMetallic", {"Anisotropy": 1e-5})):
        m, w = _export(_single(bpy, kind, **inputs)[0])
        assert m.anisotropy_kind == "NONE" and m.shader is None and w == [], kind


def test_a_principled_thin_film_exports_its_thickness_and_ior(bpy_drt):
    """Thin Film Thickness and IOR reach the material (engine/kernels/bsdf/thin_film.py),
    a glass's too; one at Cycles' cut-off (0.1 nm) is none."""
    bpy = bpy_drt
    m, w = _export(_single(bpy, "ShaderNodeBsdfPrincipled", Metallic=1.0,
                           **{"Thin Film Thickness": 420.0, "Thin Film IOR": 1.6})[0])
    assert w == [] and m.thin_film_thickness == pytest.approx(420.0)
    assert m.thin_film_ior == pytest.approx(1.6)
    m, w = _export(_single(bpy, "ShaderNodeBsdfPrincipled",
                           **{"Thin Film Thickness": 0.1})[0])
    assert w == [] and m.thin_film_thickness == 0.0
    m, w = _export(_single(bpy, "ShaderNodeBsdfPrincipled", **{"Transmission Weight": 1.0,
                                                             "Thin Film Thickness": 300.0})[0])
    assert w == [] and m.thin_film_thickness == pytest.approx(300.0)
