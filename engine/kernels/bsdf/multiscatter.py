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
compensation leaves on the closure (compensation.py, principled.py).

The tables E, E_avg and the dielectric F_ss are DRT's own, integrated from these kernels'
lobes (engine/bsdf/energy_tables.py); they come in `kernel_tables()`, and the lookups
here interpolate (bi/tri)linearly on uniform grids in rough = sqrt(alpha),
t = sqrt(cos theta_o) and z = F0^(1/4) of the relative IOR (see that module).
"""
from __future__ import annotations

import math

from ..jit import kernel
from . import fresnel
from . import microfacet as mf
from .albedo import lerp_coords
from .tables import (T_FRESNEL_AVG, T_FRESNEL_S, T_G_FRESNEL_Z, T_G_GLASS_ROUGH,
                     T_G_GLASS_T, T_G_GLASS_Z, T_G_ROUGH, T_G_T, T_GGX_E, T_GGX_E_AVG,
                     T_GLASS_E, T_GLASS_E_AVG)


@kernel
def t_coord(cos_o):
    return math.sqrt(min(max(cos_o, 0.0), 1.0))


@kernel
def side_z(eta):
    """(side, z) of relative IOR eta (engine/bsdf/energy_tables.py, `z_of_eta`)."""
    if eta < 1.0:
        e = 1.0 / eta
        side = 1
    else:
        e = eta
        side = 0
    return side, math.sqrt(abs(e - 1.0) / (e + 1.0))


@kernel
def ggx_albedo(cos_o, alpha, tables):
    """E(wo) of GGX reflection with F = 1 (single scattering)."""
    i, fi = lerp_coords(tables[T_G_ROUGH], math.sqrt(mf.clamp_alpha(alpha)))
    j, fj = lerp_coords(tables[T_G_T], t_coord(cos_o))
    table = tables[T_GGX_E]
    acc = 0.0
    for di in range(2):
        wi_ = fi if di else 1.0 - fi
        for dj in range(2):
            wj = fj if dj else 1.0 - fj
            acc = acc + wi_ * wj * table[i + di, j + dj]
    return acc


@kernel
def ggx_albedo_avg(alpha, tables):
    """E_avg of GGX reflection with F = 1."""
    i, fi = lerp_coords(tables[T_G_ROUGH], math.sqrt(mf.clamp_alpha(alpha)))
    table = tables[T_GGX_E_AVG]
    return (1.0 - fi) * table[i] + fi * table[i + 1]


@kernel
def glass_albedo(cos_o, alpha, eta, tables):
    """E(wo) of the rough dielectric interface of relative IOR eta, in flux terms."""
    return glass_grid_lookup(tables[T_GLASS_E], cos_o, alpha, eta, tables)


@kernel
def glass_grid_lookup(table, cos_o, alpha, eta, tables):
    """`table` [side, z, rough, t] on the glass grids, trilinearly interpolated."""
    s, z = side_z(eta)
    i, fi = lerp_coords(tables[T_G_GLASS_Z], z)
    j, fj = lerp_coords(tables[T_G_GLASS_ROUGH], math.sqrt(mf.clamp_alpha(alpha)))
    k, fk = lerp_coords(tables[T_G_GLASS_T], t_coord(cos_o))
    acc = 0.0
    for di in range(2):
        wi_ = fi if di else 1.0 - fi
        for dj in range(2):
            wj = fj if dj else 1.0 - fj
            for dk in range(2):
                wk = fk if dk else 1.0 - fk
                acc = acc + wi_ * wj * wk * table[s, i + di, j + dj, k + dk]
    return acc


@kernel
def glass_albedo_avg(alpha, eta, tables):
    """E_avg of the rough dielectric interface of relative IOR eta."""
    s, z = side_z(eta)
    i, fi = lerp_coords(tables[T_G_GLASS_Z], z)
    j, fj = lerp_coords(tables[T_G_GLASS_ROUGH], math.sqrt(mf.clamp_alpha(alpha)))
    table = tables[T_GLASS_E_AVG]
    acc = 0.0
    for di in range(2):
        wi_ = fi if di else 1.0 - fi
        for dj in range(2):
            wj = fj if dj else 1.0 - fj
            acc = acc + wi_ * wj * table[s, i + di, j + dj]
    return acc


@kernel
def dielectric_fresnel_avg(eta, tables):
    """F_ss of the exact dielectric Fresnel reflectance of relative IOR eta."""
    s, z = side_z(eta)
    i, fi = lerp_coords(tables[T_G_FRESNEL_Z], z)
    table = tables[T_FRESNEL_AVG]
    return (1.0 - fi) * table[s, i] + fi * table[s, i + 1]


@kernel
def layer_reflectance(cos_o, alpha, eta, tables):
    """Cycles' estimate of a dielectric GGX layer's reflectance at wo: F0 + (1 - F0) s."""
    f0 = fresnel.f0_from_ior(eta)
    return f0 + (1.0 - f0) * glass_grid_lookup(tables[T_FRESNEL_S], cos_o, alpha, eta, tables)


@kernel
def schlick_fresnel_avg(f0):
    """F_ss of Schlick's F0 + (1 - F0)(1 - mu)^5."""
    return f0 + (1.0 - f0) / 21.0


@kernel
def compensation(E, E_avg, F_ss):
    """1 + F_ms (1 - E) / E with F_ms = F_ss E_avg / (1 - F_ss (1 - E_avg))."""
    F_ms = F_ss * E_avg / (1.0 - F_ss * (1.0 - E_avg))
    return 1.0 + F_ms * ((1.0 - E) / E)
