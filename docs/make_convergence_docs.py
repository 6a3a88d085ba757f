"""Runs `python -m drt_addon converge` on each sample scene and writes docs/convergence.md
(per scene: the fitted convergence slope of every sampler and integrator, and Cycles')
and the plots docs/images/convergence_<scene>.png.

    .venv/bin/python docs/make_convergence_docs.py [SCENE ...] [--fresh]

Every scene renders 128 pixels wide, ladders of 1..MAX_SAMPLES samples for the three
samplers and the path and distribution integrators, and Cycles' ladder, all against a
DRT reference of REFERENCE_SAMPLES independent samples. References and curves are cached
in ~/.cache/drt/converge (a rerun only measures what changed; --fresh uses an empty
cache). Takes about 20 minutes on 2 cores from an empty cache.
"""
from __future__ import annotations

import json
import os
import platform
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")
SAMPLES = os.path.join(ROOT, "sample_blends")

# (scene, resolution percentage): 128 pixels wide
SCENES = [("cornell_box", 50), ("metals", 200), ("glass", 200), ("glossy_dielectric", 200),
          ("dof", 200), ("motion_cube", 200), ("hdri_world", 200), ("fog_room", 200),
          ("product_shot", 200)]
MAX_SAMPLES = 64
REFERENCE_SAMPLES = 1024
SAMPLERS = "jittered,sobol,random"
INTEGRATORS = "path,distribution"
# Clamp Direct:Indirect curves besides the file's own clamps (DRT's default: 0:10), all
# against an unclamped reference: their bias traded for noise
CLAMPS = "0:0,0:1"


def run_scene(name, percentage, out_dir, cache_dir):
    from drt_addon.batch import main
    args = ["converge", os.path.join(SAMPLES, name + ".blend"), "-o", out_dir,
            "--percentage", str(percentage), "--reference", f"drt:{REFERENCE_SAMPLES}",
            "--samplers", SAMPLERS, "--integrators", INTEGRATORS,
            "--max-samples", str(MAX_SAMPLES), "--with-cycles", "--clamps", CLAMPS]
    if cache_dir:
        args += ["--cache-dir", cache_dir]
    code = main(args)
    if code != 0:
        raise SystemExit(f"converge failed on {name} (exit {code})")
    with open(os.path.join(out_dir, "convergence.json")) as f:
        return json.load(f)


def save_small_png(src, dst):
    """The plot with a 64-colour palette: a quarter of the bytes, the same look."""
    from PIL import Image
    with Image.open(src) as im:
        im.convert("RGB").quantize(colors=64, method=Image.Quantize.MEDIANCUT).save(
            dst, optimize=True)


def study_render_seconds(result) -> float:
    """The render seconds a study measured (as recorded, whether or not this run took
    them from the cache): reference, every DRT ladder (a progressive one's last rung,
    a jittered one's every rung, plus setup) and Cycles' rungs."""
    total = result["reference"]["seconds"]
    for c in result["curves"]:
        total += c["seconds"][-1] if c["progressive"] else sum(c["seconds"])
        total += c.get("setup_seconds") or 0.0
    return total


def scene_section(result, image_name):
    from drt_addon.converge import COLUMNS, summary_rows
    ref = result["reference"]
    w, h = result["resolution"]
    lines = [f"## {result['scene']}", "",
             f"{w} x {h} pixels; reference: DRT {ref['samples']} samples "
             f"({ref['seconds']:.0f} s; its own noise, relMSE {ref['noise_floor']['relmse']:.1e}, "
             f"is taken off before fitting). Errors and seconds at the last rung.", "",
             f"![convergence of {result['scene']}](images/{image_name})", "",
             "| " + " | ".join(COLUMNS) + " |", "|---" * len(COLUMNS) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in summary_rows(result)]
    reasons = {}
    for s in result.get("skipped", []):
        reasons.setdefault(s["reason"], []).append(s["label"])
    lines += [""] + [f"Not measured: {', '.join(labels)} ({reason})."
                     for reason, labels in reasons.items()] if reasons else []
    return lines + [""]


HEADER = """# Convergence: error against samples and seconds

Written by `docs/make_convergence_docs.py` with `python -m drt_addon converge`; rerun it
to reproduce. Machine: {machine}; load average up to {load} while the curves were measured
(above the core count, other work shared the cores and every curve's seconds are
pessimistic alike). The studies
measured {minutes:.1f} minutes of rendering in all (this run: {run_minutes:.1f} minutes,
less when references and curves came from the cache).

For every sample scene, each DRT sampler (jittered, Sobol, random) with the path and the
distribution integrator renders 1, 2, 4, ... {max_spp} samples per pixel, and Cycles
renders the same ladder with the file's settings (dashed in the plots). The clamps are
measured as what they are, bias traded for noise: the reference is unclamped, and besides
the file's clamps (DRT's defaults: Direct off, Indirect 10) the jittered path tracer
renders with no clamp (0:0) and with Clamp Indirect 1 (0:1), the triangles in the plots.
A clamped curve starts lower (less noise) and flattens at its bias. Every rung is
measured against one long DRT path-traced reference of independent samples and another
seed (so its noise is independent of every curve's):

- **relMSE**: mean((a - b)^2 / (b^2 + 0.01)) over pixels and channels; **RMSE**; and
  **FLIP** (NVIDIA's perceptual metric, `flip-evaluator`; LDR-FLIP of the images clipped
  to [0, 1]). Definitions in `engine/image_error.py`.
- **Slope**: the least-squares slope of log(error) against log(samples) or
  log(seconds), after taking off the error the reference's own noise adds to every
  measurement. Plain Monte Carlo gives -1 for relMSE (-0.5 for RMSE); steeper is better
  (stratified and quasi-Monte Carlo samples can beat -1 where the integrand is smooth).
  A curve that converges to another image than the reference flattens towards 0: the
  distribution integrator leaves out diffuse interreflection, and Cycles differs from
  DRT by the small amounts [comparisons.md](comparisons.md) measures.
- **Seconds**: DRT's render time of the rung (cumulative for random and Sobol, whose
  ladder is one progressive render; jittered renders each rung on its own, since its
  strata depend on the sample count), without the scene export and acceleration
  structure build; Cycles' seconds are whole render calls, its sync and BVH build
  included, so at these small sizes its first rungs are mostly overhead.

Rerun one scene yourself: `python -m drt_addon converge sample_blends/SCENE.blend
--with-cycles -o DIR` (see `python -m drt_addon converge --help`).

"""


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    fresh = "--fresh" in argv
    names = [a for a in argv if not a.startswith("--")]
    scenes = [(n, p) for n, p in SCENES if not names or n in names]
    loads = []
    t0 = time.perf_counter()
    sections, render_seconds, results = [], 0.0, []
    with tempfile.TemporaryDirectory() as tmp:
        cache_dir = os.path.join(tmp, "cache") if fresh else None
        for name, percentage in scenes:
            out_dir = os.path.join(tmp, name)
            result = run_scene(name, percentage, out_dir, cache_dir)
            results.append(result)
            image_name = f"convergence_{name}.png"
            save_small_png(os.path.join(out_dir, "convergence.png"),
                           os.path.join(IMAGES, image_name))
            render_seconds += study_render_seconds(result)
            loads += [c["load_average"] for c in result["curves"] if c.get("load_average")]
            sections += scene_section(result, image_name)
    machine = f"{platform.machine()}, {os.cpu_count()} cores, Python " \
              f"{platform.python_version()}"
    load = f"{max(loads):.2f}" if loads else "(not recorded)"
    text = HEADER.format(machine=machine, load=load, max_spp=MAX_SAMPLES,
                         minutes=render_seconds / 60,
                         run_minutes=(time.perf_counter() - t0) / 60) + "\n".join(sections)
    with open(os.path.join(DOCS, "convergence.md"), "w") as f:
        f.write(text.rstrip() + "\n")
    print(f"wrote docs/convergence.md ({(time.perf_counter() - t0) / 60:.1f} min)")
    return results


def benchmark_section(results) -> list:
    """Section 7 of docs/benchmarks.md: every curve's fitted slopes per sample scene, and
    what the clamps trade (from the studies `main` made)."""
    labels = list(dict.fromkeys(c["label"] for r in results for c in r["curves"]))
    out = ["## 7. Convergence per sampler and integrator", "",
           f"From the convergence studies ([convergence.md](convergence.md), "
           f"`docs/make_convergence_docs.py`: 128 pixels wide, 1 to {MAX_SAMPLES} samples, "
           f"against an unclamped DRT reference of {REFERENCE_SAMPLES} samples). Each cell: "
           "the fitted slope of relative MSE against samples / against seconds (plain Monte "
           "Carlo: -1; steeper is better; near 0: the curve converges to another image, "
           "its bias).", "",
           "| curve | " + " | ".join(r["scene"] for r in results) + " |",
           "|---" * (len(results) + 1) + "|"]
    for label in labels:
        cells = []
        for r in results:
            c = next((c for c in r["curves"] if c["label"] == label), None)
            s = c and c["slopes"]
            cells.append("n/a" if not s or s["samples"]["relmse"] is None else
                         f"{s['samples']['relmse']:+.2f} / {s['seconds']['relmse']:+.2f}")
        out.append(f"| {label} | " + " | ".join(cells) + " |")
    out += ["", "Clamps, bias for noise: relative MSE at 1 and at "
            f"{MAX_SAMPLES} samples (jittered path tracer).", "",
            "| scene | no clamp | file's clamps | Clamp Indirect 1 |", "|---|---|---|---|"]
    for r in results:
        by = {c["label"]: c for c in r["curves"]}
        row = [by.get(f"DRT path jittered clamp {CLAMPS.split(',')[0]}"), by.get(
            "DRT path jittered"), by.get(f"DRT path jittered clamp {CLAMPS.split(',')[1]}")]
        out.append(f"| {r['scene']} | " + " | ".join(
            "n/a" if c is None else f"{c['relmse'][0]:.2e} -> {c['relmse'][-1]:.2e}"
            for c in row) + " |")
    return out + [""]


if __name__ == "__main__":
    main()
