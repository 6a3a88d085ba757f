"""Run inside a Blender with a window (`xvfb-run blender --addons drt SCENE.blend --python
THIS -- OUT_DIR`) by tests/test_viewport_window.py: drives DRT's Rendered viewport as an
artist would, from Blender's own event loop (a timer), and writes what it saw to
OUT_DIR/viewport.json, with a screenshot of the 3D view after each step.

Steps, each waiting until the viewport has drawn its samples (Sampling > Viewport = 4):
  start      the 3D view (camera view, no overlays) switched to Rendered;
  material   the cube's Base Color from red to green;
  move       the cube moved 1.5 m along x;
  lamp       the lamp's power x4;
  navigate   out of camera view, the view turned (no edit: nothing is exported);
  denoise    Sampling > Viewport > Denoise on, from sample 1 (OpenImageDenoise);
  solid      back to Solid shading: the engine is freed, Blender keeps running.
For each step: the viewport's counts (drt.viewport.last_viewport: syncs, export stats),
the time from the edit to the first image of it drawn, and the screenshot's path.
"""
import importlib
import json
import math
import os
import sys
import time
import traceback

import bpy

OUT = sys.argv[sys.argv.index("--") + 1]
SAMPLES = 4
TIMEOUT = 240.0
results = {"steps": [], "error": None}
try:                                  # the add-on folder is the package `drt`
    vp = importlib.import_module("drt.drt_addon.viewport")
except Exception:
    results["error"] = traceback.format_exc()
    vp = None
state = {"step": 0, "since": None, "t_edit": None, "generation": None}


def view3d():
    window = bpy.context.window_manager.windows[0]
    area = max((a for a in window.screen.areas if a.type == "VIEW_3D"),
               key=lambda a: a.width * a.height)
    region = next(r for r in area.regions if r.type == "WINDOW")
    return window, area, region, area.spaces.active


def screenshot(name):
    window, area, region, space = view3d()
    path = os.path.join(OUT, f"{name}.png")
    with bpy.context.temp_override(window=window, area=area, region=region):
        bpy.ops.screen.screenshot_area(filepath=path)
    return path


def edit(name):
    """Make step `name`'s change; returns whether it is an edit of the scene."""
    scene = bpy.context.scene
    _, _, region, space = view3d()
    if name == "start":
        space.overlay.show_overlays = False
        space.show_gizmo = False
        for part in ("header", "tool_header", "toolbar", "ui"):
            setattr(space, f"show_region_{part}", False)     # the view alone
        space.region_3d.view_perspective = "CAMERA"
        scene.cycles.preview_samples = SAMPLES
        space.shading.type = "RENDERED"
    elif name == "material":
        bsdf = bpy.data.materials["Red"].node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Base Color"].default_value = (0.05, 0.8, 0.05, 1.0)
    elif name == "move":
        scene.objects["Cube"].location.x += 1.5
    elif name == "lamp":
        scene.objects["Area"].data.energy *= 4.0
    elif name == "navigate":
        r3d = space.region_3d
        r3d.view_perspective = "PERSP"
        r3d.view_rotation.rotate(__import__("mathutils").Euler((0.0, 0.0, math.radians(20))))
    elif name == "denoise":
        scene.cycles.preview_denoising_start_sample = 1
        scene.cycles.use_preview_denoising = True
        # a click in the Sampling panel redraws the view (the UI's notifier); a timer's
        # change does not: redraw it as the click would
        view3d()[1].tag_redraw()
    elif name == "solid":
        space.shading.type = "SOLID"


STEPS = ["start", "material", "move", "lamp", "navigate", "denoise", "solid"]


def finish():
    with open(os.path.join(OUT, "viewport.json"), "w") as f:
        json.dump(results, f, indent=1, default=str)
    bpy.ops.wm.quit_blender()


def tick():
    try:
        return _tick()
    except Exception:
        results["error"] = traceback.format_exc()
        finish()
        return None


def _tick():
    lv = vp.last_viewport
    now = time.perf_counter()
    if state["since"] is None:                  # start the next step
        name = STEPS[state["step"]]
        state.update(since=now, t_edit=time.perf_counter(),
                     generation=lv.get("generation"), syncs=lv.get("syncs", 0))
        edit(name)
        return 0.02
    name = STEPS[state["step"]]
    if name == "solid":
        if now - state["since"] < 1.5:          # Blender keeps running its timers
            return 0.1
        results["steps"].append({"name": name, "responsive_after": now - state["since"],
                                 "threads": [t.name for t in __import__("threading").enumerate()
                                             if t.name.startswith("DRT viewport")]})
        finish()
        return None
    if now - state["since"] > TIMEOUT:
        results["error"] = f"step {name}: no image of {SAMPLES} samples in {TIMEOUT} s ({lv})"
        finish()
        return None
    new = lv.get("generation") != state["generation"]
    if not (new and lv.get("drawn_generation") == lv.get("generation")
            and lv.get("drawn_samples", 0) >= SAMPLES):
        return 0.02
    stats = lv.get("export_stats") or {}
    results["steps"].append({
        "name": name, "syncs": lv.get("syncs", 0) - state["syncs"],
        "mesh_evaluations": stats.get("mesh_evaluations"),
        "material_exports": stats.get("material_exports"),
        "first_sync": lv.get("first_sync"),
        "edit_to_first_draw": lv.get("first_drawn_at", now) - state["t_edit"],
        "edit_to_full_resolution": (lv.get("full_drawn_at") or now) - state["t_edit"],
        "first_image_seconds": lv.get("first_image_seconds"),
        "export_seconds": lv.get("export_seconds"), "build_seconds": lv.get("build_seconds"),
        "samples": lv.get("drawn_samples"), "error": lv.get("error"),
        "denoised": lv.get("denoised"), "rebuilt": lv.get("rebuilt"),
        "screenshot": screenshot(name)})
    state["step"] += 1
    state["since"] = None
    return 0.05


bpy.app.timers.register(tick if vp is not None else finish, first_interval=1.0)
