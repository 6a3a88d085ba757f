"""The lookup tables of the compiled BSDF, handed to the kernels as one tuple,
`kernel_tables()`, built on first use and then shared (C-contiguous float64 arrays):

  T_SIDE0, T_SIDE1   specular-layer albedo for eta >= 1 and eta < 1, indexed
                     [F0^(1/4), roughness, t] (engine/bsdf/layer_albedo.py), on the
  T_GRID_S, T_GRID_R, T_GRID_T   grids of F0^(1/4), roughness and t;
  T_GGX_E, T_GGX_E_AVG, T_GLASS_E, T_GLASS_E_AVG, T_FRESNEL_AVG, T_FRESNEL_S
                     the multiple-scattering and layering tables (engine/bsdf/
                     energy_tables.py), on the
  T_G_ROUGH, T_G_T, T_G_GLASS_ROUGH, T_G_GLASS_T, T_G_GLASS_Z, T_G_FRESNEL_Z   grids;
  T_SHEEN            the microfiber sheen's table (3, 32, 32): LTC a, b and albedo R over
                     [roughness, cos theta_o] (engine/bsdf/sheen_table.py).
"""
from __future__ import annotations

import threading

import numpy as np

T_SIDE0, T_SIDE1, T_GRID_S, T_GRID_R, T_GRID_T = 0, 1, 2, 3, 4
T_GGX_E, T_GGX_E_AVG, T_GLASS_E, T_GLASS_E_AVG, T_FRESNEL_AVG = 5, 6, 7, 8, 9
T_G_ROUGH, T_G_T, T_G_GLASS_ROUGH, T_G_GLASS_T, T_G_GLASS_Z, T_G_FRESNEL_Z = (
    10, 11, 12, 13, 14, 15)
T_FRESNEL_S = 16
T_SHEEN = 17

_lock = threading.Lock()
_tables = None


def kernel_tables() -> tuple:
    """Every table and grid of the module docstring, in that order."""
    global _tables
    if _tables is None:
        from ...bsdf import energy_tables as et
        from ...bsdf import layer_albedo as la
        from ...bsdf import sheen_table
        with _lock:
            if _tables is None:
                def arr(a):
                    return np.ascontiguousarray(a, dtype=np.float64)
                e = et.load()
                _tables = (arr(la.get_table(0)), arr(la.get_table(1)),
                           arr(la.TABLE_S), arr(la.TABLE_R), arr(la.TABLE_T),
                           e["ggx_E"], e["ggx_E_avg"], e["glass_E"], e["glass_E_avg"],
                           e["fresnel_avg"], e["grid_rough"], e["grid_t"],
                           e["grid_glass_rough"], e["grid_glass_t"], e["grid_glass_z"],
                           e["grid_fresnel_z"], e["fresnel_s"], sheen_table.load())
    return _tables
