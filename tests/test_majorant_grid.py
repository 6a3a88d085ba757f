"""Majorant grids (engine.kernels.majorant_grid, majorant_bounds): free flights through a
heterogeneous medium taken cell by cell, at the rate each cell needs; no Blender.

- The query: along random rays through a box (at scales 1e-3, 1 and 1e4), the intervals
  cell_majorant hands out partition the ray's way through the box, each carrying the
  majorant of the cell that holds its middle, and 0 outside the box until its entry.
- A thin shell: absorber in a spherical shell a third of a cell thick, whose peaks
  a cell's own 8 sample points miss. At random points of the shell the density exceeds
  its cell's majorant (where the trackers' weights turn negative: fireflies) at almost
  none of them with each cell taking its neighbours' samples too, and at many without
  (the control).
- A puff: a ball of absorber of radius 0.25 whose density falls linearly from its
  centre, inside a unit sphere of medium. Seen through its centre, it transmits
  exp(-sigma a^2) (the chord's integral) with the grid as without it (both unbiased),
  and with the grid the tracking runs the program at least 3 times less often.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import engine.integrators.compiled_path as compiled_path
import engine.kernels.majorant_bounds as majorant_bounds
from engine import RenderSettings, Volume, render
from engine.kernels.majorant_bounds import point_values
from engine.kernels.majorant_grid import (MG_CELLS, MG_HI, MG_LO, MG_RES, RES, WIDTH,
                                          cell_majorant)
from engine.kernels.volume import V_HET
from engine.nodes import context as C
from engine.nodes import converter_nodes as CV
from engine.nodes import input_nodes as I
from engine.nodes import vector_nodes as VN
from engine.nodes.pack import MAJORANTS
from engine.nodes.program import ProgramBuilder
from engine.render import RenderContext
from test_heterogeneous_volumes import _sphere_scene


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e4])
def test_cell_intervals_partition_the_ray(scale):
    rng = np.random.default_rng(4)
    lo, hi = np.array([-1.0, -0.5, -2.0]) * scale, np.array([1.5, 0.5, 1.0]) * scale
    maj = np.zeros((1, WIDTH))
    maj[0, MG_LO:MG_LO + 3], maj[0, MG_HI:MG_HI + 3], maj[0, MG_RES] = lo, hi, RES
    maj[0, MG_CELLS:] = rng.uniform(1.0, 2.0, RES ** 3)
    size = (hi - lo) / RES
    for _ in range(200):
        o = rng.uniform(lo - 2 * (hi - lo), hi + 2 * (hi - lo))
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        s, inside = 0.0, 0.0
        for _ in range(4 * RES + 8):
            mu, end = cell_majorant(maj, 0, *o, *d, s)
            assert end > s
            if not math.isfinite(end):
                assert mu == 0.0
                break
            mid = o + d * 0.5 * (s + end)
            c = np.floor((mid - lo) / size).astype(int)
            if ((c >= 0) & (c < RES)).all():
                assert mu == maj[0, MG_CELLS + (c[0] * RES + c[1]) * RES + c[2]]
                inside += end - s
            else:
                assert mu == 0.0
            s = end
        else:
            pytest.fail("the ray never left the box")
        # the intervals inside add up to the ray's chord through the box
        with np.errstate(divide="ignore"):
            a, b = (lo - o) / d, (hi - o) / d
        t0, t1 = max(np.minimum(a, b).max(), 0.0), np.maximum(a, b).min()
        assert inside == pytest.approx(max(t1 - t0, 0.0), rel=1e-6, abs=1e-9 * scale)


def _puff(sigma, radius):
    """volume_absorption = sigma x max(radius - |p|, 0), p in object space."""
    b = ProgramBuilder()
    p = b.emit(I.IN_HIT3, "vector", [C.H_OBJECT], varying=True)
    one = b.constant(1.0)
    r = b.emit(VN.VEC_MATH_VALUE, "float", [p, p, p, one, VN.VECTOR_OPS.index("LENGTH")])
    x = b.emit(CV.CV_MATH, "float", [b.constant(radius), r, b.constant(0.0),
                                     CV.MATH_OPS.index("SUBTRACT"), 0])
    x = b.emit(CV.CV_MATH, "float", [x, b.constant(0.0), b.constant(0.0),
                                     CV.MATH_OPS.index("MAXIMUM"), 0])
    c = b.constant(tuple(sigma), "vector")
    b.output("volume_absorption", b.emit(VN.VEC_MATH, "vector",
                                         [c, c, c, x, VN.VECTOR_OPS.index("SCALE")]))
    return b.build()


def _render_puff(monkeypatch, grids):
    sigma, radius = np.array([8.0, 16.0, 32.0]), 0.25
    if not grids:
        bound = compiled_path.bound_majorants
        monkeypatch.setattr(compiled_path, "bound_majorants",
                            lambda *a, **k: bound(*a, **{**k, "grids": False}))
    scene = _sphere_scene(Volume(absorption=tuple(sigma * 0.01)), _puff(sigma, radius),
                          lens=4000.0)
    settings = RenderSettings(samples=512, seed=3)
    ctx = RenderContext(scene, settings)
    try:
        film, _ = render(scene, settings, context=ctx)
        runs = int(ctx.integrator.het_runs[0])
    finally:
        ctx.close()
        monkeypatch.undo()
    return film.mean().mean(axis=(0, 1)), runs, np.exp(-sigma * radius ** 2)


def test_puff_transmits_the_same_with_fewer_program_runs(monkeypatch):
    with_grid, runs_grid, expected = _render_puff(monkeypatch, True)
    without, runs_global, _ = _render_puff(monkeypatch, False)
    print("grid", with_grid, runs_grid, "global", without, runs_global, "expected", expected)
    np.testing.assert_allclose(with_grid, expected, rtol=0.05, atol=0.004)
    np.testing.assert_allclose(without, expected, rtol=0.05, atol=0.004)
    assert runs_grid * 3 < runs_global


def _shell(sigma, radius, width):
    """volume_absorption = sigma x max(1 - | |p| - radius | / width, 0): a spherical
    shell of absorber 2 width thick, densest at `radius` (p in object space)."""
    b = ProgramBuilder()
    p = b.emit(I.IN_HIT3, "vector", [C.H_OBJECT], varying=True)
    one = b.constant(1.0)
    zero = b.constant(0.0)

    def math_op(op, x, y):
        return b.emit(CV.CV_MATH, "float", [x, y, zero, CV.MATH_OPS.index(op), 0])

    r = b.emit(VN.VEC_MATH_VALUE, "float", [p, p, p, one, VN.VECTOR_OPS.index("LENGTH")])
    x = math_op("ABSOLUTE", math_op("SUBTRACT", r, b.constant(radius)), zero)
    x = math_op("MAXIMUM", math_op("SUBTRACT", one, math_op("DIVIDE", x,
                                                            b.constant(width))), zero)
    c = b.constant(tuple(sigma), "vector")
    b.output("volume_absorption", b.emit(VN.VEC_MATH, "vector",
                                         [c, c, c, x, VN.VECTOR_OPS.index("SCALE")]))
    return b.build()


def _shell_exceedance(monkeypatch, neighbours):
    """The fraction of random points in the thin shell whose density exceeds their
    cell's majorant."""
    if not neighbours:
        monkeypatch.setattr(majorant_bounds, "with_neighbours", lambda top: top)
    cell = 2.0 * 1.0 / RES                   # the box of the unit sphere, per cell
    radius, width = 0.62, cell / 6.0
    scene = _sphere_scene(Volume(absorption=(0.01, 0.01, 0.01)),
                          _shell((40.0, 40.0, 40.0), radius, width))
    ctx = RenderContext(scene, RenderSettings(samples=1, seed=3))
    try:
        it = ctx.integrator
        m = int(np.nonzero(it.vol[:, V_HET])[0][0])
        row = it.textures[MAJORANTS][m]
        rng = np.random.default_rng(7)
        d = rng.normal(size=(20000, 3))
        d /= np.linalg.norm(d, axis=1)[:, None]
        pts = d * (radius + rng.uniform(-0.5, 0.5, (len(d), 1)) * width)
        density = point_values(it.vol, m, it.textures, it.geometry[9], it.camera, pts)
        lo, hi = row[MG_LO:MG_LO + 3], row[MG_HI:MG_HI + 3]
        c = np.clip(((pts - lo) / (hi - lo) * RES).astype(int), 0, RES - 1)
        mu = row[MG_CELLS + (c[:, 0] * RES + c[:, 1]) * RES + c[:, 2]]
    finally:
        ctx.close()
        monkeypatch.undo()
    assert density.min() > 19.0              # the points are in the shell's dense half
    return float(np.mean(density > mu))


def test_cells_take_their_neighbours_peaks(monkeypatch):
    with_n = _shell_exceedance(monkeypatch, True)
    without = _shell_exceedance(monkeypatch, False)
    print(f"density above the majorant at {with_n:.2%} of the shell's points "
          f"({without:.2%} from each cell's own samples)")
    assert with_n < 0.005
    assert without > 0.05


def test_neighbourhood_is_the_three_by_three_by_three_box():
    """with_neighbours against the maximum over each cell's box of up to 27 cells (the
    grid's edges clipped), computed directly; it uses NumPy alone, so the add-on in
    another Blender needs nothing more."""
    rng = np.random.default_rng(1)
    top = rng.random(RES ** 3) * (rng.random(RES ** 3) < 0.05)
    got = majorant_bounds.with_neighbours(top).reshape(RES, RES, RES)
    grid = top.reshape(RES, RES, RES)
    for i, j, k in rng.integers(0, RES, (300, 3)):
        box = grid[max(i - 1, 0):i + 2, max(j - 1, 0):j + 2, max(k - 1, 0):k + 2]
        assert got[i, j, k] == box.max()
