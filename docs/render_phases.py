"""Time and memory per phase of DRT's render call, for docs/big_scene_benchmarks.py.

`PhaseRecorder.install()` wraps the functions the render call goes through (the export,
each step of `engine.render.RenderContext`, the render's thread pool) so that each one,
when it returns, closes a phase: wall time since the last mark, the process's resident
memory then (/proc/self/statm) and its peak so far (/proc/self/status's VmHWM). It also sums
the time Numba spends loading compiled kernels from its on-disk cache (the first call of
each kernel in a fresh process), per phase. Nothing of the tracer is changed: the
wrappers call the originals.
"""
from __future__ import annotations

import os
import resource
import time

_PAGE = os.sysconf("SC_PAGE_SIZE")


def rss_mb() -> float:
    """The process's resident memory now."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * _PAGE / 2**20


def peak_mb() -> float:
    """The process's peak resident memory so far: /proc/self/status's VmHWM, the high-water
    mark of this program's own memory. (getrusage's maxrss is not: Linux copies it from
    the parent at fork and keeps it through exec, so a child of a big process reads its
    parent's size; the benchmark's renders are such children.)"""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def array_mb(*objects, seen=None) -> float:
    """NumPy array bytes held by these objects' attributes (and in tuples, lists and dicts
    among them, one level down), each array counted once (and not at all when its id is
    in `seen`, the arrays counted before)."""
    import numpy as np
    seen = set() if seen is None else seen
    total = 0

    def add(a):
        nonlocal total
        if isinstance(a, np.ndarray):
            base = a if a.base is None else a.base
            if id(base) not in seen and isinstance(base, np.ndarray):
                seen.add(id(base))
                total += base.nbytes
        elif isinstance(a, (tuple, list)):
            for x in a:
                if isinstance(x, np.ndarray):
                    add(x)
        elif isinstance(a, dict):
            for x in a.values():
                if isinstance(x, np.ndarray):
                    add(x)

    for obj in objects:
        for value in (vars(obj).values() if hasattr(obj, "__dict__") else [obj]):
            add(value)
    return total / 2**20


class PhaseRecorder:
    def __init__(self):
        self.marks = []      # (phase, end time, rss MB, peak MB, kernel load s, MB, n)
        self.kernel_seconds = 0.0
        self.kernel_mb = 0.0        # resident memory added while loading kernels
        self.kernels_loaded = 0
        self.loads = []             # (kernel, seconds, resident MB added) per cache load
        self.held = {}              # phase: MB of arrays its result holds (new ones)
        self._seen = set()

    def mark(self, phase: str) -> None:
        self.marks.append((phase, time.perf_counter(), rss_mb(), peak_mb(),
                           self.kernel_seconds, self.kernel_mb, self.kernels_loaded))

    def _wrap(self, module, name: str, phase: str, held=None, before=None):
        """module.name, closing `phase` when it returns (and `before` when it is called);
        held(result): the objects whose arrays the phase keeps."""
        original = getattr(module, name)

        def wrapper(*args, **kwargs):
            if before is not None:
                self.mark(before)
            result = original(*args, **kwargs)
            self.mark(phase)
            if held is not None and phase not in self.held:
                self.held[phase] = array_mb(*held(result), seen=self._seen)
            return result
        setattr(module, name, wrapper)

    def _time_cache_loads(self):
        from numba.core import caching

        from engine.kernels.kernel_cache import EngineFunctionCache
        for cls in (caching.Cache, EngineFunctionCache):   # Numba's, and the engine's
            self._time_loads_of(cls)

    def _time_loads_of(self, cls):
        original = cls.__dict__["load_overload"]
        recorder = self

        def load_overload(cache, sig, target_context):
            t0, rss0 = time.perf_counter(), rss_mb()
            try:
                result = original(cache, sig, target_context)
            finally:
                seconds, added = time.perf_counter() - t0, rss_mb() - rss0
                recorder.kernel_seconds += seconds
                recorder.kernel_mb += added
                recorder.loads.append((cache._name.split(" ")[1], seconds, added))
            recorder.kernels_loaded += result is not None
            return result
        cls.load_overload = load_overload

    def install(self):
        """Wrap the render call's steps (after `drt_addon.register()`, at the start of
        the render call)."""
        from importlib import import_module

        # the tracer loads with the first DRT render of a process (not at registration):
        # imported here, it is the render call's first phase
        from drt_addon import export, render_engine
        from drt_addon.engine_link import engine
        render = import_module(engine.__name__ + ".render")
        accel = import_module(engine.__name__ + ".accel")
        embree_scene = import_module(engine.__name__ + ".embree.scene")
        self._time_cache_loads()
        self.mark("import DRT's tracer (engine, Numba, Embree) and its export")
        keeps = (lambda result: [result])
        self._wrap(export, "export_scene", "export (depsgraph to scene description)",
                   held=lambda scene: scene.meshes)
        # Accelerator: its own arrays, then the float32 vertex buffer Embree shares
        # (engine.embree.scene.padded_float32), then Embree's hierarchy (rtcCommitScene)
        self._wrap(embree_scene, "padded_float32", "Embree: float32 vertex buffer (shared)",
                   before="accelerator arrays (engine/accel.py)")
        self._wrap(accel, "_embree_scene", "Embree: hierarchy (BVH) build")
        self._wrap(render, "Accelerator", "accelerator finished", held=keeps)
        self._wrap(render, "SurfaceBuilder", "surface arrays (engine/surface.py)", held=keeps)
        self._wrap(render, "MaterialTable", "material table")
        self._wrap(render, "_scene_radius", "scene bounds")
        self._wrap(render, "LightSet", "lights (with emissive triangles)")
        self._wrap(render, "make_integrator", "path tracer set-up (its tables)", held=keeps)
        self._wrap(render, "pack_camera", "camera kernel set-up")
        self._wrap(render, "ThreadPoolExecutor", "thread pool start")
        self._wrap(render_engine, "set_pass_pixels", "first sample (and its film to Blender)")

    def phases(self, start: float, start_rss: float) -> list:
        """[(phase, seconds, rss MB after, rss MB added, peak MB after, kernel-load s,
        kernel-load MB, kernels loaded, array MB kept)]: a phase ends at its first mark
        (later calls, e.g. the final film write, are dropped)."""
        rows, seen = [], set()
        t_prev, rss_prev, k_prev, kmb_prev, n_prev = start, start_rss, 0.0, 0.0, 0
        for phase, t, rss, peak, k, kmb, n in self.marks:
            if phase in seen:
                continue
            seen.add(phase)
            rows.append((phase, t - t_prev, rss, rss - rss_prev, peak, k - k_prev,
                         kmb - kmb_prev, n - n_prev, self.held.get(phase)))
            t_prev, rss_prev, k_prev, kmb_prev, n_prev = t, rss, k, kmb, n
        return rows
