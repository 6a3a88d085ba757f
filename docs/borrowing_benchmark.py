"""What borrowed arrays save: a one-thread Cornell render with the per-ray kernels
compiled without reference counting (`@kernel(allocates=False)`, engine/kernels/jit.py;
the default) and with every kernel counting references (`DRT_BORROWING=0`), each in its
own process, kernels loaded from their cache (the first run of a mode compiles them).

    python docs/borrowing_benchmark.py [--quick]

Prints {mode: seconds} as JSON (the median of three renders per mode); called by
docs/make_benchmarks.py for section 1.
"""
from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

_RENDER = """
import sys, time
sys.path[:0] = [{root!r}, {tests!r}]
from engine import RenderSettings, render
from engine_scenes import cornell_box
scene = cornell_box({w}, {h})
render(scene, RenderSettings(samples=1, threads=1))       # kernels loaded or compiled
times = []
for _ in range(3):
    t0 = time.perf_counter()
    render(scene, RenderSettings(samples={spp}, threads=1))
    times.append(time.perf_counter() - t0)
print(sorted(times)[1])
"""


def seconds(borrowing: bool, w: int, h: int, spp: int) -> float:
    env = dict(os.environ, DRT_BORROWING="1" if borrowing else "0")
    code = _RENDER.format(root=ROOT, tests=os.path.join(ROOT, "tests"), w=w, h=h, spp=spp)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True).stdout
    return float(out.strip().splitlines()[-1])


def main(quick: bool = False) -> dict:
    w, h, spp = (128, 128, 4) if quick else (256, 256, 16)
    runs = {"borrowed": [], "counted": []}
    for _ in range(1 if quick else 2):       # alternate the modes against drifting load
        runs["borrowed"].append(seconds(True, w, h, spp))
        runs["counted"].append(seconds(False, w, h, spp))
    return {"paths": w * h * spp, **{k: statistics.median(v) for k, v in runs.items()}}


if __name__ == "__main__":
    print(json.dumps(main("--quick" in sys.argv)))
