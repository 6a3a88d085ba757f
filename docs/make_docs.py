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


def _rmse(a, b):
    return float(np.sqrt(((a - b) ** 2).mean()))


def settings_costs(lines):
    """What each setting costs (seconds) and buys (error against a converged render)."""
    from engine import RenderSettings, render
    from engine_scenes import cornell_box
    from stratification_scenes import penumbra_scene

    scene = cornell_box(64, 64)
    ref, _ = render(scene, RenderSettings(samples=4096, sampler="sobol", seed=999,
                                          clamp_indirect=0.0))
    ref = ref.mean()
    lines += ["## What the settings cost and buy",
              "",
              "Cornell box (tests/engine_scenes.py), 64x64, path tracing; error is the RMSE "
              "against a 4096-sample Sobol render, relative to that render's mean.", "",
              "| setting | value | seconds | paths/s | relative RMSE |", "|---|---|---|---|---|"]
    for spp in (16, 64, 256):
        film, st = render(scene, RenderSettings(samples=spp, seed=1, clamp_indirect=0.0))
        lines.append(f"| samples | {spp} | {st.seconds:.2f} | {st.paths_per_second():,.0f} | "
                     f"{_rmse(film.mean(), ref) / ref.mean():.3f} |")
    for integ in ("whitted", "distribution", "path"):
        film, st = render(scene, RenderSettings(samples=64, seed=1, integrator=integ,
                                                clamp_indirect=0.0))
        err = f"{_rmse(film.mean(), ref) / ref.mean():.3f}" if integ == "path" else \
            "(converges to another image)"
        lines.append(f"| integrator | {integ} | {st.seconds:.2f} | {st.paths_per_second():,.0f} "
                     f"| {err} |")
    for clamp in (0.0, 10.0, 1.0):
        film, st = render(scene, RenderSettings(samples=64, seed=1, clamp_indirect=clamp))
        lines.append(f"| clamp indirect | {clamp:g} | {st.seconds:.2f} | "
                     f"{st.paths_per_second():,.0f} | {_rmse(film.mean(), ref) / ref.mean():.3f} "
                     f"(bias: mean {film.mean().mean() / ref.mean() - 1:+.2%}) |")
    pen = penumbra_scene(32)
    pref, _ = render(pen, RenderSettings(samples=4096, sampler="sobol", seed=5,
                                         diffuse_bounces=0))
    pref = pref.mean()
    for sampler in ("random", "jittered", "sobol"):
        film, st = render(pen, RenderSettings(samples=64, sampler=sampler, seed=2,
                                              diffuse_bounces=0))
        lines.append(f"| sampler (penumbra scene, 64 spp) | {sampler} | {st.seconds:.2f} | "
                     f"{st.paths_per_second():,.0f} | {_rmse(film.mean(), pref) / pref.mean():.3f} |")
    lines.append("")


def threads_and_memory(lines):
    """Thread scaling, peak memory and cancel latency at 1080p, each in a fresh process."""
    import json
    import subprocess

    probe = r"""
import json, sys, time
sys.path[:0] = [sys.argv[1], sys.argv[1] + '/tests', sys.argv[1] + '/docs']
from render_phases import peak_mb   # VmHWM: maxrss would be this script's, copied at fork
from engine import RenderSettings, render
from engine_scenes import cornell_box
w, h, spp, threads, cancel_after = (int(a) for a in sys.argv[2:7])
scene = cornell_box(w, h)
marks = {}
def cancelled():
    if cancel_after and 'asked' not in marks and time.perf_counter() - t0 > cancel_after:
        marks['asked'] = time.perf_counter()
    return 'asked' in marks
t0 = time.perf_counter()
film, st = render(scene, RenderSettings(samples=spp, threads=threads), cancelled=cancelled)
end = time.perf_counter()
print(json.dumps(dict(seconds=st.seconds, paths=st.paths, units=st.units_done,
                      rate=st.paths_per_second(),
                      latency=(end - marks['asked']) if 'asked' in marks else None,
                      maxrss_mb=peak_mb())))
"""

    def measure(*args):
        out = subprocess.run([sys.executable, "-c", probe, ROOT, *map(str, args)],
                             capture_output=True, text=True, check=True).stdout
        return json.loads(out.strip().splitlines()[-1])

    one = measure(480, 270, 16, 1, 0)
    two = measure(480, 270, 16, 2, 0)
    hd = measure(1920, 1080, 2, 2, 0)
    cancel = measure(1920, 1080, 64, 2, 5)
    lines += ["## Threads, memory and cancel", "",
              "| measurement | value |", "|---|---|",
              f"| paths/s, 1 thread (Cornell 480x270, 16 spp) | {one['rate']:,.0f} |",
              f"| paths/s, 2 threads | {two['rate']:,.0f} (x{two['rate'] / one['rate']:.2f}) |",
              f"| 1920x1080, 2 spp: seconds | {hd['seconds']:.1f} |",
              f"| 1920x1080: peak resident memory of the whole process (MB) | "
              f"{hd['maxrss_mb']:.0f} |",
              f"| 1920x1080: seconds per work unit (32768 paths) | "
              f"{hd['seconds'] / max(hd['units'], 1) * 2:.2f} |",
              f"| 1920x1080: cancel latency (s from the request to the return) | "
              f"{cancel['latency']:.2f} |",
              "",
              f"Two threads render x{two['rate'] / one['rate']:.2f} the paths of one: the "
              "compiled kernels and Embree release the GIL; [benchmarks.md](benchmarks.md), "
              "section 2, measures the share of a thread's time that still holds it.", "",
              "Memory does not grow with the sample count (tests/test_memory.py): a 1920x1080 "
              "render at 1024 samples uses the same work units as at 2 samples, plus the film "
              "(7 float64 values per pixel, 116 MB at 1080p).", ""]


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
    settings_costs(lines)
    threads_and_memory(lines)
    with open(os.path.join(DOCS, "measurements.md"), "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
