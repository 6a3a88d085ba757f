"""Array drivers of the texture kernels (compiled loops over rows), for the tests: the
same results as `Texture.lookup` and `MaterialTable.lookup` / `emission_at` / `alpha_at`
on arrays. Outputs are freshly allocated arrays."""
from __future__ import annotations

import numpy as np

from .jit import kernel
from .textures import (COLOR_PARAMS, PARAM_NAMES, PLAIN, alpha_at, apply_to_row,
                       emission_at, is_textured, texture_rgba, textured_value)


def _uv(uv, n):
    if uv is None:                     # no UV map: read as (0, 0), like MaterialTable
        return np.zeros((n, 2))
    return np.ascontiguousarray(np.asarray(uv, np.float64).reshape(n, 2))


def _index(material_index):
    return np.ascontiguousarray(np.asarray(material_index, np.int64).reshape(-1))


def param_id(name_or_param_id) -> int:
    """A TEX_* id from a `MaterialTable.PARAMS` name or an id."""
    if isinstance(name_or_param_id, str):
        return PARAM_NAMES.index(name_or_param_id)
    p = int(name_or_param_id)
    if not 0 <= p < len(PARAM_NAMES):
        raise ValueError(f"parameter id must be in [0, {len(PARAM_NAMES)}), got {p}")
    return p


@kernel
def _rgba_loop(T, tex_id, uv):
    n = uv.shape[0]
    out = np.empty((n, 4))
    for i in range(n):
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = texture_rgba(T, tex_id, uv[i, 0],
                                                                  uv[i, 1])
    return out


@kernel
def _lookup_loop(T, param, index, uv):
    n = index.shape[0]
    out = np.empty((n, 3))
    plain = T[PLAIN]
    for i in range(n):
        m = index[i]
        if is_textured(T, m, param):
            out[i, 0], out[i, 1], out[i, 2] = textured_value(T, m, param, uv[i, 0], uv[i, 1])
        else:
            out[i, 0], out[i, 1], out[i, 2] = plain[m, param, 0], plain[m, param, 1], \
                plain[m, param, 2]
    return out


@kernel
def _emission_loop(T, emission_table, index, uv):
    n = index.shape[0]
    out = np.empty((n, 3))
    for i in range(n):
        out[i, 0], out[i, 1], out[i, 2] = emission_at(T, emission_table, index[i],
                                                      uv[i, 0], uv[i, 1])
    return out


@kernel
def _alpha_loop(T, alpha_table, index, uv):
    n = index.shape[0]
    out = np.empty(n)
    for i in range(n):
        out[i] = alpha_at(T, alpha_table, index[i], uv[i, 0], uv[i, 1])
    return out


@kernel
def _rows_loop(T, index, uv, rows, p_base, p_metallic, p_roughness):
    for i in range(index.shape[0]):
        apply_to_row(T, index[i], uv[i, 0], uv[i, 1], rows[i], p_base, p_metallic,
                     p_roughness)


def rgba_batch(T, tex_id, uv) -> np.ndarray:
    """`Texture.lookup` of texture `tex_id` at uv (n, 2): (n, 4)."""
    uv = np.asarray(uv, np.float64).reshape(-1, 2)
    return _rgba_loop(T, int(tex_id), _uv(uv, len(uv)))


def lookup_batch(T, name_or_param_id, material_index, uv=None) -> np.ndarray:
    """`MaterialTable.lookup(name, material_index, uv)`: (n, 3) for colour parameters,
    (n,) for scalar ones (unclipped alpha, like `lookup`)."""
    p = param_id(name_or_param_id)
    index = _index(material_index)
    out = _lookup_loop(T, p, index, _uv(uv, len(index)))
    return out if p in COLOR_PARAMS else out[:, 0].copy()


def emission_at_batch(T, emission_table, material_index, uv=None) -> np.ndarray:
    """`MaterialTable.emission_at`: (n, 3)."""
    index = _index(material_index)
    return _emission_loop(T, np.ascontiguousarray(emission_table, np.float64), index,
                          _uv(uv, len(index)))


def alpha_at_batch(T, alpha_table, material_index, uv=None) -> np.ndarray:
    """`MaterialTable.alpha_at`: (n,) in [0, 1]."""
    index = _index(material_index)
    return _alpha_loop(T, np.ascontiguousarray(alpha_table, np.float64), index,
                       _uv(uv, len(index)))


def apply_to_rows_batch(T, material_index, uv, rows, p_base, p_metallic, p_roughness):
    """`apply_to_row` on a copy of rows (n, k) float64, row i for hit i; returns it."""
    index = _index(material_index)
    rows = np.array(rows, dtype=np.float64, order="C")
    _rows_loop(T, index, _uv(uv, len(index)), rows, int(p_base), int(p_metallic),
               int(p_roughness))
    return rows
