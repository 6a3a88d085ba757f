"""Shader programs in the engine, without Blender: building and folding programs, a
program driving a material at every hit (one that gives, per hit, a plain material's
values renders that material's image), and the cost of programs paid only by scenes that
have them."""
from __future__ import annotations

import dataclasses

import numpy as np
from engine import RenderContext, RenderSettings
from engine.nodes import context as C
from engine.nodes import converter_nodes as CV
from engine.nodes import input_nodes as I
from engine.nodes import texture_nodes as X
from engine.nodes.program import ProgramBuilder
from engine_scenes import cornell_box


def checker_program(scale=4.0):
    """Base colour = a Checker on the generated coordinates; roughness = 0.2 + 0.5 x its
    Fac."""
    b = ProgramBuilder()
    gen = b.emit(I.IN_HIT3, "vector", [C.H_GENERATED], varying=True)
    color = b.emit(X.TEX_CHECKER_COLOR, "color", [gen, b.constant((0.9, 0.2, 0.1)),
                                                  b.constant((0.1, 0.3, 0.9)),
                                                  b.constant(scale)])
    fac = b.emit(X.TEX_CHECKER_FAC, "float", [gen, b.constant(scale)])
    rough = b.emit(CV.CV_MATH, "float", [fac, b.constant(0.5), b.constant(0.2),
                                         CV.MATH_OPS.index("MULTIPLY_ADD"), 0])
    b.output("base_color", color)
    b.output("roughness", rough)
    return b.build(), color, rough


def test_constant_folding_and_evaluation():
    b = ProgramBuilder()
    two = b.constant(2.0)
    power = b.emit(CV.CV_MATH, "float", [two, b.constant(10.0), two,
                                         CV.MATH_OPS.index("POWER"), 0])
    varying = b.emit(I.IN_HIT1, "float", [C.H_BACKFACING], varying=True)
    prog = b.build()
    assert not power.varying and varying.varying
    assert prog.constant_value(power) == 1024.0
    hits = C.hit_rows(np.zeros((2, 3)), np.tile([0.0, 0.0, 1.0], (2, 1)),
                      front=np.array([True, False]))
    assert list(prog.evaluate(varying, hits)) == [0.0, 1.0]


def test_checker_program_values():
    prog, color, rough = checker_program()
    # generated coordinates of the identity object: 0.5 p + 0.5
    pos = np.array([[-0.9, -0.9, 0.1], [-0.4, -0.9, 0.1]])      # cells 0 and 1 along x
    hits = C.hit_rows(pos, np.tile([0.0, 0.0, 1.0], (2, 1)))
    c = prog.evaluate(color, hits)
    r = prog.evaluate(rough, hits)
    # z = 0.5 -> cell 2 (even); x cells 0 / 1, y cell 0
    assert np.allclose(c[0], (0.1, 0.3, 0.9)) and np.allclose(c[1], (0.9, 0.2, 0.1))
    assert np.allclose(r, (0.2, 0.7))


def _box(with_program):
    scene = cornell_box(24, 24)
    if with_program:
        prog, _, _ = checker_program()
        scene.materials[0] = dataclasses.replace(scene.materials[0], shader=prog)
    return scene


def test_programs_cost_only_the_scenes_that_have_them():
    settings = RenderSettings(samples=1)
    plain = RenderContext(_box(False), settings)
    assert not plain.materials.any_programs
    integ = plain.integrator
    assert integ.geometry[8].size == 0 and integ.geometry[9].size == 0       # no objects
    assert integ.geometry[10].size == 0 and integ.geometry[11].size == 0     # no attributes
    assert integ.textures[8][:, 1].sum() == 0                                # no program
    textured = RenderContext(_box(True), settings)
    assert textured.materials.any_programs
    assert textured.integrator.textures[8][0, 1] > 0


def uniform_checker_program(color, roughness):
    """A program that varies per hit in form but not in value: a Checker of one colour
    twice, and roughness = fac x 0 + `roughness`."""
    b = ProgramBuilder()
    gen = b.emit(I.IN_HIT3, "vector", [C.H_GENERATED], varying=True)
    c = b.emit(X.TEX_CHECKER_COLOR, "color", [gen, b.constant(color), b.constant(color),
                                              b.constant(4.0)])
    fac = b.emit(X.TEX_CHECKER_FAC, "float", [gen, b.constant(4.0)])
    rough = b.emit(CV.CV_MATH, "float", [fac, b.constant(0.0), b.constant(roughness),
                                         CV.MATH_OPS.index("MULTIPLY_ADD"), 0])
    b.output("base_color", c)
    b.output("roughness", rough)
    return b.build()


def test_program_driven_material_renders_as_its_per_hit_parameters():
    """A material whose program gives, at every hit, the values a plain material holds
    (a Checker of one colour, a roughness computed from it) renders the plain
    material's image, through the per-hit program path (the program is run: its outputs
    are varying); the Checker of two colours renders another image."""
    from engine import render
    settings = RenderSettings(samples=4, max_bounces=3)
    colour, roughness = (0.6, 0.5, 0.4), 0.3
    plain = cornell_box(24, 24)
    plain.materials[0] = dataclasses.replace(plain.materials[0], base_color=colour,
                                             roughness=roughness)
    same = cornell_box(24, 24)
    same.materials[0] = dataclasses.replace(
        same.materials[0], shader=uniform_checker_program(colour, roughness))
    ctx = RenderContext(same, settings)
    assert ctx.integrator.textures[8][0, 1] > 0          # the program runs at each hit
    ctx.close()
    a, b = render(plain, settings)[0].mean(), render(same, settings)[0].mean()
    np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-12)
    checker = render(_box(True), settings)[0].mean()
    assert np.abs(checker - a).mean() > 0.01 * a.mean()
