"""Cycles' shadow catcher in DRT, against Cycles' own, and writes docs/shadow_catcher.md
with docs/images/shadow_catcher.png.

The scene is tests/shadow_catcher_scene.py's (a catcher floor, an orange cube and a grey
sphere on it, a sun, a fill lamp that is no shadow catcher, a world), rendered by both
engines at SAMPLES samples and 2x the test's resolution in Cycles' four forms (Film >
Transparent on or off, the Shadow Catcher pass on or off). The figure lays each
engine's transparent Combined and Shadow Catcher pass over a checker "plate", as a
compositor does: plate x Shadow Catcher, then Combined over it. Every number in the
page is printed here.

    .venv/bin/python docs/make_shadow_catcher_docs.py

Takes about 2 minutes on 2 cores.
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
SIZE = (128, 96)
SAMPLES = 256
MODES = [(t, p) for t in (True, False) for p in (True, False)]


def _mode(transparent, on):
    return f"Film {'transparent' if transparent else 'opaque'}, pass {'on' if on else 'off'}"


def _render(bpy, engine, transparent, on):
    """({"Image": (h, w, 4), "Shadow Catcher": (h, w, 3)}, seconds) of one render."""
    import light_pass_scene
    import shadow_catcher_scene
    scene = shadow_catcher_scene.build(bpy, size=SIZE, samples=SAMPLES,
                                       transparent=transparent, catcher_pass=on)
    names = ["Image"] + (["Shadow Catcher"] if on else [])
    t0 = time.perf_counter()
    if engine == "CYCLES":
        scene.render.engine, scene.cycles.device = "CYCLES", "CPU"
        out = light_pass_scene.cycles_passes(bpy, scene, names, channels=4)
        if on:
            out["Shadow Catcher"] = out["Shadow Catcher"][..., :3]
    else:
        from drt_addon import render_engine
        scene.render.engine = "DRT"
        bpy.ops.render.render()
        last = render_engine.last_render
        assert last["ok"], last["error"]
        out = {"Image": np.dstack([last["pixels"], last["alpha"]])}
        if on:
            out["Shadow Catcher"] = np.asarray(last["passes"]["Shadow Catcher"], float)[..., :3]
    return out, time.perf_counter() - t0


def _blocks(img, k=8):
    h, w, c = img.shape
    return img[:h // k * k, :w // k * k].reshape(h // k, k, w // k, k, c).mean(axis=(1, 3))


def compare(drt, cycles) -> list:
    """(what, DRT mean, Cycles mean, mean difference, worst 8 x 8 block difference):
    Combined's colour relative to Cycles' mean, its alpha and the Shadow Catcher pass in
    their own units (the pass over the pixels wholly on the catcher, 1 elsewhere)."""
    d, c = drt["Image"], cycles["Image"]
    scale = c[..., :3].mean()
    rows = [("Combined colour", d[..., :3].mean(), c[..., :3].mean(),
             (d[..., :3].mean() - c[..., :3].mean()) / scale,
             np.abs(_blocks(d[..., :3]) - _blocks(c[..., :3])).max() / scale),
            ("Combined alpha", d[..., 3].mean(), c[..., 3].mean(),
             d[..., 3].mean() - c[..., 3].mean(),
             np.abs(_blocks(d[..., 3:]) - _blocks(c[..., 3:])).max())]
    if "Shadow Catcher" in drt:
        a, b = drt["Shadow Catcher"], cycles["Shadow Catcher"]
        inside = ((d[..., 3] < 0.01) & (c[..., 3] < 0.01))[..., None]
        a, b = np.where(inside, a, 1.0), np.where(inside, b, 1.0)
        rows.append(("Shadow Catcher (on the catcher)", a.mean(), b.mean(),
                     a.mean() - b.mean(), np.abs(_blocks(a) - _blocks(b)).max()))
    return rows


def _plate(h, w):
    """A checker background plate, as a photographed floor would stand in."""
    y, x = np.mgrid[0:h, 0:w]
    check = ((x // 12 + y // 12) % 2).astype(float)
    return (0.25 + 0.2 * check)[..., None] * np.array([1.0, 0.9, 0.75])


def composite(images):
    """The plate darkened by the Shadow Catcher pass, Combined laid over it."""
    rgba = images["Image"]
    plate = _plate(*rgba.shape[:2]) * images["Shadow Catcher"]
    return rgba[..., :3] + plate * (1.0 - rgba[..., 3:])


def figure(drt, cycles, path):
    from make_passes_docs import _figure
    rows_of = []
    for label, images in (("DRT", drt), ("Cycles", cycles)):
        rgba = images["Image"]
        rows_of.append((label, {"Combined (matte)": rgba[..., :3] + 0.5 * (1 - rgba[..., 3:]),
                                "Shadow Catcher": images["Shadow Catcher"] / 2.0,
                                "Over a plate": composite(images)}))
    _figure(["Combined (matte)", "Shadow Catcher", "Over a plate"], rows_of, path,
            "Shadow catcher, Film > Transparent, pass on (matte over grey; pass / 2)")


def write(results, seconds):
    png = os.path.join(IMAGES, "shadow_catcher.png")
    figure(results[(True, True)][0], results[(True, True)][1], png)
    lines = [
        "# Shadow catcher",
        "",
        "*Written by `docs/make_shadow_catcher_docs.py`; every number below is printed "
        "by it.*",
        "",
        "Object > Visibility > Shadow Catcher makes an object record what the rest of the "
        "scene does to it (the shadows it receives and the light other objects bounce "
        "onto it) in the **Shadow Catcher** pass (View Layer > Passes > Light), for "
        "compositing synthetic objects over a photographed plate; the catcher itself is a "
        "hole in Combined. DRT does what Cycles does, in its four forms:",
        "",
        "- **Shadow Catcher pass on**: Combined is the *matte* (the other objects and the "
        "background, the catcher transparent); multiply the plate by the pass and lay "
        "Combined over it.",
        "- **Pass off**: Cycles' approximation, the shadow laid into Combined: on a "
        "transparent film as alpha (1 - the pass's mean), on an opaque film over the "
        "world behind the catcher.",
        "- A lamp whose Object > Visibility > Shadow Catcher is off (on by default for "
        "lamps) lights the scene but not the catcher's copy of a path, so the pass "
        "brightens by its share where it shines.",
        "",
        "How: a camera ray whose first hit is a catcher splits. The path goes on as usual "
        "(Combined) and a copy traces a scene of catchers alone, lit by the catcher "
        "lamps, the catchers' emission and the world, with the same random numbers; the "
        "pass is (Combined - matte) / copy per pixel. What the film keeps and the formulas "
        "are in `engine/shadow_catcher.py`. A scene without a catcher object keeps no "
        "extra film channel and traces no copy (tests/test_shadow_catcher.py).",
        "",
        f"## Against Cycles ({SIZE[0]} x {SIZE[1]} pixels, {SAMPLES} samples)",
        "",
        "Combined's colour relative to Cycles' mean; alpha and the pass in their own units "
        "(the pass over the pixels wholly on the catcher, 1 elsewhere: at its edges "
        "the pass is a ratio of the few samples that split, in both engines). The "
        "test (tests/test_shadow_catcher_vs_cycles.py, 64 x 48) holds means to 0.01, "
        "colour blocks to 0.15 and alpha and pass blocks to 0.08.",
        "",
        "| form | what | DRT mean | Cycles mean | mean diff. | worst 8 x 8 block |",
        "|---|---|---|---|---|---|",
    ]
    for (t, p) in MODES:
        for row in compare(*results[(t, p)]):
            lines.append(f"| {_mode(t, p)} | {row[0]} | {row[1]:.4f} | {row[2]:.4f} | "
                         f"{row[3]:+.4f} | {row[4]:.4f} |")
    lines += [
        "",
        f"Render time, transparent film with the pass on: DRT {seconds['DRT']:.1f} s, "
        f"Cycles {seconds['CYCLES']:.1f} s (2 cores; DRT traces the catcher's copies as a "
        "second run over the samples that split).",
        "",
        "![DRT's and Cycles' shadow catcher](images/shadow_catcher.png)",
        "",
        "## Named differences",
        "",
        "- A catcher seen through a volume's boundary (a fog box in front of it) does not "
        "split in DRT: the boundary is the camera ray's first hit. Cycles splits there.",
        "- Hair (curves) cannot be a shadow catcher in DRT.",
        "- The Shadow Catcher pass is written as rendered, not denoised; with Render > "
        "Denoise on, Combined (after the catcher's formulas) is denoised.",
        "- On an opaque film with the pass off, the world behind the catcher is the "
        "world's colour or texture as camera rays see it, without a Sky Texture's sun "
        "disc.",
    ]
    with open(os.path.join(DOCS, "shadow_catcher.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    import bpy
    import drt_addon
    drt_addon.register()
    _render(bpy, "DRT", True, True)                 # warm-up: a first render compiles
    results, seconds = {}, {}
    for t, p in MODES:
        drt, s_drt = _render(bpy, "DRT", t, p)
        cycles, s_cycles = _render(bpy, "CYCLES", t, p)
        results[(t, p)] = (drt, cycles)
        if (t, p) == (True, True):
            seconds = {"DRT": s_drt, "CYCLES": s_cycles}
        for row in compare(drt, cycles):
            print(f"{_mode(t, p):34s} {row[0]:16s} DRT {row[1]:.4f} Cycles {row[2]:.4f} "
                  f"mean {row[3]:+.4f} block {row[4]:.4f}")
    write(results, seconds)


if __name__ == "__main__":
    main()
