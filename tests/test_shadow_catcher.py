"""Cycles' shadow catcher in the engine (engine.shadow_catcher), without Blender, on
closed forms: a black cube floats above a Lambertian catcher plane under a sun and a
black world, so the catcher's light is the sun's alone. Where the cube shadows it the
Shadow Catcher pass is 0, where nothing does it is exactly 1 (the catcher's copy of each
path takes the main path's random numbers), a lamp that is no shadow catcher brightens
it by its share, the Combined pass's four forms follow Cycles' film, and a scene without
a catcher keeps no channel and renders the same."""
import numpy as np
import pytest

from engine import RenderContext, RenderSettings, shadow_catcher
from engine.render import render
from engine.scene import Camera, Material, Scene, SunLight, World
from engine_scenes import box, look_at, quad

SIZE = 48
HALF = 10.0 * 18.0 / 50.0          # half the view's width on the plane, from 10 m at 50 mm


def _scene(catcher=True, sky=(0.0, 0.0, 0.0), transparent=False, second_sun=None):
    plane = quad((0, 0, 0), (10, 0, 0), (0, 10, 0), "plane", material=0)
    plane.shadow_catcher = catcher
    cube = box((-0.5, -0.5, 1.0), (0.5, 0.5, 2.0), "cube", material=1)
    cam = Camera(look_at((0.0, 0.0, 10.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0)), lens=50.0)
    # the sun travels towards +x and down: the cube's shadow is x in [0.5, 2.5]
    lights = [SunLight((1.0, 0.0, -1.0), (3.0, 3.0, 3.0))]
    if second_sun is not None:
        lights.append(second_sun)
    mats = [Material("plane", (0.8, 0.8, 0.8), specular_ior_level=0.0),
            Material("black", (0.0, 0.0, 0.0), specular_ior_level=0.0)]
    return Scene(cam, SIZE, SIZE, [plane, cube], mats, lights, World(sky),
                 film_transparent=transparent)


def _pixel(x, y):
    """(row, column) of the point (x, y, 0) of the plane."""
    return (int((1.0 - y / HALF) / 2.0 * SIZE), int((x / HALF + 1.0) / 2.0 * SIZE))


def _render(scene, samples=16):
    ctx = RenderContext(scene, RenderSettings(samples=samples, threads=1))
    try:
        film, _ = render(scene, ctx.settings, context=ctx)
    finally:
        ctx.close()
    return film, ctx


@pytest.fixture(scope="module")
def black_world():
    film, ctx = _render(_scene())
    return film, shadow_catcher.parts(film)


SHADOWED, LIT, LIT_FAR, CUBE = _pixel(1.6, 0.0), _pixel(-2.0, 0.5), _pixel(1.5, 2.0), \
    _pixel(0.0, 0.0)
FAR = _pixel(-3.4, -3.4)            # where the cube hides little of the sky


def test_shadow_pass_is_zero_in_shadow_and_exactly_one_where_nothing_shadows(black_world):
    film, p = black_world
    s = shadow_catcher.shadow_pass(film.mean(), film.mean_alpha(), p)
    print("S in shadow", s[SHADOWED], "lit", s[LIT], s[LIT_FAR], "cube", s[CUBE])
    assert p.splits[SHADOWED] == 1.0 and p.splits[LIT] == 1.0 and p.splits[CUBE] == 0.0
    np.testing.assert_array_equal(s[SHADOWED], 0.0)
    np.testing.assert_allclose(s[LIT], 1.0, rtol=1e-12)
    np.testing.assert_allclose(s[LIT_FAR], 1.0, rtol=1e-12)
    np.testing.assert_array_equal(s[CUBE], 1.0)         # no split: no change
    # the catcher's own light is the sun on a Lambertian plane: albedo/pi x E cos
    np.testing.assert_allclose(p.catcher[SHADOWED], 0.8 / np.pi * 3.0 * np.sqrt(0.5),
                               rtol=1e-9)
    # the shadow's share of the view: its 2 m x 1 m less what the cube hides
    shadowed = (s.mean(axis=-1) < 0.5).mean() * (2 * HALF) ** 2
    print("shadowed area", shadowed)
    assert 1.5 < shadowed < 2.0


def test_combined_is_the_matte_with_the_catcher_a_hole(black_world):
    film, p = black_world
    rgb, alpha = shadow_catcher.combined(film.mean(), film.mean_alpha(), p, pass_on=True,
                                         opaque=True)
    assert alpha[CUBE] == 1.0 and alpha[LIT] == 0.0 and alpha[SHADOWED] == 0.0
    np.testing.assert_array_equal(rgb[CUBE], film.mean()[CUBE])
    assert not rgb[LIT].any() and film.mean()[LIT].min() > 0.5
    # without the pass: the matte over the shadow (black where shadowed, clear where lit)
    rgb, alpha = shadow_catcher.combined(film.mean(), film.mean_alpha(), p, pass_on=False,
                                         opaque=False)
    assert alpha[SHADOWED] == 1.0 and alpha[LIT] == 0.0 and alpha[CUBE] == 1.0
    assert not rgb[SHADOWED].any()


def test_opaque_film_lays_the_shadow_over_the_world_behind():
    sky = (0.1, 0.2, 0.3)
    film, _ = _render(_scene(sky=sky), samples=32)
    p = shadow_catcher.parts(film)
    far = FAR
    np.testing.assert_allclose(p.behind[far], sky, rtol=1e-12)
    s = shadow_catcher.shadow_pass(film.mean(), film.mean_alpha(), p)
    rgb, alpha = shadow_catcher.combined(film.mean(), film.mean_alpha(), p, pass_on=False,
                                         opaque=True)
    print("S far", s[far], "shadowed", s[SHADOWED], "Combined", rgb[far], rgb[SHADOWED])
    assert (alpha == 1.0).all()
    # far from the cube nearly nothing shadows: the world shows through
    np.testing.assert_allclose(rgb[far], sky, rtol=0.03)
    # in the shadow the catcher keeps only the sky the cube leaves: a fraction of its
    # light, bluer than the sun's; and the world shows through by the mean of that
    assert (0.05 < s[SHADOWED]).all() and (s[SHADOWED] < 0.35).all()
    assert s[SHADOWED][2] > s[SHADOWED][0]
    np.testing.assert_allclose(rgb[SHADOWED], np.array(sky) * s[SHADOWED].mean(), rtol=1e-9)


def test_a_lamp_that_is_no_shadow_catcher_brightens_the_pass_by_its_share():
    other = SunLight((-1.0, 0.0, -1.0), (1.0, 1.0, 1.0))
    other.shadow_catcher = False
    film, _ = _render(_scene(second_sun=other), samples=64)
    p = shadow_catcher.parts(film)
    s = shadow_catcher.shadow_pass(film.mean(), film.mean_alpha(), p)
    print("S lit by both suns", s[FAR], "in the first's shadow", s[SHADOWED])
    # C - M holds both suns, K the first alone: (3 + 1) / 3 where both reach the plane
    np.testing.assert_allclose(s[FAR], 4.0 / 3.0, rtol=0.05)
    # where the cube shadows the first, C - M is the second's: 1 / 3
    np.testing.assert_allclose(s[SHADOWED], 1.0 / 3.0, rtol=0.05)


def test_catchers_change_nothing_in_combined_and_cost_nothing_without_one():
    plain, ctx = _render(_scene(catcher=False))
    assert ctx.catcher is None and ctx.film_channels() == 0
    assert plain.extra_sum.shape[1] == 0
    caught, ctx = _render(_scene(catcher=True))
    assert ctx.film_channels() == shadow_catcher.CHANNELS
    np.testing.assert_allclose(caught.mean(), plain.mean(), rtol=1e-12, atol=1e-15)


def test_transparent_film_counts_the_background_in_the_matte_transparency():
    film, _ = _render(_scene(transparent=True))
    p = shadow_catcher.parts(film)
    # every sample of a catcher pixel splits; the view has no escaped rays here, so the
    # matte's transparency is the split share
    np.testing.assert_array_equal(p.transparency, p.splits)
    rgb, alpha = shadow_catcher.combined(film.mean(), film.mean_alpha(), p, pass_on=False,
                                         opaque=False)
    assert alpha[SHADOWED] == 1.0 and alpha[LIT] == 0.0
