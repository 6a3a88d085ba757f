"""Thin-film interference (engine/kernels/bsdf/thin_film.py) against oracles that share
none of its code: the exact coherent reflectance of a film, summed over every order of
reflection for each wavelength and integrated against the colour matching functions
(Born and Wolf's thin-film formula, here in NumPy); its limits; and what the exporter
makes of the Principled BSDF's Thin Film inputs. Cycles: tests/test_thin_film_vs_cycles.py.
"""
from __future__ import annotations

import numpy as np
import pytest

from engine.bsdf import thin_film_table as table
from engine.kernels.bsdf import fresnel, thin_film


def _spectral(cos_1, d, n_film, eta):
    """The film's reflectance in each scene-linear channel: |r|^2 of the Airy amplitude
    per wavelength, both polarisations averaged, weighted by the channel's CMF."""
    data = np.load(table.DATA)
    wl = data["wavelength_nm"]
    cmf = data["xyz"] @ table.XYZ_TO_REC709.T
    sin_1 = np.sqrt(1.0 - cos_1 ** 2)
    cos_2 = np.sqrt(1.0 - (sin_1 / n_film) ** 2 + 0j)
    cos_3 = np.sqrt(1.0 - (sin_1 / eta) ** 2 + 0j)

    def r_s(n1, c1, n2, c2):
        return (n1 * c1 - n2 * c2) / (n1 * c1 + n2 * c2)

    def r_p(n1, c1, n2, c2):
        return (n2 * c1 - n1 * c2) / (n2 * c1 + n1 * c2)
    phase = np.exp(1j * 4.0 * np.pi * n_film * d * cos_2 / wl)
    R = 0.0
    for r in (r_s, r_p):
        r12, r23 = r(1.0, cos_1, n_film, cos_2), r(n_film, cos_2, eta, cos_3)
        R = R + 0.5 * np.abs((r12 + r23 * phase) / (1.0 + r12 * r23 * phase)) ** 2
    return (R[:, None] * cmf).sum(axis=0) / cmf.sum(axis=0)


def test_the_stored_table_is_what_the_cmfs_give():
    stored = table.load()
    np.testing.assert_allclose(stored, table.build(), rtol=0, atol=1e-12)
    assert stored.shape == (6, table.ROWS)
    np.testing.assert_allclose(stored[:3, 0], 1.0, rtol=1e-15)    # S(0): the CMF's area
    np.testing.assert_array_equal(stored[3:, 0], 0.0)


@pytest.mark.parametrize("cos_1", [1.0, 0.7, 0.3])
@pytest.mark.parametrize("d", [100.0, 300.0, 600.0, 1500.0])
def test_a_film_on_a_dielectric_reflects_its_spectral_integral(cos_1, d):
    """The Airy sum's three orders against every order, over 360-830 nm: within 0.001
    (measured: 3e-4 at most; the reflectances range 0.006 to 0.21)."""
    got = np.array([thin_film.over_dielectric(c, cos_1, d, 1.33, 1.5) for c in range(3)])
    np.testing.assert_allclose(got, _spectral(cos_1, d, 1.33, 1.5), atol=1e-3)


def test_the_colours_move_with_thickness_and_angle():
    """The oracle's point: a film is coloured, and its colour turns with the angle."""
    a = np.array([thin_film.over_dielectric(c, 1.0, 300.0, 1.33, 1.5) for c in range(3)])
    b = np.array([thin_film.over_dielectric(c, 0.5, 300.0, 1.33, 1.5) for c in range(3)])
    assert a.max() > 2.0 * a.min() and np.argmax(a) != np.argmax(b)


def test_a_vanishing_film_leaves_the_bare_surface():
    """Below 1 nm the film's index blends to the air's: at 1e-4 nm the dielectric's own
    Fresnel and the F82-tint metal's own value."""
    for cos in (1.0, 0.6, 0.1):
        for c in range(3):
            assert thin_film.over_dielectric(c, cos, 1e-4, 1.33, 1.5) == pytest.approx(
                fresnel.dielectric(cos, 1.5), rel=1e-6)
        f0, b = 0.9, fresnel.f82_tint_b(0.9, 0.8)
        assert thin_film.metal(0, cos, 1e-4, 1.5, f0, b) == pytest.approx(
            fresnel.f82_tint(f0, b, cos), rel=1e-6)


def test_total_reflection_and_extremes_stay_in_range():
    for cos in (1.0, 0.5, 1e-6, 0.0):
        for d in (0.2, 50.0, 1e4, 1e7):
            for c in range(3):
                for v in (thin_film.over_dielectric(c, cos, d, 2.5, 1.0 / 1.5),
                          thin_film.metal(c, cos, d, 1.2, 0.999, 0.0),
                          thin_film.specular_layer(c, cos, d, 1.33, 1.45, 0.03)):
                    assert np.isfinite(v) and 0.0 <= v <= 1.0 + 1e-12


def test_the_principled_bsdf_reflects_the_film():
    """Through the compiled Principled BSDF: a film changes the specular layer's and the
    metal's colour at normal incidence; one at the cut-off (0.1 nm) changes nothing."""
    from engine.kernels.bsdf.batch import Principled
    from engine.kernels.bsdf.params import P_THIN_FILM, P_THIN_FILM_IOR
    wo = wi = (0.0, 0.0, 1.0)
    for metallic in (0.0, 1.0):
        bsdf = Principled.with_params([(0.05, 0.05, 0.05)] * 3, metallic=metallic,
                                      roughness=0.3)
        bsdf.rows[:, P_THIN_FILM] = (0.0, 0.1, 400.0)
        bsdf.rows[:, P_THIN_FILM_IOR] = 1.33
        f = bsdf.eval_f(wo, wi)
        np.testing.assert_array_equal(f[1], f[0])
        assert np.ptp(f[2]) > 0.2 * f[2].mean(), f          # coloured
        assert np.ptp(f[0]) < 1e-9


def test_a_material_without_a_film_takes_the_plain_path():
    """Principle 3: only a film (or a Specular Tint) sends the specular layer down the
    per-channel path; a plain plastic's state has neither, so it pays nothing."""
    from engine.kernels.bsdf.batch import Principled
    from engine.kernels.bsdf.params import P_THIN_FILM
    from engine.kernels.bsdf.state import S_SPEC_TINTED, S_THIN_FILM
    bsdf = Principled.with_params([(0.5, 0.2, 0.1)] * 2, roughness=0.4)
    bsdf.rows[1, P_THIN_FILM] = 300.0
    s = bsdf.states((0.3, 0.0, 0.95))
    assert s[0, S_THIN_FILM] == 0.0 and s[0, S_SPEC_TINTED] == 0.0
    assert s[1, S_THIN_FILM] == 300.0 and s[1, S_SPEC_TINTED] == 1.0


@pytest.mark.parametrize("front", [True, False], ids=["outside", "inside"])
def test_a_frosted_glass_under_a_film_samples_its_pdf(front):
    """The glass chooses reflection or refraction by the film's reflectance
    (thin_film.glass_choice), in its sampling and in its pdf alike: chi-square, from
    outside and from inside (where part of the directions are totally reflected)."""
    from chi2 import chi2_test
    from engine.kernels import bsdf as kb
    from engine.kernels.bsdf import batch
    from test_layered_bsdf import rows_of, sampler_pairs, wo_at
    params = dict(base_color=(1.0, 1.0, 1.0), transmission=1.0, roughness=0.3,
                  thin_film_thickness=500.0, thin_film_ior=1.33, glossy_model="MULTI_GGX")
    deg = 40.0 if front else 30.0

    def sample(u):
        n = len(u)
        s = batch.sample_batch(rows_of(params, n), np.full(n, front), wo_at(deg, n),
                               u[:, 0], np.ascontiguousarray(u[:, 1:]),
                               np.ones((n, 3), bool), kb.kernel_tables())
        return s[0], s[5]

    def pdf(w):
        n = len(w)
        return batch.pdf_batch(rows_of(params, n), np.full(n, front), wo_at(deg, n),
                               np.ascontiguousarray(w), np.ones((n, 3), bool),
                               kb.kernel_tables()) * sampler_pairs(params, wo_at(deg, n), w,
                                                                   front)
    res = chi2_test(sample, pdf, 200_000, seed=11 + int(front), n_tests=2)
    print(res)
    assert res.passed, str(res)
