"""The environment map through the whole renderer (engine.render).

1. White furnace: a diffuse white sphere under a constant map of radiance 1 (a convex
   object, so the sphere reflects exactly what reaches it): radiance 1 within noise.
2. Closed form: a Lambertian plane under a sky map with a small bright sun patch
   reflects rho / pi x E, E = the integral of L cos over the upper hemisphere, computed
   here from the map's own lookup on a fine jittered grid; light sampling only, BSDF
   sampling only and MIS (the integrators' `mis_mode` hook) are three estimators of it
   and must each agree within 1 % (their standard errors below a third of that).
   On a glossy plane (no closed form) the three must agree with each other.
3. Importance sampling against uniform sampling of the same map at equal samples (MIS
   on, 1024 samples per pixel), under a sky whose sun patch gives ~90 % of the light:
   the standard error of the plane's radiance is 9.4x smaller with the map's
   distribution than with directions uniform over the sphere (variance 88x: as many
   times fewer samples for the same noise); both means agree with the closed form.
"""
from __future__ import annotations

import numpy as np
import pytest

from engine import Camera, Material, RenderContext, RenderSettings, Scene, World, render
from engine.kernels.lights import pack_lights
from engine.kernels.lights.batch import world_escaped_batch
from engine.integrators.compiled_path import CompiledPathIntegrator
from engine.lights import LightSet
from engine.piecewise_2d import PiecewiseConstant2D
from engine.textures import Texture
from engine.world_light import world_model
from engine_scenes import look_at, quad, uv_sphere

RHO = 0.5


def sky_map(width=64, height=32, sun=20.0):
    """A sky brightening towards the zenith, a dark ground, and a 4 x 3 texel sun patch
    of radiance `sun` at about 50 degrees elevation."""
    v = (np.arange(height) + 0.5) / height
    el = (v - 0.5) * np.pi
    px = np.zeros((height, width, 3), np.float32)
    px[:] = np.where(el[:, None] > 0, 0.3 + 0.7 * np.sin(np.maximum(el, 0))[:, None],
                     0.05)[:, :, None] * np.array([0.7, 0.85, 1.0])
    px[24:27, 40:44] = (sun, 0.9 * sun, 0.8 * sun)
    return px


def sky_world(**kw):
    return World(texture=Texture(sky_map(**kw), "Linear", "REPEAT"))


def hemisphere_irradiance(world, n=1500, seed=0):
    """E on an up-facing surface: the integral of L cos over the upper hemisphere, on a
    jittered n x 4n grid in (cos theta, phi) (cells of equal solid angle)."""
    L = pack_lights(LightSet([], 1.0, world=world_model(world)))
    rng = np.random.default_rng(seed)
    c = (np.arange(n)[:, None] + rng.random((n, 4 * n))) / n
    p = (np.arange(4 * n)[None, :] + rng.random((n, 4 * n))) / (4 * n) * 2.0 * np.pi
    s = np.sqrt(1.0 - c * c)
    d = np.stack([s * np.cos(p), s * np.sin(p), c], -1).reshape(-1, 3)
    radiance = world_escaped_batch(L, np.zeros(3), np.ascontiguousarray(d))[0]
    return (radiance * c.reshape(-1, 1)).mean(0) * 2.0 * np.pi


def plane_scene(world, material=None, size=8):
    mat = material or Material("grey", (RHO,) * 3, roughness=1.0, specular_ior_level=0.0)
    cam = Camera(look_at((2.0, 0.3, 1.2), (0.0, 0.0, 0.0)), lens=5000.0, clip_start=1e-3)
    floor = quad((0, 0, 0), (20, 0, 0), (0, 20, 0), "floor", 0)
    return Scene(cam, size, size, [floor], [mat], [], world)


def measure(scene, settings, mis_mode="mis", uniform=False):
    """(mean radiance (3,), its standard error (3,)) over all samples of the image."""
    ctx = RenderContext(scene, settings)
    try:
        if uniform:          # directions uniform over the sphere instead of the map's
            env = ctx.lights.world.map
            h, w = env.distribution.height, env.distribution.width
            edges = np.cos(np.pi * np.arange(h + 1) / h)
            env.distribution = PiecewiseConstant2D(np.repeat(
                (edges[:-1] - edges[1:])[:, None], w, axis=1))
        if uniform:
            ctx.integrator = CompiledPathIntegrator(ctx)
        ctx.integrator.mis_mode = mis_mode
        film, stats = render(scene, settings, context=ctx)
    finally:
        ctx.close()
    assert stats.nonfinite_samples == 0
    n = film.count.sum()
    mean = film.sum.sum(0) / n
    var = film.sum_sq.sum(0) / n - mean * mean
    return mean, np.sqrt(np.maximum(var, 0.0) / n)


def test_white_furnace_with_a_constant_map():
    sphere = uv_sphere((0, 0, 0), 1.0, n_theta=48, n_phi=96, material=0)
    cam = Camera(look_at((0, -4.0, 0), (0, 0, 0)), lens=50.0)
    world = World(texture=Texture(np.ones((16, 32, 3), np.float32), "Linear", "REPEAT"))
    scene = Scene(cam, 32, 32, [sphere], [Material("white", (1.0,) * 3,
                                                   specular_ior_level=0.0)], [], world,
                  film_transparent=True)
    settings = RenderSettings(samples=64, seed=1, clamp_indirect=0.0, max_bounces=64,
                              diffuse_bounces=64)
    film, _ = render(scene, settings)
    inside = film.mean_alpha() > 0.999
    assert inside.sum() > 300
    got = film.mean()[inside].mean(0)
    print("sphere mean", got)
    assert np.all(np.abs(got - 1.0) < 0.005)


DIRECT = dict(samples=16384, diffuse_bounces=1, max_bounces=2, seed=2, clamp_indirect=0.0)


def test_light_only_bsdf_only_and_mis_agree_with_the_closed_form():
    world = sky_world()
    expected = RHO / np.pi * hemisphere_irradiance(world)
    scene = plane_scene(world)
    se_by_mode = {}
    for mode in ("light", "bsdf", "mis"):
        value, se = measure(scene, RenderSettings(**DIRECT), mode)
        err = value / expected - 1
        print(f"{mode}: {value.round(5)} expected {expected.round(5)} "
              f"err {np.round(100 * err, 3)}% se {np.round(100 * se / expected, 3)}%")
        assert np.all(se / expected < 0.01 / 3)
        assert np.all(np.abs(err) < 0.01)
        se_by_mode[mode] = se.max()
    assert se_by_mode["mis"] < se_by_mode["bsdf"]


def test_strategies_agree_on_a_glossy_plane():
    world = sky_world()
    metal = Material("metal", (0.9, 0.9, 0.9), metallic=1.0, roughness=0.4,
                     glossy_model="GGX")
    scene = plane_scene(world, metal)
    settings = RenderSettings(**dict(DIRECT, glossy_bounces=1, samples=8192))
    got = {mode: measure(scene, settings, mode) for mode in ("light", "bsdf", "mis")}
    for mode, (value, se) in got.items():
        print(mode, value.round(5), "se", se.round(5))
    ref, se_ref = got["mis"]
    for mode in ("light", "bsdf"):
        value, se = got[mode]
        assert np.all(np.abs(value - ref) < 4.0 * np.hypot(se, se_ref))
        assert np.all(np.abs(value / ref - 1) < 0.02)


def test_importance_sampling_beats_uniform_sampling_of_the_map():
    world = sky_world(sun=400.0)
    scene = plane_scene(world)
    settings = RenderSettings(**dict(DIRECT, samples=1024))
    expected = RHO / np.pi * hemisphere_irradiance(world)
    v_imp, se_imp = measure(scene, settings)
    v_uni, se_uni = measure(scene, settings, uniform=True)
    ratio = se_uni.max() / se_imp.max()
    print(f"importance {v_imp.round(4)} se {se_imp.round(5)}; uniform {v_uni.round(4)} "
          f"se {se_uni.round(5)}; expected {expected.round(4)}; noise reduction {ratio:.2f}x "
          f"(variance {ratio ** 2:.1f}x)")
    for v, se in ((v_imp, se_imp), (v_uni, se_uni)):
        assert np.all(np.abs(v - expected) < 4.0 * se + 1e-3 * expected)
    assert ratio > 3.0


def test_world_hidden_from_the_camera_still_lights_the_scene():
    """World > Ray Visibility > Camera off: a black background, the same lighting (the
    pixels whose every camera ray hits the sphere, alpha 1 on a transparent film, are
    unchanged to the bit)."""
    world = sky_world()
    scene = Scene(Camera(look_at((0, -4.0, 1.5), (0, 0, 0.6)), lens=90.0), 12, 12,
                  [uv_sphere((0, 0, 0.6), 0.6, material=0)],
                  [Material("grey", (RHO,) * 3, specular_ior_level=0.0)], [], world)
    settings = RenderSettings(samples=8, seed=6)
    seen = render(scene, settings)[0].mean()
    scene.film_transparent = True
    alpha = render(scene, settings)[0].mean_alpha()
    scene.film_transparent = False
    world.visibility = 31 & ~1
    hidden = render(scene, settings)[0].mean()
    sky, sphere = alpha == 0.0, alpha == 1.0
    assert sky.sum() > 10 and sphere.sum() > 4
    assert np.all(hidden[sky] == 0.0) and np.all(seen[sky].sum(1) > 0.1)
    np.testing.assert_array_equal(hidden[sphere], seen[sphere])
