"""Motion blur in the tracer: exact per-ray time for rigid motion, a moving camera,
time-sliced deformation, and a static path that costs nothing."""
import numpy as np
import pytest

from engine import Camera, Material, RenderSettings, Scene, TriangleMesh, World, render
from engine.motion import DeformMotion, RigidMotion, Shutter
from engine.render import RenderContext, render_unit
from engine.sampling import dimensions as D
from engine_scenes import quad

W, H = 64, 4
E = 2.0                           # emitted radiance of the bar


def translate(x, y=0.0, z=0.0):
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def rotate_z(angle):
    m = np.eye(4)
    c, s = np.cos(angle), np.sin(angle)
    m[:2, :2] = [[c, -s], [s, c]]
    return m


def ortho_camera(motion=None):
    cam = Camera(translate(0, 0, 1.0), kind="ORTHO", ortho_scale=2.0, clip_start=1e-3)
    cam.motion = motion
    return cam


def bar_mesh(x0, width, motion=None):
    """An emissive bar from x0 to x0 + width, spanning y, in object space when moving."""
    mesh = quad((x0 + width / 2, 0, 0), (width / 2, 0, 0), (0, 1.0, 0), "bar", 0)
    mesh.motion = motion
    return mesh


def scene_with(meshes, camera=None, shutter=Shutter(), w=W, h=H):
    glow = Material("glow", (0, 0, 0), specular_ior_level=0.0, emission=(E, E, E))
    return Scene(camera or ortho_camera(), w, h, meshes, [glow], [], World((0, 0, 0)),
                 shutter=shutter)


def streak_closed_form(x0, width, velocity, w=W):
    """Time-averaged coverage of pixel columns by a bar [x0 + v t, x0 + width + v t],
    t uniform in [0, 1), averaged over each pixel (box filter of one pixel)."""
    edges = np.linspace(-1, 1, w + 1)
    out = np.empty(w)
    for i in range(w):
        x = np.linspace(edges[i], edges[i + 1], 2001)
        cov = np.clip((x - x0) / velocity, 0, 1) - np.clip((x - x0 - width) / velocity, 0, 1)
        out[i] = np.trapz(cov, x) / (edges[i + 1] - edges[i])
    return E * out


def render_row(scene, spp=256, integrator="whitted"):
    film, _ = render(scene, RenderSettings(samples=spp, integrator=integrator, seed=1,
                                           filter_type="BOX", filter_width=1.0))
    return film.mean()[:, :, 0].mean(axis=0)


@pytest.mark.parametrize("integrator", ["whitted", "path"])
def test_moving_bar_streak_matches_the_closed_form(integrator):
    x0, width, v = -0.5, 0.1, 0.6
    motion = RigidMotion([0.0, 1.0], [np.eye(4), translate(v)])
    row = render_row(scene_with([bar_mesh(x0, width, motion)]), integrator=integrator)
    expected = streak_closed_form(x0, width, v)
    print("max abs error", np.abs(row - expected).max(), "plateau", expected.max())
    # Streak width (w + v) and plateau (E * w / v) within 2% of the peak per pixel
    assert np.abs(row - expected).max() < 0.02 * E
    lit = np.nonzero(row > 0.01 * E)[0]
    expected_lit = np.nonzero(expected > 0.01 * E)[0]
    assert abs(len(lit) - len(expected_lit)) <= 1
    plateau = np.isclose(expected, E * width / v)
    assert plateau.sum() >= 10
    assert row[plateau].mean() == pytest.approx(E * width / v, rel=0.02)


def test_static_scene_takes_the_static_path():
    """No motion (or motion blur off): no time dimension is sampled and a single Embree
    scene without motion is built, whatever motion data the meshes carry."""
    still = RigidMotion([0.0, 1.0], [translate(0.1), translate(0.1)])
    for scene in (scene_with([bar_mesh(-0.5, 0.1)]),                       # nothing moves
                  scene_with([bar_mesh(-0.5, 0.1, still)]),                 # motion = still
                  scene_with([bar_mesh(-0.5, 0.1, RigidMotion([0, 1], [np.eye(4),
                                                                       translate(0.5)]))],
                             shutter=None)):                                # blur off
        ctx = RenderContext(scene, RenderSettings(samples=2))
        asked = []
        original = ctx.sampler.get_1d
        ctx.sampler.get_1d = lambda dim, p, i: (asked.append(dim), original(dim, p, i))[1]
        render_unit(ctx, np.arange(W * H), 0, 2)
        assert D.TIME not in asked
        assert ctx.accel.scene_count == 1 and not ctx.accel.moving
        ctx.close()


def test_moving_scene_samples_time_and_instances_the_moving_object():
    """A rigidly moving object is its own Embree scene, placed by a moving instance in
    the scene every ray is traced against."""
    motion = RigidMotion([0.0, 1.0], [np.eye(4), translate(0.5)])
    scene = scene_with([bar_mesh(-0.5, 0.1, motion), bar_mesh(0.3, 0.1)])
    ctx = RenderContext(scene, RenderSettings(samples=2))
    asked = []
    original = ctx.sampler.get_1d
    ctx.sampler.get_1d = lambda dim, p, i: (asked.append(dim), original(dim, p, i))[1]
    render_unit(ctx, np.arange(W * H), 0, 2)
    assert D.TIME in asked
    assert ctx.accel.scene_count == 2 and len(ctx.accel.moving) == 1
    assert "moving instance" in ctx.accel._scene.kinds
    ctx.close()


def test_zero_length_motion_equals_the_static_render():
    static = render_row(scene_with([bar_mesh(-0.2, 0.1)]), spp=16)
    still = RigidMotion([0.0, 1.0], [np.eye(4), np.eye(4)])
    same = render_row(scene_with([bar_mesh(-0.2, 0.1, still)]), spp=16)
    np.testing.assert_array_equal(static, same)


def test_rotation_blurs_along_the_arc_not_the_chord():
    """A small square at radius 0.6 turning 180 degrees about the origin passes through
    (0, 0.6) at mid-shutter; interpolating matrix entries would drag it through the
    origin instead (the chord)."""
    square = quad((0.6, 0, 0), (0.04, 0, 0), (0, 0.04, 0), "sat", 0)
    square.motion = RigidMotion([0.0, 0.5, 1.0], [rotate_z(0), rotate_z(np.pi / 2),
                                                 rotate_z(np.pi)])
    square.positions = square.positions.copy()
    scene = scene_with([square], w=64, h=64)
    film, _ = render(scene, RenderSettings(samples=64, integrator="whitted"))
    img = film.mean()[:, :, 0]
    top = img[9:12, 30:34].mean()            # around (0, 0.6): raster y = (1 - 0.6)/2*64
    centre = img[30:34, 30:34].mean()
    assert top > 0.01 and centre == 0.0


def test_moving_camera_equals_the_opposite_object_motion():
    x0, width, v = -0.5, 0.1, 0.6
    moved_object = render_row(scene_with([bar_mesh(x0, width, RigidMotion(
        [0.0, 1.0], [np.eye(4), translate(v)]))]))
    cam_motion = RigidMotion([0.0, 1.0], [translate(0, 0, 1.0), translate(-v, 0, 1.0)])
    moved_camera = render_row(scene_with([bar_mesh(x0, width)], camera=ortho_camera(cam_motion)))
    np.testing.assert_allclose(moved_camera, moved_object, atol=1e-9)


def test_deformation_streak_equals_the_rigid_one():
    """Moving the vertices (deformation, Embree's time steps) by the same translation
    gives the closed-form streak as the rigid motion does, and the same image as the
    rigid motion to float rounding with the same samples; the control, a deformation
    over half the distance, does not."""
    x0, width, v = -0.5, 0.1, 0.6
    bar = bar_mesh(x0, width)
    steps = np.stack([bar.positions, bar.positions + [v, 0, 0]])
    bar.motion = DeformMotion([0.0, 1.0], steps)
    row = render_row(scene_with([bar]))
    expected = streak_closed_form(x0, width, v)
    err = np.abs(row - expected).max() / E
    print(f"deformation: max error {err:.4f} of the bar's radiance")
    assert err < 0.02
    rigid = render_row(scene_with([bar_mesh(x0, width, RigidMotion(
        [0.0, 1.0], [np.eye(4), translate(v)]))]))
    assert np.abs(row - rigid).max() < 1e-3 * E
    half = bar_mesh(x0, width)
    half.motion = DeformMotion([0.0, 1.0], np.stack([half.positions,
                                                     half.positions + [v / 2, 0, 0]]))
    assert np.abs(render_row(scene_with([half])) - rigid).max() > 0.1 * E


def test_zooming_camera_rays_follow_the_focal_length_at_their_time():
    """A lens animated from 35 to 70 mm over the shutter: each ray equals the ray of a
    still camera with the focal length at that ray's time."""
    from engine.camera import CameraModel
    cam = Camera(translate(0, 0, 1.0), lens=35.0, shift_x=0.1)
    cam.lens_motion = ([0.0, 1.0], [35.0, 70.0])
    model = CameraModel(cam, 32, 24)
    rng = np.random.default_rng(0)
    xy = rng.random((50, 2)) * [32, 24]
    t = rng.random(50)
    moving = model.generate(xy, None, t).directions
    for k in range(50):
        still = Camera(translate(0, 0, 1.0), lens=35.0 + 35.0 * t[k], shift_x=0.1)
        ref = CameraModel(still, 32, 24).generate(xy[k:k + 1]).directions[0]
        np.testing.assert_allclose(moving[k], ref, atol=1e-12)
    scene = scene_with([bar_mesh(-0.5, 0.1)], camera=cam)
    assert scene.has_motion()
    cam.lens_motion = ([0.0, 1.0], [35.0, 35.0])
    assert not scene.has_motion()


def test_moving_lamp_is_blurred_over_its_time_slices():
    """A point lamp moving along x during the shutter, exported as 8 slices: with 64
    jittered samples each slice gets exactly 8 samples, and a point lamp with direct light
    only has no other randomness, so each pixel is the mean of the 8 still renders at the
    slice positions (up to the 1e-4 px sub-pixel jitter, which pairs differently with the
    slices) and differs from the still render at mid-shutter by far more."""
    from engine import PointLight
    plane = quad((0, 0, 0), (1, 0, 0), (0, 1, 0), "plane", 0)
    grey = Material("grey", (0.8, 0.8, 0.8), specular_ior_level=0.0)
    cam = Camera(translate(0, 0, 1.0), kind="ORTHO", ortho_scale=2.0, clip_start=1e-3)

    def lamp_at(x):
        return PointLight((x, 0.0, 0.3), (20.0,) * 3)

    xs = -0.5 + (np.arange(8) + 0.5) / 8.0            # slice middles of a move -0.5 -> 0.5
    moving = lamp_at(0.0)
    moving.motion_slices = [lamp_at(x) for x in xs]
    settings = RenderSettings(samples=64, diffuse_bounces=0, filter_type="BOX",
                              filter_width=1e-4)

    def rendered(lamp, shutter):
        scene = Scene(cam, 16, 4, [plane], [grey], [lamp], World((0, 0, 0)), shutter=shutter)
        film, _ = render(scene, settings)
        return film.mean()

    blurred = rendered(moving, Shutter())
    stills = np.mean([rendered(lamp_at(x), None) for x in xs], axis=0)
    np.testing.assert_allclose(blurred, stills, rtol=1e-4, atol=1e-9)
    middle = rendered(lamp_at(0.0), None)
    assert np.abs(blurred - middle).max() > 0.05 * middle.max()
    # Without an open shutter the lamp is the middle slice's, and no time is sampled.
    still_path = rendered(moving, None)
    np.testing.assert_allclose(still_path, rendered(moving.motion_slices[4], None))
