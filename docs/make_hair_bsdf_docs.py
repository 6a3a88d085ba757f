"""Renders the scene of tests/test_hair_bsdf_vs_cycles.py (the Hair BSDF node on particle
hair and on meshes) with DRT and with Cycles and writes docs/hair_bsdf.md: the images side
by side, the test's comparison and its control, and what the node costs a render.

    .venv/bin/python docs/make_hair_bsdf_docs.py

Takes about 3 minutes on 2 cores.
"""
from __future__ import annotations

import os
import platform
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests"), os.path.join(ROOT, "docs")]
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")

from make_comparisons import pct, side_by_side  # noqa: E402
from make_hair_docs import _render  # noqa: E402
from test_multiscatter_vs_cycles import compare  # noqa: E402

TEST_DRT, TEST_CYCLES = 256, 512       # the test's samples, at its 64 x 48 pixels
BIG, BIG_SAMPLES = 300, 128            # the images: 192 x 144 pixels


def main():
    import bpy
    import drt_addon
    drt_addon.register()
    from test_hair_bsdf_vs_cycles import _as_diffuse, _scene
    os.makedirs(IMAGES, exist_ok=True)
    tmp = tempfile.mkdtemp()
    scene = _scene(bpy)
    cycles, _ = _render(bpy, scene, "CYCLES", TEST_CYCLES)
    drt, _ = _render(bpy, scene, "DRT", TEST_DRT)
    rel, block = compare(drt, cycles)
    pngs = [os.path.join(tmp, f"{e}.png") for e in ("drt", "cycles")]
    _render(bpy, scene, "DRT", 4, BIG)                 # compiled and warm
    _, t_drt = _render(bpy, scene, "DRT", BIG_SAMPLES, BIG, pngs[0])
    _, t_cyc = _render(bpy, scene, "CYCLES", BIG_SAMPLES, BIG, pngs[1])
    side_by_side(pngs, [f"DRT {BIG_SAMPLES} spp, {t_drt:.1f} s",
                        f"Cycles {BIG_SAMPLES} spp, {t_cyc:.1f} s"],
                 os.path.join(IMAGES, "hair_bsdf.png"))
    _as_diffuse(bpy)
    control, _ = _render(bpy, scene, "DRT", TEST_DRT)
    c_rel, c_block = compare(control, cycles)
    _, t_diffuse = _render(bpy, scene, "DRT", BIG_SAMPLES, BIG)
    lines = [
        "# The Hair BSDF node",
        "",
        "DRT renders Blender's Hair BSDF node as Cycles does (its closures",
        "`bsdf_hair_reflection` and `bsdf_hair_transmission`, after Open Shading",
        "Language): the Reflection component reflects about the fibre's direction, the",
        "Transmission component lets light through the fibre to the far side, each with",
        "RoughnessU (along the fibre), RoughnessV (around it) and Offset (the cuticle's",
        "tilt), and each sample of a lobe weighs its colour (`engine/kernels/bsdf/hair.py`).",
        "The fibre's direction is a strand's tangent, or on a mesh the second edge of",
        "the triangle hit, where Cycles also drops the Offset",
        "(`engine/kernels/hair_tangent.py`). As in Cycles, a sampled direction may leave",
        "on either side of the surface: on a mesh, paths go into it.",
        "",
        "![DRT and Cycles](images/hair_bsdf.png)",
        "",
        "The scene of `tests/test_hair_bsdf_vs_cycles.py`: 300 particle hairs mixing the",
        "node's Reflection (Offset 2 degrees, RoughnessU 0.2) and Transmission (RoughnessV",
        "0.7) half and half; a smooth cylinder resting on the floor with the node's",
        "Reflection at its defaults (as the public file Untid.blend has it); a sphere",
        "mixing Reflection with a Diffuse BSDF. A point lamp of radius 0.3 m, a dim",
        f"world. {BIG}% of the test's 64 x 48 pixels, {BIG_SAMPLES} samples in both, on",
        "this machine's 2 cores.",
        "",
        "## Against Cycles",
        "",
        f"The test renders DRT {TEST_DRT} samples against Cycles {TEST_CYCLES}, at 64 x 48",
        "pixels, and allows 2 % on each channel mean and 5 % on any 8 x 8 block. The",
        "control must fail it: every Hair BSDF replaced by a Diffuse BSDF of its colour,",
        "what DRT rendered before (with a warning).",
        "",
        "| | channel means | worst block |",
        "|---|---|---|",
        f"| DRT against Cycles | {pct(rel)} | {100 * block:.2f}% |",
        f"| control: Diffuse BSDFs | {pct(c_rel)} | {100 * c_block:.2f}% |",
        "",
        "Found on the way, and fixed for every material: the lights a surface point picks",
        "from are weighed on the surface's own normal (Cycles' `sd->N`) and those wholly",
        "under it are left to the BSDF's rays, as Cycles' light tree does, also where a",
        "lobe's normal is bent (a smooth mesh's silhouette, a Normal Map). DRT counted",
        "them in next-event estimation on the bent normal, where the lobes give them",
        "nothing, which took their weight from the rays that reach them: the cylinder's",
        "bottom rim, lit through its tilted smooth normals, was 30 % too dark in one",
        "8 x 8 block (128 x 96 pixels, 1024 samples).",
        "",
        "## What it costs",
        "",
        "A material without a Hair BSDF runs none of its code: its row's hair flag is 0,",
        "so the integrator writes no fibre direction and the lobes are never set up",
        "(`tests/test_hair_bsdf.py`). The scene above with Diffuse BSDFs in place of",
        f"the Hair BSDFs: {t_diffuse:.1f} s against {t_drt:.1f} s for the same render.",
        "",
        "## Not yet",
        "",
        "- A linked Tangent input is reported and left out (DRT shades about the strand or",
        "  the triangle edge, Cycles' default).",
        "- On a mesh with a mirroring transform (negative scale) DRT swaps two corners of",
        "  each triangle to keep its normal, so the fibre direction is the other edge.",
        "- The Principled Hair BSDF: [principled_hair.md](principled_hair.md).",
        "",
        f"Written by `docs/make_hair_bsdf_docs.py` on {platform.machine()}, "
        f"{os.cpu_count()} cores, Python {platform.python_version()}.",
        "",
    ]
    with open(os.path.join(DOCS, "hair_bsdf.md"), "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
