"""A convergence study of one open .blend: a reference (a long DRT or Cycles render,
cached), then one curve per DRT sampler x integrator (and Cycles' when asked), each a
sample ladder measured against the reference (engine/image_error.py) with its fitted
log-log slopes. The result is a plain dict, written as convergence.json.

Slopes are fitted to the errors less the floor the reference's own noise adds to every
measurement (engine.image_error.noise_floor), over the rungs whose error is more than
twice that floor; FLIP is fitted as measured. A curve whose image converges to
something else than the reference (the distribution integrator leaves out diffuse
interreflection; Cycles against a DRT reference) flattens at that bias: its slope then
says so. Each curve records the 1-minute load average (the larger of before and after
it): on shared cores its seconds are pessimistic.
"""
from __future__ import annotations

import os
from dataclasses import asdict, replace
from importlib import import_module

import numpy as np

from .convergence_cache import ConvergeCache, file_identity
from .engine_link import engine

convergence = import_module(engine.__name__ + ".convergence")
image_error = import_module(engine.__name__ + ".image_error")


class Study:
    """Everything one study needs: the open scene (bpy), its DRT description and
    settings, where to cache, and a progress callback on_paths(n)."""

    def __init__(self, bpy, blend_path, description, settings, cache: ConvergeCache,
                 on_paths=None):
        self.bpy, self.description, self.settings = bpy, description, settings
        self.scene = bpy.context.scene
        self.cache, self.on_paths = cache, on_paths
        self._warm = {}
        self.identity = {**file_identity(blend_path),
                         "resolution": [description.width, description.height],
                         "frame": self.scene.frame_current,
                         "blender": bpy.app.version_string}

    # --- the reference ------------------------------------------------------------------

    def reference(self, engine_name: str, samples: int, unclamped: bool = False):
        """(convergence.Reference, cache key, was cached); `unclamped`: DRT's reference
        with Clamp Direct and Indirect off, to measure clamps' bias against."""
        settings = replace(self.settings, clamp_direct=0.0, clamp_indirect=0.0) \
            if unclamped else self.settings
        key = self.cache.key(kind="reference", engine=engine_name, samples=samples,
                             settings=asdict(settings) if engine_name == "drt" else None,
                             **self.identity)
        hit = self.cache.load_arrays(key)
        if hit is not None:
            m = hit["meta"]
            return (convergence.Reference(hit["image"], hit["variance_of_mean"],
                                          m["samples"], m["seconds"]), key, True)
        if engine_name == "drt":
            why = self._warm_up("drt", settings)
            if why is not None:
                raise ValueError(why)
            ref = convergence.reference(self.description, settings, samples,
                                        on_paths=self.on_paths)
        else:
            from .cycles_ladder import cycles_reference
            self._warm_up("cycles")
            ref = cycles_reference(self.bpy, self.scene, samples, on_paths=self.on_paths)
        self.cache.save_arrays(key, {"samples": ref.samples, "seconds": ref.seconds},
                               image=ref.image.astype(np.float32),
                               variance_of_mean=ref.variance_of_mean.astype(np.float32))
        return ref, key, False

    # --- curves -------------------------------------------------------------------------

    def drt_curve(self, sampler, integrator, rungs, ref, ref_key, floor, clamp=None):
        """One DRT ladder; `clamp` (direct, indirect) replaces the file's clamps."""
        changes = {} if clamp is None else dict(clamp_direct=clamp[0], clamp_indirect=clamp[1])
        settings = convergence.every_sample(self.settings, sampler=sampler,
                                            integrator=integrator, **changes)
        label = f"DRT {integrator} {sampler}" + \
            ("" if clamp is None else f" clamp {clamp[0]:g}:{clamp[1]:g}")
        key = self.cache.key(kind="curve", engine="drt", rungs=list(rungs),
                             settings=asdict(settings), reference=ref_key, **self.identity)
        cached = self.cache.load_json(key)
        if cached is not None:
            self._skip(ladder_paths(rungs, sampler))
            return {**cached, "cached": True}
        why = self._warm_up("drt", settings)
        if why is not None:              # e.g. volumes and the distribution integrator
            self._skip(ladder_paths(rungs, sampler))
            return {"label": label, "skipped": why}
        setup = {}
        rung_iter = convergence.ladder(self.description, settings, rungs,
                                       on_paths=self.on_paths, setup=setup)
        load = os.getloadavg()[0]
        curve = measure_curve(rung_iter, ref, floor)
        load = max(load, os.getloadavg()[0])      # the 1-minute load, before and after
        curve = {"label": label, "load_average": load, "engine": "DRT", "sampler": sampler,
                 "integrator": integrator, "seed": settings.seed,
                 "clamp": [settings.clamp_direct, settings.clamp_indirect],
                 "progressive": sampler in convergence.PREFIX_SAMPLERS,
                 "setup_seconds": setup.get("setup_seconds"), **curve}
        self.cache.save_json(key, curve)
        return {**curve, "cached": False}

    def cycles_curve(self, rungs, ref, ref_key, floor):
        from .cycles_ladder import cycles_ladder
        key = self.cache.key(kind="curve", engine="cycles", rungs=list(rungs),
                             seed=self.scene.cycles.seed, reference=ref_key, **self.identity)
        cached = self.cache.load_json(key)
        if cached is not None:
            self._skip(sum(rungs))
            return {**cached, "cached": True}
        self._warm_up("cycles")
        load = os.getloadavg()[0]
        curve = measure_curve(cycles_ladder(self.bpy, self.scene, rungs, self.on_paths),
                              ref, floor)
        load = max(load, os.getloadavg()[0])
        curve = {"label": f"Cycles ({self.scene.cycles.sampling_pattern.lower()})",
                 "load_average": load, "engine": "Cycles",
                 "sampler": self.scene.cycles.sampling_pattern.lower(),
                 "integrator": "path", "seed": self.scene.cycles.seed,
                 "progressive": False, "setup_seconds": None, **curve}
        self.cache.save_json(key, curve)
        return {**curve, "cached": False}

    def _warm_up(self, engine_name, settings=None):
        """Once per engine and integrator, before anything is timed: a 1-sample render
        (kernel compilation, Cycles' kernel loading). Returns why DRT cannot render the
        scene with these settings (the engine's ValueError), or None."""
        key = (engine_name, getattr(settings, "integrator", None))
        if key not in self._warm:
            self._warm[key] = None
            if engine_name == "drt":
                try:
                    convergence.warm_up(self.description, settings)
                except ValueError as e:
                    self._warm[key] = str(e)
            else:
                from .cycles_ladder import render_cycles
                render_cycles(self.bpy, self.scene, 1, self.scene.cycles.seed)
        return self._warm[key]

    def _skip(self, samples_per_pixel):
        """A cached curve still moves the progress bar by the work it stands for."""
        if self.on_paths is not None:
            self.on_paths(samples_per_pixel * self.description.width * self.description.height)


def measure_curve(rungs, ref, floor) -> dict:
    """Metrics of each rung against the reference, and the fitted slopes."""
    out = {"samples": [], "seconds": []}
    for name in image_error.METRICS:
        out[name] = []
    for rung in rungs:
        err = image_error.measure(rung.image, ref.image)
        out["samples"].append(rung.samples)
        out["seconds"].append(rung.seconds)
        for name in image_error.METRICS:
            out[name].append(getattr(err, name))
    out["slopes"] = {axis: {name: image_error.metric_slope(name, out[axis], out[name], floor)
                            for name in image_error.METRICS}
                     for axis in ("samples", "seconds")}
    return out


def ladder_paths(rungs, sampler) -> int:
    """Samples per pixel a DRT ladder renders (progress-bar total)."""
    return max(rungs) if sampler in convergence.PREFIX_SAMPLERS else sum(rungs)
