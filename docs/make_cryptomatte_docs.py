"""Cryptomatte mattes picked by Blender's own Cryptomatte node from DRT's passes and from
Cycles', and writes docs/cryptomatte.md with docs/images/cryptomatte.png.

The scene is tests/test_cryptomatte.py's (a grey plane, CubeA in material Red, CubeB in
Blue, and Dup and Dup.001, one mesh in two places, in Blue), rendered by both engines at
SIZE with Cryptomatte Object and Material on; the node picks CubeA and Dup.001 from
CryptoObject and Blue from CryptoMaterial. Every number in the page is printed here.

    .venv/bin/python docs/make_cryptomatte_docs.py

Takes about a minute on 2 cores.
"""
from __future__ import annotations

import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests"), os.path.join(ROOT, "docs")]
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")
SIZE = (192, 128)
PICKS = [("CryptoObject", ("CubeA",)), ("CryptoObject", ("Dup.001",)),
         ("CryptoMaterial", ("Blue",))]


def main():
    import bpy
    import drt_addon
    import test_cryptomatte as crypto
    from conftest import render_current
    from make_passes_docs import _figure
    drt_addon.register()
    crypto.W, crypto.H = SIZE
    images = {}
    for engine in ("DRT", "CYCLES"):
        scene = crypto._scene(bpy, engine)
        rgb = render_current(bpy, scene)[..., :3]
        images[engine, "render"] = rgb / (1.0 + rgb)         # shown Reinhard-mapped
        for layer, names in PICKS:
            scene = crypto._scene(bpy, engine)
            images[engine, names[0]] = crypto._matte(bpy, scene, layer, names)
    rows = []
    for layer, names in PICKS:
        d, c = images["DRT", names[0]], images["CYCLES", names[0]]
        diff = np.abs(d - c)
        rows.append((layer, names[0], c.mean(), d.mean(), diff.mean(), (diff > 0.5).mean()))
        print(f"{layer} {names[0]}: Cycles {c.mean():.4f} DRT {d.mean():.4f} mean difference "
              f"{diff.mean():.4f} pixels off by > 0.5: {(diff > 0.5).mean():.2%}")
    columns = ["render"] + [names[0] for _, names in PICKS]
    rows_of = [(label, {name: (images[engine, name] if name == "render" else
                               np.repeat(images[engine, name][..., None], 3, axis=2))
                        for name in columns})
               for label, engine in (("DRT", "DRT"), ("Cycles", "CYCLES"))]
    _figure(columns, rows_of, os.path.join(IMAGES, "cryptomatte.png"),
            "Blender's Cryptomatte node on each engine's passes (16 samples; the render "
            "Reinhard-mapped)")
    lines = [
        "# Cryptomatte",
        "",
        "*Written by `docs/make_cryptomatte_docs.py`; every number below is printed by it.*",
        "",
        "View Layer > Passes > Cryptomatte: Object, Material and Asset, with Levels, as "
        "Cycles writes them (CryptoObject00, 01, ... each holding two (id, coverage) "
        "pairs, and the manifest in the render result's metadata), so Blender's "
        "Cryptomatte node picks mattes from DRT's passes by name, as from Cycles'. Each "
        "pixel's names are ranked by the share of its samples that hit them "
        "(engine/cryptomatte.py).",
        "",
        f"## Against Cycles ({SIZE[0]} x {SIZE[1]} pixels, 16 samples)",
        "",
        "The same node on each engine's render: the matte's mean (its share of the "
        "image), the mean difference and the share of pixels off by more than 0.5 (the "
        "objects' edges, where 16 samples of either engine split a pixel differently). "
        "Dup.001 is one of two places of one mesh, which DRT renders as instances. "
        "tests/test_cryptomatte.py holds the mean difference under 10 % of the matte's "
        "mean and the pixels off by 0.5 under 1 %.",
        "",
        "| layer | picked | Cycles matte | DRT matte | mean difference | off by > 0.5 |",
        "|---|---|---|---|---|---|",
    ]
    for layer, name, c, d, diff, off in rows:
        lines.append(f"| {layer} | {name} | {c:.4f} | {d:.4f} | {diff:.4f} | {off:.2%} |")
    lines += ["", "![Cryptomatte mattes from DRT and Cycles](images/cryptomatte.png)"]
    with open(os.path.join(DOCS, "cryptomatte.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
