"""Cycles' light passes and light groups in DRT, against Cycles' own, and writes
docs/passes.md with docs/images/light_passes.png and docs/images/light_groups.png.

The scene is tests/light_pass_scene.py's (diffuse walls, a rough metal sphere, a glass
cube resting on the floor, fog, an emissive panel, an area lamp in group "key", a point
lamp in no group, the world in group "sky", the panel in group "panel"), rendered by
both engines at SAMPLES samples and 2x the test's resolution; then once more with the
glass cube lifted 1 cm off the floor (resting, its bottom face lies in the floor's plane,
which rays leaving the floor must meet as Cycles' do). Every number in the page is
printed here.

    .venv/bin/python docs/make_passes_docs.py

Takes about 3 minutes on 2 cores.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests")]
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")
SIZE = (128, 96)
SAMPLES = 256
KINDS = ("Diffuse", "Glossy", "Transmission")
LIGHT = [f"{k} {p}" for k in KINDS for p in ("Direct", "Indirect", "Color")] + [
    "Volume Direct", "Volume Indirect", "Emission", "Environment"]


def _render(bpy, engine, lift=0.0):
    """{pass name: (h, w, 3)} and seconds of one render of the scene by `engine`."""
    import light_pass_scene as lps
    groups = ["Combined_" + g for g in lps.GROUPS]
    scene = lps.build(bpy, size=SIZE, samples=SAMPLES)
    if lift:
        bpy.data.objects["Glass"].location.z += lift
    t0 = time.perf_counter()
    if engine == "CYCLES":
        scene.render.engine, scene.cycles.device = "CYCLES", "CPU"
        out = lps.cycles_passes(bpy, scene, ["Image"] + LIGHT + groups)
    else:
        out = lps.drt_passes(bpy, LIGHT + groups)
    return out, time.perf_counter() - t0


def _blocks(img, k=8):
    h, w, _ = img.shape
    return img[:h // k * k, :w // k * k].reshape(h // k, k, w // k, k, 3).mean(axis=(1, 3))


def compare(drt, cycles) -> list:
    """(pass, DRT mean, Cycles mean, mean difference and worst 8 x 8 block difference,
    both relative to Cycles' Combined mean) per pass."""
    scale = cycles["Image"].mean()
    rows = []
    for name in ["Image"] + [n for n in drt if n != "Image"]:
        a, b = drt[name], cycles[name]
        rows.append((name, a.mean(), b.mean(), (a.mean() - b.mean()) / scale,
                     np.abs(_blocks(a) - _blocks(b)).max() / scale))
    return rows


def _display(img):
    """Scene-linear RGB to 8-bit-like sRGB for a figure (clipped, no view transform)."""
    x = np.clip(img, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def _figure(columns, rows_of, path, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n_rows, n_cols = len(rows_of), len(columns)
    fig, axes = plt.subplots(n_rows, n_cols, figsize=(2.2 * n_cols, 1.8 * n_rows + 0.4),
                             squeeze=False)
    for i, (label, images) in enumerate(rows_of):
        for j, name in enumerate(columns):
            ax = axes[i][j]
            ax.imshow(_display(images[name]))
            ax.set_xticks([])
            ax.set_yticks([])
            if i == 0:
                ax.set_title(name, fontsize=8)
            if j == 0:
                ax.set_ylabel(label, fontsize=8)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write(rows, lifted, seconds, drt, cycles):
    passes_png = os.path.join(IMAGES, "light_passes.png")
    groups_png = os.path.join(IMAGES, "light_groups.png")
    shown = ["Image", "Diffuse Direct", "Diffuse Indirect", "Diffuse Color", "Glossy Direct",
             "Glossy Indirect", "Transmission Indirect", "Volume Direct", "Emission"]
    _figure(shown, [("DRT", drt), ("Cycles", cycles)], passes_png,
            f"Light passes, {SAMPLES} samples (Image = Combined)")
    for images in (drt, cycles):
        images["no group"] = images["Image"] - sum(images["Combined_" + g]
                                                   for g in ("key", "panel", "sky"))
    _figure(["Image", "Combined_key", "Combined_panel", "Combined_sky", "no group"],
            [("DRT", drt), ("Cycles", cycles)], groups_png,
            "Light groups: key (area lamp), panel (emissive), sky (world); "
            "no group = Combined less the groups (the point lamp)")
    table = ["| pass | DRT mean | Cycles mean | mean difference | worst 8 x 8 block |",
             "|---|---|---|---|---|"]
    for name, a, b, mean, block in rows:
        table.append(f"| {name} | {a:.4f} | {b:.4f} | {mean:+.4f} | {block:.4f} |")
    lift_rows = {r[0]: r for r in lifted}
    lift_table = ["| pass | resting on the floor: mean, worst block | lifted 1 cm: mean, "
                  "worst block |", "|---|---|---|"]
    for name in ("Image", "Transmission Indirect", "Combined_key"):
        r0 = next(r for r in rows if r[0] == name)
        r1 = lift_rows[name]
        lift_table.append(f"| {name} | {r0[3]:+.4f}, {r0[4]:.4f} | {r1[3]:+.4f}, "
                          f"{r1[4]:.4f} |")
    lines = [
        "# Light passes and light groups",
        "",
        "<!-- written by docs/make_passes_docs.py; do not edit by hand -->",
        "",
        "DRT writes Cycles' light passes and light groups, under Cycles' names, when the "
        "view layer asks for them (Properties > View Layer > Passes > Light, and > Light "
        "Groups). The compositor reads them as it reads Cycles': a Render Layers node "
        "has the same sockets.",
        "",
        "- **Diffuse, Glossy, Transmission Direct / Indirect**: the light of paths whose "
        "first scattering was a lobe of that kind (sheen, translucency and subsurface "
        "count as Diffuse; a glass's reflection as Glossy, its refraction as "
        "Transmission), Direct being the light sampled at the first surface and what its "
        "bounce finds, Indirect the rest; divided by that kind's Color, as Cycles writes "
        "them (a channel whose Color is 0 takes the other channels' ratio, as Cycles' film "
        "does, so a pass under a saturated colour stays grey). Where several lobes share a "
        "direction, each gets its part of the BSDF's value there.",
        "- **Diffuse, Glossy, Transmission Color**: what the first surface's lobes of that "
        "kind weigh at the view (their albedo estimates, as Cycles' closure weights).",
        "- **Volume Direct / Indirect**: paths that first scattered in a medium.",
        "- **Emission**: what camera rays see emitted: lamps, emissive surfaces, media.",
        "- **Environment**: the world seen by camera rays (through transparent surfaces, "
        "and on a transparent film too, where Combined leaves it out but the world's light "
        "group keeps it, as in Cycles).",
        "- **Combined_<group>**: the light of the lamps, emissive objects and world of a "
        "light group (Object > Shading > Light Group, World > Settings > Light Group).",
        "",
        "The passes recompose Combined as Cycles': (Diffuse Direct + Indirect) x Diffuse "
        "Color + the same for Glossy and Transmission + Volume Direct + Indirect + "
        "Emission + Environment, per pixel; the light groups plus the light in no group "
        "sum to Combined (tests/test_light_tally.py holds both exactly, "
        "tests/test_light_passes_vs_cycles.py to float32 storage). They cost nothing when "
        "not asked for: the film keeps no channel and the path tracer's tally no row.",
        "",
        f"## Against Cycles ({SIZE[0]} x {SIZE[1]} pixels, {SAMPLES} samples)",
        "",
        "Differences are relative to Cycles' Combined mean. DRT rendered in "
        f"{seconds['DRT']:.1f} s, Cycles in {seconds['CYCLES']:.1f} s.",
        "",
        *table,
        "",
        "![DRT's and Cycles' light passes](images/light_passes.png)",
        "",
        "![DRT's and Cycles' light groups](images/light_groups.png)",
        "",
        "**Glass resting on a surface.** The glass cube's bottom face lies in the floor's "
        "plane, as an object snapped to a floor does. A ray leaving the floor starts on "
        "it, skips only the face it left and crosses the glass's bottom face at distance "
        "0, in DRT as in Cycles (`engine/embree/self_hits.py`), so the light under and "
        "through the cube (all of it Transmission Indirect, and the area lamp's group) "
        "agrees. Until 2026-11-30 DRT started rays a little above the surface they left, "
        "past the coplanar face, and Transmission Indirect was 2.0x Cycles' (mean +0.031, "
        "worst block 0.47). The same scene with the cube lifted 1 cm:",
        "",
        *lift_table,
        "",
        "## Named differences",
        "",
        "- **Glossy Color of metals**: both take the lobe's albedo, Schlick's Fresnel "
        "averaged over it times its single-scattering albedo and multiscatter factor; DRT "
        "averages the Fresnel by a 16-point quadrature of the visible normals, Cycles reads "
        "a table. On a near-black metal the Color passes differ by up to 9 % "
        "([public_passes.md](public_passes.md)); Glossy Direct moves the other way, and "
        "their product, the light, agrees.",
        "- **A medium's own emission** belongs to no light group in DRT (Cycles: its "
        "object's).",
        "- The Distribution and Whitted integrators write no light passes (Combined only); "
        "the path tracer does.",
        "",
    ]
    with open(os.path.join(DOCS, "passes.md"), "w") as f:
        f.write("\n".join(lines))


def main():
    import bpy
    import drt_addon
    drt_addon.register()
    _render(bpy, "DRT")                          # warm-up: a first render compiles
    drt, t_drt = _render(bpy, "DRT")
    cycles, t_cycles = _render(bpy, "CYCLES")
    rows = compare(drt, cycles)
    lifted = compare(_render(bpy, "DRT", lift=0.01)[0], _render(bpy, "CYCLES", lift=0.01)[0])
    for row in rows:
        print(f"{row[0]:24s} DRT {row[1]:.4f} Cycles {row[2]:.4f} mean {row[3]:+.4f} "
              f"block {row[4]:.4f}")
    for row in lifted:
        print(f"lifted {row[0]:17s} mean {row[3]:+.4f} block {row[4]:.4f}")
    write(rows, lifted, {"DRT": t_drt, "CYCLES": t_cycles}, drt, cycles)


if __name__ == "__main__":
    main()
