"""The compiled path tracer (engine/integrators/compiled_path.py, kernels in
engine/kernels/) against the NumPy reference integrator (engine/integrators/path.py):
the same estimator with the same random numbers must give the same image, to rounding,
on every feature the compiled path handles: lamps of every kind, emissive triangles, the
world and suns, glossy, metal, glass and Blinn-Phong materials, smooth normals, image
textures, stochastic transparency with its bounce limit, clamps, Film > Transparent,
holdouts and the three MIS modes. A perturbed scene must not match (negative control),
and scenes the compiled path does not handle must fall back to the reference."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from engine import (AreaLight, Material, PointLight, RenderContext, RenderSettings, SunLight,
                    World, render)
from engine.integrators.compiled_path import CompiledPathIntegrator
from engine.integrators.path import PathIntegrator
from engine.textures import Texture, TextureInput
from engine_scenes import cornell_box, uv_sphere

RTOL = 1e-9


def _both(scene, settings, mis_mode="mis"):
    # the NumPy reference has no Filter Glossy (a Cycles bias the compiled path models:
    # tests/test_filter_glossy.py), so both run without it
    settings = dataclasses.replace(settings, filter_glossy=0.0)
    out = []
    for compiled in (True, False):
        ctx = RenderContext(scene, settings)
        if compiled:
            assert isinstance(ctx.integrator, CompiledPathIntegrator)
        else:
            ctx.integrator = PathIntegrator(ctx)
        ctx.integrator.mis_mode = mis_mode
        film, _ = render(scene, settings, context=ctx)
        out.append((film.mean(), film.mean_alpha()))
    return out


def _assert_same(scene, settings, **kw):
    (a, aa), (b, ba) = _both(scene, settings, **kw)
    scale = max(b.max(), 1e-12)
    assert np.abs(a - b).max() <= RTOL * scale, np.abs(a - b).max() / scale
    assert np.abs(aa - ba).max() <= 1e-12
    assert b.max() > 0                         # the scene is lit: a real comparison


def _materials_scene():
    s = cornell_box(40, 40)
    s.materials += [Material("metal", (0.9, 0.6, 0.3), metallic=1.0, roughness=0.3),
                    Material("glass", (1, 1, 1), transmission=1.0, roughness=0.0, ior=1.45),
                    Material("rough glass", (0.8, 0.9, 1), transmission=1.0, roughness=0.4),
                    Material("phong", (0.5, 0.5, 0.8), roughness=0.2, glossy_model="BLINN_PHONG"),
                    Material("glow", (0, 0, 0), emission=(4.0, 3.0, 2.0))]
    for k, c in enumerate([(-0.5, 0.2, 1.5), (0.5, -0.3, 0.9), (0.0, -0.6, 0.3),
                           (0.55, 0.4, 1.5), (-0.5, -0.6, 1.6)]):
        sph = uv_sphere(c, 0.22, 8, 16, f"s{k}", 3 + k)
        sph.corner_normals = (sph.positions[sph.triangles] - np.asarray(c)) / 0.22
        s.meshes.append(sph)
    return s


def test_materials_and_smooth_normals():
    _assert_same(_materials_scene(), RenderSettings(samples=8))


@pytest.mark.parametrize("mode", ["mis", "light", "bsdf"])
def test_mis_modes(mode):
    _assert_same(_materials_scene(), RenderSettings(samples=4), mis_mode=mode)


def test_every_lamp_kind_world_and_sun():
    s = _materials_scene()
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
    _assert_same(s, RenderSettings(samples=4))


def test_textures_transparency_and_clamps():
    s = cornell_box(40, 40)
    rng = np.random.default_rng(3)
    tex = Texture(rng.uniform(0, 1, (8, 8, 4)).astype(np.float32), srgb=True)
    s.materials[0].base_color_texture = TextureInput(tex)
    s.materials[0].roughness_texture = TextureInput(tex, channel="luminance")
    s.materials[0].alpha = 0.6
    s.materials[1].alpha_texture = TextureInput(tex, channel="alpha")
    s.materials[1].transparent_color = (0.9, 0.5, 0.2)
    for mesh in s.meshes:
        mesh.uvs = rng.uniform(0, 1, (len(mesh.triangles), 3, 2)).astype(np.float32)
    _assert_same(s, RenderSettings(samples=8, clamp_direct=0.5, clamp_indirect=0.3,
                                   transparent_bounces=1))


def test_film_transparent_and_holdouts():
    s = _materials_scene()
    s.meshes[-1].holdout = True
    s.meshes[2].holdout = True          # the back wall: camera rays see a hole
    s.film_transparent = True
    s.world = World((0.3, 0.3, 0.3))
    _assert_same(s, RenderSettings(samples=4))


def test_a_different_scene_does_not_match():
    s = cornell_box(32, 32)
    settings = RenderSettings(samples=4)
    ctx = RenderContext(s, settings)
    a = render(s, settings, context=ctx)[0].mean()
    s.materials[0].base_color = (0.7299, 0.73, 0.73)       # 0.01% darker in red
    b = render(s, settings)[0].mean()
    assert np.abs(a - b).max() > RTOL * b.max()


def test_motion_falls_back_to_the_reference():
    from engine.motion import RigidMotion, Shutter
    s = cornell_box(16, 16)
    m0, m1 = np.eye(4), np.eye(4)
    m1[:3, 3] = (0.1, 0, 0)
    mesh = s.meshes[-1]
    mesh.motion = RigidMotion(np.array([0.0, 1.0]), np.stack([m0, m1]))
    s.shutter = Shutter()
    ctx = RenderContext(s, RenderSettings(samples=1))
    assert isinstance(ctx.integrator, PathIntegrator)


@pytest.mark.parametrize("kind,aperture,blades,filt", [
    ("PERSP", 0.0, 0, "BLACKMAN_HARRIS"), ("PERSP", 0.05, 0, "BLACKMAN_HARRIS"),
    ("PERSP", 0.05, 6, "BOX"), ("ORTHO", 0.0, 0, "BOX")])
def test_camera_ray_kernel_matches_the_camera_model(kind, aperture, blades, filt):
    """The compiled camera rays (engine/kernels/camera_rays.py) against CameraModel with
    the same sampler numbers and pixel filter."""
    from engine.render import camera_rays
    from engine.sampling import dimensions as D
    s = cornell_box(37, 23)
    c = s.camera
    c.kind, c.aperture_radius, c.blades, c.focus_distance = kind, aperture, blades, 3.0
    c.blade_rotation, c.aperture_ratio, c.shift_x, c.shift_y = 0.3, 1.3, 0.1, -0.05
    ctx = RenderContext(s, RenderSettings(samples=16, filter_type=filt, filter_width=1.7))
    pixel = np.repeat(np.arange(37 * 23), 16)
    index = np.tile(np.arange(16), 37 * 23)
    rays, _ = camera_rays(ctx, pixel, index)
    u = ctx.sampler.get_2d(D.PIXEL, pixel, index)
    off = ctx.filter.sample(u)
    xy = np.stack([pixel % 37 + 0.5 + off[:, 0], pixel // 37 + 0.5 + off[:, 1]], axis=1)
    lens = ctx.sampler.get_2d(D.LENS, pixel, index) if ctx.camera.has_lens else None
    ref = ctx.camera.generate(xy, lens)
    assert np.allclose(rays.origins, ref.origins, rtol=0, atol=1e-12)
    assert np.allclose(rays.directions, ref.directions, rtol=0, atol=1e-13)
    assert np.allclose(rays.tmax, ref.tmax, rtol=1e-13)
    assert not np.allclose(np.roll(rays.origins, 1, 0), ref.origins, atol=1e-6)
