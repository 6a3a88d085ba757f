"""Lamp light through rough glass against Cycles (docs/comparisons.md, known difference
3): a rough glass sphere (Glass BSDF, roughness 0.67, IOR 1.45) before a 2 m area lamp
that it hides from the camera, black world, 32 x 32 pixels, Cycles 2048 samples per
pixel, DRT 1024; the distribution, Filter Glossy and clamps as named per test.

Cycles evaluates a rough glass's refraction at every pair of directions on opposite
sides of the surface from the generalised half vector alone, also where that vector is
not a microfacet normal that refracts one direction into the other (engine/kernels/
bsdf/dielectric.py's note). Sampling never produces those pairs, so they add light through
next-event estimation only: a lamp seen through rough glass is brighter in Cycles than
in an estimator of Walter's BTDF. DRT does the same. Roughness 0.67, DRT against Cycles,
image mean (DRT with two seeds where given):

  distribution, Filter Glossy       before (Walter's pairs)   after
  GGX, 0 (no clamps)                -0.78 %                   -0.04 %, -0.15 %
  Multiscatter GGX, 0 (no clamps)   -1.04 %                   +0.25 %, +0.12 %
  Multiscatter GGX, 1 (defaults)    -1.35 %                   +0.22 %

(Cycles against itself with another seed: 0.01 %.) MEAN_TOLERANCE = 0.5 % fails every
"before". The +0.1 to +0.25 % left with Multiscatter GGX is within DRT's noise here
(0.13 % between its seeds) and not resolved.

`test_cycles_pairs_add_what_cycles_formula_adds` checks the added light per direction
against an independent quadrature of Cycles' refraction formula.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import render_current
from engine.kernels.bsdf import lobe_batch
from test_closures_vs_cycles import _area, _camera, _fresh, _material, _sphere

MEAN_TOLERANCE = 0.005
_renders = {}


def rough_glass_scene(bpy, roughness, filter_glossy, distribution="MULTI_GGX"):
    scene = _fresh(bpy)
    scene.render.resolution_x = scene.render.resolution_y = 32
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.cycles.blur_glossy = filter_glossy
    if filter_glossy == 0.0:
        scene.cycles.sample_clamp_indirect = scene.cycles.sample_clamp_indirect = 0.0
    _camera(scene, bpy, (0.0, -4.0, 0.0), (90.0, 0.0, 0.0), lens=50.0)
    _area(scene, bpy, (0.0, 3.0, 0.0), (-90.0, 0.0, 0.0), 2.0, 200.0)
    mat, nodes, links, out = _material(bpy, "RoughGlass")
    glass = nodes.new("ShaderNodeBsdfGlass")          # Multiscatter GGX, Blender's default
    glass.distribution = distribution
    glass.inputs["IOR"].default_value = 1.45
    glass.inputs["Roughness"].default_value = roughness
    links.new(glass.outputs[0], out.inputs["Surface"])
    _sphere(bpy, (0.0, 0.0, 0.0), 1.0, mat)
    return scene


def render(bpy, engine, roughness, filter_glossy, distribution):
    key = (engine, roughness, filter_glossy, distribution)
    if key not in _renders:
        scene = rough_glass_scene(bpy, roughness, filter_glossy, distribution)
        scene.render.engine = engine
        c = scene.cycles
        c.samples, scene.drt.samples = 2048, 1024
        c.use_denoising = c.use_adaptive_sampling = False
        c.device = "CPU"
        _renders[key] = render_current(bpy, scene)
    return _renders[key]


@pytest.mark.parametrize("distribution,filter_glossy", [("GGX", 0.0), ("MULTI_GGX", 1.0)])
def test_lamp_through_rough_glass_matches_cycles(bpy_drt, distribution, filter_glossy):
    cycles = render(bpy_drt, "CYCLES", 0.67, filter_glossy, distribution)
    drt = render(bpy_drt, "DRT", 0.67, filter_glossy, distribution)
    assert np.isfinite(drt).all() and cycles.mean() > 0.05
    rel = drt.mean() / cycles.mean() - 1.0
    print(f"rough glass {distribution}, Filter Glossy {filter_glossy}: DRT {drt.mean():.5f}, "
          f"Cycles {cycles.mean():.5f}, {100 * rel:+.2f} %")
    assert abs(rel) <= MEAN_TOLERANCE, rel


def _cycles_refraction(mu, alpha, ior, n):
    """Integral over the far hemisphere of Cycles' refraction eval (its cosine included,
    Fresnel of |cos|), written from its formula: D(h) |h.wi| |h.wo| ior^2 (1 - F) G2 /
    (cos_i |ior wo + wi|^2), h ~ -(ior wo + wi), wi the view direction at cos mu. Returns
    (every pair, the pairs with wi.h > 0 > wo.h for h facing the normal)."""
    a2 = alpha * alpha
    wi = np.array([math.sqrt(1.0 - mu * mu), 0.0, mu])
    ct = -(np.arange(n) + 0.5) / n
    ph = (np.arange(2 * n) + 0.5) * (math.pi / n)
    CT, PH = np.meshgrid(ct, ph, indexing="ij")
    st = np.sqrt(1.0 - CT * CT)
    wo = np.stack([st * np.cos(PH), st * np.sin(PH), CT], -1)
    H = -(ior * wo + wi)
    len2 = (H * H).sum(-1)
    H /= np.sqrt(len2)[..., None]
    c_hi, c_ho = H @ wi, (H * wo).sum(-1)
    d = a2 / (math.pi * (1.0 + (a2 - 1.0) * H[..., 2] ** 2) ** 2)

    def lam(c):
        return 0.5 * (np.sqrt(1.0 + a2 * (1.0 - c * c) / (c * c)) - 1.0)
    g = np.sqrt(ior * ior - 1.0 + c_hi * c_hi + 0j).real          # Fresnel of |cos|
    c = np.abs(c_hi)
    F = np.where(ior * ior - 1.0 + c * c > 0,
                 0.5 * ((g - c) / (g + c)) ** 2
                 * (1.0 + ((c * (g + c) - 1.0) / (c * (g - c) + 1.0)) ** 2), 1.0)
    val = (1.0 - F) * d / mu * ior * ior * np.abs(c_hi * c_ho) / len2 \
        / (1.0 + lam(mu) + lam(np.abs(CT)))
    m = H * np.sign(H[..., 2:3])
    walter = ((m @ wi) > 0) & ((m * wo).sum(-1) < 0)
    dw = (1.0 / n) * (math.pi / n)
    return val.sum() * dw, (val * walter).sum() * dw


@pytest.mark.parametrize("mu,alpha,ior", [(0.95, 0.45, 1.45), (0.4, 0.45, 1.45),
                                          (0.7, 0.6, 1 / 1.45), (0.4, 0.6, 1 / 1.45)])
def test_cycles_pairs_add_what_cycles_formula_adds(mu, alpha, ior):
    """DRT's refraction integrated over the far hemisphere, with and without Cycles'
    extra pairs, against the same integrals of Cycles' formula (neither carries a
    radiance factor 1 / ior^2: engine/kernels/bsdf/dielectric.py)."""
    n = 600
    ct = -(np.arange(n) + 0.5) / n
    ph = (np.arange(2 * n) + 0.5) * (math.pi / n)
    CT, PH = np.meshgrid(ct, ph, indexing="ij")
    st = np.sqrt(1.0 - CT * CT)
    wi = np.stack([st * np.cos(PH), st * np.sin(PH), CT], -1).reshape(-1, 3)
    wo = np.tile([math.sqrt(1.0 - mu * mu), 0.0, mu], (len(wi), 1))
    # DRT's material IOR is relative to the outside; ior < 1 is the view from inside
    eta, flip = (ior, 1.0) if ior > 1.0 else (1.0 / ior, -1.0)
    wo_s, wi_s = wo * [1.0, 1.0, flip], wi * [1.0, 1.0, flip]
    dw = (1.0 / n) * (math.pi / n)
    cos = np.abs(wi[:, 2]) * dw
    both = [lobe_batch.rough_dielectric_eval(wo_s, wi_s, eta, alpha, walter=w)[1]
            for w in (False, True)]
    drt_all, drt_walter = ((f * cos).sum() for f in both)
    cyc_all, cyc_walter = _cycles_refraction(mu, alpha, ior, n)
    print(f"mu {mu}, alpha {alpha}, ior {ior:.3f}: DRT {drt_all:.4f} / {drt_walter:.4f}, "
          f"Cycles' formula {cyc_all:.4f} / {cyc_walter:.4f}")
    assert cyc_all > 1.04 * cyc_walter                 # the extra pairs matter here
    assert drt_walter == pytest.approx(cyc_walter, rel=2e-3)
    assert drt_all == pytest.approx(cyc_all, rel=2e-3)
