"""`python -m drt_addon compile`: compile and cache DRT's kernels before the first render.

Numba compiles DRT's kernels on first use and caches them on disk (engine/kernels/jit.py),
so a machine's first render pays the compile once (docs/benchmarks.md measures it). This
command pays it during set-up instead: it renders a few of the sample scenes, each
chosen for code paths the others do not reach, at a tiny size and one sample, with
progress ("compiling kernels, one time: N of M") per scene. Later renders of any scene
load the kernels from the cache. It writes nothing but the cache, and changes no file.

    python -m drt_addon compile [SCENE.blend ...]     (default: SCENES)
"""
from __future__ import annotations

import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# Sample scenes whose renders together reach the kernels DRT renders with: surfaces and
# an area lamp; rigid and deforming motion; a homogeneous volume; node programs and
# closures; a thin lens; an HDRI world; transparency and ray visibility.
SCENES = ("cornell_box", "motion_cube", "motion_torus", "fog_room", "node_closures",
          "dof", "hdri_world", "ray_visibility")
SIZE = 16          # pixels along the longer side of each compile render


def add_parser(sub) -> None:
    c = sub.add_parser("compile", help="compile and cache the kernels before the first "
                                       "render (renders a few sample scenes at 16 px)")
    c.add_argument("blends", nargs="*", metavar="SCENE.blend",
                   help="scenes to render (default: a set of the sample scenes)")
    c.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    c.set_defaults(run=run)


def _tiny(scene) -> None:
    r = scene.render
    r.resolution_percentage = max(1, round(100 * SIZE / max(r.resolution_x, r.resolution_y)))
    scene.render.engine = "DRT"
    scene.drt.samples = 1


def run(args) -> int:
    from .batch import EXIT_OK, EXIT_RENDER, check_blend, open_blend
    blends = args.blends or [os.path.join(ROOT, "sample_blends", f"{n}.blend")
                             for n in SCENES]
    for blend in blends:
        check_blend(blend)
    import bpy
    from tqdm import tqdm

    from . import register, render_engine
    register()
    bar = None

    def compiling(done, total):
        nonlocal bar
        if bar is None:
            bar = tqdm(total=total, unit="kernel", file=sys.stderr, leave=False,
                       disable=args.no_progress, dynamic_ncols=True,
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
