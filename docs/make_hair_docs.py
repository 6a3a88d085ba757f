"""Renders the hair scene of tests/test_hair_vs_cycles.py with DRT and with Cycles and
writes docs/hair.md: the images side by side, the comparison the test makes and its
control, the difference that remains on thick strands seen end-on (and its cause), and
what hair costs: export, acceleration structure, memory and time per sample.

    .venv/bin/python docs/make_hair_docs.py

Takes about 5 minutes on 2 cores.
"""
from __future__ import annotations

import os
import platform
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests"), os.path.join(ROOT, "docs")]
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")

from make_comparisons import pct, save_png, side_by_side  # noqa: E402
from test_multiscatter_vs_cycles import compare  # noqa: E402

TEST_DRT, TEST_CYCLES = 256, 512       # the test's samples, at its 64 x 48 pixels
BIG, BIG_SAMPLES = 300, 128            # the images: 192 x 144 pixels
THICK = 4.0                            # Diameter Root of the end-on case (default 1)


def _render(bpy, scene, engine, samples, percentage=100, png=None):
    from conftest import render_current, use_engine
    scene.render.resolution_percentage = percentage
    use_engine(scene, engine, samples)
    t0 = time.perf_counter()
    img = render_current(bpy, scene)
    seconds = time.perf_counter() - t0
    if png is not None:
        save_png(bpy, scene, png)
    return img, seconds


def _silhouette(bpy, scene):
    """The scene as coverage: the fur emits white, everything else is black."""
    scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    for o in list(bpy.data.objects):
        if o.type == "LIGHT" or o.name.startswith("Plane") or o.name == "Curls":
            bpy.data.objects.remove(o)
    for name, emit in (("fur", 1.0), ("skin", 0.0)):
        p = bpy.data.materials[name].node_tree.nodes["Principled BSDF"]
        p.inputs["Base Color"].default_value = (0, 0, 0, 1)
        p.inputs["Specular IOR Level"].default_value = 0.0
        p.inputs["Emission Color"].default_value = (1, 1, 1, 1)
        p.inputs["Emission Strength"].default_value = emit


def _costs(bpy, strands):
    """(export seconds of the hair, Embree build seconds, seconds per sample with and
    without the hair, strands, keys) of the test scene with `strands` parent hairs at
    Render Steps 3, rendered by F12 at 64 x 48 pixels."""
    from drt_addon import render_engine
    from test_hair_vs_cycles import _scene
    out = {}
    for hair in (True, False):
        scene = _scene(bpy)
        bpy.data.objects["Sphere"].particle_systems[0].settings.count = strands
        bpy.context.view_layer.use_strand = hair
        _render(bpy, scene, "DRT", 4)               # compiled, warm
        _, seconds = _render(bpy, scene, "DRT", 32)
        last = render_engine.last_render
        out[hair] = (last["export_stats"]["seconds"], last["build_seconds"], seconds / 32,
                     last["scene"])
    s = out[True][3]
    keys = sum(len(c.keys) for c in s.curves)
    return (out[True][0] - out[False][0], out[True][1] - out[False][1], out[True][2],
            out[False][2], sum(c.curve_count for c in s.curves), keys)


def main():
    import bpy
    import drt_addon
    drt_addon.register()
    from test_hair_vs_cycles import _scene
    os.makedirs(IMAGES, exist_ok=True)
    tmp = tempfile.mkdtemp()
    lines = []
    # the test's comparison, and its control
    scene = _scene(bpy)
    cycles, _ = _render(bpy, scene, "CYCLES", TEST_CYCLES)
    drt, _ = _render(bpy, scene, "DRT", TEST_DRT)
    rel, block = compare(drt, cycles)
    bpy.context.view_layer.use_strand = False
    bald, _ = _render(bpy, scene, "DRT", TEST_DRT)
    c_rel, c_block = compare(bald, cycles)
    bpy.context.view_layer.use_strand = True
    nt = bpy.data.materials["fur"].node_tree
    link = nt.nodes["Color Ramp"].inputs["Fac"].links[0]
    source = link.from_socket
    nt.links.remove(link)
    nt.nodes["Color Ramp"].inputs["Fac"].default_value = 0.5
    flat, _ = _render(bpy, scene, "DRT", TEST_DRT)
    f_rel, f_block = compare(flat, cycles)
    nt.links.new(source, nt.nodes["Color Ramp"].inputs["Fac"])
    # the images
    pngs = [os.path.join(tmp, f"{e}.png") for e in ("drt", "cycles")]
    _, t_drt = _render(bpy, scene, "DRT", BIG_SAMPLES, BIG, pngs[0])
    _, t_cyc = _render(bpy, scene, "CYCLES", BIG_SAMPLES, BIG, pngs[1])
    side_by_side(pngs, [f"DRT {BIG_SAMPLES} spp, {t_drt:.0f} s",
                        f"Cycles {BIG_SAMPLES} spp, {t_cyc:.0f} s"],
                 os.path.join(IMAGES, "hair.png"))
    # thick strands seen end-on: the shaded comparison and the silhouettes
    scene = _scene(bpy)
    bpy.data.objects["Sphere"].particle_systems[0].settings.root_radius = THICK
    t_cycles, _ = _render(bpy, scene, "CYCLES", TEST_CYCLES)
    t_drt, _ = _render(bpy, scene, "DRT", TEST_DRT)
    k_rel, k_block = compare(t_drt, t_cycles)
    _silhouette(bpy, scene)
    sil_c, _ = _render(bpy, scene, "CYCLES", 16, 400)
    sil_d, _ = _render(bpy, scene, "DRT", 16, 400)
    only_drt = float(np.mean((sil_d[..., 0] > 0.5) & (sil_c[..., 0] < 0.1)))
    only_cyc = float(np.mean((sil_c[..., 0] > 0.5) & (sil_d[..., 0] < 0.1)))
    cov_c, cov_d = float(sil_c[..., 0].mean()), float(sil_d[..., 0].mean())
    # costs
    costs = {n: _costs(bpy, n) for n in (400, 20000)}
    lines += [
        "# Hair",
        "",
        "DRT draws a mesh's particle hair and hair Curves objects as Cycles draws them with",
        "its default curve shape (Render > Curves > Shape: 3D Curves): each strand is a",
        "round tube swept along a Catmull-Rom spline through its keys, its radius",
        "interpolated along it, intersected exactly by Embree's round Catmull-Rom curves",
        "(`engine/curves.py`, `engine/kernels/curve_hit.py`). What the strands are is read",
        "as Cycles reads it (`drt_addon/export/hair.py`):",
        "",
        "- particle hair (a Particle System modifier enabled for renders, Hair, Render As",
        "  Path): the parents, or the children when there are children; 2^Steps + 1 keys",
        "  each (Render Steps for F12, Viewport Steps in the viewport); the radius from",
        "  Hair Shape (Diameter Root and Tip x Radius Scale / 2, Strand Shape, Close Tip);",
        "  the material of the settings' Material slot; the root's UV on the emitter when",
        "  a material reads UVs;",
        "- Curves objects: their points and `radius` attribute (5 mm where it is",
        "  missing), with the object's first material;",
        "- View Layer > Filter > Curves off draws no hair, as in Cycles.",
        "",
        "The Curves Info node (Hair Info) reads Is Strand, Intercept, Length, Thickness,",
        "Tangent Normal and Random, as Cycles interpolates them; the test scene colours",
        "its fur by Intercept and its curls by Random.",
        "",
        "A strand is shaded like any surface: its normal points from the spline to the",
        "hit point, the same on both sides. As in Cycles, whose Embree is built with",
        "back-face culling of curves, a ray meets a strand only where it enters the tube:",
        "a ray from a strand's surface leaves it freely (`engine/embree/curve_culling.py`,",
        "Embree filter functions: the Embree DRT loads is built without that option).",
        "",
        "![DRT and Cycles](images/hair.png)",
        "",
        "The scene of `tests/test_hair_vs_cycles.py`: a sphere with 400 particle hairs",
        "0.45 m long in a second material slot, at Blender's Hair Shape defaults (1 cm",
        "thick at the root, closed tip), and a Curves object of six curling strands with a",
        f"radius attribute, under a point lamp. {BIG}% of the test's 64 x 48 pixels,",
        f"{BIG_SAMPLES} samples in both, on this machine's 2 cores.",
        "",
        "## Against Cycles",
        "",
        f"The test renders DRT {TEST_DRT} samples against Cycles {TEST_CYCLES}, at 64 x 48",
        "pixels, and allows 2 % on each channel mean and 5 % on any 8 x 8 block. The",
        "controls must fail it: the same DRT render with View Layer > Filter > Curves off",
        "(no hair, as DRT rendered hair before), and with the fur's Color Ramp at its",
        "middle instead of driven by Intercept.",
        "",
        "| | channel means | worst block |",
        "|---|---|---|",
        f"| DRT against Cycles | {pct(rel)} | {100 * block:.2f}% |",
        f"| control: no hair | {pct(c_rel)} | {100 * c_block:.2f}% |",
        f"| control: no Intercept | {pct(f_rel)} | {100 * f_block:.2f}% |",
        "",
        "## A difference that remains: thick strands seen end-on",
        "",
        "Embree built with back-face culling of curves (Cycles' build) keeps, for each",
        "piece of a subdivided segment, only the hits where the ray enters the piece's",
        "bounding shell; a ray running nearly along a thick strand, inside the shell's",
        "inner cylinder, finds none there and passes. DRT's culling tests the hit's own",
        "normal, so it draws the strand's end-on cross-section, which Cycles leaves out,",
        "and it leaves out the inside of a strand's open root that Cycles shows. The",
        "difference grows with the strands' thickness over their length; it sits at the",
        "roots of strands that point towards the camera. With the test's",
        f"hairs {THICK:g} times thicker than Blender's default (Diameter Root {THICK:g}):",
        "",
        "| | DRT against Cycles |",
        "|---|---|",
        f"| shaded, channel means | {pct(k_rel)} |",
        f"| shaded, worst block | {100 * k_block:.2f}% |",
        f"| fur coverage (emissive fur, 256 x 192 pixels) | {cov_d:.4f} against {cov_c:.4f} "
        f"({100 * (cov_d / cov_c - 1):+.1f}%) |",
        f"| pixels only DRT covers / only Cycles covers | {100 * only_drt:.2f}% / "
        f"{100 * only_cyc:.2f}% |",
        "",
        "## What hair costs",
        "",
        "F12 of the test scene at 64 x 48 pixels, 32 samples, with the sphere's parent",
        "hairs at two counts (Render Steps 3: 9 keys each), against the same scene with",
        "View Layer > Filter > Curves off. A scene without hair builds no curve geometry",
        "(`tests/test_hair.py`); its kernels compare each hit's id with the hair's range",
        "and skip the curve code.",
        "",
        "| strands | keys | export of the hair (s) | acceleration structure and tables "
        "of the hair (s) | s per sample with hair | without |",
        "|---|---|---|---|---|---|",
    ]
    for n, (exp, build, with_, without, count, keys) in costs.items():
        lines.append(f"| {count} | {keys} | {exp:.2f} | {build:.3f} | {with_:.3f} | "
                     f"{without:.3f} |")
    lines += [
        "",
        "## Not yet",
        "",
        "- The Principled Hair BSDF's Huang model renders with the Chiang model's",
        "  closure, reported ([principled_hair.md](principled_hair.md); the Hair BSDF",
        "  node: [hair_bsdf.md](hair_bsdf.md)).",
        "- Curves > Shape Ribbons (DRT draws 3D curves, and warns); poly-type Curves",
        "  objects, which Cycles draws as straight round segments (DRT draws the spline",
        "  through the same points).",
        "- Motion blur of hair: strands stand still, where they are at the frame.",
        "",
        f"Written by `docs/make_hair_docs.py` on {platform.machine()}, "
        f"{os.cpu_count()} cores, Python {platform.python_version()}.",
        "",
    ]
    with open(os.path.join(DOCS, "hair.md"), "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
