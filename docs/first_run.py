"""The first run on a fresh machine: section 10 of docs/benchmarks.md (called by
docs/make_benchmarks.py; alone: `.venv/bin/python docs/first_run.py`).

Times, as whole processes with an empty kernel cache (a fresh NUMBA_CACHE_DIR each):
  a. the README's first command after its install: `python -m drt_addon compile`, then
     `python -m drt_addon render sample_blends/cornell_box.blend`;
  b. the render alone, compiling what it needs itself (a user who skips the compile step,
     or Blender's first F12 from a zip built without kernels);
  c. the extension zip: `python -m drt_addon package --platform linux-x64` (its kernels
     compiled per CPU tier) and with `--no-kernels`, sizes and build times; then Blender's
     first F12 of the Cornell box after Install from Disk of the zip, in a fresh user
     folder: its render time and the kernels it compiled.
Reads each render's own "rendered in N s of render time" and the compile step's lines
(kernels compiled per scene).
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PY = os.path.join(ROOT, ".venv", "bin", "python")
RENDER = ["-m", "drt_addon", "render", "sample_blends/cornell_box.blend", "--no-progress",
          "-o"]
TARGET = 40.0        # seconds of render time to the first image


def _run(args, env) -> tuple[float, str]:
    t0 = time.perf_counter()
    out = subprocess.run([PY, *args], cwd=ROOT, env=env, check=True, capture_output=True,
                         text=True)
    return time.perf_counter() - t0, out.stdout + out.stderr


def _render_seconds(text: str) -> float:
    return float(re.search(r"rendered in ([0-9.]+) s of render time", text).group(1))


# Blender, Install from Disk into a fresh user folder, F12 of the Cornell box at the
# file's settings; prints the seconds and the kernels compiled.
F12 = """
import sys, time, bpy
zip_path, blend = sys.argv[-2:]
bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default",
                                         enable_on_install=True)
bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False)
bpy.context.scene.render.engine = "DRT"
t0 = time.perf_counter()
bpy.ops.render.render(write_still=False)
seconds = time.perf_counter() - t0
last = sys.modules["bl_ext.user_default.drt.drt_addon.render_engine"].last_render
stats = last["stats"]
print("F12", seconds, stats.kernels_compiled, stats.compile_seconds, last["ok"])
"""


def measure_zip(tmp) -> dict:
    out = {}
    env = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_", "DRT_"))}
    for tag, extra in (("kernels", []), ("no_kernels", ["--no-kernels"])):
        folder = os.path.join(tmp, "zip-" + tag)
        seconds, text = _run(["-m", "drt_addon", "package", "--platform", "linux-x64",
                              "-o", folder, *extra], env)
        zip_path = [l for l in text.splitlines() if l.endswith(".zip")][-1]
        out[tag] = dict(seconds=seconds, mb=os.path.getsize(zip_path) / 1e6, zip=zip_path,
                        tiers=re.findall(r"compiled the (\S+) kernels in ([0-9.]+) s", text))
    user = os.path.join(tmp, "blender-user")
    whole, text = _run(["-c", F12, out["kernels"]["zip"],
                        os.path.join(ROOT, "sample_blends", "cornell_box.blend")],
                       dict(env, BLENDER_USER_RESOURCES=user))
    f12 = next(l for l in text.splitlines() if l.startswith("F12 ")).split()
    out["f12"] = dict(whole=whole, seconds=float(f12[1]), compiled=int(f12[2]),
                      compile_seconds=float(f12[3]), ok=f12[4] == "True")
    return out


def measure() -> dict:
    tmp = tempfile.mkdtemp(prefix="drt-first-run-")
    base = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    out = {}
    env = dict(base, NUMBA_CACHE_DIR=os.path.join(tmp, "with-compile-step"))
    out["compile_step"], text = _run(["-m", "drt_addon", "compile", "--no-progress"], env)
    out["compile_lines"] = [l for l in text.splitlines() if l.startswith("drt: ")]
    out["after_whole"], text = _run(RENDER + [os.path.join(tmp, "a.png")], env)
    out["after_render"] = _render_seconds(text)
    env = dict(base, NUMBA_CACHE_DIR=os.path.join(tmp, "render-alone"))
    out["alone_whole"], text = _run(RENDER + [os.path.join(tmp, "b.png")], env)
    out["alone_render"] = _render_seconds(text)
    out["zip"] = measure_zip(tmp)
    return out


def section(r: dict) -> tuple[list, list]:
    lines = ["## 10. The first run", "",
             "`docs/first_run.py`: whole processes on an empty kernel cache, as on a fresh "
             "clone after the README's install step. Numba compiles the kernels a render "
             "reaches on first use and caches them; the README's first command compiles "
             "them during set-up (`python -m drt_addon compile`, which renders a few sample "
             "scenes at 16 px), so its render loads them.", "",
             "| | seconds |", "|---|---|",
             f"| `python -m drt_addon compile` (set-up) | {r['compile_step']:.1f} |",
             f"| then the render: whole process | {r['after_whole']:.1f} |",
             f"| ... its render time | {r['after_render']:.1f} |",
             f"| the render alone on an empty cache: whole process | {r['alone_whole']:.1f} |",
             f"| ... its render time (the compile included) | {r['alone_render']:.1f} |", "",
             "The compile step, scene by scene:", "", "```", *r["compile_lines"], "```", ""]
    z = r.get("zip")
    if z:
        k, f = z["kernels"], z["f12"]
        tiers = ", ".join(f"{t} {float(s):.0f} s" for t, s in k["tiers"])
        lines += ["The extension zip for linux-x64 (`python -m drt_addon package --platform "
                  "linux-x64`) ships the kernels those scenes reach, compiled once per CPU "
                  f"tier ({tiers}); then Blender's first F12 of the Cornell box after "
                  "Install from Disk, in a fresh user folder:", "",
                  "| | zip | build, seconds |", "|---|---|---|",
                  f"| with its kernels (default) | {k['mb']:.0f} MB | {k['seconds']:.0f} |",
                  f"| `--no-kernels` | {z['no_kernels']['mb']:.0f} MB | "
                  f"{z['no_kernels']['seconds']:.0f} |", "",
                  f"First F12 from the zip with its kernels: {f['seconds']:.1f} s, "
                  f"{f['compiled']} kernels compiled ({f['compile_seconds']:.1f} s of "
                  f"compiling); the Blender process {f['whole']:.0f} s in all.", ""]
    targets = [("10. README's first command: render time to the first image, fresh clone",
                f"<= {TARGET:.0f} s", f"{r['after_render']:.1f} s (set-up compile "
                f"{r['compile_step']:.0f} s; a render that compiles itself "
                f"{r['alone_render']:.0f} s)", r["after_render"] <= TARGET)]
    if z:
        targets.append(("10. The extension zip's first F12 compiles nothing (x86-64)",
                        "0 kernels compiled", f"{z['f12']['compiled']} compiled, F12 "
                        f"{z['f12']['seconds']:.1f} s", z["f12"]["compiled"] == 0
                        and z["f12"]["ok"]))
    return lines, targets


if __name__ == "__main__":
    result = measure()
    lines, targets = section(result)
    print("\n".join(lines))
    print(targets)
    sys.exit(0)
