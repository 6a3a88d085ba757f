"""What distinguishes the three integrators, each checked where it has an exact answer."""
import numpy as np
import pytest

from engine import (AreaLight, Camera, Material, RenderSettings, Scene, World, render)
from engine_scenes import cornell_box, quad
from stratification_scenes import penumbra_scene


def test_only_the_path_tracer_lights_the_ceiling_by_interreflection():
    """The Cornell light faces down, so the ceiling receives no direct light at all."""
    scene = cornell_box(32, 32)
    means = {}
    for integrator in ("whitted", "distribution", "path"):
        film, _ = render(scene, RenderSettings(samples=8, integrator=integrator))
        img = film.mean()[5:10, 6:12]       # a patch of ceiling left of the light
        means[integrator] = np.median(img)
    assert means["whitted"] == 0.0
    assert means["distribution"] == 0.0
    assert means["path"] > 0.05


def _penumbra_profile(integrator):
    film, _ = render(penumbra_scene(24), RenderSettings(samples=64, integrator=integrator,
                                                        diffuse_bounces=0))
    return film.mean()[12, :, 0]


def test_whitted_shadows_are_hard_and_distribution_shadows_soft():
    hard, soft = _penumbra_profile("whitted"), _penumbra_profile("distribution")
    # Pixels in the shadow's transition (lit, but less than half the lit level): Whitted's
    # single shadow ray to the light centre makes a step (only the pixel straddling it,
    # blended by the pixel filter); the distributed shadow rays make a penumbra.
    def transition(profile):
        return int(((profile > 0) & (profile < 0.5 * profile.max())).sum())
    assert transition(hard) <= 2
    assert transition(soft) >= 5


def test_whitted_mirror_reflects_emission_exactly():
    """A perfect metal mirror (base colour 1, F0 = 1) facing an emissive wall: every
    pixel sees the wall's radiance through the mirror."""
    mirror = Material("mirror", (1.0, 1.0, 1.0), metallic=1.0, roughness=0.0)
    glow = Material("glow", (0, 0, 0), specular_ior_level=0.0, emission=(2.0, 1.0, 0.5))
    meshes = [quad((0, 0, 0), (1, 0, 0), (0, 1, 0), "mirror", 0),
              quad((0, 0, 3), (0, 10, 0), (10, 0, 0), "ceiling", 1)]
    m = np.eye(4)
    m[:3, 3] = (0, 0, 1.0)
    cam = Camera(m @ np.diag([1, 1, 1, 1]), lens=100.0, clip_start=1e-3)
    # look straight down at the mirror
    cam.matrix = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1.0], [0, 0, 0, 1.0]])
    scene = Scene(cam, 8, 8, meshes, [mirror, glow], [], World((0, 0, 0)))
    film, _ = render(scene, RenderSettings(samples=4, integrator="whitted"))
    np.testing.assert_allclose(film.mean(), np.broadcast_to([2.0, 1.0, 0.5], (8, 8, 3)),
                               rtol=1e-9)


def test_unknown_integrator_is_a_clear_error():
    with pytest.raises(ValueError, match="integrator"):
        render(cornell_box(4, 4), RenderSettings(integrator="bidirectional"))
