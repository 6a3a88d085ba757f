"""Shared fixtures: the bpy module with the DRT add-on registered once per session, and
helpers that render a .blend with DRT or Cycles into scene-linear pixels."""
from __future__ import annotations

import os
import sys
import tempfile

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TESTS = os.path.dirname(os.path.abspath(__file__))
SAMPLES_DIR = os.path.join(ROOT, "sample_blends")
for p in (ROOT, TESTS):
    if p not in sys.path:
        sys.path.insert(0, p)


@pytest.fixture(scope="session")
def bpy_drt():
    """bpy with the source-checkout add-on registered (once: Blender refuses a second
    registration of the same classes)."""
    import bpy

    import drt_addon
    drt_addon.register()
    if os.environ.get("DRT_TEST_RENDER_LOG"):
        _log_renders(bpy, os.environ["DRT_TEST_RENDER_LOG"])
    return bpy


def _log_renders(bpy, path):
    """With DRT_TEST_RENDER_LOG=FILE, each render the suite starts through Blender appends
    a line to FILE: the test, the engine, samples, resolution and seconds (where the
    suite's time goes: `python tests/render_log.py FILE` sums it up)."""
    import json
    import time

    started = {}

    @bpy.app.handlers.persistent              # kept when a test opens another file
    def pre(scene, *_):
        started["t"] = time.perf_counter()

    @bpy.app.handlers.persistent
    def post(scene, *_):
        r = scene.render
        row = {"test": os.environ.get("PYTEST_CURRENT_TEST", "").split(" ")[0],
               "engine": r.engine, "samples": int(scene.drt.samples if r.engine == "DRT"
                                                  else scene.cycles.samples),
               "size": [r.resolution_x * r.resolution_percentage // 100,
                        r.resolution_y * r.resolution_percentage // 100],
               "seconds": time.perf_counter() - started.pop("t", time.perf_counter())}
        with open(path, "a") as f:
            f.write(json.dumps(row) + "\n")

    bpy.app.handlers.render_pre.append(pre)
    bpy.app.handlers.render_post.append(post)
    bpy.app.handlers.render_cancel.append(post)


def read_image_linear(bpy, path) -> np.ndarray:
    """A float image file as (h, w, 3), row 0 at the top."""
    img = bpy.data.images.load(path, check_existing=False)
    try:
        w, h = img.size
        px = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(px)
    finally:
        bpy.data.images.remove(img)
    return px.reshape(h, w, 4)[::-1, :, :3].astype(np.float64)


def use_engine(scene, engine, samples):
    """Render `scene` with `engine` at `samples` per pixel, Cycles on the CPU without
    denoising or adaptive sampling (so both engines take every sample)."""
    scene.render.engine = engine
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.device = "CPU"
    scene.drt.samples = samples


def render_blend(bpy, path, engine, samples, percentage=50, setup=None) -> np.ndarray:
    """Open `path`, render it with `engine` ('DRT' or 'CYCLES') and return the Combined
    pass as scene-linear float64 (h, w, 3), read back through an OpenEXR file exactly as
    Blender wrote it (so row order and the write-back path are tested too)."""
    bpy.ops.wm.open_mainfile(filepath=path, load_ui=False)
    scene = bpy.context.scene
    scene.render.resolution_percentage = percentage
    use_engine(scene, engine, samples)
    if setup is not None:
        setup(scene)
    return render_current(bpy, scene)


def cached_render(cache, bpy, path, engine, samples, setup=None, tag="") -> np.ndarray:
    """render_blend at 100 % of `path`, kept in `cache` (a test module's dict) under
    (engine, samples, tag): one render per setting for the whole module."""
    key = (engine, samples, tag)
    if key not in cache:
        cache[key] = render_blend(bpy, path, engine, samples=samples, percentage=100,
                                  setup=setup)
    return cache[key]


def _still_images(settings):
    """A file whose output is a movie (Blender 5's media type VIDEO offers only FFMPEG)
    is set to write still images, so that OpenEXR can be picked."""
    if getattr(settings, "media_type", "IMAGE") != "IMAGE":
        settings.media_type = "IMAGE"


def read_render_result(bpy, scene) -> np.ndarray:
    """Blender's Render Result as Blender writes it: scene-linear OpenEXR, read back as
    float64 (h, w, 3), row 0 at the top."""
    settings = scene.render.image_settings
    _still_images(settings)
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "render.exr")
        bpy.data.images["Render Result"].save_render(filepath=out, scene=scene)
        return read_image_linear(bpy, out)


def read_render_rgba(bpy, scene) -> np.ndarray:
    """Blender's Render Result with its alpha, as (h * w, 4) float64 (bottom-up rows)."""
    settings = scene.render.image_settings
    _still_images(settings)
    settings.file_format, settings.color_depth, settings.color_mode = "OPEN_EXR", "32", "RGBA"
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "rgba.exr")
        bpy.data.images["Render Result"].save_render(filepath=path, scene=scene)
        img = bpy.data.images.load(path, check_existing=False)
        try:
            px = np.empty(img.size[0] * img.size[1] * 4, np.float32)
            img.pixels.foreach_get(px)
        finally:
            bpy.data.images.remove(img)
    return px.reshape(-1, 4).astype(np.float64)


def render_current(bpy, scene) -> np.ndarray:
    """Render the open scene with its engine (asserting DRT succeeded) and read it back."""
    bpy.ops.render.render()
    if scene.render.engine == "DRT":
        from drt_addon import render_engine
        assert render_engine.last_render["ok"], render_engine.last_render["error"]
    return read_render_result(bpy, scene)


def grey_room(bpy, size, grey, world=0.02):
    """A new empty scene at `size` pixels (100 %) with a grey floor and back wall (8 m
    planes, Principled at base colour `grey`) under a uniform world of `world`: the
    stage of small comparison scenes built in a test."""
    import math
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.world = bpy.data.worlds.new("dim")
    scene.world.color = (world, world, world)
    mat = bpy.data.materials.new("grey")
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (
        grey, grey, grey, 1.0)
    bpy.ops.mesh.primitive_plane_add(size=8.0)
    bpy.context.object.data.materials.append(mat)
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 2.0, 2.0),
                                     rotation=(math.pi / 2, 0.0, 0.0))
    bpy.context.object.data.materials.append(mat)
    return scene


def as_diffuse(bpy, bl_idname, colour):
    """Every node of type `bl_idname` in every material replaced, in place, by a Diffuse
    BSDF of colour(material, node) (RGB): the controls of the comparisons of shader
    nodes, what DRT rendered before it supported them."""
    for mat in bpy.data.materials:
        nt = mat.node_tree
        for node in [n for n in nt.nodes if n.bl_idname == bl_idname]:
            diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
            diffuse.inputs["Color"].default_value = (*colour(mat, node)[:3], 1.0)
            for link in list(node.outputs[0].links):
                nt.links.new(diffuse.outputs[0], link.to_socket)
            nt.nodes.remove(node)
