"""Materials at the limits of their parameters and light at grazing angles: every render
is finite and non-negative, and bounded by energy conservation.

The bound is the white furnace: a convex object under a uniform white world of radiance
1 with no other light sees only the world, so with an energy-conserving BSDF no pixel's
expected value exceeds 1. The test takes the mean of the pixels inside the sphere's
outline (16 x 16 pixels, 16 samples) and allows 4 standard errors of noise above 1."""
import numpy as np
import pytest

from engine import Camera, Material, RenderSettings, Scene, SunLight, World, render
from engine_scenes import look_at, quad, uv_sphere
from extreme_checks import sane

WHITE = (1.0, 1.0, 1.0)
# Blinn-Phong exponent n = 2 / alpha^2 - 2 with alpha = roughness^2 (engine.scene.Material)
BLINN_1E6 = (2.0 / (1e6 + 2.0)) ** 0.25

LIMITS = {
    "roughness 0": dict(roughness=0.0),
    "roughness 1e-4": dict(roughness=1e-4),
    "roughness 1": dict(roughness=1.0),
    "metal roughness 0": dict(metallic=1.0, roughness=0.0),
    "metal roughness 1e-4": dict(metallic=1.0, roughness=1e-4),
    "metal roughness 1": dict(metallic=1.0, roughness=1.0),
    "metal multiscatter roughness 1": dict(metallic=1.0, roughness=1.0, glossy_model="MULTI_GGX"),
    "Blinn-Phong exponent 1e6": dict(glossy_model="BLINN_PHONG", roughness=BLINN_1E6),
    "Blinn-Phong metal exponent 1e6": dict(glossy_model="BLINN_PHONG", metallic=1.0,
                                           roughness=BLINN_1E6),
    "Blinn-Phong roughness 0": dict(glossy_model="BLINN_PHONG", metallic=1.0, roughness=0.0),
    "Blinn-Phong roughness 1": dict(glossy_model="BLINN_PHONG", metallic=1.0, roughness=1.0),
    "IOR 1": dict(ior=1.0),
    "IOR 1.0001": dict(ior=1.0001),
    "IOR 4": dict(ior=4.0),
    "glass IOR 1": dict(transmission=1.0, ior=1.0, roughness=0.0),
    "glass IOR 1.0001": dict(transmission=1.0, ior=1.0001, roughness=0.0),
    "glass IOR 4": dict(transmission=1.0, ior=4.0, roughness=0.0),
    "rough glass IOR 1.0001": dict(transmission=1.0, ior=1.0001, roughness=1e-4),
    "rough glass IOR 4": dict(transmission=1.0, ior=4.0, roughness=1.0),
    "Beckmann metal roughness 0": dict(metallic=1.0, roughness=0.0, glossy_model="BECKMANN"),
    "Beckmann metal roughness 1": dict(metallic=1.0, roughness=1.0, glossy_model="BECKMANN"),
    "Beckmann glass IOR 1.0001": dict(transmission=1.0, ior=1.0001, roughness=1e-4,
                                      glossy_model="BECKMANN"),
    "Beckmann glass IOR 4 roughness 1": dict(transmission=1.0, ior=4.0, roughness=1.0,
                                             glossy_model="BECKMANN"),
    "Beckmann refraction roughness 1": dict(transmission=1.0, roughness=1.0,
                                            refraction_only=True, glossy_model="BECKMANN"),
    "Glossy BSDF (constant Fresnel) roughness 1": dict(metallic=1.0, roughness=1.0,
                                                       metal_fresnel="CONSTANT",
                                                       glossy_model="MULTI_GGX"),
    "metallic 0 base 0": dict(metallic=0.0, base_color=(0.0, 0.0, 0.0)),
    "metallic 1 base 0": dict(metallic=1.0, base_color=(0.0, 0.0, 0.0)),
    "metallic 0 base 1": dict(metallic=0.0, base_color=WHITE),
    "metallic 1 base 1": dict(metallic=1.0, base_color=WHITE),
    "coat 1 roughness 0 IOR 4": dict(coat_weight=1.0, coat_roughness=0.0, coat_ior=4.0),
    "sheen 1 roughness 0": dict(sheen_weight=1.0, sheen_roughness=0.0, sheen_tint=WHITE),
    "specular IOR level 1": dict(specular_ior_level=1.0, ior=4.0),
}


def _furnace(material, samples=16, size=16):
    sphere = uv_sphere((0, 0, 0), 1.0, 12, 24)
    cam = Camera(look_at((0, -4, 0), (0, 0, 0)), lens=60)
    scene = Scene(cam, size, size, [sphere], [material], [], World(WHITE))
    return render(scene, RenderSettings(samples=samples, seed=1, sampler="random"))


def _mean_and_error(film, size=16):
    """Mean and standard error of the pixels whose centres lie well inside the sphere's
    outline (it spans 0.86 of the half-width; pixels within 0.75)."""
    c = (np.arange(size) + 0.5) / size * 2 - 1
    inside = np.hypot(*np.meshgrid(c, c)) < 0.75
    img = film.mean()[inside]
    se = np.sqrt(film.variance_of_mean()[inside].sum()) / img.size
    return img.mean(), se


@pytest.mark.parametrize("name", list(LIMITS))
def test_material_at_its_limits_is_finite_and_energy_bounded(name):
    film, stats = _furnace(Material(name, **{"base_color": WHITE, **LIMITS[name]}))
    assert not sane(film, stats), f"{name}: {sane(film, stats)}"
    mean, se = _mean_and_error(film)
    print(f"{name}: furnace image mean {mean:.4f} +- {se:.4f}")
    assert mean <= 1.0 + 4 * se + 1e-9, f"{name}: the furnace reflects {mean:.4f} > 1"


def test_emission_strength_1e6_is_finite_and_exact():
    """Emission radiance 1e6 (strength 1e6, white): seen directly it is 1e6 plus at most
    the world's 1 reflected (an estimate: within four of its standard errors; the light
    tree samples the world, not the sphere's own triangles below each point)."""
    film, stats = _furnace(Material("hot", base_color=WHITE, emission=(1e6,) * 3))
    assert not sane(film, stats)
    img = film.mean()[..., 0]
    centre = img[6:10, 6:10]                  # pixels wholly on the sphere
    se = np.sqrt(film.variance_of_mean()[6:10, 6:10, 0])
    assert np.all(centre >= 1e6) and np.all(centre <= 1e6 + 1.0 + 4 * se + 1e-3), centre


def _grazing_plane_scene(material, light=None, eye_height=1e-3, size=16):
    """A 1e4 m plane under a white world, the camera eye_height above it looking along it
    (the view axis 0.01 degrees below the horizon)."""
    plane = quad((0, 0, 0), (1e4, 0, 0), (0, 1e4, 0), "plane")
    pitch = np.radians(0.01)
    eye = np.array([0.0, 0.0, eye_height])
    cam = Camera(look_at(eye, eye + [0, np.cos(pitch), -np.sin(pitch)]), lens=50,
                 clip_start=1e-5, clip_end=1e6)
    return Scene(cam, size, size, [plane], [material], [light] if light else [],
                 World((0.0,) * 3 if light else WHITE))


@pytest.mark.parametrize("kw", [dict(roughness=1.0), dict(metallic=1.0, roughness=0.0),
                                dict(metallic=1.0, roughness=0.05),
                                dict(metallic=1.0, roughness=0.05, glossy_model="MULTI_GGX"),
                                dict(glossy_model="BLINN_PHONG", metallic=1.0,
                                     roughness=BLINN_1E6),
                                dict(transmission=1.0, roughness=0.1, ior=1.5),
                                dict(metallic=1.0, roughness=0.05, glossy_model="BECKMANN"),
                                dict(transmission=1.0, roughness=0.1, ior=1.5,
                                     glossy_model="BECKMANN")],
                         ids=["diffuse", "mirror", "glossy", "multiscatter", "blinn-phong",
                              "rough glass", "beckmann", "beckmann glass"])
def test_grazing_view_of_a_large_plane_is_finite_and_energy_bounded(kw):
    """Camera rays almost parallel to the plane (grazing glossy lobes): the plane
    reflects the white world only, so no pixel exceeds 1 in expectation."""
    scene = _grazing_plane_scene(Material("m", base_color=WHITE, **kw))
    film, stats = render(scene, RenderSettings(samples=16, seed=2, sampler="random"))
    assert not sane(film, stats), sane(film, stats)
    lower = film.mean()[9:]                        # rows below the horizon: the plane
    se = np.sqrt(film.variance_of_mean()[9:].sum()) / lower.size
    print(f"{kw}: plane mean {lower.mean():.4f} +- {se:.4f}")
    assert lower.mean() <= 1.0 + 4 * se + 1e-9
    assert lower.mean() > 0.0


@pytest.mark.parametrize("kw", [dict(roughness=1.0, specular_ior_level=0.0),
                                dict(metallic=1.0, roughness=0.05),
                                dict(roughness=0.0)], ids=["diffuse", "glossy", "smooth"])
def test_sun_at_89_9_degrees(kw):
    """A sun 0.1 degrees above the horizon of the plane: every plane pixel is finite and
    non-negative; the diffuse plane (direct light only) is exactly rho/pi E cos(89.9 deg)
    in every pixel: no shadow acne."""
    theta = np.radians(89.9)
    sun = SunLight((-np.sin(theta), 0.0, -np.cos(theta)), (3.0, 3.0, 3.0))
    rho = 0.8
    plane = quad((0, 0, 0), (1, 0, 0), (0, 1, 0), "plane")
    cam = Camera(look_at((0, -0.5, 2.0), (0, 0, 0)), lens=50, clip_start=1e-2, clip_end=1e2)
    scene = Scene(cam, 16, 16, [plane], [Material("m", base_color=(rho,) * 3, **kw)], [sun],
                  World((0, 0, 0)))
    film, stats = render(scene, RenderSettings(samples=4, diffuse_bounces=0, filter_type="BOX",
                                               filter_width=0.1))
    assert not sane(film, stats), sane(film, stats)
    img = film.mean()[..., 0]
    if kw.get("specular_ior_level") == 0.0:
        np.testing.assert_allclose(img, rho / np.pi * 3.0 * np.cos(theta), rtol=1e-6)
    else:
        assert img.max() < 3.0        # below the sun's irradiance E
