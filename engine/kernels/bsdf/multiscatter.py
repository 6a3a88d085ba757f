"""Multiple-scattering energy compensation of the GGX lobes (Cycles' "Multiscatter GGX"),
scalar: the compiled twin of engine/bsdf/multiscatter.py (see there for what Cycles does
and the sources). Same coordinates, same interpolation order and the same formula, so the
factors agree with NumPy's to the bit; the tables come in `kernel_tables()`.
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
