"""Kernels compiled without reference counting (`@kernel(allocates=False)`, see
engine/kernels/jit.py) borrow their arrays from the caller. That is safe only if such a
kernel returns no array (its caller would release a reference it never got) and keeps no
array it did not get as an argument (a fresh array there is never freed). Numba refuses
allocations and views in such a kernel; `BorrowingCheck` refuses an argument returned.
These tests check the guards, with controls that show each can fail, and that renders of
sample scenes reaching the borrowing kernels (a Cornell box; node programs, textures,
volumes, an HDRI world, motion blur, glass from .blend files) leak no allocation."""
import dataclasses
import gc
import os

import numpy as np
import pytest
from numba import njit, types
from numba.core.runtime import _nrt_python, rtsys

from conftest import SAMPLES_DIR
from engine import RenderSettings, render
from engine.kernels.bsdf import principled
from engine.kernels.jit import kernel
from engine.kernels.lights import light_set
from engine.kernels import surface, textures, volume
from engine.nodes import interpreter
from engine_scenes import cornell_box

BLENDS = ("product_shot", "fog_room", "hdri_world", "motion_cube", "glass", "node_closures")


def leaked_allocations(run) -> int:
    """Compiled-code allocations that `run()` makes and never frees."""
    gc.collect()
    was = _nrt_python.memsys_stats_enabled()
    _nrt_python.memsys_enable_stats()
    try:
        s0 = rtsys.get_allocation_stats()
        run()
        gc.collect()
        s1 = rtsys.get_allocation_stats()
    finally:
        if not was:
            _nrt_python.memsys_disable_stats()
    return (s1.alloc - s0.alloc) - (s1.free - s0.free)


def render_blends(bpy):
    from drt_addon.engine_link import engine
    from drt_addon.export import Reporter, export_scene
    for name in BLENDS:
        bpy.ops.wm.open_mainfile(filepath=os.path.join(SAMPLES_DIR, name + ".blend"))
        description = export_scene(bpy.context.evaluated_depsgraph_get(), Reporter(),
                                   size=(24, 18))
        settings = dataclasses.replace(bpy.context.scene.drt.to_engine_settings(),
                                       samples=2, threads=2)
        engine.render(description, settings)


def test_the_per_hit_kernels_borrow():
    for fn in (principled.setup, principled.sample, light_set.sample, light_set.world_escaped,
               surface.rebuild_at_time, textures.texture_rgba, volume.segment,
               interpreter.run):
        assert fn.targetoptions.get("_nrt") is False, fn.py_func.__qualname__


def test_a_borrowing_kernel_compiles_with_scalar_results():
    @kernel(allocates=False, cache=False)
    def first_two(a):
        return a[0], a[1] * 2.0

    assert first_two(np.array([1.0, 3.0])) == (1.0, 6.0)


def test_an_array_result_is_refused():
    # Numba refuses a new array or a view out of a kernel without reference counting,
    # but lets an argument through: the check refuses that
    @kernel(allocates=False, cache=False)
    def same(a):
        return a

    with pytest.raises(TypeError, match="returns an array"):
        same.compile((types.float64[:],))

    @kernel(allocates=False, cache=False)
    def pair(a, x):
        return x, a

    with pytest.raises(TypeError, match="returns an array"):
        pair.compile((types.float64[:], types.float64))


def test_an_allocation_is_refused():
    @kernel(allocates=False, cache=False)
    def scratch(n):
        return np.zeros(n)[0]

    with pytest.raises(Exception, match="zeros|empty|NRT"):
        scratch(3)


def test_renders_leak_no_allocation(bpy_drt):
    scene = cornell_box(16, 16)
    render(scene, RenderSettings(samples=1, threads=1))
    render_blends(bpy_drt)                  # kernels loaded or compiled
    assert leaked_allocations(lambda: render(scene, RenderSettings(samples=2, threads=2))) == 0
    assert leaked_allocations(lambda: render_blends(bpy_drt)) == 0


def test_a_leak_is_caught():
    @njit(cache=False)
    def fresh(n):
        return np.zeros(n)

    fresh(4)             # compiled with reference counting, as any allocating kernel is

    @kernel(allocates=False, cache=False)
    def uses_fresh(n):
        return fresh(n)[0]          # its fresh array is never released

    uses_fresh(4)
    assert leaked_allocations(lambda: uses_fresh(4)) == 1
