"""Where a light can reach along a ray (engine/kernels/lights/lit_segment.py), the range
equiangular sampling draws its distances from, and how far a ray's medium reaches.

- A spot's range holds every point the lamp lights, for delta, sphere and disc spots:
  the oracle is the distance from the point to the spot's cone, at most the lamp's
  radius (a ray leaving any point of the lamp within the cone's angle), computed in
  closed form without the module's shifted apex. For a delta spot the range is tight:
  it ends where the ray crosses the cone or the segment ends. An area lamp's range is
  the ray's part in front of its plane.
- The equiangular density over a clipped range integrates to one.
- A ray that reaches nothing goes on through the world's volume to infinity, past the
  camera's clip end, as in Cycles (whose missed rays end their volume segment at
  FLT_MAX): an absorbing world hides the sky whatever the clip end, and an emitting one
  shines E / sigma_t. Before, DRT ended camera rays' volume at the clip end and saw
  the sky through the rest (smoke.blend, a public file: +51 %).
- Shadow rays towards a sun or the world are endless too: through a volume that fills
  the world no sun light arrives (Cycles renders such a floor black; DRT let four scene
  radii of fog attenuate it, 0.81 of the light at density 0.01), while a lamp with a
  position lights the floor through exp(-sigma_t d) of it.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from engine import Camera, Material, RenderSettings, Scene, Volume, World, render
from engine.kernels import equiangular as eq
from engine.kernels.lights import pack_lights
from engine.kernels.lights.lit_segment import cone_range, lit_range
from engine.lights import LightSet
from engine.scene.lights import AreaLight, PointLight, SunLight
from engine_scenes import look_at, quad


def _cone_distance(x, c, a, half):
    """The distance from point x to the solid cone of apex c, unit axis a, half angle
    `half` (< 90 degrees)."""
    v = x - c
    n = np.linalg.norm(v)
    if n == 0.0:
        return 0.0
    phi = math.acos(min(max(float(v @ a) / n, -1.0), 1.0))
    if phi <= half:
        return 0.0
    if phi - half >= 0.5 * math.pi:
        return n
    return n * math.sin(phi - half)


def _spot(rng, radius, soft):
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    size = rng.uniform(math.radians(4.0), math.radians(170.0))
    pos = rng.uniform(-2.0, 2.0, 3)
    light = PointLight(tuple(pos), (100.0, 100.0, 100.0), radius=radius, spot_size=size,
                       spot_blend=rng.uniform(0.0, 1.0), direction=tuple(axis),
                       soft_falloff=soft)
    return light, pos, axis, 0.5 * size


@pytest.mark.parametrize("radius,soft", [(0.0, False), (0.3, False), (0.3, True)])
def test_a_spots_range_holds_every_point_it_lights(radius, soft):
    rng = np.random.default_rng(11)
    checked = inside = 0
    for _ in range(200):
        light, pos, axis, half = _spot(rng, radius, soft)
        L = pack_lights(LightSet([light], 10.0))
        for _ in range(10):
            o = rng.uniform(-6.0, 6.0, 3)
            d = rng.normal(size=3)
            d /= np.linalg.norm(d)
            t_max = math.inf if rng.random() < 0.5 else rng.uniform(0.5, 20.0)
            lo, hi = lit_range(L, 0, *o, *d, 0.0, t_max, 0.5)
            far = min(t_max, 40.0)
            for t in np.concatenate([np.linspace(0.0, far, 201), rng.uniform(0, far, 50)]):
                x = o + t * d
                lit = (half >= 0.5 * math.pi - 2e-3
                       or _cone_distance(x, pos, axis, half) <= radius * (1 - 1e-9))
                checked += 1
                if lit:
                    inside += 1
                    assert lo <= t <= hi, (t, lo, hi, half, radius)
    print(f"{checked} points, {inside} lit")
    assert inside > checked // 10                 # the check saw lit points


def test_a_delta_spots_range_ends_on_the_cone_or_the_segment():
    rng = np.random.default_rng(12)
    empty = clipped = 0
    for _ in range(400):
        light, pos, axis, half = _spot(rng, 0.0, False)
        if half > math.radians(80.0):
            continue
        L = pack_lights(LightSet([light], 10.0))
        o = rng.uniform(-6.0, 6.0, 3)
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        lo, hi = lit_range(L, 0, *o, *d, 0.0, 30.0, 0.5)
        if lo > hi:
            empty += 1
            # nothing of the segment is lit
            for t in np.linspace(0.0, 30.0, 301):
                assert _cone_distance(o + t * d, pos, axis, half) > 0.0
            continue
        for end, edge in ((lo, 0.0), (hi, 30.0)):
            if end != edge:
                clipped += 1
                # on the (slightly widened) cone: the angle from the axis is the half angle
                v = o + end * d - pos
                angle = math.acos(np.clip(v @ axis / np.linalg.norm(v), -1, 1))
                assert angle == pytest.approx(half + 1e-3, abs=1e-6)
        mid = o + 0.5 * (lo + hi) * d
        assert _cone_distance(mid, pos, axis, half + 2e-3) == 0.0
    print(f"empty {empty}, ends on the cone {clipped}")
    assert empty > 20 and clipped > 100


def test_cone_range_of_a_ray_along_the_axis_and_through_the_apex():
    # along the axis from behind the apex: lit from the apex on, to infinity
    lo, hi = cone_range(0.0, 0.0, 0.0, 0.0, 0.0, 1.0, math.cos(0.3), 0.0, 0.0, -5.0,
                        0.0, 0.0, 1.0, 0.0, math.inf)
    assert lo == pytest.approx(5.0) and hi == math.inf
    # against the axis: lit until the apex
    lo, hi = cone_range(0.0, 0.0, 0.0, 0.0, 0.0, 1.0, math.cos(0.3), 0.0, 0.0, 5.0,
                        0.0, 0.0, -1.0, 0.0, math.inf)
    assert lo == 0.0 and hi == pytest.approx(5.0)
    # across the cone's mouth at height 2: |x| <= 2 tan(0.3)
    lo, hi = cone_range(0.0, 0.0, 0.0, 0.0, 0.0, 1.0, math.cos(0.3), -3.0, 0.0, 2.0,
                        1.0, 0.0, 0.0, 0.0, math.inf)
    assert lo == pytest.approx(3.0 - 2.0 * math.tan(0.3))
    assert hi == pytest.approx(3.0 + 2.0 * math.tan(0.3))
    # the backward nappe is not lit
    lo, hi = cone_range(0.0, 0.0, 0.0, 0.0, 0.0, 1.0, math.cos(0.3), -3.0, 0.0, -2.0,
                        1.0, 0.0, 0.0, 0.0, math.inf)
    assert lo > hi


def test_an_area_lamps_range_is_in_front_of_it():
    m = np.eye(4)
    m[:3, 3] = (0.0, 0.0, 3.0)                  # emits along -Z from z = 3
    L = pack_lights(LightSet([AreaLight(m, (100.0, 100.0, 100.0), size_x=2.0)], 10.0))
    lo, hi = lit_range(L, 0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, math.inf, 0.5)
    assert lo == 0.0 and hi == pytest.approx(3.0, abs=1e-5)
    lo, hi = lit_range(L, 0, 5.0, 1.0, 6.0, 0.0, 0.0, -1.0, 0.0, math.inf, 0.5)
    assert lo == pytest.approx(3.0, abs=1e-5) and hi == math.inf
    lo, hi = lit_range(L, 0, 0.0, 0.0, 4.0, 1.0, 0.0, 0.0, 0.0, math.inf, 0.5)
    assert lo > hi                               # behind it, parallel to its plane
    # a point lamp is not clipped
    L = pack_lights(LightSet([PointLight((0.0, 0.0, 3.0), (1.0, 1.0, 1.0))], 10.0))
    assert lit_range(L, 0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 7.0, 0.5) == (0.0, 7.0)


@pytest.mark.parametrize("t_lo,t_hi", [(1.0, 4.0), (2.5, math.inf), (0.2, 1.9)])
def test_the_equiangular_density_on_a_clipped_range_integrates_to_one(t_lo, t_hi):
    ray, c = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0), (2.0, 0.7, 0.0)
    total = integrate.quad(lambda t: eq.pdf(*ray, *c, t_lo, t_hi, t), t_lo, t_hi,
                           points=[2.0] if t_hi < math.inf else None, limit=400)[0]
    assert total == pytest.approx(1.0, abs=1e-6)
    assert eq.pdf(*ray, *c, t_lo, t_hi, 0.5 * t_lo) == 0.0
    for u in (0.0, 0.3, 0.999):
        t, p = eq.sample(*ray, *c, t_lo, t_hi, u)
        assert t_lo <= t <= t_hi and p == pytest.approx(eq.pdf(*ray, *c, t_lo, t_hi, t))


def _world_fog(volume, clip_end):
    """A camera in a world filled by `volume` under a white sky, one small quad behind
    it (a scene has geometry), with the camera's clip end at `clip_end`."""
    cam = Camera(look_at((0.0, 0.0, 0.0), (0.0, 1.0, 0.0)), lens=35.0, clip_end=clip_end)
    behind = quad((0.0, -50.0, 0.0), (0.1, 0.0, 0.0), (0.0, 0.0, 0.1), material=0)
    scene = Scene(cam, 8, 8, [behind], [Material("grey", (0.5, 0.5, 0.5))], [],
                  World((1.0, 1.0, 1.0), volume=volume))
    film, stats = render(scene, RenderSettings(samples=4, seed=1))
    assert stats.nonfinite_samples == 0
    return film.mean()


@pytest.mark.parametrize("clip_end", [2.0, 10.0, 1000.0])
def test_missed_rays_go_on_through_the_world_volume_past_the_clip_end(clip_end):
    absorbing = Volume(absorption=(0.1, 0.1, 0.1))
    # the sky is not seen through an infinite absorber (before: exp(-0.1 clip_end))
    assert np.abs(_world_fog(absorbing, clip_end)).max() < 1e-12
    glowing = Volume(absorption=(0.1, 0.2, 0.4), emission=(1.0, 1.0, 1.0))
    image = _world_fog(glowing, clip_end)
    np.testing.assert_allclose(image, np.broadcast_to((10.0, 5.0, 2.5), image.shape),
                               rtol=1e-9)


def _floor_under(light, volume):
    """A grey floor seen from 2 m above, lit by `light`, in a world filled by `volume`
    (black sky): the image mean."""
    cam = Camera(look_at((0.0, 0.0, 2.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0)), lens=50.0)
    floor = quad((0.0, 0.0, 0.0), (4.0, 0.0, 0.0), (0.0, 4.0, 0.0), material=0)
    scene = Scene(cam, 8, 8, [floor], [Material("grey", (0.5, 0.5, 0.5))], [light],
                  World((0.0, 0.0, 0.0), volume=volume))
    film, stats = render(scene, RenderSettings(samples=16, seed=2))
    assert stats.nonfinite_samples == 0
    return float(film.mean().mean())


def test_no_sun_light_passes_a_volume_that_fills_the_world():
    sun = SunLight((0.0, 0.0, -1.0), (3.0, 3.0, 3.0))
    fog = Volume(absorption=(0.01, 0.01, 0.01))
    clear = _floor_under(sun, None)
    assert clear > 0.1                                  # the control: lit without fog
    assert _floor_under(sun, fog) == 0.0
    # a lamp with a position lights the floor through the fog between them: exp(-0.2 x
    # (2 m from the camera + 1 m from the lamp)) straight down, less aslant (the floor
    # seen is within 0.72 m of the middle)
    lamp = PointLight((0.0, 0.0, 1.0), (100.0, 100.0, 100.0))
    ratio = _floor_under(lamp, Volume(absorption=(0.2, 0.2, 0.2))) / _floor_under(lamp, None)
    assert math.exp(-0.2 * 3.5) < ratio < math.exp(-0.2 * 3.0)
