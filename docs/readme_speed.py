"""The README's first command, before and after the compiled kernels: section 8 of
docs/benchmarks.md (called by docs/make_benchmarks.py; alone:
`.venv/bin/python docs/readme_speed.py [BASE_COMMIT]`).

Checks BASE_COMMIT (default: the last commit before the samplers and the path tracer
became compiled kernels) out into a temporary git worktree beside this checkout, with
this checkout's .venv, and times, in each tree, the render part of the README's first
command on that tree's own sample scene, as whole processes:

    .venv/bin/python -m drt_addon render sample_blends/cornell_box.blend -o OUT.png

twice: the first run of a fresh checkout (the current tree compiles its kernels into
an empty cache), then a second run (kernels loaded from the cache). Prints the seconds.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# the parent of "Samplers as compiled Numba kernels": NumPy samplers and path tracer
BASE_COMMIT = "5123345^"
COMMAND = ["-m", "drt_addon", "render", "sample_blends/cornell_box.blend", "-o"]


def _timed_render(tree: str, out: str, env: dict) -> float:
    t0 = time.perf_counter()
    subprocess.run([os.path.join(ROOT, ".venv", "bin", "python"), *COMMAND, out], cwd=tree,
                   env=env, check=True, capture_output=True, text=True)
    return time.perf_counter() - t0


def _samples(tree: str) -> int:
    code = ("import bpy, drt_addon; drt_addon.register(); "
            "bpy.ops.wm.open_mainfile(filepath='sample_blends/cornell_box.blend'); "
            "s = bpy.context.scene; print('SPP', s.drt.samples, s.render.resolution_x * "
            "s.render.resolution_percentage // 100, s.render.resolution_y * "
            "s.render.resolution_percentage // 100)")
    out = subprocess.run([os.path.join(ROOT, ".venv", "bin", "python"), "-c", code], cwd=tree,
                         check=True, capture_output=True, text=True).stdout
    line = next(l for l in out.splitlines() if l.startswith("SPP"))
    spp, w, h = map(int, line.split()[1:])
    return spp, w, h


def measure(base: str = BASE_COMMIT) -> dict:
    tmp = tempfile.mkdtemp(prefix="drt-readme-")
    base_tree = os.path.join(tmp, "base")
    rev = subprocess.run(["git", "rev-parse", "--short", base], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout.strip()
    subprocess.run(["git", "worktree", "add", "--detach", "-q", base_tree, rev], cwd=ROOT,
                   check=True)
    try:
        out = {}
        for name, tree in (("before", base_tree), ("now", ROOT)):
            cache = os.path.join(tmp, f"cache-{name}")
            env = {**os.environ, "NUMBA_CACHE_DIR": cache}     # an empty kernel cache
            png = os.path.join(tmp, f"{name}.png")
            first = _timed_render(tree, png, env)
            second = _timed_render(tree, png, env)
            spp, w, h = _samples(tree)
            out[name] = dict(first=first, second=second, samples=spp, size=(w, h))
            print(name, out[name], flush=True)
        out["base"] = rev
        return out
    finally:
        subprocess.run(["git", "worktree", "remove", "--force", base_tree], cwd=ROOT)
        shutil.rmtree(tmp, ignore_errors=True)


def table(r: dict) -> list:
    b, n = r["before"], r["now"]
    return ["## 8. The README's first command", "",
            "`.venv/bin/python -m drt_addon render sample_blends/cornell_box.blend -o "
            f"OUT.png`, whole processes, in this checkout and in commit {r['base']} (the "
            "last before the compiled kernels: NumPy samplers and path tracer), each on "
            "its own sample scene (`docs/readme_speed.py`).", "",
            "| | pixels | samples | first run (s) | second run (s) | second run per "
            "pixel sample (us) |", "|---|---|---|---|---|---|",
            *(f"| {name} | {d['size'][0]}x{d['size'][1]} | {d['samples']} | "
              f"{d['first']:.1f} | {d['second']:.1f} | {1e6 * _per(d):.2f} |"
              for name, d in (("before", b), ("now", n))),
            "", f"The second run is {b['second'] / n['second']:.1f}x faster than before "
            f"({_per(b) / _per(n):.1f}x per pixel sample, process start and file load "
            "included). The first run of a fresh checkout also compiles the kernels into "
            f"the cache: {n['first'] - n['second']:.0f} s more than a cached run.", ""]


def _per(d: dict) -> float:
    return d["second"] / (d["samples"] * d["size"][0] * d["size"][1])


if __name__ == "__main__":
    print("\n".join(table(measure(*sys.argv[1:2]))))
