"""Rendering leaves the user's data alone and Blender ready for the next render (issue 11):
after a render, after a render cancelled in each of its phases and after a failed one,
the .blend on disk, the scene's frame and settings and the objects are unchanged
(tests/user_data.py); a cancel stops at the next poll; twenty renders in one session do
not grow its memory.

The scene: the small animated Cornell box of the batch tests (32 x 24, 4 samples) at
frame 2, with motion blur on, so the export moves the frame to the shutter's steps and
must put it back."""
import gc

import numpy as np
import pytest

from batch_scenes import build_animated_cornell
from user_data import differences, file_state, snapshot

PHASES = ["export", "acceleration structure", "tracing", "passes"]


@pytest.fixture(scope="module")
def blend(bpy_drt, tmp_path_factory):
    return build_animated_cornell(bpy_drt, tmp_path_factory.mktemp("side") / "anim.blend")


def _open(bpy, blend):
    bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    scene.render.use_motion_blur = True
    scene.frame_set(2)
    scene.view_layers[0].use_pass_z = True           # so the extra passes are polled too
    return scene


def _render_again_works(bpy):
    from drt_addon.render_engine import last_render
    bpy.ops.render.render()
    assert last_render["ok"], last_render["error"]
    assert last_render["pixels"].max() > 0


def test_the_snapshot_sees_each_kind_of_change(bpy_drt, blend):
    scene = _open(bpy_drt, blend)
    before = snapshot(bpy_drt, blend)
    scene.frame_current += 1
    scene.drt.samples += 1
    block = bpy_drt.data.objects["ShortBlock"]
    block.location.z += 0.5
    block.data.vertices[0].co.x += 1e-3
    bpy_drt.context.view_layer.update()
    assert differences(before, snapshot(bpy_drt, blend)) == [
        "drt.samples", "frame", "objects.ShortBlock"]


def test_a_render_changes_nothing(bpy_drt, blend):
    from drt_addon.render_engine import last_render
    _open(bpy_drt, blend)
    before = snapshot(bpy_drt, blend)
    bpy_drt.ops.render.render()
    assert last_render["ok"], last_render["error"]
    assert last_render["export_stats"]["motion"]["frame_sets"] > 0   # the frame did move
    depth = last_render["passes"]["Depth"]          # with motion blur too (it failed before)
    assert np.isfinite(depth).all() and depth.min() > 0
    assert differences(before, snapshot(bpy_drt, blend)) == []


@pytest.mark.parametrize("phase", PHASES)
def test_cancel_in_each_phase_stops_there_and_changes_nothing(bpy_drt, blend, phase,
                                                            monkeypatch):
    from drt_addon.render_engine import DRTRenderEngine, last_render
    _open(bpy_drt, blend)
    before = snapshot(bpy_drt, blend)
    polls = []          # (phase, answer) of every poll
    state = {"cancelled": False, "tracing": 0}

    def cancel_in_phase(self):
        # Esc pressed in `phase` (in tracing, after the first pass); it stays pressed
        now = last_render["phase"]
        state["tracing"] += now == "tracing"
        if now == phase and (phase != "tracing" or state["tracing"] >= 2):
            state["cancelled"] = True
        polls.append((now, state["cancelled"]))
        return state["cancelled"]

    with monkeypatch.context() as m:
        m.setattr(DRTRenderEngine, "_cancel_requested", cancel_in_phase)
        bpy_drt.ops.render.render()
    assert last_render["error"] == "cancelled" and not last_render["ok"]
    assert last_render["cancelled_in"] == phase
    # promptly: the render stops at the poll that saw the cancel (no step after it polls)
    assert [yes for _, yes in polls].index(True) == len(polls) - 1, polls
    if phase == "export":
        assert last_render["scene"] is None
    if phase != "passes":
        assert last_render["passes"] == {}
    assert differences(before, snapshot(bpy_drt, blend)) == []
    _render_again_works(bpy_drt)


def _broken(*args, **kwargs):
    raise MemoryError("out of memory building the BVH")


def test_a_failed_render_changes_nothing(bpy_drt, blend, monkeypatch):
    """A render that fails after the export (here the acceleration structure raises) is
    reported as one error, and leaves everything as it was."""
    from drt_addon import render_engine
    from drt_addon.engine_link import engine
    _open(bpy_drt, blend)
    before = snapshot(bpy_drt, blend)

    with monkeypatch.context() as m:
        m.setattr(engine, "RenderContext", _broken)
        # the engine's error report: in the UI the status bar, here the operator raises
        with pytest.raises(RuntimeError, match="MemoryError: out of memory building"):
            bpy_drt.ops.render.render()
    last = render_engine.last_render
    assert not last["ok"]
    assert last["error"] == "DRT: render failed: MemoryError: out of memory building the BVH"
    assert differences(before, snapshot(bpy_drt, blend)) == []
    _render_again_works(bpy_drt)


def test_a_failed_render_in_the_batch_renderer_is_one_line(bpy_drt, blend, monkeypatch,
                                                          tmp_path, capsys):
    from drt_addon import render_engine
    from drt_addon.batch import EXIT_RENDER, main
    from drt_addon.engine_link import engine
    before = file_state(blend)
    monkeypatch.setattr(engine, "RenderContext", _broken)
    code = main(["render", blend, "-o", str(tmp_path / "x.png"), "--no-progress"])
    err = capsys.readouterr().err
    assert code == EXIT_RENDER
    assert [l for l in err.splitlines() if l.startswith("drt: error")] == [
        "drt: error: render of frame 1 failed: MemoryError: out of memory building the BVH"]
    assert "Traceback" not in err and "MemoryError" in render_engine.last_render["traceback"]
    assert not (tmp_path / "x.png").exists()
    assert file_state(blend) == before


def _grid_scene(bpy):
    """A 130k-triangle grid under a sun, 8 x 8 pixels, 1 sample: export and BVH dominate."""
    import math
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "DRT"
    scene.render.resolution_x = scene.render.resolution_y = 8
    scene.drt.samples = 1
    scene.cycles.use_denoising = False
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=256, y_subdivisions=256, size=4.0)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (0.0, 0.0, 5.0)
    scene.collection.objects.link(sun)
    scene.collection.objects.link(cam)
    scene.camera = cam
    cam.rotation_euler = (0.0, 0.0, math.radians(10.0))
    return scene


def test_repeated_renders_do_not_leak(bpy_drt):
    """20 renders of the same scene: after the first 5 (caches, kernels, Blender's render
    buffers) resident memory must stay flat. A leak of the exported scene per render would
    add 15 x its size; the bound is 3 x its size."""
    import psutil

    from drt_addon.render_engine import last_render
    _grid_scene(bpy_drt)
    proc = psutil.Process()
    rss = []
    for _ in range(20):
        bpy_drt.ops.render.render()
        assert last_render["ok"], last_render["error"]
        gc.collect()
        rss.append(proc.memory_info().rss)
    meshes = last_render["scene"].meshes
    scene_bytes = sum(a.nbytes for m in meshes for a in vars(m).values()
                      if hasattr(a, "nbytes"))
    growth = rss[-1] - rss[4]
    print(f"RSS after renders 1, 5, 20: {rss[0] / 1e6:.1f}, {rss[4] / 1e6:.1f}, "
          f"{rss[-1] / 1e6:.1f} MB; growth over the last 15: {growth / 1e6:.2f} MB; "
          f"exported scene {scene_bytes / 1e6:.1f} MB")
    assert scene_bytes > 2e6                     # a leak of it would show
    assert growth < 3 * scene_bytes
