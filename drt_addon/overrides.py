"""Command-line overrides of a scene's render settings, applied in memory (the .blend on
disk is never written): the batch renderer applies them after opening the file, and so
does every Dask worker, so a frame rendered anywhere uses the same settings.

Each setting goes to DRT's own property (`scene.drt`) and, for `--engine CYCLES`, to
Cycles' (`scene.cycles`). Adaptive sampling and the time limit are set only where the
running DRT or Blender has the property; where it has not, the override is reported as
not applied rather than silently dropped.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass


@dataclass(frozen=True)
class Overrides:
    engine: str = "DRT"
    samples: int | None = None
    seed: int | None = None
    percentage: int | None = None
    noise_threshold: float | None = None
    min_samples: int | None = None
    time_limit: float | None = None

    @classmethod
    def from_args(cls, args) -> "Overrides":
        return cls(**{k: getattr(args, k, None) for k in asdict(cls())
                      if getattr(args, k, None) is not None})

    def problems(self) -> list[str]:
        """What is out of range, as messages for `drt: error:`."""
        out = []
        if self.samples is not None and not 1 <= self.samples <= 1 << 24:
            out.append("--samples must be between 1 and 16777216")
        if self.seed is not None and self.seed < 0:
            out.append("--seed must be >= 0")
        if self.percentage is not None and not 1 <= self.percentage <= 10000:
            out.append("--percentage must be in 1..10000")
        if self.noise_threshold is not None and not self.noise_threshold > 0:
            out.append("--noise-threshold must be > 0")
        if self.min_samples is not None and self.min_samples < 0:
            out.append("--min-samples must be >= 0")
        if self.time_limit is not None and not self.time_limit >= 0:
            out.append("--time-limit must be >= 0 seconds (0: no limit)")
        return out


# override field -> (property name on scene.drt / scene.cycles)
_SAMPLING = {"samples": "samples", "seed": "seed", "min_samples": "adaptive_min_samples",
             "time_limit": "time_limit"}
# the file's Cycles settings that both engines render with: set there whatever the engine
_FILES_OWN = {"seed"}


def _targets(scene, engine: str, field: str = "") -> list:
    """The property groups to set, the chosen engine's last (DRT's always: a Cycles
    reference render with the same --samples keeps the DRT settings in step)."""
    if field in _FILES_OWN:
        return [getattr(scene, "cycles", None)]
    owners = [getattr(scene, "drt", None)]
    if engine == "CYCLES":
        owners.append(getattr(scene, "cycles", None))
    return owners


def _set(owner, name, value) -> bool:
    if not hasattr(owner, name):
        return False
    setattr(owner, name, value)
    return True


def apply_overrides(scene, overrides: Overrides) -> list[str]:
    """Set the overrides on `scene` (a bpy Scene, or anything shaped like one). Returns
    messages for the overrides the running engine has no setting for."""
    scene.render.engine = overrides.engine
    if overrides.percentage is not None:
        scene.render.resolution_percentage = overrides.percentage
    owners = _targets(scene, overrides.engine)
    missing = []
    for field, prop in _SAMPLING.items():
        value = getattr(overrides, field)
        if value is None:
            continue
        applied = [owner is not None and _set(owner, prop, value)
                   for owner in _targets(scene, overrides.engine, field)]
        if not applied[-1]:
            missing.append(f"--{field.replace('_', '-')} not applied: this {overrides.engine}"
                           f" has no {prop} setting")
    if overrides.noise_threshold is not None:
        applied = [owner is not None
                   and _set(owner, "adaptive_threshold", overrides.noise_threshold)
                   and _set(owner, "use_adaptive_sampling", True) for owner in owners]
        if not applied[-1]:
            missing.append(f"--noise-threshold not applied: this {overrides.engine} has no "
                           "adaptive sampling setting")
    return missing
