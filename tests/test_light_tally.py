"""Light passes and light groups in the engine (engine.light_passes,
engine.kernels.light_tally), without Blender: the slots of light sum to Combined exactly,
each light group holds exactly its lights' share, asking for them changes nothing in
Combined and costs nothing when not asked, and a closed form: a Lambertian plane under a
uniform world L sees Diffuse Direct = L (once divided by Diffuse Color, as Blender's
pass is), Diffuse Color = its albedo, no indirect light, no glossy light."""
import numpy as np
import pytest

from engine import RenderContext, RenderSettings
from engine import light_passes
from engine.kernels.light_tally import LIGHT_SLOTS, SLOT_NAMES
from engine.render import render
from engine.scene import Camera, Material, PointLight, Scene, World
from engine_scenes import cornell_box, look_at, quad


def _cornell(groups=("key",), lamp_group="key", point_group=""):
    scene = cornell_box(24, 24)
    scene.lights[0].lightgroup = lamp_group
    scene.lights.append(PointLight((0.2, 0.3, 0.6), (3.0, 2.5, 2.0), lightgroup=point_group))
    scene.light_groups = tuple(groups)
    return scene


def _images(scene, samples=16, passes=True):
    film, _ = render(scene, RenderSettings(samples=samples, threads=1, light_passes=passes))
    return film, light_passes.images(film, scene.light_groups)


@pytest.fixture(scope="module")
def cornell():
    return _images(_cornell(groups=("key", "fill"), point_group="fill"))


def test_light_slots_sum_to_combined(cornell):
    film, img = cornell
    total = sum(img[SLOT_NAMES[i]] for i in LIGHT_SLOTS)
    combined = film.mean()
    print("largest difference", np.abs(total - combined).max(), "of", combined.max())
    np.testing.assert_allclose(total, combined, rtol=1e-9, atol=1e-9)
    # the Cornell box is diffuse: no glossy, transmission or volume light, but its lamp
    # is seen (Emission) and indirect light is there
    for name in ("glossy_direct", "transmission_indirect", "volume_direct", "environment"):
        assert not img[name].any(), name
    assert img["emission"].max() > 1.0 and img["diffuse_indirect"].mean() > 0.01


def test_groups_hold_their_lights_and_sum_to_combined(cornell):
    film, img = cornell
    both = img["group:key"] + img["group:fill"]
    np.testing.assert_allclose(both, film.mean(), rtol=1e-9, atol=1e-9)
    assert img["group:fill"].mean() > 0.005 and img["group:key"].mean() > 0.05
    # the same render with the point lamp in no group: Combined less the groups is
    # exactly what its group held (the sampling is the same)
    film2, img2 = _images(_cornell(groups=("key",)))
    np.testing.assert_allclose(film2.mean(), film.mean(), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(film2.mean() - img2["group:key"], img["group:fill"],
                               rtol=1e-9, atol=1e-9)


def test_asking_changes_nothing_in_combined_and_not_asking_costs_nothing():
    scene = _cornell(groups=())
    film_on, _ = _images(scene, passes=True)
    film_off, img_off = _images(scene, passes=False)
    # (the same arithmetic on Combined either way; a tolerance, not bits, for other CPUs)
    np.testing.assert_allclose(film_on.mean(), film_off.mean(), rtol=1e-12, atol=1e-15)
    assert film_on.extra_sum.shape[1] == len(SLOT_NAMES)
    # not asked: the film keeps no channel and the paths' tally no row
    assert film_off.extra_sum.shape[1] == 0 and img_off == {}
    ctx = RenderContext(scene, RenderSettings(samples=1, threads=1))
    assert light_passes.channels(ctx) == 0
    integ = ctx.integrator
    assert not integ.light_passes and integ.light_groups == () and integ.group_tables is None


@pytest.mark.parametrize("albedo, sky", [(0.5, (0.2, 0.3, 0.5)), (0.9, (1.0, 0.5, 0.25))])
def test_plane_under_a_uniform_world_has_the_world_as_diffuse_direct(albedo, sky):
    plane = quad((0, 0, 0), (50, 0, 0), (0, 50, 0), "plane")
    cam = Camera(look_at((0.0, -2.0, 1.5), (0.0, 0.0, 0.0)), lens=50.0)
    mat = Material("lambert", (albedo,) * 3, specular_ior_level=0.0)
    scene = Scene(cam, 16, 12, [plane], [mat], [], World(sky), light_groups=("sky",))
    scene.world.lightgroup = "sky"
    film, img = _images(scene, samples=64)
    colour = img["diffuse_color"]
    np.testing.assert_allclose(colour, albedo, rtol=1e-12)
    direct = light_passes.divide_by_colour(img["diffuse_direct"], colour)
    print("Diffuse Direct mean", direct.reshape(-1, 3).mean(0), "world", sky)
    np.testing.assert_allclose(direct.reshape(-1, 3).mean(0), sky, rtol=0.01)
    assert not img["diffuse_indirect"].any() and not img["glossy_direct"].any()
    np.testing.assert_allclose(img["group:sky"], film.mean(), rtol=1e-12)


def test_transparent_film_keeps_the_background_in_environment_and_its_group():
    """As Cycles: on a transparent film Combined has no background (alpha 0 there), but
    the Environment pass and the world's light group still hold it."""
    sky = (0.2, 0.3, 0.5)
    plane = quad((0, 0, 0), (0.5, 0, 0), (0, 0.5, 0), "plane")     # the middle of the view
    cam = Camera(look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0)), lens=50.0)
    scene = Scene(cam, 16, 16, [plane], [Material("grey", (0.5,) * 3)], [], World(sky),
                  film_transparent=True, light_groups=("sky",))
    scene.world.lightgroup = "sky"
    film, img = _images(scene, samples=16)
    alpha = film.mean_alpha()
    background = alpha == 0.0
    assert background.sum() > 100 and (alpha == 1.0).sum() > 4
    assert not film.mean()[background].any()
    np.testing.assert_allclose(img["environment"][background], np.tile(sky, (background.sum(), 1)),
                               rtol=1e-12)
    np.testing.assert_allclose(img["group:sky"][background],
                               np.tile(sky, (background.sum(), 1)), rtol=1e-12)
    # on the plane the world lights it: its group holds that light, Combined the same
    covered = alpha == 1.0
    np.testing.assert_allclose(img["group:sky"][covered], film.mean()[covered], rtol=1e-9)
    assert not img["environment"][covered].any()


@pytest.mark.parametrize("colour, expected", [
    ((1.0, 0.5, 1.0), (1.0, 4.0, 3.0)),      # no zero: light / colour per channel
    ((1.0, 0.0, 1.0), (1.0, 2.0, 3.0)),      # one zero: the mean of the others' ratios
    ((0.0, 0.0, 1.0), (3.0, 3.0, 3.0)),      # two zeros: the third's ratio
    ((2.0, 1.0, 0.0), (0.5, 2.0, 1.25)),
    ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),      # no colour: no pass
])
def test_direct_and_indirect_divide_by_colour_as_cycles_film_does(colour, expected):
    """Cycles' safe_divide_even_color (its film's read of Diffuse Direct and the like):
    a channel whose colour is 0 takes the other channels' ratio, so a pass under a
    saturated colour (a missing texture's magenta, a pure red) stays grey."""
    light = np.array([[1.0, 2.0, 3.0]])
    out = light_passes.divide_by_colour(light, np.array([colour]))
    np.testing.assert_allclose(out[0], expected, rtol=1e-12)


def test_film_keeps_extra_channels_through_shipping_and_merging():
    from engine.film import Film
    film = Film(2, 1, extra=3)
    with pytest.raises(ValueError):
        film.add(np.array([0]), np.zeros((1, 3)), index=np.array([0]))
    film.add(np.array([1]), np.ones((1, 3)), index=np.array([0]),
             extra=np.full((1, 3, 3), 2.0))
    shipped = Film.from_statistics(2, 1, film.statistics())
    assert shipped.extra_sum.shape == (2, 3, 3) and shipped.extra_sum[1].min() == 2.0
    assert shipped.merge(film).extra_sum[1].max() == 4.0
