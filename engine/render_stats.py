"""What a render reports: samples and paths done, seconds (the kernels' one-time compile
apart), cancels, time limits, adaptive sampling's converged share, and the stats line
Blender shows (engine.render fills it in)."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass
class RenderStats:
    samples_done: int = 0
    paths: int = 0
    nonfinite_samples: int = 0
    seconds: float = 0.0
    cancelled: bool = False
    units_done: int = 0
    units_running_at_cancel: int = 0   # finished after the cancel (at most the thread count)
    time_limited: bool = False         # stopped by settings.time_limit
    active_pixels: int = -1            # pixels still sampled after the last pass (adaptive)
    pixel_samples: int = 0             # samples taken over all pixels
    compile_seconds: float = 0.0       # spent compiling kernels (a first render only)
    kernels_compiled: int = 0          # kernels compiled, of kernels_reachable
    kernels_reachable: int = 0

    def sampling_seconds(self) -> float:
        """Seconds spent rendering, the kernels' one-time compile left out."""
        return max(self.seconds - self.compile_seconds, 0.0)

    def paths_per_second(self) -> float:
        seconds = self.sampling_seconds()
        return self.paths / seconds if seconds > 0 else 0.0

    def status(self, samples: int, n_pixels: int) -> str:
        """The stats line: samples, adaptive sampling's share of converged pixels, the
        time limit."""
        text = f"Sample {self.samples_done}/{samples}"
        if self.active_pixels >= 0:
            text += f" | {100.0 * (1 - self.active_pixels / max(n_pixels, 1)):.0f}% converged"
        if self.time_limited:
            text += " | time limit reached"
        return text
