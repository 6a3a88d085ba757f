"""`python -m drt_addon compile`: compile and cache DRT's kernels before the first render.

Numba compiles DRT's kernels on first use and caches them on disk (engine/kernels/kernel_cache.py),
so a machine's first render pays the compile once (docs/benchmarks.md measures it). This
command pays it during set-up instead: it renders a few of the sample scenes, each
chosen for code paths the others do not reach, at a tiny size and one sample, with
progress ("compiling kernels, one time: N of M") per scene. Later renders of any scene
load the kernels from the cache. It writes nothing but the cache, and changes no file.

With `--jobs N` (default: one per core) the scenes are shared out among N processes,
which compile in parallel; a kernel two of them reach is compiled by one while the
other waits for it (engine/kernels/compile_lock.py), then loaded from the cache.

    python -m drt_addon compile [--jobs N] [SCENE.blend ...]     (default: SCENES)
"""
from __future__ import annotations

import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# Sample scenes whose renders together reach the kernels DRT renders with: surfaces and
# an area lamp; rigid and deforming motion; a homogeneous volume; node programs and
# closures; a thin lens; an HDRI world; transparency and ray visibility; subsurface
# scattering (rays cast inside the kernel).
SCENES = ("cornell_box", "fog_room", "motion_cube", "motion_torus", "node_closures",
          "dof", "hdri_world", "ray_visibility", "subsurface")
SIZE = 16          # pixels along the longer side of each compile render


def add_parser(sub) -> None:
    c = sub.add_parser("compile", help="compile and cache the kernels before the first "
                                       "render (renders a few sample scenes at 16 px)")
    c.add_argument("blends", nargs="*", metavar="SCENE.blend",
                   help="scenes to render (default: a set of the sample scenes)")
    c.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    c.add_argument("--jobs", type=int, default=os.cpu_count() or 1, metavar="N",
                   help="processes compiling in parallel (default: one per core)")
    c.set_defaults(run=run)


def _tiny(scene) -> None:
    r = scene.render
    r.resolution_percentage = max(1, round(100 * SIZE / max(r.resolution_x, r.resolution_y)))
    scene.render.engine = "DRT"
    scene.drt.samples = 1
    if hasattr(scene, "cycles"):
        # Render > Denoise, on in new files: the first-hit passes it reads compile too
        scene.cycles.use_denoising = True


def run(args) -> int:
    from .batch import check_blend
    blends = args.blends or [os.path.join(ROOT, "sample_blends", f"{n}.blend")
                             for n in SCENES]
    for blend in blends:
        check_blend(blend)
    blends = [os.path.abspath(b) for b in blends]
    jobs = max(1, min(args.jobs, len(blends)))
    if jobs == 1:
        return _compile_here(blends, args.no_progress)
    return _compile_in_processes(blends, jobs, args.no_progress)


def _compile_in_processes(blends, jobs: int, no_progress: bool) -> int:
    """Scenes dealt round-robin to `jobs` processes (`compile --jobs 1`), their lines
    passed on as they come, a bar over the scenes on stderr."""
    import selectors
    import subprocess

    from tqdm import tqdm

    from .batch import EXIT_OK, EXIT_RENDER
    t_all = time.perf_counter()
    procs = [subprocess.Popen([sys.executable, "-m", "drt_addon", "compile", "--jobs", "1",
                               "--no-progress", *blends[k::jobs]], cwd=ROOT,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                              bufsize=1)
             for k in range(jobs)]
    bar = tqdm(total=len(blends), unit="scene", file=sys.stderr, leave=False,
               disable=no_progress, dynamic_ncols=True,
               desc=f"compiling kernels, one time, {jobs} processes")
    sel = selectors.DefaultSelector()
    for p in procs:
        sel.register(p.stdout, selectors.EVENT_READ, "out")
        sel.register(p.stderr, selectors.EVENT_READ, "err")
    open_streams = 2 * len(procs)
    while open_streams:
        for key, _ in sel.select():
            line = key.fileobj.readline()
            if not line:
                sel.unregister(key.fileobj)
                open_streams -= 1
                continue
            if key.data == "err":
                bar.write(line.rstrip("\n"), file=sys.stderr)
            elif line.startswith("drt: ") and "kernels compiled," in line:
                bar.write(line.rstrip("\n"), file=sys.stdout)
                bar.update(1)
    bar.close()
    codes = [p.wait() for p in procs]
    if any(codes):
        return next(c for c in codes if c) or EXIT_RENDER
    print(f"drt: kernels compiled and cached in {time.perf_counter() - t_all:.0f} s "
          f"({jobs} processes)", flush=True)
    return EXIT_OK


def _compile_here(blends, no_progress: bool) -> int:
    from .batch import EXIT_OK, EXIT_RENDER, open_blend
    import bpy
    from tqdm import tqdm

    from . import register, render_engine
    register()
    bar = None

    def compiling(done, total):
        nonlocal bar
        if bar is None:
            bar = tqdm(total=total, unit="kernel", file=sys.stderr, leave=False,
                       disable=no_progress, dynamic_ncols=True,
                       desc=render_engine.compile_line(done, total).rsplit(":", 1)[0])
        bar.total = total
        bar.update(done - bar.n)

    render_engine.compile_listeners.append(compiling)
    t_all = time.perf_counter()
    try:
        for blend in blends:
            open_blend(bpy, blend)
            scene = bpy.context.scene
            _tiny(scene)
            t0 = time.perf_counter()
            try:
                bpy.ops.render.render(write_still=False)
            except RuntimeError:
                pass          # DRT's own report is in last_render
            if bar is not None:
                bar.close()
                bar = None
            last = render_engine.last_render
            if not last.get("ok"):
                print(f"drt: error: compile render of {blend} failed: "
                      f"{last.get('error') or 'unknown'}", file=sys.stderr)
                return EXIT_RENDER
            stats = last["stats"]
            print(f"drt: {os.path.basename(blend)}: {stats.kernels_compiled} kernels "
                  f"compiled, {time.perf_counter() - t0:.1f} s", flush=True)
    finally:
        render_engine.compile_listeners.remove(compiling)
    print(f"drt: kernels compiled and cached in {time.perf_counter() - t_all:.0f} s",
          flush=True)
    return EXIT_OK
