"""Section 3 of docs/benchmarks.md (called by docs/make_benchmarks.py): time to equal
error against Cycles, whole processes side by side, each engine against its own long
render."""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "docs"), os.path.join(ROOT, "tests")]
from engine.image_error import relmse  # noqa: E402
from big_scene_benchmarks import user_env  # noqa: E402
from conftest import read_image_linear  # noqa: E402


def _cli_render(blend, engine, samples, out, percentage, extra=()):
    """Whole process, as a user runs it: returns wall seconds."""
    code = ("import sys, runpy; sys.argv = ['drt'] + sys.argv[1:]; "
            "from drt_addon.batch import main; raise SystemExit(main())")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", code, "render", blend, "-o", out, "--engine", engine,
                    "--samples", str(samples), "--percentage", str(percentage), *extra],
                   cwd=ROOT, check=True, capture_output=True, text=True, env=user_env())
    return time.perf_counter() - t0


def _read_exr(path):
    import bpy
    return read_image_linear(bpy, path)


TIMED_RUNS = 3      # processes per timed point of section 3; their median is kept


def equal_error(blend, percentage, ref_spp, ladder, cycles_spp=64, runs=TIMED_RUNS):
    """Each engine against its own long render (noise, not bias: the bias between the two
    engines is measured in docs/comparisons.md). Time for DRT to reach the relative MSE
    Cycles reaches at `cycles_spp`, from a power law fitted to the ladder, over Cycles'
    time for those samples. Each timed point is the median of `runs` processes, the
    engines taking turns (a process of 1 to 4 s on a shared machine can meet a burst of
    other work); its error is that of its image, the same in every run (a fixed
    seed)."""
    tmp = tempfile.mkdtemp(prefix="drt-bench-")
    refs = {}
    for engine in ("CYCLES", "DRT"):
        ref = os.path.join(tmp, f"{engine}_ref.exr")
        _cli_render(blend, engine, ref_spp, ref, percentage)
        refs[engine] = _read_exr(ref)
    # Cycles at 1 sample too: its seconds as a line in samples, like DRT's
    points = [("CYCLES", 1), ("CYCLES", cycles_spp)] + [("DRT", spp) for spp in ladder]
    secs = {point: [] for point in points}
    for _ in range(runs):
        for engine, spp in points:
            out = os.path.join(tmp, f"{engine}_{spp}.exr")
            secs[engine, spp].append(_cli_render(blend, engine, spp, out, percentage))
    result = {"CYCLES": [], "DRT": []}
    for engine, spp in points:
        out = os.path.join(tmp, f"{engine}_{spp}.exr")
        result[engine].append((spp, float(np.median(secs[engine, spp])),
                               relmse(_read_exr(out), refs[engine])))
    (_, t_c1, _), (_, t_c, e_c) = result["CYCLES"]
    per_c = (t_c - t_c1) / (cycles_spp - 1)
    spp, secs, err = (np.array(c, dtype=np.float64) for c in zip(*result["DRT"]))
    slope, icpt = np.polyfit(np.log(spp), np.log(err), 1)        # log e = icpt + slope log n
    need = float(np.exp((np.log(e_c) - icpt) / slope))
    per, fixed = np.polyfit(spp, secs, 1)                         # seconds = fixed + per n
    t_d = fixed + per * need
    return dict(cycles=result["CYCLES"][1:], drt=result["DRT"], slope=slope, fixed=fixed,
                per=per, drt_spp_needed=need, drt_seconds=t_d, cycles_seconds=t_c,
                ratio=t_d / t_c, cycles_fixed=t_c - per_c * cycles_spp, cycles_per=per_c,
                # sampling alone (no fixed costs): DRT's samples for Cycles' error over
                # Cycles' samples, each at its own seconds per sample
                sampling_ratio=per * need / max(per_c * cycles_spp, 1e-9))


def equal_error_section(results, rows, pct, ref):
    """(lines, targets) of section 3 from equal_error's results and their table rows."""
    ratios = [r["ratio"] for r in results]
    med = float(np.median(ratios))
    fixed = float(np.median([r["fixed"] for r in results]))
    fixed_c = float(np.median([r["cycles_fixed"] for r in results]))
    sampling = [r["sampling_ratio"] for r in results]
    targets = [("3. time to Cycles' 64-spp error, median scene", "<= 1.0x",
                f"{med:.2f}x (fixed cost per process: DRT {fixed:.1f} s, Cycles "
                f"{fixed_c:.1f} s; sampling alone, DRT over Cycles: median "
                f"{np.median(sampling):.2f}x)", bool(med <= 1.0)),
               ("3. ... worst scene", "<= 1.5x", f"{max(ratios):.2f}x",
                bool(max(ratios) <= 1.5)),
               ("3. fixed cost of a process (file, tracer, kernels, acceleration "
                "structure), median scene, DRT less Cycles", "<= 0.3 s",
                f"{fixed - fixed_c:+.1f} s (DRT {fixed:.1f} s, Cycles {fixed_c:.1f} s; "
                "section 4 times its parts)", bool(fixed - fixed_c <= 0.3))]
    lines = ["## 3. Time to equal error against Cycles", "",
             f"Whole processes (`python -m drt_addon render`, file load and export "
             f"included), {pct}% resolution, the scenes' own settings; each time the "
             f"median of {TIMED_RUNS} processes, the engines taking turns. Each engine's "
             f"error is its relative MSE against its own {ref}-sample render, so this "
             "measures noise per second; the bias between the engines is measured in "
             "[comparisons.md](comparisons.md). DRT's time for Cycles' error comes from "
             "a power law fitted to its sample ladder; its seconds as a line in "
             "samples: a fixed cost per process (Python, `bpy` and the add-on, the "
             "file, DRT's tracer (Numba, Embree) imported by its first render, export, "
             "the compiled kernels loaded from their cache, the acceleration structure) "
             "plus a cost per sample. Cycles' seconds are a line too, from its renders "
             "at 1 and 64 samples. *Sampling alone* leaves the fixed costs out: DRT's "
             "seconds per sample times its samples for Cycles' error, over Cycles' "
             "seconds per sample times 64; it is what a long render (or many frames in "
             "one batch process) approaches. Python's bytecode cache is on, as on a "
             "user's machine (before 2026-11-26 the benchmark ran with "
             "PYTHONDONTWRITEBYTECODE set, so each DRT process compiled its sources "
             "again, about 0.2 s). Until the same day DRT's add-on imported its tracer "
             "when Blender registered it, so Cycles' processes paid about 0.2 s for DRT "
             "too, and the ratios below were lower by that much of Cycles' time.", "",
             "| scene | Cycles | DRT to the same error | DRT / Cycles | DRT: fixed + "
             "per sample | Cycles: fixed + per sample | sampling alone, DRT / Cycles "
             "| DRT ladder |", "|---|---|---|---|---|---|---|---|", *rows, "",
             f"DRT's fixed cost per process is a median {fixed:.1f} s against Cycles' "
             f"{fixed_c:.1f} s (the tracer's import, the compiled kernels' loading and "
             "the acceleration structure; section 4 times each). Sampling alone, DRT "
             f"takes a median {np.median(sampling):.2f}x Cycles' time for the same error "
             f"({min(sampling):.2f}x to {max(sampling):.2f}x over the scenes"
             + ("; a path vertex's shading in scalar float64 code, section 1, is DRT's "
                "cost there)." if np.median(sampling) > 1.0 else ")."), ""]
    return lines, targets


def fmt_row(name, r):
    c_spp, c_s, c_e = r["cycles"][0]
    ladder = ", ".join(f"{s} spp {t:.1f} s relMSE {e:.2e}" for s, t, e in r["drt"])
    return (f"| {name} | {c_s:.1f} s for {c_spp} spp (relMSE {c_e:.2e}) | "
            f"{r['drt_seconds']:.1f} s ({r['drt_spp_needed']:.0f} spp; slope "
            f"{r['slope']:.2f}) | **{r['ratio']:.2f}x** | {r['fixed']:.1f} s + "
            f"{r['per'] * 1e3:.0f} ms | {r['cycles_fixed']:.1f} s + "
            f"{r['cycles_per'] * 1e3:.0f} ms | {r['sampling_ratio']:.2f}x | {ladder} |")
