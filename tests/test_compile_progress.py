"""A first render compiles kernels: it says so ("compiling kernels, one time: N of M"),
leaves the compile out of its sample rate, and a cancel during the compile returns at
once (engine.kernels.compile_watch, engine.render). The compile is provoked by a kernel
made fresh in the test, with no on-disk cache."""
from __future__ import annotations

import importlib
import threading

import numpy as np
from numba.core import event

from engine.kernels import jit
from engine.kernels.compile_watch import CompileWatch, reachable
from engine.kernels.path_vertex import shade
from engine.settings import RenderSettings
from engine_scenes import cornell_box

render_module = importlib.import_module("engine.render")     # the module, not the function


def fresh_kernel():
    """A kernel Numba must compile (cache off) that takes a while to compile."""
    def body(x):
        acc = 0.0
        for i in range(x.shape[0]):
            acc += np.sin(x[i]) * np.cos(x[i] * 2.0) + np.exp(-x[i] * x[i]) + \
                np.log1p(abs(x[i])) + np.tanh(x[i]) + np.arctan2(x[i], 1.0 + acc)
        return acc
    return jit.kernel(body, cache=False)


def test_reachable_follows_callees_and_only_them():
    found = {f.__module__ + "." + f.__qualname__ for f in reachable([shade])}
    assert "engine.kernels.path_vertex.shade" in found
    assert "engine.kernels.bsdf.principled.setup" in found        # via a module attribute
    assert "engine.kernels.lights.light_set.sample" in found
    assert not any(name.startswith("engine.kernels.whitted_vertex") for name in found)
    # rays cast inside the kernel: the subsurface walk's
    assert "engine.embree.rays.intersect1" in found
    assert "engine.kernels.subsurface.walk" in found
    assert 50 < len(found) < 700


def test_watch_counts_what_compiles():
    k = fresh_kernel()
    with CompileWatch({k.py_func}) as watch:
        assert k(np.linspace(0, 1, 5)) != 0.0
    assert watch.done == {k.py_func} and watch.total == 1
    assert watch.seconds > 0 and not watch.compiling
    k(np.linspace(0, 1, 5))                          # no longer watched, compiled already


class _Compiling:
    """Makes a scene's render call a fresh kernel before its first radiance."""

    def __init__(self, ctx):
        self.kernel = fresh_kernel()
        self.finished = threading.Event()
        integrator = ctx.integrator
        original = integrator.radiance
        kernel, finished = self.kernel, self.finished

        def radiance(*args, **kwargs):
            kernel(np.ones(3))
            finished.set()
            return original(*args, **kwargs)
        integrator.radiance = radiance
        entries = ctx.entry_kernels
        ctx.entry_kernels = lambda: entries() + [kernel]


def test_render_reports_compiling_and_times_samples_without_it(monkeypatch):
    monkeypatch.setattr(render_module, "POLL", 0.002)
    scene = cornell_box(8, 8)
    settings = RenderSettings(samples=2, threads=1)
    ctx = render_module.RenderContext(scene, settings)
    _Compiling(ctx)
    said = []
    film, stats = render_module.render(scene, settings, context=ctx,
                                       compiling=lambda done, total: said.append((done, total)))
    ctx.close()
    assert said, "no compile progress while a kernel compiled"
    assert all(total == stats.kernels_reachable and 0 <= done < total for done, total in said)
    assert stats.kernels_compiled >= 1 and stats.kernels_reachable > 50
    assert 0 < stats.compile_seconds < stats.seconds
    assert stats.sampling_seconds() == stats.seconds - stats.compile_seconds
    assert stats.samples_done == 2 and film.count.sum() == 2 * 64


def test_cancel_during_a_compile_returns_without_waiting_for_it(monkeypatch):
    monkeypatch.setattr(render_module, "POLL", 0.002)
    scene = cornell_box(8, 8)
    settings = RenderSettings(samples=4, threads=1)
    ctx = render_module.RenderContext(scene, settings)
    probe = _Compiling(ctx)
    started = threading.Event()

    class Started(event.Listener):                   # Esc once the compile has begun
        def on_start(self, ev):
            if ev.data["dispatcher"].py_func is probe.kernel.py_func:
                started.set()

        def on_end(self, ev):
            pass
    listener = Started()
    event.register("numba:compile", listener)
    try:
        film, stats = render_module.render(scene, settings, context=ctx,
                                           cancelled=started.is_set)
    finally:
        event.unregister("numba:compile", listener)
    returned_before_compile_ended = not probe.finished.is_set()
    assert stats.cancelled and stats.samples_done == 0
    assert returned_before_compile_ended
    probe.finished.wait(120)                         # the compile ends in the background
    assert probe.finished.is_set()
    assert film.count.sum() == 0                     # and adds nothing to the film
    ctx.close()


def test_shade_is_compiled_without_what_the_scene_lacks():
    """Principle 3 for the compiler: a scene without node programs, volumes, subsurface
    scattering and emitters whose emission varies over them gets a `shade` whose last
    five arguments are None, so Numba compiles none of that code (nor the interpreter,
    the media's tracking and scattering, the random walk and the emitters' evaluation at
    light samples, which only it calls); a scene with a world volume gets the volume
    table in its place, one with a subsurface material the scene for the walk's rays."""
    from dataclasses import replace

    from numba.core import types

    from engine.scene import Volume
    settings = RenderSettings(samples=1, threads=1)
    plain = cornell_box(8, 8)
    ctx = render_module.RenderContext(plain, settings)
    render_module.render(plain, settings, context=ctx)
    assert ctx.integrator.features == (None, None, None, None, None)
    ctx.close()
    foggy = cornell_box(8, 8)
    foggy.world = replace(foggy.world, volume=Volume(scattering=(0.1, 0.1, 0.1)))
    ctx = render_module.RenderContext(foggy, settings)
    render_module.render(foggy, settings, context=ctx)
    programs, volumes, het, sss, shaded = ctx.integrator.features
    assert programs is None and het is None and sss is None and shaded is None
    assert volumes is ctx.integrator.vol
    ctx.close()
    waxy = cornell_box(8, 8)
    waxy.materials[0] = replace(waxy.materials[0], subsurface_weight=1.0)
    ctx = render_module.RenderContext(waxy, settings)
    assert ctx.integrator.features[:3] == (None, None, None)
    assert ctx.integrator.features[3] is not None and ctx.integrator.features[4] is None
    ctx.close()
    last5 = [tuple(type(t) for t in sig[-5:]) for sig in shade.signatures]
    assert (types.NoneType,) * 5 in last5
    assert any(t[0] is types.NoneType and t[1] is not types.NoneType for t in last5)


def test_the_batch_renderers_bar_says_compiling_then_counts_samples(capsys):
    """python -m drt_addon render's frame bar during a first render: 'compiling kernels,
    one time: N of M' instead of a sample rate, then samples timed from there; with
    --no-progress nothing is drawn and nothing fails."""
    from drt_addon.batch_report import Progress
    quiet = Progress(1, enabled=False)
    quiet.start_frame("frame 1", 4)
    quiet.compiling(3, 10)
    quiet.samples_done(1, 4)
    quiet.close()
    shown = Progress(1, enabled=True)
    shown.start_frame("frame 1", 4)
    shown.compiling(3, 10)
    assert shown.samples.desc == "frame 1: compiling kernels, one time: 3 of 10"
    shown.samples_done(1, 4)
    assert shown.samples.desc == "frame 1" and shown.samples.n == 1
    assert shown.samples.initial == 1            # the compile's time is not in the rate
    shown.samples_done(3, 4)
    assert shown.samples.n == 3
    shown.close()
    assert "compiling kernels, one time: 3 of 10" in capsys.readouterr().err
