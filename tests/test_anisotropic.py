"""Anisotropic reflection (engine/kernels/bsdf/anisotropic.py) against oracles that share
none of its code: the normalisation of D and its projected area (quadrature), sampling
against the pdf (chi-square, tests/chi2.py), sampled against integrated albedo,
reciprocity, the closed-form symmetry of Glossy's mapping (Anisotropy a along the
tangent is -a across it), and finite values at the extremes. Cycles comparisons:
test_anisotropic_vs_cycles.py."""
from __future__ import annotations

import math

import numpy as np
import pytest

from chi2 import chi2_test
from engine.bsdf.material_table import MaterialTable
from engine.kernels import bsdf as kb
from engine.kernels.bsdf import anisotropic as an
from engine.kernels.bsdf import batch
from engine.kernels.bsdf import beckmann as bk
from engine.kernels.bsdf import microfacet as mf
from engine.kernels.bsdf.params import P_TANGENT
from engine.scene import Material
from test_beckmann import hemisphere_quadrature
from test_layered_bsdf import sphere_quadrature, wo_at

N = 200_000


def metal(r, a, kind="PRINCIPLED", model="GGX", rot=0.0, **kw):
    return dict(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=r, glossy_model=model,
                anisotropy_kind=kind, anisotropy=a, anisotropic_rotation=rot, **kw)


def plastic(r, a, rot=0.0):
    return dict(base_color=(0.2, 0.4, 0.8), roughness=r, glossy_model="MULTI_GGX",
                anisotropy_kind="PRINCIPLED", anisotropy=a, anisotropic_rotation=rot)


def rows_of(params, n, tangent=(1.0, 0.0, 0.0)):
    """n material rows with the per-hit tangent (local to the shading frame) set."""
    row = kb.pack_materials(MaterialTable([Material(name="m", **params)]))
    rows = np.ascontiguousarray(np.tile(row, (n, 1)))
    rows[:, P_TANGENT:P_TANGENT + 3] = tangent
    return rows


def wo_az(deg, az, n):
    t, f = np.radians(deg), np.radians(az)
    return np.tile([np.sin(t) * np.cos(f), np.sin(t) * np.sin(f), np.cos(t)], (n, 1))


def case(params, deg, az=30.0, tangent=(1.0, 0.0, 0.0), pdf_params=None):
    pdf_params = pdf_params or params
    tables = kb.kernel_tables()
    every = np.ones((1, 3), bool)

    def sample(u):
        n = len(u)
        wi, _, _, _, delta, valid = batch.sample_batch(
            rows_of(params, n, tangent), np.ones(n, bool), wo_az(deg, az, n), u[:, 0],
            np.ascontiguousarray(u[:, 1:]), np.repeat(every, n, 0), tables)
        assert not delta.any()
        return wi, valid

    def pdf(w):
        n = len(w)
        return batch.pdf_batch(rows_of(pdf_params, n, tangent), np.ones(n, bool),
                               wo_az(deg, az, n), np.ascontiguousarray(w),
                               np.repeat(every, n, 0), tables)
    return sample, pdf


# --- the distribution against quadrature ---------------------------------------------------

@pytest.mark.parametrize("beckmann", [False, True], ids=["GGX", "Beckmann"])
@pytest.mark.parametrize("ax,ay", [(0.3, 0.05), (0.8, 0.2), (0.15, 0.6)])
def test_D_is_normalised_and_its_projected_area_is_one_over_G1(ax, ay, beckmann):
    h, dw = hemisphere_quadrature(800)
    d = np.array([an.D(x, y, z, ax, ay, beckmann) for x, y, z in h])
    assert abs((d * h[:, 2] * dw).sum() - 1.0) < 2e-3
    for deg, az in ((0.0, 0.0), (40.0, 0.0), (40.0, 90.0), (70.0, 35.0), (85.0, 120.0)):
        wo = wo_az(deg, az, 1)[0]
        projected = (d * np.maximum(h @ wo, 0.0) * dw).sum()
        # G1 = cos / projected area (Smith), from the stretch-invariant Lambda
        expected = 1.0 / an.G1_over_cos(wo[0], wo[1], wo[2], ax, ay, beckmann)
        assert abs(projected / expected - 1.0) < 3e-3, (deg, az, projected, expected)


@pytest.mark.parametrize("beckmann", [False, True], ids=["GGX", "Beckmann"])
def test_equal_alphas_are_the_isotropic_lobe(beckmann):
    rng = np.random.default_rng(2)
    worst = 0.0
    for _ in range(300):
        a = float(rng.uniform(0.01, 1.0))
        o = rng.normal(size=3)
        i = rng.normal(size=3)
        o[2], i[2] = abs(o[2]), abs(i[2])
        o, i = o / np.linalg.norm(o), i / np.linalg.norm(i)
        ours = an.reflection_eval(*o, *i, a, a, beckmann)[0]
        if beckmann:
            hx, hy, hz, _ = mf.half_vector(*o, *i)
            iso = bk.reflection_eval(*o, *i, hx, hy, hz, a)
            p_iso = bk.reflection_pdf(*o, hx, hy, hz, a)
        else:
            iso = mf.reflection_eval(*o, *i, a)[0]
            p_iso = mf.reflection_pdf(*o, *i, a)
        p = an.reflection_pdf(*o, *i, a, a, beckmann)
        worst = max(worst, abs(ours - iso) / max(iso, 1e-300),
                    abs(p - p_iso) / max(p_iso, 1e-300))
    assert worst < 1e-9, worst


# --- sampling against the pdf --------------------------------------------------------------

CASES = {
    "metal-ggx-0.8": (metal(0.4, 0.8), 50.0, (1.0, 0.0, 0.0)),
    "metal-ggx-1-rotated": (metal(0.5, 1.0, rot=0.125), 30.0, (0.6, 0.8, 0.0)),
    "metal-ggx-tilted-tangent": (metal(0.3, 0.7), 70.0, (0.6, 0.0, 0.8)),
    "metal-beckmann-glossy--0.6": (metal(0.5, -0.6, kind="GLOSSY", model="BECKMANN"), 45.0,
                                   (0.0, 1.0, 0.0)),
    "metal-multiscatter-rough": (metal(0.9, 0.9, model="MULTI_GGX"), 60.0, (1.0, 0.0, 0.0)),
    "plastic-0.9": (plastic(0.35, 0.9, rot=0.3), 40.0, (0.8, -0.6, 0.0)),
}
N_TESTS = len(CASES) + 1


@pytest.mark.parametrize("name", list(CASES))
def test_sampling_matches_pdf(name):
    params, deg, tangent = CASES[name]
    sample, pdf = case(params, deg, tangent=tangent)
    res = chi2_test(sample, pdf, N, seed=sum(map(ord, name)), n_tests=N_TESTS)
    print(f"{name}: {res}")
    assert res.passed, f"{name}: {res}"
    assert abs(res.pdf_integral - res.valid_fraction) < 0.01, str(res)


def test_negative_control_isotropic_pdf_fails_anisotropic_samples():
    params = metal(0.4, 0.8)
    sample, pdf = case(params, 50.0, pdf_params=metal(0.4, 0.0))
    res = chi2_test(sample, pdf, N, seed=7, n_tests=N_TESTS)
    print(f"negative control: {res}")
    assert not res.passed


# --- energy, reciprocity, symmetry ---------------------------------------------------------

def albedo_both_ways(params, deg, az, tangent, n=400_000, seed=1):
    tables = kb.kernel_tables()
    rng = np.random.default_rng(seed)
    every = np.ones((n, 3), bool)
    _, weight, _, _, _, _ = batch.sample_batch(
        rows_of(params, n, tangent), np.ones(n, bool), wo_az(deg, az, n), rng.random(n),
        rng.random((n, 2)), every, tables)
    w, dw = sphere_quadrature(600, 600)
    f = batch.eval_f_batch(rows_of(params, len(w), tangent), np.ones(len(w), bool),
                           wo_az(deg, az, len(w)), w, tables)
    return weight.mean(0), (f * (np.abs(w[:, 2]) * dw)[:, None]).sum(0)


@pytest.mark.parametrize("name", ["metal-ggx-0.8", "metal-beckmann-glossy--0.6",
                                  "plastic-0.9"])
def test_sampled_albedo_equals_integrated(name):
    params, deg, tangent = CASES[name]
    mc, quad = albedo_both_ways(params, deg, 30.0, tangent)
    print(f"{name}: sampled {mc.round(4)}, integrated {quad.round(4)}")
    assert np.allclose(mc, quad, rtol=0.01, atol=2e-3), (mc, quad)
    assert (quad < 1.0).all()


def test_multiscatter_compensates_as_the_isotropic_lobe_of_the_mean_alpha():
    """Cycles' compensation takes the isotropic alpha sqrt(alpha_x alpha_y) (its
    microfacet_ggx_preserve_energy): a white anisotropic multiscatter metal gains the
    factor the isotropic one of that alpha gains, so it stays below 1 where one alpha is
    large (here alpha_x is clamped to 1: single scattering keeps 0.56, compensated 0.77)."""
    white = dict(base_color=(1.0, 1.0, 1.0))
    params = metal(0.8, 1.0, model="MULTI_GGX", **{})
    params.update(white)
    ax, ay = an.alphas(1, 1.0, 0.8)
    assert ax == 1.0 and ay == pytest.approx(0.64 * math.sqrt(0.1))
    r_mean = (ax * ay) ** 0.25
    tangent = (1.0, 0.0, 0.0)
    _, ms = albedo_both_ways(params, 40.0, 30.0, tangent)
    _, ss = albedo_both_ways(dict(params, glossy_model="GGX"), 40.0, 30.0, tangent)
    iso = dict(params, anisotropy=0.0, roughness=r_mean)
    _, iso_ms = albedo_both_ways(iso, 40.0, 30.0, tangent)
    _, iso_ss = albedo_both_ways(dict(iso, glossy_model="GGX"), 40.0, 30.0, tangent)
    print(f"anisotropic {ss[0]:.4f} -> {ms[0]:.4f}; isotropic r {r_mean:.4f}: "
          f"{iso_ss[0]:.4f} -> {iso_ms[0]:.4f}")
    assert ms[0] / ss[0] == pytest.approx(iso_ms[0] / iso_ss[0], rel=2e-3)
    assert ss[0] < 0.6 < 0.75 < ms[0] < 0.8


def upper_pairs(n, seed):
    """n random pairs (wo, wi) of unit directions above the surface."""
    rng = np.random.default_rng(seed)
    w = rng.normal(size=(2, n, 3))
    w[..., 2] = np.abs(w[..., 2])
    w /= np.linalg.norm(w, axis=2)[..., None]
    return np.ascontiguousarray(w[0]), np.ascontiguousarray(w[1])


def test_reciprocity():
    n = 2000
    wo, wi = upper_pairs(n, 4)
    tables = kb.kernel_tables()
    for params in (metal(0.3, 0.9, rot=0.2), metal(0.6, 0.5, kind="GLOSSY", model="BECKMANN")):
        rows = rows_of(params, n, (0.6, 0.8, 0.0))
        a = batch.eval_f_batch(rows, np.ones(n, bool), wo, wi, tables)
        b = batch.eval_f_batch(rows, np.ones(n, bool), wi, wo, tables)
        assert np.allclose(a, b, rtol=1e-9, atol=1e-12)


def test_glossy_anisotropy_across_the_tangent_is_minus_along_it():
    """Glossy's mapping: Anisotropy a with the tangent along X is Anisotropy -a with the
    tangent turned a quarter (its alphas swap), to rounding."""
    n = 3000
    wo, wi = upper_pairs(n, 5)
    tables = kb.kernel_tables()
    a = batch.eval_f_batch(rows_of(metal(0.5, 0.5, kind="GLOSSY"), n), np.ones(n, bool), wo,
                           wi, tables)
    b = batch.eval_f_batch(rows_of(metal(0.5, -0.5, kind="GLOSSY", rot=0.25), n),
                           np.ones(n, bool), wo, wi, tables)
    c = batch.eval_f_batch(rows_of(metal(0.5, -0.5, kind="GLOSSY"), n), np.ones(n, bool), wo,
                           wi, tables)
    assert np.allclose(a, b, rtol=1e-9, atol=1e-12)
    assert not np.allclose(a, c, rtol=0.05)          # the turn is what makes them equal


def test_lobe_is_wider_along_the_tangent():
    """Principled: alpha_x = r^2 / aspect > alpha_y along the tangent, so a highlight
    seen from the normal spreads along it."""
    tables = kb.kernel_tables()
    n = 100_000
    rng = np.random.default_rng(6)
    for tangent, axis in (((1.0, 0.0, 0.0), 0), ((0.0, 1.0, 0.0), 1)):
        wi, _, _, _, _, valid = batch.sample_batch(
            rows_of(metal(0.4, 0.9), n, tangent), np.ones(n, bool), wo_at(0.0, n),
            rng.random(n), rng.random((n, 2)), np.ones((n, 3), bool), tables)
        spread = (wi[valid, :2] ** 2).mean(0)
        assert spread[axis] > 4.0 * spread[1 - axis], spread


# --- extremes ------------------------------------------------------------------------------

@pytest.mark.parametrize("params,tangent", [
    (metal(0.0, 1.0), (1.0, 0.0, 0.0)), (metal(1.0, 1.0), (1.0, 0.0, 0.0)),
    (metal(0.5, 0.99, kind="GLOSSY"), (0.0, 1.0, 0.0)),
    (metal(0.5, 1.0), (0.0, 0.0, 1.0)),            # along the normal: isotropic
    (metal(0.5, 1.0), (math.nan, 0.0, 0.0)),        # no tangent: isotropic
    (metal(0.02, 1.0, model="BECKMANN"), (1.0, 0.0, 0.0)),
    (plastic(1.0, 1.0), (1e-300, 1e-300, 0.0))])
def test_extremes_stay_finite(params, tangent):
    tables = kb.kernel_tables()
    rng = np.random.default_rng(3)
    n = 4000
    cos_o = np.concatenate([[1.0, 1e-12, 0.0, 1e-300], rng.random(n - 4) ** 4])
    phi = rng.random(n) * 2 * np.pi
    s = np.sqrt(1.0 - cos_o ** 2)
    wo = np.stack([s * np.cos(phi), s * np.sin(phi), cos_o], 1)
    rows = rows_of(params, n, tangent)
    every = np.ones((n, 3), bool)
    wi, weight, pdf, _, _, valid = batch.sample_batch(
        rows, np.ones(n, bool), wo, rng.random(n), rng.random((n, 2)), every, tables)
    assert np.isfinite(wi).all() and np.isfinite(weight).all() and np.isfinite(pdf).all()
    f = batch.eval_f_batch(rows, np.ones(n, bool), wo, wi, tables)
    p = batch.pdf_batch(rows, np.ones(n, bool), wo, wi, every, tables)
    assert np.isfinite(f).all() and np.isfinite(p).all()
    assert (weight[valid] >= 0).all()


# --- the tangent the program computes (engine.nodes.input_nodes.tangent) ----------------

def _object(matrix):
    from engine.nodes.context import object_rows
    return object_rows(np.asarray(matrix, float).reshape(1, 4, 4), [(1.0, 1.0, 1.0)], [0.0],
                       [0], (0.0, 0.0, 0.0), (1.0, 1.0, 1.0))


def _cycles_tangent(data_object, matrix, n):
    """Cycles' svm_node_tangent after the attribute: object_normal_transform (the inverse
    transpose, normalised), then cross(N, normalize(cross(T, N)))."""
    t = np.linalg.inv(np.asarray(matrix, float)[:3, :3]).T @ np.asarray(data_object, float)
    t /= np.linalg.norm(t)
    c = np.cross(t, n)
    c /= np.linalg.norm(c)
    return np.cross(n, c)


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_radial_tangent_is_cycles_about_each_axis(axis):
    from engine.nodes import input_nodes as I
    from engine.nodes.context import hit_rows
    rng = np.random.default_rng(8)
    matrix = np.diag([2.0, 0.5, 1.5, 1.0])
    matrix[:3, :3] = matrix[:3, :3] @ np.array([[0.8, -0.6, 0.0], [0.6, 0.8, 0.0],
                                                [0.0, 0.0, 1.0]])
    matrix[:3, 3] = (0.3, -1.0, 2.0)
    for _ in range(20):
        p_obj = rng.uniform(-1.0, 1.0, 3)
        p = matrix[:3, :3] @ p_obj + matrix[:3, 3]
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        hit = hit_rows(p[None], n[None], objects=_object(matrix), obj=[0])[0]
        g = p_obj * 0.5 + 0.5        # generated: the unit texture space centred on 0
        from engine.nodes.context import H_GENERATED
        assert np.allclose(hit[H_GENERATED:H_GENERATED + 3], g)
        gx, gy, gz = g - 0.5
        data = [(0.0, -gz, gy), (-gz, 0.0, gx), (-gy, gx, 0.0)][axis]
        ours = np.array(I.tangent(hit, I.TANGENT_RADIAL, axis))
        assert np.allclose(ours, _cycles_tangent(data, matrix, n), atol=1e-12)
        assert abs(ours @ n) < 1e-12


def test_uv_tangent_and_its_absence():
    from engine.nodes import input_nodes as I
    from engine.nodes.context import hit_rows
    n = np.array([0.0, 0.6, 0.8])
    matrix = np.diag([1.0, 3.0, 1.0, 1.0])
    hit = hit_rows(np.zeros((1, 3)), n[None], objects=_object(matrix), obj=[0],
                   tangent=[(1.0, 1.0, 0.0, -1.0)])[0]
    ours = np.array(I.tangent(hit, I.TANGENT_UV_MAP, 0))
    assert np.allclose(ours, _cycles_tangent((1.0, 1.0, 0.0), matrix, n), atol=1e-12)
    bare = hit_rows(np.zeros((1, 3)), n[None])[0]           # a mesh without tangents
    assert I.tangent(bare, I.TANGENT_UV_MAP, 0) == (0.0, 0.0, 0.0)
