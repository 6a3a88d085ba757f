"""The compiled BSDF's lobes beyond Principled's base (engine/kernels/bsdf/layers.py):
coat, sheen (Principled's and the Sheen BSDF node's), translucency, and the Refraction
BSDF's refraction-only glass.

  * Sampling against the pdf (chi-square, tests/chi2.py) for each lobe alone and for a
    Principled material with every layer, at three view angles, with the kernels' own
    array drivers (kernels/bsdf/batch.py); a negative control (the sheen sampled at one
    roughness against the pdf of another) must fail.
  * Energy: the mean sample weight (f |cos| / pdf) equals the quadrature integral of
    f |cos| (sampling and evaluation agree), and stays <= 1 for white materials (a white
    coat over white diffuse, a white sheen, a white translucent leaf, white refraction).
  * Layering: coat and sheen dim the base by Cycles' factors (1 - weight E(wo), and the
    coat tint's Beer factor), checked on the state.
  * Cost (principle 3): a material without these lobes never reads or writes their state
    slots: NaNs left there change nothing.
"""
from __future__ import annotations

import numpy as np
import pytest

from chi2 import chi2_test
from engine.bsdf.material_table import MaterialTable
from engine.kernels import bsdf as kb
from engine.kernels.bsdf import batch, coat, layers, sheen
from engine.kernels.bsdf import principled as P
from engine.scene import Material

N = 200_000
ANGLES = (10.0, 50.0, 80.0)
ALL = (True, True, True)

MATERIALS = {
    "coat": dict(base_color=(0.0, 0.0, 0.0), specular_ior_level=0.0, coat_weight=1.0,
                 coat_roughness=0.3, coat_ior=1.5),
    "sheen_node": dict(base_color=(0.0, 0.0, 0.0), specular_ior_level=0.0, sheen_weight=1.0,
                       sheen_roughness=0.5, sheen_layered=False),
    "sheen_rough0.1": dict(base_color=(0.0, 0.0, 0.0), specular_ior_level=0.0,
                           sheen_weight=1.0, sheen_roughness=0.1, sheen_layered=False),
    "translucent": dict(base_color=(0.0, 0.0, 0.0), specular_ior_level=0.0,
                        translucent_color=(0.5, 0.7, 0.2)),
    "refraction_rough": dict(transmission=1.0, roughness=0.4, refraction_only=True,
                             base_color=(1.0, 1.0, 1.0)),
    "principled_all": dict(base_color=(0.7, 0.2, 0.1), roughness=0.4, metallic=0.3,
                           coat_weight=0.8, coat_roughness=0.2, coat_tint=(0.9, 0.6, 0.5),
                           sheen_weight=0.7, sheen_tint=(1.0, 0.9, 0.8),
                           translucent_color=(0.1, 0.2, 0.1), glossy_model="MULTI_GGX"),
}


def rows_of(params, n=1):
    row = kb.pack_materials(MaterialTable([Material(name="m", **params)]))
    return np.ascontiguousarray(np.tile(row, (n, 1)))


def wo_at(deg, n):
    t = np.radians(deg)
    return np.tile([np.sin(t), 0.0, np.cos(t)], (n, 1))


def sampler_pairs(params, wo, w, front=True):
    """1 where the sampler can produce w from wo, else 0: the kernels evaluate refraction
    as Cycles does, also at pairs whose generalised half vector h ~ wo + eta w (eta the
    IOR on w's side over wo's) is not a microfacet normal that refracts one into the
    other (wo.h > 0 > w.h fails; engine/kernels/bsdf/dielectric.py's note). Those pairs add light
    only through next-event estimation; sampling never produces them."""
    if not params.get("transmission"):
        return np.ones(len(w))
    ior = Material(name="m", **params).ior
    ior = ior if front else 1.0 / ior              # the IOR beyond wo's side (front: 1)
    eta = np.where(wo[:, 2] > 0, ior, 1.0 / ior)
    h = wo + eta[:, None] * w
    h *= np.where(h[:, 2] < 0, -1.0, 1.0)[:, None]
    refr = wo[:, 2] * w[:, 2] < 0
    ok = ((wo * h).sum(1) > 0) & ((w * h).sum(1) < 0)
    return np.where(refr & ~ok, 0.0, 1.0)


def case(name, deg, pdf_name=None):
    return case_of(MATERIALS[name], deg, MATERIALS[pdf_name or name])


def case_of(params, deg, pdf_params=None, front=True):
    """(sample, pdf) of the chi-square test for the material `params` seen from `deg`
    (front: from outside), the pdf that of `pdf_params` (default: the same)."""
    pdf_params = pdf_params or params
    tables = kb.kernel_tables()
    allowed = np.ones((1, 3), bool)

    def sample(u):
        n = len(u)
        wi, _, _, _, delta, valid = batch.sample_batch(
            rows_of(params, n), np.full(n, front), wo_at(deg, n), u[:, 0],
            np.ascontiguousarray(u[:, 1:]), np.repeat(allowed, n, 0), tables)
        assert not delta.any()
        return wi, valid

    def pdf(w):
        n = len(w)
        return batch.pdf_batch(rows_of(pdf_params, n), np.full(n, front), wo_at(deg, n),
                               np.ascontiguousarray(w), np.repeat(allowed, n, 0), tables
                               ) * sampler_pairs(pdf_params, wo_at(deg, n), w, front)
    return sample, pdf


CASES = [(f"{m}-{d:g}deg", m, d) for m in MATERIALS for d in ANGLES]
N_TESTS = len(CASES) + 1


@pytest.mark.parametrize("label,name,deg", CASES, ids=[c[0] for c in CASES])
def test_sampling_matches_pdf(label, name, deg):
    sample, pdf = case(name, deg)
    seed = sum(ord(ch) * (i + 1) for i, ch in enumerate(label))
    res = chi2_test(sample, pdf, N, seed=seed, n_tests=N_TESTS)
    print(f"{label}: {res}")
    assert res.passed, f"{label}: {res}"
    assert abs(res.pdf_integral - res.valid_fraction) < 0.01, str(res)


def test_negative_control_sheen_roughness():
    """Sheen samples at roughness 0.5 against the pdf at roughness 0.1 must fail."""
    sample, pdf = case("sheen_node", 50.0, pdf_name="sheen_rough0.1")
    res = chi2_test(sample, pdf, N, seed=5, n_tests=N_TESTS)
    print(f"negative control: {res}")
    assert not res.passed


# --- energy ------------------------------------------------------------------------------

def sphere_quadrature(n_mu=400, n_phi=400):
    """Midpoint nodes and weights over the whole sphere (d omega = d mu d phi)."""
    mu = -1.0 + (np.arange(2 * n_mu) + 0.5) / n_mu
    phi = (np.arange(n_phi) + 0.5) * (2.0 * np.pi / n_phi)
    M, F = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1.0 - M * M)
    w = np.stack([s * np.cos(F), s * np.sin(F), M], -1).reshape(-1, 3)
    return w, np.full(len(w), (1.0 / n_mu) * (2.0 * np.pi / n_phi))


def albedo_both_ways(params, deg, n=400_000, seed=1):
    """(mean sample weight (3,), quadrature of f |cos| (3,)) at view angle deg."""
    tables = kb.kernel_tables()
    rng = np.random.default_rng(seed)
    allowed = np.ones((n, 3), bool)
    _, weight, _, _, delta, valid = batch.sample_batch(
        rows_of(params, n), np.ones(n, bool), wo_at(deg, n), rng.random(n),
        rng.random((n, 2)), allowed, tables)
    mc = weight.mean(0)
    w, dw = sphere_quadrature()
    f = batch.eval_f_batch(rows_of(params, len(w)), np.ones(len(w), bool),
                           wo_at(deg, len(w)), w, tables)
    f = f * sampler_pairs(params, wo_at(deg, len(w)), w)[:, None]
    quad = (f * (np.abs(w[:, 2]) * dw)[:, None]).sum(0)
    return mc, quad, bool(delta.any())


@pytest.mark.parametrize("name,params", [
    ("white coat over white diffuse", dict(base_color=(1.0, 1.0, 1.0), specular_ior_level=0.0,
                                           coat_weight=1.0, coat_roughness=0.3)),
    ("white sheen", dict(base_color=(0.0, 0.0, 0.0), specular_ior_level=0.0,
                         sheen_weight=1.0, sheen_roughness=0.6, sheen_layered=False)),
    ("white translucent", dict(base_color=(0.0, 0.0, 0.0), specular_ior_level=0.0,
                               translucent_color=(1.0, 1.0, 1.0))),
    ("sheen over white diffuse", dict(base_color=(1.0, 1.0, 1.0), specular_ior_level=0.0,
                                      sheen_weight=1.0, sheen_roughness=0.3)),
    ("white rough refraction", dict(transmission=1.0, roughness=0.5, refraction_only=True,
                                    base_color=(1.0, 1.0, 1.0))),
])
def test_albedo_sampled_equals_integrated_and_at_most_one(name, params):
    for deg in ANGLES:
        mc, quad, delta = albedo_both_ways(params, deg)
        print(f"{name} at {deg:g} deg: sampled {mc.round(4)}, integrated {quad.round(4)}")
        assert not delta
        assert np.allclose(mc, quad, rtol=0.01, atol=2e-3), (mc, quad)
        # (refraction carries no radiance scaling, as in Cycles: at most 1 too)
        assert quad.max() <= 1.0 + 0.005


def test_smooth_refraction_only_refracts_with_weight_one():
    params = dict(transmission=1.0, roughness=0.0, refraction_only=True, base_color=(1.0,) * 3)
    n = 1000
    rng = np.random.default_rng(2)
    wi, weight, pdf, kind, delta, valid = batch.sample_batch(
        rows_of(params, n), np.ones(n, bool), wo_at(40.0, n), rng.random(n),
        rng.random((n, 2)), np.ones((n, 3), bool), kb.kernel_tables())
    assert valid.all() and delta.all() and (wi[:, 2] < 0).all()
    assert (kind == kb.TRANSMISSION).all()
    assert np.allclose(weight, 1.0)             # no Fresnel, no radiance scaling
    # from inside beyond the critical angle: total internal reflection, nothing sampled
    _, _, _, _, _, valid = batch.sample_batch(
        rows_of(params, n), np.zeros(n, bool), wo_at(60.0, n), rng.random(n),
        rng.random((n, 2)), np.ones((n, 3), bool), kb.kernel_tables())
    assert not valid.any()


# --- layering ----------------------------------------------------------------------------

def setup_state(params, deg, front=True):
    state = np.full(kb.NSTATE, np.nan)
    wo = wo_at(deg, 1)[0]
    P.setup(rows_of(params)[0], front, wo[0], wo[1], wo[2], kb.kernel_tables(), state)
    return state


def test_coat_and_sheen_dim_the_base_as_cycles_layers():
    base = dict(base_color=(0.8, 0.8, 0.8), roughness=0.5)
    deg = 60.0
    mu = np.cos(np.radians(deg))
    plain = setup_state(base, deg)
    tables = kb.kernel_tables()
    coated = setup_state(dict(base, coat_weight=0.7, coat_roughness=0.2, coat_ior=1.6,
                              coat_tint=(0.5, 1.0, 1.0)), deg)
    E = coat.layer_albedo(mu, 0.04, 1.6, tables)
    depth = 1.0 / np.sqrt(1.0 - (1.0 - mu * mu) / 1.6 ** 2)
    want = (1.0 - 0.7 * E) * np.array([1.0 + 0.7 * (0.5 ** depth - 1.0), 1.0, 1.0])
    assert 0.05 < E < 0.3
    assert np.allclose(coated[P.S_DIFFUSE:P.S_DIFFUSE + 3],
                       plain[P.S_DIFFUSE:P.S_DIFFUSE + 3] * want, rtol=1e-12)
    sheened = setup_state(dict(base, sheen_weight=0.5, sheen_tint=(1.0, 0.5, 0.5)), deg)
    a, b, R = sheen.lookup(mu, 0.5, tables)
    assert 0.0 < R < 1.0
    assert np.allclose(sheened[P.S_DIFFUSE:P.S_DIFFUSE + 3],
                       plain[P.S_DIFFUSE:P.S_DIFFUSE + 3] * (1.0 - 0.5 * R), rtol=1e-12)
    # the Sheen BSDF node's sheen sits beside the base: nothing dimmed
    beside = setup_state(dict(base, sheen_weight=0.5, sheen_layered=False), deg)
    assert np.array_equal(beside[P.S_DIFFUSE:P.S_DIFFUSE + 3],
                          plain[P.S_DIFFUSE:P.S_DIFFUSE + 3])


def test_plain_materials_never_touch_the_layer_slots():
    """Principle 3: a Principled material without coat, sheen, translucency or
    refraction-only glass has P_LAYERS 0, and its setup, eval, pdf and sampling neither
    write nor read the layers' slots (NaN there changes nothing)."""
    tables = kb.kernel_tables()
    rng = np.random.default_rng(4)
    for params in (dict(), dict(metallic=1.0, roughness=0.3), dict(transmission=1.0),
                   dict(base_color=(0.2, 0.5, 0.9), roughness=0.7, glossy_model="MULTI_GGX")):
        row = rows_of(params)[0]
        assert row[kb.params.P_LAYERS] == 0.0
        nan_state = np.full(kb.NSTATE, np.nan)
        zero_state = np.zeros(kb.NSTATE)
        for state in (nan_state, zero_state):
            P.setup(row, True, 0.3, 0.2, np.sqrt(1 - 0.13), tables, state)
        assert np.isnan(nan_state[layers.S_FIRST:layers.NSTATE]).all()   # the layers' slots
        for _ in range(200):
            wo = np.array([0.3, 0.2, np.sqrt(1 - 0.13)])
            wi = rng.normal(size=3)
            wi /= np.linalg.norm(wi)
            u = rng.random(3)
            for fn, args in ((P.eval_f, (*wo, *wi)), (P.pdf, (*wo, *wi, True, True, True)),
                             (P.sample, (*wo, *u, True, True, True))):
                a, b = fn(nan_state, *args), fn(zero_state, *args)
                assert np.array_equal(np.asarray(a, float), np.asarray(b, float))
                assert np.all(np.isfinite(np.atleast_1d(np.asarray(a, float))[:7]))


def test_stored_specular_albedo_tables_are_what_the_build_computes(tmp_path, monkeypatch):
    """engine/bsdf/data/specular_albedo.npz holds exactly what the quadrature builds (so
    loading it instead of building, a second saved per process, changes nothing), and a
    file made on other grids is ignored."""
    from engine.bsdf import layer_albedo as la
    stored = la._stored()
    assert stored is not None, "the tables file is missing or on other grids"
    for side in (0, 1):
        assert np.array_equal(stored[side], la._build_specular_albedo_table(side)), side
    other = tmp_path / "other.npz"
    np.savez(other, side0=stored[0], side1=stored[1], **{**la._grids(), "strata": [8]})
    monkeypatch.setattr(la, "PATH", str(other))
    assert la._stored() is None
