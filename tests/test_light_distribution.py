"""Cycles' light distribution without the light tree (engine.light_distribution): the
pick probabilities of a LightSet's entries, checked against the rule Cycles' scene/
light.cpp (device_update_distribution) builds them by, on lamps, the world, a Sky
Texture's sun and emissive triangles. The image it makes is compared with Cycles in
tests/test_light_distribution_vs_cycles.py."""
import numpy as np
import pytest

from engine import lights as L
from engine.light_distribution import cycles_distribution
from engine.mesh_lights import EmissiveTriangles
from engine.scene import PointLight, SunLight


def test_lamps_alike_whatever_their_power():
    """A 1 mW lamp is picked as often as a 1 kW one (Cycles weighs lights alike)."""
    lamps = [PointLight((0, 0, 1), (1e-3,) * 3), PointLight((0, 1, 1), (1e3,) * 3),
             PointLight((1, 0, 1), (40.0,) * 3)]
    ls = L.LightSet(lamps, 10.0)
    np.testing.assert_allclose(ls.select_pdf, [1 / 3] * 3, rtol=1e-12)


def test_triangles_by_area_lights_share_the_other_half():
    """With lamps and triangles, the triangles share one half by area (not by emission)
    and the lamps and the world the other half evenly."""
    v0 = np.array([[0, 0, 0], [0, 0, 0]], float)
    v1 = np.array([[1, 0, 0], [3, 0, 0]], float)
    v2 = np.array([[0, 1, 0], [0, 1, 0]], float)
    tris = EmissiveTriangles(v0, v1, v2, radiance=[[100, 100, 100], [1, 1, 1]],
                             prim_ids=[0, 1], n_prims_total=2)
    lamps = [PointLight((0, 0, 1), (5.0,) * 3)]
    ls = L.LightSet(lamps, 10.0, mesh_lights=tris, world=(0.2, 0.2, 0.2))
    # entries: the lamp, the world, then the triangles (areas 0.5 and 1.5)
    np.testing.assert_allclose(ls.select_pdf, [0.25, 0.25, 0.125, 0.375], rtol=1e-12)
    assert ls.cdf[-1] == 1.0


def test_triangles_alone_by_area():
    p = cycles_distribution(0, None, None, [1.0, 3.0, 0.0])
    np.testing.assert_allclose(p, [0.25, 0.75, 0.0])


def test_sky_sun_takes_four_fifths_of_the_world_share():
    """A Sky Texture's sun disc is the world's light in Cycles, which sends 4/5 of the
    world's samples to it: the world and its sun share one light's pick."""
    sun = SunLight((0.0, 0.0, -1.0), (3.0,) * 3, angle=0.01)
    lamp = PointLight((0, 0, 1), (5.0,) * 3)
    ls = L.LightSet([lamp, sun], 10.0, world=(0.1, 0.1, 0.1), world_sun=sun)
    k_sun = ls.sources.index(sun)
    k_world = ls.sources.index(L.WORLD)
    assert ls.select_pdf[0] == pytest.approx(0.5)
    assert ls.select_pdf[k_sun] == pytest.approx(0.4)
    assert ls.select_pdf[k_world] == pytest.approx(0.1)
    # a sun lamp that is not the world's is a light of its own
    other = L.LightSet([lamp, sun], 10.0, world=(0.1, 0.1, 0.1))
    np.testing.assert_allclose(other.select_pdf, [1 / 3] * 3, rtol=1e-12)


def test_dark_lights_left_out():
    """A lamp of no power is no entry, as Cycles' has_contribution leaves it out."""
    lamps = [PointLight((0, 0, 1), (0.0,) * 3), PointLight((0, 1, 1), (2.0,) * 3)]
    ls = L.LightSet(lamps, 10.0)
    assert len(ls) == 1 and ls.select_pdf[0] == 1.0
