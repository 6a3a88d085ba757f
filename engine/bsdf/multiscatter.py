"""Multiple-scattering energy compensation of the GGX lobes, as Cycles' "Multiscatter GGX"
(Blender's default distribution since 4.0): each single-scattering lobe is scaled, per
outgoing direction wo, by the energy that light bouncing more than once between the
microfacets would add.

What Cycles does (read in Cycles' sources: kernel/closure/bsdf_microfacet.h,
`microfacet_ggx_preserve_energy` and the `bsdf_microfacet_setup_fresnel_*` functions;
kernel/closure/bsdf_util.h, `fresnel_f82_Fss`, `fresnel_dielectric_Fss` and
`closure_layering_weight`; kernel/svm/closure.h, the Principled BSDF and the Glass and
Glossy nodes; the tables' definitions in app/cycles_precompute.cpp). With
  E(wo)   the directional albedo of the lobe with Fresnel 1 (for glass: of the whole
          dielectric interface, reflection plus refraction, in flux terms),
  E_avg   its cosine-weighted average over wo, and
  F_ss    the lobe's hemispherical average Fresnel reflectance 2 int_0^1 F(mu) mu dmu,
the multiple-scattering Fresnel is F_ms = F_ss E_avg / (1 - F_ss (1 - E_avg)) (Kulla and
Conty 2017, "Revisiting Physically Based Shading at Imageworks", appendix) and

    f(wo, wi) = f_single(wo, wi) (1 + F_ms (1 - E(wo)) / E(wo)),

which is f_single / E(wo) when F_ss = 1: the missing energy 1 - E(wo) is returned in the
shape of the single-scattering lobe, coloured by the Fresnel of further bounces. The
factor depends on wo only, so sampling is unchanged (the compensated BSDF is not exactly
reciprocal, as in Cycles). F_ss per lobe, as Cycles chooses it:
  metal      Schlick (Cycles' F82-tint with the default white tint): F0 + (1 - F0) / 21,
             the exact average of F0 + (1 - F0)(1 - mu)^5;
  specular   the dielectric layer of the Principled BSDF: the average of the exact
             dielectric Fresnel of its IOR (Cycles evaluates Kulla and Conty's fitted
             polynomial; here the integral itself, tabulated);
  glass      the refraction tint ("the transmissive tint makes up most of the overall
             colour"), so white glass gets exactly 1 / E(wo).
The Principled diffuse base lies under the specular layer and gets what that layer
leaves (`closure_layering_weight`): 1 minus the layer's albedo as Cycles estimates it,
`layer_reflectance` (the Fresnel averaged over the visible normals, as if the lobe lost
no energy) times, for Multiscatter GGX, the weight E(wo) (1 + F_ms (1 - E) / E) that the
compensation leaves on the closure (see principled.py).

The tables E, E_avg and the dielectric F_ss are DRT's own, computed from DRT's lobes
(engine/bsdf/energy_tables.py); lookups interpolate (bi/tri)linearly on uniform grids
in rough = sqrt(alpha), t = sqrt(cos theta_o) and z = F0^(1/4) of the relative IOR (see
that module). engine/kernels/bsdf/multiscatter.py is the compiled twin of this module.
"""
from __future__ import annotations

import numpy as np

from . import energy_tables as et
from . import fresnel
from . import microfacet as mf


def _lerp(grid, v):
    """(cell i0, fraction) of v on the uniform grid, v clamped to the grid's range."""
    f = (np.clip(v, grid[0], grid[-1]) - grid[0]) / (grid[1] - grid[0])
    i0 = np.minimum(f.astype(np.int64), len(grid) - 2)
    return i0, f - i0


def _t(cos_o):
    return np.sqrt(np.clip(np.asarray(cos_o, dtype=np.float64), 0.0, 1.0))


def _rough(alpha):
    return np.sqrt(mf.clamp_alpha(alpha))


def ggx_albedo(cos_o, alpha) -> np.ndarray:
    """E(wo) of GGX reflection with F = 1 (single scattering)."""
    tab = et.load()
    i, fi = _lerp(tab["grid_rough"], _rough(alpha))
    j, fj = _lerp(tab["grid_t"], _t(cos_o))
    table = tab["ggx_E"]
    acc = 0.0
    for di, wi in ((0, 1.0 - fi), (1, fi)):
        for dj, wj in ((0, 1.0 - fj), (1, fj)):
            acc = acc + wi * wj * table[i + di, j + dj]
    return acc


def ggx_albedo_avg(alpha) -> np.ndarray:
    """E_avg of GGX reflection with F = 1."""
    tab = et.load()
    i, fi = _lerp(tab["grid_rough"], _rough(alpha))
    table = tab["ggx_E_avg"]
    return (1.0 - fi) * table[i] + fi * table[i + 1]


def _side_z(eta):
    z, side = et.z_of_eta(eta)
    return z, side.astype(np.int64)


def glass_albedo(cos_o, alpha, eta) -> np.ndarray:
    """E(wo) of the rough dielectric interface of relative IOR eta, in flux terms."""
    return glass_grid_lookup("glass_E", cos_o, alpha, eta)


def glass_grid_lookup(name, cos_o, alpha, eta) -> np.ndarray:
    """Table `name` [side, z, rough, t] on the glass grids, trilinearly interpolated."""
    tab = et.load()
    z, s = _side_z(eta)
    i, fi = _lerp(tab["grid_glass_z"], z)
    j, fj = _lerp(tab["grid_glass_rough"], _rough(alpha))
    k, fk = _lerp(tab["grid_glass_t"], _t(cos_o))
    table = tab[name]
    acc = 0.0
    for di, wi in ((0, 1.0 - fi), (1, fi)):
        for dj, wj in ((0, 1.0 - fj), (1, fj)):
            for dk, wk in ((0, 1.0 - fk), (1, fk)):
                acc = acc + wi * wj * wk * table[s, i + di, j + dj, k + dk]
    return acc


def glass_albedo_avg(alpha, eta) -> np.ndarray:
    """E_avg of the rough dielectric interface of relative IOR eta."""
    tab = et.load()
    z, s = _side_z(eta)
    i, fi = _lerp(tab["grid_glass_z"], z)
    j, fj = _lerp(tab["grid_glass_rough"], _rough(alpha))
    table = tab["glass_E_avg"]
    acc = 0.0
    for di, wi in ((0, 1.0 - fi), (1, fi)):
        for dj, wj in ((0, 1.0 - fj), (1, fj)):
            acc = acc + wi * wj * table[s, i + di, j + dj]
    return acc


def dielectric_fresnel_avg(eta) -> np.ndarray:
    """F_ss of the exact dielectric Fresnel reflectance of relative IOR eta."""
    tab = et.load()
    z, s = _side_z(eta)
    i, fi = _lerp(tab["grid_fresnel_z"], z)
    table = tab["fresnel_avg"]
    return (1.0 - fi) * table[s, i] + fi * table[s, i + 1]


def layer_reflectance(cos_o, alpha, eta) -> np.ndarray:
    """The reflectance of a dielectric GGX layer at wo as Cycles estimates it for the
    layers below (`bsdf_microfacet_estimate_albedo`): F0 + (1 - F0) s, s the mean of
    (F(wo.h) - F0) / (1 - F0) over the visible normals (energy_tables' `fresnel_s`), the
    Fresnel averaged as if the lobe lost no energy to masking."""
    f0 = fresnel.f0_from_ior(eta)
    return f0 + (1.0 - f0) * glass_grid_lookup("fresnel_s", cos_o, alpha, eta)


def schlick_fresnel_avg(f0) -> np.ndarray:
    """F_ss of Schlick's F0 + (1 - F0)(1 - mu)^5: F0 + (1 - F0) / 21."""
    f0 = np.asarray(f0, dtype=np.float64)
    return f0 + (1.0 - f0) / 21.0


def compensation(E, E_avg, F_ss) -> np.ndarray:
    """The factor 1 + F_ms (1 - E) / E of the module docstring; E and E_avg broadcast
    against F_ss (e.g. (n, 1) against a colour (n, 3))."""
    F_ms = F_ss * E_avg / (1.0 - F_ss * (1.0 - E_avg))
    return 1.0 + F_ms * ((1.0 - E) / E)
