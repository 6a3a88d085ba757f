"""The path tracer's three estimators of direct light agree: next-event estimation alone,
BSDF sampling alone and their multiple importance sampling (`mis_mode` "light", "bsdf",
"mis") are unbiased estimators of the same image, computed by different code (light
sampling and its pdfs, BSDF sampling and its pdfs, the MIS weights), so a bug in any one
of them (a pdf off by a factor, a lamp whose sampled point and hit point disagree, a
lobe evaluated but never sampled) moves one image mean away from the others. Checked on
every lamp kind (point, sphere, spot, soft falloff, sun with and without a disc, area
disk and ellipse, one hidden from the camera, the two in one plane and in front of the
Cornell box's lamp, so that rays pass through one lamp to the next, as in Cycles), the
uniform world, emissive triangles,
and metal, glass, rough glass, Blinn-Phong and diffuse materials with smooth normals; the
means agree within 4 standard errors (each pixel's own variance: the image's structure
is no noise), and the comparison fails when every light sample weighs 10% too much in
the MIS image (the control)."""
from __future__ import annotations

import functools

import numpy as np

from engine import (AreaLight, Material, PointLight, RenderContext, RenderSettings, SunLight,
                    World, render)
from engine_scenes import cornell_box, uv_sphere


SAMPLES = 4096


def _materials_scene(size=24):
    s = cornell_box(size, size)
    s.materials += [Material("metal", (0.9, 0.6, 0.3), metallic=1.0, roughness=0.3,
                             glossy_model="MULTI_GGX"),
                    Material("glass", (1, 1, 1), transmission=1.0, roughness=0.0, ior=1.45),
                    Material("rough glass", (0.8, 0.9, 1), transmission=1.0, roughness=0.4,
                             glossy_model="MULTI_GGX"),
                    Material("phong", (0.5, 0.5, 0.8), roughness=0.2, glossy_model="BLINN_PHONG"),
                    Material("glow", (0, 0, 0), emission=(4.0, 3.0, 2.0))]
    for k, c in enumerate([(-0.5, 0.2, 1.5), (0.5, -0.3, 0.9), (0.0, -0.6, 0.3),
                           (0.55, 0.4, 1.5), (-0.5, -0.6, 1.6)]):
        sph = uv_sphere(c, 0.22, 8, 16, f"s{k}", 3 + k)
        sph.corner_normals = (sph.positions[sph.triangles] - np.asarray(c)) / 0.22
        s.meshes.append(sph)
    m = np.eye(4)
    m[:3, 3] = (0.3, 0.3, 1.9)
    s.lights += [PointLight((0.4, -0.4, 1.2), (20, 20, 20)),
                 PointLight((-0.4, 0.0, 1.5), (10, 12, 14), radius=0.1),
                 PointLight((0.0, 0.4, 1.5), (10, 12, 14), radius=0.1, soft_falloff=True),
                 PointLight((0.0, 0.0, 1.9), (30, 30, 30), spot_size=1.0, spot_blend=0.3),
                 SunLight((0.2, 0.7, -1.0), (2, 2, 2), angle=0.1),
                 SunLight((0.0, 0.7, -1.0), (1, 1, 1)),
                 AreaLight(m, (10, 10, 10), "DISK", 0.3, 0.3),
                 AreaLight(m, (10, 10, 10), "ELLIPSE", 0.4, 0.2, visible_camera=False)]
    s.world = World((0.2, 0.25, 0.3))
    return s


@functools.lru_cache(maxsize=None)
def _materials_image_mean(mode, light_scale=1.0):
    """`_image_mean` of the materials scene at SAMPLES, rendered once per (mode, scale)
    for the module: the agreement test and its control share the BSDF-only image."""
    return _image_mean(_materials_scene(), mode, SAMPLES, light_scale)


def _image_mean(scene, mode, samples, light_scale=1.0, light_tree=None):
    """(mean radiance (3,), its standard error (3,)) over every sample of the image,
    direct light only (one bounce), estimated with `mode`; lights picked with the light
    tree unless `light_tree` is False or `light_scale` is not 1."""
    # each pixel's camera ray through its centre: no edge of a lamp or an emitter seen
    # by the camera adds noise that all three estimators share
    # (the control scales the pick's probabilities: it picks lights without the tree)
    settings = RenderSettings(samples=samples, seed=11, max_bounces=1, clamp_direct=0.0,
                              clamp_indirect=0.0, filter_glossy=0.0, filter_type="BOX",
                              filter_width=1e-3,
                              light_tree=light_scale == 1.0 if light_tree is None
                              else light_tree)
    ctx = RenderContext(scene, settings)
    try:
        ctx.integrator.mis_mode = mode
        if light_scale != 1.0:
            _scale_lamp_samples(ctx, light_scale)    # the control
        film, stats = render(scene, settings, context=ctx)
    finally:
        ctx.close()
    assert stats.nonfinite_samples == 0
    # each pixel's own variance: the image's structure is no noise
    n = film.count.astype(np.float64)[:, None]
    pixel_mean = film.sum / n
    pixel_var = np.maximum(film.sum_sq / n - pixel_mean ** 2, 0.0) / n
    pixels = len(n)
    return pixel_mean.mean(0), np.sqrt(pixel_var.sum(0)) / pixels


def _scale_lamp_samples(ctx, factor):
    """Multiply the selection pdfs' inverse: each entry's light sample weighs `factor`
    times more (its pick probability divided by it), which only next-event estimation
    reads."""
    from engine.kernels.lights.pack import SELECT_PDF
    ctx.integrator.lights[SELECT_PDF][:] /= factor


def _agree(a, b):
    (ma, sa), (mb, sb) = a, b
    return bool(np.all(np.abs(ma - mb) <= 4.0 * np.hypot(sa, sb)))


def test_light_bsdf_and_mis_estimators_agree():
    got = {mode: _materials_image_mean(mode) for mode in ("mis", "light", "bsdf")}
    for mode, (m, se) in got.items():
        print(mode, m.round(5), "se", se.round(5))
    assert got["mis"][0].min() > 0.05                    # a lit scene
    assert _agree(got["mis"], got["light"])
    assert _agree(got["mis"], got["bsdf"])
    # the estimators differ (their noise does): not one computation three times
    assert not np.allclose(got["light"][1], got["bsdf"][1], rtol=0.05)


def test_a_light_sampling_error_is_caught():
    right = _materials_image_mean("bsdf")
    wrong = _materials_image_mean("mis", light_scale=1.1)
    print("bsdf", right[0].round(5), "mis with light samples x1.1", wrong[0].round(5))
    assert not _agree(right, wrong)


def test_rays_pass_through_lamps_to_the_lamps_behind():
    """A ray passes through a lamp and goes on to what lies behind it, other lamps
    included (Cycles advances a ray past the light it found): a camera looking up
    through a small disk lamp at a larger square lamp sees the sum of their radiances,
    as each of them alone gives (superposition), where both overlap."""
    from engine import Camera, Scene
    from engine_scenes import look_at

    def lamp(z, shape, size, power):
        m = np.eye(4)
        m[:3, 3] = (0.0, 0.0, z)
        return AreaLight(m, (power,) * 3, shape, size, size)

    disk, square = lamp(1.9, "DISK", 0.2, 5.0), lamp(1.98, "SQUARE", 1.0, 40.0)
    cam = Camera(look_at((0, 0, 0), (0, 0, 1), up=(0, 1, 0)), lens=200.0, clip_start=1e-3)

    def centre(lights):
        scene = Scene(cam, 5, 5, [], [Material("grey")], lights, World((0, 0, 0)))
        film, _ = render(scene, RenderSettings(samples=4, filter_type="BOX",
                                               filter_width=1e-3))
        return film.mean()[2, 2]

    alone_disk, alone_square, both = centre([disk]), centre([square]), centre([disk, square])
    assert alone_disk.min() > 0 and alone_square.min() > 0
    np.testing.assert_allclose(both, alone_disk + alone_square, rtol=1e-12)
