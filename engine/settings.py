"""Render settings, with Cycles' defaults where Cycles has the same setting."""
from __future__ import annotations

from dataclasses import dataclass

SAMPLERS = ("jittered", "sobol", "random")
INTEGRATORS = ("path", "distribution", "whitted")


@dataclass
class RenderSettings:
    samples: int = 64
    seed: int = 0
    sampler: str = "jittered"
    integrator: str = "path"
    # Light paths (Cycles' defaults)
    max_bounces: int = 12
    diffuse_bounces: int = 4
    glossy_bounces: int = 4
    transmission_bounces: int = 12
    transparent_bounces: int = 8
    volume_bounces: int = 0           # scatterings in volumes a path goes on after
    clamp_direct: float = 0.0         # 0 = off, as in Cycles
    clamp_indirect: float = 10.0
    # Cycles' Filter Glossy (`blur_glossy`, 0 = off) and caustics switches
    # (engine.kernels.prepare_closures)
    filter_glossy: float = 1.0
    caustics_reflective: bool = True
    caustics_refractive: bool = True
    # Cycles' Sampling > Lights > Light Tree: pick the light to sample for each shading
    # point by its importance there (engine/kernels/lights/tree.py), else as Cycles does
    # without the tree (engine.light_distribution)
    light_tree: bool = True
    # Film
    filter_type: str = "BLACKMAN_HARRIS"
    filter_width: float = 1.5
    # Cycles' Film > Exposure (`cycles.film_exposure`): every radiance sample is
    # multiplied by it as it enters the film, so the Combined image and the noise
    # estimate scale by it and the first-hit passes (depth, normal, albedo) do not, as
    # Cycles applies it to its light passes only. Clamps act before it, as in Cycles.
    film_exposure: float = 1.0
    # Adaptive sampling (engine.adaptive_sampling), as Cycles': pixels stop once their
    # error estimate is under the threshold (0 = Cycles' automatic max(0.001, 1/samples));
    # min samples 0 = Cycles' automatic ceil(16 / threshold^0.3), at least 4.
    adaptive_sampling: bool = False
    adaptive_threshold: float = 0.01
    adaptive_min_samples: int = 0
    # Seconds of tracing after which the render stops (0 = no limit), as Cycles' Time
    # Limit: export and the acceleration structure do not count.
    time_limit: float = 0.0
    # Cycles' light passes (Diffuse, Glossy, Transmission and Volume Direct / Indirect,
    # the Color passes, Emission, Environment): the path tracer splits its light
    # (engine.light_passes). Light groups are asked for by Scene.light_groups.
    light_passes: bool = False
    # Execution: paths per work unit bounds memory (about 1 KB of state per path).
    chunk_paths: int = 1 << 15
    threads: int = 0                   # 0 = all cores

    def validate(self) -> "RenderSettings":
        problems = []
        if not isinstance(self.samples, int) or self.samples < 1 or self.samples > 1 << 24:
            problems.append(f"samples must be an integer in 1..16777216, got {self.samples!r}")
        if self.sampler not in SAMPLERS:
            problems.append(f"sampler must be one of {SAMPLERS}, got {self.sampler!r}")
        if self.integrator not in INTEGRATORS:
            problems.append(f"integrator must be one of {INTEGRATORS}, got {self.integrator!r}")
        for name in ("max_bounces", "diffuse_bounces", "glossy_bounces",
                     "transmission_bounces", "transparent_bounces", "volume_bounces"):
            v = getattr(self, name)
            if not isinstance(v, int) or v < 0 or v > 1024:
                problems.append(f"{name} must be an integer in 0..1024, got {v!r}")
        for name in ("clamp_direct", "clamp_indirect"):
            v = getattr(self, name)
            if not (v >= 0) or v == float("inf"):
                problems.append(f"{name} must be a finite number >= 0 (0 = off), got {v!r}")
        if not (0.0 <= self.filter_glossy < float("inf")):
            problems.append(f"filter_glossy must be a finite number >= 0 (0 = off), got "
                            f"{self.filter_glossy!r}")
        if not (0.0 <= self.film_exposure < float("inf")):
            problems.append(f"film_exposure must be a finite number >= 0, got "
                            f"{self.film_exposure!r}")
        if not (0 < self.filter_width <= 100):
            problems.append(f"filter_width must be in (0, 100] pixels, got {self.filter_width!r}")
        if not (0.0 <= self.adaptive_threshold <= 1.0):
            problems.append(f"adaptive_threshold must be in [0, 1] (0 = automatic), got "
                            f"{self.adaptive_threshold!r}")
        if not isinstance(self.adaptive_min_samples, int) or not \
                0 <= self.adaptive_min_samples <= 1 << 24:
            problems.append(f"adaptive_min_samples must be an integer in 0..16777216 "
                            f"(0 = automatic), got {self.adaptive_min_samples!r}")
        if not (0.0 <= self.time_limit < float("inf")):
            problems.append(f"time_limit must be a finite number of seconds >= 0 (0 = off), "
                            f"got {self.time_limit!r}")
        if self.chunk_paths < 256:
            problems.append("chunk_paths must be at least 256")
        if problems:
            raise ValueError("; ".join(problems))
        return self
