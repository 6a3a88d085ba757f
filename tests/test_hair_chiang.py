"""The Principled Hair BSDF's Chiang model (engine/kernels/bsdf/hair_chiang.py) against
closed forms written here from the paper's and Cycles' definitions
(bsdf_principled_hair_chiang.h), sharing no code with the kernel: the sampler against
the density (chi-square), evaluation against that density and value, energy (a fibre
that absorbs nothing returns all light: the four lobes' attenuations sum to 1 and each
lobe is a density), the node's colour parametrisations, h from the geometry, extremes.
The whole node against Cycles: tests/test_principled_hair_vs_cycles.py."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import special

from chi2 import chi2_test
from engine.bsdf.material_table import MaterialTable
from engine.kernels.bsdf import batch
from engine.kernels.bsdf import hair_chiang as H
from engine.kernels.bsdf import params as R
from engine.principled_hair import PrincipledHair
from engine.scene import Material

T = np.array([0.3, 0.9, 0.2]) / np.linalg.norm([0.3, 0.9, 0.2])   # in the shading frame
LUM = np.array([0.2126729, 0.7151522, 0.0721750])
TABLES = batch.P.kernel_tables()
N = 200_000


# ----------------------------------------------------------------- the model, in NumPy
def fit_v(r):
    return (0.726 * r + 0.812 * r ** 2 + 3.7 * r ** 20) ** 2


def fit_s(r):
    return (0.265 * r + 1.194 * r ** 2 + 5.372 * r ** 22) * math.sqrt(math.pi / 8)


def fresnel(c, eta):
    c = abs(c)
    g2 = eta * eta - 1 + c * c
    if g2 <= 0:
        return 1.0
    g = math.sqrt(g2)
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1) / (c * (g - c) + 1)
    return 0.5 * a * a * (1 + b * b)


def m_p(sin_i, cos_i, sin_o, cos_o, v):
    """d'Eon's longitudinal lobe (Cycles' sign), through scipy's scaled Bessel I0."""
    x = cos_i * cos_o / v
    log_i0 = np.log(special.i0e(x)) + x
    # 1 / (2 v sinh(1/v)) in logs
    log_norm = -math.log(2 * v) - (1 / v + math.log1p(-math.exp(-2 / v)) - math.log(2))
    return np.exp(log_norm + log_i0 - sin_i * sin_o / v)


def n_p(phi, p, s, gamma_o, gamma_t):
    d = phi - (2 * p * gamma_t - 2 * gamma_o + p * math.pi)
    d = (d + math.pi) % (2 * math.pi) - math.pi
    pdf = np.exp(-np.abs(d) / s) / (s * (1 + np.exp(-np.abs(d) / s)) ** 2)
    norm = 1 - 2 / (1 + math.exp(math.pi / s))
    return pdf / norm


def model(wo, wi, h, sigma, rough, radial, coat, offset, eta):
    """(F (n, 3), pdf (n,)) per Cycles' definitions; wi rows, wo one direction."""
    v, s = fit_v(rough), fit_s(radial)
    m0 = fit_v(max((1 - coat) * rough, 0.001))
    Y = np.cross(T, wo)
    Y /= np.linalg.norm(Y)
    Z = np.cross(T, Y)
    sin_o = float(T @ wo)
    cos_o = math.sqrt(1 - sin_o ** 2)
    phi_o = math.atan2(Z @ wo, Y @ wo)
    sin_i = np.clip(wi @ T, -1, 1)
    cos_i = np.sqrt(1 - sin_i ** 2)
    phi = np.arctan2(wi @ Z, wi @ Y) - phi_o
    sin_t = sin_o / eta
    cos_t = math.sqrt(1 - sin_t ** 2)
    gamma_o = math.asin(h)
    sin_gt = h * cos_o / math.sqrt(eta ** 2 - sin_o ** 2)
    gamma_t = math.asin(sin_gt)
    Tr = np.exp(-np.asarray(sigma) * 2 * math.sqrt(1 - sin_gt ** 2) / cos_t)
    f = fresnel(cos_o * math.sqrt(1 - h * h), eta)
    A = [np.full(3, f), (1 - f) ** 2 * Tr]
    A.append(A[1] * Tr * f)
    A.append(A[2] * Tr * f / (1 - Tr * f))
    E = np.array([float(LUM @ a) for a in A])
    E /= E.sum()
    a = -offset                      # Cycles keeps minus the node's Offset
    tilt = [(-2 * a), a, 4 * a]      # the view's theta shifted per lobe
    F = np.zeros((len(wi), 3))
    pdf = np.zeros(len(wi))
    for p in range(4):
        if p < 3:
            th = math.asin(sin_o) + tilt[p]
            so, co = math.sin(th), abs(math.cos(th))
            vp = (m0, 0.25 * v, 4 * v)[p]
            mn = m_p(sin_i, cos_i, so, co, vp) * n_p(phi, p, s, gamma_o, gamma_t)
        else:
            mn = m_p(sin_i, cos_i, sin_o, cos_o, 4 * v) / (2 * math.pi)
        F += A[p][None, :] * mn[:, None]
        pdf += E[p] * mn
    return F, pdf


# ------------------------------------------------------------------- kernel access
def normal_for(h, wo):
    """A geometric normal facing wo at which the view meets the fibre at h: -h Y -
    sqrt(1 - h^2) Z in the model's frame (Y = T x wo, Z = T x Y, normalised)."""
    Y = np.cross(T, wo)
    if np.linalg.norm(Y) < 1e-9:
        return np.array([0.0, 0.0, 1.0])
    Y /= np.linalg.norm(Y)
    Z = np.cross(T, Y)
    Z /= np.linalg.norm(Z)
    return -h * Y - math.sqrt(max(1 - h * h, 0.0)) * Z


def rows_for(n, hair, h, wo, strand_random=None, strand=True):
    """Rows of one Principled Hair material with the per-hit columns the integrator
    writes: the tangent T and a geometric normal giving h for the view wo, on a strand
    (or a mesh)."""
    rows = R.pack_materials(MaterialTable([Material(base_color=(0, 0, 0),
                                                    specular_ior_level=0.0,
                                                    principled_hair=hair)]))
    rows = np.ascontiguousarray(rows[np.zeros(n, np.int64)])
    rows[:, R.P_CHIANG_T:R.P_CHIANG_T + 3] = T
    rows[:, R.P_CHIANG_NG:R.P_CHIANG_NG + 3] = normal_for(h, wo)
    if strand_random is not None:
        rows[:, R.P_CHIANG_RANDOM + 2] = strand_random
    rows[:, R.P_HAIR_CURVE] = 1.0 if strand else 0.0
    return rows


def _wo(deg):
    a = math.radians(deg)
    return np.array([math.sin(a) * 0.6, -math.sin(a) * 0.8, math.cos(a)])


def absorbing(sigma, rough=0.3, radial=0.3, coat=0.0, offset=math.radians(2), ior=1.55):
    return PrincipledHair(parametrization="ABSORPTION", absorption=tuple(sigma),
                          roughness=rough, radial_roughness=radial, coat=coat,
                          offset=offset, ior=ior)


CASES = [(0.3, 0.3, 0.0, 0.0, 30.0, (0.2, 0.5, 1.0)),
         (0.15, 0.5, 0.5, 0.6, 60.0, (0.05, 0.1, 0.3)),
         (0.6, 0.2, 0.0, -0.9, 10.0, (1.0, 2.0, 3.0)),
         (0.08, 0.15, 0.0, 0.3, 75.0, (0.0, 0.0, 0.0))]
IDS = [f"r{c[0]}-radial{c[1]}-coat{c[2]}-h{c[3]}-{c[4]:g}deg" for c in CASES]


def _sampler(hair, h, deg):
    def sample(u):
        n = len(u)
        wi, weight, pdf, kind, delta, valid = batch.sample_batch(
            rows_for(n, hair, h, _wo(deg)), np.ones(n, bool),
            np.ascontiguousarray(np.broadcast_to(_wo(deg), (n, 3))), u[:, 0],
            np.ascontiguousarray(u[:, 1:]), np.ones((n, 3), bool), TABLES)
        return wi, valid
    return sample


@pytest.mark.parametrize("rough,radial,coat,h,deg,sigma", CASES, ids=IDS)
def test_sampler_draws_the_models_density(rough, radial, coat, h, deg, sigma):
    hair = absorbing(sigma, rough, radial, coat)
    res = chi2_test(_sampler(hair, h, deg),
                    lambda w: model(_wo(deg), w, h, sigma, rough, radial, coat,
                                    math.radians(2), 1.55)[1],
                    N, seed=int(deg * 3 + rough * 100), n_tests=len(CASES) + 1)
    print(res)
    assert res.passed, str(res)


def test_negative_control_wrong_h():
    """Samples at h = 0.6 against the density at h = 0 must fail."""
    sigma = (0.05, 0.1, 0.3)
    res = chi2_test(_sampler(absorbing(sigma, 0.15, 0.5), 0.6, 60.0),
                    lambda w: model(_wo(60.0), w, 0.0, sigma, 0.15, 0.5, 0.0,
                                    math.radians(2), 1.55)[1],
                    N, seed=5, n_tests=len(CASES) + 1)
    assert not res.passed, str(res)


@pytest.mark.parametrize("rough,radial,coat,h,deg,sigma", CASES, ids=IDS)
def test_value_and_pdf_match_the_model_and_weight_is_f_over_pdf(rough, radial, coat, h,
                                                                 deg, sigma):
    """Evaluation: f |cos| and pdf as the model's, anywhere on the sphere; a sample's
    weight is F / pdf with that pdf, the lobe drawn gives its kind (R glossy, the rest
    transmission), and directions leave on either side of the surface."""
    hair = absorbing(sigma, rough, radial, coat)
    n = 4000
    rng = np.random.default_rng(11)
    wo = np.ascontiguousarray(np.broadcast_to(_wo(deg), (n, 3)))
    w = rng.normal(size=(n, 3))
    w = np.ascontiguousarray(w / np.linalg.norm(w, axis=1, keepdims=True))
    rows = rows_for(n, hair, h, _wo(deg))
    F, pdf = model(_wo(deg), w, h, sigma, rough, radial, coat, math.radians(2), 1.55)
    f = batch.eval_f_batch(rows, np.ones(n, bool), wo, w, TABLES)
    ev = batch.pdf_batch(rows, np.ones(n, bool), wo, w, np.ones((n, 3), bool), TABLES)
    # Cycles sums I0's series to 10 terms below 12 and its asymptote keeps 1/(16 x) for
    # 1/(8 x) above: within 2.5 % of the exact Bessel function used here
    np.testing.assert_allclose(f * np.abs(w[:, 2:3]), F, rtol=0.025, atol=1e-12)
    np.testing.assert_allclose(ev, pdf, rtol=0.025, atol=1e-12)
    wi, weight, spdf, kind, delta, valid = batch.sample_batch(
        rows, np.ones(n, bool), wo, rng.random(n), rng.random((n, 2)), np.ones((n, 3), bool),
        TABLES)
    assert valid.mean() > 0.99 and not delta.any()
    Fs, ps = model(_wo(deg), wi[valid], h, sigma, rough, radial, coat, math.radians(2), 1.55)
    np.testing.assert_allclose(spdf[valid], ps, rtol=0.025)
    np.testing.assert_allclose(weight[valid], Fs / ps[:, None], rtol=0.05)
    # and exactly its own evaluation's: the pdf sampling reports, weight x pdf = f |cos|
    sv = wi[valid]
    ev_s = batch.pdf_batch(rows[valid], np.ones(len(sv), bool), wo[valid], sv,
                           np.ones((len(sv), 3), bool), TABLES)
    f_s = batch.eval_f_batch(rows[valid], np.ones(len(sv), bool), wo[valid], sv, TABLES)
    np.testing.assert_allclose(spdf[valid], ev_s, rtol=1e-9)
    np.testing.assert_allclose(weight[valid] * spdf[valid, None],
                               f_s * np.abs(sv[:, 2:3]), rtol=1e-9)
    assert (wi[valid, 2] < 0).any() and (wi[valid, 2] > 0).any()
    assert {int(k) for k in kind[valid]} == {batch.P.GLOSSY, batch.P.TRANSMISSION}


def _sphere(n_mu=600, n_phi=600):
    mu = (np.arange(n_mu) + 0.5) / n_mu * 2 - 1
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2 * np.pi
    M, P = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1 - M * M)
    w = np.stack([s * np.cos(P), s * np.sin(P), M], -1).reshape(-1, 3)
    return np.ascontiguousarray(w), 4 * np.pi / (n_mu * n_phi)


@pytest.mark.parametrize("rough,radial", [(0.3, 0.3), (0.6, 0.9), (1.0, 1.0)])
@pytest.mark.parametrize("h", [-0.95, 0.0, 0.5])
@pytest.mark.parametrize("deg", [0.0, 50.0, 85.0])
def test_white_furnace_a_clear_fibre_returns_all_light(rough, radial, h, deg):
    """No absorption: A_R + A_TT + A_TRT + A_rest = 1 and each lobe is a density, so the
    value integrates to 1 over the sphere (d'Eon's lobe is normalised at any view)."""
    w, dw = _sphere()
    n = len(w)
    rows = rows_for(n, absorbing((0.0, 0.0, 0.0), rough, radial), h, _wo(deg))
    wo = np.ascontiguousarray(np.broadcast_to(_wo(deg), (n, 3)))
    f = batch.eval_f_batch(rows, np.ones(n, bool), wo, w, TABLES)
    albedo = (f * np.abs(w[:, 2:3])).sum(0) * dw
    print(f"roughness {rough}/{radial}, h {h}, {deg} deg: {albedo}")
    np.testing.assert_allclose(albedo, 1.0, atol=0.01)


@pytest.mark.parametrize("rough,radial", [(0.001, 0.001), (1.0, 1.0), (0.001, 1.0)])
@pytest.mark.parametrize("h", [-1.0, 0.0, 1.0])
@pytest.mark.parametrize("ior", [1.0001, 1.55, 3.0])
def test_finite_at_the_extremes(rough, radial, h, ior):
    """Roughness 0.001 and 1, h at the fibre's edges, IOR near 1, a black fibre
    (infinite absorption from Color 0), views grazing and along the fibre: no NaN, no
    Inf, valid samples."""
    rng = np.random.default_rng(3)
    n = 3000
    w = rng.normal(size=(n, 3))
    w = np.ascontiguousarray(w / np.linalg.norm(w, axis=1, keepdims=True))
    for hair in (absorbing((0.3, 0.3, 0.3), rough, radial, ior=ior),
                 PrincipledHair(color=(0.0, 0.5, 1.0), roughness=rough,
                                radial_roughness=radial, ior=ior)):
        for wo1 in (_wo(0.0), _wo(89.99), T, -T, np.array([0.0, 0.0, 1.0])):
            rows = rows_for(n, hair, h, wo1)
            wo = np.ascontiguousarray(np.broadcast_to(wo1, (n, 3)))
            f = batch.eval_f_batch(rows, np.ones(n, bool), wo, w, TABLES)
            assert np.isfinite(f).all() and (f >= 0).all()
            wi, weight, pdf, _, _, valid = batch.sample_batch(
                rows, np.ones(n, bool), wo, rng.random(n), rng.random((n, 2)),
                np.ones((n, 3), bool), TABLES)
            assert np.isfinite(wi).all() and np.isfinite(weight).all()
            assert np.isfinite(pdf[valid]).all() and (pdf[valid] > 0).all()
            if abs(float(wo1 @ T)) < 0.99:
                assert valid.mean() > 0.9


def test_colour_parametrisations_as_cycles_defines_them():
    """Direct Coloring: sigma = (ln c / scale(radial))^2; Melanin: -ln(1 - m) split by
    Redness into eu- and pheomelanin's absorption, plus the Tint's; Random Color and
    Random Roughness scale by 1 + 2 (random - 1/2) amount."""
    def scale(x):
        return ((((0.245 * x + 5.574) * x - 10.73) * x + 2.532) * x - 0.215) * x + 5.969
    c = (0.75, 0.55, 0.3)
    got = H.absorption(H.COLOR, *c, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.5, 0.4)
    np.testing.assert_allclose(got, [(math.log(x) / scale(0.4)) ** 2 for x in c], rtol=1e-12)
    m, red, rc, rnd = 0.35, 0.7, 0.4, 0.9
    tint = (0.9, 0.8, 1.0)
    got = H.absorption(H.MELANIN, *tint, m, red, *tint, rc, rnd, 0.3)
    mm = -math.log(1 - m * (1 + 2 * (rnd - 0.5) * rc))
    eu, ph = mm * (1 - red), mm * red
    want = (eu * np.array([0.506, 0.841, 1.653]) + ph * np.array([0.343, 0.733, 1.924])
            + np.array([(math.log(t) / scale(0.3)) ** 2 for t in tint]))
    np.testing.assert_allclose(got, want, rtol=1e-12)
    assert H.absorption(H.ABSORPTION, 0.1, 0.2, 0.3, 0.8, 1.0, 1, 1, 1, 0.0, 0.0,
                        0.3) == (0.1, 0.2, 0.3)
    # Random Roughness: a strand's Random 0.9 with amount 0.5 is roughness x 1.4
    hair = PrincipledHair(roughness=0.3, radial_roughness=0.3, random_roughness=0.5)
    same = PrincipledHair(roughness=0.42, radial_roughness=0.42)
    w = _sphere(60, 80)[0]
    wo = np.ascontiguousarray(np.broadcast_to(_wo(40.0), (len(w), 3)))
    f1 = batch.eval_f_batch(rows_for(len(w), hair, 0.2, _wo(40.0), strand_random=0.9),
                            np.ones(len(w), bool), wo, w, TABLES)
    # the colour's absorption also follows the radial roughness, as in Cycles
    f2 = batch.eval_f_batch(rows_for(len(w), same, 0.2, _wo(40.0)), np.ones(len(w), bool), wo, w,
                            TABLES)
    np.testing.assert_allclose(f1, f2, rtol=1e-9)


def test_h_is_where_the_view_meets_the_fibre():
    """A fibre along x seen from +z: a hit whose normal leans by angle a across it has
    |h| = sin a, opposite signs on the two sides, 0 at the centre."""
    t = (1.0, 0.0, 0.0)
    view = (0.0, 0.0, 1.0)
    hs = []
    for a in (-1.2, -0.4, 0.0, 0.4, 1.2):
        g = (0.0, math.sin(a), math.cos(a))
        hs.append(H.offset_h(*g, *t, *view))
    np.testing.assert_allclose(np.abs(hs), np.abs(np.sin([-1.2, -0.4, 0.0, 0.4, 1.2])),
                               atol=1e-12)
    assert hs[0] == -hs[4] and hs[1] == -hs[3] and hs[2] == 0.0
    assert H.offset_h(0.0, 0.0, 1.0, *t, 1.0, 0.0, 0.0) == 0.0     # view along the fibre


def test_materials_without_principled_hair_never_read_its_columns():
    """The per-hit Principled Hair columns are read only by rows that have the closure:
    NaN there changes nothing for other materials (and the row of a Hair BSDF node)."""
    mats = [Material(), Material(base_color=(0.2, 0.5, 0.1), coat_weight=0.7),
            Material(hair_reflection=(0.5, 0.4, 0.3)), Material(transmission=1.0)]
    rows = R.pack_materials(MaterialTable(mats))
    n = 2000
    rng = np.random.default_rng(4)
    idx = np.arange(n) % len(mats)
    wo = np.ascontiguousarray(np.broadcast_to(_wo(35.0), (n, 3)))
    wi = rng.normal(size=(n, 3))
    wi = np.ascontiguousarray(wi / np.linalg.norm(wi, axis=1, keepdims=True))
    u, ud = rng.random(n), rng.random((n, 2))
    out = []
    for fill in (0.0, np.nan):
        r = np.ascontiguousarray(rows[idx])
        r[:, R.P_HAIR_T:R.P_HAIR_T + 3] = T
        r[:, R.P_CHIANG_T:R.P_CHIANG_T + 3] = fill
        r[:, R.P_CHIANG_NG:R.P_CHIANG_NG + 3] = fill
        f = batch.eval_f_batch(r, np.ones(n, bool), wo, wi, TABLES)
        s = batch.sample_batch(r, np.ones(n, bool), wo, u, ud, np.ones((n, 3), bool), TABLES)
        out.append((f, s[1], s[2]))
    for a, b in zip(*out):
        assert np.array_equal(a, b)


def test_on_a_mesh_lights_see_cycles_bump_test_and_samples_do_not():
    """On a triangle the closure's normal Y = X x wo is not the surface's N (local z):
    Cycles' bsdf_eval refuses light where N.wi, N.Y and Y.wi disagree in sign (its
    bump_shadowing_term), its bsdf_sample does not. The same closure on a strand: no
    test."""
    hair = absorbing((0.2, 0.3, 0.5), 0.4, 0.4)
    n = 6000
    rng = np.random.default_rng(9)
    wo1 = _wo(40.0)
    wo = np.ascontiguousarray(np.broadcast_to(wo1, (n, 3)))
    w = rng.normal(size=(n, 3))
    w = np.ascontiguousarray(w / np.linalg.norm(w, axis=1, keepdims=True))
    f, p = {}, {}
    for strand in (True, False):
        rows = rows_for(n, hair, 0.3, wo1, strand=strand)
        f[strand] = batch.eval_f_batch(rows, np.ones(n, bool), wo, w, TABLES)
        p[strand] = batch.pdf_batch(rows, np.ones(n, bool), wo, w, np.ones((n, 3), bool),
                                    TABLES)
    Y = np.cross(T, wo1)
    Y /= np.linalg.norm(Y)
    refused = w[:, 2] * Y[2] * (w @ Y) < 0
    assert 0.1 < refused.mean() < 0.9
    assert np.all(f[False][refused] == 0) and np.all(p[False][refused] == 0)
    assert np.array_equal(f[False][~refused], f[True][~refused])
    assert np.array_equal(p[False][~refused], p[True][~refused])
    assert (f[True][refused] > 0).all()
    u, ud = rng.random(n), rng.random((n, 2))
    s = {strand: batch.sample_batch(rows_for(n, hair, 0.3, wo1, strand=strand),
                                    np.ones(n, bool), wo, u, ud, np.ones((n, 3), bool),
                                    TABLES) for strand in (True, False)}
    for a, b in zip(s[True], s[False]):
        assert np.array_equal(a, b)
    # the back of a triangle (its normal away from the view): Cycles turns the normal
    # and negates dPdu, so a tangent -T there shades as T on the front
    front = rows_for(n, hair, 0.3, wo1, strand=False)
    back = front.copy()
    back[:, R.P_CHIANG_NG:R.P_CHIANG_NG + 3] *= -1
    back[:, R.P_CHIANG_T:R.P_CHIANG_T + 3] *= -1
    fb = batch.eval_f_batch(back, np.ones(n, bool), wo, w, TABLES)
    np.testing.assert_allclose(fb, f[False], rtol=1e-12, atol=0)
    turned = front.copy()
    turned[:, R.P_CHIANG_T:R.P_CHIANG_T + 3] *= -1      # not the same as a back face
    assert not np.allclose(batch.eval_f_batch(turned, np.ones(n, bool), wo, w, TABLES),
                           f[False])
