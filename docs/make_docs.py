"""Renders the images in docs/ and writes the measurements quoted there.

    .venv/bin/python docs/make_docs.py

Everything the docs claim about speed or accuracy comes from this script's output, which
it writes to docs/measurements.md (rerun it to reproduce the numbers on your machine).
"""
from __future__ import annotations

import os
import platform
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "tests"))
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")


def save_png(bpy, scene, path):
    s = scene.render.image_settings
    s.file_format = "PNG"
    s.color_depth = "8"
    bpy.data.images["Render Result"].save_render(filepath=path, scene=scene)


def cornell(bpy, lines):
    from conftest import render_blend
    from drt_addon import render_engine

    blend = os.path.join(ROOT, "sample_blends", "cornell_box.blend")
    samples = 256
    t0 = time.perf_counter()
    drt = render_blend(bpy, blend, "DRT", samples=samples, percentage=100)
    t_drt = time.perf_counter() - t0
    stats = render_engine.last_render["stats"]
    save_png(bpy, bpy.context.scene, os.path.join(IMAGES, "cornell_box.png"))
    t0 = time.perf_counter()
    cyc = render_blend(bpy, blend, "CYCLES", samples=1024, percentage=100)
    t_cyc = time.perf_counter() - t0
    save_png(bpy, bpy.context.scene, os.path.join(IMAGES, "cornell_box_cycles.png"))
    m_drt, m_cyc = drt.mean(axis=(0, 1)), cyc.mean(axis=(0, 1))
    rel = (m_drt - m_cyc) / m_cyc
    mad = np.abs(drt - cyc).mean() / cyc.mean()
    lines += [
        "## Cornell box (sample_blends/cornell_box.blend, 256x256, path tracing, "
        "Cycles' default light paths)",
        "",
        "| | DRT | Cycles |",
        "|---|---|---|",
        f"| samples per pixel | {samples} | 1024 |",
        f"| wall time (s, incl. scene export) | {t_drt:.1f} | {t_cyc:.1f} |",
        f"| mean R, G, B (scene-linear) | {m_drt[0]:.4f}, {m_drt[1]:.4f}, {m_drt[2]:.4f} "
        f"| {m_cyc[0]:.4f}, {m_cyc[1]:.4f}, {m_cyc[2]:.4f} |",
        "",
        f"- DRT paths per second: {stats.paths_per_second():,.0f}",
        f"- relative difference of the channel means (DRT - Cycles) / Cycles: "
        f"{rel[0]:+.2%}, {rel[1]:+.2%}, {rel[2]:+.2%}",
        f"- per-pixel mean absolute difference / Cycles' mean: {mad:.2%} (includes both "
        f"renders' noise)",
        "",
    ]


def main():
    import bpy

    import drt_addon
    drt_addon.register()
    os.makedirs(IMAGES, exist_ok=True)
    lines = ["# Measurements", "",
             "Written by `docs/make_docs.py`; rerun it to reproduce. Machine: "
             f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
             f"Blender {bpy.app.version_string} (bpy module).", ""]
    cornell(bpy, lines)
    with open(os.path.join(DOCS, "measurements.md"), "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
