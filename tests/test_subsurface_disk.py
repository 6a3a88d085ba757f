"""Christensen-Burley subsurface scattering by disk sampling (engine/kernels/
subsurface_disk.py), against oracles that share none of its code: the profile's closed
form integrated by SciPy, the inverse of its closed-form CDF, the exact expectation of
the estimator on a plane (the lobe's whole weight comes back: 1 per channel), and the
geometry of the exits (on the surface, on the side the light entered from). Renders
against Cycles: tests/test_subsurface_vs_cycles.py."""
import math

import numpy as np
import pytest

from engine.accel import Accelerator
from engine.kernels.bsdf.params import (P_BASE, P_SSS_METHOD, P_SSS_RADIUS, P_SSS_WEIGHT,
                                SSS_BURLEY, SSS_RANDOM_WALK)
from engine.kernels import subsurface_disk as B
from engine.surface import SurfaceBuilder
from engine_scenes import box


def _cdf(d, r):
    """The untruncated profile's CDF (Christensen and Burley 2015), closed form."""
    return 1.0 - 0.25 * math.exp(-r / d) - 0.75 * math.exp(-r / (3.0 * d))


@pytest.mark.parametrize("d", [1e-3, 0.3, 40.0])
def test_the_truncated_profile_integrates_to_one_and_sampling_inverts_its_cdf(d):
    from scipy.integrate import quad
    total, _ = quad(lambda r: B.density(d, r), 0.0, B.TRUNCATE * d, limit=200,
                    points=[d, 3 * d])
    assert total == pytest.approx(1.0, abs=1e-7)
    assert B.TRUNCATE_CDF == pytest.approx(_cdf(1.0, B.TRUNCATE), abs=1e-12)
    assert B.density(d, B.TRUNCATE * d * 1.0001) == 0.0 and B.density(d, 0.0) == 0.0
    for xi in np.linspace(0.0, 0.999, 37):
        r, h = B.sample_radius(d, xi)
        assert 0.0 <= r <= B.TRUNCATE * d
        assert _cdf(d, r) / B.TRUNCATE_CDF == pytest.approx(xi, abs=2e-6)
        assert h * h + r * r == pytest.approx((B.TRUNCATE * d) ** 2, rel=1e-9)


def test_a_channel_without_radius_is_never_picked():
    for xi in np.linspace(0.0, 0.9999, 101):
        d, rest = B._pick_channel(0.0, 0.2, 0.0, xi)
        assert d == 0.2 and rest == pytest.approx(xi)
        d, rest = B._pick_channel(0.1, 0.0, 0.4, xi)
        assert d == (0.1 if xi < 0.5 else 0.4) and 0.0 <= rest < 1.0
    assert B.disk_pdf(0.0, 0.0, 0.0, 0.1) == 0.0


SLAB = box((-60, -60, -20), (60, 60, 0), "slab")
THIN = box((-60, -60, -0.02), (60, 60, 0), "thin")


def _exits(meshes, radius, front=True, n=40000, seed=1):
    """n samples of the exit from (0, 0, 0) on the top face of the first mesh, light
    arriving from above (front) or, front False, from inside below (then the
    geometric normal facing the ray is -z)."""
    accel = Accelerator(meshes)
    geometry = SurfaceBuilder(accel).geometry()
    rng = np.random.default_rng(seed)
    keys = rng.integers(0, 2**63, n, dtype=np.uint64)
    out = np.zeros((n, 8))
    normal = np.array([0.0, 0.0, 1.0 if front else -1.0])
    B.exit_batch(accel.kernel_rays(), geometry, keys, 0, front, np.zeros(3), normal,
                 np.asarray(radius, float), rng.random((n, 2)), out)
    accel.close()
    return out


def test_on_a_plane_the_whole_weight_comes_back_on_the_entry_side():
    """On a plane only the probes along the normal meet the surface (half of them), each
    exit weighing density / disk pdf x 2: the expectation is the truncated profile's
    integral, 1 per channel, for any radii."""
    radius = (1.0, 0.5, 0.05)
    out = _exits([SLAB], radius)
    assert np.all(np.isfinite(out))
    left = out[:, 0] == 1
    assert abs(left.mean() - 0.5) < 0.02                  # the normal's probes
    w = out[:, 1:4] * left[:, None]
    mean, se = w.mean(0), w.std(0) / math.sqrt(len(w))
    print(f"plane: mean weight {mean}, 1 sigma {se}")
    assert np.all(np.abs(mean - 1.0) < 4 * se + 1e-3) and np.all(se < 0.02)
    np.testing.assert_array_equal(out[left, 5:8], np.tile([0.0, 0.0, 1.0], (left.sum(), 1)))
    # the exits lie within the widest channel's truncation radius (16 d)
    assert np.all(out[left, 4] >= 0)


def test_light_entering_from_inside_leaves_on_the_inside():
    """A surface hit from behind (front False): Cycles flips the exits' normals
    (PATH_RAY_SUBSURFACE_BACKFACING), so the exit is seen from the side the light came
    from, and the weight is the same."""
    out = _exits([SLAB], (0.6, 0.3, 0.1), front=False)
    left = out[:, 0] == 1
    np.testing.assert_array_equal(out[left, 5:8],
                                  np.tile([0.0, 0.0, -1.0], (left.sum(), 1)))
    w = out[:, 1:4] * left[:, None]
    mean, se = w.mean(0), w.std(0) / math.sqrt(len(w))
    assert np.all(np.abs(mean - 1.0) < 4 * se + 1e-3)


def test_a_thin_sheet_lets_light_out_of_its_far_side():
    """A 2 cm sheet with a mean free path of 4 cm: some exits are on the bottom face,
    seen from below (normal -z); the top face's weight is still the plane's 1, and the
    bottom's adds to it (Burley's profile assumes a half space, as in Cycles)."""
    out = _exits([THIN], (0.5, 0.5, 0.5))
    left = out[:, 0] == 1
    top = left & (out[:, 7] > 0.5)
    bottom = left & (out[:, 7] < -0.5)
    assert top.sum() + bottom.sum() == left.sum() and bottom.mean() > 0.05
    w_top = (out[:, 1:4] * top[:, None]).mean(0)
    w_bottom = (out[:, 1:4] * bottom[:, None]).mean(0)
    print(f"sheet: top {w_top}, bottom {w_bottom}")
    assert np.all(w_bottom > 0.05)
    # the top face alone, every probe's candidates summed: the plane's expectation; the
    # resampling keeps the top with probability w_top / (w_top + w_bottom) per probe,
    # scaled by the sum, so the kept top weight's mean is still below 1 + noise
    assert np.all(w_top < 1.05)


def test_other_objects_are_passed_through():
    """The probe meets only the entered object's surface: a box just below the plane,
    inside the slab, leaves every sample as it was."""
    radius = (0.8, 0.4, 0.2)
    alone = _exits([SLAB], radius, n=4000)
    inner = box((-0.3, -0.3, -0.5), (0.3, 0.3, -0.1), "inner")
    shared = _exits([SLAB, inner], radius, n=4000)
    np.testing.assert_allclose(alone[:, :4], shared[:, :4], rtol=1e-3, atol=1e-6)


def test_after_a_diffuse_bounce_burley_is_a_diffuse_lobe():
    """Cycles turns a Christensen-Burley closure into a diffuse BSDF on a path with a
    diffuse ancestor: the lobe's share goes to the diffuse lobe (radii 0); random walks
    and paths without a diffuse bounce keep it."""
    from engine.kernels.bsdf import principled
    from engine.kernels.bsdf.params import NPARAM
    from engine.kernels.bsdf.state import NSTATE, S_DIFFUSE, S_SSS
    from engine.kernels.bsdf.tables import kernel_tables
    from engine.kernels.path_config import PathConfig
    from engine.kernels.prepare_closures import prepare_closures

    cfg = PathConfig(0, 1, 12, 4, 4, 12, 0, 0.0, 10.0, 0, False, 1.0, True, True)
    tables = kernel_tables()
    base = np.zeros(NPARAM)
    base[P_BASE:P_BASE + 3] = (0.8, 0.5, 0.3)
    base[P_SSS_WEIGHT] = 1.0
    base[P_SSS_RADIUS:P_SSS_RADIUS + 3] = (1.0, 0.5, 0.2)
    for method in (SSS_BURLEY, SSS_RANDOM_WALK):
        for bounces in (0, 1):
            row = base.copy()
            row[P_SSS_METHOD] = method
            prepare_closures(cfg, row, np.inf, 2, bounces)
            state = np.zeros(NSTATE)
            principled.setup(row, True, 0.0, 0.0, 1.0, tables, state)
            diffuse_now = method == SSS_BURLEY and bounces > 0
            sss = state[S_SSS:S_SSS + 3]
            assert (np.all(sss == 0) if diffuse_now else np.all(sss > 0)), (method, bounces)
            assert np.all(state[S_DIFFUSE:S_DIFFUSE + 3] > 0) == diffuse_now
