"""Baking with DRT against Cycles' bake of the same scene, and writes docs/bake.md with
docs/images/bake.png.

The scene is tests/test_bake_vs_cycles.py's (a floor plane with a Principled material
baked to a float image, an orange cube resting on it, a sun, a world), baked by both
engines at SAMPLES samples to a SIZE x SIZE image for each pass type of the test; then
Diffuse once more with the cube lifted 1 cm off the floor (resting, its bottom face lies
in the floor's plane, which rays leaving the floor must meet as Cycles' do). Every number
in the page is printed here.

    .venv/bin/python docs/make_bake_docs.py

Takes about a minute on 2 cores.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests"), os.path.join(ROOT, "docs")]
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")
SIZE = 64
SAMPLES = 256


def _row(name, drt, cycles):
    d, c = drt[..., :3].astype(float), cycles[..., :3].astype(float)
    k = SIZE // 8
    blocks = [x.reshape(8, k, 8, k, 3).mean(axis=(1, 3)) for x in (d, c)]
    scale = max(c.mean(), 1e-3)
    return (name, d.mean(), c.mean(), (d.mean() - c.mean()) / scale,
            np.abs(blocks[0] - blocks[1]).max() / scale)


def main():
    import bpy
    import drt_addon
    import test_bake_vs_cycles as bake_test
    from make_passes_docs import _figure
    drt_addon.register()
    bake_test.SIZE, bake_test.SAMPLES = SIZE, SAMPLES
    bake_test._bake(bpy, "DRT", "COMBINED", {})           # warm-up: a first bake compiles
    rows, images, seconds = [], {}, {}
    for name, (kind, filters) in bake_test.CASES.items():
        out = []
        for engine in ("DRT", "CYCLES"):
            t0 = time.perf_counter()
            out.append(bake_test._bake(bpy, engine, kind, filters))
            seconds[(name, engine)] = time.perf_counter() - t0
        images[name] = out
        rows.append(_row(name, *out))
        print(f"{name:15s} DRT {rows[-1][1]:.4f} Cycles {rows[-1][2]:.4f} "
              f"mean {rows[-1][3]:+.4f} block {rows[-1][4]:.4f} "
              f"({seconds[(name, 'DRT')]:.1f} s, {seconds[(name, 'CYCLES')]:.1f} s)")
    lifted = _row("diffuse, cube lifted 1 cm",
                  *(bake_test._bake(bpy, e, "DIFFUSE", {}, lift=0.01) for e in ("DRT", "CYCLES")))
    indirect = [_row(f"diffuse indirect{label}",
                     *(bake_test._bake(bpy, e, "DIFFUSE", {"use_pass_direct": False}, lift=lift)
                       for e in ("DRT", "CYCLES"))) for label, lift in (("", 0.0),
                                                                         (", lifted", 0.01))]
    for row in [lifted] + indirect:
        print(f"{row[0]:28s} DRT {row[1]:.4f} Cycles {row[2]:.4f} mean {row[3]:+.4f}")
    shown = ["combined", "diffuse", "diffuse color", "glossy", "ao", "normal"]
    rows_of = [(label, {n: images[n][i][::-1, :, :3].astype(float) * (8.0 if n == "glossy"
                                                                         else 1.0)
                        for n in shown})
               for i, label in enumerate(("DRT", "Cycles"))]
    _figure(shown, rows_of, os.path.join(IMAGES, "bake.png"),
            f"Baked to a {SIZE} x {SIZE} image, {SAMPLES} samples (glossy x 8; normal in "
            "tangent space)")
    lines = [
        "# Baking",
        "",
        "*Written by `docs/make_bake_docs.py`; every number below is printed by it.*",
        "",
        "DRT bakes through Blender's own bake operator, as Cycles does: Render > Bake "
        "(DRT's panel draws Cycles' Bake Type and Blender's bake settings), or "
        "`bpy.ops.object.bake(type=...)` with DRT as the render engine. Select the "
        "object, give its material an active Image Texture node with the image to bake "
        "into, and press Bake. Blender hands DRT the triangle and barycentrics of every "
        "texel of the object's UV layout; DRT shades each point as Cycles' bake does (a "
        "ray from the point plus its normal that hits the point: the view direction is the "
        "normal, and the path tracer goes on from there) and Blender writes the image "
        "(margins, Clear Image, tangent or object space for normals, colour spaces; "
        "Selected to Active and cages are Blender's too).",
        "",
        "| Bake type | what DRT writes |",
        "|---|---|",
        "| Combined | the light leaving the surface towards its normal; the Lighting "
        "(Direct, Indirect) and Contributions (Diffuse, Glossy, Transmission, Emit) "
        "filters pick the light passes' parts ([passes.md](passes.md)) |",
        "| Diffuse, Glossy, Transmission | that kind's Direct and / or Indirect light "
        "divided by its Color, as Cycles bakes it (times its Color with the Color "
        "filter on); Color alone: the albedo |",
        "| Emit | the surface's emission |",
        "| Normal | the world-space shading normal (Blender turns it into tangent or "
        "object space with the swizzle) |",
        "| Ambient Occlusion | Cycles' AO (World > Ambient Occlusion > Distance) |",
        "",
        "Other bake types (Roughness, Position, UV, Shadow, Environment) are refused with "
        "an error naming what DRT bakes (tests/test_bake_vs_cycles.py).",
        "",
        f"## Against Cycles ({SIZE} x {SIZE} texels, {SAMPLES} samples)",
        "",
        "Mean and worst 8 x 8 block difference relative to Cycles' mean (the test, "
        "tests/test_bake_vs_cycles.py, bakes 32 x 32 at 64 samples).",
        "",
        "| bake | DRT mean | Cycles mean | mean diff. | worst block | DRT s | Cycles s |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        lines.append(f"| {row[0]} | {row[1]:.4f} | {row[2]:.4f} | {row[3]:+.4f} | "
                     f"{row[4]:.4f} | {seconds[(row[0], 'DRT')]:.1f} | "
                     f"{seconds[(row[0], 'CYCLES')]:.1f} |")
    lines += [
        "",
        "![DRT's and Cycles' bakes](images/bake.png)",
        "",
        "**A surface resting on the baked one.** The cube stands on the floor, as an "
        "artist leaves it; its bottom face lies in the floor's plane. A ray leaving the "
        "floor starts on it, skips only the triangle it left and meets the coplanar face, "
        "in DRT as in Cycles (`engine/embree/self_hits.py`). Until 2026-11-30 DRT started "
        "rays a little above the surface, past such a face, and the floor's indirect "
        "light was 9 % below Cycles'. The same bakes with the cube lifted 1 cm:",
        "",
        "| bake | DRT mean | Cycles mean | mean diff. |",
        "|---|---|---|---|",
    ]
    for row in indirect + [lifted]:
        lines.append(f"| {row[0]} | {row[1]:.4f} | {row[2]:.4f} | {row[3]:+.4f} |")
    lines += [
        "",
        "## Named differences",
        "",
        "- A texel's samples spread over its footprint as Cycles' do, but a jittered "
        "point that would leave its triangle stays at the texel's centre (Cycles draws "
        "again, up to ten times); Normal and Ambient Occlusion take the texel centres.",
        "- Normal is the interpolated shading normal; a material's Bump or Normal Map "
        "node is not applied to it (Cycles' is the bumped normal).",
        "- The Combined filters pick light by the kind of the first scattering (the light "
        "passes' split); Cycles removes the unticked closures at every bounce.",
        "- DRT bakes only texels of meshes exported as themselves (an object whose "
        "mesh is instanced elsewhere is exported alone for the bake).",
    ]
    with open(os.path.join(DOCS, "bake.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
