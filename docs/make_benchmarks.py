"""Speed benchmarks of DRT on this machine; writes docs/benchmarks.md.

    .venv/bin/python docs/make_benchmarks.py [--quick]

The five targets of the speed work, each measured here and nowhere else (tests never time
anything):
  1. per-core efficiency: all-in rays per second of a whole render (camera, shadow and
     bounce rays, with sampling, shading and film) over bare Embree's rays per second on
     exactly the same rays, one thread;
  2. cores: the speed-up of N threads over one;
  3. time to equal error against Cycles, whole processes side by side
     (docs/equal_error_benchmark.py);
  4. a 1M-triangle mesh: depsgraph to first sample, and peak memory, against Cycles;
  5. 1000 rigidly moving objects: one sample with motion blur over one without;
and, for the trade of speed against accuracy, 6. what adaptive sampling saves per sample
scene (docs/adaptive_benchmark.py) and 7. every sampler's and integrator's convergence
slopes and the clamps' bias for noise (docs/make_convergence_docs.py). Where a target is
not met, the section measures why: a stage-by-stage profile (docs/stage_profile.py), the
GIL-held share of a thread's time, DRT's fixed cost per process, the big mesh's export,
build and first sample. 8. times the README's first command against the last commit
before the compiled kernels (docs/readme_speed.py).
Every figure in docs/benchmarks.md is printed by this script.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests")]
from big_scene_benchmarks import (big_mesh, big_mesh_section, many_instances,  # noqa: E402
                                  many_instances_section, many_moving,
                                  save_big_mesh)
from stage_profile import gil_bound, table_lines as stage_table  # noqa: E402
import borrowing_benchmark  # noqa: E402
import vertex_costs  # noqa: E402
from equal_error_benchmark import equal_error, equal_error_section, fmt_row  # noqa: E402
DOCS = os.path.join(ROOT, "docs")
SAMPLES = os.path.join(ROOT, "sample_blends")


# ----------------------------------------------------------------------------- 1 and 2

def per_core_efficiency(w, h, spp):
    """All-in rays/s of a one-thread Cornell render over bare Embree on the same rays."""
    from engine import RenderContext, RenderSettings, render
    from engine_scenes import cornell_box

    scene = cornell_box(w, h)
    settings = RenderSettings(samples=spp, threads=1)
    render(scene, RenderSettings(samples=1, threads=1))        # compile / load kernels
    ctx = RenderContext(scene, settings)
    ctx.accel.recorder = []
    t0 = time.perf_counter()
    film, stats = render(scene, settings, context=ctx)
    seconds = time.perf_counter() - t0
    batches = ctx.accel.recorder
    rays = sum(len(b[1]) for b in batches)
    t0 = time.perf_counter()
    ctx.accel.replay(batches)
    bare_seconds = time.perf_counter() - t0
    ctx.close()
    from stage_profile import profile_render
    profile = profile_render(scene, settings)                  # the same render, timed
    return dict(rays=rays, seconds=seconds, bare_seconds=bare_seconds, profile=profile,
                rate=rays / seconds, bare_rate=rays / bare_seconds,
                integrator=type(ctx.integrator).__name__,
                shadow=ctx.accel.rays_traced["OCCLUDED"], paths=stats.paths)


def borrowing_lines(b) -> list:
    """Section 1's paragraph on reference counting (docs/borrowing_benchmark.py)."""
    return [f"Numba counts references to every array a compiled function is given, also "
            f"to each array of a tuple (the light table, the geometry), with an atomic "
            f"increment on entry and a decrement on return, unless the function is "
            f"compiled without it. The per-ray kernels that allocate nothing borrow their "
            f"arrays instead (`@kernel(allocates=False)`, engine/kernels/jit.py): the same "
            f"render ({b['paths']:,} paths, one thread) takes {b['borrowed']:.2f} s so, "
            f"{b['counted']:.2f} s with every kernel counting (`DRT_BORROWING=0`; "
            f"{b['counted'] / b['borrowed']:.2f}x; `docs/borrowing_benchmark.py`): the "
            f"counting took {1 - b['borrowed'] / b['counted']:.0%} of the counted "
            f"render."]


def thread_scaling(w, h, spp, max_threads):
    from engine import RenderSettings, render
    from engine_scenes import cornell_box

    scene = cornell_box(w, h)
    render(scene, RenderSettings(samples=1, threads=1))
    out = {}
    for n in range(1, max_threads + 1):
        film, stats = render(scene, RenderSettings(samples=spp, threads=n))
        out[n] = stats.paths_per_second()
    from stage_profile import profile_render
    return out, profile_render(scene, RenderSettings(samples=spp, threads=1))[2]


# ----------------------------------------------------------------------------- report

def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller renders, for a smoke run")
    ap.add_argument("--adaptive-scenes", default="",
                    help="section 6 for these sample scenes only (comma-separated .blend "
                         "names): their rows replace or join the last run's")
    ap.add_argument("--skip", default="", help="comma-separated sections to skip (1..10)")
    ap.add_argument("--only", default="", help="comma-separated sections to run (1..10); the "
                    "others keep their last measured figures (docs/benchmarks.json)")
    ap.add_argument("--section6-page", action="store_true",
                    help="write section 6 again from its last measured rows (no render)")
    args = ap.parse_args()
    skip = set(args.skip.split(",")) - {""}
    if args.only:
        skip |= set(map(str, range(1, 11))) - set(args.only.split(","))
    saved = _load_sections()
    if args.section6_page:
        from adaptive_benchmark import table, targets as adaptive_targets
        rows = saved["6"]["rows"]
        saved["6"].update(lines=table(rows), targets=adaptive_targets(rows))
        _save_sections(saved)
        _write_page(saved)
        return
    q = args.quick
    cores = os.cpu_count() or 1
    base = f"{platform.machine()}, {cores} cores, Python {platform.python_version()}"
    started = {"load": os.getloadavg()[0]}
    lines, targets = [], []

    def done(section):
        """Keep what the section just measured (its lines and targets, the machine and
        its load average when the section started and ended) and start the next."""
        end = os.getloadavg()[0]
        machine = (f"{base}; load average {started['load']:.2f} when it started, "
                   f"{end:.2f} when it ended")
        started["load"] = end
        saved[section] = dict(lines=lines[:], targets=targets[:], machine=machine)
        _save_sections(saved)
        lines.clear()
        targets.clear()

    if "1" not in skip:
        r = per_core_efficiency(*((128, 128, 4) if q else (256, 256, 16)))
        eff = r["rate"] / r["bare_rate"]
        total, stages, _ = r["profile"]
        top_stage, top_secs = max(stages.items(), key=lambda kv: kv[1])
        embree = sum(v for k, v in stages.items() if k.startswith("Embree"))
        vertex_ns = next(v for k, v in stages.items() if k.startswith("shading")) \
            / (r["rays"] - r["shadow"]) * 1e9
        ray_ns = r["bare_seconds"] / r["rays"] * 1e9
        targets.append(("1. all-in rays/s over bare Embree, one thread", ">= 0.5",
                        f"{eff:.2f} ({top_stage.split(':')[0]} {top_secs / total:.0%} of the "
                        f"time, Embree {embree / total:.0%}: a path vertex's shading "
                        f"{vertex_ns:.0f} ns, a bare Embree ray {ray_ns:.0f} ns)", eff >= 0.5))
        lines += ["## 1. Per-core efficiency", "",
                  f"Cornell box (tests/engine_scenes.py), {r['paths']:,} paths, one thread, "
                  f"{r['integrator']}.", "",
                  "| | rays | seconds | rays/s |", "|---|---|---|---|",
                  f"| whole render (camera, bounce and {r['shadow']:,} shadow rays; sampling, "
                  f"shading, film) | {r['rays']:,} | {r['seconds']:.2f} | {r['rate']:,.0f} |",
                  f"| bare Embree on the same rays | {r['rays']:,} | {r['bare_seconds']:.2f} | "
                  f"{r['bare_rate']:,.0f} |",
                  f"| ratio | | | **{eff:.2f}** |", "",
                  "Where the time goes: the same render again with every stage timed "
                  "(`docs/stage_profile.py`).", "",
                  *stage_table(total, stages, r["bare_seconds"]), "",
                  "The gap is the shading kernel: per path vertex it draws four sampler "
                  "numbers, rebuilds the hit, sets the BSDF up, samples a light, evaluates "
                  "the BSDF there and samples it for the next ray, in scalar float64 code, "
                  "one ray at a time. Each piece timed on its own (compiled loops on the "
                  "scene's own materials, lamp and triangles):", "",
                  *vertex_costs.lines(vertex_costs.measure(), vertex_ns, ray_ns), "",
                  *borrowing_lines(borrowing_benchmark.main(q)), ""]
        print(lines[-3:], flush=True)
        done("1")
    if "2" not in skip:
        rates, held = thread_scaling(*((128, 128, 4) if q else (320, 240, 16)), cores)
        top = rates[cores] / rates[1]
        targets.append((f"2. {cores} threads over one", f">= {0.9 * cores:.1f}x",
                        f"{top:.2f}x (GIL bound {gil_bound(held, cores):.2f}x)",
                        top >= 0.9 * cores))
        lines += ["## 2. Cores", "", "Cornell box, paths per second by thread count.", "",
                  "| threads | paths/s | speed-up |", "|---|---|---|"]
        lines += [f"| {n} | {v:,.0f} | {v / rates[1]:.2f}x |" for n, v in rates.items()]
        lines += ["", f"Of one thread's time, {held:.1%} holds the GIL (Python and NumPy "
                  "between the stages; the compiled kernels and Embree release it; "
                  "`docs/stage_profile.py`), which bounds N threads at "
                  + ", ".join(f"{gil_bound(held, n):.2f}x for {n}" for n in rates)
                  + " (Amdahl). Below that bound, the threads share the memory bus and the "
                  "machine's other load (the load average above).", ""]
        print(lines[-4:], flush=True)
        done("2")
    if "3" not in skip:
        big = os.path.join(tempfile.mkdtemp(prefix="drt-bench-"), "big_mesh.blend")
        tris = save_big_mesh(big)         # section 4's scene
        scenes = [("Cornell box", "cornell_box.blend"), ("metals", "metals.blend"),
                  ("glass", "glass.blend"), ("glossy dielectric", "glossy_dielectric.blend"),
                  ("depth of field", "dof.blend"), ("motion blur", "motion_cube.blend"),
                  (f"{tris / 1e6:.1f}M-triangle mesh (section 4's)", big)]
        pct, ref, ladder = (25, 256, [4, 16]) if q else (100, 1024, [16, 64, 256])
        rows, results = [], []
        for name, blend in scenes:
            results.append(equal_error(os.path.join(SAMPLES, blend), pct, ref, ladder))
            rows.append(fmt_row(name, results[-1]))
            print(rows[-1], flush=True)
        sec_lines, sec_targets = equal_error_section(results, rows, pct, ref)
        lines += sec_lines
        targets += sec_targets
        done("3")
    if "4" not in skip:
        load_now = os.getloadavg()[0]
        big = big_mesh()
        sec_lines, sec_targets = big_mesh_section(big, load_now)
        lines += sec_lines
        targets += sec_targets
        load_now = os.getloadavg()[0]
        sec_lines, sec_targets = many_instances_section(many_instances(), load_now, big)
        lines += sec_lines
        targets += sec_targets
        done("4")
    if "5" not in skip:
        r = many_moving(200 if q else 1000)
        ratio = r["blur"] / r["static"]
        targets.append(("5. 1000 moving objects: a sample with blur over without", "<= 2x",
                        f"{ratio:.1f}x", ratio <= 2.0))
        lines += ["## 5. Many moving objects", "",
                  "1000 cubes, each moving rigidly over the shutter, one sun; seconds per "
                  "sample (160x120).", "",
                  "| motion blur | s per sample |", "|---|---|",
                  f"| off | {r['static']:.2f} |", f"| on | {r['blur']:.2f} |", ""]
        done("5")
    if "6" not in skip:
        from adaptive_benchmark import (UNEVEN, measure, measure_cycles, table,
                                        targets as adaptive_targets)
        rows = []
        chosen = [b for b in args.adaptive_scenes.split(",") if b] or ADAPTIVE_SCENES
        size = dict(long_side=32 if q else 96, ref_spp=256 if q else 2048,
                    ladder=(4, 16, 64) if q else (16, 64, 256))
        for blend in chosen:
            path = blend if blend == UNEVEN else os.path.join(SAMPLES, blend)
            for sampler in ("jittered", "sobol"):
                rows.append(measure(path, sampler=sampler, **size))
                print(blend, sampler, rows[-1]["metrics"], flush=True)
            rows.append(measure_cycles(path, **size))
            print(blend, "Cycles", rows[-1]["metrics"], flush=True)
        lines += table(rows) if chosen == ADAPTIVE_SCENES else \
            _join_rows(saved["6"]["lines"], table(rows), chosen)
        targets += adaptive_targets(rows) if chosen == ADAPTIVE_SCENES else \
            saved["6"]["targets"]
        done("6")
        if chosen == ADAPTIVE_SCENES:
            saved["6"]["rows"] = rows            # its page again: --section6-page
            _save_sections(saved)
    if "7" not in skip:      # the convergence studies (cached in ~/.cache/drt/converge)
        import make_convergence_docs as studies
        lines += studies.benchmark_section(studies.main(["cornell_box"] if q else []))
        done("7")
    if "8" not in skip:
        import readme_speed
        lines += readme_speed.table(readme_speed.measure())
        done("8")
    if "9" not in skip:
        import make_batch_benchmark as frames_bench
        table, speedup = frames_bench.measure(4 if q else 8)
        frames_bench.write_doc(table)
        targets.append(("frames on 2 Dask workers over 1 (batch renderer)", ">= 1.8x",
                        f"{speedup:.2f}x", speedup >= 1.8))
        lines += ["## 9. A frame range on Dask workers", "",
                  "`python -m drt_addon render --workers N` on a local Dask cluster "
                  "(`docs/make_batch_benchmark.py`; also in [batch.md](batch.md)).", "",
                  *table.splitlines(), ""]
        done("9")
    if "10" not in skip:
        import first_run
        sec_lines, sec_targets = first_run.section(first_run.measure())
        lines += sec_lines
        targets += sec_targets
        done("10")
    _write_page(saved)


ADAPTIVE_SCENES = ("cornell_box.blend", "metals.blend", "glass.blend",
                   "glossy_dielectric.blend", "dof.blend", "motion_cube.blend",
                   "hdri_world.blend", "fog_room.blend", "product_shot.blend",
                   "cornell_box.blend from afar")      # adaptive_benchmark.UNEVEN
SECTIONS_JSON = os.path.join(DOCS, "benchmarks.json")


def _join_rows(old: list, new: list, scenes) -> list:
    """Section 6's lines with the table rows of `scenes` taken from `new` (replacing
    theirs in `old`, or added after its last row)."""
    fresh = [line for line in new if line.startswith("| ") and line.split(" | ")[0][2:]
             in scenes]
    kept = [line for line in old if not (line.startswith("| ") and
                                         line.split(" | ")[0][2:] in scenes)]
    last = max(i for i, line in enumerate(kept) if line.startswith("| "))
    return kept[:last + 1] + fresh + kept[last + 1:]


def _load_sections() -> dict:
    if os.path.exists(SECTIONS_JSON):
        with open(SECTIONS_JSON) as f:
            return json.load(f)
    return {}


def _save_sections(saved: dict) -> None:
    with open(SECTIONS_JSON, "w") as f:       # numpy scalars as plain numbers and bools
        json.dump(saved, f, indent=1, default=lambda o: o.item())


def _write_page(saved: dict) -> None:
    order = sorted(saved, key=int)
    head = ["# Benchmarks", "",
            "Written by `docs/make_benchmarks.py` (figures kept in docs/benchmarks.json, so "
            "one section can be rerun with `--only N`); rerun it to reproduce. Each "
            "section's machine and load: "
            + "; ".join(f"{k}: {saved[k]['machine']}" for k in order)
            + " (a load above 0.5 means other work shared the cores and the figures are "
            "pessimistic).", "",
            "## Targets", "", "| target | wanted | measured | met |", "|---|---|---|---|"]
    for k in order:
        head += [f"| {a} | {b} | {c} | {'yes' if ok else '**no**'} |"
                 for a, b, c, ok in saved[k]["targets"]]
    body = [line for k in order for line in saved[k]["lines"]]
    with open(os.path.join(DOCS, "benchmarks.md"), "w") as f:
        f.write("\n".join(head + [""] + body) + "\n")
    print("\n".join(head))


if __name__ == "__main__":
    main()
