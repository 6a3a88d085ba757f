"""engine.sky_model / engine.sky_texture without Blender: the sun's position conventions
(Cycles' wrapping of elevation and rotation), the sun disc as a light (its mean radiance
and direction), the equirectangular map against the sky's own lookup, Preetham's sky,
and the exporter's Sky Texture reading (Hosek / Wilkie reported, Mapping turns the sun).
Against Cycles renders: tests/test_sky_world_vs_cycles.py."""
import math

import numpy as np
import pytest

from engine import World, sky_model
from engine.kernels.lights import pack_lights
from engine.kernels.lights.batch import world_escaped_batch
from engine.lights import LightSet
from engine.sky_texture import SkyParameters, SkyTexture, normalized_sun, sky_world
from engine.world_light import world_model


@pytest.fixture(scope="module")
def default_sky():
    return SkyTexture(SkyParameters())


def _directions(n, seed=1):
    d = np.random.default_rng(seed).normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1)[:, None]


@pytest.mark.parametrize("elevation, rotation, expected", [
    (0.3, 0.0, (0.3, 2 * math.pi)),
    (0.3, 1.0, (0.3, 2 * math.pi - 1.0)),
    (0.3, -1.0, (0.3, 1.0)),
    # past the zenith: mirrored elevation, the rotation turned by pi
    (2.0, 0.5, (math.pi - 2.0, 2 * math.pi - 0.5 - math.pi)),
    (0.3 + 2 * math.pi, 0.0, (0.3, 2 * math.pi)),
])
def test_sun_position_wraps_as_cycles(elevation, rotation, expected):
    e, r = normalized_sun(elevation, rotation)
    assert e == pytest.approx(expected[0], abs=1e-6)
    assert r == pytest.approx(expected[1], abs=1e-6)


def test_sun_direction_follows_rotation():
    """Rotation 0 puts the sun along +Y; rotating by r turns it towards +X (the sky's
    glow follows it: its brightest direction at the sun's elevation)."""
    for rot in (0.0, math.radians(60.0)):
        sky = SkyTexture(SkyParameters(sun_rotation=rot, sun_disc=False))
        e = math.radians(15.0)
        expected = [math.cos(e) * math.sin(rot), math.cos(e) * math.cos(rot), math.sin(e)]
        np.testing.assert_allclose(sky.sun_vector(), expected, atol=1e-6)
        az = np.linspace(0, 2 * np.pi, 721)[:-1]
        ring = np.stack([np.cos(e) * np.sin(az), np.cos(e) * np.cos(az),
                         np.full_like(az, np.sin(e))], axis=1)
        brightest = az[np.argmax(sky.radiance(ring).sum(1))]
        assert abs((brightest - rot + np.pi) % (2 * np.pi) - np.pi) < math.radians(1.0)


def test_sun_light_is_the_disc_mean(default_sky):
    """The lamp's radiance is the disc's mean over its solid angle: for the default
    0.545-degree sun, the limb darkening's mean (0.8) times the mean of the bottom and
    top pixels (the disc is small enough for both to be linear)."""
    centre, rgb, size = default_sky.sun_light()
    np.testing.assert_allclose(centre, default_sky.sun_vector())
    assert size == pytest.approx(SkyParameters().sun_size)
    expected = 0.8 * 0.5 * (default_sky.bottom + default_sky.top)
    from engine.sky_texture import xyz_to_rgb
    np.testing.assert_allclose(rgb, xyz_to_rgb(expected), rtol=2e-3)
    # and the same disc integrated by brute force over random directions near the sun
    d = _directions(400000, seed=3) * 0.01 + centre
    d /= np.linalg.norm(d, axis=1)[:, None]
    inside = np.arccos(np.clip(d @ centre, -1, 1)) < 0.5 * size
    brute = xyz_to_rgb(default_sky.sun_disc_xyz(d[inside]).mean(0))
    np.testing.assert_allclose(rgb, brute, rtol=0.01)


def test_no_sun_light_without_disc_or_below_the_ground():
    assert SkyTexture(SkyParameters(sun_disc=False)).sun_light() is None
    assert SkyTexture(SkyParameters(sun_elevation=math.radians(-5.0))).sun_light() is None


def test_map_matches_the_sky_lookup(default_sky):
    """The 1024 x 512 map read as DRT reads environment maps against Cycles' own table
    lookup at random directions: measured mean difference 0.09 %, image mean 0.06 %."""
    texture, _ = sky_world(SkyParameters())
    L = pack_lights(LightSet([], 1.0, world=world_model(World(texture=texture))))
    d = _directions(100000)
    ref = default_sky.radiance(d)
    got = world_escaped_batch(L, np.zeros(3), np.ascontiguousarray(d))[0]
    rel = np.abs(got - ref).sum(1) / ref.sum(1)
    assert np.median(rel) < 2e-3 and rel.mean() < 3e-3
    np.testing.assert_allclose(got.mean(0), ref.mean(0), rtol=3e-3)


def test_table_is_symmetric_about_the_sun_and_finite(default_sky):
    t = default_sky.table
    assert t.shape == (256, 512, 3) and np.isfinite(t).all() and (t > 0).all()
    np.testing.assert_array_equal(t, t[:, ::-1])
    # brighter towards the sun (azimuth pi, the middle columns) at its elevation
    row = int((np.sqrt(math.radians(15.0) * 2 / np.pi) * 0.5 + 0.5) * 256)
    assert t[row, 256, 1] > 2.0 * t[row, 0, 1]


def test_denser_air_and_lower_sun_change_the_sky():
    """Twice the air scatters more light into the zenith (measured +43 %); a sun at the
    horizon makes it far darker than at 15 degrees (measured -84 %)."""
    up = np.array([[0.0, 0.0, 1.0]])
    base = SkyTexture(SkyParameters(sun_disc=False)).radiance(up)[0]
    dense = SkyTexture(SkyParameters(sun_disc=False, air_density=2.0)).radiance(up)[0]
    low = SkyTexture(SkyParameters(sun_disc=False, sun_elevation=0.0)).radiance(up)[0]
    assert dense.sum() > 1.2 * base.sum()
    assert low.sum() < 0.5 * base.sum()
    print("zenith RGB", base, "air x2", dense, "sun at the horizon", low)


def test_preetham_sky_is_brightest_near_the_sun():
    sun = np.array([0.0, 0.6, 0.8])
    sky = SkyTexture(SkyParameters(sky_type="PREETHAM", sun_direction=tuple(sun)))
    assert sky.sun_light() is None
    d = _directions(20000)
    d = d[d[:, 2] > 0.05]
    rgb = sky.radiance(d)
    assert np.isfinite(rgb).all() and (rgb >= 0).all() and rgb.max() > 0
    near = d[np.argmax(rgb.sum(1))]
    assert near @ sun > math.cos(math.radians(20.0))


def test_hosek_wilkie_is_not_modelled():
    with pytest.raises(NotImplementedError):
        SkyTexture(SkyParameters(sky_type="HOSEK_WILKIE"))


def test_earth_intersection_angle():
    # seen from 100 m the ground's edge lies 0.32 degrees below the horizon
    assert math.degrees(sky_model.earth_intersection_angle(100.0)) == pytest.approx(
        0.321, abs=0.001)
