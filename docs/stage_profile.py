"""Where a render's time goes, stage by stage: the measured causes behind sections 1 and 2
of docs/benchmarks.md (called by docs/make_benchmarks.py).

Each stage of the compiled path tracer's wavefront loop (engine/integrators/
compiled_path.py and engine/render.py) is wrapped in a timer for the length of one
render: Embree's closest-hit and shadow queries (wrapper included), the compiled
kernels (camera rays, sampler keys, shading, shadow results), the film. What no stage
accounts for is Python and NumPy between the stages: work units, array slicing and
allocation. Timers cost about a microsecond per call, a handful of calls per bounce.

The compiled kernels and Embree release the GIL; Python and NumPy between them mostly
hold it. With a fraction s of one thread's time under the GIL, N threads can run at most
1 / (s + (1 - s) / N) times faster (Amdahl), which `gil_bound` gives for comparison with
the measured thread scaling.
"""
from __future__ import annotations

import contextlib
import time
from collections import defaultdict

# (module path, attribute, stage name, releases the GIL)
STAGES = (
    ("engine.render", "generate_camera_rays", "camera rays (compiled)", True),
    ("engine.render", "pixel_keys", "sampler keys (compiled)", True),
    ("engine.integrators.compiled_path", "pixel_keys", "sampler keys (compiled)", True),
    ("engine.integrators.compiled_path", "camera_cones", "ray footprints (compiled)", True),
    ("engine.integrators.compiled_path", "shade",
     "shading: hit rebuild, BSDF, light sampling, MIS (compiled)", True),
    ("engine.integrators.compiled_path", "add_unoccluded",
     "shadow-ray results into radiance (compiled)", True),
    ("engine.integrators.compiled_path", "add_transmitted",
     "shadow-ray results into radiance (compiled)", True),
    ("engine.film", "Film.add", "film accumulation (NumPy)", False),
)
EMBREE = (("intersect", "Embree closest-hit queries"), ("occluded", "Embree shadow queries"))
OTHER = "Python and NumPy between the stages"


def _timed(table, name, fn):
    def timed(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            table[name] += time.perf_counter() - t0
    return timed


@contextlib.contextmanager
def stage_timers(accel):
    """Times every stage of renders made inside the block; yields {stage: seconds}."""
    from importlib import import_module
    table = defaultdict(float)
    undo = []
    for module, attr, name, _ in STAGES:
        owner = import_module(module)
        *path, leaf = attr.split(".")
        for part in path:
            owner = getattr(owner, part)
        original = owner.__dict__[leaf]
        undo.append((owner, leaf, original))
        setattr(owner, leaf, _timed(table, name, original))
    for method, name in EMBREE:
        setattr(accel, method, _timed(table, name, getattr(accel, method)))
    try:
        yield table
    finally:
        for owner, leaf, original in undo:
            setattr(owner, leaf, original)
        for method, _ in EMBREE:
            delattr(accel, method)          # the instance attribute hid the method


def profile_render(scene, settings):
    """(total seconds, {stage: seconds} with OTHER the rest, GIL-held fraction) of one
    render of `scene` (kernels already loaded), on settings.threads threads."""
    from engine import RenderContext, render
    ctx = RenderContext(scene, settings)
    with stage_timers(ctx.accel) as table:
        t0 = time.perf_counter()
        render(scene, settings, context=ctx)
        total = time.perf_counter() - t0
    ctx.close()
    stages = dict(table)
    stages[OTHER] = max(total - sum(stages.values()), 0.0)
    free = {name for _, _, name, releases in STAGES if releases} | {n for _, n in EMBREE}
    held = sum(v for k, v in stages.items() if k not in free) / total
    return total, stages, held


def gil_bound(held: float, threads: int) -> float:
    """Amdahl's bound on the speed-up of `threads` threads when a fraction `held` of one
    thread's time holds the GIL."""
    return 1.0 / (held + (1.0 - held) / threads)


def table_lines(total, stages, bare_embree_seconds) -> list:
    """Markdown rows: stage, seconds, share of the render."""
    out = ["| stage | seconds | share |", "|---|---|---|"]
    for name, secs in sorted(stages.items(), key=lambda kv: -kv[1]):
        out.append(f"| {name} | {secs:.2f} | {secs / total:.0%} |")
    out.append(f"| (bare Embree on the same rays, for comparison) | {bare_embree_seconds:.2f} "
               f"| {bare_embree_seconds / total:.0%} |")
    return out
