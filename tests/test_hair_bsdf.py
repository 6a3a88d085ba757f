"""The Hair BSDF node's lobes (engine/kernels/bsdf/hair.py) against closed forms written
here from Cycles' definitions (kernel/closure/bsdf_hair.h), sharing no code with the
kernel: the direction sampler against the density of its angles (chi-square), the
reported pdfs and weights, evaluation's side and azimuth tests, energy and extremes.
A Hair BSDF mixed with other shaders is measured against Cycles itself
(tests/test_hair_bsdf_vs_cycles.py): Cycles weighs a sampled hair direction with its
own reported pdf on either side, which no closed form here reproduces more simply."""
from __future__ import annotations

import math

import numpy as np
import pytest

from chi2 import chi2_test
from engine.bsdf.material_table import MaterialTable
from engine.kernels.bsdf import batch
from engine.kernels.bsdf import params as R
from engine.scene import Material

T = np.array([1.0, 0.2, 0.1]) / np.linalg.norm([1.0, 0.2, 0.1])   # in the shading frame
N = 200_000


def _angles(t, w):
    """theta = asin(t.w) and the unit part of w perpendicular to t, per row."""
    s = np.clip(w @ t, -1.0, 1.0)
    perp = w - s[:, None] * t
    return np.arcsin(s), perp / np.linalg.norm(perp, axis=1, keepdims=True)


def density(wo, wi, offset, r1, r2, transmission, cycles_r_pdf=False):
    """The lobe's density over wi (1/sr) as its sampler draws it: a Cauchy half angle
    t = (theta_i + theta_r)/2 - offset of width r1 cut to theta_i in [-pi/2, pi/2]
    (d theta_i = 2 dt) times the azimuth's density, over d(omega) = cos(theta_i)
    d(theta_i) d(phi). cycles_r_pdf: R's azimuth term as Cycles' sample reports it.
    (Cycles' evaluation of TT extends its Cauchy term past the 90 degrees about the far
    side that its sampler draws: there the kernel's pdf is Cycles' and this is 0.)"""
    wo = np.broadcast_to(wo, wi.shape)
    theta_r, locy = _angles(T, wo)
    theta_i, wiy = _angles(T, wi)
    hi = math.atan((0.5 * (math.pi / 2 + theta_r[0]) - offset) / r1)
    lo = math.atan((0.5 * (-math.pi / 2 + theta_r[0]) - offset) / r1)
    t = 0.5 * (theta_i + theta_r) - offset
    p_t = (r1 / (t * t + r1 * r1)) / (hi - lo)        # density of t
    p_theta = 0.5 * p_t                                # of theta_i = 2 t + ...
    phi = np.arccos(np.clip(np.sum(wiy * locy, 1), -1.0, 1.0))     # |azimuth|, [0, pi]
    if transmission:
        c = 2.0 * math.atan(math.pi / (2.0 * r2))
        p = math.pi - phi                              # from the far side, drawn within
        p_phi = np.where(p <= math.pi / 2 + 1e-12, r2 / (c * (p * p + r2 * r2)), 0.0)
    else:
        inside = phi <= math.pi * r2 + 1e-12
        term = np.cos(0.5 * phi) if cycles_r_pdf else np.cos(0.5 * phi / r2)
        p_phi = np.where(inside, term * 0.25 / r2, 0.0)
    out = p_theta * p_phi / np.cos(theta_i)
    return np.where(math.pi / 2 - np.abs(theta_i) < 0.001, 0.0, out)


def hair_rows(n, transmission, offset, r1, r2, colour=(1.0, 1.0, 1.0), strand=True):
    part = "transmission" if transmission else "reflection"
    m = Material(base_color=(0.0, 0.0, 0.0), specular_ior_level=0.0,
                 **{"hair_" + part: colour, f"hair_{part}_roughness": (r1, r2),
                    f"hair_{part}_offset": -offset})       # Cycles keeps minus the node's
    rows = R.pack_materials(MaterialTable([m]))[np.zeros(n, np.int64)]
    rows[:, R.P_HAIR_T:R.P_HAIR_T + 3] = T
    rows[:, R.P_HAIR_CURVE] = 1.0 if strand else 0.0
    return np.ascontiguousarray(rows)


def _wo(deg):
    a = math.radians(deg)
    return np.array([math.sin(a) * 0.6, -math.sin(a) * 0.8, math.cos(a)])


CASES = [("R", False, 0.0, 0.1, 1.0, 30.0), ("R", False, 0.05, 0.3, 0.5, 60.0),
         ("R", False, 0.0, 0.001, 0.2, 10.0), ("TT", True, 0.0, 0.1, 1.0, 30.0),
         ("TT", True, -0.04, 0.25, 0.3, 75.0)]
IDS = [f"{c[0]}-r{c[3]:g}-{c[4]:g}-off{c[2]:g}-{c[5]:g}deg" for c in CASES]
TABLES = batch.P.kernel_tables()


def _sample(transmission, offset, r1, r2, deg):
    def sample(u):
        n = len(u)
        wi, weight, pdf, kind, delta, valid = batch.sample_batch(
            hair_rows(n, transmission, offset, r1, r2), np.ones(n, bool),
            np.ascontiguousarray(np.broadcast_to(_wo(deg), (n, 3))), u[:, 0],
            np.ascontiguousarray(u[:, 1:]), np.ones((n, 3), bool), TABLES)
        return wi, valid
    return sample


@pytest.mark.parametrize("label,transmission,offset,r1,r2,deg", CASES, ids=IDS)
def test_sampler_draws_the_lobes_density(label, transmission, offset, r1, r2, deg):
    res = chi2_test(_sample(transmission, offset, r1, r2, deg),
                    lambda w: density(_wo(deg), w, offset, r1, r2, transmission), N,
                    seed=int(deg * 7 + r1 * 1000), n_tests=len(CASES) + 1)
    print(f"{label}: {res}")
    assert res.passed, str(res)


def test_negative_control_wrong_roughness():
    """R samples at RoughnessV 0.5 against the density at 0.7 must fail."""
    res = chi2_test(_sample(False, 0.0, 0.3, 0.5, 40.0),
                    lambda w: density(_wo(40.0), w, 0.0, 0.3, 0.7, False), N, seed=3,
                    n_tests=len(CASES) + 1)
    assert not res.passed, str(res)


@pytest.mark.parametrize("label,transmission,offset,r1,r2,deg", CASES, ids=IDS)
def test_weight_is_the_colour_and_pdf_as_cycles_reports(label, transmission, offset, r1,
                                                        r2, deg):
    """A Hair BSDF alone: each sample weighs its colour (Cycles' eval = pdf), on either
    side of the surface, and reports Cycles' pdf; evaluation gives pdf = f |cos| on its
    own side only (R: also within 90 degrees of the view's azimuth)."""
    n = 4000
    rng = np.random.default_rng(7)
    colour = (0.2, 0.5, 0.9)
    rows = hair_rows(n, transmission, offset, r1, r2, colour)
    wo = np.ascontiguousarray(np.broadcast_to(_wo(deg), (n, 3)))
    every = np.ones((n, 3), bool)
    wi, weight, pdf, kind, delta, valid = batch.sample_batch(
        rows, np.ones(n, bool), wo, rng.random(n), rng.random((n, 2)), every, TABLES)
    assert valid.mean() > 0.99 and not delta.any()
    assert np.all(kind[valid] == (batch.P.TRANSMISSION if transmission else batch.P.GLOSSY))
    np.testing.assert_allclose(weight[valid], np.broadcast_to(colour, (valid.sum(), 3)),
                               rtol=1e-9)
    np.testing.assert_allclose(pdf[valid], density(_wo(deg), wi[valid], offset, r1, r2,
                                                   transmission, cycles_r_pdf=True),
                               rtol=1e-7)
    if r2 == 1.0:                   # the azimuth spans the circle: samples on either side
        assert (wi[valid, 2] < 0).any() and (wi[valid, 2] > 0).any()
    f = batch.eval_f_batch(rows, np.ones(n, bool), wo, wi, TABLES)
    ev = batch.pdf_batch(rows, np.ones(n, bool), wo, wi, every, TABLES)
    side = (wi[:, 2] < 0) if transmission else (wi[:, 2] > 0)
    assert np.all(f[~side] == 0.0) and np.all(ev[~side] == 0.0)
    np.testing.assert_allclose(f[side, 2] * np.abs(wi[side, 2]), 0.9 * ev[side], rtol=1e-9)
    if not transmission and r2 > 0.5:          # R samples past 90 degrees of azimuth
        _, locy = _angles(T, wo)
        _, wiy = _angles(T, wi)
        behind = np.sum(locy * wiy, 1) < 0
        assert (behind & side).any() and np.all(ev[behind] == 0.0)


def _sphere(n_mu=500, n_phi=500):
    mu = (np.arange(n_mu) + 0.5) / n_mu * 2 - 1
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2 * np.pi
    M, P = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1 - M * M)
    w = np.stack([s * np.cos(P), s * np.sin(P), M], -1).reshape(-1, 3)
    return np.ascontiguousarray(w), 4 * np.pi / (n_mu * n_phi)


@pytest.mark.parametrize("r1,r2", [(0.001, 0.001), (0.1, 1.0), (1.0, 1.0), (0.5, 0.05)])
@pytest.mark.parametrize("deg", [0.0, 45.0, 89.9])
def test_energy_bounds_and_finite_at_the_extremes(r1, r2, deg):
    """R reflects at most its colour (f |cos| integrates to <= 1); TT at most Cycles'
    own excess, 2 atan(pi / r2) / (2 atan(pi / (2 r2))) (its evaluation extends the
    Cauchy azimuth term over the whole circle, past what it samples): at roughness 0.001
    and 1 and grazing views, with nothing non-finite."""
    w, dw = _sphere()
    n = len(w)
    wo = np.ascontiguousarray(np.broadcast_to(_wo(deg), (n, 3)))
    for transmission in (False, True):
        rows = hair_rows(n, transmission, 0.02, r1, r2)
        f = batch.eval_f_batch(rows, np.ones(n, bool), wo, w, TABLES)
        assert np.isfinite(f).all() and (f >= 0).all()
        if r1 < 0.05:
            continue        # a lobe of 0.001 radians: finite, but no quadrature sees it
        albedo = float((f[:, 0] * np.abs(w[:, 2])).sum() * dw)
        bound = 1.0
        if transmission:
            bound = math.atan(math.pi / r2) / math.atan(math.pi / (2 * r2))
        print(f"r1 {r1}, r2 {r2}, {deg} deg: {'TT' if transmission else 'R'} albedo "
              f"{albedo:.4f} (bound {bound:.4f})")
        assert albedo <= bound + 0.02          # the quadrature's error on peaked lobes
        # along the tangent itself: no azimuth, no light, no NaN
        wt = np.ascontiguousarray(np.broadcast_to(T, (1, 3)))
        assert np.all(batch.eval_f_batch(rows[:1], np.ones(1, bool), wo[:1], wt, TABLES) == 0)
        # and samples from such a lobe: finite, weight the colour
        rng = np.random.default_rng(2)
        m = 5000
        wi, weight, pdf, _, _, valid = batch.sample_batch(
            rows[:m], np.ones(m, bool), wo[:m], rng.random(m), rng.random((m, 2)),
            np.ones((m, 3), bool), TABLES)
        assert np.isfinite(wi).all() and np.isfinite(weight).all() and valid.mean() > 0.9
        np.testing.assert_allclose(weight[valid], 1.0, rtol=1e-9)
        assert np.all(pdf[valid] > 0)


def test_offset_applies_on_strands_only():
    """Cycles drops the node's Offset on a mesh: the same lobe with and without it."""
    w, _ = _sphere(40, 50)
    wo = np.ascontiguousarray(np.broadcast_to(_wo(40.0), (len(w), 3)))
    f = {}
    for strand in (True, False):
        for off in (0.0, 0.1):
            rows = hair_rows(len(w), False, off, 0.2, 0.8, strand=strand)
            f[strand, off] = batch.eval_f_batch(rows, np.ones(len(w), bool), wo, w, TABLES)
    assert np.array_equal(f[False, 0.0], f[False, 0.1])
    assert not np.allclose(f[True, 0.0], f[True, 0.1])


def test_materials_without_a_hair_bsdf_never_reach_its_code():
    """The integrator writes a fibre direction only for rows whose hair flag is set, and
    only a Hair BSDF sets it; a material with other beside-lobes (coat, sheen,
    translucency) never reads the per-hit hair columns: NaN there changes nothing."""
    mats = [Material(), Material(base_color=(0.2, 0.5, 0.1), coat_weight=0.7),
            Material(translucent_color=(0.3, 0.3, 0.3), sheen_weight=0.5),
            Material(metallic=1.0, roughness=0.2), Material(transmission=1.0)]
    rows = R.pack_materials(MaterialTable(mats))
    assert np.all(rows[:, R.P_HAIR] == 0.0)
    hair = R.pack_materials(MaterialTable([Material(hair_transmission=(0.5, 0.5, 0.5))]))
    assert hair[0, R.P_HAIR] == 1.0
    n = 3000
    rng = np.random.default_rng(4)
    idx = np.arange(n) % len(mats)
    wo = np.ascontiguousarray(np.broadcast_to(_wo(35.0), (n, 3)))
    wi = rng.normal(size=(n, 3))
    wi = np.ascontiguousarray(wi / np.linalg.norm(wi, axis=1, keepdims=True))
    u, ud = rng.random(n), rng.random((n, 2))
    out = []
    for fill in (0.0, np.nan):
        r = np.ascontiguousarray(rows[idx])
        r[:, R.P_HAIR_T:R.P_HAIR_T + 3] = fill
        r[:, R.P_HAIR_CURVE] = fill
        f = batch.eval_f_batch(r, np.ones(n, bool), wo, wi, TABLES)
        s = batch.sample_batch(r, np.ones(n, bool), wo, u, ud, np.ones((n, 3), bool), TABLES)
        out.append((f, s[1], s[2]))
    for a, b in zip(*out):
        assert np.array_equal(a, b)
