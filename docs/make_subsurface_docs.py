"""Renders the subsurface scene (sample_blends/subsurface.blend) with DRT and with Cycles
and writes docs/subsurface.md: the comparison the test makes (64 x 48, DRT 512 against
Cycles 1024 samples, tests/test_subsurface_vs_cycles.py), its control, and larger images
side by side at equal samples with both engines' render times.

    .venv/bin/python docs/make_subsurface_docs.py

Takes about 15 minutes on 2 cores.
"""
from __future__ import annotations

import os
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests"), os.path.join(ROOT, "docs")]
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")
BLEND = os.path.join(ROOT, "sample_blends", "subsurface.blend")

from make_comparisons import pct, render, side_by_side  # noqa: E402
from test_artist_scenes_vs_cycles import _block_mad  # noqa: E402
from test_multiscatter_vs_cycles import compare  # noqa: E402
from test_subsurface_vs_cycles import (BLOCK_MAD_TOLERANCE, BLOCK_TOLERANCE,  # noqa: E402
                                       CYCLES_SAMPLES, DRT_SAMPLES, _burley,
                                       _diffuse_instead)

BIG = 300                 # percent: 192 x 144 pixels
BIG_SAMPLES = 256


def main() -> int:
    import bpy

    import drt_addon
    drt_addon.register()
    cycles, t_cycles = render(bpy, BLEND, "CYCLES", CYCLES_SAMPLES)
    drt, t_drt = render(bpy, BLEND, "DRT", DRT_SAMPLES)
    control, _ = render(bpy, BLEND, "DRT", 128, setup=_diffuse_instead)
    rows = []
    for label, img in (("DRT", drt), ("control: subsurface rendered diffuse, DRT 128",
                                       control)):
        means, block = compare(img, cycles)
        rows.append(f"| {label} | {pct(means)} | {block:.2%} | {_block_mad(img, cycles):.2%} |")
    # every material by Christensen-Burley, in both engines; the control: DRT's random walk
    cycles_b, t_cycles_b = render(bpy, BLEND, "CYCLES", CYCLES_SAMPLES, setup=_burley)
    drt_b, t_drt_b = render(bpy, BLEND, "DRT", DRT_SAMPLES, setup=_burley)
    rows_b = []
    for label, img in (("DRT, Christensen-Burley", drt_b),
                       ("control: DRT's random walk against Cycles' Burley", drt)):
        means, block = compare(img, cycles_b)
        rows_b.append(f"| {label} | {pct(means)} | {block:.2%} | "
                      f"{_block_mad(img, cycles_b):.2%} |")
    with tempfile.TemporaryDirectory() as tmp:
        pngs = {}
        times = {}
        for engine in ("DRT", "CYCLES"):
            png = os.path.join(tmp, f"{engine}.png")
            _, times[engine] = render(bpy, BLEND, engine, BIG_SAMPLES, percentage=BIG,
                                      png=png)
            pngs[engine] = png
        out = os.path.join(IMAGES, "subsurface.png")
        side_by_side([pngs["DRT"], pngs["CYCLES"]],
                     [f"DRT {BIG_SAMPLES} spp, {times['DRT']:.0f} s",
                      f"Cycles {BIG_SAMPLES} spp, {times['CYCLES']:.0f} s"], out)
    text = f"""# Subsurface scattering

DRT renders subsurface scattering as Cycles does: a random walk below the surface
(Chiang, Kutz and Burley 2016), with Cycles' coefficients, its guided sampling (Dwivedi),
and its entry and exit (`engine/kernels/subsurface.py`, `subsurface_vertex.py`). It
reads the Principled BSDF's Subsurface Weight, Radius, Scale, IOR and Anisotropy with the
Random Walk and Random Walk (Skin) methods, and the Subsurface Scattering node.
Christensen-Burley is rendered by Cycles' disk sampling (`engine/kernels/subsurface_disk.py`;
below).

![DRT and Cycles](images/subsurface.png)

`sample_blends/subsurface.blend`: a Principled skin Suzanne (Random Walk, Scale 0.1,
bumped by a Noise Texture: the walk leaves on the bent normal, as in Cycles), a
wax candle (Random Walk (Skin), Scale 0.05) lit by a flame lamp just above it, and a
marble sphere (a Subsurface Scattering node mixed with a Glossy BSDF). The scene uses
Blender's defaults. The images are {BIG}% of the file's 64 x 48 pixels, at
{BIG_SAMPLES} samples in both engines, rendered on this machine's 2 cores.

## Against Cycles

The test's comparison is DRT {DRT_SAMPLES} samples against Cycles {CYCLES_SAMPLES},
at 64 x 48 pixels. It allows 1 % on each channel mean, {BLOCK_MAD_TOLERANCE:.0%} on the
mean absolute difference of the 8 x 8 block means (block MAD), and
{BLOCK_TOLERANCE:.0%} on any one block. The control renders the subsurface weight as the
diffuse lobe it replaces, and it must fail.

The worst block is the top of the candle, and its error is noise. The candle is lit by
its 4 W flame lamp 6 cm above it, beside an 85 W key lamp and a 50 W rim lamp. With
another sampler seed the same block was 6.3 % off, and the means and the block MAD
stayed where they are. DRT now picks lamps with the light tree, as Cycles does
([light_tree.md](light_tree.md)), which favours the flame near the candle; that left
this block where it was (3.4 % with the tree, 3.5 % picking by power, at this seed).
Its cause is not the lamp pick, and it is not resolved.

| render | mean per channel | worst 8 x 8 block | block MAD |
|---|---|---|---|
{chr(10).join(rows)}

Render times at 64 x 48: DRT {t_drt:.1f} s ({DRT_SAMPLES} samples), Cycles
{t_cycles:.1f} s ({CYCLES_SAMPLES} samples).

## Christensen-Burley

The Subsurface Method (Principled) or Falloff (Subsurface Scattering node) Christensen-Burley
has no walk: light that enters at a point leaves at another point of the same object, at
a distance drawn from Christensen and Burley's radial profile of each channel's Radius x
Scale. The exit is found as Cycles finds it: a probe ray along one of three axes (the
surface's normal with probability 1/2, either tangent with 1/4) from a disk drawn from the
profile, every surface of the object it crosses a candidate weighed by the profile and the
three axes' multiple importance sampling, one candidate kept by resampling (Cycles keeps at
most 4 drawn at random; DRT keeps them all in the reservoir: the same expectation). After a
diffuse bounce the lobe is a diffuse one, as in Cycles. On a plane the estimator returns
the lobe's whole weight, 1 per channel (`tests/test_subsurface_disk.py`).

The same scene with every material set to Christensen-Burley, DRT {DRT_SAMPLES} samples
against Cycles {CYCLES_SAMPLES}, at the tolerances above; the control is DRT's random walk,
which rendered Christensen-Burley before, against Cycles' Burley, and it must fail:

| render | mean per channel | worst 8 x 8 block | block MAD |
|---|---|---|---|
{chr(10).join(rows_b)}

Render times at 64 x 48: DRT {t_drt_b:.1f} s ({DRT_SAMPLES} samples), Cycles
{t_cycles_b:.1f} s ({CYCLES_SAMPLES} samples).

## What it costs

A walk casts one ray per step. Each step stays inside the object and the walk ends
where it leaves. A scene without a subsurface material compiles and runs none of this
code (`tests/test_compile_progress.py`).

## Not modelled

- Textured subsurface parameters: the weight, radius, scale, IOR and anisotropy take
  their average, and the report says so. The base colour, which is the albedo, may be
  textured.

Written by `docs/make_subsurface_docs.py`.
"""
    with open(os.path.join(DOCS, "subsurface.md"), "w") as f:
        f.write(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
