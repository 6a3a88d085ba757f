"""The speed-up of 2 local Dask workers over 1 on a frame range; writes its table into
docs/batch.md (between the `batch-benchmark` markers).

    .venv/bin/python docs/make_batch_benchmark.py [--frames N] [--samples S]

The job: the Cornell box of tests/batch_scenes.py (the short block moving), 96 x 72
pixels, N frames (default 8) of S samples (default 32). Measured for each configuration,
after warming up (every worker has imported bpy, opened the file and loaded the compiled
kernels): the wall time of the whole frame range, frames written to disk, the fastest of
--repeat runs (default 2). Also shown:
the same range on one machine without Dask (one process, the engine's threads on every
core), and the one-off cost of starting a local cluster and warming its workers.
"""
from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests")]
DOC = os.path.join(ROOT, "docs", "batch.md")
BEGIN, END = "<!-- batch-benchmark:begin -->", "<!-- batch-benchmark:end -->"
PERCENTAGE = 300                      # of the test scene's 32 x 24


def time_dask(bpy, blend, frames, overrides, workers, out_dir, repeat):
    from drt_addon.batch import plan_outputs
    from drt_addon.dask_jobs import connect, file_stamp, render_frames, render_part
    t0 = time.perf_counter()
    client, cluster = connect(workers=workers)
    try:
        client.wait_for_workers(workers)
        warm = [client.submit(render_part, blend, file_stamp(blend), frames[0], overrides,
                              0, 1, workers=[w], pure=False)
                for w in client.scheduler_info()["workers"]]
        client.gather(warm)
        startup = time.perf_counter() - t0
        bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False)
        scene = bpy.context.scene
        from drt_addon.overrides import apply_overrides
        apply_overrides(scene, overrides)
        jobs, _ = plan_outputs(bpy, scene, os.path.join(out_dir, f"w{workers}_####.png"),
                               frames)
        runs = []
        for _ in range(repeat):
            t1 = time.perf_counter()
            results = render_frames(client, bpy, scene, blend, jobs, overrides)
            wall = time.perf_counter() - t1
            assert len(results) == len(frames)
            runs.append((wall, sum(r.seconds for r in results) / wall))
        wall, busy = min(runs)
        return wall, busy, startup
    finally:
        client.close()
        cluster.close()


def time_single_machine(blend, frames, samples, out_dir, repeat):
    from drt_addon.batch import main
    common = [blend, "--samples", str(samples), "--percentage", str(PERCENTAGE),
              "--no-progress"]
    assert main(["render", *common, "-o", os.path.join(out_dir, "warm.png"),
                 "--frame", str(frames[0])]) == 0
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        assert main(["render", *common, "-o", os.path.join(out_dir, "one_####.png"),
                     "--frames", f"{frames[0]}-{frames[-1]}"]) == 0
        times.append(time.perf_counter() - t0)
    return min(times)


def write_doc(table: str) -> None:
    text = open(DOC).read()
    pattern = re.compile(re.escape(BEGIN) + ".*?" + re.escape(END), re.S)
    if not pattern.search(text):
        raise SystemExit(f"{DOC} has no {BEGIN} ... {END} block")
    open(DOC, "w").write(pattern.sub(lambda _: f"{BEGIN}\n{table}\n{END}", text))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=8)
    ap.add_argument("--samples", type=int, default=32)
    ap.add_argument("--repeat", type=int, default=2,
                    help="runs of each configuration; the fastest counts (other jobs may "
                         "share the cores)")
    args = ap.parse_args()
    table, _ = measure(args.frames, args.samples, args.repeat)
    print(table)
    write_doc(table)


def measure(n_frames: int = 8, samples: int = 32, repeat: int = 2):
    """(the table for docs/batch.md, the speed-up of 2 workers over 1)."""
    import bpy

    import drt_addon
    from batch_scenes import build_animated_cornell
    from drt_addon.overrides import Overrides
    drt_addon.register()
    load = os.getloadavg()[0]          # before anything of ours runs
    work = tempfile.mkdtemp(prefix="drt-batch-bench-")
    blend = build_animated_cornell(bpy, os.path.join(work, "anim.blend"))
    bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False)
    bpy.context.scene.frame_end = n_frames
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    frames = list(range(1, n_frames + 1))
    overrides = Overrides(samples=samples, percentage=PERCENTAGE)
    one, busy1, start1 = time_dask(bpy, blend, frames, overrides, 1, work, repeat)
    two, busy2, start2 = time_dask(bpy, blend, frames, overrides, 2, work, repeat)
    here = time_single_machine(blend, frames, samples, work, repeat)
    w, h = 32 * PERCENTAGE // 100, 24 * PERCENTAGE // 100
    rows = [
        "| configuration | seconds for the range | per frame | tasks running at once "
        "| speed-up over 1 worker |",
        "|---|---|---|---|---|",
        f"| Dask, 1 local worker (`--workers 1`) | {one:.1f} | {one / len(frames):.2f} | "
        f"{busy1:.2f} | 1.00 |",
        f"| Dask, 2 local workers (`--workers 2`) | {two:.1f} | {two / len(frames):.2f} | "
        f"{busy2:.2f} | **{one / two:.2f}** |",
        f"| one machine, no Dask (engine threads on both cores) | {here:.1f} | "
        f"{here / len(frames):.2f} | - | {one / here:.2f} |",
    ]
    note = (f"\n{len(frames)} frames of {w} x {h} pixels at {samples} samples, written "
            f"as PNG; fastest of {repeat} runs each; {os.cpu_count()} cores (the machine "
            f"has 2), load average {load:.1f} when the run started and "
            f"{os.getloadavg()[0]:.1f} at its end (other jobs shared the cores). Starting the "
            f"local cluster and warming its workers (import bpy, open the file, load the "
            f"compiled kernels) took {start1:.1f} s for 1 worker and {start2:.1f} s for 2, "
            "once per job. *Tasks running at once*: the tasks' own seconds added up, over the "
            "wall time (2.0 when both workers render all the time).")
    if load > (os.cpu_count() or 1) - 0.5:
        note += (" The cores were busy with other jobs during this run (load average above "
                 "the core count less one of ours): the speed-up above is what was left of a "
                 "second core, not what a second core gives; compare the one-machine row, "
                 "whose engine threads had both cores too. Rerun on an idle machine.")
    note += " Written by `docs/make_batch_benchmark.py`."
    return "\n".join(rows) + "\n" + note, one / two


if __name__ == "__main__":
    main()
