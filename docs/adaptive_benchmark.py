"""What adaptive sampling saves, per sample scene: section 6 of docs/benchmarks.md
(called by docs/make_benchmarks.py; also runnable alone for one scene:
`.venv/bin/python docs/adaptive_benchmark.py sample_blends/cornell_box.blend`).

For each scene, in this process (bpy module, the scene exported once, DRT's settings from
the file): a long uniform render is the reference; a ladder of uniform renders gives the
error (relative MSE) as a power law of samples and seconds as a line in samples; an
adaptive render at the noise threshold gives its error, its samples over all pixels and
its seconds. The uniform samples and seconds needed for the adaptive render's error come
from the two fits; their ratio to the adaptive render's is the saving.
"""
from __future__ import annotations

import dataclasses
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

from engine.image_error import display_image, relmse  # noqa: E402
from engine.textures import linear_to_srgb  # noqa: E402


def export(blend: str, long_side: int):
    """(engine Scene, DRT's engine settings) of a .blend, its longer side `long_side`
    pixels (the sample scenes differ in size)."""
    import bpy
    import drt_addon
    from drt_addon.export import export_scene
    drt_addon.register()
    bpy.ops.wm.open_mainfile(filepath=os.path.abspath(blend), load_ui=False)
    scene = bpy.context.scene
    w, h = scene.render.resolution_x, scene.render.resolution_y
    size = (long_side, max(1, round(long_side * h / w))) if w >= h else \
        (max(1, round(long_side * w / h)), long_side)
    description = export_scene(bpy.context.evaluated_depsgraph_get(), size=size)
    return description, scene.drt.to_engine_settings()


def display_mse(img, ref):
    """MSE of what the screen shows: clipped to [0, 1] and sRGB-encoded (Blender's
    Standard view)."""
    return float(np.mean((linear_to_srgb(display_image(img))
                          - linear_to_srgb(display_image(ref))) ** 2))


METRICS = {"relative MSE": relmse, "display MSE": display_mse}


def uneven(long_side: int):
    """(engine Scene, DRT's default settings) of the scene whose noise is uneven that
    tests/test_adaptive_sampling.py renders: the Cornell box seen from further back in
    a grey world, the world noise-free, the box's indirect light noisy."""
    tests = os.path.join(ROOT, "tests")
    if tests not in sys.path:
        sys.path.insert(0, tests)
    from engine import RenderSettings
    from test_adaptive_sampling import uneven_scene
    return uneven_scene(long_side), RenderSettings()


UNEVEN = "uneven noise (tests/test_adaptive_sampling.py)"


def measure(blend: str, long_side: int = 96, ref_spp: int = 2048,
            ladder=(16, 64, 256), threshold: float = 0.01, max_spp: int = 1024,
            threads: int = 0, sampler: str | None = None) -> dict:
    """Section 6's figures for one .blend (or UNEVEN) at Noise Threshold `threshold`
    (Cycles' default 0.01)."""
    from engine import render
    scene, base = uneven(long_side) if blend == UNEVEN else export(blend, long_side)
    base = dataclasses.replace(base, threads=threads, adaptive_sampling=False,
                               time_limit=0.0, sampler=sampler or base.sampler)
    n_pixels = scene.width * scene.height

    def run(**changes):
        settings = dataclasses.replace(base, **changes)
        t0 = time.perf_counter()
        film, stats = render(scene, settings)
        return film, stats, time.perf_counter() - t0

    run(samples=1)                                             # kernels loaded
    ref = run(samples=ref_spp, seed=12345)[0].mean()
    uniform = []
    for spp in ladder:
        film, _, secs = run(samples=spp, seed=1)
        uniform.append((spp, secs, {k: f(film.mean(), ref) for k, f in METRICS.items()}))
    film, stats, a_secs = run(samples=max_spp, seed=1, adaptive_sampling=True,
                              adaptive_threshold=threshold)
    a_spp = stats.pixel_samples / n_pixels
    spp = np.array([u[0] for u in uniform], dtype=np.float64)
    secs = np.array([u[1] for u in uniform])
    per, fixed = np.polyfit(spp, secs, 1)                       # seconds = fixed + per n
    out = dict(scene=blend if blend == UNEVEN else os.path.basename(blend),
               size=(scene.width, scene.height),
               sampler=base.sampler,
               threshold=threshold, max_spp=max_spp, ref_spp=ref_spp, ladder=list(ladder),
               adaptive_spp=a_spp, adaptive_seconds=a_secs, min_spp=int(film.count.min()),
               metrics={})
    for name, f in METRICS.items():
        err = np.array([u[2][name] for u in uniform])
        a_err = f(film.mean(), ref)
        slope, icpt = np.polyfit(np.log(spp), np.log(err), 1)   # log e = icpt + slope log n
        need = float(np.exp((np.log(a_err) - icpt) / slope))
        out["metrics"][name] = dict(
            slope=float(slope), adaptive_error=a_err, uniform_spp_needed=need,
            sample_saving=need / a_spp, time_saving=float((fixed + per * need) / a_secs))
    return out


def targets(rows) -> list:
    """Section 6's target rows: adaptive sampling's time saving for the display error
    (what Cycles' stopping rule aims at), on every scene, and where noise is uneven."""
    if not rows:
        return []

    def saving(r):
        return r["metrics"]["display MSE"]["time_saving"]
    worst = min(rows, key=saving)
    uneven_rows = [r for r in rows if r["scene"] == UNEVEN] or rows
    best = max(uneven_rows, key=saving)
    t = rows[0]["threshold"]
    return [(f"6. adaptive sampling (Noise Threshold {t}): uniform's time to its display "
             "error over its own, every scene", ">= 1.0x",
             f"{saving(worst):.2f}x at worst ({worst['scene']}, {worst['sampler']})",
             saving(worst) >= 1.0),
            ("6. ... where noise is uneven", ">= 2x",
             f"{saving(best):.2f}x ({best['scene']}, {best['sampler']})",
             saving(best) >= 2.0)]


def table(rows) -> list:
    """Markdown lines of section 6."""
    if not rows:
        return []
    r0 = rows[0]
    out = ["## 6. Adaptive sampling", "",
           f"Each sample scene with its longer side {max(r0['size'])} pixels, DRT's own "
           f"settings, one process (`docs/adaptive_benchmark.py`). Noise Threshold "
           f"{r0['threshold']} (at most {r0['max_spp']} samples) against uniform sampling; "
           f"errors against a {r0['ref_spp']}-sample uniform render. The uniform samples "
           "and seconds that reach the adaptive render's error come from a power law "
           f"fitted to uniform renders at {', '.join(map(str, r0['ladder']))} samples. "
           "The saving is that over the adaptive render's (above 1x: adaptive sampling "
           "is cheaper for the same error).", "",
           "| scene | sampler | adaptive: mean spp (min) | seconds | samples saved, rel. MSE "
           "| time saved, rel. MSE | samples saved, display MSE | time saved, display MSE |",
           "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        rel, ab = r["metrics"]["relative MSE"], r["metrics"]["display MSE"]
        out.append(f"| {r['scene']} | {r['sampler']} | {r['adaptive_spp']:.0f} "
                   f"({r['min_spp']}) | "
                   f"{r['adaptive_seconds']:.1f} | {rel['sample_saving']:.2f}x | "
                   f"{rel['time_saving']:.2f}x | {ab['sample_saving']:.2f}x | "
                   f"{ab['time_saving']:.2f}x |")
    return out + ["", "Under adaptive sampling the jittered sampler stratifies a pixel's "
                  "first Min Samples on their own and later samples in generations that "
                  "double (64, 64, 128, 256, ... at threshold 0.01): a pixel that stops "
                  "early holds whole "
                  "stratified sets, as a uniform render of that many samples does (with "
                  "strata over all of Samples, as before, it held a random subset of 1024 "
                  "strata, and adaptive sampling lost to uniform on every sample scene: "
                  "0.23x to 0.99x). Sobol points are progressive (every prefix is well "
                  "spread), as Cycles' samplers are.", "",
                  "Display MSE is the error of what the screen shows (clipped to [0, 1], "
                  "sRGB-encoded), which is what Cycles' stopping rule (DRT's) aims at: it "
                  "weighs a pixel's error by the square root of its brightness below 1 and "
                  "by its brightness above, so dark pixels stop with a larger relative error "
                  "and over-exposed ones early. Relative MSE weighs dark pixels most and can "
                  "favour uniform sampling. On scenes whose noise is even there is little to "
                  "save, and the passes over few pixels cost some overhead; adaptive sampling "
                  "pays off where noise is uneven (tests/test_adaptive_sampling.py measures "
                  "7x fewer samples on such a scene).", ""]


if __name__ == "__main__":
    import json
    print(json.dumps(measure(sys.argv[1]), indent=1))
