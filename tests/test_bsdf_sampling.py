"""Chi-square tests of every BSDF sampling routine against its own pdf (tests/chi2.py):
the compiled lobes and the Principled mixture the renderer runs, through their array
drivers (engine/kernels/bsdf/lobe_batch.py, batch.py).

Each case draws 200k directions for one incident direction (0, 45 and 85 degrees from the
normal) and compares the histogram over adaptive (cos theta, phi) cells with the pdf
integrated over the cells. Rejected samples are one more bin, so the pdf must also
integrate to the probability of producing a sample. The significance 0.01 is
Sidak-corrected for the number of chi-square tests in this file (N_TESTS), so a correct
implementation fails the whole file with probability 1 %; the seeds are fixed, so the
outcome is deterministic. The negative controls (a pdf 10 % too large on half the
sphere, a GGX pdf with alpha 10 % off) must fail at the same threshold.
"""
from __future__ import annotations

import numpy as np
import pytest

from chi2 import chi2_test
from engine.kernels import bsdf as kb
from engine.kernels.bsdf import lobe_batch as lb
from engine.kernels.bsdf.batch import Principled
from engine.kernels.bsdf.principled import DIFFUSE, GLOSSY, TRANSMISSION
from engine.warp import cosine_hemisphere

N = 200_000
ANGLES = (0.0, 45.0, 85.0)


def wo_at(deg, n, below=False):
    t = np.radians(deg)
    z = -np.cos(t) if below else np.cos(t)
    return np.tile([np.sin(t), 0.0, z], (n, 1))


# --- the cases ---------------------------------------------------------------------------

def case_cosine(_):
    def sample(u):
        return cosine_hemisphere(u[:, 1:]), np.ones(len(u), bool)
    return sample, lambda w: np.maximum(w[:, 2], 0.0) / np.pi


def case_blinn_phong(deg, exponent):
    def sample(u):
        return lb.blinn_phong_sample(wo_at(deg, len(u)), u[:, 1:], exponent)
    return sample, lambda w: lb.blinn_phong_eval(wo_at(deg, len(w)), w, exponent)[1]


def case_vndf(deg, alpha, pdf_alpha=None):
    """The visible normals themselves: h ~ D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo_z
    (Heitz 2014, eq. 2, composed here from the kernels' D and G1)."""
    pa = alpha if pdf_alpha is None else pdf_alpha

    def sample(u):
        h = lb.ggx_visible_normal(wo_at(deg, len(u)), alpha, u[:, 1:])
        return h, np.ones(len(u), bool)

    def pdf(h):
        wo = wo_at(deg, len(h))
        return (lb.ggx_G1_over_cos(wo, pa) * np.maximum((wo * h).sum(1), 0.0)
                * lb.ggx_D(h, pa))
    return sample, pdf


def case_ggx_reflection(deg, alpha):
    def sample(u):
        wi, _, valid = lb.ggx_reflection_sample(wo_at(deg, len(u)), alpha, u[:, 1:])
        return wi, valid
    return sample, lambda w: lb.ggx_reflection_pdf(wo_at(deg, len(w)), w, alpha)


def case_rough_dielectric(deg, eta, alpha, below=False, allow_r=True, allow_t=True):
    def sample(u):
        wi, _, _, valid, _ = lb.rough_dielectric_sample(
            wo_at(deg, len(u), below), eta, alpha, u[:, 0], u[:, 1:], allow_r, allow_t)
        return wi, valid

    def pdf(w):     # the sampler's own density (not Cycles' MIS pdf, see dielectric.py)
        return lb.rough_dielectric_pdf(wo_at(deg, len(w), below), w, eta, alpha, allow_r,
                                       allow_t, walter=True)
    return sample, pdf


PRINCIPLED = {
    # every lobe present: diffuse, specular (level 0.7), metal, rough glass
    "all_lobes": dict(base_color=(0.8, 0.5, 0.3), metallic=0.3, transmission=0.4,
                      roughness=0.5, ior=1.45, specular_ior_level=0.7, front_facing=True),
    # seen from inside a rough glass (relative IOR 1/1.5) with diffuse and specular
    "back_face_glass": dict(base_color=(0.9, 0.9, 0.9), metallic=0.0, transmission=0.6,
                            roughness=0.3, ior=1.5, specular_ior_level=0.5, front_facing=False),
    # the lecture's Blinn-Phong distribution in the specular and metal lobes
    "blinn_phong": dict(base_color=(0.7, 0.6, 0.2), metallic=0.5, transmission=0.0,
                        roughness=0.3, ior=1.5, specular_ior_level=0.5, front_facing=True,
                        blinn_phong=True),
    # Multiscatter GGX: every lobe compensated, which changes the lobe selection
    "all_lobes_multiscatter": dict(base_color=(0.8, 0.5, 0.3), metallic=0.3,
                                   transmission=0.4, roughness=0.7, ior=1.45,
                                   specular_ior_level=0.7, front_facing=True,
                                   multiscatter=True),
    "back_face_glass_multiscatter": dict(base_color=(0.9, 0.7, 0.9), metallic=0.0,
                                         transmission=0.6, roughness=0.9, ior=1.5,
                                         specular_ior_level=0.5, front_facing=False,
                                         multiscatter=True),
}
ALLOWED = {
    "all": (True, True, True),
    "transmission_only": (False, False, True),
    "no_transmission": (True, True, False),
}


def make_principled(params, n):
    """n hits of the material `params`, refraction evaluated on Walter's pairs only (the
    sampler's own density; Cycles' extra pairs: kernels/bsdf/dielectric.py)."""
    p = params
    model = (kb.GLOSSY_BLINN_PHONG if p.get("blinn_phong") else
             kb.GLOSSY_MULTI_GGX if p.get("multiscatter") else kb.GLOSSY_GGX)
    return Principled.with_params(np.tile(p["base_color"], (n, 1)), p["metallic"],
                                  p["transmission"], p["roughness"], p["ior"],
                                  p["specular_ior_level"], p["front_facing"], model,
                                  walter=True)


def case_principled(deg, name, allowed="all", diffuse_n=(0.0, 0.0, 1.0)):
    params = PRINCIPLED[name]
    mask = np.array(ALLOWED[allowed], bool)

    def sample(u):
        n = len(u)
        s = make_principled(params, n).sample(wo_at(deg, n), u[:, 0], u[:, 1:],
                                              np.tile(mask, (n, 1)), diffuse_n)
        assert not s.delta.any()
        return s.wi, s.valid

    def pdf(w):
        n = len(w)
        return make_principled(params, n).pdf(wo_at(deg, n), w, np.tile(mask, (n, 1)),
                                              diffuse_n)
    return sample, pdf


# a bent frame's raw normal, 40 degrees off the frame's (principled.bend_diffuse): the
# diffuse lobe is drawn about it, partly under the frame's plane
BENT = (np.sin(np.radians(40.0)) * np.cos(1.0), np.sin(np.radians(40.0)) * np.sin(1.0),
        np.cos(np.radians(40.0)))


CASES = [("cosine", case_cosine, (None,))]
CASES += [(f"blinn_phong-n{e:g}-{d:g}deg", case_blinn_phong, (d, e))
          for e in (1.0, 20.0, 1000.0) for d in ANGLES]
CASES += [(f"ggx_vndf-a{a:g}-{d:g}deg", case_vndf, (d, a))
          for a in (0.05, 0.3, 1.0) for d in ANGLES]
CASES += [(f"ggx_reflection-a{a:g}-{d:g}deg", case_ggx_reflection, (d, a))
          for a in (0.05, 0.3, 1.0) for d in ANGLES]
CASES += [(f"rough_dielectric-eta{eta:.3g}-a{a:g}-{d:g}deg", case_rough_dielectric, (d, eta, a))
          for eta in (1.5, 1 / 1.5) for a in (0.1, 0.5) for d in ANGLES]
CASES += [("rough_dielectric-from_inside-45deg", case_rough_dielectric, (45.0, 1.5, 0.3, True)),
          ("rough_dielectric-reflect_only-45deg", case_rough_dielectric,
           (45.0, 1.5, 0.3, False, True, False)),
          ("rough_dielectric-refract_only-85deg", case_rough_dielectric,
           (85.0, 1 / 1.5, 0.3, False, False, True))]
CASES += [(f"principled-{m}-{d:g}deg", case_principled, (d, m))
          for m in PRINCIPLED for d in ANGLES]
CASES += [(f"principled-{m}-{a}-45deg", case_principled, (45.0, m, a))
          for m in ("all_lobes", "all_lobes_multiscatter")
          for a in ("transmission_only", "no_transmission")]
CASES += [(f"principled-{m}-bent_diffuse-{d:g}deg", case_principled, (d, m, "all", BENT))
          for m in ("all_lobes", "blinn_phong") for d in (0.0, 85.0)]

# every chi-square test run by this file, including the negative controls
N_TESTS = len(CASES) + 2


@pytest.mark.parametrize("name,make,args", CASES, ids=[c[0] for c in CASES])
def test_sampling_matches_pdf(name, make, args):
    sample, pdf = make(*args)
    seed = sum(ord(ch) * (i + 1) for i, ch in enumerate(name))
    res = chi2_test(sample, pdf, N, seed=seed, n_tests=N_TESTS)
    print(f"{name}: {res}")
    assert res.passed, f"{name}: {res}"
    # the pdf must carry (almost) all the mass of what is sampled
    assert abs(res.pdf_integral - res.valid_fraction) < 0.01, str(res)


def test_negative_control_pdf_too_large_on_half_the_sphere():
    """A pdf that is 10 % too large where y > 0 must fail the harness."""
    sample, pdf = case_cosine(None)
    res = chi2_test(sample, lambda w: pdf(w) * np.where(w[:, 1] > 0, 1.1, 1.0), N, seed=7,
                    n_tests=N_TESTS)
    print(f"negative control (pdf x1.1 on y > 0): {res}")
    assert not res.passed
    assert res.p_value < res.threshold


def test_negative_control_wrong_roughness():
    """VNDF samples with alpha 0.3 against the pdf of alpha 0.33 must fail."""
    sample, pdf = case_vndf(45.0, 0.3, pdf_alpha=0.33)
    res = chi2_test(sample, pdf, N, seed=11, n_tests=N_TESTS)
    print(f"negative control (alpha 0.3 vs 0.33): {res}")
    assert not res.passed


def test_lobe_kinds_follow_allowed_mask():
    """Sampled kinds respect `allowed`: transmission only -> every valid sample refracts
    (goes below the surface); no transmission -> nothing does."""
    n = 20_000
    rng = np.random.default_rng(3)
    b = make_principled(PRINCIPLED["all_lobes"], n)
    wo = wo_at(30.0, n)
    for mask, want in (((False, False, True), {TRANSMISSION}),
                       ((True, True, False), {DIFFUSE, GLOSSY})):
        s = b.sample(wo, rng.random(n), rng.random((n, 2)), np.tile(mask, (n, 1)))
        assert s.valid.mean() > 0.5
        assert set(np.unique(s.kind[s.valid]).tolist()) == want
        below = s.wi[s.valid, 2] < 0
        assert np.array_equal(below, s.kind[s.valid] == TRANSMISSION)
