"""A Principled emission under its coat and sheen (engine/kernels/bsdf/layered_emission.py),
without Blender: the factors' closed forms at normal incidence and their order, the
interpolation between the tabulated cosines, and that a scene without a dimmed
emitter carries nothing for it (principle 3). tests/test_layered_emission_vs_cycles.py
compares whole renders with Cycles."""
from __future__ import annotations

import numpy as np
import pytest

from engine.bsdf.material_table import MaterialTable
from engine.kernels import bsdf as kb
from engine.kernels.bsdf import layered_emission as le
from engine.kernels.bsdf.params import P_EMISSION_DIM
from engine.kernels.lights.pack import EMIT_DIM, TRI_DIM, _dimming
from engine.scene import Material

EMITS = dict(base_color=(0.1, 0.1, 0.1), emission=(3.0, 1.8, 0.9))


def params_of(*materials):
    return kb.pack_materials(MaterialTable([Material(name=f"m{i}", **m)
                                            for i, m in enumerate(materials)]))


def rows_of(**m):
    return le.dimming_rows(params_of(dict(EMITS, **m)), kb.kernel_tables())[0]


def test_only_emitters_under_a_coat_or_principled_sheen_are_dimmed():
    params = params_of(EMITS,                                             # no layer
                       dict(EMITS, coat_weight=1.0),                      # dimmed: 0
                       dict(coat_weight=1.0),                             # no emission
                       dict(EMITS, coat_weight=1.0, emission_under_layers=False),
                       dict(EMITS, sheen_weight=1.0, sheen_layered=False),  # Sheen node
                       dict(EMITS, sheen_weight=1.0))                     # dimmed: 1
    assert params[:, P_EMISSION_DIM].tolist() == [-1, 0, -1, -1, -1, 1]
    assert le.dimming_rows(params, kb.kernel_tables()).shape == (2, 2, le.N_COS, 3)


def test_a_scene_without_dimmed_emitters_carries_empty_tables():
    params = params_of(EMITS, dict(coat_weight=1.0))
    rows = le.dimming_rows(params, kb.kernel_tables())
    assert rows.shape == (0, 2, le.N_COS, 3)
    tri_dim, emit_dim = _dimming((params[[0, 0, 1], P_EMISSION_DIM], rows),
                                 np.array([0, 1]))
    assert tri_dim.shape == (0,) and emit_dim.shape == (0, 2, le.N_COS, 3)
    assert TRI_DIM != EMIT_DIM


def test_smooth_coat_at_normal_incidence_leaves_one_minus_f0():
    """A clear coat (roughness 0, IOR 1.5, weight 1) seen head-on dims by its Fresnel
    reflectance F0 = ((n - 1) / (n + 1))^2 = 0.04 and has nothing to tint."""
    rows = rows_of(coat_weight=1.0, coat_roughness=0.0, coat_ior=1.5)
    assert rows[le.LAYERS, -1] == pytest.approx([0.96] * 3, abs=2e-3)
    assert rows[le.TINT].tolist() == np.ones((le.N_COS, 3)).tolist()


@pytest.mark.parametrize("weight", [1.0, 0.4])
def test_tint_at_normal_incidence_is_the_tint_mixed_by_weight(weight):
    """Head-on the path through the coat is its unit thickness: mix(1, tint, weight)."""
    tint = np.array([0.5, 0.8, 1.0])
    rows = rows_of(coat_weight=weight, coat_ior=1.8, coat_tint=tuple(tint))
    assert rows[le.TINT, -1] == pytest.approx(1.0 + weight * (tint - 1.0), rel=1e-12)


def test_tint_deepens_and_layers_dim_towards_grazing():
    rows = rows_of(coat_weight=1.0, coat_ior=1.5, coat_tint=(0.5, 0.8, 1.0),
                   sheen_weight=1.0, sheen_roughness=0.3)
    layers, tint = rows[le.LAYERS], rows[le.TINT]
    assert np.all(layers <= tint + 1e-12) and np.all(layers >= 0.0)
    assert np.all(np.diff(tint[:, 0]) >= 0.0)         # longer paths at grazing angles
    assert tint[:, 2].tolist() == [1.0] * le.N_COS     # an untinted channel
    assert np.all(layers[0] < 0.05 * layers[-1])      # edge-on, the layers reflect all


def test_dimmed_interpolates_between_tabulated_cosines():
    rows = rows_of(coat_weight=1.0, coat_tint=(0.3, 0.6, 0.9), sheen_weight=0.5)[None]
    step = 1.0 / (le.N_COS - 1)
    for which in (le.LAYERS, le.TINT):
        for i in (0, 7, le.N_COS - 2):
            mid = le.dimmed(rows, 0, which, -(i + 0.25) * step, 1.0, 2.0, 4.0)
            want = (0.75 * rows[0, which, i] + 0.25 * rows[0, which, i + 1]) * [1, 2, 4]
            assert mid == pytest.approx(tuple(want), rel=1e-12)
        assert le.dimmed(rows, 0, which, 1.5, 1.0, 1.0, 1.0) == \
            pytest.approx(tuple(rows[0, which, -1]), rel=1e-12)
        assert np.isfinite(le.dimmed(rows, 0, which, np.nan, 1.0, 1.0, 1.0)).all()
