"""Cameras and geometry at their limits: every render is finite and non-negative, and
where the limit has a known answer, the render gives it.

Cameras: f-stop 0.01 and 1e4 (aperture radius lens / (2 f-stop), as the exporter
computes it), focus distance 1e-4 and 1e6, lens 1 mm and 5000 mm, orthographic scale
1e-3 and 1e4, resolution 1 x 1, 1 x 4096 and 4096 x 1. Geometry: needle triangles,
duplicate vertices and triangles, a triangle of 1e-7 m, a mesh with no faces, objects
scaled to zero, an emissive triangle of zero area, lights of zero size."""
import copy

import numpy as np
import pytest

from engine import (AreaLight, Camera, Material, PointLight, RenderSettings, Scene, SunLight,
                    TriangleMesh, World, render)
from engine_scenes import cornell_box, look_at, quad
from extreme_checks import sane

SETTINGS = dict(samples=8, seed=3)


def _render(scene, **kw):
    film, stats = render(scene, RenderSettings(**{**SETTINGS, **kw}))
    assert not sane(film, stats), sane(film, stats)
    return film.mean()


@pytest.fixture(scope="module")
def pinhole():
    return _render(cornell_box(16, 16))


def _with_camera(size=(16, 16), **camera):
    scene = cornell_box(*size)
    for k, v in camera.items():
        setattr(scene.camera, k, v)
    return scene


def _aperture(fstop, lens=35.0):
    return lens * 1e-3 / (2.0 * fstop)          # drt_addon/export/camera.py


def test_f_stop_1e4_is_a_pinhole(pinhole):
    img = _render(_with_camera(aperture_radius=_aperture(1e4), focus_distance=3.9))
    assert abs(img.mean() / pinhole.mean() - 1) < 0.03


@pytest.mark.parametrize("fstop,focus", [(0.01, 3.0), (0.01, 1e6), (1e4, 1e-3)])
def test_extreme_apertures_keep_a_uniform_plane_exact(fstop, focus):
    """Depth of field only moves light between pixels: a uniformly lit diffuse plane
    (sun, direct light only), 3 m below a camera looking straight down, stays exactly
    rho / pi E cos(theta) in every pixel through a 1.75 m aperture (f/0.01 at 35 mm)
    focused on it or at 1e6 m, and through f/1e4 focused at 1 mm."""
    plane = quad((0, 0, 0), (1e3, 0, 0), (0, 1e3, 0), "plane")
    cam = Camera(look_at((0, 0, 3), (0, 0, 0), up=(0, 1, 0)), lens=35, clip_start=1e-3,
                 clip_end=1e5,
                 aperture_radius=_aperture(fstop), focus_distance=focus)
    theta = np.radians(30)
    sun = SunLight((0, -np.sin(theta), -np.cos(theta)), (2.0,) * 3)
    scene = Scene(cam, 16, 16, [plane], [Material("m", (0.5,) * 3, specular_ior_level=0.0)],
                  [sun], World((0, 0, 0)))
    img = _render(scene, diffuse_bounces=0)
    np.testing.assert_allclose(img, 0.5 / np.pi * 2.0 * np.cos(theta), rtol=1e-9)


def test_focus_distance_1e4_sees_only_the_world():
    """Focus 0.1 mm in front of an f/2.8 lens: every lens ray leaves almost parallel to
    the lens and its near clip (clip start along the view axis) lies beyond the scene, so
    only the world is seen, as in Cycles (measured with the default cube scene at 16 x 16
    pixels: both engines give the world colour in every pixel)."""
    scene = _with_camera(aperture_radius=_aperture(2.8), focus_distance=1e-4)
    scene.world = World((0.25, 0.5, 0.75))
    img = _render(scene)
    np.testing.assert_allclose(img, np.broadcast_to((0.25, 0.5, 0.75), img.shape), rtol=1e-12)


def test_focus_distance_1e6_with_a_small_aperture_is_nearly_the_pinhole(pinhole):
    img = _render(_with_camera(aperture_radius=_aperture(16.0), focus_distance=1e6))
    assert abs(img.mean() / pinhole.mean() - 1) < 0.05


def test_lens_1mm_sees_the_whole_box_and_5000mm_one_patch(pinhole):
    wide = _render(_with_camera(size=(64, 64), lens=1.0))
    tele = _render(_with_camera(lens=5000.0))
    # 1 mm: a 172-degree view, the box (28 degrees) in the middle 2 x 2 pixels; black
    # around it
    assert wide[31:33, 31:33].max() > 0 and wide[:24].max() == 0
    # 5000 mm: a 2.8 cm patch of the back wall (white, behind the tall box's edge or not)
    assert tele.mean() > 0 and tele.mean(-1).std() < 0.5 * pinhole.mean(-1).std()


@pytest.mark.parametrize("scale", [1e-3, 1e4])
def test_orthographic_scale_limits(scale):
    img = _render(_with_camera(kind="ORTHO", ortho_scale=scale))
    if scale == 1e4:       # the 2 m box is well under one pixel: a black frame almost
        assert img.mean() < 1e-3
    else:                  # a 1 mm patch of the back wall through the box's open front
        assert img.min() > 0


@pytest.mark.parametrize("size", [(1, 1), (1, 4096), (4096, 1)])
def test_extreme_resolutions(size, pinhole):
    img = _render(_with_camera(size=size), samples=4)
    assert img.shape == (size[1], size[0], 3)
    assert img.max() > 0


def _lit_floor_scene(extra_meshes, materials=None, lights=None, size=16):
    floor = quad((0, 0, 0), (2, 0, 0), (0, 2, 0), "floor")
    cam = Camera(look_at((0, -3, 3), (0, 0, 0)), lens=35)
    mats = materials or [Material("m", (0.8, 0.8, 0.8), specular_ior_level=0.0)]
    lights = lights if lights is not None else [PointLight((0, 0, 2), (200.0,) * 3)]
    return Scene(cam, size, size, [floor] + extra_meshes, mats, lights, World((0.05,) * 3))


def test_needle_duplicate_and_tiny_triangles():
    """Needles 1 m long and 1e-9 m wide, a vertex used twice in one triangle, the same
    triangle twice (coincident faces), a 1e-7 m triangle: all render, and the floor
    under them looks as it does without them (they cover almost nothing)."""
    pts = np.array([[-1, 0, 0.5], [1, 0, 0.5], [0, 1e-9, 0.5],      # needle
                    [0, 0, 0.7], [0, 0, 0.7], [0.3, 0.2, 0.7],      # duplicate vertex
                    [0.5, 0.5, 0.2], [0.6, 0.5, 0.2], [0.5, 0.6, 0.2],
                    [0.2, -0.3, 0.4], [0.2 + 1e-7, -0.3, 0.4], [0.2, -0.3 + 1e-7, 0.4]])
    tris = np.array([[0, 1, 2], [3, 4, 5], [6, 7, 8], [6, 7, 8], [9, 10, 11], [0, 2, 1]])
    clutter = TriangleMesh("clutter", pts, tris, np.zeros(len(tris)))
    base = _render(_lit_floor_scene([]))
    img = _render(_lit_floor_scene([clutter]))
    # one 0.005 m^2 (doubled) triangle casts the only real shadow: a few % of the mean
    assert abs(img.mean() / base.mean() - 1) < 0.05


def test_mesh_without_faces_and_objects_scaled_to_zero():
    """A mesh with vertices but no faces and a cube scaled to a point change nothing; a
    cube scaled to zero height renders as the two coincident squares it has become: as
    in Cycles, a ray leaving one meets the other at distance 0, so the lit square is
    darker, speckled by its own shadow (tests/test_coincident_faces_vs_cycles.py)."""
    empty = TriangleMesh("no faces", np.random.default_rng(0).random((5, 3)),
                         np.zeros((0, 3), np.int32), np.zeros(0))
    from engine_scenes import box
    point = box((0.2, 0.2, 0.5), (0.4, 0.4, 0.7), "point")
    point.positions = np.zeros_like(point.positions) + (0.3, 0.3, 0.6)
    flat = box((-0.2, -0.2, 0.8), (0.2, 0.2, 1.2), "flat")
    flat.positions = flat.positions * (1, 1, 0) + (0, 0, 1.0)
    base = _render(_lit_floor_scene([]))
    no_op = _render(_lit_floor_scene([empty, point]))
    # (their vertices move the median vertex Embree sees the scene around, so
    # float32 rounding differs: 1e-7)
    np.testing.assert_allclose(no_op, base, rtol=1e-6, atol=0)
    squashed = _render(_lit_floor_scene([flat]))
    square = _render(_lit_floor_scene([quad((0, 0, 1.0), (0.2, 0, 0), (0, 0.2, 0))]))
    print(f"squashed cube vs square: mean {squashed.mean():.5f} vs {square.mean():.5f}, "
          f"base {base.mean():.5f}")
    assert np.isfinite(squashed).all() and squashed.min() >= 0.0
    assert 0.8 < squashed.mean() / square.mean() < 1.0
    assert np.abs(squashed - base).max() > 0.05          # and it is there


def test_emissive_triangle_of_zero_area_adds_no_light_and_no_nan():
    pts = np.array([[0, 0, 1], [1, 0, 1], [2, 0, 1], [0.1, 0.1, 1], [0.1, 0.1, 1],
                    [0.1, 0.1, 1]])
    lamp = TriangleMesh("zero lamp", pts, [[0, 1, 2], [3, 4, 5]], [1])
    mats = [Material("m", (0.8,) * 3, specular_ior_level=0.0),
            Material("glow", (0.8,) * 3, emission=(1e3,) * 3)]
    base = _render(_lit_floor_scene([], mats))
    img = _render(_lit_floor_scene([lamp], mats))
    np.testing.assert_allclose(img, base, rtol=1e-6, atol=0)     # float32 rounding: 1e-7


def _light_under(light):
    """Radiance of the middle of a diffuse floor 1 m under `light` (direct light only)."""
    floor = quad((0, 0, 0), (1, 0, 0), (0, 1, 0), "floor")
    m = np.eye(4)
    m[:3, 3] = (0, 0, 1e-3)
    cam = Camera(m, kind="ORTHO", ortho_scale=0.01, clip_start=1e-4, clip_end=1.0)
    scene = Scene(cam, 4, 4, [floor], [Material("m", (1.0,) * 3, specular_ior_level=0.0)],
                  [light], World((0, 0, 0)))
    return _render(scene, diffuse_bounces=0, filter_type="BOX", filter_width=0.5).mean()


def test_lights_of_zero_size_are_their_limits():
    """A point light of radius 0, a sun of angle 0, a spot of Blender's smallest cone (1
    degree) and an area light of 1e-9 m: each lights the floor below with the limit of
    its kind (point: S / (4 pi) / d^2 x rho / pi; area, one-sided cosine emitter: 4x a
    point light's of the same power straight below it; the sun: rho / pi E)."""
    s = 100.0
    point = _light_under(PointLight((0, 0, 1), (s,) * 3))
    np.testing.assert_allclose(point, s / (4 * np.pi) / np.pi, rtol=1e-3)
    spot = _light_under(PointLight((0, 0, 1), (s,) * 3, spot_size=np.radians(1.0)))
    np.testing.assert_allclose(spot, point, rtol=1e-3)
    m = np.eye(4)
    m[:3, 3] = (0, 0, 1)
    area = _light_under(AreaLight(m, (s,) * 3, "SQUARE", 1e-9, 1e-9))
    np.testing.assert_allclose(area, 4 * point, rtol=1e-3)
    disk = _light_under(AreaLight(m, (s,) * 3, "DISK", 1e-9, 1e-9))
    np.testing.assert_allclose(disk, 4 * point, rtol=1e-3)
    sun = _light_under(SunLight((0, 0, -1), (3.0,) * 3, angle=0.0))
    np.testing.assert_allclose(sun, 3.0 / np.pi, rtol=1e-9)


def test_area_light_of_zero_size_is_a_clear_error():
    """The exporter skips a zero-size area lamp with a warning (as Cycles does;
    tests/test_degenerate_input.py); handed straight to the engine it is an error that
    names the lamp, never a NaN."""
    m = np.eye(4)
    scene = copy.deepcopy(cornell_box(4, 4))
    scene.lights = [AreaLight(m, (10.0,) * 3, "SQUARE", 0.0, 0.0, name="flat")]
    with pytest.raises(ValueError, match="flat"):
        render(scene, RenderSettings(samples=1))
