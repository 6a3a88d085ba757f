"""`python -m drt_addon converge SCENE.blend`: how fast a scene's render converges.

    python -m drt_addon converge SCENE.blend [-o DIR] [--reference drt:N | cycles:N]
        [--samplers jittered,sobol,random] [--integrators path,distribution]
        [--max-samples N] [--with-cycles] [--clamps D:I,...] [--percentage P]
        [--cache-dir DIR]

Renders the scene at 1, 2, 4, ... --max-samples samples per pixel with each sampler and
integrator (engine/convergence.py: one progressive render per random or Sobol curve,
one render per rung for jittered), measures every rung against the reference (RMSE,
relative MSE, FLIP: engine/image_error.py) and writes DIR/convergence.json (per curve:
samples, seconds, the three errors, the fitted log-log slopes against samples and
against seconds) and DIR/convergence.png (convergence_plot.py). The reference and each
curve are cached on disk (convergence_cache.py), so a rerun renders only what changed.
With --clamps, the clamps are measured as what they are, bias traded for noise: the
reference is rendered unclamped, and each Clamp Direct:Indirect pair adds a curve (the
first sampler and integrator) that flattens at its bias while its early rungs are less
noisy. The defaults (DRT reference of 512 samples, ladders to 32 samples, three samplers, the
scene's integrator) take about 4 minutes for the 256x256 Cornell box on 2 cores.
"""
from __future__ import annotations

import json
import math
import os
import platform
import sys
import time
from importlib import import_module

from .batch import EXIT_OK, EXIT_RENDER, EXIT_USAGE, CliError, check_blend, open_blend

DEFAULT_REFERENCE = "drt:512"
DEFAULT_MAX_SAMPLES = 32
DEFAULT_SAMPLERS = "jittered,sobol,random"
MAX_SAMPLES_LIMIT = 1 << 16


def add_parser(sub) -> None:
    c = sub.add_parser("converge", help="error against samples and seconds for each sampler "
                                        "and integrator: convergence.json and .png")
    c.set_defaults(run=run_converge)
    c.add_argument("blend", help="the .blend file")
    c.add_argument("-o", "--output-dir",
                   help="folder for convergence.json and convergence.png "
                        "(default: convergence_<scene> in the current folder)")
    c.add_argument("--reference", default=DEFAULT_REFERENCE,
                   help="drt:N (DRT, N random samples, another seed) or cycles:N (Cycles, "
                        f"the file's settings); default {DEFAULT_REFERENCE}")
    c.add_argument("--samplers", default=DEFAULT_SAMPLERS,
                   help=f"comma-separated DRT samplers (default {DEFAULT_SAMPLERS})")
    c.add_argument("--integrators",
                   help="comma-separated DRT integrators (path, distribution, whitted; "
                        "default: the scene's)")
    c.add_argument("--max-samples", type=int, default=DEFAULT_MAX_SAMPLES,
                   help=f"largest rung of the 1, 2, 4, ... ladder (default "
                        f"{DEFAULT_MAX_SAMPLES})")
    c.add_argument("--with-cycles", action="store_true",
                   help="add Cycles' own curve (the file's Cycles settings, dashed)")
    c.add_argument("--clamps",
                   help="comma-separated Clamp Direct:Indirect pairs (0 = off), each a "
                        "curve of the first sampler and integrator; the reference is then "
                        "rendered unclamped, so the clamps show their bias (e.g. 0:0,0:1)")
    c.add_argument("--percentage", type=int,
                   help="resolution percentage, 1..10000 (default: the scene's)")
    c.add_argument("--cache-dir", help="where references and curves are cached (default: "
                                       "~/.cache/drt/converge)")


def parse_reference(text: str):
    engine_name, _, samples = text.partition(":")
    engine_name = engine_name.strip().lower()
    if engine_name not in ("drt", "cycles") or not samples.strip().isdigit():
        raise CliError(EXIT_USAGE, f"drt: error: --reference must be drt:N or cycles:N, got "
                                   f"{text!r}")
    n = int(samples)
    if not 2 <= n <= 1 << 24:
        raise CliError(EXIT_USAGE, "drt: error: the reference needs 2..16777216 samples")
    return engine_name, n


def _names(text: str, allowed, option: str) -> list:
    names = [n.strip().lower() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in allowed]
    if not names or unknown:
        raise CliError(EXIT_USAGE, f"drt: error: {option} takes a comma-separated list of "
                                   f"{', '.join(allowed)}; got {text!r}")
    return list(dict.fromkeys(names))


def _validate(args):
    from .engine_link import engine
    settings_mod = import_module(engine.__name__ + ".settings")
    ref = parse_reference(args.reference)
    samplers = _names(args.samplers, settings_mod.SAMPLERS, "--samplers")
    integrators = None if args.integrators is None else \
        _names(args.integrators, settings_mod.INTEGRATORS, "--integrators")
    if not 1 <= args.max_samples <= MAX_SAMPLES_LIMIT:
        raise CliError(EXIT_USAGE, f"drt: error: --max-samples must be in "
                                   f"1..{MAX_SAMPLES_LIMIT}")
    if args.percentage is not None and not 1 <= args.percentage <= 10000:
        raise CliError(EXIT_USAGE, "drt: error: --percentage must be in 1..10000")
    return ref, samplers, integrators, parse_clamps(args.clamps, ref[0])


def parse_clamps(text, reference_engine: str) -> list:
    """[(direct, indirect), ...] of --clamps."""
    if not text:
        return []
    pairs = []
    for item in text.split(","):
        d, sep, i = item.strip().partition(":")
        try:
            pair = (float(d), float(i))
        except ValueError:
            pair = None
        if not sep or pair is None or min(pair) < 0 or not all(map(math.isfinite, pair)):
            raise CliError(EXIT_USAGE, f"drt: error: --clamps takes Direct:Indirect pairs of "
                                       f"numbers >= 0 (0 = off), got {item.strip()!r}")
        pairs.append(pair)
    if reference_engine != "drt":
        raise CliError(EXIT_USAGE, "drt: error: --clamps measures bias against an unclamped "
                                   "DRT reference: use --reference drt:N")
    return list(dict.fromkeys(pairs))


def _export(bpy):
    """(scene description, engine settings) of the open file, warnings to stderr."""
    from .export import ExportError, Reporter, export_scene

    def report(_kind, message):
        print(f"drt: warning: {message}", file=sys.stderr)
    try:
        description = export_scene(bpy.context.evaluated_depsgraph_get(), Reporter(report))
        settings = bpy.context.scene.drt.to_engine_settings().validate()
    except (ExportError, ValueError) as e:
        raise CliError(EXIT_RENDER, f"drt: error: export failed: {e}") from None
    return description, settings


def _progress_bar(total: int):
    from tqdm import tqdm
    return tqdm(total=total, unit="path", unit_scale=True, file=sys.stderr, disable=None,
                dynamic_ncols=True, smoothing=0.1)


def run_converge(args) -> int:
    (ref_engine, ref_samples), samplers, integrators, clamps = _validate(args)
    check_blend(args.blend)
    stem = os.path.splitext(os.path.basename(args.blend))[0]
    out_dir = args.output_dir or f"convergence_{stem}"
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as e:
        raise CliError(EXIT_USAGE, f"drt: error: cannot create the output folder {out_dir}: "
                                   f"{e.strerror}") from None
    import bpy

    from . import register
    from .convergence_cache import ConvergeCache, default_cache_dir
    from .convergence_plot import plot_study
    from .convergence_study import Study, ladder_paths
    from .engine_link import engine
    convergence = import_module(engine.__name__ + ".convergence")
    image_error = import_module(engine.__name__ + ".image_error")

    t_start = time.perf_counter()
    register()
    open_blend(bpy, args.blend)
    scene = bpy.context.scene
    if args.percentage is not None:
        scene.render.resolution_percentage = args.percentage
    if scene.camera is None:
        raise CliError(EXIT_RENDER, "drt: error: render failed: the scene has no active camera")
    description, settings = _export(bpy)
    integrators = integrators or [settings.integrator]
    rungs = convergence.sample_ladder(args.max_samples)
    pixels = description.width * description.height
    spp_total = ref_samples + sum(ladder_paths(rungs, s) for s in samplers) * len(integrators) \
        + ladder_paths(rungs, samplers[0]) * len(clamps) + (sum(rungs) if args.with_cycles else 0)
    cache = ConvergeCache(args.cache_dir or default_cache_dir())
    with _progress_bar(spp_total * pixels) as bar:
        study = Study(bpy, args.blend, description, settings, cache, on_paths=bar.update)
        bar.set_description(f"reference {ref_engine}:{ref_samples}")
        try:
            ref, ref_key, ref_cached = study.reference(ref_engine, ref_samples,
                                                       unclamped=bool(clamps))
        except ValueError as e:
            raise CliError(EXIT_RENDER, f"drt: error: cannot render the reference: {e}") \
                from None
        if ref_cached:
            bar.update(ref_samples * pixels)
        floor = image_error.noise_floor(ref.variance_of_mean, ref.image)
        curves, skipped = [], []
        for integrator in integrators:
            for sampler in samplers:
                bar.set_description(f"DRT {integrator} {sampler}")
                curve = study.drt_curve(sampler, integrator, rungs, ref, ref_key, floor)
                if "skipped" in curve:
                    if not any(s["reason"] == curve["skipped"] for s in skipped):
                        bar.write(f"drt: warning: {curve['label']} skipped: "
                                  f"{curve['skipped']}", file=sys.stderr)
                    skipped.append({"label": curve["label"], "reason": curve["skipped"]})
                else:
                    curves.append(curve)
        for direct, indirect in clamps:
            bar.set_description(f"DRT clamp {direct:g}:{indirect:g}")
            curves.append(study.drt_curve(samplers[0], integrators[0], rungs, ref, ref_key,
                                          floor, clamp=(direct, indirect)))
        if args.with_cycles:
            bar.set_description("Cycles")
            curves.append(study.cycles_curve(rungs, ref, ref_key, floor))
    if not curves:
        raise CliError(EXIT_RENDER, f"drt: error: no curve could be rendered: "
                                    f"{skipped[0]['reason']}")
    result = {
        "scene": stem, "file": os.path.abspath(args.blend),
        "resolution": [description.width, description.height],
        "reference": {"spec": f"{ref_engine}:{ref_samples}",
                      "engine": "DRT" if ref_engine == "drt" else "Cycles",
                      "samples": ref.samples, "seconds": ref.seconds, "cached": ref_cached,
                      "clamps": "off" if clamps else "the file's",
                      "sampler": convergence.REFERENCE_SAMPLER if ref_engine == "drt"
                      else scene.cycles.sampling_pattern.lower(),
                      "noise_floor": floor},
        "metrics": {"rmse": "sqrt(mean((a - b)^2)) over pixels and channels",
                    "relmse": f"mean((a - b)^2 / (b^2 + {image_error.RELMSE_EPS:g}))",
                    "flip": "mean LDR-FLIP (flip-evaluator) of the images clipped to [0, 1]",
                    "slopes": "least-squares slope of log(error) against log(samples) and "
                              "log(seconds); MSE-like errors less the reference's noise "
                              "floor, over rungs above twice it (RMSE through its square)"},
        "curves": curves,
        "skipped": skipped,
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version(),
                    "platform": platform.platform()},
        "total_seconds": time.perf_counter() - t_start,
    }
    json_path = os.path.join(out_dir, "convergence.json")
    png_path = os.path.join(out_dir, "convergence.png")
    with open(json_path, "w") as f:
        json.dump(result, f, indent=1)
    plot_study(result, png_path)
    print(summary(result))
    print(f"drt: wrote {json_path} and {png_path} ({result['total_seconds']:.1f} s)")
    return EXIT_OK


COLUMNS = ("curve", "spp", "seconds", "relMSE", "RMSE", "FLIP", "relMSE slope/spp",
           "relMSE slope/s", "RMSE slope/spp", "FLIP slope/spp")


def _slope(v):
    return "n/a" if v is None else f"{v:+.2f}"


def summary_rows(result: dict) -> list:
    """Per curve, the COLUMNS as text: its last rung and its fitted slopes."""
    rows = []
    for c in result["curves"]:
        s = c["slopes"]
        rows.append([c["label"], str(c["samples"][-1]), f"{c['seconds'][-1]:.2f}",
                     f"{c['relmse'][-1]:.2e}", f"{c['rmse'][-1]:.2e}", f"{c['flip'][-1]:.4f}",
                     _slope(s["samples"]["relmse"]), _slope(s["seconds"]["relmse"]),
                     _slope(s["samples"]["rmse"]), _slope(s["samples"]["flip"])])
    return rows


def summary(result: dict) -> str:
    ref = result["reference"]
    rows = [list(COLUMNS)] + summary_rows(result)
    widths = [max(len(r[i]) for r in rows) for i in range(len(COLUMNS))]
    lines = [f"reference: {ref['engine']} {ref['samples']} spp, {ref['seconds']:.1f} s"
             f"{' (cached)' if ref['cached'] else ''}; its noise floor relMSE "
             f"{ref['noise_floor']['relmse']:.2e}"]
    for r in rows:
        lines.append("  ".join([r[0].ljust(widths[0])] +
                               [v.rjust(w) for v, w in zip(r[1:], widths[1:])]))
    lines.append("(plain Monte Carlo: relMSE slope -1, RMSE -0.5)")
    for s in result.get("skipped", []):
        lines.append(f"skipped {s['label']}: {s['reason']}")
    return "\n".join(lines)
