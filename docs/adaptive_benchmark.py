"""What adaptive sampling saves, per sample scene: section 6 of docs/benchmarks.md
(called by docs/make_benchmarks.py; also runnable alone for one scene:
`.venv/bin/python docs/adaptive_benchmark.py sample_blends/cornell_box.blend`).

For each scene and engine (DRT with each of its samplers, then Cycles in the same bpy),
in this process (the file's own settings): a long uniform render is the reference; a
ladder of uniform renders gives the error as a power law of samples and seconds as a line
in samples; an adaptive render at the noise threshold gives its error, its seconds and
(DRT's) its samples over all pixels. The uniform samples and seconds needed for the
adaptive render's error come from the two fits; their ratio to the adaptive render's is
the saving.
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


UNEVEN = "cornell_box.blend from afar"


def open_scene(blend: str, long_side: int):
    """The bpy scene of a .blend, its longer side `long_side` pixels (the sample scenes
    differ in size). UNEVEN is the scene whose noise is uneven: the Cornell box seen from
    further back in a grey world (as tests/test_adaptive_sampling.py's), so the world
    around the box is noise-free and the box's indirect light is noisy."""
    import bpy
    import drt_addon
    drt_addon.register()
    if blend == UNEVEN:
        scene = _tests_module("uneven_noise_blend").open_uneven(bpy)
    else:
        bpy.ops.wm.open_mainfile(filepath=os.path.abspath(blend), load_ui=False)
        scene = bpy.context.scene
    w, h = scene.render.resolution_x, scene.render.resolution_y
    size = (long_side, max(1, round(long_side * h / w))) if w >= h else \
        (max(1, round(long_side * w / h)), long_side)
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    return scene


def _tests_module(name: str):
    """A helper module of tests/ (the uneven scene, Cycles' sample counts)."""
    import importlib
    tests = os.path.join(ROOT, "tests")
    if tests not in sys.path:
        sys.path.insert(0, tests)
    return importlib.import_module(name)


def export(blend: str, long_side: int):
    """(engine Scene, DRT's engine settings) of a .blend (or UNEVEN) at `long_side`."""
    import bpy
    from drt_addon.export import export_scene
    scene = open_scene(blend, long_side)
    size = (scene.render.resolution_x, scene.render.resolution_y)
    description = export_scene(bpy.context.evaluated_depsgraph_get(), size=size)
    return description, scene.drt.to_engine_settings()


def display_mse(img, ref):
    """MSE of what the screen shows: clipped to [0, 1] and sRGB-encoded (Blender's
    Standard view)."""
    return float(np.mean((linear_to_srgb(display_image(img))
                          - linear_to_srgb(display_image(ref))) ** 2))


METRICS = {"relative MSE": relmse, "display MSE": display_mse}
REPEAT_UNDER = 5.0       # seconds: a render shorter than this is timed 3 times (fastest)


def timed(run):
    """(image, seconds) of run() -> (image, seconds): a short render's seconds are the
    fastest of three runs, as timeit takes them (the host's other work only adds time,
    and is a large part of a second)."""
    image, secs = run()
    if secs < REPEAT_UNDER:
        secs = min([secs] + [run()[1] for _ in range(2)])
    return image, secs


def savings(ref, uniform, adaptive, a_secs, a_spp=None) -> dict:
    """Each metric's saving: the uniform samples and seconds that reach the adaptive
    image's error (uniform: [(spp, seconds, image)]; errors as a power law of samples,
    seconds as a line), over the adaptive render's (a_spp None: samples not known)."""
    spp = np.array([u[0] for u in uniform], dtype=np.float64)
    secs = np.array([u[1] for u in uniform])
    per, fixed = np.polyfit(spp, secs, 1)                       # seconds = fixed + per n
    out = {}
    for name, f in METRICS.items():
        err = np.array([f(u[2], ref) for u in uniform])
        a_err = f(adaptive, ref)
        slope, icpt = np.polyfit(np.log(spp), np.log(err), 1)   # log e = icpt + slope log n
        need = float(np.exp((np.log(a_err) - icpt) / slope))
        out[name] = dict(slope=float(slope), adaptive_error=a_err, uniform_spp_needed=need,
                         sample_saving=None if a_spp is None else need / a_spp,
                         time_saving=float((fixed + per * need) / a_secs))
    return out, float(per)


def measure(blend: str, long_side: int = 96, ref_spp: int = 2048,
            ladder=(16, 64, 256), threshold: float = 0.01, max_spp: int = 1024,
            threads: int = 0, sampler: str | None = None) -> dict:
    """Section 6's figures for DRT on one .blend (or UNEVEN) at Noise Threshold
    `threshold` (Cycles' default 0.01)."""
    from engine import render
    scene, base = export(blend, long_side)
    base = dataclasses.replace(base, threads=threads, adaptive_sampling=False,
                               time_limit=0.0, sampler=sampler or base.sampler)
    n_pixels = scene.width * scene.height
    last = {}

    def run(**changes):
        settings = dataclasses.replace(base, **changes)
        t0 = time.perf_counter()
        film, stats = render(scene, settings)
        last["film"], last["stats"] = film, stats
        return film.mean(), time.perf_counter() - t0

    run(samples=1)                                             # kernels loaded
    ref = run(samples=ref_spp, seed=12345)[0]
    uniform = []
    for spp in ladder:
        img, secs = timed(lambda: run(samples=spp, seed=1))
        uniform.append((spp, secs, img))
    adaptive, a_secs = timed(lambda: run(samples=max_spp, seed=1, adaptive_sampling=True,
                                         adaptive_threshold=threshold))
    film, stats = last["film"], last["stats"]
    a_spp = stats.pixel_samples / n_pixels
    metrics, per = savings(ref, uniform, adaptive, a_secs, a_spp)
    return dict(scene=blend if blend == UNEVEN else os.path.basename(blend),
                engine="DRT", size=(scene.width, scene.height), sampler=base.sampler,
                threshold=threshold, max_spp=max_spp, ref_spp=ref_spp, ladder=list(ladder),
                adaptive_spp=a_spp, adaptive_seconds=a_secs, min_spp=int(film.count.min()),
                # seconds per sample of the adaptive render over a uniform one's: the
                # pixels that go on sampling are the noisy ones, often the costly ones
                sample_cost=float(a_secs / (a_spp * per)) if per > 0 else None,
                metrics=metrics)


def measure_cycles(blend: str, long_side: int = 96, ref_spp: int = 2048,
                   ladder=(16, 64, 256), threshold: float = 0.01,
                   max_spp: int = 1024) -> dict:
    """The same figures for Cycles (in this bpy) on the same scene: its own reference,
    ladder and adaptive render (Min Samples automatic), the file's other settings, denoising
    off; its samples per pixel from its Debug Sample Count pass."""
    import bpy
    from drt_addon.cycles_ladder import use_cycles
    from drt_addon.image_files import render_result
    scene = open_scene(blend, long_side)

    def run(samples, seed, adaptive=False):
        use_cycles(scene, samples, seed)
        scene.cycles.use_adaptive_sampling = adaptive
        scene.cycles.adaptive_threshold = threshold
        scene.cycles.adaptive_min_samples = 0
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=False)
        secs = time.perf_counter() - t0
        return render_result(scene), secs

    run(1, 0)                                                  # kernels loaded
    ref = run(ref_spp, 12345)[0]
    uniform = []
    for spp in ladder:
        img, secs = timed(lambda: run(spp, 1))
        uniform.append((spp, secs, img))
    adaptive, a_secs = timed(lambda: run(max_spp, 1, True))
    counts = _sample_counts(bpy, scene)          # the same render again (the same seed)
    a_spp = float(counts.mean())
    metrics, per = savings(ref, uniform, adaptive, a_secs, a_spp)
    return dict(scene=blend if blend == UNEVEN else os.path.basename(blend),
                engine="Cycles", size=(scene.render.resolution_x, scene.render.resolution_y),
                sampler="Cycles' own", threshold=threshold, max_spp=max_spp, ref_spp=ref_spp,
                ladder=list(ladder), adaptive_spp=a_spp, adaptive_seconds=a_secs,
                min_spp=int(round(float(counts.min()))),
                sample_cost=float(a_secs / (a_spp * per)) if per > 0 else None,
                metrics=metrics)


def _sample_counts(bpy, scene):
    """(h, w) samples each pixel took in Cycles' render with the scene's settings (the
    render made again with the Debug Sample Count pass: tests/cycles_sample_count.py)."""
    return _tests_module("cycles_sample_count").cycles_sample_counts(bpy, scene)


def _saving(r, name="display MSE"):
    return r["metrics"][name]["time_saving"]


def _cycles_on(rows, scene):
    """Cycles' row for `scene`, or None."""
    return next((r for r in rows if r["engine"] == "Cycles" and r["scene"] == scene), None)


def targets(rows) -> list:
    """Section 6's target rows: DRT's adaptive sampling's time saving for the display
    error (what Cycles' stopping rule aims at), on every scene and where noise is uneven,
    each with Cycles' own saving on the same scene beside it."""
    drt = [r for r in rows if r["engine"] == "DRT"]
    if not drt:
        return []

    def beside(r):
        c = _cycles_on(rows, r["scene"])
        return f"; Cycles' own there: {_saving(c):.2f}x" if c else ""
    worst = min(drt, key=_saving)
    best = max([r for r in drt if r["scene"] == UNEVEN] or drt, key=_saving)
    t = drt[0]["threshold"]
    return [(f"6. adaptive sampling (Noise Threshold {t}): uniform's time to its display "
             "error over its own, every scene", ">= 1.0x",
             f"{_saving(worst):.2f}x at worst ({worst['scene']}, {worst['sampler']}"
             f"{beside(worst)})", _saving(worst) >= 1.0),
            ("6. ... where noise is uneven", ">= 2x",
             f"{_saving(best):.2f}x ({best['scene']}, {best['sampler']}{beside(best)})",
             _saving(best) >= 2.0)]


def _uneven_text(rows) -> list:
    """The uneven scene's samples and sample costs, DRT's (its better sampler) against
    Cycles'."""
    drt = [r for r in rows if r["engine"] == "DRT" and r["scene"] == UNEVEN]
    c = _cycles_on(rows, UNEVEN)
    if not drt or c is None or c["adaptive_spp"] is None:
        return []
    d = max(drt, key=_saving)
    dm, cm = d["metrics"]["display MSE"], c["metrics"]["display MSE"]
    return [f"On {UNEVEN} DRT ({d['sampler']}) saves {dm['sample_saving']:.2f}x the "
            f"samples for the same display error and Cycles {cm['sample_saving']:.2f}x "
            f"(mean {d['adaptive_spp']:.0f} and {c['adaptive_spp']:.0f} samples a pixel, "
            f"at least {d['min_spp']} and {c['min_spp']}); an adaptive sample costs DRT "
            f"{d['sample_cost']:.2f}x a uniform one and Cycles {c['sample_cost']:.2f}x: "
            f"time saved {dm['time_saving']:.2f}x and {cm['time_saving']:.2f}x. With about "
            "as many samples DRT's adaptive image has the error of "
            f"{dm['uniform_spp_needed']:.0f} uniform samples, Cycles' that of "
            f"{cm['uniform_spp_needed']:.0f}. Pixels stop at the same checks in both "
            "(tests/test_adaptive_sampling_vs_cycles.py: the same share stops at the "
            "first); which of the box's pixels go on longer, and why DRT's choice gains "
            "less, is not found yet.", ""]


def _generations(threshold: float) -> str:
    """The jittered sampler's first generations under adaptive sampling at `threshold`."""
    from engine import RenderSettings
    from engine.adaptive_sampling import AdaptiveSampling
    first = AdaptiveSampling.from_settings(RenderSettings(
        adaptive_sampling=True, adaptive_threshold=threshold)).first_check()
    return ", ".join(str(n) for n in (first, first, 2 * first, 4 * first))


def _x(v, digits=2):
    return "–" if v is None else f"{v:.{digits}f}x"


def table(rows) -> list:
    """Markdown lines of section 6."""
    drt = [r for r in rows if r["engine"] == "DRT"]
    if not drt:
        return []
    r0 = drt[0]
    out = ["## 6. Adaptive sampling", "",
           f"Each sample scene with its longer side {max(r0['size'])} pixels, the file's "
           "own settings, one process per engine (`docs/adaptive_benchmark.py`). Noise "
           f"Threshold {r0['threshold']} (at most {r0['max_spp']} samples) against uniform "
           f"sampling; each engine's errors against its own {r0['ref_spp']}-sample uniform "
           "render. The uniform samples and seconds that reach the adaptive render's error "
           "come from a power law fitted to uniform renders at "
           f"{', '.join(map(str, r0['ladder']))} samples and a line through their seconds "
           f"(a render under {REPEAT_UNDER:.0f} s is timed three times, the fastest kept). "
           "The saving is that over the adaptive render's (above 1x: adaptive sampling "
           "is cheaper for the same error). Cycles renders the same scenes with its own "
           "sampler; its samples per pixel are its Debug Sample Count pass. "
           f"{UNEVEN} is the Cornell box seen from further back in a grey world (as "
           "tests/test_adaptive_sampling.py's scene): the world around the box is "
           "noise-free, the box's indirect light is noisy.", "",
           "| scene | engine, sampler | adaptive: mean spp (min) | seconds | a sample's "
           "cost, adaptive over uniform | samples saved, rel. MSE | time saved, rel. MSE "
           "| samples saved, display MSE | time saved, display MSE |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        rel, ab = r["metrics"]["relative MSE"], r["metrics"]["display MSE"]
        spp = "–" if r["adaptive_spp"] is None else \
            f"{r['adaptive_spp']:.0f} ({r['min_spp']})"
        out.append(f"| {r['scene']} | {r['engine']}, {r['sampler']} | {spp} | "
                   f"{r['adaptive_seconds']:.1f} | {_x(r['sample_cost'])} | "
                   f"{_x(rel['sample_saving'])} | {_x(rel['time_saving'])} | "
                   f"{_x(ab['sample_saving'])} | {_x(ab['time_saving'])} |")
    cycles = [r for r in rows if r["engine"] == "Cycles"]
    pairs = [(r, _cycles_on(rows, r["scene"])) for r in drt]
    pairs = [(d, c) for d, c in pairs if c is not None]
    ahead = sum(_saving(d) >= _saving(c) for d, c in pairs)
    text = []
    if cycles:
        low, high = min(cycles, key=_saving), max(cycles, key=_saving)
        losing = [c["scene"] for c in cycles if _saving(c) < 1.0]
        drt_losing = sorted({d["scene"] for d in drt if _saving(d) < 1.0})
        text = [f"Cycles' own adaptive sampling saves from {_saving(low):.2f}x "
                f"({low['scene']}) to {_saving(high):.2f}x ({high['scene']}) of its time "
                f"for the same display error; it loses time on {len(losing)} of "
                f"{len(cycles)} scenes ({', '.join(losing) or 'none'}), DRT with at least "
                f"one of its samplers on {len(drt_losing)} "
                f"({', '.join(drt_losing) or 'none'}). DRT's saving is at "
                f"least Cycles' on {ahead} of {len(pairs)} (scene, sampler) pairs. A "
                "stopping rule that ends each pixel at the same error (Cycles', DRT's) "
                "spends samples in proportion to each pixel's variance (as the rule "
                "weighs it); for a mean squared error weighed alike that is exactly as "
                "good as spreading the same samples evenly (over P pixels, n_i = v_i / e "
                "makes the sum of v_i / n_i equal P e, and so does every n_i equal to "
                "their mean), so its saving "
                "comes only from pixels that "
                "converge before the rest (at Min Samples), and the noise of its own error "
                "estimate (one degree of freedom a pixel: some stop early by chance) "
                "costs it a little everywhere.", ""]
    return out + ["", *text,
                  "A sample's cost is the adaptive render's seconds per sample over the "
                  "uniform renders': the pixels that go on sampling after Min Samples are "
                  "the noisy ones, whose paths are often the long ones (in the box, not the "
                  "world that rays leave at once), so the time saved is less than the "
                  "samples saved.", "", *_uneven_text(rows),
                  "Under adaptive sampling the jittered sampler stratifies a pixel's "
                  "samples up to Cycles' first check on their own and later samples in "
                  f"generations that double ({_generations(drt[0]['threshold'])}, ... at "
                  f"threshold {drt[0]['threshold']}): a pixel that stops early holds whole "
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
                  "favour uniform sampling.", ""]


if __name__ == "__main__":
    import json
    scene = sys.argv[1] if len(sys.argv) > 1 else UNEVEN
    print(json.dumps([measure(scene), measure_cycles(scene)], indent=1))
