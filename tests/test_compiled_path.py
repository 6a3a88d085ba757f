"""The compiled path tracer (engine/integrators/compiled_path.py, kernels in
engine/kernels/) against the NumPy reference integrator (engine/integrators/path.py):
the same estimator with the same random numbers must give the same image, to rounding,
on every feature the compiled path handles: lamps of every kind, emissive triangles, the
world and suns, glossy, metal, glass (single- and multiple-scattering GGX) and
Blinn-Phong materials, smooth normals, image textures, stochastic transparency with its
bounce limit, clamps, Film > Transparent, holdouts, the three MIS modes, and motion blur
of objects (rigid and deforming) and cameras. A perturbed scene must not match (negative
control), and scenes the compiled path does not handle (moving lamps) must fall back to
the reference."""
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


def _turn_about(centre, axis, angle):
    """The rotation by `angle` about the line through `centre` along `axis`."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    m[:3, 3] = np.asarray(centre) - m[:3, :3] @ np.asarray(centre)
    return m


def _moving_scene(turn=np.radians(150.0)):
    """The materials scene set in motion: a smooth metal sphere turning by `turn` about
    the box's vertical axis (3 motion steps), the glass sphere moving and stretching, a
    deforming sphere, the short box sliding, a large (Embree-traced) sphere moving, the
    emissive sphere moving, and the camera moving and turning."""
    from engine.motion import DeformMotion, RigidMotion, Shutter
    s = _materials_scene()
    spheres = {m.name: m for m in s.meshes}
    steps = np.array([0.0, 0.5, 1.0])
    spheres["s0"].motion = RigidMotion(steps, np.stack(
        [_turn_about((0, 0, 1), (0, 0, 1), f * turn) for f in steps]))
    stretch = np.eye(4)
    stretch[:3, :3] = np.diag([1.4, 1.0, 0.8])
    stretch[:3, 3] = (0.2, 0.1, 0.0)
    c = np.array([0.5, -0.3, 0.9])
    grow = np.eye(4)
    grow[:3, 3] = c
    spheres["s1"].motion = RigidMotion([0.0, 1.0],
                                       [np.eye(4), grow @ stretch @ np.linalg.inv(grow)])
    wobble = spheres["s2"]
    end = wobble.positions + np.random.default_rng(7).normal(0, 0.03, wobble.positions.shape)
    wobble.motion = DeformMotion([0.0, 1.0], np.stack([wobble.positions, end + (0, 0.2, 0)]))
    slide = np.eye(4)
    slide[:3, 3] = (-0.3, 0.2, 0.0)
    spheres["short"].motion = RigidMotion([0.0, 1.0], [np.eye(4), slide])
    spheres["s4"].motion = RigidMotion([0.0, 1.0], [np.eye(4), slide])
    big = uv_sphere((0.3, 0.5, 0.3), 0.25, 16, 32, "big", 0)
    big.corner_normals = (big.positions[big.triangles] - (0.3, 0.5, 0.3)) / 0.25
    big.motion = RigidMotion([0.0, 1.0], [np.eye(4), _turn_about((0.3, 0.3, 0.3), (1, 0, 0), 2.0)])
    s.meshes.append(big)
    cam = s.camera
    cam.motion = RigidMotion([0.0, 1.0], [cam.matrix, _turn_about((0, -3.9, 1.0), (0, 0, 1), 0.03)
                                          @ cam.matrix])
    s.shutter = Shutter()
    return s


def test_motion_blur_objects_and_camera():
    """Rigid (translating, turning by 150 degrees, stretching) and deforming objects,
    small ones intersected in the kernel and a large one by Embree, an emissive one and
    a moving camera: the compiled path equals the NumPy reference."""
    s = _moving_scene()
    ctx = RenderContext(s, RenderSettings(samples=1))
    assert ctx.has_motion and len(ctx.accel.moving) == 6
    assert (ctx.accel.tlas.unit_root < 0).any() and (ctx.accel.tlas.unit_root >= 0).any()
    ctx.close()
    _assert_same(s, RenderSettings(samples=8))


def test_motion_blur_through_transparency_and_textures():
    from engine.motion import RigidMotion, Shutter
    s = cornell_box(32, 32)
    rng = np.random.default_rng(5)
    tex = Texture(rng.uniform(0, 1, (8, 8, 4)).astype(np.float32), srgb=True)
    s.materials.append(Material("veil", (0.8, 0.3, 0.2), alpha=0.5,
                                transparent_color=(0.9, 0.6, 0.3)))
    s.materials[0].base_color_texture = TextureInput(tex)
    tall = s.meshes[5]
    tall.material_indices[:] = 3
    tall.motion = RigidMotion([0.0, 1.0],
                              [np.eye(4), _turn_about((-0.3, 0.2, 0.6), (0, 0, 1), 2.0)])
    short = s.meshes[6]
    short.motion = RigidMotion([0.0, 1.0],
                               [np.eye(4), _turn_about((0.4, -0.3, 0.3), (1, 1, 0), 1.0)])
    for mesh in s.meshes:
        mesh.uvs = rng.uniform(0, 1, (len(mesh.triangles), 3, 2)).astype(np.float32)
    s.shutter = Shutter()
    _assert_same(s, RenderSettings(samples=8, transparent_bounces=2))


def test_a_different_motion_does_not_match():
    """Negative control: the metal sphere turning 0.01 degrees less changes the image
    by far more than the tolerance."""
    settings = RenderSettings(samples=2)
    a = render(_moving_scene(), settings)[0].mean()
    b = render(_moving_scene(np.radians(149.99)), settings)[0].mean()
    assert np.abs(a - b).max() > 1e3 * RTOL * b.max()


def test_moving_lamps_render_compiled_as_the_reference_does():
    """A lamp moving during the shutter (two slices) renders in the compiled tracer
    (`_both` checks it is the integrator chosen) as the NumPy reference renders it."""
    from engine.motion import Shutter
    s = cornell_box(16, 16, light_kind="point")
    lamp = s.lights[0]
    lamp.motion_slices = [PointLight((x, 0.0, 1.8), (60.0, 60.0, 60.0)) for x in (-0.4, 0.4)]
    s.shutter = Shutter()
    _assert_same(s, RenderSettings(samples=4, max_bounces=3))


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
