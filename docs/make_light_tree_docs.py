"""Renders the many-lights scene (sample_blends/night_street.blend) and writes
docs/light_tree.md: DRT against Cycles (the test's comparison, measured against a
4096-sample Cycles reference, and its control), and what the light tree buys: the error
of DRT with the tree and without it (lights picked as Cycles' light distribution picks
them), at equal samples and per second
of rendering, against a 4096-sample DRT reference, with images side by side.

    .venv/bin/python docs/make_light_tree_docs.py

Takes about 8 minutes on 2 cores.
"""
from __future__ import annotations

import os
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests"), os.path.join(ROOT, "docs")]
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")
BLEND = os.path.join(ROOT, "sample_blends", "night_street.blend")

from make_comparisons import pct, render, side_by_side  # noqa: E402
from test_artist_scenes_vs_cycles import _block_mad  # noqa: E402
from test_light_tree_vs_cycles import _no_signs  # noqa: E402
from test_multiscatter_vs_cycles import compare  # noqa: E402

REFERENCE = 4096
SAMPLES = (64, 256)
# scenes of a few lights, where the tree has less to gain: what it costs them
FEW_LIGHTS = ("fog_room", "product_shot", "subsurface", "smoke_plume")
COST_SAMPLES = 128


def _tree_off(scene):
    scene.cycles.use_light_tree = False


def _seeded(setup):
    def f(scene):
        scene.cycles.seed = 7                 # not the reference's seed
        if setup is not None:
            setup(scene)
    return f


def rel_mse(img, ref):
    """Mean of (img - ref)^2 / (ref^2 + 0.01) over pixels and channels."""
    return float(np.mean((img - ref) ** 2 / (ref ** 2 + 1e-2)))


def main() -> int:
    import bpy

    import drt_addon
    drt_addon.register()
    cycles_ref, t_ref = render(bpy, BLEND, "CYCLES", REFERENCE)
    cycles, t_cycles = render(bpy, BLEND, "CYCLES", 1024)
    drt, t_drt = render(bpy, BLEND, "DRT", 512)
    control, _ = render(bpy, BLEND, "DRT", 128, setup=_no_signs)
    rows = []
    for label, img, against in (
            ("DRT 512 against Cycles 1024 (the test)", drt, cycles),
            (f"DRT 512 against Cycles {REFERENCE}", drt, cycles_ref),
            (f"Cycles 1024 against Cycles {REFERENCE}", cycles, cycles_ref),
            ("control: the sign lamps left out, DRT 128, against Cycles 1024", control,
             cycles)):
        means, block = compare(img, against)
        rows.append(f"| {label} | {pct(means)} | {block:.2%} | "
                    f"{_block_mad(img, against):.2%} |")
    drt_ref, t_drt_ref = render(bpy, BLEND, "DRT", REFERENCE)
    noise = []
    with tempfile.TemporaryDirectory() as tmp:
        pngs, captions = [], []
        for spp in SAMPLES:
            for label, setup in (("tree", None), ("tree off", _tree_off)):
                png = os.path.join(tmp, f"{label}_{spp}.png") if spp == SAMPLES[0] else None
                img, seconds = render(bpy, BLEND, "DRT", spp, setup=_seeded(setup), png=png)
                err = rel_mse(img, drt_ref)
                noise.append((spp, label, seconds, err))
                if png:
                    pngs.append(png)
                    captions.append(f"{label}, {spp} spp: relMSE {err:.1e}")
        png = os.path.join(tmp, "reference.png")
        render(bpy, BLEND, "CYCLES", 1024, png=png)
        pngs.append(png)
        captions.append("Cycles 1024 spp")
        side_by_side(pngs, captions, os.path.join(IMAGES, "light_tree.png"))
    cost = []
    for name in FEW_LIGHTS:
        path = os.path.join(ROOT, "sample_blends", f"{name}.blend")
        seconds = {}
        for label, setup in (("tree", None), ("tree off", _tree_off)):
            render(bpy, path, "DRT", 4, setup=setup)          # loads, not timed
            seconds[label] = min(render(bpy, path, "DRT", COST_SAMPLES, setup=setup)[1]
                                 for _ in range(2))
        cost.append(f"| {name} | {seconds['tree']:.2f} s | {seconds['tree off']:.2f} s | "
                    f"{seconds['tree'] / seconds['tree off']:.2f}x |")
    table = []
    for spp, label, seconds, err in noise:
        table.append(f"| {spp} | {label} | {seconds:.1f} s | {err:.2e} | {err * seconds:.2e} |")
    gain = {spp: next(e for s, lb, t, e in noise if s == spp and lb == "tree off")
            / next(e for s, lb, t, e in noise if s == spp and lb == "tree") for spp in SAMPLES}
    eff = {spp: next(e * t for s, lb, t, e in noise if s == spp and lb == "tree off")
           / next(e * t for s, lb, t, e in noise if s == spp and lb == "tree")
           for spp in SAMPLES}
    text = f"""# Many lights: the light tree

A scene with many lamps is noisy when every shading point picks its light sample in
proportion to the lamps' power: most samples go to lamps far away. Cycles picks with a
light tree (Conty Estevez and Kulla 2018, on by default since Blender 3.5), and so does
DRT, with Cycles' bounds and choices (`engine/kernels/lights/tree_build.py`, `tree.py`,
`tree_cone.py`):

- a binary tree over the lamps and emissive triangles, built by the surface area
  orientation heuristic over 12 buckets, at most 8 lights a leaf; suns and the world in
  a leaf of their own beside it;
- each node bounds its lights' positions (a box), emission directions (a cone) and
  energy; at a shading point a node's importance is its energy over the squared
  distance times the best cosines its box and cone allow, and DRT, as Cycles, averages
  the probabilities from that upper bound and from the matching lower bound;
- the point's normal matters: lights wholly below an opaque surface get no samples,
  a transmitting surface (or one whose normal a bump bends) takes light from both sides,
  a point in a volume from everywhere;
- the probability of the light a BSDF-sampled ray finds is computed again for the
  previous vertex, walking up from the light's leaf, for multiple importance sampling.

It follows the file's Sampling > Lights > Light Tree (`scene.cycles.use_light_tree`);
off, lights are picked as Cycles' light distribution picks them then: every lamp (and
the world) alike whatever its power, emissive triangles by area, each half of the picks
when there are both (`engine/light_distribution.py`). That is not only noise: where a
bent normal lets next-event estimation take light that BSDF sampling refuses (as Cycles'
closures do), the image depends on the picks (`tests/test_light_distribution_vs_cycles.py`).

![DRT with and without the tree, and Cycles](images/light_tree.png)

`sample_blends/night_street.blend` (`sample_blends/light_tree_scenes.py`): a street at
night with 48 street lamps (every third a spot), 12 small shop-sign lamps of 2 to 6 W,
36 lit windows (an Emission shader: 72 emissive triangles) and a night sky, at Blender's
defaults, 64 x 48 pixels.

## Against Cycles

Against a Cycles reference of {REFERENCE} samples ({t_ref:.0f} s), and in the test's own
comparison (`tests/test_light_tree_vs_cycles.py`: 1 % on each channel mean, 3 % on any
8 x 8 block, 1 % on the block MAD; the control must fail):

| render | mean per channel | worst 8 x 8 block | block MAD |
|---|---|---|---|
{chr(10).join(rows)}

Render times at 64 x 48 on this machine's 2 cores: DRT {t_drt:.1f} s (512 samples), Cycles
{t_cycles:.1f} s (1024 samples).

## What it buys, and what it costs

Error against a DRT reference of {REFERENCE} samples ({t_drt_ref:.0f} s), as relMSE
(the mean of (image - reference)^2 / (reference^2 + 0.01)), with the tree and with lights
picked as Cycles without the tree ("tree off"), each with a sampler seed other than the
reference's:

| samples | lights picked | time | relMSE | relMSE x time |
|---|---|---|---|---|
{chr(10).join(table)}

At equal samples the tree's error is {gain[SAMPLES[0]]:.1f}x ({SAMPLES[0]} samples) and
{gain[SAMPLES[1]]:.1f}x ({SAMPLES[1]} samples) smaller. A pick walks the tree, which
costs more than a search of a CDF, so per second of rendering the gain is
{eff[SAMPLES[0]]:.1f}x and {eff[SAMPLES[1]]:.1f}x. `tests/test_light_tree.py` measures the
variance of a street of 64 lamps at equal samples: the tree's is a fraction of the
pick without it, and both converge to the same image.

A scene with a single light builds no tree and picks nothing. The sample scenes with a
few lights (a lamp and the sky, three lamps and the sky, a sun and the sky) render
{COST_SAMPLES} samples at 64 x 48 in these times (best of two):

| scene | tree | tree off | ratio |
|---|---|---|---|
{chr(10).join(cost)}

In volumes a scattering point picks its light with the tree (no normal). The
equiangular strategy picks its light before it knows its point, for the whole ray
segment through the medium, with the tree's volume form as Cycles does
(`tree_segment.py`: a light's energy times the angle the segment subtends from it, over
its distance to the segment's line; suns and the world, towards which no distance is
sampled, are left to the scattering). The two strategies are weighted by their densities
of the pair (light, distance). `tests/test_lit_fog.py` measures a row of 16 spot beams
in fog: at equal samples the variance with the tree is a fraction of the pick without it.

Written by `docs/make_light_tree_docs.py`.
"""
    with open(os.path.join(DOCS, "light_tree.md"), "w") as f:
        f.write(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
