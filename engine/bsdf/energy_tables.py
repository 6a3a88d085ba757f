"""Albedo tables of DRT's GGX lobes, for the multiple-scattering energy compensation of
engine/kernels/bsdf/multiscatter.py, and the code that computes them.

The tables are computed here, from the compiled lobes the renderer runs
(engine/kernels/bsdf/microfacet.py and dielectric.py, through lobe_batch.py), by
quadrature, and cached in `engine/bsdf/data/ggx_energy.npz` (NumPy
.npy arrays in one archive). Rebuild the file after changing a lobe or a grid:

    python -m engine.bsdf.energy_tables

(a few minutes on one core). `load()` reads the file once per process and checks that
its grids are the grids below; tests/test_multiscatter.py recomputes sample entries.

Tables (float64), with rough = sqrt(alpha) (Blender's roughness), t = sqrt(cos theta_o)
and, for a relative IOR eta, z = sqrt(|e - 1| / (e + 1)) where e = eta on side 0
(eta >= 1) and e = 1 / eta on side 1 (eta < 1), i.e. z = F0(e)^(1/4):

  ggx_E[r, t]             directional albedo of GGX reflection with F = 1, single
                          scattering: integral of D G2 / (4 cos_o) over the hemisphere;
  ggx_E_avg[r]            its cosine-weighted average 2 int_0^1 E(mu) mu dmu;
  glass_E[s, z, r, t]     directional albedo of the rough dielectric interface (reflection
                          plus refraction) in flux terms (the kernels' own: no radiance
                          scaling), so that a lossless interface gives 1;
  glass_E_avg[s, z, r]    its cosine-weighted average;
  fresnel_avg[s, z]       2 int_0^1 F(mu) mu dmu of the exact dielectric Fresnel reflectance
                          (the "Fss" of a dielectric specular layer);
  fresnel_s[s, z, r, t]   the mean over the visible normals h of wo of
                          s(h) = (F(wo.h) - F0) / (1 - F0) (0 where the reflection leaves
                          below the surface): the dielectric GGX layer's reflectance as
                          Cycles estimates it for layering, F0 + (1 - F0) s, which assumes
                          a lobe that loses no energy (Cycles' ggx_gen_schlick_ior_s table,
                          read in app/cycles_precompute.cpp; on the glass grids).

Quadrature: an entry is an expectation over the visible normals of wo (Heitz 2018), whose
sampling map takes (u0, u1) in the unit square; with u0 = rho^2 it is a Gauss-Legendre
rule in rho (weight 2 rho) times the midpoint rule in u1 (periodic in the azimuth). Each
sampled normal contributes the exact weight of its reflection (F G2/G1) and, for glass,
of its refraction ((1 - F) G2/G1) at once, so no random choice enters. Averages over mu
integrate the linear interpolant of the table exactly, so they are consistent with the
lookups. The convergence is measured in tests/test_multiscatter.py.
"""
from __future__ import annotations

import os
import threading

import numpy as np

from ..kernels.bsdf import lobe_batch as lb

ROUGH = np.linspace(0.01, 1.0, 34)       # sqrt(alpha), from sqrt(ALPHA_MIN)
T = np.linspace(0.0, 1.0, 33)            # sqrt(cos theta_o)
GLASS_ROUGH = np.linspace(0.01, 1.0, 23)
GLASS_T = np.linspace(0.0, 1.0, 23)
GLASS_Z = np.linspace(0.0, 0.9, 19)      # eta up to (1 + 0.81) / (1 - 0.81) = 9.5
FRESNEL_Z = np.linspace(0.0, 1.0, 257)   # z = 1: eta = infinity, F = 1
INDEX_MATCHED = 1e-6                     # kernels/bsdf/dielectric.py: no interface
MU_MIN = 1e-9                            # cos theta_o used for the node t = 0
QUAD_GGX = (96, 192)                     # Gauss-Legendre nodes in rho, midpoints in u1
QUAD_GLASS = (48, 96)
QUAD_FRESNEL = 64                        # Gauss-Legendre nodes above the critical angle

PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "ggx_energy.npz")
GRIDS = {"grid_rough": ROUGH, "grid_t": T, "grid_glass_rough": GLASS_ROUGH,
         "grid_glass_t": GLASS_T, "grid_glass_z": GLASS_Z, "grid_fresnel_z": FRESNEL_Z}
NAMES = ("ggx_E", "ggx_E_avg", "glass_E", "glass_E_avg", "fresnel_avg", "fresnel_s")


# --- coordinates -----------------------------------------------------------------------

def eta_of_z(z, side):
    """The relative IOR of coordinate z on side 0 (eta >= 1) or side 1 (eta < 1)."""
    s = np.asarray(z, dtype=np.float64) ** 2
    with np.errstate(divide="ignore"):
        e = np.where(s < 1.0, (1.0 + s) / np.maximum(1.0 - s, 0.0), np.inf)
    return 1.0 / e if side else e


def z_of_eta(eta):
    """(z, side) of relative IOR eta: z = sqrt(|e - 1| / (e + 1)), e = max(eta, 1/eta)."""
    eta = np.asarray(eta, dtype=np.float64)
    side = eta < 1.0
    e = np.where(side, 1.0 / eta, eta)
    return np.sqrt(np.abs(e - 1.0) / (e + 1.0)), side


def mu_of_t(t):
    return np.maximum(np.asarray(t, dtype=np.float64) ** 2, MU_MIN)


# --- quadrature ------------------------------------------------------------------------

def vndf_rule(n_rho, n_phi):
    """(u (k, 2), weights (k,)) of the visible-normal rule described in the docstring."""
    x, w = np.polynomial.legendre.leggauss(n_rho)
    rho = 0.5 * (x + 1.0)
    w_rho = w * rho                       # 0.5 (interval) x 2 rho (density of rho^2)
    u1 = (np.arange(n_phi) + 0.5) / n_phi
    u = np.stack([np.repeat(rho * rho, n_phi), np.tile(u1, n_rho)], -1)
    return u, np.repeat(w_rho, n_phi) / n_phi


def _directions(mu, k):
    mu = np.repeat(np.asarray(mu, dtype=np.float64), k)
    return np.stack([np.sqrt(np.maximum(0.0, 1.0 - mu * mu)), np.zeros_like(mu), mu], -1)


def reflection_albedo(mu, alpha, quad=QUAD_GGX) -> np.ndarray:
    """E(mu, alpha) (m,) of GGX reflection with F = 1, for arrays mu, alpha (m,)."""
    u, w = vndf_rule(*quad)
    mu, alpha = np.broadcast_arrays(np.asarray(mu, float), np.asarray(alpha, float))
    k = len(w)
    wo = _directions(mu.ravel(), k)
    a = np.repeat(alpha.ravel(), k)
    wi, _, valid = lb.ggx_reflection_sample(wo, a, np.tile(u, (mu.size, 1)))
    g = np.where(valid, lb.ggx_G2_over_G1(wo, wi, a), 0.0)
    return (g.reshape(-1, k) * w).sum(1).reshape(mu.shape)


def glass_albedo(mu, alpha, eta, quad=QUAD_GLASS) -> np.ndarray:
    """Flux albedo (m,) of the rough dielectric of relative IOR eta seen from wo above
    the surface: reflection F G2/G1 plus refraction (1 - F) G2/G1 (the weights of
    `lobe_batch.rough_dielectric_sample`, which carry no radiance scaling).
    Index-matched (|eta - 1| < INDEX_MATCHED), the quadrature is degenerate (every normal
    refracts wo into -wo); the entry is the limit eta -> 1 of the rough interface: F = 0
    and every sample refracts along -wo with weight G2(wo, -wo) / G1(wo), so that the
    table interpolates continuously towards IORs near 1 (the kernels render eta = 1
    itself as no interface)."""
    u, w = vndf_rule(*quad)
    mu, alpha, eta = np.broadcast_arrays(np.asarray(mu, float), np.asarray(alpha, float),
                                         np.asarray(eta, float))
    k = len(w)
    wo = _directions(mu.ravel(), k)
    a = np.repeat(alpha.ravel(), k)
    e = np.repeat(eta.ravel(), k)
    uu = np.tile(u, (mu.size, 1))
    zero = np.zeros(len(wo))
    _, w_r, _, ok_r, _ = lb.rough_dielectric_sample(wo, e, a, zero, uu, True, False)
    _, w_t, _, ok_t, _ = lb.rough_dielectric_sample(wo, e, a, zero, uu, False, True)
    g = np.where(ok_r, w_r, 0.0) + np.where(ok_t, w_t, 0.0)
    out = (g.reshape(-1, k) * w).sum(1).reshape(mu.shape)
    wo = _directions(mu.ravel(), 1)
    limit = lb.ggx_G2_over_G1(wo, -wo, alpha.ravel()).reshape(mu.shape)
    return np.where(np.abs(eta - 1.0) < INDEX_MATCHED, limit, out)


def fresnel_interpolant(mu, alpha, eta, quad=QUAD_GLASS) -> np.ndarray:
    """The mean (m,) over the visible normals of wo of s = (F(wo.h) - F0) / (1 - F0)
    for GGX reflection (0 for a reflection below the surface), exact dielectric F of
    relative IOR eta; see `fresnel_s` in the module docstring."""
    u, w = vndf_rule(*quad)
    mu, alpha, eta = np.broadcast_arrays(np.asarray(mu, float), np.asarray(alpha, float),
                                         np.asarray(eta, float))
    k = len(w)
    wo = _directions(mu.ravel(), k)
    a = np.repeat(alpha.ravel(), k)
    e = np.repeat(eta.ravel(), k)
    wi, h, valid = lb.ggx_reflection_sample(wo, a, np.tile(u, (mu.size, 1)))
    F = lb.fresnel_dielectric(np.clip((wo * h).sum(1), 0.0, 1.0), e)
    F0 = ((e - 1.0) / (e + 1.0)) ** 2
    span = 1.0 - F0
    s = np.clip((F - F0) / np.where(span > 0, span, 1.0), 0.0, 1.0)
    g = np.where(valid & (span > 0), s, 0.0)
    return (g.reshape(-1, k) * w).sum(1).reshape(mu.shape)


def fresnel_average(eta) -> np.ndarray:
    """2 int_0^1 F(mu, eta) mu dmu of the exact dielectric Fresnel reflectance (eta (m,)).
    Below the critical cosine c (eta < 1) F = 1, which gives c^2; above it, F has a
    square-root edge at c, removed by mu = c + (1 - c) x^2 before Gauss-Legendre in x."""
    eta = np.atleast_1d(np.asarray(eta, dtype=np.float64))
    x, w = np.polynomial.legendre.leggauss(QUAD_FRESNEL)
    x, w = 0.5 * (x + 1.0), 0.5 * w
    out = np.ones(eta.shape)
    fin = np.isfinite(eta) & (eta > 0.0)          # eta 0 or infinity: F = 1 everywhere
    e = eta[fin][:, None]
    c = np.sqrt(np.clip(1.0 - e * e, 0.0, 1.0))      # critical cosine (0 for eta >= 1)
    mu = c + (1.0 - c) * x * x
    F = lb.fresnel_dielectric(mu, np.broadcast_to(e, mu.shape))
    out[fin] = c[:, 0] ** 2 + 4.0 * (1.0 - c[:, 0]) * (F * mu * x * w).sum(1)
    return out


def _average_over_mu(E, t_grid):
    """2 int_0^1 E(mu) mu dmu = 4 int_0^1 E(t) t^3 dt of the piecewise-linear interpolant
    of E (..., len(t_grid)) in t, exactly (the cell integrals of t^3 and t^4)."""
    t0, t1 = t_grid[:-1], t_grid[1:]
    h = t1 - t0
    i3 = (t1 ** 4 - t0 ** 4) / 4.0
    i4 = (t1 ** 5 - t0 ** 5) / 5.0
    # on a cell E = E0 + (E1 - E0) (t - t0) / h
    w0 = i3 - (i4 - t0 * i3) / h
    w1 = (i4 - t0 * i3) / h
    return 4.0 * (E[..., :-1] * w0 + E[..., 1:] * w1).sum(-1)


# --- building, saving, loading -----------------------------------------------------------

def build(progress=None) -> dict:
    """Every table (see the module docstring), computed from scratch."""
    out = dict(GRIDS)
    rr, tt = np.meshgrid(ROUGH, mu_of_t(T), indexing="ij")
    E = np.empty(rr.shape)
    for i in range(len(ROUGH)):
        E[i] = reflection_albedo(tt[i], rr[i] ** 2)
    out["ggx_E"] = np.clip(E, 0.0, 1.0)
    out["ggx_E_avg"] = _average_over_mu(out["ggx_E"], T)
    rr, tt = np.meshgrid(GLASS_ROUGH, mu_of_t(GLASS_T), indexing="ij")
    G = np.empty((2, len(GLASS_Z), len(GLASS_ROUGH), len(GLASS_T)))
    for s in (0, 1):
        for j, z in enumerate(GLASS_Z):
            eta = float(eta_of_z(z, s))
            for i in range(len(GLASS_ROUGH)):
                G[s, j, i] = glass_albedo(tt[i], rr[i] ** 2, eta)
            if progress is not None:
                progress(f"glass side {s}, z {z:.3f} (eta {eta:.4g})")
    out["glass_E"] = np.clip(G, 0.0, 1.0)
    out["glass_E_avg"] = _average_over_mu(out["glass_E"], GLASS_T)
    out["fresnel_avg"] = np.stack([fresnel_average(eta_of_z(FRESNEL_Z, s)) for s in (0, 1)])
    out["fresnel_s"] = build_fresnel_s(progress)
    return out


def build_fresnel_s(progress=None) -> np.ndarray:
    rr, tt = np.meshgrid(GLASS_ROUGH, mu_of_t(GLASS_T), indexing="ij")
    S = np.empty((2, len(GLASS_Z), len(GLASS_ROUGH), len(GLASS_T)))
    for s in (0, 1):
        for j, z in enumerate(GLASS_Z):
            eta = float(eta_of_z(z, s))
            for i in range(len(GLASS_ROUGH)):
                S[s, j, i] = fresnel_interpolant(tt[i], rr[i] ** 2, eta)
            if progress is not None:
                progress(f"layer Fresnel side {s}, z {z:.3f} (eta {eta:.4g})")
    return np.clip(S, 0.0, 1.0)


def save(tables, path=PATH):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    np.savez(path, **tables)


_loaded = None
_lock = threading.Lock()


def load() -> dict:
    """The tables from `PATH` (built and written there if the file is missing), once per
    process. Raises if the file's grids are not this module's (rebuild it)."""
    global _loaded
    if _loaded is None:
        with _lock:
            if _loaded is None:
                if os.path.exists(PATH):
                    with np.load(PATH) as f:
                        tables = {k: np.ascontiguousarray(f[k], dtype=np.float64)
                                  for k in f.files}
                else:
                    tables = build()
                    try:
                        save(tables)
                    except OSError:
                        pass
                for k, grid in GRIDS.items():
                    if k not in tables or not np.array_equal(tables[k], grid):
                        raise RuntimeError(f"{PATH}: grid {k} differs from energy_tables.py; "
                                           f"rebuild it (python -m engine.bsdf.energy_tables)")
                missing = [k for k in NAMES if k not in tables]
                if missing:
                    raise RuntimeError(f"{PATH} lacks {missing}; rebuild it")
                _loaded = tables
    return _loaded


if __name__ == "__main__":
    import time
    start = time.time()
    tables = build(progress=lambda s: print(f"{time.time() - start:7.1f} s  {s}", flush=True))
    save(tables)
    print(f"wrote {PATH} in {time.time() - start:.0f} s")
