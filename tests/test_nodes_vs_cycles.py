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
import node_cases_procedural
import node_probe

SAMPLES = 64
# Spheres: Fresnel's bright rim against the black background and a dim centre make the
# rim's antialiasing noise large next to the tile mean; 256 samples bring it under 3%.
SPHERE_SAMPLES = 256
MEAN_TOL = 0.01
BLOCK_TOL = 0.03
PIXEL_TOL = 0.03

FAMILIES = {**node_cases.FAMILIES, **node_cases_procedural.FAMILIES}
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
