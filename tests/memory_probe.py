"""Peak memory of engine renders, traced with tracemalloc (NumPy's arrays included), for
tests/test_memory.py and the memory figures of docs/robustness_hostile.md.

A render holds its film (engine.film.Film: 96 bytes per pixel), the list of pixels
still sampled (8 per pixel) and one work unit per thread: at most `chunk_paths` paths,
about 530 bytes each (measured: 3.6 MB at 2048 paths, 11.2 MB at 16384, one thread). The
bounds allow 1 KB per path and 2 MB of constants."""
from __future__ import annotations

import tracemalloc

from engine import RenderSettings, render
from engine_scenes import cornell_box

PER_PIXEL = 96 + 8
PER_PATH = 1024
CONSTANTS = 2e6


def traced_peak(scene, settings, cancelled=None):
    """(peak traced bytes, RenderStats) of rendering `scene`; the kernels are loaded by a
    tiny render first, so that their loading is not counted."""
    render(cornell_box(8, 8), RenderSettings(samples=1, threads=1))
    tracemalloc.start()
    try:
        _, stats = render(scene, settings, cancelled=cancelled)
        return tracemalloc.get_traced_memory()[1], stats
    finally:
        tracemalloc.stop()


def bound(width, height, chunk_paths) -> float:
    return PER_PIXEL * width * height + PER_PATH * chunk_paths + CONSTANTS


def cancel_after(units: int):
    """A `cancelled` callback that says yes from poll units + 1 on (Esc after `units`)."""
    polls = []

    def cancelled():
        polls.append(1)
        return len(polls) > units
    return cancelled


# (label, width, height, samples, chunk_paths, work units before the cancel or None)
CASES = [("a large frame, a small chunk", 512, 512, 1, 2048, None),
         ("1e6 samples at 1920 x 1080, cancelled", 1920, 1080, 1_000_000, 1 << 15, 2)]


def measure(width, height, samples, chunk, units):
    settings = RenderSettings(samples=samples, chunk_paths=chunk, threads=1)
    return traced_peak(cornell_box(width, height), settings,
                       cancelled=cancel_after(units) if units is not None else None)


def memory_table() -> str:
    """The CASES measured, as a Markdown table."""
    rows = ["| Render | Pixels x samples | Peak traced memory | Film | Bound |",
            "|---|---|---|---|---|"]
    for label, w, h, samples, chunk, units in CASES:
        peak, stats = measure(w, h, samples, chunk, units)
        rows.append(f"| {label} (chunk {chunk} paths, {stats.paths} paths traced) | "
                    f"{w * h * samples:.3g} | {peak / 1e6:.1f} MB | "
                    f"{96 * w * h / 1e6:.1f} MB | {bound(w, h, chunk) / 1e6:.1f} MB |")
    return "\n".join(rows) + "\n"
