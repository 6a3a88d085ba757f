"""Directional albedo of the Principled specular layer: GGX reflection with exact
dielectric Fresnel, single scattering, tabulated once per process and interpolated.

E_spec(wo) = integral of F(wo.h) D G2 / (4 cos_o) over the reflected hemisphere, the
energy the layer reflects for light leaving along wo; the diffuse layer below gets the
rest (engine/kernels/bsdf/principled.py). The tables are built here (thread-safe, on
first use when the stored file does not match the grids) over (cos theta_o, roughness,
F0^(1/4), side of eta; for eta < 1 the cos axis is aligned on the critical angle) by
stratified visible-normal quadrature of the compiled GGX lobe and Fresnel kernels
(engine/kernels/bsdf/lobe_batch.py); engine/kernels/bsdf/albedo.py interpolates them
trilinearly.

Building both tables takes about a second, once per process; they are kept in
`engine/bsdf/data/specular_albedo.npz` with their grids, and loaded from there (a file
whose grids are not the ones below is rebuilt in memory). Rebuild the file after
changing the lobe, the Fresnel term or a grid:

    python -m engine.bsdf.layer_albedo

tests/test_layered_bsdf.py checks that the file holds what the build computes.
"""
from __future__ import annotations

import os
import threading

import numpy as np

from ..kernels.bsdf import lobe_batch as lb

TABLE_T = np.linspace(0.0, 1.0, 33)          # cos theta_o coordinate, see _mu_of_t
TABLE_R = np.linspace(0.01, 1.0, 17)         # roughness (alpha = r^2 >= ALPHA_MIN)
TABLE_S = np.linspace(0.0, 0.95 ** 0.5, 25)  # F0^(1/4) = sqrt(|eta - 1| / (eta + 1)):
#                                              dense near eta = 1, where E is steep
TABLE_STRATA = 16                            # 16 x 16 stratified visible normals per entry
_tables = [None, None]                       # eta >= 1, eta < 1; each built on first use
_table_lock = threading.Lock()
PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "specular_albedo.npz")


def _critical_cos(eta):
    """cos of the critical angle for relative IOR eta < 1 (0 for eta >= 1)."""
    return np.sqrt(np.clip(1.0 - np.asarray(eta, dtype=np.float64) ** 2, 0.0, 1.0))


def _mu_of_t(t, c):
    """The cos theta_o of table coordinate t in [0, 1]. For eta >= 1 (c = 0): t^2. For
    eta < 1 the critical cosine c sits at t = 1/2 with nodes crowding towards it from
    both sides (c sin^2(pi t) below, quadratic above), so that the steep edge of total
    internal reflection is resolved even for small roughness."""
    t = np.asarray(t, dtype=np.float64)
    lo = c * np.sin(np.pi * np.minimum(t, 0.5)) ** 2
    hi = c + (1.0 - c) * (2.0 * t - 1.0) ** 2
    return np.where(c > 0, np.where(t <= 0.5, lo, hi), t * t)


def _eta_of(x, side):
    eta = (1.0 + x) / (1.0 - x)
    return 1.0 / eta if side else eta


def _build_specular_albedo_table(side):
    """E[s, r, t] = integral of F D G2 / (4 cos_o) over the reflected hemisphere, by
    midpoint quadrature of the visible-normal sampling weight F(wo.h) G2/G1, for
    eta >= 1 (side 0) or eta < 1 (side 1)."""
    k = TABLE_STRATA
    g = (np.arange(k) + 0.5) / k
    u = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)  # (S, 2)
    table = np.empty((len(TABLE_S), len(TABLE_R), len(TABLE_T)))
    cache = {}
    for j, x in enumerate(TABLE_S ** 2):
        eta = _eta_of(x, side)
        c = float(_critical_cos(eta))
        if c not in cache:       # eta >= 1: one set of directions serves every eta
            mu = np.maximum(_mu_of_t(TABLE_T, c), 1e-6)
            rr, tt = np.meshgrid(TABLE_R, mu, indexing="ij")        # (R, T)
            cos_o = np.repeat(tt.reshape(-1), len(u))
            alpha = np.repeat(rr.reshape(-1) ** 2, len(u))
            wo = np.stack([np.sqrt(np.maximum(0.0, 1.0 - cos_o ** 2)), np.zeros_like(cos_o),
                           cos_o], -1)
            wi, h, valid = lb.ggx_reflection_sample(wo, alpha, np.tile(u, (tt.size, 1)))
            weight = np.where(valid, lb.ggx_G2_over_G1(wo, wi, alpha), 0.0)
            cache = {c: (weight, np.clip((wo * h).sum(1), 0.0, 1.0), tt.shape)}
        weight, cos_oh, shape = cache[c]
        F = lb.fresnel_dielectric(cos_oh, eta)
        table[j] = (F * weight).reshape(-1, len(u)).mean(1).reshape(shape)
    return np.clip(table, 0.0, 1.0)


def _grids() -> dict:
    return {"grid_t": TABLE_T, "grid_r": TABLE_R, "grid_s": TABLE_S,
            "strata": np.array([TABLE_STRATA])}


def _stored():
    """The two tables from PATH, or None when it is missing or made on other grids."""
    try:
        with np.load(PATH) as f:
            if all(k in f.files and np.array_equal(f[k], g) for k, g in _grids().items()):
                return [np.ascontiguousarray(f[f"side{i}"], dtype=np.float64)
                        for i in (0, 1)]
    except (OSError, KeyError, ValueError):
        pass
    return None


def get_table(side):
    if _tables[side] is None:
        with _table_lock:
            if _tables[side] is None:
                stored = _stored()
                if stored is not None:
                    _tables[0], _tables[1] = stored
                else:
                    _tables[side] = _build_specular_albedo_table(side)
    return _tables[side]


def save(path=PATH):
    """Build both tables and write them with their grids."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    np.savez(path, side0=_build_specular_albedo_table(0),
             side1=_build_specular_albedo_table(1), **_grids())


if __name__ == "__main__":
    save()
    print(f"wrote {PATH}")
