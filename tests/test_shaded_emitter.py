"""Emission that varies over a surface, light-sampled where it lands
(engine.kernels.shaded_emitter), without Blender: which triangles are such lights, what
it costs a scene without them, the sampled point's barycentrics, and that evaluating the
material at the sampled point gives what a constant emitter gives when the program's
value is that constant. The comparison with Cycles is tests/test_mixed_emission_vs_cycles.py."""
from __future__ import annotations

import dataclasses

import numpy as np

from engine import Material, RenderContext, RenderSettings, render
from engine.kernels.lights.pack import (EMISSION_SHADED, TRI_E1, TRI_E2, TRI_PRIM, TRI_V0,
                                        TRI_VISIBILITY)
from engine.kernels.shaded_emitter import EmitterShading, barycentrics, radiance
from engine.nodes import context as C
from engine.nodes import input_nodes as I
from engine.nodes import texture_nodes as X
from engine.nodes.pack import NREGS
from engine.nodes.program import ProgramBuilder
from engine_scenes import cornell_box, quad

GLOW = (6.0, 5.0, 4.0)


def _checker_emission(a, b):
    """A program whose emission is a Checker of colours a and b (one colour: varying in
    form, constant in value)."""
    pb = ProgramBuilder()
    gen = pb.emit(I.IN_HIT3, "vector", [C.H_GENERATED], varying=True)
    pb.output("emission", pb.emit(X.TEX_CHECKER_COLOR, "color",
                                  [gen, pb.constant(a), pb.constant(b), pb.constant(4.0)]))
    return pb.build()


def _lit_box(emitter: Material):
    """The Cornell box lit by a 0.6 m emissive panel under its ceiling (no lamp)."""
    scene = cornell_box(24, 24)
    scene.lights = []
    scene.materials.append(emitter)
    scene.meshes.append(quad((0, 0, 1.97), (0.3, 0, 0), (0, -0.3, 0), "panel",
                             len(scene.materials) - 1))
    return scene


def _shaded_entries(scene, settings):
    ctx = RenderContext(scene, settings)
    try:
        vis = ctx.integrator.lights[TRI_VISIBILITY]
        return int(((vis & EMISSION_SHADED) != 0).sum()), len(vis), ctx.integrator.features[4]
    finally:
        ctx.close()


def test_only_varying_emitters_are_shaded_and_only_their_scenes_pay():
    settings = RenderSettings(samples=1)
    plain = _lit_box(Material("panel", (0, 0, 0), emission=GLOW))
    shaded, entries, feature = _shaded_entries(plain, settings)
    assert entries == 2 and shaded == 0 and feature is None   # compiled without it
    varying = _lit_box(Material("panel", (0, 0, 0), emission=GLOW,
                                shader=_checker_emission(GLOW, (0.5, 0.5, 0.5))))
    shaded, entries, feature = _shaded_entries(varying, settings)
    assert entries == 2 and shaded == 2 and feature is not None


def test_barycentrics_of_points_on_the_triangle():
    rng = np.random.default_rng(3)
    v0, e1, e2 = rng.normal(size=(3, 3))
    L = [None] * (max(TRI_V0, TRI_E1, TRI_E2) + 1)
    L[TRI_V0], L[TRI_E1], L[TRI_E2] = v0[None], e1[None], e2[None]
    L = tuple(np.zeros((0,)) if a is None else a for a in L)
    for _ in range(50):
        u, v = rng.uniform(size=2)
        if u + v > 1.0:
            u, v = 1.0 - u, 1.0 - v
        q = v0 + u * e1 + v * e2
        bu, bv = barycentrics(L, 0, *q)
        assert abs(bu - u) < 1e-9 and abs(bv - v) < 1e-9


def test_a_program_of_constant_value_lights_as_the_constant_does():
    """The same panel as a plain emitter and as a program that says the same colour
    everywhere (a Checker of one colour): the shaded light samples evaluate the program
    at each sampled point, the same light in, the same image out (same random numbers);
    a two-colour Checker lights the box differently."""
    settings = RenderSettings(samples=4, max_bounces=3)
    plain = render(_lit_box(Material("panel", (0, 0, 0), emission=GLOW)), settings)[0].mean()
    same = render(_lit_box(Material("panel", (0, 0, 0), emission=GLOW,
                                    shader=_checker_emission(GLOW, GLOW))), settings)[0].mean()
    np.testing.assert_allclose(same, plain, rtol=1e-9, atol=1e-12)
    dimmer = dataclasses.replace(Material("panel", (0, 0, 0), emission=GLOW),
                                 shader=_checker_emission(GLOW, (0.5, 0.5, 0.5)))
    checker = render(_lit_box(dimmer), settings)[0].mean()
    assert checker.mean() < 0.9 * plain.mean()


def test_a_light_sample_carries_the_emission_at_its_point():
    """`radiance` at points across a panel whose emission is a Checker of a colour and
    black: each point carries its own cell's colour (the entry's estimate is their
    average, which no point carries). The panel belongs to no object, so its Generated
    coordinates are 0.5 x + 0.5 (engine.nodes.context), and the Checker's cells (a
    quarter of that wide) meet once on it, at x = 0."""
    bright = (12.0, 10.0, 8.0)
    scene = _lit_box(Material("panel", (0, 0, 0), emission=GLOW,
                              shader=_checker_emission(bright, (0.0, 0.0, 0.0))))
    ctx = RenderContext(scene, RenderSettings(samples=1))
    try:
        it = ctx.integrator
        L = it.lights
        es = EmitterShading(it.textures, it.params, it.geometry, it.textures, it.emission,
                            np.zeros(C.N_HIT), np.zeros(max(it.textures[NREGS][0], 1)))
        counts, info = np.zeros((1, 3), np.int64), (np.zeros(1, np.int64), np.zeros((1, 2)))
        entries = np.flatnonzero(L[TRI_VISIBILITY] & EMISSION_SHADED)
        receiver = np.array([0.0, 0.0, 1.0])
        seen = []
        for x in (np.arange(12) + 0.5) / 12 * 0.6 - 0.3:       # across the panel
            q = np.array([x, 0.013, 1.97])
            for j in entries:
                u, v = barycentrics(L, j, *q)
                on = L[TRI_V0][j] + u * L[TRI_E1][j] + v * L[TRI_E2][j]
                if np.abs(on - q).max() < 1e-9:
                    break
            w = q - receiver
            dist = float(np.linalg.norm(w))
            w /= dist
            seen.append(radiance(es, L, int(L[TRI_PRIM][j]), counts, info, 0, 1,
                                 *receiver, *w, dist, 0.0, *GLOW))
    finally:
        ctx.close()
    seen = np.array(seen)
    lit = (seen == bright).all(axis=1)
    assert (lit | (seen == 0.0).all(axis=1)).all(), seen
    assert lit.sum() == 6 and np.abs(np.diff(lit.astype(int))).sum() == 1, lit
