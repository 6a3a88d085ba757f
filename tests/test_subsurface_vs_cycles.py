"""Subsurface scattering against Cycles: sample_blends/subsurface.blend (a Principled
skin Suzanne by Random Walk with a Bump, which bends the walk's exit too as in Cycles; a
wax candle by Random Walk (Skin) under a flame lamp; a Subsurface Scattering node's
marble mixed with a Glossy; sample_blends/subsurface_scenes.py) at Blender's defaults, DRT 512 against Cycles 1024 samples at
64 x 48: image means within 1 % per channel (the artist scenes' tolerance,
tests/test_artist_scenes_vs_cycles.py), the mean absolute difference of the 8 x 8 block
means within 1 % of the image mean, and every block within 8 %.

Measured (docs/subsurface.md has the numbers of its own run): means -0.28 %, block MAD
0.57 %, worst block 3.4 %. Before the Suzanne had its Bump, with sampler seeds 0 and 7:
means -0.3 % and -0.1 %, block MAD 0.55 % and 0.66 % (Cycles against itself with
another seed: 0.34 %), worst block 3.7 % and 6.3 %: the candle's top, lit by its flame
lamp 6 cm above it (4 W beside an 85 W key and a 50 W rim lamp), is noise. Picking the
flame with the light tree instead of by power left that block where it was (3.4 % with
the tree, 3.5 % without, at this seed): its cause is not the lamp pick, and it is not
resolved.
The control, every subsurface weight rendered as the diffuse lobe it was before DRT
walked it (DRT 128), fails: mean -2.0 % in red, block MAD 1.45 %."""
from __future__ import annotations

import os

from conftest import SAMPLES_DIR, cached_render
from test_artist_scenes_vs_cycles import _agrees

CYCLES_SAMPLES = 1024
DRT_SAMPLES = 512
BLOCK_TOLERANCE = 0.08          # the flame-lit candle top's noise (above)
BLOCK_MAD_TOLERANCE = 0.01

_renders = {}
BLEND = os.path.join(SAMPLES_DIR, "subsurface.blend")


def _render(bpy, engine, samples, setup=None):
    return cached_render(_renders, bpy, BLEND, engine, samples, setup,
                         "" if setup is None else setup.__name__)


def _diffuse_instead(scene):
    """The control: no subsurface scattering, its weight left to the diffuse lobe (the
    Subsurface Scattering node becomes a Diffuse BSDF of its colour)."""
    import bpy
    for mat in bpy.data.materials:
        nt = mat.node_tree
        if nt is None:
            continue
        for node in list(nt.nodes):
            if node.bl_idname == "ShaderNodeBsdfPrincipled":
                node.inputs["Subsurface Weight"].default_value = 0.0
            elif node.bl_idname == "ShaderNodeSubsurfaceScattering":
                diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
                diffuse.inputs["Color"].default_value = node.inputs["Color"].default_value
                for link in list(node.outputs[0].links):
                    nt.links.new(diffuse.outputs[0], link.to_socket)
                nt.nodes.remove(node)


def test_subsurface_scene_matches_cycles(bpy_drt):
    cycles = _render(bpy_drt, "CYCLES", CYCLES_SAMPLES)
    assert cycles.shape == (48, 64, 3) and cycles.std() > 0.2 * cycles.mean()
    def agrees(label, drt):
        return _agrees(label, drt, cycles, BLOCK_TOLERANCE, BLOCK_MAD_TOLERANCE)
    assert agrees("subsurface", _render(bpy_drt, "DRT", DRT_SAMPLES))
    assert not agrees("subsurface rendered diffuse (control)",
                      _render(bpy_drt, "DRT", 128, _diffuse_instead))


def _burley(scene):
    """Every subsurface material by Christensen-Burley (Principled's Subsurface Method,
    the Subsurface Scattering node's Falloff): Cycles' disk sampling, no walk."""
    import bpy
    for mat in bpy.data.materials:
        for node in (mat.node_tree.nodes if mat.node_tree is not None else ()):
            if node.bl_idname == "ShaderNodeBsdfPrincipled":
                node.subsurface_method = "BURLEY"
            elif node.bl_idname == "ShaderNodeSubsurfaceScattering":
                node.falloff = "BURLEY"


def test_christensen_burley_matches_cycles(bpy_drt):
    """The same scene by Christensen-Burley: DRT's disk sampling against Cycles', at the
    tolerances above. The control, the random walk DRT rendered in its place before,
    must fail against Cycles' Burley."""
    cycles = _render(bpy_drt, "CYCLES", CYCLES_SAMPLES, _burley)
    assert _agrees("Christensen-Burley", _render(bpy_drt, "DRT", DRT_SAMPLES, _burley),
                   cycles, BLOCK_TOLERANCE, BLOCK_MAD_TOLERANCE)
    assert not _agrees("random walk against Cycles' Burley (control)",
                       _render(bpy_drt, "DRT", DRT_SAMPLES), cycles, BLOCK_TOLERANCE,
                       BLOCK_MAD_TOLERANCE)
