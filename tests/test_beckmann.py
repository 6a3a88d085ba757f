"""The Beckmann distribution of the compiled BSDF (engine/kernels/bsdf/beckmann.py), the
microfacet model Blender offers on the Glossy, Glass and Refraction BSDF nodes (the
Refraction BSDF's default).

  * Its parts against independent mathematics: the inverse error function against
    SciPy's, D normalised (integral of D cos = 1), the exact Smith Lambda against the
    projected area it must give (integral of D max(0, wo.h) = wo_z (1 + Lambda)), and
    Cycles' rational Lambda (what the BSDF's value uses) within 0.32% of the exact G1.
  * Sampling against the pdf (chi-square, tests/chi2.py) for a Glossy, a Glass and a
    Refraction BSDF with Beckmann at three roughnesses and three view angles; a negative
    control (Beckmann samples against GGX's pdf) must fail.
  * Energy: the mean sample weight f |cos| / pdf equals the quadrature of f |cos| (the
    value uses Cycles' Lambda, the pdf the sampler's exact one: still unbiased), and a
    white Beckmann metal reflects less than 1 (no energy compensation, as in Cycles).
  * Extremes: roughness at either clamp, directions at the normal and at grazing angles:
    every value finite, every sample valid or cleanly rejected.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import special

from chi2 import chi2_test
from engine.kernels import bsdf as kb
from engine.kernels.bsdf import batch
from engine.kernels.bsdf import beckmann as bk
from test_layered_bsdf import albedo_both_ways, case_of as case, rows_of, wo_at

N = 200_000
ANGLES = (10.0, 50.0, 80.0)


def glossy(r, model="BECKMANN"):
    """A Glossy BSDF as the exporter writes it: a white metal."""
    return dict(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=r, glossy_model=model)


def glass(r, model="BECKMANN", refraction_only=False):
    return dict(base_color=(1.0, 1.0, 1.0), transmission=1.0, roughness=r, ior=1.45,
                glossy_model=model, refraction_only=refraction_only)


MATERIALS = {
    **{f"glossy_r{r}": glossy(r) for r in (0.1, 0.5, 1.0)},
    **{f"glass_r{r}": glass(r) for r in (0.2, 0.6)},
    **{f"refraction_r{r}": glass(r, refraction_only=True) for r in (0.3, 0.8)},
}


# --- the parts against independent mathematics -------------------------------------------

def test_erfinv_matches_scipy_to_double_precision():
    y = np.concatenate([np.linspace(-1 + 1e-15, 1 - 1e-15, 4001),
                        [1e-300, -1e-17, 0.5, -0.5, 0.4999999, 0.5000001, 1 - 1e-12]])
    ours = np.array([bk.erfinv(v) for v in y])
    ref = special.erfinv(y)
    rel = np.abs(ours - ref) / np.maximum(np.abs(ref), 1e-300)
    assert rel.max() < 1e-13, rel.max()
    assert bk.erfinv(0.0) == 0.0 and math.isfinite(bk.erfinv(1.0))


def hemisphere_quadrature(n=600):
    """Midpoint nodes and weights over the upper hemisphere, uniform in (theta, phi)."""
    theta = (np.arange(n) + 0.5) * (0.5 * np.pi / n)
    phi = (np.arange(2 * n) + 0.5) * (np.pi / n)
    T, F = np.meshgrid(theta, phi, indexing="ij")
    h = np.stack([np.sin(T) * np.cos(F), np.sin(T) * np.sin(F), np.cos(T)], -1).reshape(-1, 3)
    return h, (np.sin(T) * (0.5 * np.pi / n) * (np.pi / n)).reshape(-1)


@pytest.mark.parametrize("alpha", [0.2, 0.5, 1.0])
def test_D_is_normalised_and_lambda_is_the_projected_area(alpha):
    h, dw = hemisphere_quadrature()
    d = np.array([bk.D(x, y, z, alpha) for x, y, z in h])
    assert abs((d * h[:, 2] * dw).sum() - 1.0) < 1e-4
    for deg in (0.0, 30.0, 60.0, 85.0):
        wo = wo_at(deg, 1)[0]
        projected = (d * np.maximum(h @ wo, 0.0) * dw).sum()
        expected = wo[2] + bk.z_lambda(wo[0], wo[1], wo[2], alpha)
        assert abs(projected / expected - 1.0) < 1e-4, (deg, projected, expected)


def test_cycles_lambda_is_walters_rational_fit_within_a_third_of_a_percent():
    worst = 0.0
    for alpha in (0.05, 0.3, 1.0):
        for deg in np.linspace(0.0, 89.99, 2000):
            t = math.radians(deg)
            x, z = math.sin(t), math.cos(t)
            exact = 1.0 / (z + bk.z_lambda(x, 0.0, z, alpha))
            cycles = 1.0 / (z + bk.z_lambda_cycles(x, 0.0, z, alpha))
            worst = max(worst, abs(cycles / exact - 1.0))
            # the fit itself, at a = cot t / alpha (Walter et al. 2007, below eq. 27)
            a = z / (alpha * x) if x > 0 else math.inf
            lam = 0.0 if a >= 1.6 else (1 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a)
            assert math.isclose(bk.z_lambda_cycles(x, 0.0, z, alpha), z * lam,
                                rel_tol=1e-12, abs_tol=1e-15)
    assert 1e-3 < worst < 0.0032, worst


# --- sampling ----------------------------------------------------------------------------

CASES = [(f"{m}-{d:g}deg", m, d) for m in MATERIALS for d in ANGLES]
N_TESTS = len(CASES) + 2


@pytest.mark.parametrize("label,name,deg", CASES, ids=[c[0] for c in CASES])
def test_sampling_matches_pdf(label, name, deg):
    sample, pdf = case(MATERIALS[name], deg)
    seed = sum(ord(ch) * (i + 1) for i, ch in enumerate(label))
    res = chi2_test(sample, pdf, N, seed=seed, n_tests=N_TESTS)
    print(f"{label}: {res}")
    assert res.passed, f"{label}: {res}"
    assert abs(res.pdf_integral - res.valid_fraction) < 0.01, str(res)


def test_sampling_from_inside_the_glass_matches_pdf():
    sample, pdf = case(MATERIALS["glass_r0.6"], 30.0, front=False)
    res = chi2_test(sample, pdf, N, seed=11, n_tests=N_TESTS)
    print(res)
    assert res.passed, str(res)


def test_negative_control_beckmann_samples_are_not_ggx():
    sample, pdf = case(glossy(0.5), 50.0, pdf_params=glossy(0.5, "GGX"))
    res = chi2_test(sample, pdf, N, seed=5, n_tests=N_TESTS)
    print(f"negative control: {res}")
    assert not res.passed


# --- energy ------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["glossy_r0.5", "glossy_r1.0", "glass_r0.6",
                                  "refraction_r0.3"])
def test_sampled_albedo_equals_integrated(name):
    params = MATERIALS[name]
    for deg in (10.0, 60.0):
        mc, quad, _ = albedo_both_ways(params, deg)
        print(f"{name} at {deg:g} deg: sampled {mc.round(4)}, integrated {quad.round(4)}")
        assert np.allclose(mc, quad, rtol=0.01, atol=2e-3), (mc, quad)


def test_white_beckmann_metal_loses_energy_to_masking_as_in_cycles():
    """No multiple-scattering compensation for Beckmann: a white rough metal reflects
    clearly less than 1 (the multiscatter GGX one keeps it within 1%, test_multiscatter)."""
    _, quad, _ = albedo_both_ways(glossy(1.0), 60.0)
    assert 0.6 < quad[0] < 0.95, quad


# --- extremes ----------------------------------------------------------------------------

@pytest.mark.parametrize("params", [glossy(0.0), glossy(1.0), glass(0.02), glass(1.0),
                                    glass(0.5, refraction_only=True)])
def test_extremes_stay_finite(params):
    tables = kb.kernel_tables()
    rng = np.random.default_rng(3)
    n = 4000
    cos_o = np.concatenate([[1.0, 1e-12, 0.0, 1e-300], rng.random(n - 4) ** 4])
    wo = np.stack([np.sqrt(1 - cos_o ** 2), np.zeros(n), cos_o], -1)
    wi, weight, pdf, _, _, valid = batch.sample_batch(
        rows_of(params, n), np.ones(n, bool), wo, rng.random(n), rng.random((n, 2)),
        np.ones((n, 3), bool), tables)
    assert np.isfinite(wi).all() and np.isfinite(weight).all()
    assert np.isfinite(pdf[valid]).all() and (pdf[valid] > 0).all()
    assert np.allclose(np.linalg.norm(wi[valid], axis=1), 1.0)
    w = rng.normal(size=(n, 3))
    w /= np.linalg.norm(w, axis=1)[:, None]
    f = batch.eval_f_batch(rows_of(params, n), np.ones(n, bool), wo, w, tables)
    p = batch.pdf_batch(rows_of(params, n), np.ones(n, bool), wo, w,
                        np.ones((n, 3), bool), tables)
    assert np.isfinite(f).all() and (f >= 0).all() and np.isfinite(p).all()
    for c in (1.0, 1e-9, 0.0):
        x, y, z = bk.sample_visible_normal(math.sqrt(1 - c * c), 0.0, c, 0.3, 0.999999, 0.0)
        assert all(map(math.isfinite, (x, y, z))) and z > 0.0
