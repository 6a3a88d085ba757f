"""The diffuse lobe's roughness (engine/kernels/bsdf/oren_nayar.py) against oracles that
share none of its code: a white lobe reflects everything at every view and roughness
(a quadrature of f cos over the hemisphere, Cycles' energy-preserving model), f is
reciprocal, roughness 0 is Lambert exactly, roughness flattens: at a grazing view it
sends more light back towards the viewer than Lambert (retro-reflection), the sampler's
weights are f cos / pdf of the cosine density, and extreme inputs stay finite. Against
Cycles: tests/test_oren_nayar_vs_cycles.py."""
from __future__ import annotations

import numpy as np
import pytest

from engine.kernels.bsdf.batch import Principled


def _hemisphere(n_theta=400, n_phi=200):
    """Midpoint-rule directions and solid angles over the upper hemisphere."""
    theta = (np.arange(n_theta) + 0.5) / n_theta * (np.pi / 2)
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2 * np.pi
    T, P = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    dw = (np.sin(T) * (np.pi / 2 / n_theta) * (2 * np.pi / n_phi)).ravel()
    return d, dw


def _diffuse(n, roughness, color=(1.0, 1.0, 1.0)):
    return Principled.of(n, base_color=color, specular_ior_level=0.0,
                         diffuse_roughness=roughness)


def _wo(mu):
    return np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])


@pytest.mark.parametrize("roughness", [0.2, 0.5, 1.0])
@pytest.mark.parametrize("mu", [1.0, 0.6, 0.15])
def test_a_white_rough_diffuse_lobe_reflects_everything(roughness, mu):
    d, dw = _hemisphere()
    f = _diffuse(len(d), roughness).eval_f(_wo(mu), d)
    albedo = (f[:, 0] * d[:, 2] * dw).sum()
    assert albedo == pytest.approx(1.0, abs=2e-3), albedo
    grey = _diffuse(len(d), roughness, (0.5, 0.5, 0.5)).eval_f(_wo(mu), d)
    assert 0.3 < (grey[:, 0] * d[:, 2] * dw).sum() < 0.5    # less, by multiple scattering


def test_roughness_zero_is_lambert_and_roughness_is_reciprocal_and_retroreflects():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(500, 3))
    b = rng.normal(size=(500, 3))
    a[:, 2], b[:, 2] = np.abs(a[:, 2]), np.abs(b[:, 2])
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    lambert = Principled.of(500, base_color=(0.7, 0.5, 0.3), specular_ior_level=0.0)
    zero = Principled.of(500, base_color=(0.7, 0.5, 0.3), specular_ior_level=0.0,
                         diffuse_roughness=0.0)
    np.testing.assert_array_equal(zero.eval_f(a, b), lambert.eval_f(a, b))
    np.testing.assert_allclose(lambert.eval_f(a, b)[:, 0], 0.7 / np.pi, rtol=1e-12)
    rough = Principled.of(500, base_color=(0.7, 0.5, 0.3), specular_ior_level=0.0,
                          diffuse_roughness=0.8)
    np.testing.assert_allclose(rough.eval_f(a, b), rough.eval_f(b, a), rtol=1e-9)
    view = _wo(0.2)
    back = np.array([view])                              # towards the viewer
    forward = np.array([[-view[0], 0.0, view[2]]])       # the mirror direction
    one = _diffuse(1, 1.0)
    assert one.eval_f(view, back)[0, 0] > 1.2 / np.pi > one.eval_f(view, forward)[0, 0]


def test_sampled_weights_are_f_cos_over_the_cosine_pdf():
    n = 2000
    rng = np.random.default_rng(5)
    bsdf = _diffuse(n, 0.7, (0.9, 0.6, 0.2))
    wo = _wo(0.4)
    s = bsdf.sample(wo, rng.random(n), rng.random((n, 2)))
    ok = s.valid
    assert ok.mean() > 0.99
    wi = s.wi[ok]
    np.testing.assert_allclose(s.pdf[ok], wi[:, 2] / np.pi, rtol=1e-9)
    f = _diffuse(int(ok.sum()), 0.7, (0.9, 0.6, 0.2)).eval_f(wo, wi)
    np.testing.assert_allclose(s.weight[ok], f * wi[:, 2:3] / s.pdf[ok, None], rtol=1e-9)


@pytest.mark.parametrize("roughness", [1e-6, 1e-5, 0.5, 1.0, 7.0, -3.0, np.nan])
def test_extreme_roughness_and_grazing_directions_stay_finite(roughness):
    wo = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 1e-12], _wo(1e-7), _wo(1.0)])
    wi = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 1e-300], _wo(1e-9), [0.0, 1.0, 1e-8]])
    f = _diffuse(4, roughness, (1.0, 0.0, 3.0)).eval_f(wo, wi)
    assert np.all(np.isfinite(f)) and np.all(f >= 0.0)
