"""Blender's camera model: field of view from lens and sensor with sensor fit, shift,
orthographic scale, clipping planes and the thin lens."""
import numpy as np
import pytest

from engine.camera import CameraModel
from engine.pixel_filter import PixelFilter, blackman_harris
from engine.scene import Camera
from engine.thin_lens import aperture_area, sample_aperture


def _corner_dirs(model, w, h):
    xy = np.array([[0.0, h / 2], [w, h / 2], [w / 2, 0.0], [w / 2, h]])
    return model.generate(xy).directions


def _angle(a, b):
    return np.degrees(np.arccos(np.clip((a * b).sum(), -1, 1)))


@pytest.mark.parametrize("w,h,fit,expect_axis", [(200, 100, "AUTO", "x"), (100, 200, "AUTO", "y"),
                                                 (100, 200, "HORIZONTAL", "x"),
                                                 (200, 100, "VERTICAL", "y")])
def test_field_of_view_follows_sensor_fit(w, h, fit, expect_axis):
    cam = Camera(np.eye(4), lens=50.0, sensor_width=36.0, sensor_height=24.0, sensor_fit=fit)
    d = _corner_dirs(CameraModel(cam, w, h), w, h)
    sensor = 24.0 if fit == "VERTICAL" else 36.0
    fov = np.degrees(2 * np.arctan(sensor / 2 / 50.0))
    fov_x, fov_y = _angle(d[0], d[1]), _angle(d[2], d[3])
    got = fov_x if expect_axis == "x" else fov_y
    assert got == pytest.approx(fov, abs=1e-9)
    # The other axis follows the aspect ratio on the image plane.
    tx, ty = np.tan(np.radians(fov_x / 2)), np.tan(np.radians(fov_y / 2))
    assert tx / ty == pytest.approx(w / h, rel=1e-12)


def test_camera_looks_down_minus_z_and_shift_moves_the_view():
    cam = Camera(np.eye(4), lens=50.0, shift_x=0.5)
    model = CameraModel(cam, 100, 100)
    centre = model.generate(np.array([[50.0, 50.0]])).directions[0]
    # shift 0.5 moves the view by half of the fitted extent: centre ray x/z = 0.5 * 36/50
    assert centre[0] / -centre[2] == pytest.approx(0.5 * 36 / 50)
    assert centre[1] == pytest.approx(0.0)


def test_orthographic_rays_are_parallel_and_span_ortho_scale():
    cam = Camera(np.eye(4), kind="ORTHO", ortho_scale=4.0)
    r = CameraModel(cam, 200, 100).generate(np.array([[0.0, 50.0], [200.0, 50.0]]))
    assert np.allclose(r.directions, [0, 0, -1])
    assert r.origins[1, 0] - r.origins[0, 0] == pytest.approx(4.0)


def test_clip_planes_are_planes():
    cam = Camera(np.eye(4), clip_start=0.5, clip_end=10.0)
    r = CameraModel(cam, 64, 64).generate(np.array([[0.0, 0.0], [32.0, 32.0]]))
    # origins lie on z = -0.5, far ends on z = -10
    assert np.allclose(r.origins[:, 2], -0.5)
    assert np.allclose((r.origins + r.directions * r.tmax[:, None])[:, 2], -10.0)


def test_thin_lens_focuses_on_the_focus_plane():
    cam = Camera(np.eye(4), aperture_radius=0.05, focus_distance=3.0, clip_start=1e-6)
    model = CameraModel(cam, 64, 64)
    u = np.random.default_rng(0).random((500, 2))
    xy = np.full((500, 2), 20.0)
    r = model.generate(xy, u)
    t = (-3.0 - r.origins[:, 2]) / r.directions[:, 2]
    p = r.origins + r.directions * t[:, None]
    assert np.ptp(p[:, 0]) < 1e-9 and np.ptp(p[:, 1]) < 1e-9   # all meet at one point
    assert np.ptp(r.origins[:, 0]) > 0.05                         # from different lens points


@pytest.mark.parametrize("blades", [0, 3, 5, 8])
def test_aperture_samples_cover_the_aperture_uniformly(blades):
    rng = np.random.default_rng(1)
    p = sample_aperture(rng.random((200000, 2)), 1.0, blades, rotation=0.3)
    assert (np.hypot(p[:, 0], p[:, 1]) <= 1.0 + 1e-12).all()
    # Uniform in area: the fraction inside radius 0.5 is (area of the scaled shape)/area.
    frac = (np.hypot(p[:, 0], p[:, 1]) < 0.5).mean()
    assert frac == pytest.approx(0.25, abs=0.01) if blades == 0 else frac > 0.2
    assert aperture_area(1.0, blades) == pytest.approx(np.pi if blades == 0 else
                                                       0.5 * blades * np.sin(2 * np.pi / blades))


def test_blackman_harris_filter_sampling_matches_its_pdf():
    f = PixelFilter("BLACKMAN_HARRIS", 1.5)
    x = f.sample(np.random.default_rng(2).random((400000, 2)))
    assert np.abs(x).max() <= 1.5
    hist, edges = np.histogram(x[:, 0], bins=30, range=(-1.5, 1.5), density=True)
    mid = 0.5 * (edges[1:] + edges[:-1])
    np.testing.assert_allclose(hist, f.pdf_1d(mid), atol=0.02)
    assert blackman_harris(np.array([0.0]), 1.5)[0] == pytest.approx(1.0, abs=1e-3)


def test_invalid_cameras_are_rejected_clearly():
    with pytest.raises(ValueError, match="finite"):
        CameraModel(Camera(np.full((4, 4), np.nan)), 10, 10)
    with pytest.raises(ValueError, match="clip"):
        CameraModel(Camera(np.eye(4), clip_start=5, clip_end=1), 10, 10)
    with pytest.raises(ValueError, match="lens"):
        CameraModel(Camera(np.eye(4), lens=0.0), 10, 10)
