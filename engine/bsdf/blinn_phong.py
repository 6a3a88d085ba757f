"""Normalised Blinn-Phong microfacet reflection (the Cook-Torrance era lobe).

Distribution of normals (Blinn 1977, normalised as in Cook & Torrance 1982 / Cook 1984
practice, and Walter et al. 2007 eq. 30):
    D(h) = (n + 2) / (2 pi) cos^n(theta_h)          [1/sr, integral D cos(theta_h) = 1]
BRDF, with the Cook-Torrance V-cavity shadowing-masking (Cook & Torrance 1982, eq. 4)
    G = min(1, 2 (n.h)(n.wo) / (wo.h), 2 (n.h)(n.wi) / (wo.h))
    f(wo, wi) = D(h) G / (4 cos(theta_o) cos(theta_i))            [1/sr]
with no Fresnel factor (multiply by a specular colour or F if wanted). The V-cavity
surface is a real microgeometry, so the lobe conserves energy (directional albedo <= 1)
and is reciprocal (h, G and the denominator are symmetric in wo, wi).

Sampling: the half vector with pdf(h) = (n + 1) / (2 pi) cos^n(theta_h), i.e.
cos(theta_h) = u^(1/(n+1)), then reflection; pdf(wi) = pdf(h) / (4 |wo.h|) (Jacobian of
the reflection map, Walter et al. 2007 eq. 14).

Large exponents (tested up to 1e6): cos^n is evaluated as exp(n/2 log1p(-sin^2)), sampled
cosines come from expm1 so that 1 - cos(theta_h) keeps its precision, and D stays finite
((n + 2) / (2 pi) ~ 1.6e5 at the peak for n = 1e6).

Directions: unit (n, 3) float64 in the local frame (normal = +Z), away from the surface;
reflection only (zero unless both are above the surface). `exponent`: (n,) or scalar >= 0.
"""
from __future__ import annotations

import numpy as np

INV_2PI = 0.5 / np.pi


def _cos_pow(h, exponent):
    """cos(theta_h)^n for unit h with h_z > 0, via log1p of sin^2."""
    s2 = np.clip(h[:, 0] * h[:, 0] + h[:, 1] * h[:, 1], 0.0, 1.0 - 1e-16)
    return np.exp(exponent * 0.5 * np.log1p(-s2))


def D(h: np.ndarray, exponent) -> np.ndarray:
    """(n + 2)/(2 pi) cos^n(theta_h); zero for h_z <= 0."""
    e = np.broadcast_to(np.asarray(exponent, dtype=np.float64), h[:, 2].shape)
    return np.where(h[:, 2] > 0, (e + 2.0) * INV_2PI * _cos_pow(h, e), 0.0)


def _half(wo, wi):
    h = wo + wi
    n = np.sqrt((h * h).sum(1))
    ok = n > 1e-12
    return h / np.where(ok, n, 1.0)[:, None], ok


def G(wo: np.ndarray, wi: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Cook-Torrance V-cavity shadowing-masking."""
    c = (wo * h).sum(1)
    ok = c > 0
    cs = np.where(ok, c, 1.0)
    g = np.minimum(1.0, np.minimum(2.0 * h[:, 2] * wo[:, 2] / cs, 2.0 * h[:, 2] * wi[:, 2] / cs))
    return np.where(ok, np.maximum(g, 0.0), 0.0)


def eval_f(wo: np.ndarray, wi: np.ndarray, exponent) -> np.ndarray:
    """BRDF value (n,) in 1/sr."""
    h, ok = _half(wo, wi)
    ok &= (wo[:, 2] > 0) & (wi[:, 2] > 0)
    den = 4.0 * wo[:, 2] * wi[:, 2]
    # G <= 2 h_z min(cos) / (wo.h) keeps D G / den finite even for tiny cosines
    val = D(h, exponent) * G(wo, wi, h) / np.where(ok, den, 1.0)
    return np.where(ok, val, 0.0)


def pdf(wo: np.ndarray, wi: np.ndarray, exponent) -> np.ndarray:
    """pdf over wi (1/sr) of `sample`."""
    h, ok = _half(wo, wi)
    ok &= (wo[:, 2] > 0) & (wi[:, 2] > 0)
    c = (wo * h).sum(1)
    ok &= c > 0
    e = np.broadcast_to(np.asarray(exponent, dtype=np.float64), c.shape)
    pdf_h = (e + 1.0) * INV_2PI * _cos_pow(h, e)
    return np.where(ok, pdf_h / (4.0 * np.where(ok, c, 1.0)), 0.0)


def sample(wo: np.ndarray, u: np.ndarray, exponent):
    """Sample wi from wo: returns (wi, valid). u: (n, 2) in [0, 1)."""
    e = np.broadcast_to(np.asarray(exponent, dtype=np.float64), u[:, 0].shape)
    with np.errstate(divide="ignore"):
        log_u = np.log(u[:, 0])                      # -inf at u = 0: cos = 0, rejected
    k = 2.0 * log_u / (e + 1.0)                      # log(cos^2)
    cos2 = np.exp(k)
    sin2 = np.clip(-np.expm1(k), 0.0, 1.0)
    cos_h = np.sqrt(cos2)
    sin_h = np.sqrt(sin2)
    phi = 2.0 * np.pi * u[:, 1]
    h = np.stack([sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h], -1)
    c = (wo * h).sum(1)
    wi = 2.0 * c[:, None] * h - wo
    valid = (wo[:, 2] > 0) & (wi[:, 2] > 0) & (c > 0) & (cos_h > 0)
    return wi, valid
