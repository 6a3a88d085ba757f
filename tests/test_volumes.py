"""Homogeneous volumes in the engine (engine.kernels.volume, medium_vertex), against
closed forms: no Blender needed.

- Transmittance: a camera looking through a sphere of pure absorber at a uniform world
  sees exp(-sigma_a chord) exactly (no sampling is involved: absorption only).
- Emission: a sphere of emitting, absorbing medium seen through its centre gives
  e (1 - exp(-sigma_t chord)) / sigma_t.
- Volume furnace: a sphere of scattering-only medium (albedo 1, a different extinction
  per colour channel, forward scattering) in a uniform white world, with no bounce limit
  that matters, neither adds nor removes light: every pixel sees the world's radiance.
  This exercises the distance sampling, its one-sample MIS over colour channels, the
  phase function's sampling and next-event estimation with their MIS, the volume stack
  across the boundary and shadow rays through the medium.
- The phase function's sampling against its own pdf (chi-square, tests/chi2.py).
- The camera's start stack; cost only when used; the distribution ray tracer renders volumes,
  Whitted's refuses them.
"""
import numpy as np
import pytest

from chi2 import chi2_test
from engine import Camera, Material, RenderSettings, Scene, Volume, World, render
from engine.render import RenderContext
from engine_scenes import box, look_at, uv_sphere

R = 1.0


def _sphere_scene(volume, world=(1.0, 1.0, 1.0), size=9, lens=200.0, eye=(0, -6, 0)):
    """A volume-only sphere of radius R at the origin, seen from `eye` by a narrow
    camera (the pixels' chords are all close to the diameter)."""
    mats = [Material("medium", surface=False, volume=volume)]
    sphere = uv_sphere((0, 0, 0), R, n_theta=64, n_phi=128, material=0)
    cam = Camera(look_at(eye, (0, 0, 0)), lens=lens, clip_start=1e-3)
    return Scene(cam, size, size, [sphere], mats, [], World(world))


def _centre(film):
    img = film.mean()
    c = img.shape[0] // 2
    return img[c, c]


def test_absorbing_sphere_transmits_exp_minus_sigma_chord():
    sigma = np.array([0.2, 0.7, 1.5])
    film, _ = render(_sphere_scene(Volume(absorption=tuple(sigma))),
                     RenderSettings(samples=16, seed=0))
    got = _centre(film)
    expected = np.exp(-sigma * 2 * R)
    print("transmittance", got, "expected", expected)
    # the pixel filter spreads over chords a little shorter than the diameter
    np.testing.assert_allclose(got, expected, rtol=0.02)
    # a control: half the absorption is far from it
    assert np.all(np.abs(np.exp(-sigma * R) - got) > 0.05 * got)


def test_emitting_absorbing_sphere_integrates_exactly():
    sigma, e = np.array([0.5, 1.0, 2.0]), np.array([1.0, 0.5, 2.0])
    film, _ = render(_sphere_scene(Volume(absorption=tuple(sigma), emission=tuple(e)),
                                   world=(0, 0, 0)),
                     RenderSettings(samples=16, seed=0))
    got = _centre(film)
    expected = e * (1 - np.exp(-sigma * 2 * R)) / sigma
    print("emission", got, "expected", expected)
    np.testing.assert_allclose(got, expected, rtol=0.02)


@pytest.mark.parametrize("g", [0.0, 0.6])
def test_volume_white_furnace(g):
    """Albedo 1 in every channel, chromatic extinction: the image equals the world."""
    vol = Volume(scattering=(0.5, 1.5, 3.0), anisotropy=g)
    settings = RenderSettings(samples=256, seed=3, max_bounces=400, volume_bounces=400,
                              clamp_indirect=0.0)
    film, _ = render(_sphere_scene(vol, lens=60.0), settings)
    img = film.mean()
    mean = img.mean(axis=(0, 1))
    print(f"g={g}: image mean per channel {mean}")
    np.testing.assert_allclose(mean, 1.0, atol=0.01)
    # and with Cycles' default of no volume bounces, energy is lost: a control
    film0, _ = render(_sphere_scene(vol, lens=60.0), RenderSettings(samples=64, seed=3))
    assert film0.mean().mean(axis=(0, 1)).min() < 0.9


def test_phase_function_sampling_matches_its_pdf():
    from engine.kernels.volume import hg_phase, hg_sample
    d = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    for g in (-0.7, 0.0, 0.4, 0.95):
        def sample(u, g=g):
            w = np.array([hg_sample(g, *d, a, b)[:3] for a, b in u[:, 1:]])
            return w, np.ones(len(w), bool)

        def pdf(w, g=g):
            return np.array([hg_phase(g, float(x)) for x in w @ d])
        res = chi2_test(sample, pdf, 100_000, seed=11, n_tests=5)
        print(f"g={g}: {res}")
        assert res.passed, res
        assert abs(res.pdf_integral - 1.0) < 0.01


def test_phase_sampling_control_fails():
    """Samples of g = 0.4 against the pdf of g = 0.5 fail the harness."""
    from engine.kernels.volume import hg_phase, hg_sample
    d = np.array([0.0, 0.0, 1.0])

    def sample(u):
        return np.array([hg_sample(0.4, *d, a, b)[:3] for a, b in u[:, 1:]]), \
            np.ones(len(u), bool)
    res = chi2_test(sample, lambda w: np.array([hg_phase(0.5, float(x)) for x in w[:, 2]]),
                    100_000, seed=12, n_tests=5)
    assert not res.passed


def test_camera_inside_a_volume_starts_inside_it():
    fog = Material("fog", surface=False, volume=Volume(scattering=(0.1,) * 3))
    wall = Material("wall")
    cam = Camera(look_at((0, 0, 0), (0, 1, 0)))
    meshes = [box((-2, -2, -2), (2, 2, 2), "fog", 1), box((5, 5, 5), (6, 6, 6), "x", 0)]
    scene = Scene(cam, 8, 8, meshes, [wall, fog], [], World((1, 1, 1),
                  volume=Volume(absorption=(0.01,) * 3)))
    ctx = RenderContext(scene, RenderSettings(samples=1))
    try:
        stack = ctx.integrator.start_stack
        world_row = ctx.integrator.vol.shape[0] - 1
        assert list(stack[:3]) == [world_row, 1, -1]
    finally:
        ctx.close()
    outside = Scene(Camera(look_at((0, -9, 0), (0, 0, 0))), 8, 8, meshes, [wall, fog], [],
                    World((1, 1, 1)))
    ctx = RenderContext(outside, RenderSettings(samples=1))
    try:
        assert list(ctx.integrator.start_stack[:1]) == [-1]
    finally:
        ctx.close()


def test_scenes_without_volumes_carry_no_volume_state():
    scene = _sphere_scene(None)
    scene.materials[0] = Material("plain")
    ctx = RenderContext(scene, RenderSettings(samples=1))
    try:
        assert not ctx.integrator.has_volumes
        assert ctx.integrator.vol.shape[0] == 0
        assert ctx.integrator.shadow_rays_per_path == 1   # no equiangular light samples
    finally:
        ctx.close()
    ctx = RenderContext(_sphere_scene(Volume(scattering=(0.1,) * 3)), RenderSettings(samples=1))
    try:
        assert ctx.integrator.shadow_rays_per_path == 2   # one more per segment in a medium
    finally:
        ctx.close()


def test_distribution_renders_volumes_and_whitted_refuses_them():
    """The distribution ray tracer runs on the path tracer's kernels, media included: an
    absorbing sphere transmits exp(-sigma_a chord) there too. Whitted's does not model
    media, and says so."""
    sigma = 0.7
    film, _ = render(_sphere_scene(Volume(absorption=(sigma,) * 3)),
                     RenderSettings(samples=4, integrator="distribution"))
    np.testing.assert_allclose(_centre(film), np.exp(-sigma * 2 * R), rtol=0.02)
    with pytest.raises(ValueError, match="volumes"):
        render(_sphere_scene(Volume(absorption=(1.0,) * 3)),
               RenderSettings(samples=1, integrator="whitted"))
