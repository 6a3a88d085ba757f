"""Denoised DRT against denoised Cycles at equal render time, and writes docs/denoising.md.

For each scene, both engines render with Render > Denoise at Cycles' defaults
(OpenImageDenoise, albedo and normal, Accurate prefilter, High quality) at a ladder of
sample counts, in this one process, each render timed from the render call to its end
(export or sync, the acceleration structure, sampling and the denoiser; the first render
of each engine, and DRT's first of each scene, are warm-ups, not kept). Errors are against one reference: Cycles at
REFERENCE_SAMPLES, not denoised. DRT's error at each Cycles render's time is read off
DRT's own ladder (interpolated in log error against log seconds), so the table says what
each engine's denoised image is worth for the same wait.

    .venv/bin/python docs/make_denoising_docs.py

Takes about 15 minutes on 2 cores.
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

SCENES = ("cornell_box", "metals", "glass", "hdri_world", "product_shot")
SIZE = 256                            # pixels along each image's longer side
CYCLES_LADDER = (4, 16, 64)
DRT_LADDER = (2, 4, 8, 16, 32, 64, 128, 256)
REFERENCE_SAMPLES = 2048


def _render(bpy, scene_name, engine, samples, denoise, png=None):
    """(denoised or plain image, noisy image or None, seconds) of one render; the image as
    Blender displays it to `png` if given."""
    from conftest import read_render_result, use_engine
    from drt_addon import render_engine
    bpy.ops.wm.open_mainfile(filepath=os.path.join(ROOT, "sample_blends",
                                                   f"{scene_name}.blend"), load_ui=False)
    scene = bpy.context.scene
    r = scene.render
    r.resolution_percentage = round(100 * SIZE / max(r.resolution_x, r.resolution_y))
    use_engine(scene, engine, samples)
    scene.cycles.use_denoising = denoise
    t0 = time.perf_counter()
    bpy.ops.render.render()
    seconds = time.perf_counter() - t0
    image = read_render_result(bpy, scene)
    if png is not None:
        from make_comparisons import save_png
        save_png(bpy, scene, png)
    noisy = render_engine.last_render["passes"].get("Noisy Image") if engine == "DRT" \
        else None
    return image, noisy, seconds


def _png(name, engine):
    import tempfile
    folder = os.path.join(tempfile.gettempdir(), "drt_denoise_docs")
    os.makedirs(folder, exist_ok=True)
    return os.path.join(folder, f"{name}_{engine}.png")


def _at_time(seconds, ladder_seconds, ladder_errors):
    """An error of the ladder at `seconds`, interpolated in log-log (clamped to the
    ladder's ends)."""
    x, y = np.log(ladder_seconds), np.log(ladder_errors)
    return float(np.exp(np.interp(np.log(seconds), x, y)))


def measure(bpy):
    from engine.image_error import flip, relmse
    rows, images = [], {}
    _render(bpy, SCENES[0], "CYCLES", 1, True)          # warm-up: OIDN
    for name in SCENES:
        # each scene's own warm-up: the kernels its features need (a scene's first
        # render would otherwise compile them inside a timed render when the cache is cold)
        _render(bpy, name, "DRT", 1, True)
        ref, _, ref_seconds = _render(bpy, name, "CYCLES", REFERENCE_SAMPLES, False)
        ladder = []
        for spp in DRT_LADDER:
            png = _png(name, "drt") if spp == 16 else None
            img, noisy, secs = _render(bpy, name, "DRT", spp, True, png)
            ladder.append((spp, secs, relmse(img, ref), flip(img, ref), relmse(noisy, ref)))
            if png:
                images[(name, "DRT")] = png
        d_secs = [r[1] for r in ladder]
        for spp in CYCLES_LADDER:
            png = _png(name, "cycles") if spp == 16 else None
            img, _, secs = _render(bpy, name, "CYCLES", spp, True, png)
            plain, _, _ = _render(bpy, name, "CYCLES", spp, False)
            if png:
                images[(name, "CYCLES")] = png
            rows.append(dict(
                scene=f"{name} ({ref.shape[1]} x {ref.shape[0]})", spp=spp, seconds=secs, cycles_relmse=relmse(img, ref),
                cycles_flip=flip(img, ref), cycles_noisy=relmse(plain, ref),
                drt_spp=_at_time(secs, d_secs, [r[0] for r in ladder]),
                drt_relmse=_at_time(secs, d_secs, [r[2] for r in ladder]),
                drt_flip=_at_time(secs, d_secs, [r[3] for r in ladder]),
                drt_noisy=_at_time(secs, d_secs, [r[4] for r in ladder]),
                drt_same_spp=next(r[2] for r in ladder if r[0] == spp),
                beyond=secs > d_secs[-1], drt_last_seconds=d_secs[-1],
                before=secs < d_secs[0], drt_first_seconds=d_secs[0],
                ref_seconds=ref_seconds))
    return rows, images


def write(rows, images, bpy):
    from make_comparisons import side_by_side
    import platform
    os.makedirs(IMAGES, exist_ok=True)
    load = os.getloadavg()[0]
    lines = [
        "# Denoising",
        "",
        "Written by `docs/make_denoising_docs.py`; rerun it to reproduce. Machine: "
        f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}; "
        f"load average {load:.2f} when it ended.",
        "",
        "DRT denoises as Cycles does: Render > Denoise and the view layer's Denoising, both "
        "on in a new file, run Intel Open Image Denoise on the finished render, with "
        "Cycles' own settings (Sampling > Denoise in DRT's panels shows them): the input "
        "passes (colour, + albedo, + albedo and normal), the prefilter (None, Fast, "
        "Accurate) and the quality (High, Balanced, Fast). The denoised image is the "
        "Combined pass; the noisy one is kept as the Noisy Image pass. OIDN comes from the "
        "pinned `pyoidn` binding, which the extension zip bundles. The albedo and normal "
        "it is given are DRT's Denoising Albedo and Denoising Normal passes: the first "
        "surface's diffuse albedo, its Base Color and Metallic as the path tracer "
        "shades them there (textures and shader programs), and its interpolated "
        "camera-space normal. Two differences from Cycles' guides are named here and "
        "measured below: Cycles' normal is the material's (bump and normal maps; the "
        "product shot's bumped finishes), and it follows paths through mirror-like "
        "surfaces (roughness under 0.075) to the first rough one (the glass and metal "
        "scenes).",
        "",
        f"Each scene scaled to {SIZE} pixels on its longer side (the size is beside its "
        "name), both engines denoised at Cycles' defaults. The error is against Cycles at "
        f"{REFERENCE_SAMPLES} samples, not denoised; relMSE = mean((a - b)^2 / (b^2 + "
        "0.01)), FLIP is NVIDIA's perceptual metric (`flip-evaluator`, LDR). DRT's "
        "figures are at Cycles' render time: read off DRT's own ladder "
        f"({', '.join(map(str, DRT_LADDER))} samples), interpolated in log-log; its samples "
        "in that time are shown. Seconds are whole render calls (export or sync, "
        "acceleration structure, sampling and the denoiser).",
        "",
        "| scene | Cycles samples | seconds | Cycles relMSE noisy | Cycles relMSE denoised "
        "| DRT relMSE noisy | DRT relMSE denoised | DRT / Cycles denoised relMSE | Cycles FLIP "
        "| DRT FLIP | DRT samples in that time | DRT denoised relMSE at Cycles' samples |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['scene']} | {r['spp']} | {r['seconds']:.2f} | {r['cycles_noisy']:.2e} | "
            f"{r['cycles_relmse']:.2e} | {r['drt_noisy']:.2e} | {r['drt_relmse']:.2e} | "
            f"**{r['drt_relmse'] / r['cycles_relmse']:.2f}x** | {r['cycles_flip']:.4f} | "
            f"{r['drt_flip']:.4f} | {r['drt_spp']:.0f}"
            + (f" (its last rung, {r['drt_last_seconds']:.2f} s: Cycles took longer)"
               if r["beyond"] else "")
            + (f" (its first rung, {r['drt_first_seconds']:.2f} s: longer than Cycles' "
               "render, so DRT's error at Cycles' time is worse than shown)"
               if r["before"] else "")
            + f" | {r['drt_same_spp']:.2e} |")
    ratios = [r["drt_relmse"] / r["cycles_relmse"] for r in rows]
    same = [r["drt_same_spp"] / r["cycles_relmse"] for r in rows]
    lines += [
        "",
        f"Over the {len(rows)} rows, DRT's denoised relMSE at Cycles' render time is a median "
        f"{np.median(ratios):.2f}x Cycles' (from {min(ratios):.2f}x to {max(ratios):.2f}x). "
        "Above 1x DRT is worse for the same wait: its sampling is slower per sample "
        "([benchmarks.md](benchmarks.md), section 3) and its guide passes stop at the first "
        "surface. Where Cycles took longer than DRT's whole ladder (its fixed cost, as on "
        "the HDRI world, where Cycles builds its map's importance table), DRT's last rung "
        "is shown and says so; where DRT's first rung took longer than Cycles' render, "
        "that rung is shown and says so. The last column compares the denoisers at equal "
        f"samples, without the engines' speeds: DRT's relMSE is {min(same):.2f}x to "
        f"{max(same):.2f}x Cycles' (median {np.median(same):.2f}x).",
        "",
    ]
    for name in SCENES:
        if (name, "DRT") in images:
            out = os.path.join(IMAGES, f"denoise_{name}.png")
            side_by_side([images[(name, "DRT")], images[(name, "CYCLES")]],
                         ["DRT 16 spp, denoised", "Cycles 16 spp, denoised"], out)
            lines += [f"![{name}: DRT and Cycles at 16 samples, denoised]"
                      f"(images/denoise_{name}.png)", ""]
    with open(os.path.join(DOCS, "denoising.md"), "w") as f:
        f.write("\n".join(lines))


def main():
    import bpy
    import drt_addon
    drt_addon.register()
    rows, images = measure(bpy)
    write(rows, images, bpy)
    for r in rows:
        print(r["scene"], r["spp"], f"{r['drt_relmse'] / r['cycles_relmse']:.2f}x")


if __name__ == "__main__":
    main()
