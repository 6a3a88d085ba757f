"""Sample ladders for convergence studies: one scene rendered at 1, 2, 4, ... samples per
pixel, each rung's image with the seconds it took, and a reference render with its own
noise estimate.

A prefix of a random or Sobol render is itself a render of that many samples (a sample's
numbers do not depend on the sample count, and every prefix of 2**k Owen-scrambled Sobol
samples is a (0, k, 2)-net), so for those samplers one progressive render gives the
whole ladder: consecutive sample ranges [0, 1), [1, 2), [2, 4), ... merge exactly into
one film (engine.render), which is read at each rung with the cumulative render seconds.
The jittered sampler stratifies over the sample count it is given (a prefix of its N
samples covers a random subset of the N strata), so each of its rungs is a render of its
own, costing twice the samples of the progressive ladder in all.

Every rung takes all its samples: adaptive sampling and the time limit are turned off,
and a film with fewer samples in any pixel is an error.
Seconds are the render's own (work units on the thread pool); building the render
context (acceleration structure) is reported apart as `setup_seconds`, and `warm_up`
keeps kernel compilation out of them.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from .film import Film
from .render import RenderContext, render

PREFIX_SAMPLERS = ("random", "sobol")
# A reference renders with independent samples and another seed than the ladders, so its
# noise is independent of theirs and its per-pixel variance estimate is unbiased.
REFERENCE_SAMPLER = "random"
REFERENCE_SEED_OFFSET = 1_000_003


def sample_ladder(max_samples: int) -> list[int]:
    """1, 2, 4, ... up to max_samples (included even when not a power of two)."""
    if max_samples < 1:
        raise ValueError(f"max_samples must be at least 1, got {max_samples}")
    rungs, k = [], 1
    while k < max_samples:
        rungs.append(k)
        k *= 2
    return rungs + [max_samples]


def every_sample(settings, **changes):
    """`settings` with `changes` and every sample taken (adaptive sampling and a time
    limit off)."""
    return replace(settings, adaptive_sampling=False, time_limit=0.0, **changes)

@dataclass
class Rung:
    samples: int
    seconds: float        # render seconds to reach this image (cumulative when progressive)
    image: np.ndarray     # (h, w, 3) mean radiance


def _check_complete(film: Film, samples: int) -> None:
    short = int((film.count < samples).sum())
    if short:
        raise RuntimeError(f"{short} pixels got fewer than {samples} samples (adaptive "
                           f"sampling or a time limit stopped the render early)")


def _render_range(scene, settings, ctx, start, end, on_paths):
    done = [0]

    def progress(film, stats, fraction):
        if on_paths is not None:
            on_paths(stats.paths - done[0])
        done[0] = stats.paths

    t0 = time.perf_counter()
    film, _ = render(scene, settings, sample_start=start, sample_end=end, context=ctx,
                     progress=progress)
    return film, time.perf_counter() - t0


def ladder(scene, settings, rungs, on_paths=None, setup=None):
    """Yield a Rung per sample count in `rungs` (increasing) for `settings` (sampler,
    integrator, seed as given). on_paths(n) is called as paths finish (progress bars);
    setup, a dict, receives `setup_seconds`."""
    rungs = sorted(set(int(r) for r in rungs))
    if settings.sampler in PREFIX_SAMPLERS:
        yield from _progressive(scene, every_sample(settings, samples=rungs[-1]), rungs,
                                on_paths, setup)
        return
    setup_seconds = 0.0
    for k in rungs:
        s = every_sample(settings, samples=k)
        t0 = time.perf_counter()
        ctx = RenderContext(scene, s)
        setup_seconds += time.perf_counter() - t0
        try:
            film, seconds = _render_range(scene, s, ctx, 0, k, on_paths)
        finally:
            ctx.close()
        _check_complete(film, k)
        if setup is not None:
            setup["setup_seconds"] = setup_seconds
        yield Rung(k, seconds, film.mean())


def _progressive(scene, settings, rungs, on_paths, setup):
    t0 = time.perf_counter()
    ctx = RenderContext(scene, settings)
    if setup is not None:
        setup["setup_seconds"] = time.perf_counter() - t0
    try:
        total = Film(scene.width, scene.height)
        seconds, start = 0.0, 0
        for k in rungs:
            film, dt = _render_range(scene, settings, ctx, start, k, on_paths)
            total.merge(film)
            seconds += dt
            start = k
            _check_complete(total, k)
            yield Rung(k, seconds, total.mean())
    finally:
        ctx.close()


def warm_up(scene, settings) -> None:
    """One sample of every pixel, discarded: compiles (or loads from Numba's cache) the
    kernels these settings use, so that no rung's seconds include that."""
    s = every_sample(settings, samples=1)
    ctx = RenderContext(scene, s)
    try:
        render(scene, s, context=ctx)
    finally:
        ctx.close()


@dataclass
class Reference:
    image: np.ndarray               # (h, w, 3)
    variance_of_mean: np.ndarray    # (h, w, 3): the reference's own noise, per pixel
    samples: int
    seconds: float


def reference(scene, settings, samples: int, on_paths=None) -> Reference:
    """A long render with independent samples and a seed of its own."""
    s = every_sample(settings, samples=samples, sampler=REFERENCE_SAMPLER,
                     seed=settings.seed + REFERENCE_SEED_OFFSET)
    ctx = RenderContext(scene, s)
    try:
        film, seconds = _render_range(scene, s, ctx, 0, samples, on_paths)
    finally:
        ctx.close()
    _check_complete(film, samples)
    return Reference(film.mean(), film.variance_of_mean(), samples, seconds)
