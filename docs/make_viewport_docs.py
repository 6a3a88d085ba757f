"""Measures DRT's Rendered viewport and writes docs/viewport.md: how long an edit takes to
show on the sample scenes, what it re-exports, and screenshots of the viewport in a real
Blender window.

    .venv/bin/python docs/make_viewport_docs.py

1. The sample scenes, in the bpy module: a viewport of VIEW_W x VIEW_H pixels in camera
   view, its session synced by the depsgraph's own updates (a depsgraph_update_post
   handler, as Blender calls view_update). For the first sync and for three edits (an
   object moved, a material's colour, a lamp's power): the export and acceleration
   structure times, the meshes and materials exported again, and the time from the edit
   to the first image (the coarsest) and to the first full-resolution image.
2. Debian's Blender 3.4 in a window on a virtual screen (xvfb-run), driven by
   tests/viewport_window_driver.py as tests/test_viewport_window.py drives it: the
   screenshots of each step, and the same times measured inside Blender. Skipped (and
   said so) where `blender` or `xvfb-run` is missing.

Takes about 3 minutes on 2 cores, with the kernels cached.
"""
from __future__ import annotations

import json
import os
import platform
import shutil
import sys
import tempfile
import time
import types
from pathlib import Path

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests")]
DOCS = os.path.join(ROOT, "docs")
IMAGES = os.path.join(DOCS, "images")
VIEW_W, VIEW_H = 960, 540
SAMPLES = 16          # Max Samples: the view keeps refining while the next edit comes
SCENES = ["cornell_box", "product_shot", "glass_caustics", "fog_room", "night_street",
          "instances"]


def _camera_context(bpy):
    """What view_update and view_draw read of a 3D view in camera view."""
    cam = bpy.context.scene.camera
    dg = bpy.context.evaluated_depsgraph_get()
    rv3d = types.SimpleNamespace(view_perspective="CAMERA",
                                 view_matrix=cam.matrix_world.inverted(),
                                 window_matrix=cam.calc_matrix_camera(dg, x=VIEW_W, y=VIEW_H))
    return types.SimpleNamespace(region=types.SimpleNamespace(width=VIEW_W, height=VIEW_H),
                                 space_data=types.SimpleNamespace(use_render_border=False),
                                 region_data=rv3d)


def _wait(session, t_edit, timeout=600.0):
    """(seconds to the first image, to the first full-resolution one): the next edit
    comes while the view still refines, as an artist's does."""
    first = None
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < timeout:
        if session.error:
            raise RuntimeError(session.error)
        p = session.published
        if p is not None and p[0] == session.generation:
            now = time.perf_counter()
            first = first or now - t_edit
            if p[3] == 1:
                return first, now - t_edit
        time.sleep(0.002)
    raise RuntimeError("the viewport did not finish")


def _edits(bpy):
    """(name, change) of the three edits, on the scene's first mesh, material, lamp."""
    scene = bpy.context.scene
    mesh = next(o for o in scene.objects if o.type == "MESH" and o.visible_get())
    lamp = next((o for o in scene.objects if o.type == "LIGHT"), None)
    mat = next((m for m in bpy.data.materials if m.node_tree is not None and
                "Principled BSDF" in m.node_tree.nodes and m.users), None)
    out = [("move " + mesh.name, lambda: setattr(mesh, "location",
                                                 mesh.location + type(mesh.location)((0.05, 0, 0))))]
    if mat is not None:
        socket = mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"]
        out.append(("colour of " + mat.name, lambda: setattr(
            socket, "default_value", (0.2, 0.6, 0.3, 1.0))))
    if lamp is not None:
        out.append(("power of " + lamp.name, lambda: setattr(
            lamp.data, "energy", lamp.data.energy * 1.5)))
    return out


def measure_scene(bpy, name):
    from drt_addon.export import Reporter
    from drt_addon.viewport import ViewportSession, last_viewport
    bpy.ops.wm.open_mainfile(filepath=os.path.join(ROOT, "sample_blends", name + ".blend"))
    bpy.context.scene.render.engine = "DRT"
    bpy.context.scene.cycles.preview_samples = SAMPLES
    bpy.context.scene.cycles.use_preview_denoising = False
    context = _camera_context(bpy)
    session = ViewportSession(lambda: None)
    rows = []

    def on_update(_scene, depsgraph):
        session.sync(depsgraph, context, Reporter())
    try:
        t = time.perf_counter()
        session.sync(bpy.context.evaluated_depsgraph_get(), context, Reporter())
        rows.append(_row("first sync", last_viewport, _wait(session, t)))
        bpy.app.handlers.depsgraph_update_post.append(on_update)
        for edit, change in _edits(bpy):
            t = time.perf_counter()
            change()
            bpy.context.view_layer.update()
            rows.append(_row(edit, last_viewport, _wait(session, t)))
    finally:
        if on_update in bpy.app.handlers.depsgraph_update_post:
            bpy.app.handlers.depsgraph_update_post.remove(on_update)
        session.free()
    return rows


def _row(what, lv, times):
    stats = lv["export_stats"]
    return {"what": what, "export": lv["export_seconds"], "build": lv["build_seconds"],
            "meshes": stats["mesh_evaluations"], "materials": stats["material_exports"],
            "rebuilt": lv["rebuilt"],
            "first": times[0], "full": times[1]}


def window_screenshots():
    """The Debian Blender window run: its steps, or None (with the reason) without it."""
    blender, xvfb = shutil.which("blender"), shutil.which("xvfb-run")
    if blender is None or xvfb is None:
        return None, "no `blender` or `xvfb-run` on PATH"
    from legacy_blender import SCENE_SCRIPT, LegacyBlender
    home = Path(tempfile.mkdtemp(prefix="drt-viewport-docs-"))
    b = LegacyBlender(blender, home)
    b.run("--python", SCENE_SCRIPT, "--", b.blend)
    out = home / "out"
    out.mkdir()
    driver = os.path.join(ROOT, "tests", "viewport_window_driver.py")
    proc = b.run("--addons", "drt", b.blend, "--python", driver, "--", str(out), window=True,
                 timeout=900)
    result = json.loads((out / "viewport.json").read_text()) if (out / "viewport.json"
                                                                  ).is_file() else None
    if result is None or result["error"]:
        return None, (result or {}).get("error") or proc.log[-2000:]
    from PIL import Image
    tiles = []
    for step in result["steps"]:
        if "screenshot" in step:
            with Image.open(step["screenshot"]) as im:
                tiles.append(im.convert("RGB").resize((400, int(400 * im.height / im.width))))
    w, h = tiles[0].size
    sheet = Image.new("RGB", (3 * w, 2 * h))
    for i, tile in enumerate(tiles[:6]):
        sheet.paste(tile, ((i % 3) * w, (i // 3) * h))
    os.makedirs(IMAGES, exist_ok=True)
    sheet.save(os.path.join(IMAGES, "viewport_steps.png"))
    return result["steps"], None


def write(scenes, steps, why_not):
    lines = [
        "# The Rendered viewport",
        "",
        "Switch a 3D view to Rendered shading with DRT as the render engine: DRT traces the "
        "view progressively, first coarse (one sample at 1/8, 1/4, 1/2 of the view's size, "
        "as Cycles starts at 64 pixels), then at full resolution up to Sampling > Viewport > "
        "Max Samples (Cycles' own `preview_samples`; 0 is no limit). An edit restarts it and "
        "exports again only what the edit touched; moving the view exports nothing. "
        "Sampling > Viewport > Denoise (with its passes, prefilter, quality and start "
        "sample) denoises the viewport with OpenImageDenoise, as Cycles does. Render Region "
        "works in the view (View > Render Region) and in camera view (the scene's). The view "
        "is drawn through Blender's display transform, as Cycles' is.",
        "",
        f"Measured by `docs/make_viewport_docs.py` on {platform.processor() or platform.machine()}, "
        f"{os.cpu_count()} cores, Python {platform.python_version()}.",
        "",
        "## In a Blender window",
        "",
    ]
    if steps is None:
        lines += [f"Not measured on this machine: {why_not}.", ""]
    else:
        lines += [
            "![The Rendered viewport, step by step](images/viewport_steps.png)",
            "",
            "*Debian's Blender 3.4 in a window on a virtual screen (Xvfb, Mesa's software "
            "OpenGL), DRT as its add-on: the 3D view in camera view switched to Rendered, "
            "then (left to right, top to bottom) the cube's Base Color made green, the cube "
            "moved, the lamp's power x4, the view turned out of camera view, Sampling > "
            "Viewport > Denoise on (this scene is nearly noiseless at 4 samples). The same "
            "run is tests/test_viewport_window.py.*",
            "",
            "| step | exported again: meshes | materials | edit to first image drawn | "
            "to full resolution drawn |",
            "|---|---|---|---|---|",
        ]
        for s in steps:
            if "edit_to_first_draw" in s:
                lines.append(f"| {s['name']} | {s['mesh_evaluations']} | "
                             f"{s['material_exports']} | {s['edit_to_first_draw']:.3f} s | "
                             f"{s['edit_to_full_resolution']:.3f} s |")
        lines.append("")
    lines += [
        f"## The sample scenes, {VIEW_W} x {VIEW_H} pixels",
        "",
        "In the bpy module (no window: the times are the session's, drawing excluded). "
        "*First image*: the coarsest (one sample at 1/8 of the size); *full resolution*: "
        "one sample at every pixel. *meshes*, *materials*: how many the edit exported "
        "again. *BVH*: the acceleration structure's build; *kept* after an edit of lamps "
        "alone (the time is then the lights' and the integrator's set-up).",
        "",
        "| scene | what | export | BVH | meshes | materials | first image | full "
        "resolution |",
        "|---|---|---|---|---|---|---|---|",
        # BVH: the acceleration structure's build, or "kept" (a lamp's edit)
    ]
    firsts, fulls = [], []
    for name, rows in scenes.items():
        for r in rows:
            bvh = f"{r['build']:.3f} s" if r["rebuilt"] else f"kept ({r['build']:.3f} s)"
            lines.append(f"| {name} | {r['what']} | {r['export']:.3f} s | {bvh} | "
                         f"{r['meshes']} | {r['materials']} | {r['first']:.3f} s | "
                         f"{r['full']:.3f} s |")
            if r["what"] != "first sync":
                firsts.append(r["first"])
                fulls.append(r["full"])
    lines += [
        "",
        f"Over the {len(firsts)} edits: the first image after an edit in "
        f"{np.median(firsts):.3f} s (median; at most {max(firsts):.3f} s), the first "
        f"full-resolution image in {np.median(fulls):.3f} s (median; at most "
        f"{max(fulls):.3f} s). Within 0.3 s of the edit: the first image in "
        f"{sum(f <= 0.3 for f in firsts)} of {len(firsts)} edits, the full-resolution one in "
        f"{sum(f <= 0.3 for f in fulls)}. A full-resolution sample costs what a final render's sample "
        "costs at this size (benchmarks.md), so heavier scenes refine more slowly; the "
        "coarse images keep the view responsive meanwhile.",
        "",
        "What is not there yet: the viewport renders no motion blur (as Cycles' viewport), "
        "ignores Cycles' viewport-only adaptive sampling, Pause and texture limit "
        "([settings.md](settings.md)), and a change that Blender reports without naming what "
        "changed (an image, a node group) exports every material again, a geometry node "
        "group every mesh.",
        "",
    ]
    with open(os.path.join(DOCS, "viewport.md"), "w") as f:
        f.write("\n".join(lines))
    print("wrote docs/viewport.md")


def main():
    import bpy
    import drt_addon
    drt_addon.register()
    scenes = {}
    for name in SCENES:
        scenes[name] = measure_scene(bpy, name)
        for r in scenes[name]:
            print(name, r, flush=True)
    steps, why_not = window_screenshots()
    write(scenes, steps, why_not)


if __name__ == "__main__":
    main()
