"""The first run on a fresh machine: section 10 of docs/benchmarks.md (called by
docs/make_benchmarks.py; alone: `.venv/bin/python docs/first_run.py`).

Times, as whole processes with an empty kernel cache (a fresh NUMBA_CACHE_DIR each):
  a. the README's first command after its install: `python -m drt_addon compile`, then
     `python -m drt_addon render sample_blends/cornell_box.blend`;
  b. the render alone, compiling what it needs itself (a user who skips the compile step,
     or Blender's first F12).
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
    targets = [("10. README's first command: render time to the first image, fresh clone",
                f"<= {TARGET:.0f} s", f"{r['after_render']:.1f} s (set-up compile "
                f"{r['compile_step']:.0f} s; a render that compiles itself "
                f"{r['alone_render']:.0f} s)", r["after_render"] <= TARGET)]
    return lines, targets


if __name__ == "__main__":
    result = measure()
    lines, targets = section(result)
    print("\n".join(lines))
    print(targets)
    sys.exit(0)
