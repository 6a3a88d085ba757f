"""Subsurface scattering (engine/kernels/subsurface.py, subsurface_vertex.py): Cycles'
random walk, checked against oracles that share none of its code: the dipole equation
the Skin radius solves, two estimators of the same walk (classic distance sampling and
Dwivedi's guided one) that must agree, a white furnace, and the walk's indifference to
other objects inside the one it walks in. tests/test_subsurface_vs_cycles.py compares
renders with Cycles."""
import numpy as np
import pytest

from engine import Camera, Material, RenderSettings, Scene, World, render
from engine.accel import Accelerator
from engine.kernels import subsurface as S
from engine_scenes import box, look_at, uv_sphere


def test_skin_radius_solves_the_dipole_reflectance():
    """Random Walk (Skin) scales the radius by sqrt(3 (1 - a')) where the dipole's total
    reflectance Rd(a') (Jensen et al. 2001 with Cycles' F_dr fit) equals the albedo:
    found by 12 bisection steps, as Cycles does, so within 2^-12 of the root (SciPy's)."""
    from scipy.optimize import brentq
    for ior in (1.2, 1.4, 2.0):
        inv = 1 / ior
        f_dr = inv * (-1.44 * inv + 0.71) + 0.668 + 0.0636 * ior
        A = (4 / 3) * (1 + f_dr) / (1 - f_dr)

        def rd(a):
            s = np.sqrt(3 * (1 - a))
            return 0.5 * a * (1 + np.exp(-A * s)) * np.exp(-s)
        for albedo in (0.05, 0.3, 0.7, 0.95):
            s = S.skin_radius_scale(albedo, ior)
            root = brentq(lambda a: rd(a) - albedo, 0.0, 1.0, xtol=1e-14)
            assert 1 - s * s / 3 == pytest.approx(root, abs=2.0 ** -12), (ior, albedo)
    assert S.skin_radius_scale(0.0, 1.4) == pytest.approx(np.sqrt(3.0))
    assert S.skin_radius_scale(0.999, 1.4) == pytest.approx(np.sqrt(3e-6))


def test_single_scattering_albedo_rises_with_the_albedo_and_stays_below_one():
    for g in (0.0, 0.5, 0.9):
        alphas = [S.remap(a, 1.0, g)[1] for a in np.linspace(0, 1, 41)]
        assert np.all(np.diff(alphas) >= 0) and alphas[0] == 0.0
        assert 0.99 < alphas[-1] <= 0.999999
        assert S.remap(0.5, 0.25, g)[0] == pytest.approx(4.0 / (1 - g))


SLAB = box((-60, -60, -20), (60, 60, 0), "slab")


def _walks(meshes, albedo, radius, g, guided, n=20000, seed=1):
    accel = Accelerator(meshes)
    keys = np.random.default_rng(seed).integers(0, 2**63, n, dtype=np.uint64)
    out = np.zeros((n, 5))
    S.walk_batch(accel.kernel_rays(), keys, 0, np.array([0.0, 0.0, -1e-4]),
                 np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, 1.0]), albedo, radius, g,
                 guided, out)
    accel.close()
    return out


@pytest.mark.parametrize("g", [0.0, 0.7])
def test_guided_and_classic_walks_estimate_the_same_reflectance(g):
    """Dwivedi-guided distances and directions (with their balance-heuristic MIS over the
    classic, forward and backward strategies and over the colour channels) are another
    estimator of the classic walk's reflectance of a thick slab: they agree within their
    noise. The reflectance is near the albedo, which Chiang et al.'s fit aims at (for
    light from every direction; this one comes straight down, so it goes deeper and
    less comes back, the more so the more forward it scatters: measured 0.77, 0.44,
    0.16 at g = 0 and 0.78, 0.41, 0.13 at g = 0.7 for albedos 0.8, 0.5, 0.2)."""
    albedo, radius = (0.8, 0.5, 0.2), (0.2, 0.1, 0.05)
    classic = _walks([SLAB], albedo, radius, g, False)
    guided = _walks([SLAB], albedo, radius, g, True, seed=2)
    for out in (classic, guided):
        assert np.all(np.isfinite(out)) and np.all(out[:, 1:4] >= 0)
        assert np.all(out[out[:, 0] == 1, 4] >= 0)          # left through the slab
    r_c = (classic[:, 1:4] * classic[:, :1]).mean(0)
    r_g = (guided[:, 1:4] * guided[:, :1]).mean(0)
    se = np.sqrt((classic[:, 1:4] * classic[:, :1]).var(0) / len(classic)
                 + (guided[:, 1:4] * guided[:, :1]).var(0) / len(guided))
    print(f"g={g}: classic {r_c}, guided {r_g}, 1 sigma {se}")
    assert np.all(np.abs(r_c - r_g) < 4 * se + 1e-4)
    np.testing.assert_allclose(r_g, albedo, rtol=0.4)


def test_the_walk_passes_through_other_objects_inside():
    """The walk meets only its own object's surface: a box inside the slab, which most
    walks cross, changes nothing, walk for walk (but for the last float32 bits of the
    rays, which Embree takes relative to the scene's centre, and the box moves it)."""
    albedo, radius = (0.9, 0.6, 0.3), (0.5, 0.3, 0.1)
    alone = _walks([SLAB], albedo, radius, 0.0, True, n=3000)
    inner = box((-0.3, -0.3, -0.5), (0.3, 0.3, -0.1), "inner")
    shared = _walks([SLAB, inner], albedo, radius, 0.0, True, n=3000)
    same = np.all(np.abs(alone[:, :4] - shared[:, :4]) <= 1e-3 * np.abs(alone[:, :4]), 1)
    assert same.mean() > 0.995
    np.testing.assert_array_equal(alone[:, 4], shared[:, 4])


def _furnace(method, g, samples):
    # Skin's walk radius at albedo 1 is sqrt(3e-6) of the Radius: larger, so its walks
    # are short too (a long walk may still be inside at Cycles' 256 steps, and is lost)
    radius = (8e3, 4e3, 2e3) if method == "RANDOM_WALK_SKIN" else (8.0, 4.0, 2.0)
    sss = Material("sss", (1.0, 1.0, 1.0), specular_ior_level=0.0, subsurface_weight=1.0,
                   subsurface_radius=radius, subsurface_anisotropy=g,
                   subsurface_method=method)
    cam = Camera(look_at((0, -4, 0), (0, 0, 0)), lens=50.0)
    scene = Scene(cam, 12, 12, [uv_sphere((0, 0, 0), 1.0)], [sss], [], World((1, 1, 1)))
    film, _ = render(scene, RenderSettings(samples=samples, seed=4, clamp_indirect=0.0))
    return film.mean()


@pytest.mark.parametrize("method,g", [("RANDOM_WALK", 0.0), ("RANDOM_WALK", 0.8),
                                      ("RANDOM_WALK_SKIN", 0.0)])
def test_white_furnace(method, g):
    """A white sphere that scatters everything below its surface, in a white world: every
    walk leaves (the radius is larger than the sphere, so walks are short) and nothing is
    absorbed, so the sphere vanishes into the world."""
    img = _furnace(method, g, 64)
    assert np.all(np.isfinite(img))
    print(method, g, img.mean(), img.min(), img.max())
    assert img.mean() == pytest.approx(1.0, abs=0.01)


def test_distribution_ray_tracing_lights_the_walks_exit():
    """Cook's distribution ray tracing (the path tracer without diffuse bounces) still
    walks below the surface and lights the exit directly, as Cycles does with Diffuse
    bounces 0: the white furnace holds there too."""
    sss = Material("sss", (1.0, 1.0, 1.0), specular_ior_level=0.0, subsurface_weight=1.0,
                   subsurface_radius=(8.0, 4.0, 2.0))
    cam = Camera(look_at((0, -4, 0), (0, 0, 0)), lens=50.0)
    scene = Scene(cam, 12, 12, [uv_sphere((0, 0, 0), 1.0)], [sss], [], World((1, 1, 1)))
    film, _ = render(scene, RenderSettings(samples=64, seed=5, integrator="distribution"))
    assert film.mean().mean() == pytest.approx(1.0, abs=0.01)
