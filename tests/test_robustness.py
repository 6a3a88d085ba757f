"""Numerical robustness at the extremes: scene scales 1e-3 to 1e4, grazing light, thin
walls, degenerate and tiny triangles, near-zero apertures, bad input."""
import numpy as np
import pytest

from engine import (Camera, Material, PointLight, RenderSettings, Scene, SunLight, TriangleMesh,
                    World, render)
from engine_scenes import box, cornell_box, look_at, quad, scaled

SCALES = [1e-3, 1.0, 1e2, 1e4]


@pytest.fixture(scope="module")
def cornell_unit():
    film, _ = render(cornell_box(32, 32), RenderSettings(samples=16, seed=5))
    return film.mean()


@pytest.mark.parametrize("s", [1e-3, 1e4])
def test_scene_scale_does_not_change_the_image(cornell_unit, s):
    """Same seed, same scene at another scale: same random numbers, same paths, so the
    image must agree pixel by pixel up to float32 rounding of the geometry."""
    film, stats = render(scaled(cornell_box(32, 32), s), RenderSettings(samples=16, seed=5))
    img = film.mean()
    assert stats.nonfinite_samples == 0 and np.isfinite(img).all()
    ref = cornell_unit
    rel_mean = abs(img.mean() - ref.mean()) / ref.mean()
    mad = np.abs(np.clip(img, 0, 2) - np.clip(ref, 0, 2)).mean() / np.clip(ref, 0, 2).mean()
    print(f"scale {s:g}: mean differs by {rel_mean:.3%}, pixel MAD {mad:.3%}")
    assert rel_mean < 0.01
    assert mad < 0.03


@pytest.mark.parametrize("s", SCALES)
@pytest.mark.parametrize("far", [False, True])
def test_no_shadow_acne_at_grazing_light(s, far):
    """A plane under a delta sun at 85 degrees from the normal: with direct light only the
    exact answer is rho/pi * E * cos(85 deg) in every pixel, so one self-shadowed shadow
    ray (acne) shows as a pixel below it. The plane is also moved far from the origin."""
    offset = np.array([3e3, -2e3, 1e3]) * s if far else np.zeros(3)
    plane = quad(offset, (s, 0, 0), (0, s, 0), "plane")
    theta = np.radians(85.0)
    sun = SunLight((-np.sin(theta), 0.0, -np.cos(theta)), (3.0, 3.0, 3.0))
    cam = Camera(look_at(offset + np.array([0, -0.5, 2.0]) * s, offset), lens=50,
                 clip_start=1e-2 * s, clip_end=1e2 * s)
    rho = 0.8
    scene = Scene(cam, 24, 24, [plane], [Material("m", (rho,) * 3, specular_ior_level=0.0)],
                  [sun], World((0, 0, 0)))
    film, _ = render(scene, RenderSettings(samples=4, diffuse_bounces=0, filter_type="BOX",
                                           filter_width=0.1))
    img = film.mean()[..., 0]
    expected = rho / np.pi * 3.0 * np.cos(theta)
    lit = img[img > 0]
    assert lit.size == img.size, f"{(img == 0).sum()} acne pixels"
    np.testing.assert_allclose(img, expected, rtol=1e-6)


@pytest.mark.parametrize("s", SCALES)
@pytest.mark.parametrize("t", [1e-2, 1e-4])
def test_no_light_leaks_into_a_closed_thin_walled_box(s, t):
    """A point light outside a closed box whose walls are 1% or 0.01% of its size thick:
    with full global illumination not a single sample inside may be lit (a ray offset
    larger than the wall would let shadow rays start beyond it)."""
    walls = [box((-1, -1, -1), (1, 1, -1 + t)), box((-1, -1, 1 - t), (1, 1, 1)),
             box((-1, -1, -1), (-1 + t, 1, 1)), box((1 - t, -1, -1), (1, 1, 1)),
             box((-1, -1, -1), (1, -1 + t, 1)), box((-1, 1 - t, -1), (1, 1, 1))]
    for w in walls:
        w.positions = w.positions * s
    light = PointLight((0, 0, 1.05 * s), (1e3 * s * s,) * 3)      # just above the roof
    cam = Camera(look_at((0, -0.8 * s, 0.5 * s), (0, 0, -0.9 * s)), lens=18,
                 clip_start=1e-3 * s, clip_end=10 * s)
    scene = Scene(cam, 24, 24, walls, [Material("w", (0.9, 0.9, 0.9), specular_ior_level=0.0)],
                  [light], World((0, 0, 0)))
    film, _ = render(scene, RenderSettings(samples=8))
    assert film.count.sum() == 24 * 24 * 8
    assert film.sum.max() == 0.0


def test_degenerate_and_tiny_triangles_render_finite():
    pts = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0],          # collinear
                    [0, 1, 0], [0, 1, 0], [0, 1, 0],          # one point
                    [0, 0, 0], [1e-12, 0, 0], [0, 1e-12, 0],  # tiny
                    [-1, -1, 0], [1, -1, 0], [1, 1, 0]], float)
    tris = np.arange(12).reshape(4, 3)
    normals = np.zeros((4, 3, 3), np.float32)                 # zero-length shading normals
    normals[3] = (0, 0, 1)
    mesh = TriangleMesh("bad", pts, tris, np.zeros(4), corner_normals=normals)
    cam = Camera(look_at((0, 0, 3), (0, 0, 0), up=(0, 1, 0)), lens=30)
    scene = Scene(cam, 16, 16, [mesh], [Material()], [PointLight((0, 0, 2), (100,) * 3)])
    film, stats = render(scene, RenderSettings(samples=4))
    assert stats.nonfinite_samples == 0
    assert np.isfinite(film.mean()).all() and film.mean().max() > 0


def test_tiny_aperture_equals_pinhole():
    scene = cornell_box(16, 16)
    pin, _ = render(scene, RenderSettings(samples=16, seed=3, diffuse_bounces=0))
    scene.camera.aperture_radius = 1e-12
    scene.camera.focus_distance = 3.9
    lens, _ = render(scene, RenderSettings(samples=16, seed=3, diffuse_bounces=0))
    a, b = np.clip(pin.mean(), 0, 1), np.clip(lens.mean(), 0, 1)
    assert np.isfinite(b).all()
    assert abs(a.mean() - b.mean()) / a.mean() < 0.03


def test_nan_geometry_is_a_clear_error():
    pts = np.array([[0, 0, 0], [1, 0, np.nan], [0, 1, 0]])
    mesh = TriangleMesh("broken", pts, [[0, 1, 2]], [0])
    scene = Scene(Camera(np.eye(4)), 8, 8, [mesh], [Material()], [])
    with pytest.raises(ValueError, match="broken.*non-finite"):
        render(scene, RenderSettings(samples=1))


@pytest.mark.parametrize("kwargs,match", [
    (dict(samples=0), "samples"), (dict(sampler="halton"), "sampler"),
    (dict(max_bounces=-1), "max_bounces"), (dict(filter_width=0.0), "filter_width"),
    (dict(clamp_indirect=float("nan")), "clamp_indirect"),
])
def test_absurd_settings_are_clear_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        render(cornell_box(4, 4), RenderSettings(**kwargs))


def test_scene_without_lights_or_geometry_renders_black_or_background():
    empty = Scene(Camera(np.eye(4)), 8, 8, [], [Material()], [], World((0.2, 0.3, 0.4)))
    film, _ = render(empty, RenderSettings(samples=2))
    np.testing.assert_allclose(film.mean(), np.broadcast_to([0.2, 0.3, 0.4], (8, 8, 3)))


@pytest.mark.parametrize("s", SCALES)
@pytest.mark.parametrize("gap", [1e-4, 2e-6])
def test_no_leak_under_a_sheet_lying_on_a_table(s, gap):
    """A sheet hovering 1e-4 or 2e-6 (relative) above a table, lit from straight above:
    the table under the sheet must be black. A ray offset larger than the gap would start
    shadow rays above the sheet and light the table through it: DRT's rays start on the
    surface they leave (engine.embree.self_hits), where until 2026-11-30 they started
    2^-17 of the coordinates' magnitude above it (7.6 mm at 1 km: 2e-6 leaked)."""
    table = quad((0, 0, 0), (s, 0, 0), (0, s, 0), "table")
    sheet = quad((0, 0, gap * s), (0.6 * s, 0, 0), (0, 0.6 * s, 0), "sheet")
    sun = SunLight((0, 0, -1), (5.0, 5.0, 5.0))
    # an orthographic camera between table and sheet, looking down at the table
    m = np.eye(4)
    m[:3, 3] = (0, 0, 0.5 * gap * s)
    cam = Camera(m, kind="ORTHO", ortho_scale=1.0 * s, clip_start=0.1 * gap * s, clip_end=s)
    scene = Scene(cam, 20, 20, [table, sheet],
                  [Material("m", (0.8,) * 3, specular_ior_level=0.0)], [sun])
    film, _ = render(scene, RenderSettings(samples=2, diffuse_bounces=0, filter_type="BOX",
                                           filter_width=0.1))
    img = film.mean()[..., 0]
    assert img.max() == 0.0, f"{(img > 0).sum()} leaking pixels"


@pytest.mark.parametrize("s", SCALES)
def test_no_leak_through_a_sheet_under_a_light_panel(s):
    """An emissive panel with an opaque sheet 2e-6 (relative) under it, over a table: the
    table must be black. A shadow ray towards the panel names its triangle and runs to the
    sampled point, as Cycles' run to ls->P naming ls->prim; until 2026-11-30 they stopped
    2^-17 of the coordinates' magnitude short of it, before the sheet, and lit the table
    through it."""
    table = quad((0, 0, 0), (s, 0, 0), (0, s, 0), "table")
    panel = quad((0, 0, s), (0.3 * s, 0, 0), (0, -0.3 * s, 0), "panel", material=1)
    sheet = quad((0, 0, s * (1.0 - 2e-6)), (0.5 * s, 0, 0), (0, 0.5 * s, 0), "sheet")
    m = np.eye(4)
    m[:3, 3] = (0, 0, 0.5 * s)
    cam = Camera(m, kind="ORTHO", ortho_scale=1.0 * s, clip_start=1e-3 * s, clip_end=s)
    mats = [Material("m", (0.8,) * 3, specular_ior_level=0.0),
            Material("light", (0.0,) * 3, specular_ior_level=0.0, emission=(10.0,) * 3)]
    scene = Scene(cam, 20, 20, [table, panel, sheet], mats, [])
    film, _ = render(scene, RenderSettings(samples=4, diffuse_bounces=0, filter_type="BOX",
                                           filter_width=0.1))
    img = film.mean()[..., 0]
    assert img.max() == 0.0, f"{(img > 0).sum()} leaking pixels"
    # the control: without the sheet the panel lights the table
    lit, _ = render(Scene(cam, 20, 20, [table, panel], mats, []),
                    RenderSettings(samples=4, diffuse_bounces=0))
    assert lit.mean()[..., 0].min() > 0.0
