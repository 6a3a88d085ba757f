"""Cycles' side of a convergence study, rendered by the Cycles in the same bpy: one
render per rung at the file's own settings, with only the sample count, the seed and
what would stop a render early changed (adaptive sampling, a time limit; denoising is
off too, since it is not sampling). The seconds of a rung are the whole render call, so
they include Cycles' scene sync and BVH build, which DRT's rung seconds leave out (DRT
reports its setup apart).

A Cycles reference is two renders of half the samples each with different seeds: their
mean is the reference and a quarter of their squared difference an unbiased per-pixel
estimate of the variance of that mean (the reference's own noise).
"""
from __future__ import annotations

import time
from importlib import import_module

from .engine_link import engine
from .image_files import render_result

convergence = import_module(engine.__name__ + ".convergence")


def use_cycles(scene, samples: int, seed: int) -> None:
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.samples = int(samples)
    c.seed = int(seed)
    c.use_animated_seed = False
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.time_limit = 0.0
    c.device = "CPU"


def render_cycles(bpy, scene, samples: int, seed: int):
    """(image (h, w, 3), seconds of the render call)."""
    previous = scene.render.engine
    use_cycles(scene, samples, seed)
    try:
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=False)
        seconds = time.perf_counter() - t0
        return render_result(scene), seconds
    finally:
        scene.render.engine = previous


def _pixels(scene) -> int:
    pct = scene.render.resolution_percentage / 100.0
    return int(scene.render.resolution_x * pct) * int(scene.render.resolution_y * pct)


def cycles_ladder(bpy, scene, rungs, on_paths=None):
    """A convergence.Rung per sample count, each its own render with the file's seed."""
    seed = scene.cycles.seed
    for k in sorted(set(int(r) for r in rungs)):
        image, seconds = render_cycles(bpy, scene, k, seed)
        if on_paths is not None:
            on_paths(k * _pixels(scene))
        yield convergence.Rung(k, seconds, image)


def cycles_reference(bpy, scene, samples: int, on_paths=None):
    """A convergence.Reference from two half-sample renders with seeds of their own."""
    half = max(1, samples // 2)
    seed = scene.cycles.seed + convergence.REFERENCE_SEED_OFFSET
    a, t_a = render_cycles(bpy, scene, half, seed)
    if on_paths is not None:
        on_paths(half * _pixels(scene))
    b, t_b = render_cycles(bpy, scene, half, seed + 1)
    if on_paths is not None:
        on_paths(half * _pixels(scene))
    return convergence.Reference(image=0.5 * (a + b), variance_of_mean=0.25 * (a - b) ** 2,
                                 samples=2 * half, seconds=t_a + t_b)
