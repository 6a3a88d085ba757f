"""Directional albedo of the Principled specular layer (GGX reflection with exact
dielectric Fresnel), looked up in the tables engine/bsdf/layer_albedo.py integrates, on
its coordinates, trilinearly. The tables reach the kernels in the tuple of
`tables.kernel_tables()`.
"""
from __future__ import annotations

import math

from ..jit import kernel
from . import microfacet as mf
from .tables import T_GRID_R, T_GRID_S, T_GRID_T, T_SIDE0, T_SIDE1, kernel_tables  # noqa: F401


@kernel
def critical_cos(eta):
    """cos of the critical angle for relative IOR eta < 1 (0 for eta >= 1)."""
    return math.sqrt(min(max(1.0 - eta * eta, 0.0), 1.0))


@kernel
def t_of_mu(mu, c):
    """Table coordinate t in [0, 1] of cos theta_o = mu for critical cosine c."""
    mu = min(max(mu, 0.0), 1.0)
    if c > 0.0:
        if mu <= c:
            return math.asin(math.sqrt(min(max(mu / c, 0.0), 1.0))) / math.pi
        return 0.5 + 0.5 * math.sqrt(min(max((mu - c) / max(1.0 - c, 1e-300), 0.0), 1.0))
    return math.sqrt(mu)


@kernel
def lerp_coords(grid, v):
    """(i0, f): the cell and the fraction of v on a uniform grid, v clamped to it."""
    n = grid.shape[0]
    f = (min(max(v, grid[0]), grid[n - 1]) - grid[0]) / (grid[1] - grid[0])
    i0 = min(int(f), n - 2)
    return i0, f - i0


@kernel
def specular_albedo(cos_o, alpha, eta, tables):
    """Directional albedo of GGX reflection with dielectric Fresnel of relative IOR eta
    (single scattering), interpolated trilinearly from the tables."""
    alpha = mf.clamp_alpha(alpha)
    if eta < 1.0:
        table = tables[T_SIDE1]
    else:
        table = tables[T_SIDE0]
    x = abs(eta - 1.0) / (eta + 1.0)
    i, fi = lerp_coords(tables[T_GRID_S], math.sqrt(x))
    j, fj = lerp_coords(tables[T_GRID_R], math.sqrt(alpha))
    k, fk = lerp_coords(tables[T_GRID_T], t_of_mu(cos_o, critical_cos(eta)))
    acc = 0.0
    for di in range(2):
        wi_ = fi if di else 1.0 - fi
        for dj in range(2):
            wj = fj if dj else 1.0 - fj
            for dk in range(2):
                wk = fk if dk else 1.0 - fk
                acc = acc + wi_ * wj * wk * table[i + di, j + dj, k + dk]
    return acc
