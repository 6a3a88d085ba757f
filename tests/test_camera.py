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


def test_camera_with_clip_end_before_clip_start_sees_nothing():
    """As in Cycles (measured: the world alone in every pixel; tests/test_fuzz_renders.py):
    rays of length 0, not an error."""
    for kw in (dict(clip_start=5, clip_end=1), dict(clip_start=5, clip_end=5),
               dict(kind="ORTHO", ortho_scale=0.0)):
        model = CameraModel(Camera(np.eye(4), **kw), 10, 10)
        rays = model.generate(np.array([[5.0, 5.0], [0.5, 9.5]]))
        assert model.sees_nothing and np.all(rays.tmax == 0.0), kw
    assert not CameraModel(Camera(np.eye(4)), 10, 10).sees_nothing


def test_invalid_cameras_are_rejected_clearly():
    with pytest.raises(ValueError, match="finite"):
        CameraModel(Camera(np.full((4, 4), np.nan)), 10, 10)
    with pytest.raises(ValueError, match="lens"):
        CameraModel(Camera(np.eye(4), lens=0.0), 10, 10)


# --- chi-square goodness of fit: lens and filter sampling against their own pdfs ------
from scipy import integrate, stats  # noqa: E402

ALPHA = 0.01 / 6          # Bonferroni over the chi-square tests in this file


def chi_square_pvalue(counts, expected):
    """Pearson's chi-square p-value, cells with an expected count below 5 pooled."""
    counts, expected = np.ravel(counts), np.ravel(expected)
    keep = expected >= 5
    obs = np.append(counts[keep], counts[~keep].sum())
    exp = np.append(expected[keep], expected[~keep].sum())
    if exp[-1] == 0:
        obs, exp = obs[:-1], exp[:-1]
    return stats.chisquare(obs, exp).pvalue


def _inside_aperture(x, y, blades, rotation):
    if blades < 3:
        return x * x + y * y <= 1.0
    # inside the regular polygon with corners at angles rotation + (2k + 1) pi / blades
    inside = np.ones(np.shape(x), dtype=bool)
    for k in range(blades):
        a0 = rotation + np.pi * (2 * k + 1) / blades
        a1 = a0 + 2 * np.pi / blades
        p0 = np.array([np.cos(a0), np.sin(a0)])
        p1 = np.array([np.cos(a1), np.sin(a1)])
        edge = p1 - p0
        inside &= (edge[0] * (y - p0[1]) - edge[1] * (x - p0[0])) >= -1e-12
    return inside


@pytest.mark.parametrize("blades,rotation", [(0, 0.0), (5, 0.3), (6, 0.0), (3, 1.0)])
def test_lens_sampling_chi_square(blades, rotation):
    """Aperture samples are uniform over the disk or polygon: chi-square over a 16x16 grid,
    expected counts from the cell's area inside the aperture (4096-point sub-grid)."""
    n, cells, sub = 200_000, 16, 64
    u = np.random.default_rng(10 + blades).random((n, 2))
    p = sample_aperture(u, 1.0, blades, rotation)
    counts, _, _ = np.histogram2d(p[:, 0], p[:, 1], bins=cells, range=[[-1, 1], [-1, 1]])
    edges = np.linspace(-1, 1, cells + 1)
    fine = (np.arange(cells * sub) + 0.5) / (cells * sub) * 2 - 1
    X, Y = np.meshgrid(fine, fine, indexing="ij")
    frac = _inside_aperture(X, Y, blades, rotation).reshape(cells, sub, cells, sub).mean(axis=(1, 3))
    expected = n * frac / frac.sum()
    p_value = chi_square_pvalue(counts, expected)
    print(f"blades={blades}: chi-square p = {p_value:.3g}")
    assert p_value > ALPHA
    assert edges.size == cells + 1


@pytest.mark.parametrize("kind,width", [("BLACKMAN_HARRIS", 1.5), ("BLACKMAN_HARRIS", 0.7),
                                        ("GAUSSIAN", 1.5), ("GAUSSIAN", 3.0), ("BOX", 1.0)])
def test_filter_importance_sampling_chi_square(kind, width):
    f = PixelFilter(kind, width)
    n, bins = 200_000, 40
    x = f.sample(np.random.default_rng(3).random((n, 2)))[:, 0]
    counts, edges = np.histogram(x, bins=bins, range=(-f.radius, f.radius))
    expected = np.array([integrate.quad(f.pdf_1d, a, b)[0] for a, b in zip(edges[:-1], edges[1:])])
    expected *= n / expected.sum()
    p_value = chi_square_pvalue(counts, expected)
    print(f"{kind} {width}: chi-square p = {p_value:.3g}")
    assert p_value > ALPHA


def test_gaussian_filter_is_cycles_gaussian():
    """Cycles' Gaussian of width w: exp(-2 (2x/w)^2), a normal density of standard
    deviation w/4, over [-1.5 w, 1.5 w]: the samples' moments, and the shape."""
    for width in (0.5, 1.5, 3.0):
        f = PixelFilter("GAUSSIAN", width)
        x = f.sample(np.random.default_rng(5).random((400_000, 2)))
        assert f.radius == 1.5 * width and np.abs(x).max() <= f.radius
        assert abs(x.mean()) < 0.005 * width
        assert x.std() == pytest.approx(width / 4, rel=0.005)
        mid = np.linspace(-width, width, 7)
        np.testing.assert_allclose(f.pdf_1d(mid), np.exp(-0.5 * (mid / (width / 4)) ** 2)
                                   / (width / 4 * np.sqrt(2 * np.pi)), rtol=1e-6)


def test_chi_square_harness_rejects_a_wrong_pdf():
    """Negative control: samples from a box filter judged against Blackman-Harris."""
    bh = PixelFilter("BLACKMAN_HARRIS", 1.5)
    x = (np.random.default_rng(4).random(200_000) - 0.5) * 3.0
    counts, edges = np.histogram(x, bins=40, range=(-1.5, 1.5))
    expected = np.array([integrate.quad(bh.pdf_1d, a, b)[0] for a, b in zip(edges[:-1], edges[1:])])
    expected *= len(x) / expected.sum()
    keep = expected >= 5
    assert stats.chisquare(counts[keep], expected[keep] * counts[keep].sum() / expected[keep].sum()).pvalue < ALPHA


def test_blades_are_oriented_as_in_cycles():
    """Cycles puts the aperture polygon's corners at rotation + (2k+1) pi / blades: with 6
    blades and no rotation a corner points at 30 degrees and an edge's middle at 0."""
    u = np.random.default_rng(5).random((400000, 2))
    p = sample_aperture(u, 1.0, 6, 0.0)
    ang = np.degrees(np.arctan2(p[:, 1], p[:, 0]))
    r = np.hypot(p[:, 0], p[:, 1])
    near_30 = r[np.abs(ang - 30) < 1].max()
    near_0 = r[np.abs(ang) < 1].max()
    assert near_30 > 0.99 and near_0 < np.cos(np.radians(30)) + 0.01


def _interp_by_bisection(x, xp, fp):
    """NumPy's interpolation rule by a plain search: the last interval with xp[j] <= x."""
    import bisect
    if x < xp[0]:
        return fp[0]
    if x >= xp[-1]:
        return fp[-1]
    j = bisect.bisect_right(xp, x) - 1
    return (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]) * (x - xp[j]) + fp[j]


@pytest.mark.parametrize("width", [1.5, 0.7, 4.0])
def test_guided_filter_lookup_finds_the_same_interval_as_a_full_search(width):
    """The camera kernel inverts the pixel filter's CDF from a guide table (cutpoints)
    instead of a binary search over all of it: the same interval, so the same offset to
    the bit, for u at the guide's cell boundaries, on the CDF's own knots, just below
    them, at 0 and next to 1, and at random."""
    from engine.kernels.camera_rays import GUIDE_CELLS, interp_guided
    from engine.kernels.cdf_search import guide_table
    f = PixelFilter("BLACKMAN_HARRIS", width)
    cdf, xs = f._cdf, f._xs
    guide = guide_table(cdf, GUIDE_CELLS)
    assert guide.shape == (GUIDE_CELLS + 1,) and np.all(np.diff(guide) >= 0)
    knots = cdf[::7]
    u = np.concatenate([np.arange(GUIDE_CELLS) / GUIDE_CELLS, knots, np.nextafter(knots, 0),
                        [0.0, np.nextafter(1.0, 0)],
                        np.random.default_rng(6).random(20000)])
    u = u[(u >= 0) & (u < 1)]
    xp, fp = cdf.tolist(), xs.tolist()
    got = np.array([interp_guided(float(v), cdf, xs, guide) for v in u])
    want = np.array([_interp_by_bisection(float(v), xp, fp) for v in u])
    assert np.array_equal(got, want)
    np.testing.assert_allclose(got, np.interp(u, cdf, xs), rtol=0, atol=1e-12)


def test_guided_lookup_handles_flat_and_steep_cdfs():
    """Ties (a flat CDF where the density is zero) and most of the mass in one guide
    cell: still the interval NumPy picks."""
    from engine.kernels.camera_rays import interp_guided
    from engine.kernels.cdf_search import guide_table
    cdf = np.array([0.0, 0.0, 0.0, 1e-9, 2e-9, 0.5, 0.5, 0.5, 0.999999, 1.0, 1.0])
    xs = np.linspace(-1.0, 1.0, len(cdf))
    guide = guide_table(cdf, 8)
    u = np.concatenate([np.linspace(0, 1, 97)[:-1], [1e-9, 5e-10, 0.5, 0.9999995]])
    got = np.array([interp_guided(float(v), cdf, xs, guide) for v in u])
    want = np.array([_interp_by_bisection(float(v), cdf.tolist(), xs.tolist()) for v in u])
    assert np.array_equal(got, want)


@pytest.mark.parametrize("kind,aperture,blades,filt", [
    ("PERSP", 0.0, 0, "BLACKMAN_HARRIS"), ("PERSP", 0.05, 0, "BLACKMAN_HARRIS"),
    ("PERSP", 0.05, 6, "BOX"), ("ORTHO", 0.0, 0, "BOX"), ("PERSP", 0.0, 0, "GAUSSIAN")])
def test_camera_ray_kernel_matches_the_camera_model(kind, aperture, blades, filt):
    """The compiled camera rays (engine/kernels/camera_rays.py) against CameraModel with
    the same sampler numbers and pixel filter."""
    from engine.render import camera_rays
    from engine.sampling import dimensions as D
    from engine import RenderContext, RenderSettings
    from engine_scenes import cornell_box
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
