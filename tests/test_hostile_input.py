"""Hostile and broken input (issue 11): each case of tests/hostile_cases.py gets one
clear message in Blender and one stderr line with the documented exit code from the batch
renderer, never a traceback, a hang or a silently black image; the catalogue in
docs/robustness_hostile.md holds these very messages."""
import os

import numpy as np
import pytest

from conftest import ROOT
from hostile_cases import CASES, SKY, markdown_table, run_cases

DOC = os.path.join(ROOT, "docs", "robustness_hostile.md")
# the documented exit codes (drt_addon/batch.py): 3 the file, 4 the render
EXIT = {"missing file": 3, "a file that is not a .blend": 3, "a truncated .blend": 3,
        "a scene with no camera": 4, "an Empty as the scene's camera": 4}


@pytest.fixture(scope="module")
def outcomes(bpy_drt, tmp_path_factory):
    found = run_cases(bpy_drt, str(tmp_path_factory.mktemp("hostile")))
    return {o.name: o for o in found}


@pytest.mark.parametrize("name", [c[0] for c in CASES])
def test_one_clear_message_and_the_documented_exit_code(outcomes, name):
    o = outcomes[name]
    assert o.code == EXIT.get(name, 0), o.batch
    text = " ".join([o.ui, *o.batch, *o.warnings])
    assert "Traceback" not in text and "Error:" not in text
    if name == "a camera that looks away from everything":
        assert o.batch == [] and o.warnings == []           # nothing wrong: no message
        return
    assert len(o.batch) == 1, o.batch
    assert o.batch[0].startswith("drt: error:" if o.code else "drt: warning:"), o.batch
    assert o.ui                                             # and one in Blender
    if o.code == 0:
        assert len(o.warnings) == 1, o.warnings
        assert o.batch[0].removeprefix("drt: warning: ") in o.warnings[0]
    else:
        assert o.pixels is None                             # no image, not a black one


def test_a_camera_looking_away_sees_the_lit_world(outcomes):
    """Not an error: every ray escapes, so every pixel is exactly the world's colour."""
    px = outcomes["a camera that looks away from everything"].pixels
    np.testing.assert_allclose(px, np.broadcast_to(SKY, px.shape), rtol=1e-5)


def test_no_image_is_silently_black(outcomes):
    """An image with no light in it comes with a warning that says why."""
    black = [o for o in outcomes.values() if o.pixels is not None and o.pixels.max() == 0.0]
    assert {o.name for o in black} >= {"an empty scene (a camera, nothing else)",
                                       "objects but no light",
                                       "a camera that looks away from everything, a black "
                                       "world"}
    for o in black:
        assert o.warnings, o.name


def test_broken_node_trees_render_what_is_left(outcomes):
    loop = outcomes["a material whose shader nodes are linked in a loop"]
    assert "'Mix A' -> 'Mix B'" in loop.warnings[0]
    reroute = outcomes["a reroute with nothing linked into it"]
    for o in (loop, reroute):
        assert np.isfinite(o.pixels).all() and o.pixels.max() > 0.05, o.name
    nan = outcomes["NaN and infinite vertex coordinates"]
    assert np.isfinite(nan.pixels).all() and nan.pixels.max() > 0.05
    assert "skipped" in nan.warnings[0]


def test_an_unlinked_surface_is_black_before_the_world(outcomes):
    px = outcomes["a material whose output has nothing linked to Surface"].pixels
    lum = px.mean(axis=2)
    assert lum.min() == 0.0 and lum.max() > 0.2          # the black cube, the sky


def test_a_missing_image_is_pink(outcomes):
    """Cycles' colour for an image without pixels: magenta (it rendered black before)."""
    px = outcomes["an image texture whose file is missing"].pixels.reshape(-1, 3)
    r, g, b = px[px.sum(axis=1).argmax()]
    assert r > 0.05 and b > 0.05 and g < 0.3 * r, (r, g, b)


def test_a_missing_library_names_what_is_missing(outcomes):
    o = outcomes["a linked library that cannot be found"]
    assert "'//lib.blend'" in o.warnings[0] and "Object 'LibCube'" in o.warnings[0]


def test_a_shared_shader_chain_is_read_in_bounded_time(bpy_drt):
    """40 Mix Shaders, each feeding both inputs of the next: read naively, 2^40 paths
    to the output. The export reads at most MAX_SHADER_READS nodes and says so."""
    from drt_addon.export.errors import Reporter
    from drt_addon.export.materials import export_material
    from drt_addon.export.nodes import shader
    bpy = bpy_drt
    mat = bpy.data.materials.new("Chain")
    tree = mat.node_tree
    prev = tree.nodes.new("ShaderNodeBsdfDiffuse").outputs[0]
    for _ in range(40):
        mix = tree.nodes.new("ShaderNodeMixShader")
        tree.links.new(prev, mix.inputs[1])
        tree.links.new(prev, mix.inputs[2])
        prev = mix.outputs[0]
    out = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial")
    tree.links.new(prev, out.inputs["Surface"])
    calls = []
    original = shader._closure

    def counting(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    shader._closure = counting
    try:
        reporter = Reporter()
        export_material(mat, reporter)
    finally:
        shader._closure = original
        bpy.data.materials.remove(mat)
    assert len(calls) <= 2 * shader.MAX_SHADER_READS + 2
    assert any("too deep" in w for w in reporter.warnings), reporter.warnings


def test_the_catalogue_in_the_docs_has_the_real_messages(outcomes):
    with open(DOC) as f:
        doc = f.read()
    assert markdown_table(outcomes.values()) in doc, \
        "docs/robustness_hostile.md is stale: run docs/make_robustness_hostile.py"
