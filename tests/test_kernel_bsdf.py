"""The compiled Principled BSDF (engine/kernels/bsdf) over random materials, hits,
directions, random numbers and `allowed` masks: the packing of materials into rows, the
table lookups at the tables' nodes, and what must hold between its three functions with
no second implementation to compare with: a sample's pdf is `pdf` at the sampled
direction, its weight is `eval_f` of the allowed lobes times |cos| over that pdf, the
kinds respect the masks, every output is finite. Closed forms for plain diffuse, the
Glossy BSDF and the Specular Tint. (Chi-square, furnace and reciprocity tests of the
same kernels: test_bsdf_sampling.py, test_bsdf_energy.py, test_multiscatter.py.)

Materials are `engine.scene.Material` objects packed through MaterialTable and
`pack_materials`, so the packing is tested too.
"""
from __future__ import annotations

import numpy as np
import pytest

from engine.bsdf import energy_tables as et
from engine.bsdf import layer_albedo
from engine.bsdf.material_table import MaterialTable
from engine.kernels import bsdf as kb
from engine.kernels.bsdf import batch
from engine.kernels.bsdf import table_batch as tb
from engine.kernels.bsdf.principled import DIFFUSE, GLOSSY, TRANSMISSION
from engine.scene import Material

RTOL = 1e-9
ATOL = 1e-12
N_MATERIALS = 300
N_HITS = 20_000


# --- random materials and hits -------------------------------------------------------------

def random_materials(rng, n):
    mats = []
    for k in range(n):
        kind = rng.integers(6)
        base = tuple(rng.uniform(0.0, 1.0, 3))
        if rng.random() < 0.1:
            base = tuple(rng.uniform(0.0, 1.6, 3))       # > 1: diffuse unclamped
        if rng.random() < 0.05:
            base = (0.0, 0.0, 0.0)
        m = Material(
            name=f"m{k}", base_color=base,
            metallic=float(rng.choice([0.0, 0.0, 0.5, 1.0, rng.random()])),
            roughness=float(rng.choice([0.0, 1e-3, 0.0187, 0.05, 0.5, 1.0, rng.random()])),
            ior=float(rng.choice([1.0, 1.01, 1.45, 1.5, 2.4, 0.75])),
            transmission=float(rng.choice([0.0, 0.0, 0.5, 1.0])),
            specular_ior_level=float(rng.choice([0.0, 0.5, 0.5, 1.0, rng.random()])),
            glossy_model="BLINN_PHONG" if rng.random() < 0.25 else
            ("MULTI_GGX" if k % 2 else "GGX"))
        if kind == 0:                                     # plain diffuse
            m.metallic, m.transmission, m.specular_ior_level = 0.0, 0.0, 0.0
        if rng.random() < 0.2:
            m.metal_color = tuple(rng.uniform(0.0, 1.2, 3))
        if rng.random() < 0.2:
            m.glass_color = tuple(rng.uniform(0.0, 1.2, 3))
        mats.append(m)
    return mats


def unit(v):
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def random_hits(rng, n, n_mat):
    index = rng.integers(0, n_mat, n)
    front = rng.random(n) < 0.6
    # wo: uniform over the upper hemisphere, some grazing and some at the normal
    z = rng.uniform(0.0, 1.0, n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    special = rng.random(n)
    z = np.where(special < 0.05, 1e-4, z)
    z = np.where((special >= 0.05) & (special < 0.08), 1.0, z)
    z = np.maximum(z, 1e-4)
    s = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    wo = unit(np.stack([s * np.cos(phi), s * np.sin(phi), z], -1))
    # wi on the whole sphere, some at the mirror direction and straight through
    wi = unit(rng.normal(size=(n, 3)))
    pick = rng.random(n)
    mirror = np.stack([-wo[:, 0], -wo[:, 1], wo[:, 2]], -1)
    wi = np.where((pick < 0.05)[:, None], mirror, wi)
    wi = np.where(((pick >= 0.05) & (pick < 0.08))[:, None], -wo, wi)
    u_lobe = rng.random(n)
    u_dir = rng.random((n, 2))
    u_dir[rng.random(n) < 0.01, 0] = 0.0
    u_lobe[rng.random(n) < 0.01] = 0.0
    allowed = rng.random((n, 3)) < 0.8
    allowed[rng.random(n) < 0.4] = True
    return index, front, wo, wi, u_lobe, u_dir, allowed


@pytest.fixture(scope="module")
def case():
    rng = np.random.default_rng(20240607)
    mats = random_materials(rng, N_MATERIALS)
    table = MaterialTable(mats)
    index, front, wo, wi, u_lobe, u_dir, allowed = random_hits(rng, N_HITS, len(mats))
    # Filter Glossy's lower bound on the lobes' alpha at a fifth of the hits
    filter_alpha = np.where(np.random.default_rng(8).random(N_HITS) < 0.2,
                            np.random.default_rng(9).uniform(0.0, 0.5, N_HITS), 0.0)
    assert ((filter_alpha > 0) & (filter_alpha > kb.pack_materials(table)[index, kb.P_ROUGHNESS]
                                  ** 2)).mean() > 0.1      # Filter Glossy widens lobes
    rows = kb.pack_materials(table)[index]
    rows[:, kb.P_FILTER_ALPHA] = filter_alpha
    return dict(mats=mats, table=table, index=index, front=front, wo=wo, wi=wi,
                u_lobe=u_lobe, u_dir=u_dir, allowed=allowed, rows=rows,
                filter_alpha=filter_alpha, tables=kb.kernel_tables())


def close(a, b, rtol=RTOL, atol=ATOL):
    """Elementwise |a - b| <= atol + rtol |b|, with equal infinities."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    same_inf = np.isinf(a) & np.isinf(b) & (np.sign(a) == np.sign(b))
    with np.errstate(invalid="ignore"):
        return same_inf | (np.abs(a - b) <= atol + rtol * np.abs(b))


def assert_close(a, b, what, rtol=RTOL, atol=ATOL):
    ok = close(a, b, rtol, atol)
    if not ok.all():
        bad = np.nonzero(~ok.reshape(len(ok), -1).all(1))[0]
        k = bad[0]
        raise AssertionError(f"{what}: {len(bad)} mismatches, first at {k}: "
                             f"{a[k]} vs {b[k]}")


# --- packing and tables ------------------------------------------------------------------

def test_pack_materials_columns():
    mats = [Material(base_color=(0.1, 0.2, 0.3), metallic=0.4, roughness=0.6, ior=1.7,
                     transmission=0.8, specular_ior_level=0.9, metal_color=(0.5, 0.6, 0.7),
                     glossy_model="BLINN_PHONG"),
            Material(glass_color=(0.2, 0.3, 0.4)),
            Material(glossy_model="MULTI_GGX")]
    rows = kb.pack_materials(MaterialTable(mats))
    assert rows.shape == (3, kb.NPARAM) and rows.dtype == np.float64
    r = rows[0]
    assert tuple(r[kb.P_BASE:kb.P_BASE + 3]) == (0.1, 0.2, 0.3)
    assert (r[kb.P_METALLIC], r[kb.P_ROUGHNESS], r[kb.P_IOR], r[kb.P_TRANSMISSION],
            r[kb.P_SPEC_LEVEL]) == (0.4, 0.6, 1.7, 0.8, 0.9)
    assert tuple(r[kb.P_METAL_COLOR:kb.P_METAL_COLOR + 3]) == (0.5, 0.6, 0.7)
    assert r[kb.P_HAS_METAL_COLOR] == 1 and r[kb.P_HAS_GLASS_COLOR] == 0
    assert r[kb.P_GLOSSY_MODEL] == kb.GLOSSY_BLINN_PHONG
    r = rows[1]
    assert r[kb.P_HAS_METAL_COLOR] == 0 and r[kb.P_HAS_GLASS_COLOR] == 1
    assert tuple(r[kb.P_GLASS_COLOR:kb.P_GLASS_COLOR + 3]) == (0.2, 0.3, 0.4)
    assert r[kb.P_GLOSSY_MODEL] == kb.GLOSSY_GGX
    assert rows[2, kb.P_GLOSSY_MODEL] == kb.GLOSSY_MULTI_GGX
    assert (rows[:, kb.P_FILTER_ALPHA] == 0).all()            # a per-hit value, none packed


def test_kernel_tables_are_the_stored_tables():
    t = kb.kernel_tables()
    assert t is kb.kernel_tables()
    assert t[0] is layer_albedo.get_table(0) and t[1] is layer_albedo.get_table(1)
    for a, b in zip(t[2:], (layer_albedo.TABLE_S, layer_albedo.TABLE_R, layer_albedo.TABLE_T)):
        assert np.array_equal(a, b)


def test_lookups_return_the_table_entries_at_its_nodes():
    """At a node of its grid each lookup returns that entry (to rounding of the node's
    coordinates), so the coordinates (F0^(1/4), sqrt(alpha), t and the critical-angle
    axis for eta < 1; z and the side of eta) are the generators' own."""
    rng = np.random.default_rng(3)
    for side in (0, 1):
        table = layer_albedo.get_table(side)
        for _ in range(40):
            i, j, k = (rng.integers(len(g)) for g in (layer_albedo.TABLE_S,
                                                      layer_albedo.TABLE_R,
                                                      layer_albedo.TABLE_T))
            eta = float(layer_albedo._eta_of(layer_albedo.TABLE_S[i] ** 2, side))
            c = float(layer_albedo._critical_cos(eta))
            mu = float(layer_albedo._mu_of_t(layer_albedo.TABLE_T[k], c))
            if mu < 1e-6:
                continue                           # the table's own floor of cos theta_o
            got = tb.specular_albedo(mu, layer_albedo.TABLE_R[j] ** 2, eta)
            assert abs(got - table[i, j, k]) < 1e-9, (side, i, j, k, got, table[i, j, k])
    tab = et.load()
    for _ in range(40):
        i, j = rng.integers(len(et.ROUGH)), rng.integers(1, len(et.T))
        got = tb.ggx_albedo(et.mu_of_t(et.T[j]), et.ROUGH[i] ** 2)
        assert abs(got - tab["ggx_E"][i, j]) < 1e-9
        s, z = rng.integers(2), rng.integers(len(et.GLASS_Z))
        i, j = rng.integers(len(et.GLASS_ROUGH)), rng.integers(1, len(et.GLASS_T))
        eta = float(et.eta_of_z(et.GLASS_Z[z], s))
        args = (et.mu_of_t(et.GLASS_T[j]), et.GLASS_ROUGH[i] ** 2, eta)
        assert abs(tb.glass_albedo(*args) - tab["glass_E"][s, z, i, j]) < 1e-9
        assert abs(tb.glass_albedo_avg(*args[1:]) - tab["glass_E_avg"][s, z, i]) < 1e-9


def test_eval_and_pdf_are_finite_and_positive_where_a_lobe_is(case):
    c = case
    f = batch.eval_f_batch(c["rows"], c["front"], c["wo"], c["wi"], c["tables"])
    assert np.isfinite(f).all() and (f >= 0).all()
    assert (f > 0).any(1).mean() > 0.3
    for allowed in (c["allowed"], np.ones_like(c["allowed"])):
        p = batch.pdf_batch(c["rows"], c["front"], c["wo"], c["wi"], allowed, c["tables"])
        assert np.isfinite(p).all() and (p >= 0).all()
        assert (p > 0).mean() > 0.3


def sample_case(c, rows=None):
    rows = c["rows"] if rows is None else rows
    return batch.Sample(*batch.sample_batch(rows, c["front"], c["wo"], c["u_lobe"],
                                            c["u_dir"], c["allowed"], c["tables"]))


def test_samples_are_well_formed(case):
    c = case
    wi, weight, pdf, kind, delta, valid = sample_case(c)
    assert np.isfinite(wi).all() and np.isfinite(weight).all()
    assert np.allclose((wi[valid] ** 2).sum(1), 1.0, rtol=1e-12)
    assert (weight >= 0).all() and (pdf >= 0).all()
    assert np.isinf(pdf[delta]).all() and np.isfinite(pdf[~delta]).all()
    assert (weight[~valid] == 0).all() and (pdf[~valid] == 0).all()
    assert (pdf[valid] > 0).all()
    # every kind, delta and non-delta, valid and rejected samples occur
    for k in (DIFFUSE, GLOSSY, TRANSMISSION):
        assert (valid & (kind == k) & ~delta).sum() > 100
    for k in (GLOSSY, TRANSMISSION):
        assert (valid & (kind == k) & delta).sum() > 50
    assert (~valid).sum() > 50
    # the lobe kinds respect the allowed masks; transmission goes below the surface
    assert c["allowed"][np.nonzero(valid)[0], kind[valid]].all()
    assert np.array_equal(wi[valid, 2] < 0, kind[valid] == TRANSMISSION)


def weight_mismatches(c, s, rows):
    """Valid non-delta samples whose pdf is not `pdf` at the sampled wi, or whose weight
    is not f(allowed lobes) |cos| / pdf, with the BSDF of `rows`."""
    ok = s.valid & ~s.delta
    idx = np.nonzero(ok)[0]
    wo, wi, allowed = c["wo"][idx], s.wi[idx], c["allowed"][idx]
    f = batch.eval_seen_batch(rows[idx], c["front"][idx], wo, wi, allowed, c["tables"])
    p = batch.pdf_batch(rows[idx], c["front"][idx], wo, wi, allowed, c["tables"])
    bad_p = ~close(s.pdf[idx], p)
    bad_w = ~close(s.weight[idx], f * np.abs(wi[:, 2:3]) / p[:, None]).all(1)
    return idx, p, bad_p | bad_w


def test_sample_weight_is_f_cos_over_pdf(case):
    """At every valid non-delta sample (including the lobes' peaks: mirror-like GGX at
    alpha 1e-4, Blinn-Phong exponents up to 2e8, refraction) the sample's pdf is `pdf`
    there and its weight is f |cos| / pdf of the allowed lobes."""
    c = case
    s = sample_case(c)
    idx, p, bad = weight_mismatches(c, s, c["rows"])
    assert len(idx) > 10_000
    assert p.max() > 1e6                           # really near-specular lobes
    assert not bad.any(), f"{bad.sum()} of {len(idx)}"


def test_negative_control_perturbed_roughness(case):
    """Samples of the case checked against a BSDF with roughness 1 % off (or the other
    facing flag) fail the same test."""
    c = case
    s = sample_case(c)
    rows = c["rows"].copy()
    rows[:, kb.P_ROUGHNESS] *= 1.01
    assert weight_mismatches(c, s, rows)[2].sum() > 100
    flipped = dict(c, front=~c["front"])
    assert weight_mismatches(flipped, s, c["rows"])[2].sum() > 100


def test_plain_diffuse_is_lambert():
    """Plain diffuse materials (Specular IOR Level 0): f = base / pi, pdf = cos / pi
    where diffuse is allowed, and every sample weighs its base colour."""
    rng = np.random.default_rng(11)
    mats = [Material(base_color=tuple(rng.uniform(0, 1, 3)), specular_ior_level=0.0)
            for _ in range(20)] + [Material(base_color=(0.0, 0.0, 0.0),
                                            specular_ior_level=0.0)]
    table = MaterialTable(mats)
    index, front, wo, wi, u_lobe, u_dir, allowed = random_hits(rng, 5000, len(mats))
    rows, tables = kb.pack_materials(table)[index], kb.kernel_tables()
    base = table.base_color[index]
    up = wi[:, 2] > 0
    f = batch.eval_f_batch(rows, front, wo, wi, tables)
    assert_close(f, np.where(up[:, None], base / np.pi, 0.0), "f")
    p = batch.pdf_batch(rows, front, wo, wi, allowed, tables)
    lit = allowed[:, DIFFUSE] & (base.max(1) > 0)
    assert_close(p, np.where(up & lit, wi[:, 2] / np.pi, 0.0), "pdf")
    wi_k, weight, pdf, kind, delta, valid = batch.sample_batch(
        rows, front, wo, u_lobe, u_dir, allowed, tables)
    assert not delta.any() and (kind[valid] == DIFFUSE).all()
    assert np.array_equal(valid, lit & (wi_k[:, 2] > 0))
    assert_close(weight[valid], base[valid], "weight")
    assert_close(pdf[valid], wi_k[valid, 2] / np.pi, "sample pdf")


def test_transmits():
    mats = [Material(transmission=1.0), Material(transmission=0.5, metallic=0.5),
            Material(transmission=1.0, metallic=1.0), Material(transmission=0.0),
            Material(transmission=2.0, metallic=-1.0)]
    rows = kb.pack_materials(MaterialTable(mats))
    state = np.empty(kb.NSTATE)
    got = []
    for row in rows:
        kb.setup(row, True, 0.0, 0.0, 1.0, kb.kernel_tables(), state)
        got.append(kb.transmits(state))
    assert got == [True, True, False, False, True]


def test_scalar_interface_matches_batch(case):
    """The scalar kernels called one by one (the integrator's interface, argument order
    and return order) give what the batch drivers give (to rounding: the two are
    separate compilations, which may contract operations differently)."""
    c = case
    state = np.zeros(kb.NSTATE)
    for k in range(0, N_HITS, 997):
        row, fr, o, i = c["rows"][k], bool(c["front"][k]), c["wo"][k], c["wi"][k]
        a = [bool(x) for x in c["allowed"][k]]
        kb.setup(row, fr, o[0], o[1], o[2], c["tables"], state)
        f = kb.eval_f(state, *o, *i)
        p = kb.pdf(state, *o, *i, *a)
        s = kb.sample(state, *o, c["u_lobe"][k], *c["u_dir"][k], *a)
        one = slice(k, k + 1)
        args = (c["rows"][one], c["front"][one], c["wo"][one])
        assert_close(np.array(f), batch.eval_f_batch(*args, c["wi"][one], c["tables"])[0], "f")
        assert_close(np.array([p]), batch.pdf_batch(*args, c["wi"][one], c["allowed"][one],
                                                    c["tables"]), "pdf")
        bs = batch.sample_batch(*args, c["u_lobe"][one], c["u_dir"][one],
                                c["allowed"][one], c["tables"])
        assert_close(np.array(s[0:6]), np.concatenate([bs[0][0], bs[1][0]]), "sample")
        assert_close(np.array([s[6]]), bs[2], "sample pdf")
        assert (s[7], s[8], s[9]) == (bs[3][0], bs[4][0], bs[5][0])


def test_glossy_bsdf_reflects_its_colour_at_every_angle():
    """metal_fresnel 'CONSTANT' (a Glossy BSDF): f = colour x the white lobe's f at
    every angle, as Cycles' Fresnel-less Glossy; 'SCHLICK' (Principled's metal) whitens
    towards grazing angles, so the same colour there reflects more."""
    colour = (0.1, 0.3, 0.6)
    rng = np.random.default_rng(4)
    n = 4000
    cos_o = np.concatenate([rng.random(n - 1), [1e-3]])
    wo = np.stack([np.sqrt(1 - cos_o ** 2), np.zeros(n), cos_o], -1)
    wi = rng.normal(size=(n, 3))
    wi[:, 2] = np.abs(wi[:, 2])
    wi /= np.linalg.norm(wi, axis=1)[:, None]
    tables = kb.kernel_tables()

    def f(**params):
        rows = kb.pack_materials(MaterialTable([Material(metallic=1.0, roughness=0.4,
                                                         **params)]))[np.zeros(n, int)]
        return batch.eval_f_batch(rows, np.ones(n, bool), wo, wi, tables)
    white = f(base_color=(1.0, 1.0, 1.0), metal_fresnel="CONSTANT")
    const = f(base_color=colour, metal_fresnel="CONSTANT")
    schlick = f(base_color=colour)
    assert (white[:, 0] > 0).mean() > 0.5
    assert np.allclose(const, white * np.array(colour), rtol=1e-12, atol=0.0)
    assert (schlick >= const * (1 - 1e-12)).all()
    h = (wo + wi) / np.linalg.norm(wo + wi, axis=1)[:, None]
    grazing = ((wo * h).sum(1) < 0.3) & (white[:, 0] > 0)       # wo far from the facet
    assert grazing.sum() > 20
    assert (schlick[grazing, 0] > 1.5 * const[grazing, 0]).all()
    with pytest.raises(ValueError, match="metal_fresnel"):
        MaterialTable([Material(metal_fresnel="F82")])


def test_specular_tint_is_cycles_f82_tint_on_metals():
    """F82-tint (Cycles' Principled metal with a Specular Tint): Schlick's Fresnel times
    the tint at mu = 1/7, Schlick's at the normal, and its hemispherical average (the
    multiscatter Fss) F0 + (1 - F0) / 21 - b / 126 by quadrature; a white tint is plain
    Schlick, bit for bit."""
    from engine.kernels.bsdf import fresnel as kf
    for f0, tint in ((0.9, 0.3), (0.5, 1.0), (0.05, 0.0), (1.0, 0.5)):
        b = kf.f82_tint_b(f0, tint)
        assert kf.f82_tint(f0, b, 1.0 / 7.0) == pytest.approx(kf.schlick(f0, 1.0 / 7.0) * tint,
                                                              rel=1e-12, abs=1e-15)
        assert kf.f82_tint(f0, b, 1.0) == pytest.approx(f0, rel=1e-12)
        mu = (np.arange(4000) + 0.5) / 4000
        F = np.array([kf.f82_tint(f0, b, m) for m in mu])
        assert (F >= 0).all() and (F <= 1).all()
        unclamped = f0 + (1 - f0) * (1 - mu) ** 5 - b * mu * (1 - mu) ** 6
        if (unclamped >= 0).all():          # (a tint of 0 dips below 0, clamped there)
            avg = 2.0 * np.mean(F * mu)
            assert avg == pytest.approx(f0 + (1 - f0) / 21 - b / 126, abs=1e-6)
    # through the BSDF: a tinted metal at cos(wo, h) = 1/7 reflects tint x the white one's
    n = 1
    t = np.arccos(1.0 / 7.0)
    wo = np.array([[np.sin(t), 0.0, np.cos(t)]])
    wi = np.array([[-np.sin(t), 0.0, np.cos(t)]])              # h = the normal
    tables = kb.kernel_tables()

    def f(tint):
        mat = Material(metallic=1.0, roughness=0.5, base_color=(0.9, 0.6, 0.3),
                       specular_tint=tint)
        rows = kb.pack_materials(MaterialTable([mat]))[np.zeros(n, int)]
        return batch.eval_f_batch(rows, np.ones(n, bool), wo, wi, tables)[0]
    assert np.allclose(f((0.2, 0.5, 1.0)), f((1.0, 1.0, 1.0)) * np.array([0.2, 0.5, 1.0]),
                       rtol=1e-12)


def test_specular_tint_colours_the_dielectric_layer_as_cycles():
    """The specular layer with a Specular Tint (kernels/bsdf/specular_tint.py): at the
    mirror direction of normal incidence its reflectance is F0 x tint; towards grazing
    it fades to white; a tinted glossy plastic's sampled albedo equals its quadrature,
    and with a tint <= 1 over a white base the furnace stays <= 1."""
    from test_layered_bsdf import albedo_both_ways
    tables = kb.kernel_tables()
    wo = np.array([[0.0, 0.0, 1.0]])

    def f(tint, wo=wo, wi=wo):
        mat = Material(base_color=(0.0, 0.0, 0.0), roughness=0.3, specular_tint=tint)
        rows = kb.pack_materials(MaterialTable([mat]))[np.zeros(1, int)]
        return batch.eval_f_batch(rows, np.ones(1, bool), wo, wi, tables)[0]
    tint = np.array([0.5, 1.0, 2.0])
    assert np.allclose(f(tuple(tint)), f((1.0, 1.0, 1.0)) * tint, rtol=1e-12)
    t = np.radians(89.0)
    graze_o = np.array([[np.sin(t), 0.0, np.cos(t)]])
    graze_i = np.array([[-np.sin(t), 0.0, np.cos(t)]])
    ratio = f(tuple(tint), graze_o, graze_i) / f((1.0, 1.0, 1.0), graze_o, graze_i)
    assert np.all(np.abs(ratio - 1.0) <= 0.3 * np.abs(tint - 1.0))   # fading to white
    for params in (dict(base_color=(1.0, 1.0, 1.0), roughness=0.4,
                        specular_tint=(0.2, 0.6, 1.0), glossy_model="MULTI_GGX"),
                   dict(base_color=(0.0, 0.0, 0.0), roughness=0.2, specular_ior_level=1.0,
                        specular_tint=(1.0, 0.3, 2.0))):
        for deg in (10.0, 70.0):
            mc, quad, _ = albedo_both_ways(params, deg)
            assert np.allclose(mc, quad, rtol=0.01, atol=2e-3), (params, deg, mc, quad)
            if params["base_color"][0] == 1.0:
                assert quad.max() <= 1.0 + 0.005


def test_specular_tint_on_glass_tints_reflection_and_lets_the_rest_through():
    """Principled glass with a Specular Tint: smooth glass samples carry F_c / F on
    reflection and (1 - F_c) / (1 - F) on refraction per channel, with F_c = f0_c + (1 -
    f0_c) (F - F0) / (1 - F0), f0_c = F0 x tint; rough tinted glass's sampled albedo
    equals its quadrature."""
    from engine.kernels.bsdf import fresnel as kf
    from test_layered_bsdf import albedo_both_ways
    tint = np.array([0.1, 1.0, 3.0])
    n = 4000
    rng = np.random.default_rng(8)
    tables = kb.kernel_tables()
    t = np.radians(40.0)
    wo = np.tile([np.sin(t), 0.0, np.cos(t)], (n, 1))
    u_lobe, u_dir = rng.random(n), rng.random((n, 2))

    def sample(tint):
        mat = Material(transmission=1.0, roughness=0.0, ior=2.0, base_color=(1.0,) * 3,
                       specular_tint=tuple(tint))
        rows = kb.pack_materials(MaterialTable([mat]))[np.zeros(n, int)]
        return batch.sample_batch(rows, np.ones(n, bool), wo, u_lobe, u_dir,
                                  np.ones((n, 3), bool), tables)
    wi_t, w_t, _, _, delta, valid = sample(tint)
    wi_w, w_w, _, _, _, _ = sample((1.0, 1.0, 1.0))
    assert delta[valid].all() and np.array_equal(wi_t, wi_w)     # the same choices
    F = kf.dielectric(np.cos(t), 2.0)
    F0 = kf.f0_from_ior(2.0)
    Fc = F0 * tint + (1 - F0 * tint) * (F - F0) / (1 - F0)
    refl = valid & (wi_t[:, 2] > 0)
    refr = valid & (wi_t[:, 2] < 0)
    assert refl.any() and refr.any()
    assert np.allclose(w_t[refl], w_w[refl] * Fc / F, rtol=1e-12)
    assert np.allclose(w_t[refr], w_w[refr] * (1 - Fc) / (1 - F), rtol=1e-12)
    params = dict(transmission=1.0, roughness=0.4, ior=1.6, base_color=(1.0,) * 3,
                  specular_tint=(0.2, 1.0, 2.5))
    for deg in (20.0, 70.0):
        mc, quad, _ = albedo_both_ways(params, deg)
        assert np.allclose(mc, quad, rtol=0.01, atol=2e-3), (deg, mc, quad)
